"""The HTML report of a run: one self-contained file (styles inline, images embedded as base64).

It is written from the ``summary.json`` content, so the report and the JSON always show the same
numbers, plus the case (its parameters) and the PNG files of the run. The writer that calls it is
:func:`rvfem.outputs.summary.write_report`; the formulas behind the assumptions listed are in
docs/theory.md.
"""

from __future__ import annotations

import base64
import html
import json
import math
import os
import re
from pathlib import Path
from typing import Any

from rvfem.case.definition import Case
from rvfem.case.registry import bearing_model, pin_model
from rvfem.evaluate.rigid import REFERENCE_NAMES

__all__ = ["assumptions", "key_field_angles", "toml_text", "write_report"]

_CSS = """
body { font-family: system-ui, -apple-system, 'Segoe UI', Roboto, sans-serif; margin: 2em auto; max-width: 1200px;
       color: #222; line-height: 1.45; padding: 0 1em; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; } h2 { font-size: 1.25em; margin-top: 2em; border-bottom: 1px solid #ccc; }
h3 { font-size: 1.05em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th { background: #f2f2f2; } td.l, th.l { text-align: left; }
tr.flex td { background: #f7fbff; }
.meta { color: #555; font-size: 0.9em; }
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; }
.grid { display: grid; grid-template-columns: repeat(auto-fit, minmax(520px, 1fr)); gap: 1em; }
ul li { margin: 0.2em 0; }
code { background: #f4f4f4; padding: 0 0.2em; }
.warnings { border: 2px solid #c0392b; background: #fdf0ee; padding: 0.4em 1em; margin: 1em 0; }
.warnings h2 { margin-top: 0.3em; border: none; color: #a93226; }
"""


def _e(x: Any) -> str:
    return html.escape(str(x))


