"""The screen text of the command line: the tables ``rvfem run`` and ``rvfem rigid`` print, from
their summaries (:func:`rvfem.outputs.summary.build_summary`, :func:`rvfem.outputs.summary.rigid_summary`).
Numbers show at least :data:`SCREEN_DIGITS` significant figures; lives in whole hours or with three
significant figures."""

from __future__ import annotations

import math

from rvfem.evaluate.rigid import REFERENCE_NAMES
from rvfem.outputs.design_summary import bearing_check_lines, mass_strength_lines
from rvfem.outputs.report import toml_text
from rvfem.units import nm_from_nmm

__all__ = ["SCREEN_DIGITS", "summary_text", "stage_time_lines", "rigid_text", "warning_lines", "reference_lines",
           "stress_lines"]



def _num(value: float | None, fmt: str) -> str:
    """``format(value, fmt)``, or a dash as wide for a value that could not be computed (None)."""
    if value is None:
        width = "".join(c for c in fmt.split(".")[0] if c.isdigit())
        return "–".rjust(int(width or 0))
    return format(value, fmt)


SCREEN_DIGITS = 4
"""Fewest significant figures a number of the screen tables shows (:func:`_sig`)."""


def _sig(value: float | None, fmt: str) -> str:
    """A load, pressure or stress for a screen table: ``format(value, fmt)`` (a fixed-point format
    such as ``"8.0f"``) where that shows at least :data:`SCREEN_DIGITS` significant figures and fits
    the width, else the value with that many significant figures (``0.007113``, ``3.813e+08``);
    a dash for None. A 1e-3 N·m torque gives loads in mN, not "0"."""
    if value is None:
        return _num(value, fmt)
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


def _life(value: float | None, width: int = 0) -> str:
    """A life in hours for the screen: whole hours from 1 h to 10⁷ h, three significant figures
    outside (``0.0497``, ``1.23e+24``), ``inf`` at zero load, a dash for None."""
    if value is None:
        return _num(value, f"{width}.0f")
    v = float(value)
    if not math.isfinite(v) or v == 0:
        return f"{v:{width}.0f}"
    if 1.0 <= abs(v) < 1e7:
        return f"{v:{width}.0f}"
    return f"{v:{width}.3g}"


def _header_lines(summary: dict) -> list[str]:
    """The case, the model, the torque and the rating, and the head of the bearing table."""
    c, m = summary["case"], summary["model"]
    return [
        f"Case {c['name']}" + (f" ({c['file']})" if c.get("file") else "") +
        (f", overrides: {', '.join(f'{k} = {toml_text(v)}' for k, v in c['overrides'].items())}"
         if c["overrides"] else ""),
        f"  model: bearings '{m['bearing_model']}', P{m['element_order']}, {m['nodes']} nodes, {m['dofs']} dofs, "
        f"{m['elements']} elements; {m['angles']} crank angles (step {m['angle_step_deg']:g}°)",
        f"  torque {m['output_torque_Nm']:g} N·m on {m['discs']} discs = {nm_from_nmm(m['disc_torque_Nmm']):g} N·m per disc "
        f"about the disc centre; C = {m['dynamic_load_rating_N']:.0f} N, n_b = {m['bearing_speed_rpm']:g} rpm",
        "",
        f"  {'bearing':>7} {'model':<9} {'max N':>8} {'at °':>6} {'min N':>8} {'at °':>6} {'F_m N':>8} {'L10h h':>9}",
    ]


def _bearing_lines(summary: dict, handbook: bool) -> list[str]:
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
            lines.append(head + f"{_sig(s['max_load_N'], '8.0f')} "
                         f"{_num(s['max_at_deg'], '6.1f')} {_sig(s['min_load_N'], '8.0f')} {_num(s['min_at_deg'], '6.1f')} "
                         f"{_sig(s['equivalent_load_N'], '8.0f')} {_life(s['L10h_h'], 9)}")
        lines.append(f"  {'':>7} {'delta':<9} {_num(b['delta_max_percent'], '+7.1f')}% {'':>6} "
                     f"{_num(b['delta_min_percent'], '+7.1f')}% {'':>6} {_num(b['delta_equivalent_percent'], '+7.1f')}%  "
                     f"life ratio {_num(b['life_ratio'], '.2f')}" + ("" if handbook else "  (vs equal share)"))
    return lines


