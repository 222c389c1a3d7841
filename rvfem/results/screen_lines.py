"""The screen lines of the result sections, from their part of a ``summary.json`` (what ``rvfem
run`` and ``rvfem rigid`` print; the command line composes them, :mod:`rvfem.app.screen`). Numbers
show at least :data:`SCREEN_DIGITS` significant figures; lives in whole hours or with three
significant figures."""

from __future__ import annotations

from typing import Any

import math

from rvfem.evaluate.rigid import REFERENCE_NAMES
from rvfem.results.format import toml_text
from rvfem.units import nm_from_nmm

__all__ = ["SCREEN_DIGITS", "cycle_lines", "handbook_reference", "wall_time_lines", "num", "sig", "life", "header_lines", "bearing_lines", "stage_lines", "hertz_line", "duty_lines", "drawing_text", "bearing_depth_lines", "roller_depth_lines", "warning_lines", "reference_lines", "stress_lines", "accuracy_lines"]


def num(value: float | None, fmt: str) -> str:
    """``format(value, fmt)``, or a dash as wide for a value that could not be computed (None)."""
    if value is None:
        width = "".join(c for c in fmt.split(".")[0] if c.isdigit())
        return "–".rjust(int(width or 0))
    return format(value, fmt)



SCREEN_DIGITS = 4

"""Fewest significant figures a number of the screen tables shows (:func:`_sig`)."""



def sig(value: float | None, fmt: str) -> str:
    """A load, pressure or stress for a screen table: ``format(value, fmt)`` (a fixed-point format
    such as ``"8.0f"``) where that shows at least :data:`SCREEN_DIGITS` significant figures and fits
    the width, else the value with that many significant figures (``0.007113``, ``3.813e+08``);
    a dash for None. A 1e-3 N·m torque gives loads in mN, not "0"."""
    if value is None:
        return num(value, fmt)
    v = float(value)
    spec = fmt.rstrip("f")
    width_text, _, decimals_text = spec.partition(".")
    width = int("".join(c for c in width_text if c.isdigit()) or 0)
    decimals = int(decimals_text or 0)
    fixed = format(v, fmt)
    fits = len(fixed) <= (width or 12)          # a free-width number up to 12 characters
    if v == 0 or not math.isfinite(v) or (abs(v) >= 10.0 ** (SCREEN_DIGITS - 1 - decimals) and fits):
        return fixed
    return f"{v:.{SCREEN_DIGITS}g}".rjust(width)



def life(value: float | None, width: int = 0) -> str:
    """A life in hours for the screen: whole hours from 1 h to 10⁷ h, three significant figures
    outside (``0.0497``, ``1.23e+24``), ``inf`` at zero load, a dash for None."""
    if value is None:
        return num(value, f"{width}.0f")
    v = float(value)
    if not math.isfinite(v) or v == 0:
        return f"{v:{width}.0f}"
    if 1.0 <= abs(v) < 1e7:
        return f"{v:{width}.0f}"
    return f"{v:{width}.3g}"



def header_lines(summary: dict[str, Any]) -> list[str]:
    """The case, the model, the torque and the rating, and the head of the bearing table."""
    c, m = summary["case"], summary["model"]
    return [
        f"Case {c['name']}" + (f" ({c['file']})" if c.get("file") else "") +
        (f", overrides: {', '.join(f'{k} = {toml_text(v)}' for k, v in c['overrides'].items())}"
         if c["overrides"] else ""),
        f"  model: bearings '{m['bearing_model']}', P{m['element_order']}, {m['nodes']} nodes, {m['dofs']} dofs, "
        f"{m['elements']} elements; {m['angles']} crank angles (step {m['angle_step_deg']:g}°)",
        f"  torque {m['output_torque_Nm']:g} N·m on {m['discs']} discs = {nm_from_nmm(m['disc_torque_Nmm']):g} N·m per disc "
        f"about the reducer axis; C = {m['dynamic_load_rating_N']:.0f} N, n_b = {m['bearing_speed_rpm']:g} rpm",
        "",
        f"  {'bearing':>7} {'model':<9} {'max N':>8} {'at °':>6} {'min N':>8} {'at °':>6} {'F_m N':>8} {'L10h h':>9}",
    ]