_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def toml_text(value: Any) -> str:
    """A case value as it is written in a case file (TOML): ``true``, ``0.0``, ``"text"``,
    ``[1.0, 2.0]``, ``{equidistant = 0.0, shift = 0.0}`` (no Python ``True`` or dicts in what users
    read).

    Examples
    --------
    >>> toml_text({"symmetric": True, "values": [0.5, 1]})
    '{symmetric = true, values = [0.5, 1]}'
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_text(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k if _BARE_KEY.match(str(k)) else json.dumps(str(k))} = {toml_text(v)}"
                               for k, v in value.items()) + "}"
    return str(value)


def _num(v: Any, fmt: str = ".1f") -> str:
    if v is None:
        return "–"
    if isinstance(v, float) and not math.isfinite(v):
        return "–"
    if isinstance(v, (int, float)):
        return format(v, fmt)
    return _e(v)


def _img(path: Path, alt: str) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{_e(alt)}">'


def _figure(root: Path, rel: str | None, caption: str) -> str:
    if not rel or not (root / rel).is_file():
        return ""
    return f"<figure>{_img(root / rel, caption)}<figcaption>{_e(caption)}</figcaption></figure>"


def _where(at: dict) -> str:
    d = at["distance_to_feature_mm"]
    label = _e(at["feature_label"])
    return f"on the {label}" if d < 1e-6 else f"{d:.2f} mm from the {label}"


def _table(header: list[str], rows: list[list[Any]], left: int = 1, classes: list[str] | None = None) -> str:
    out = ["<table><tr>" + "".join(f'<th class="{"l" if i < left else ""}">{_e(h)}</th>'
                                  for i, h in enumerate(header)) + "</tr>"]
    for r, row in enumerate(rows):
        cls = f' class="{classes[r]}"' if classes and classes[r] else ""
        out.append(f"<tr{cls}>" + "".join(f'<td class="{"l" if i < left else ""}">{c}</td>'
                                          for i, c in enumerate(row)) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def assumptions(summary: dict, case: Case) -> list[str]:
    """The modelling assumptions of a run, as sentences (HTML-escaped text)."""

    m = summary["model"]
    handbook = summary["references"]["bearing_loads"] == "handbook"
    # each model states its own assumptions (rvfem.solve.models)
    bearing = (f"Crank bearings: bearing model <b>{_e(m['bearing_model'])}</b> — "
               f"{_e(bearing_model(m['bearing_model'])(case).describe())}.")
    if m["bearing_model"] != "rollers":
        bearing += " No discrete rollers, so no FE roller loads; Hertz only from the Stribeck estimate."
    try:
        pin = _e(pin_model(m["pin_model"])(case).describe())
    except Exception:   # a validation-only pin model needs its stiffness: name it only
        pin = f"pin model {_e(m['pin_model'])}"
    rs = summary["reducer_stage"]
    overrides = summary["case"].get("overrides") or {}
    stated = ([f"Values set on top of the case file (overrides): "
               f"{', '.join(f'{_e(k)} = {_e(toml_text(v))}' for k, v in overrides.items())}; case.json holds every "
               "value used."]
              if overrides else [])
    return stated + [
        f"2D plane-stress finite-element model of one cycloid disc (thickness {case.cycloid.thickness:g} mm, "
        f"E = {case.material.youngs_modulus:g} MPa, ν = {case.material.poissons_ratio:g}), "
        f"P{m['element_order']} triangles; the disc stiffness is factorised once and each crank angle is "
        "solved on the condensed contact and roller unknowns.",
        f"Reducer stage: <b>{_e(rs['model'])}</b>. "
        + ("Disc A is solved at θ together with disc B at θ + 180°; one carrier rotation, so the output torque "
           f"divides between the discs by their stiffness (disc A carries {rs['torque_share']['min']:.3f}–"
           f"{rs['torque_share']['max']:.3f} × T/2 over the cycle). " if rs["torque_share"] else
           f"Each of the {m['discs']} discs carries T_disc = T_out/{m['discs']} = {m['disc_torque_Nmm'] / 1000:g} N·m "
           "(the handbook's equal share). ")
        + ("The eccentrics are rigid: the flexibility effect reported is an <b>upper bound</b>."
           if rs["crank_support_rigid"] else
           "Each crankshaft is a beam on two elastic support bearings (case table crank_support) carrying both "
           "discs' eccentrics; the eccentrics move relative to the carrier by its influence matrix times the "
           "bearing forces."),
        "Torque convention: a disc's torque is the moment of its pin forces about the <b>disc centre</b> "
        "(the handbook's ΣP_x = T/(2·e·Zc) for T/2). About the reducer axis the moment differs by Zp/Zc "
        f"({100 * (case.pins.count / case.cycloid.teeth - 1):.1f} % here).",
        f"Pins: {pin}; " + (f"Coulomb friction μ = {case.analysis.friction:g} along the sliding direction."
                             if case.analysis.friction > 0 else "no friction (μ = 0)."),
        bearing,
        "Carrier: one rigid body that only rotates, about the disc centre in the disc frame; its rotation is the "
        "unknown conjugate to the disc torque (torsional stiffness = T_disc / rotation, mean over the cycle).",
        ("Rigid reference: the handbook model (Gao et al., eqs. 4-10; rigid disc, rigid bearings, equal load sharing, "
         f"pin-force resultant ratio k_y = {m['handbook_k_y']:.3f}), evaluated at the same crank angles. "
         if handbook else
         "Rigid reference: the equal share of the FE pin resultant (rigid disc on rigid, equally loaded eccentrics); "
         "the handbook model is not defined for Zp − Zc ≠ 1. ")
        + f"The FE pin-force resultant ratio |P_y/P_x| comes out {m['fe_pin_resultant_ratio']:.3f} on average.",
        f"Life: ISO 281 dynamic load rating C = {m['dynamic_load_rating_N']:.0f} N, equivalent load "
        f"F_m = (mean F^p)^(1/p) with p = {m['equivalent_load_exponent']:.4g} over a uniformly sampled turn, "
        f"L10h = 10⁶/(60·n_b)·(C/F_m)^(10/3), bearing speed n_b = {m['bearing_speed_rpm']:g} rpm; life ratio "
        + ("= L_flex/L_rigid." if handbook else "= L_flex/L_equal_share."),
        f"Hertz: line contact of the most loaded roller on the eccentric (convex, inner) and in the bore (concave, "
        f"outer), from the largest FE roller load and from Stribeck's Q_max = {summary['hertz']['stribeck_factor']:g}·F/Z "
        + ("with the rigid (handbook) and the FE bearing load." if handbook else
           "with the FE bearing load (no handbook load for Zp − Zc ≠ 1)."),
        "Stresses: vertex values are area-weighted averages of the adjacent element stresses. Pin and roller forces "
        "are spread over a footprint of about 1.5 elements, so the stress right under a contact depends on the mesh "
        "and is not the Hertz contact stress (see the Hertz table for that); the \"away from contacts\" peak "
        f"ignores a band of {summary['stress']['away_from_contacts']['profile_band_mm']:.2g} mm along the profile and "
        f"{summary['stress']['away_from_contacts']['bore_band_mm']:.2g} mm along the bores. Both stress peaks are "
        "searched over every solved crank angle (the cycle's von Mises envelope), and their fields are kept. "
        "The structural peak is then re-solved on P2 elements of the same mesh, loaded with the cycle's converged "
        "contact and roller forces at the crank angles where the P1 peak lies: P1 vertex stresses lie low at a "
        "free edge (about 15 % on the default case); its estimated error is the spread of the P2 element stresses "
        "at the peak vertex around their average."
        if summary["stress"].get("away_from_contacts") else
        "Stresses: vertex values are area-weighted averages of the adjacent element stresses.",
        "Images: deformation with the disc's rigid-body motion removed, magnified by the factor written on the "
        "image; pins drawn at their nominal positions at that angle (dark: in contact).",
    ]


def _references_html(refs: dict) -> str:
    """Which rigid references the run is compared with, and why (the ``references`` object)."""

    main = refs["bearing_loads"]
    items = []
    for key, r in refs.items():
        if not isinstance(r, dict):
            continue
        state = ("<b>compared with (deltas)</b>" if key == main else "compared with") if r["defined"] else \
            "<b>not used</b>"
        items.append(f"<li>{_e(REFERENCE_NAMES[key])}: {state} — {_e(r['why'])}</li>")
    return ("<p>References: the flexible bearing loads are compared with <b>"
            f"{_e(REFERENCE_NAMES[main])}</b>.</p><ul>" + "".join(items) + "</ul>")


def _depends_on(summary: dict, case: Case) -> str:
    """The section "What this delta depends on": this run's modelling choices next to the measured
    sensitivity of the shipped fan-hole case (notebooks/what_drives_the_flexibility_effect.ipynb)."""
    m, rs = summary["model"], summary["reducer_stage"]
    b, mod = case.crank_bearing, case.cycloid.modification
    law = b.stiffness_law if b.model == "rollers" else "isotropic spring"
    choices = (f"{rs['model']}; bearing model {m['bearing_model']} ({law}), radial clearance "
               f"{b.radial_clearance:g} mm; pin model {m['pin_model']}, friction μ = {case.analysis.friction:g}; "
               f"profile modification ΔRrp = {mod.equidistant:g} mm, ΔRp = {mod.shift:g} mm")
    return (
        "<h2>What this delta depends on</h2>"
        f"<p>This delta is for: {_e(choices)}.</p>"
        "<p>Each of these choices moves the delta by several points, some (the reducer-stage model, the "
        "crank-support stiffness, a profile modification, clearance, pin friction) more than the hole "
        "geometry does; rigid crank support is the upper bound. The table above separates the reducer-stage "
        "steps for this case; the tornado chart of all the drivers on the shipped RV-40E fan-hole case, and "
        "the curves behind it, are in <code>notebooks/what_drives_the_flexibility_effect.ipynb</code> and "
        "<code>docs/figures/tornado_rv40e_fanholes.png</code> of the rvfem repository.</p>")


def _case_rows(case: Case) -> list[list[str]]:
    c, p, k, b, mat, ld, an, ms = (case.cycloid, case.pins, case.cranks, case.crank_bearing, case.material,
                                   case.loads, case.analysis, case.mesh)
    rows = [
        ["cycloid", f"Zc = {c.teeth}, e = {c.eccentricity:g} mm, b = {c.thickness:g} mm, central hole r = "
                    f"{c.central_hole_radius:g} mm"],
        ["profile modification", f"ΔRrp = {c.modification.equidistant:g} mm, ΔRp = {c.modification.shift:g} mm, "
                                 f"rotation {c.modification.rotation_deg:g}°"],
        ["pins", f"Zp = {p.count}, Rp = {p.circle_radius:g} mm, r_rp = {p.radius:g} mm, model {p.model}"],
        ["cranks", f"N = {k.count} on r0 = {k.circle_radius:g} mm at {', '.join(f'{a:g}°' for a in k.angles_deg)}"],
        ["crank bearing", f"Z = {b.rollers}, D_we = {b.roller_diameter:g} mm, L_we = {b.roller_length:g} mm, "
                          f"D_m = {b.pitch_diameter:g} mm, bore r = {b.bore_radius:g} mm, clearance "
                          f"{b.radial_clearance:g} mm, b_m = {b.b_m:g}, λ_ν = {b.lambda_nu:g}"],
        ["material", f"{mat.name}: E = {mat.youngs_modulus:g} MPa, ν = {mat.poissons_ratio:g}"],
        ["loads", f"T_out = {ld.torque_Nm:g} N·m, {ld.speed_rpm:g} rpm output, {ld.discs} discs"
                  + (f", duty cycle of {len(ld.duty_cycle)} rows" if ld.duty_cycle else "")],
        ["analysis", f"angle step {an.angle_step_deg:g}°, P{an.element_order}, p = {an.equivalent_load_exponent:.4g}, "
                     f"saved angles {', '.join(f'{a:g}°' for a in an.saved_angles_deg)}"],
        ["mesh sizes", f"flank {ms.size_flank:g} mm, bore {ms.size_bore:g} mm, interior {ms.size_interior:g} mm, holes "
                       + (f"{ms.size_hole:g} mm" if ms.size_hole is not None else
                          f"{min(2 * ms.size_bore, ms.size_interior):g} mm (default: 2 × bore size)")],
    ]
    if case.fan_holes is not None:
        f = case.fan_holes
        span = f"span {f.span_deg:g}°" if f.span_deg is not None else f"ligament {f.ligament:g} mm"
        rows.append(["fan holes", f"{f.count}, r = {f.inner_radius:g}…{f.outer_radius:g} mm, {span}, fillet "
                                  f"{f.fillet_radius:g} mm"])
    if case.round_holes is not None:
        r = case.round_holes
        rows.append(["round holes", f"{r.count} × r = {r.radius:g} mm on r = {r.circle_radius:g} mm"])
    return [[_e(a), _e(v)] for a, v in rows]


def key_field_angles(summary: dict, case: Case) -> list[float]:
    """Crank angles (degrees) whose stress images the report embeds: the case's saved angles (the
    nearest kept field), the angle of the largest bearing load and the angles of the stress peaks.
    The images of further angles (``--field-step``) are linked: a report with every image of a
    10° step embedded weighs about 19 MB."""
    fields = [f["theta_deg"] for f in summary.get("fields", [])]
    wanted = [summary["max_bearing_load"]["theta_deg"]]
    st = summary["stress"]
    for entry in (st.get("structural_peak"), st.get("away_from_contacts"), st.get("contact_zone")):
        if entry:
            wanted.append(entry["at"]["theta_deg"])
    key = set()
    for a in wanted:
        key.add(round(a, 6))
    for a in case.analysis.saved_angles_deg:
        if fields:
            key.add(round(min(fields, key=lambda t: abs((t - a + 180.0) % 360.0 - 180.0)), 6))
    return sorted(key)


def _symmetry_sentence(m: dict) -> str:
    """How the mesh was built and how many crank angles were solved."""
    n = m.get("mesh_symmetry", 1)
    solved = m.get("angles_solved", m["angles"])
    mesh = (f"mesh exactly {n}-fold symmetric (one {360 / n:g}° sector copied by rotation)" if n > 1
            else "full-disc mesh")
    if solved < m["angles"]:
        return (f"{mesh}; {solved} of the {m['angles']} crank angles solved, the others follow from them "
                "by symmetry (exact);")
    return f"{mesh}; every crank angle solved;"


def _warnings_html(warnings: list[dict]) -> str:
    """The results outside their model's range (``summary["warnings"]``, :mod:`rvfem.evaluate.validity`),
    one line each in a box at the top of the report; nothing when there are none."""
    if not warnings:
        return ""
    return ("<div class='warnings'><h2>Warnings: results outside their model's range</h2><ul>"
            + "".join(f"<li><code>{_e(w['code'])}</code>: {_e(w['message'])}</li>" for w in warnings)
            + "</ul><p class='meta'>Limits and their sources: docs/outputs.md, \"Warnings\".</p></div>")


def write_report(path: str | os.PathLike, summary: dict, case: Case, root: str | os.PathLike) -> Path:
    """Write ``report.html``.

    Parameters
    ----------
    path : path-like
        The HTML file.
    summary : dict
        The ``summary.json`` content (numbers shown in the report).
    case : Case
        The case as analysed.
    root : path-like
        Folder the image paths in ``summary["images"]`` / ``summary["plots"]`` are relative to.

    Returns
    -------
    Path
    """
    path, root = Path(path), Path(root)
    c, m = summary["case"], summary["model"]
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>rvfem: {_e(c['name'])}</title>"
             f"<style>{_CSS}</style></head><body>"]
    parts.append(f"<h1>Crank-bearing loads with a flexible cycloid disc — {_e(c['name'])}</h1>")
    meta = [f"rvfem {_e(summary['rvfem_version'])}"]
    if c.get("file"):
        meta.append(f"case file <code>{_e(c['file'])}</code> (sha256 {_e(c['sha256'][:16])}…"
                    f"{'' if c['matches_file'] else ', modified'})")
    if c["overrides"]:
        meta.append("overrides: " + ", ".join(f"<code>{_e(k)} = {_e(toml_text(v))}</code>"
                                              for k, v in c["overrides"].items()))
    parts.append(f"<p class='meta'>{' · '.join(meta)}</p>")
    if c.get("description"):
        parts.append(f"<p>{_e(c['description'])}</p>")
    parts.append(f"<p class='meta'>Model: bearing model <b>{_e(m['bearing_model'])}</b>, P{m['element_order']} "
                 f"elements, {m['nodes']} nodes, {m['dofs']} dofs, {m['elements']} elements; {m['angles']} crank "
                 f"angles (step {m['angle_step_deg']:g}°); {_symmetry_sentence(m)} wall time "
                 f"{summary['timings_s']['total']:.1f} s.</p>")

    parts.append(_warnings_html(summary.get("warnings", [])))

    # -- results ---------------------------------------------------------------------------------
    refs = summary["references"]
    handbook = refs["bearing_loads"] == "handbook"
    ref_word = "rigid" if handbook else "equal-share"
    parts.append("<h2>Crank-bearing loads and lives: "
                 + ("rigid handbook" if handbook else "equal share of the FE pin resultant")
                 + " vs flexible disc</h2>")
    parts.append(_references_html(refs))
    rows, classes = [], []
    keys = ("rigid", "flexible") if handbook else ("rigid", "equal_share", "flexible")
    for b in summary["bearings"]:
        for key in keys:
            s = b[key]
            if s is None:
                rows.append([f"{b['bearing']}", key, "not defined for Zp − Zc ≠ 1"] + [""] * 9)
                classes.append("")
                continue
            rows.append([f"{b['bearing']}" if key == "rigid" else "", key, _num(s["max_load_N"], ".0f"),
                         _num(s["max_at_deg"]), _num(s["min_load_N"], ".0f"), _num(s["min_at_deg"]),
                         _num(s["equivalent_load_N"], ".0f"), _num(s["L10h_h"], ".0f"),
                         _num(b["delta_max_percent"], "+.1f") + " %" if key == "flexible" else "",
                         _num(b["delta_min_percent"], "+.1f") + " %" if key == "flexible" else "",
                         _num(b["delta_equivalent_percent"], "+.1f") + " %" if key == "flexible" else "",
                         _num(b["life_ratio"], ".3f") if key == "flexible" else ""])
            classes.append("flex" if key == "flexible" else "")
    parts.append(_table(["bearing", "model", "max N", "at °", "min N", "at °", "F_m N", "L10h h", "Δmax",
                         "Δmin", "ΔF_m", f"L_flex/L_{'rigid' if handbook else 'equal_share'}"], rows, left=2,
                        classes=classes))
    parts.append("<p class='meta'>Angles are crank angles θ (eccentric relative to the carrier). Deltas in % of "
                 f"the {ref_word} value. "
                 + ("The equal-share reference (FE pin resultant shared equally) is in summary.json.</p>"
                    if handbook else "</p>"))

    st = summary["stress"]
    sp, away, cz = st.get("structural_peak"), st.get("away_from_contacts"), st["contact_zone"]
    pins = summary["pins_in_contact"]
    other = []
    if sp:
        a_ = sp["at"]
        other += [
            ["<b>structural stress peak</b> (away from contacts, P2 re-solve)",
             f"<b>{sp['von_mises_MPa']:.1f} MPa</b> ± {sp['estimated_error_MPa']:.1f} MPa estimated "
             f"({sp['estimated_error_percent']:.1f} %), at ({a_['x_mm']:.2f}, {a_['y_mm']:.2f}) mm, {_where(a_)}, "
             f"θ = {a_['theta_deg']:g}°"],
            ["convergence check of the structural peak",
             f"P{away['element_order']} cycle {sp['p1_MPa']:.1f} MPa ({sp['p1_error_percent']:+.1f} % against P2); "
             f"P2 re-solved at θ = {', '.join(f'{x:g}' for x in sp['angles_deg'])}° in {sp['seconds']:.1f} s. "
             f"Method: {_e(sp['method'])}; the estimate is the spread of the P2 element stresses at the peak "
             "vertex around their average."],
        ]
    if away:
        other.append([f"structural peak of the P{away['element_order']} cycle's envelope",
                      f"{away['peak_von_mises_MPa']:.1f} MPa at ({away['at']['x_mm']:.2f}, {away['at']['y_mm']:.2f}) mm, "
                      f"{_where(away['at'])}, θ = {away['at']['theta_deg']:g}°"])
    other.append(["contact-zone peak (under a footprint, mesh-dependent)",
                  f"{cz['peak_von_mises_MPa']:.1f} MPa at ({cz['at']['x_mm']:.2f}, {cz['at']['y_mm']:.2f}) mm, "
                  f"{_where(cz['at'])}, θ = {cz['at']['theta_deg']:g}°; depends on the footprint width and the mesh, "
                  "not a Hertz stress"])
    mx = summary["max_bearing_load"]
    other += [
        ["largest bearing load", f"{mx['flexible_N']:.0f} N, bearing {mx['bearing']}, θ = {mx['theta_deg']:.1f}°"],
        ["pins in contact", f"{pins['min']}–{pins['max']} of {pins['of']} (mean {pins['mean']:.1f})"],
        ["torsional stiffness (per disc)", f"{summary['torsional_stiffness_Nm_per_arcmin']:.2f} N·m/arcmin"],
        ["carrier rotation", f"{summary['carrier_rotation_arcmin']['mean']:.3f} arcmin (mean)"],
        ["equilibrium residual (max)", f"{summary['equilibrium_residual']:.2e}"],
        ["active-set iterations", f"max {summary['active_set_iterations']['max']}, mean "
                                  f"{summary['active_set_iterations']['mean']:.1f}"],
    ]
    parts.append("<h2>Other results</h2>" + _table(["quantity", "value"], other, left=2))

    rows = [[r["step"] + (" (this run)" if r["final"] else ""), r["bearing"], _num(r["max_N"], ".0f"),
             _num(r["delta_max_percent"], "+.1f"), _num(r["min_N"], ".0f"), _num(r["delta_min_percent"], "+.1f"),
             _num(r["equivalent_N"], ".0f"), _num(r["delta_equivalent_percent"], "+.1f"), _num(r["life_ratio"], ".3f")]
            for r in summary["attribution"]]
    labels = dict.fromkeys((r["step"], r["label"]) for r in summary["attribution"])
    parts.append(
        "<h2>What the flexibility delta is made of</h2><p>Each step adds one modelling effect, on the same "
        "crank angles and the same disc model; deltas are against the "
        + ("handbook. " if handbook else "equal share (the handbook is not defined for Zp − Zc ≠ 1). ")
        + "; ".join(f"<b>{_e(k)}</b>: {_e(v)}" for k, v in labels) + ".</p>"
        + _table(["step", "bearing", "max N", "Δmax %", "min N", "Δmin %", "F_m N", "ΔF_m %", "life ratio"], rows))
    parts.append(_depends_on(summary, case))

    h = summary["hertz"]
    hrows = []
    for key, label in (("fe_rollers", "FE roller loads (largest)"), ("stribeck_rigid", "Stribeck, rigid F_max"),
                       ("stribeck_flexible", "Stribeck, FE F_max")):
        e = h.get(key)
        if not e:
            continue
        where = []
        if e.get("bearing"):
            where.append(f"bearing {e['bearing']}" + (f", roller {e['roller']}" if e.get("roller") else ""))
        if e.get("theta_deg") is not None:
            where.append(f"θ = {e['theta_deg']:.1f}°")
        hrows.append([_e(label), _e(", ".join(where)), _num(e["roller_load_N"], ".0f"),
                      _num(e["inner"]["peak_pressure_MPa"], ".0f"), _num(1000 * e["inner"]["half_width_mm"], ".1f"),
                      _num(e["outer"]["peak_pressure_MPa"], ".0f"), _num(1000 * e["outer"]["half_width_mm"], ".1f")])
    parts.append("<h2>Hertz pressure of the most loaded roller</h2>")
    parts.append(_table(["source", "where", "Q N", "p_inner MPa", "b_inner µm", "p_outer MPa", "b_outer µm"],
                        hrows, left=2))
    if "duty_cycle" in summary:
        d = summary["duty_cycle"]
        parts.append("<h3>Duty cycle (Palmgren–Miner)</h3>" + _table(
            ["model", "rated life h", "equivalent torque N·m", "equivalent speed rpm", "service life h"],
            [[k, _num(d[k]["rated_life_h"], ".0f"), _num(d[k]["equivalent_torque_Nm"]),
              _num(d[k]["equivalent_speed_rpm"], ".2f"), _num(d[k]["service_life_h"], ".0f")] if d[k] else
             [k, "not defined for Zp − Zc ≠ 1", "", "", ""] for k in ("rigid", "flexible")],
            left=1))
        parts.append("<p class='meta'>Both lives scale the rated life with (T_i/T0)^(10/3) (Gao et al. eq. 18): "
                     "they assume the bearing loads grow linearly with the torque.</p>")
        fe = d.get("flexible_fe")
        if fe:
            parts.append(
                "<p>Checked with the flexible model solved at every duty-cycle torque ("
                + ", ".join(f"{t:g}" for t in fe["torques_Nm"]) + " N·m): F_m differs from the linear scaling by "
                + ", ".join(f"{e:+.2f} %" for e in fe["linear_scaling_error_percent"])
                + f"; Palmgren–Miner over the rows with those loads gives a service life of "
                f"<b>{_num(fe['service_life_h'], '.0f')} h</b> ({_num(fe['life_difference_percent'], '+.1f')} % "
                f"against the linear scaling; {fe['seconds']:.1f} s).</p>")

    # -- plots and images ----------------------------------------------------------------------
    pl = summary.get("plots", {})
    parts.append("<h2>Plots</h2><div class='grid'>")
    parts.append(_figure(root, pl.get("bearing_loads"), "Bearing load over the crank angle: flexible (solid) "
                         + ("and rigid handbook (dashed)." if handbook else
                            "and the equal share of the FE pin resultant (dashed).")))
    parts.append(_figure(root, pl.get("pins_in_contact"), "Number of pins in contact over the crank angle."))
    parts.append(_figure(root, pl.get("pin_forces"), "Pin forces at the angle of the largest bearing load: FE vs "
                         + ("the classical rigid distribution." if refs["classical_pin_forces"]["defined"] else
                            "no rigid reference (the classical distribution is not defined for Zp − Zc ≠ 1).")))
    parts.append(_figure(root, pl.get("roller_loads"), "Roller loads at the angle of the largest bearing load."))
    parts.append("</div>")
    im = summary.get("images", {})
    if im:
        parts.append("<h2>Stress images</h2>")
        key = key_field_angles(summary, case)
        linked = []
        for f in summary.get("fields", []):
            if not f.get("image"):
                continue
            if any(math.isclose(f["theta_deg"], a, abs_tol=1e-6) for a in key):
                parts.append(_figure(root, f["image"], f"von Mises on the deformed disc at θ = {f['theta_deg']:.1f}° "
                                                       f"(ParaView: {f['vtu']})."))
            else:
                linked.append(f"<a href='{_e(f['image'])}'>{f['theta_deg']:g}°</a>")
        if linked:
            parts.append("<p class='meta'>Further stress images (<code>--field-step</code>), linked, not embedded, "
                         "to keep this file light: " + ", ".join(linked) + ".</p>")
        parts.append("<div class='grid'>")
        parts.append(_figure(root, im.get("stress_away_from_contacts_closeup"),
                             "Close-up at the structural peak away from the pin and roller contacts (ring)."))
        parts.append(_figure(root, im.get("stress_peak_closeup"),
                             "Close-up at the contact-zone peak (ring): mesh-dependent, under a footprint."))
        parts.append("</div>")
        parts.append(_figure(root, im.get("mesh"), "The mesh (linear triangles) and a close-up of the rim under bore 1."))

    # -- case and assumptions ------------------------------------------------------------------
    parts.append("<h2>Case parameters</h2>" + _table(["item", "value"], _case_rows(case), left=2))
    parts.append("<h2>Assumptions</h2><ul>" + "".join(f"<li>{a}</li>" for a in assumptions(summary, case)) + "</ul>")
    defaults = c.get("defaults_used") or {}
    if defaults:
        parts.append("<h3>Where the case file is silent (defaults used)</h3>" + _table(
            ["key", "value"], [[f"<code>{_e(k)}</code>", f"<code>{_e(toml_text(v))}</code>"]
                               for k, v in defaults.items()], left=2))
    elif not c.get("matches_file"):
        parts.append("<p class='meta'>The case was built or modified in code; case.json holds every value used.</p>")

    t = summary["timings_s"]
    parts.append("<h2>Files and timings</h2><p class='meta'>"
                 + ", ".join(f"<code>{_e(f)}</code>" for f in summary["files"]) + "</p><p class='meta'>"
                 + ", ".join(f"{_e(k)} {v:.2f} s" for k, v in t.items() if isinstance(v, (int, float))) + "</p>")
    parts.append("</body></html>\n")
    path.write_text("\n".join(p for p in parts if p), encoding="utf-8")
    return path