def _stage_lines(summary: dict, handbook: bool) -> list[str]:
    """The reducer stage and what the delta of bearing 1 is made of, step by step."""
    rs = summary["reducer_stage"]
    lines = ["", f"  reducer stage: {rs['model']}"]
    if rs["torque_share"]:
        lines[-1] += (f"; torque of disc A {rs['torque_share']['min']:.3f}–{rs['torque_share']['max']:.3f} × T/2")
    lines.append(f"  what the delta of bearing 1 is made of (against the "
                 f"{'handbook' if handbook else 'equal share of the FE pin resultant'}):")
    for r in summary["attribution"]:
        if r["bearing"] == 1:
            lines.append(f"    {r['step']:<12} max {_num(r['delta_max_percent'], '+6.1f')}%  min "
                         f"{_num(r['delta_min_percent'], '+6.1f')}%  F_m {_num(r['delta_equivalent_percent'], '+6.1f')}%"
                         f"  life ratio {_num(r['life_ratio'], '.2f')}" + ("   <- this run" if r["final"] else ""))
    return lines


def _hertz_line(h: dict) -> str:
    """The Hertz pressures of the most loaded roller: rigid Stribeck, then the FE roller load (or
    Stribeck with the FE bearing load where there are no FE roller loads)."""
    sr, fe = h["stribeck_rigid"], h.get("fe_rollers")
    line = ("  Hertz, most loaded roller: " + (
        f"rigid rings Q = {_sig(sr['roller_load_N'], '.0f')} N, p_in {_sig(sr['inner']['peak_pressure_MPa'], '.0f')}"
        f" / p_out {_sig(sr['outer']['peak_pressure_MPa'], '.0f')} MPa" if sr else
        "rigid rings not defined for Zp − Zc ≠ 1"))
    if fe:
        return line + (f"; FE Q = {_sig(fe['roller_load_N'], '.0f')} N, p_in "
                       f"{_sig(fe['inner']['peak_pressure_MPa'], '.0f')} / p_out "
                       f"{_sig(fe['outer']['peak_pressure_MPa'], '.0f')} MPa")
    sf = h["stribeck_flexible"]
    return line + (f"; rigid rings under the FE bearing loads Q = {_sig(sf['roller_load_N'], '.0f')} N, p_in "
                   f"{_sig(sf['inner']['peak_pressure_MPa'], '.0f')} / p_out "
                   f"{_sig(sf['outer']['peak_pressure_MPa'], '.0f')} MPa")


def _duty_lines(duty: dict | None) -> list[str]:
    """The duty-cycle service lives and their check by the flexible model; none without a duty cycle."""
    if not duty:
        return []
    lines = ["  duty cycle: service life " + ", ".join(
        f"{key} {_life(duty[key]['service_life_h'])} h" if duty[key] else f"{key} not defined"
        for key in ("rigid", "flexible"))
        + f" (equivalent torque {duty['flexible']['equivalent_torque_Nm']:.1f} N·m, "
          f"speed {duty['flexible']['equivalent_speed_rpm']:.2f} rpm; loads scaled linearly with the torque)"]
    fe = duty.get("flexible_fe")
    if fe:
        lines.append(
            "    flexible FE at every duty torque (" + ", ".join(f"{t:g}" for t in fe["torques_Nm"]) + " N·m): "
            f"service life {_life(fe['service_life_h'])} h ({_num(fe['life_difference_percent'], '+.1f')} % "
            "against the linear scaling); F_m off linear scaling by "
            + ", ".join(f"{e:+.1f} %" for e in fe["linear_scaling_error_percent"]))
    return lines