def bearing_lines(summary: dict[str, Any], handbook: bool) -> list[str]:
    """Per bearing: the loads and life by each model, then the deltas and the life ratio."""
    rows = ("rigid", "flexible") if handbook else ("rigid", "equal_share", "flexible")
    names = {"rigid": "rigid", "flexible": "flexible", "equal_share": "eq. share"}
    lines = []
    for b in summary["bearings"]:
        for key in rows:
            s = b[key]
            head = f"  {b['bearing'] if key == 'rigid' else '':>7} {names[key]:<9} "
            if s is None:
                lines.append(head + "not defined for Zp − Zc ≠ 1")
                continue
            lines.append(head + f"{sig(s['max_load_N'], '8.0f')} "
                         f"{num(s['max_at_deg'], '6.1f')} {sig(s['min_load_N'], '8.0f')} {num(s['min_at_deg'], '6.1f')} "
                         f"{sig(s['equivalent_load_N'], '8.0f')} {life(s['L10h_h'], 9)}")
        lines.append(f"  {'':>7} {'delta':<9} {num(b['delta_max_percent'], '+7.1f')}% {'':>6} "
                     f"{num(b['delta_min_percent'], '+7.1f')}% {'':>6} {num(b['delta_equivalent_percent'], '+7.1f')}%  "
                     f"life ratio {num(b['life_ratio'], '.2f')}" + ("" if handbook else "  (vs equal share)"))
    return lines



def stage_lines(summary: dict[str, Any], handbook: bool) -> list[str]:
    """The reducer stage and what the delta of bearing 1 is made of, step by step."""
    rs = summary["reducer_stage"]
    lines = ["", f"  reducer stage: {rs['model']}"]
    if rs["torque_share"]:
        lines[-1] += (f"; torque of disc A {rs['torque_share']['min']:.3f}–{rs['torque_share']['max']:.3f} × T/2")
    lines.append(f"  what the delta of bearing 1 is made of (against the "
                 f"{'handbook' if handbook else 'equal share of the FE pin resultant'}):")
    for r in summary["attribution"]:
        if r["bearing"] == 1:
            lines.append(f"    {r['step']:<12} max {num(r['delta_max_percent'], '+6.1f')}%  min "
                         f"{num(r['delta_min_percent'], '+6.1f')}%  F_m {num(r['delta_equivalent_percent'], '+6.1f')}%"
                         f"  life ratio {num(r['life_ratio'], '.2f')}" + ("   <- this run" if r["final"] else ""))
    return lines



def hertz_line(h: dict[str, Any]) -> str:
    """The Hertz pressures of the most loaded roller: rigid Stribeck, then the FE roller load (or
    Stribeck with the FE bearing load where there are no FE roller loads)."""
    sr, fe = h["stribeck_rigid"], h.get("fe_rollers")
    line = ("  Hertz, most loaded roller: " + (
        f"rigid rings Q = {sig(sr['roller_load_N'], '.0f')} N, p_in {sig(sr['inner']['peak_pressure_MPa'], '.0f')}"
        f" / p_out {sig(sr['outer']['peak_pressure_MPa'], '.0f')} MPa" if sr else
        "rigid rings not defined for Zp − Zc ≠ 1"))
    if fe:
        return line + (f"; FE Q = {sig(fe['roller_load_N'], '.0f')} N, p_in "
                       f"{sig(fe['inner']['peak_pressure_MPa'], '.0f')} / p_out "
                       f"{sig(fe['outer']['peak_pressure_MPa'], '.0f')} MPa")
    sf = h["stribeck_flexible"]
    return line + (f"; rigid rings under the FE bearing loads Q = {sig(sf['roller_load_N'], '.0f')} N, p_in "
                   f"{sig(sf['inner']['peak_pressure_MPa'], '.0f')} / p_out "
                   f"{sig(sf['outer']['peak_pressure_MPa'], '.0f')} MPa")



def duty_lines(duty: dict[str, Any] | None) -> list[str]:
    """The duty-cycle service lives and their check by the flexible model; none without a duty cycle."""
    if not duty:
        return []
    lines = ["  duty cycle: service life " + ", ".join(
        f"{key} {life(duty[key]['service_life_h'])} h" if duty[key] else f"{key} not defined"
        for key in ("rigid", "flexible"))
        + f" (equivalent torque {duty['flexible']['equivalent_torque_Nm']:.1f} N·m, "
          f"speed {duty['flexible']['equivalent_speed_rpm']:.2f} rpm; loads scaled linearly with the torque)"]
    fe = duty.get("flexible_fe")
    if fe:
        lines.append(
            "    flexible FE at every duty torque (" + ", ".join(f"{t:g}" for t in fe["torques_Nm"]) + " N·m): "
            f"service life {life(fe['service_life_h'])} h ({num(fe['life_difference_percent'], '+.1f')} % "
            "against the linear scaling); F_m off linear scaling by "
            + ", ".join(f"{e:+.1f} %" for e in fe["linear_scaling_error_percent"]))
    return lines