def summary_text(summary: dict, stages=None) -> str:
    """One screen of text with the key numbers of a ``summary.json`` (what ``rvfem run`` prints);
    with ``stages`` (the names of the run's stages, :data:`rvfem.app.run.STAGES`) also where the
    wall time went (:func:`stage_time_lines`)."""

    handbook = summary["references"]["bearing_loads"] == "handbook"
    pins, t = summary["pins_in_contact"], summary["timings_s"]
    lines = _header_lines(summary) + _bearing_lines(summary, handbook)
    lines += [""] + reference_lines(summary["references"])
    lines += _stage_lines(summary, handbook)
    lines += [""] + stress_lines(summary["stress"]) + [
        f"  pins in contact {pins['min']}–{pins['max']} of {pins['of']}; disc torque / mean carrier rotation "
        f"{summary['torsional_stiffness_Nm_per_arcmin']:.1f} N·m/arcmin per disc; equilibrium residual "
        f"{summary['equilibrium_residual']:.1e}",
    ]
    lines += _accuracy_lines(summary.get("accuracy"))
    lines += mass_strength_lines(summary)
    lines.append(_hertz_line(summary["hertz"]))
    lines += roller_depth_lines(summary.get("crank_bearing_depth"))
    lines += bearing_check_lines(summary.get("bearing_checks"))
    lines += _duty_lines(summary.get("duty_cycle"))
    lines.append(f"  wall time {t['total']:.1f} s (cycle {t['cycle']:.1f} s, {_drawing_text(t, summary['files'])}); "
                 f"{len(summary['files'])} files")
    lines += stage_time_lines(t, stages)
    lines += warning_lines(summary.get("warnings", []))
    return "\n".join(lines)


def stage_time_lines(timings: dict, stages=None, shown: int = 8) -> list[str]:
    """Where the wall time went: ``total = Σ stages + other`` (``timings_s`` of a run,
    :func:`rvfem.app.run.outside_stages`), the ``shown`` longest of ``stages`` (names) by name,
    the rest summed; nothing without ``stages`` or for timings without ``other`` (a summary of
    an earlier version)."""
    if stages is None or "other" not in timings:
        return []
    spans = sorted(((float(timings[k]), k) for k in stages if k in timings), reverse=True)
    parts = [f"{name} {seconds:.1f}" for seconds, name in spans[:shown]]
    rest = spans[shown:]
    if rest:
        parts.append(f"{len(rest)} shorter stages {sum(sec for sec, _ in rest):.1f}")
    parts.append(f"between the stages {timings['other']:.1f}")
    return [f"  time {timings['total']:.1f} s = " + " + ".join(parts) + " s"]


def _drawing_text(t: dict, files) -> str:
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


def _bearing_depth_lines(b: dict) -> list[str]:
    """One bearing's lines of :func:`roller_depth_lines` without its name (``{name}`` in front)."""
    lines = []
    for model in ("rigid", "flexible"):
        d = b[model]
        if d is not None:
            lines.append(f"{model:<8} p_max {_sig(d['roller_peak_pressure_MPa'], '.0f')} MPa "
                         f"(edge factor {_num(d['roller_edge_factor'], '.2f')}, {d['peak_raceway']}), h_min "
                         f"{_num(d['film_thickness_min_um'], '.3f')} µm, κ {_num(d['kappa'], '.2f')}, a_ISO "
                         f"{_num(d['a_iso'], '.2f')}; L10h {_life(d['L10h_h'])} h, L_nm {_life(d['L_nm_h'])} h, "
                         f"L10r {_life(d['L10r_h'])} h")
    if b["rigid"] is not None:
        lines.append(f"flexible/rigid: L10h {_num(b['L10h_ratio'], '.2f')}, L_nm {_num(b['L_nm_ratio'], '.2f')}, "
                     f"L10r {_num(b['L10r_ratio'], '.2f')}")
    return lines


def roller_depth_lines(depth: dict | None) -> list[str]:
    """The crank bearing in depth: per bearing the pressure along the roller, film, κ and the three
    lives (basic L10h, modified L_nm, lamina L10r) rigid and flexible with the flexible/rigid ratio.
    Neighbouring bearings whose lines read the same (N-fold symmetry: every crank bearing carries the
    same loads, 120° apart) share them: ``bearings 1–3``."""
    if not depth:
        return []
    groups: list[tuple[list[int], list[str]]] = []
    for b in depth["bearings"]:
        body = _bearing_depth_lines(b)
        if groups and groups[-1][1] == body:
            groups[-1][0].append(b["bearing"])
        else:
            groups.append(([b["bearing"]], body))
    lines = [f"  crank bearing in depth ({depth['profile']} rollers, {depth['slices']} slices; crankshaft slope up to "
             f"{_sig(depth['max_slope_mrad'], '.3f')} mrad):"]
    for numbers, body in groups:
        name = f"bearings {numbers[0]}–{numbers[-1]}" if len(numbers) > 1 else f"bearing {numbers[0]}"
        lines += [f"    {name} {line}" for line in body]
    return lines


def warning_lines(warnings: list[dict], prefix: str = "  warning: ") -> list[str]:
    """The ``warnings`` of ``summary.json`` or ``rvfem rigid --json`` as screen lines, one each
    (:mod:`rvfem.evaluate.validity`), preceded by an empty line; none when there are none."""
    if not warnings:
        return []
    return [""] + [prefix + w["message"] for w in warnings]


def reference_lines(references: dict) -> list[str]:
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


def stress_lines(stress: dict) -> list[str]:
    """The disc-stress lines of the screen summary (the ``stress`` object of ``summary.json``):
    the structural peak away from contacts first, with its convergence check, then the
    contact-zone peak, labelled as such."""
    lines = []
    sp, away, cz = stress.get("structural_peak"), stress.get("away_from_contacts"), stress["contact_zone"]
    if sp:
        assert away is not None   # a structural peak comes with the cycle's envelope
        at = sp["at"]
        lines += [
            f"  structural stress peak (away from contacts) {_sig(sp['von_mises_MPa'], '.0f')} MPa von Mises ± "
            f"{sp['estimated_error_MPa']:.1f} MPa (estimated), {at['feature_label']} at ({at['x_mm']:.1f}, "
            f"{at['y_mm']:.1f}) mm, θ = {at['theta_deg']:g}°",
            f"    P2 re-solve at θ = {', '.join(f'{x:g}' for x in sp['angles_deg'])}° with the cycle's forces "
            f"({sp['seconds']:.1f} s); the P{away['element_order']} cycle alone gives {_sig(sp['p1_MPa'], '.0f')} MPa "
            f"({sp['p1_error_percent']:+.0f} %)",
        ]
    elif away:
        at = away["at"]
        lines.append(f"  structural stress peak (away from contacts) {_sig(away['peak_von_mises_MPa'], '.0f')} MPa "
                     "von Mises "
                     f"(P{away['element_order']}, not re-solved on P2), {at['feature_label']} at ({at['x_mm']:.1f}, "
                     f"{at['y_mm']:.1f}) mm, θ = {at['theta_deg']:g}°")
    at = cz["at"]
    lines.append(f"  contact-zone peak {_sig(cz['peak_von_mises_MPa'], '.0f')} MPa (under a pin or roller footprint, "
                 f"mesh-dependent; not a Hertz stress), {at['feature_label']}, {at['distance_to_feature_mm']:.2f} mm "
                 f"from it, θ = {at['theta_deg']:g}°")
    return lines