def drawing_text(t: dict[str, Any], files: Any) -> str:
    """The drawing's part of the wall-time line: with a render worker (``drawing_background`` in
    the timings) the plots and images are drawn by a child process while the tables and VTK files
    are written, so its time is the span from handing them over to having them all, of which this
    process only waited for ``plots`` + ``images``; without, the time the images took here."""
    images = sum(1 for f in files if f.startswith("images/") and f.endswith(".png"))
    wait = t.get("plots", 0.0) + t.get("images", 0.0)
    if "drawing_background" in t:
        return (f"{images} images and the plots drawn in a background process within "
                f"{t['drawing_background']:.1f} s, {wait:.1f} s of it waited for")
    return f"{images} images {t.get('images', 0.0):.1f} s" if images else "no images"



def _damage_words(d: dict[str, Any]) -> str:
    """Where one model's lamina damage peaks, in words (``eccentric x = ±4.49 mm, 7.9× the mean,
    half-peak over 0.31 mm``)."""
    return (f"{d['damage_raceway']} x = ±{abs(d['damage_x_mm']):.2f} mm, {num(d['damage_peak_over_mean'], '.1f')}× "
            f"the mean, half-peak over {num(d['damage_spread_mm'], '.2f')} mm")


def bearing_depth_lines(b: dict[str, Any]) -> list[str]:
    """One bearing's lines of :func:`roller_depth_lines` without its name (``{name}`` in front)."""
    lines = []
    for model in ("rigid", "flexible"):
        d = b[model]
        if d is not None:
            lines.append(f"{model:<8} p_max {sig(d['roller_peak_pressure_MPa'], '.0f')} MPa "
                         f"(edge factor {num(d['roller_edge_factor'], '.2f')}, {d['peak_raceway']}), h_min "
                         f"{num(d['film_thickness_min_um'], '.3f')} µm, κ {num(d['kappa'], '.2f')}, a_ISO "
                         f"{num(d['a_iso'], '.2f')}; L10h {life(d['L10h_h'])} h, L_nm {life(d['L_nm_h'])} h, "
                         f"L10r {life(d['L10r_h'])} h")
    where = [f"{model} {_damage_words(b[model])}" for model in ("rigid", "flexible")
             if b[model] is not None and b[model].get("damage_raceway") is not None]
    if where:
        lines.append("damage peak (where spalling starts): " + "; ".join(where))
    if b["rigid"] is not None:
        lines.append(f"flexible/rigid: L10h {num(b['L10h_ratio'], '.2f')}, L_nm {num(b['L_nm_ratio'], '.2f')}, "
                     f"L10r {num(b['L10r_ratio'], '.2f')}")
    return lines



def roller_depth_lines(depth: dict[str, Any] | None) -> list[str]:
    """The crank bearing in depth: per bearing the pressure along the roller, film, κ and the three
    lives (basic L10h, modified L_nm, lamina L10r) rigid and flexible with the flexible/rigid ratio.
    Neighbouring bearings whose lines read the same (N-fold symmetry: every crank bearing carries the
    same loads, 120° apart) share them: ``bearings 1–3``."""
    if not depth:
        return []
    groups: list[tuple[list[int], list[str]]] = []
    for b in depth["bearings"]:
        body = bearing_depth_lines(b)
        if groups and groups[-1][1] == body:
            groups[-1][0].append(b["bearing"])
        else:
            groups.append(([b["bearing"]], body))
    lines = [f"  crank bearing in depth ({depth['profile']} rollers, {depth['slices']} slices; crankshaft slope up to "
             f"{sig(depth['max_slope_mrad'], '.3f')} mrad):"]
    for numbers, body in groups:
        name = f"bearings {numbers[0]}–{numbers[-1]}" if len(numbers) > 1 else f"bearing {numbers[0]}"
        lines += [f"    {name} {line}" for line in body]
    return lines



def warning_lines(warnings: list[dict[str, Any]], prefix: str = "  warning: ") -> list[str]:
    """The ``warnings`` of ``summary.json`` or ``rvfem rigid --json`` as screen lines, one each
    (:mod:`rvfem.evaluate.validity`), preceded by an empty line; none when there are none."""
    if not warnings:
        return []
    return [""] + [prefix + w["message"] for w in warnings]



def reference_lines(references: dict[str, Any]) -> list[str]:
    """What a run or the rigid evaluation is compared with, and why (the ``references`` object of
    ``summary.json`` or ``rvfem rigid --json``), as screen lines."""

    used = [k for k, r in references.items() if isinstance(r, dict) and r["defined"]]
    main = references["bearing_loads"]
    head = (f"bearing loads compared with {REFERENCE_NAMES[main]}" if main in used else
            "no bearing-load reference computed here")
    others = [REFERENCE_NAMES[k] for k in used if k != main]
    lines = ["  references: " + head + ("; also " + ", ".join(others) if others else "")]
    for key, r in references.items():   # why the reference is not the handbook, why others are missing
        if isinstance(r, dict) and (not r["defined"] or (key == references["bearing_loads"] != "handbook")):
            lines.append(f"    {REFERENCE_NAMES[key]}: {r['why']}")
    return lines



def stress_lines(stress: dict[str, Any]) -> list[str]:
    """The disc-stress lines of the screen summary (the ``stress`` object of ``summary.json``):
    the structural peak away from contacts first, with its convergence check, then the
    contact-zone peak, labelled as such."""
    lines = []
    sp, away, cz = stress.get("structural_peak"), stress.get("away_from_contacts"), stress["contact_zone"]
    if sp:
        assert away is not None   # a structural peak comes with the cycle's envelope
        at = sp["at"]
        lines += [
            f"  structural stress peak (away from contacts) {sig(sp['von_mises_MPa'], '.0f')} MPa von Mises ± "
            f"{sp['estimated_error_MPa']:.1f} MPa (estimated), {at['feature_label']} at ({at['x_mm']:.1f}, "
            f"{at['y_mm']:.1f}) mm, θ = {at['theta_deg']:g}°",
            f"    P2 re-solve at θ = {', '.join(f'{x:g}' for x in sp['angles_deg'])}° with the cycle's forces "
            f"({sp['seconds']:.1f} s); the P{away['element_order']} cycle alone gives {sig(sp['p1_MPa'], '.0f')} MPa "
            f"({sp['p1_error_percent']:+.0f} %)",
        ]
    elif away:
        at = away["at"]
        lines.append(f"  structural stress peak (away from contacts) {sig(away['peak_von_mises_MPa'], '.0f')} MPa "
                     "von Mises "
                     f"(P{away['element_order']}, not re-solved on P2), {at['feature_label']} at ({at['x_mm']:.1f}, "
                     f"{at['y_mm']:.1f}) mm, θ = {at['theta_deg']:g}°")
    at = cz["at"]
    lines.append(f"  contact-zone peak {sig(cz['peak_von_mises_MPa'], '.0f')} MPa (under a pin or roller footprint, "
                 f"mesh-dependent; not a Hertz stress), {at['feature_label']}, {at['distance_to_feature_mm']:.2f} mm "
                 f"from it, θ = {at['theta_deg']:g}°")
    return lines



def accuracy_lines(acc: dict[str, Any] | None) -> list[str]:
    """The transmission-accuracy line of ``rvfem run``: rigidity and lost motion of the stage."""
    if not acc:
        return []
    return [f"  hysteresis loop at {acc['torque_Nm']:g} N·m, input locked, crank angle {acc['crank_angle_deg']:g}°: "
            f"torsional rigidity {acc['torsional_rigidity_Nm_per_arcmin']:.1f} N·m/arcmin, lost motion "
            f"{acc['lost_motion_arcmin']:.3f} arcmin (stage only; rvfem hysteresis for the loop)"]



def handbook_reference(summary: dict[str, Any]) -> bool:
    """True when the bearing loads of a summary are compared with the handbook (else the equal share)."""
    return bool(summary["references"]["bearing_loads"] == "handbook")


def cycle_lines(summary: dict[str, Any]) -> list[str]:
    """Pins in contact, the disc's torsional stiffness and the equilibrium residual of the cycle."""
    pins = summary["pins_in_contact"]
    return [f"  pins in contact {pins['min']}–{pins['max']} of {pins['of']}; disc torque / mean carrier rotation "
            f"{summary['torsional_stiffness_Nm_per_arcmin']:.1f} N·m/arcmin per disc; equilibrium residual "
            f"{summary['equilibrium_residual']:.1e}"]


def wall_time_lines(summary: dict[str, Any]) -> list[str]:
    """The run's wall time and number of files."""
    t = summary["timings_s"]
    return [f"  wall time {t['total']:.1f} s (cycle {t['cycle']:.1f} s, {drawing_text(t, summary['files'])}); "
            f"{len(summary['files'])} files"]