def rigid_text(report: dict) -> str:
    """The rigid handbook evaluation (a :func:`rigid_summary` dict) as a table (``rvfem rigid``)."""

    p = report["equivalent_load_exponent"]
    p_text = "10/3" if math.isclose(p, 10.0 / 3.0) else f"{p:g}"
    defined = report["references"]["handbook"]["defined"]
    lines = [
        f"Case {report['case']} ({report['source']}): {report['model']}",
        f"  output torque {report['output_torque_Nm']:g} N·m, disc torque {nm_from_nmm(report['disc_torque_Nmm']):g} N·m, "
        f"output speed {report['output_speed_rpm']:g} rpm, bearing speed {report['bearing_speed_rpm']:g} rpm",
        f"  k = {report['k']:.4f}, k_y = {_num(report['k_y'], '.4f')}, ΣPx = {_sig(report['sum_px_N'], '.1f')} N, "
        f"ΣPy = {_sig(report['sum_py_N'], '.1f')} N, crank-angle step {report['angle_step_deg']:g}°",
        f"  dynamic load rating C = {report['dynamic_load_rating_N']:.1f} N; equivalent load exponent p = {p_text}",
    ]
    if report.get("overrides"):
        lines.append(f"  overrides: {', '.join(report['overrides'])}")
    if not defined:
        lines += reference_lines(report["references"])
    header = (f"{'bearing':>7} {'max N':>9} {'at °':>6} {'min N':>9} {'at °':>6} {'F_m N':>9} "
              f"{'L10h h':>9} {'Q_max N':>8} {'p_in MPa':>9} {'p_out MPa':>9} {'κ':>5} {'a_ISO':>5} "
              f"{'L_nm h':>9} {'L10r h':>9}")
    lines += ["", header, "-" * len(header)]
    for b in report["bearings"]:
        if b["max_load_N"] is None and not defined:
            lines.append(f"{b['bearing']:>7d}  not defined for Zp − Zc ≠ 1 (rvfem run compares the FE with the "
                         "equal share)")
            continue
        lines.append(
            f"{b['bearing']:>7d} {_sig(b['max_load_N'], '9.1f')} {b['max_at_deg']:6.1f} {_sig(b['min_load_N'], '9.1f')} "
            f"{b['min_at_deg']:6.1f} {_sig(b['equivalent_load_N'], '9.1f')} {_life(b['L10h_h'], 9)} "
            f"{_sig(b['max_roller_load_N'], '8.1f')} {_sig(b['hertz_inner']['peak_pressure_MPa'], '9.1f')} "
            f"{_sig(b['hertz_outer']['peak_pressure_MPa'], '9.1f')}"
            + (f" {_num(d['kappa'], '5.2f')} {_num(d['a_iso'], '5.2f')} {_life(d['L_nm_h'], 9)} {_life(d['L10r_h'], 9)}"
               if (d := b.get("depth")) else ""))
    lines += [
        "",
        "  at °: crank angle θ of the eccentric relative to the carrier; F_m = (mean F^p)^(1/p) over a turn",
        f"  L10h = 1e6/(60·n_b)·(C/F_m)^(10/3); Q_max: the most loaded roller, rigid rings with the rollers at "
        f"their cage positions (= {report['stribeck_factor']:.2f}·F_max/Z), Hertz at it (p_in: eccentric, p_out: "
        "disc bore); κ, a_ISO, L_nm = a_ISO·L10h (ISO 281), L10r the lamina life (ISO/TS 16281)",
    ]
    lines += bearing_check_lines(report.get("bearing_checks"))
    duty = report.get("duty_cycle")
    if "duty_cycle" in report and duty is None:
        lines.append("  duty cycle: service life not defined (no handbook bearing lives for Zp − Zc ≠ 1)")
    if duty:
        lines.append(
            f"  duty cycle: equivalent torque {duty['equivalent_torque_Nm']:.1f} N·m, equivalent speed "
            f"{duty['equivalent_speed_rpm']:.2f} rpm, service life {_life(duty['service_life_h'])} h "
            f"(from the shortest rated life {_life(duty['rated_life_h'])} h)")
    lines += warning_lines(report.get("warnings", []))
    return "\n".join(lines)


def _accuracy_lines(acc: dict | None) -> list[str]:
    """The transmission-accuracy line of ``rvfem run``: rigidity and lost motion of the stage."""
    if not acc:
        return []
    return [f"  hysteresis loop at {acc['torque_Nm']:g} N·m, input locked, crank angle {acc['crank_angle_deg']:g}°: "
            f"torsional rigidity {acc['torsional_rigidity_Nm_per_arcmin']:.1f} N·m/arcmin, lost motion "
            f"{acc['lost_motion_arcmin']:.3f} arcmin (stage only; rvfem hysteresis for the loop)"]
