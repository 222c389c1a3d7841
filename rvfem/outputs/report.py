"""The HTML report of a run: one self-contained file (styles inline, images embedded as base64).

It is written from the ``summary.json`` content, so the report and the JSON always show the same
numbers, plus the case (its parameters) and the PNG files of the run. The page is the Jinja2
template ``templates/report.html.j2`` (autoescape on: every value is shown as text); this module
prepares its context, a plain dict of texts, tables and figures (:func:`report_context`). The
writer that calls it is :func:`rvfem.outputs.summary.write_report`; the formulas behind the
assumptions listed are in docs/theory.md.

A text of the context is a string or, where a word is bold, code or a link, a list of parts:
strings, ``{"b": text}``, ``{"code": text}`` and ``{"href": address, "text": text}``. A table is
``{"header": [...], "left": n, "rows": [{"cells": [...], "kind": ""}]}`` (the first ``n`` columns
left-aligned; ``kind`` ``"flex"`` shades the row of the flexible disc).
"""

from __future__ import annotations

import base64
import functools
import math
import os
from pathlib import Path
from typing import Any

import jinja2

import rvfem.geometry  # noqa: F401  (registers the hole shapes Case.hole_shapes looks up)
from rvfem.case.definition import ROLLER_PROFILE_KINDS, Case
from rvfem.case.schema import file_fields, format_quantity
from rvfem.evaluate.rigid import REFERENCE_NAMES
from rvfem.results.bearing_checks import bearing_check_lines
from rvfem.results.registry import sections
from rvfem.results.format import toml_text
from rvfem.results.mass_strength import mass_strength_report
from rvfem.solve.models import bearing_model, pin_model
from rvfem.units import nm_from_nmm

__all__ = ["TEMPLATE", "assumptions", "key_field_angles", "png_data_uri", "render_report", "report_context",
           "template_environment", "toml_text", "write_report"]

TEMPLATE = "report.html.j2"
"""The report's template, in the folder ``templates`` of this package (shipped as package data)."""


def key_field_angles(summary: dict, case: Case) -> list[float]:
    """Crank angles (degrees) whose stress images the report embeds: the case's saved angles (the
    nearest kept field), the angle of the largest bearing load and the angles of the stress peaks.
    The images of further angles (``--field-step``) are linked: a report with every image of a
    10° step embedded weighs about 19 MB."""
    fields: list[float] = [f["theta_deg"] for f in summary.get("fields", [])]
    wanted = [summary["max_bearing_load"]["theta_deg"]]
    st = summary["stress"]
    for entry in (st.get("structural_peak"), st.get("away_from_contacts"), st.get("contact_zone")):
        if entry:
            wanted.append(entry["at"]["theta_deg"])
    key: set[float] = set()
    for a in wanted:
        key.add(round(a, 6))
    for a in case.analysis.saved_angles_deg:
        if fields:
            nearest = min(fields, key=lambda t: abs((t - a + 180.0) % 360.0 - 180.0))
            key.add(round(nearest, 6))
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


# --------------------------------------------------------------------------------------------
# Pieces of the context: texts with bold words, code and links; tables; figures
# --------------------------------------------------------------------------------------------


def _b(text: Any) -> dict:
    return {"b": str(text)}


def _code(text: Any) -> dict:
    return {"code": str(text)}


def _joined(parts: list, separator: str = ", ") -> list:
    """``parts`` with ``separator`` between them (a text of parts)."""
    out: list = []
    for i, part in enumerate(parts):
        out += [separator, part] if i else [part]
    return out


def _table(header: list[str], rows: list[list[Any]], left: int = 1, kinds: list[str] | None = None) -> dict:
    return {"header": list(header), "left": left,
            "rows": [{"cells": list(row), "kind": kinds[r] if kinds else ""} for r, row in enumerate(rows)]}


def _num(v: Any, fmt: str = ".1f") -> str:
    if v is None:
        return "–"
    if isinstance(v, float) and not math.isfinite(v):
        return "–"
    if isinstance(v, (int, float)):
        return format(v, fmt)
    return str(v)


def _figure(root: Path, rel: str | None, caption: str) -> dict | None:
    """The PNG file ``root/rel`` as a data URI with its caption; None if there is none."""
    if not rel or not (root / rel).is_file():
        return None
    return {"src": png_data_uri(root / rel), "caption": caption}


def png_data_uri(path: str | os.PathLike) -> str:
    """The PNG file ``path`` as a ``data:`` URI, to embed it in a self-contained page."""
    return "data:image/png;base64," + base64.b64encode(Path(path).read_bytes()).decode("ascii")


def _where(at: dict) -> str:
    d = at["distance_to_feature_mm"]
    label = at["feature_label"]
    return f"on the {label}" if d < 1e-6 else f"{d:.2f} mm from the {label}"


# --------------------------------------------------------------------------------------------
# Assumptions
# --------------------------------------------------------------------------------------------


def _bearing_assumption(m: dict, case: Case) -> list:
    """The crank-bearing model (each model states its own assumptions: rvfem.solve.models)."""
    text = ["Crank bearings: bearing model ", _b(m["bearing_model"]),
            f" — {bearing_model(m['bearing_model'])(case).describe()}."]
    if m["bearing_model"] != "rollers":
        text.append(" No discrete rollers, so no FE roller loads; Hertz only from the Stribeck estimate.")
    return text


def _pin_assumption(m: dict, case: Case) -> str:
    try:
        pin = pin_model(m["pin_model"])(case).describe()
    except Exception:   # a validation-only pin model needs its stiffness: name it only
        pin = f"pin model {m['pin_model']}"
    return f"Pins: {pin}; " + (f"Coulomb friction μ = {case.analysis.friction:g} along the sliding direction."
                               if case.analysis.friction > 0 else "no friction (μ = 0).")


def _stage_assumption(summary: dict) -> list:
    """The reducer stage: how the torque divides between the discs, and the crank support."""
    m, rs = summary["model"], summary["reducer_stage"]
    share = rs["torque_share"]
    text = ["Reducer stage: ", _b(rs["model"]), ". "]
    if share:
        text.append("Disc A is solved at θ together with disc B at θ + 180°; one carrier rotation, so the output "
                    f"torque divides between the discs by their stiffness (disc A carries {share['min']:.3f}–"
                    f"{share['max']:.3f} × T/2 over the cycle). ")
    else:
        text.append(f"Each of the {m['discs']} discs carries T_disc = T_out/{m['discs']} = "
                    f"{nm_from_nmm(m['disc_torque_Nmm']):g} N·m (the handbook's equal share). ")
    if rs["crank_support_rigid"]:
        return text + ["The eccentrics are rigid: the flexibility effect reported is an ", _b("upper bound"), "."]
    return text + ["Each crankshaft is a beam on two elastic support bearings (case table crank_support) carrying "
                   "both discs' eccentrics; the eccentrics move relative to the carrier by its influence matrix "
                   "times the bearing forces."]


def _reference_assumption(m: dict, handbook: bool) -> str:
    """The rigid reference the run is compared with."""
    if handbook:
        text = ("Rigid reference: the handbook model (Gao et al., eqs. 4-10; rigid disc, rigid bearings, equal load "
                f"sharing, pin-force resultant ratio k_y = {m['handbook_k_y']:.3f}), evaluated at the same crank "
                "angles. ")
    else:
        text = ("Rigid reference: the equal share of the FE pin resultant (rigid disc on rigid, equally loaded "
                "eccentrics); the handbook model is not defined for Zp − Zc ≠ 1. ")
    return text + f"The FE pin-force resultant ratio |P_y/P_x| comes out {m['fe_pin_resultant_ratio']:.3f} on average."


def _life_and_hertz_assumptions(summary: dict, handbook: bool) -> list[str]:
    m = summary["model"]
    return [
        f"Life: ISO 281 dynamic load rating C = {m['dynamic_load_rating_N']:.0f} N, equivalent load "
        f"F_m = (mean F^p)^(1/p) with p = {m['equivalent_load_exponent']:.4g} over a uniformly sampled turn, "
        f"L10h = 10⁶/(60·n_b)·(C/F_m)^(10/3), bearing speed n_b = {m['bearing_speed_rpm']:g} rpm; life ratio "
        + ("= L_flex/L_rigid." if handbook else "= L_flex/L_equal_share."),
        "Hertz: line contact of the most loaded roller (the largest roller load over the cycle, every bearing and "
        "roller) on the eccentric (convex, inner) and in the bore (concave, outer): from the FE roller loads and "
        f"from {summary['hertz'].get('rigid_roller_model', 'rigid rings')} "
        + ("under the rigid (handbook) and the FE bearing loads" if handbook else
           "under the FE bearing loads (no handbook load for Zp − Zc ≠ 1)")
        + "; Q_max·Z/F is its k in Stribeck's Q_max = k·F/Z (4.08 for zero clearance, many rollers).",
    ]


def _stress_assumption(stress: dict) -> str:
    """How the stresses are recovered, and the bands the structural peak leaves out."""
    away = stress.get("away_from_contacts")
    if not away:
        return "Stresses: vertex values are area-weighted averages of the adjacent element stresses."
    return ("Stresses: vertex values are area-weighted averages of the adjacent element stresses. Pin and roller "
            "forces are spread over a footprint of about 1.5 elements, so the stress right under a contact depends "
            "on the mesh and is not the Hertz contact stress (see the Hertz table for that); the \"away from "
            f"contacts\" peak ignores a band of {away['profile_band_mm']:.2g} mm along the profile and "
            f"{away['bore_band_mm']:.2g} mm along the bores. Both stress peaks are searched over every solved crank "
            "angle (the cycle's von Mises envelope), and their fields are kept. The structural peak is then "
            "re-solved on P2 elements of the same mesh, loaded with the cycle's converged contact and roller forces "
            "at the crank angles where the P1 peak lies: P1 vertex stresses lie low at a free edge (about 15 % on "
            "the default case); its estimated error is the spread of the P2 element stresses at the peak vertex "
            "around their average.")


def assumptions(summary: dict, case: Case) -> list[str | list]:
    """The modelling assumptions of a run, as sentences: each a text, or a list of parts where a
    word is bold (see the module's docstring)."""

    m = summary["model"]
    handbook = summary["references"]["bearing_loads"] == "handbook"
    overrides = summary["case"].get("overrides") or {}
    stated: list[str | list] = ([f"Values set on top of the case file (overrides): "
               f"{', '.join(f'{k} = {toml_text(v)}' for k, v in overrides.items())}; case.json holds every "
               "value used."]
              if overrides else [])
    return stated + [
        f"2D plane-stress finite-element model of one cycloid disc (thickness {case.cycloid.thickness:g} mm, "
        f"E = {case.material.youngs_modulus:g} MPa, ν = {case.material.poissons_ratio:g}), "
        f"P{m['element_order']} triangles; the disc stiffness is factorised once and each crank angle is "
        "solved on the condensed contact and roller unknowns.",
        _stage_assumption(summary),
        ["Torque convention: the carrier (the output) turns about the ", _b("reducer axis"), " and carries the "
         "output torque; a disc's pin forces have the moment T/discs about that axis, Zc/Zp of it about the disc "
         "centre. The handbook's ΣP_x = T/(2·e·Zc) takes T/2 about the disc centre: its loads are Zp/Zc "
         f"({100 * (case.pins.count / case.cycloid.teeth - 1):.1f} % here) above a rigid disc's under this convention."],
        _pin_assumption(m, case),
        _bearing_assumption(m, case),
        "Carrier: one rigid body that only rotates, about the reducer axis; its rotation is the unknown conjugate to "
        "the output torque (torsional stiffness = T_disc / rotation, mean over the cycle).",
        _reference_assumption(m, handbook),
        *_life_and_hertz_assumptions(summary, handbook),
        _stress_assumption(summary["stress"]),
        "Images: deformation with the disc's rigid-body motion removed, magnified by the factor written on the "
        "image; pins drawn at their nominal positions at that angle (dark: in contact).",
    ]


# --------------------------------------------------------------------------------------------
# Sections of the report
# --------------------------------------------------------------------------------------------


def _head(summary: dict) -> dict:
    """The title, the line of provenance (version, case file, overrides) and the model line."""
    c, m = summary["case"], summary["model"]
    meta: list = [f"rvfem {summary['rvfem_version']}"]
    if c.get("file"):
        meta.append(["case file ", _code(c["file"]),
                     f" (sha256 {c['sha256'][:16]}…{'' if c['matches_file'] else ', modified'})"])
    if c["overrides"]:
        meta.append(["overrides: ", *_joined([_code(f"{k} = {toml_text(v)}") for k, v in c["overrides"].items()])])
    details = (f"P{m['element_order']} elements, {m['nodes']} nodes, {m['dofs']} dofs, {m['elements']} elements; "
               f"{m['angles']} crank angles (step {m['angle_step_deg']:g}°); {_symmetry_sentence(m)} wall time "
               f"{summary['timings_s']['total']:.1f} s.")
    return {"name": c["name"], "meta": meta, "description": c.get("description") or "",
            "model": {"bearing_model": m["bearing_model"], "details": details},
            "warnings": [{"code": w["code"], "message": w["message"]} for w in summary.get("warnings", [])]}


def _bearing_row(b: dict, key: str) -> list:
    """One row of the bearing table: the loads of ``b`` by the model ``key``, with the deltas in the
    row of the flexible disc."""
    s = b[key]
    if s is None:
        return [f"{b['bearing']}", key, "not defined for Zp − Zc ≠ 1"] + [""] * 9
    deltas = [""] * 4
    if key == "flexible":
        deltas = [_num(b[d], "+.1f") + " %" for d in ("delta_max_percent", "delta_min_percent",
                                                        "delta_equivalent_percent")] + [_num(b["life_ratio"], ".3f")]
    return [f"{b['bearing']}" if key == "rigid" else "", key, _num(s["max_load_N"], ".0f"), _num(s["max_at_deg"]),
            _num(s["min_load_N"], ".0f"), _num(s["min_at_deg"]), _num(s["equivalent_load_N"], ".0f"),
            _num(s["L10h_h"], ".0f"), *deltas]


def _loads(summary: dict) -> dict:
    """The bearing loads and lives against the reference, and which references the run uses and why."""
    refs = summary["references"]
    main = refs["bearing_loads"]
    handbook = main == "handbook"
    references = []
    for key, r in refs.items():
        if not isinstance(r, dict):
            continue
        state = ([_b("compared with (deltas)")] if key == main else "compared with") if r["defined"] else \
            [_b("not used")]
        references.append({"name": REFERENCE_NAMES[key], "state": state, "why": r["why"]})
    rows, kinds = [], []
    for b in summary["bearings"]:
        for key in ("rigid", "flexible") if handbook else ("rigid", "equal_share", "flexible"):
            rows.append(_bearing_row(b, key))
            kinds.append("flex" if key == "flexible" and b[key] is not None else "")
    header = ["bearing", "model", "max N", "at °", "min N", "at °", "F_m N", "L10h h", "Δmax", "Δmin", "ΔF_m",
              f"L_flex/L_{'rigid' if handbook else 'equal_share'}"]
    return {"reference": REFERENCE_NAMES[main], "references": references,
            "table": _table(header, rows, left=2, kinds=kinds)}


def _stress_rows(stress: dict) -> list[list]:
    """The rows of the stress peaks: structural (P2 re-solve, with its convergence check), the P1
    envelope's, the contact zone's."""
    sp, away, cz = stress.get("structural_peak"), stress.get("away_from_contacts"), stress["contact_zone"]
    rows: list[list] = []
    if sp:
        assert away is not None   # a structural peak comes with the cycle's envelope
        a_ = sp["at"]
        rows += [
            [[_b("structural stress peak"), " (away from contacts, P2 re-solve)"],
             [_b(f"{sp['von_mises_MPa']:.1f} MPa"), f" ± {sp['estimated_error_MPa']:.1f} MPa estimated "
              f"({sp['estimated_error_percent']:.1f} %), at ({a_['x_mm']:.2f}, {a_['y_mm']:.2f}) mm, {_where(a_)}, "
              f"θ = {a_['theta_deg']:g}°"]],
            ["convergence check of the structural peak",
             f"P{away['element_order']} cycle {sp['p1_MPa']:.1f} MPa ({sp['p1_error_percent']:+.1f} % against P2); "
             f"P2 re-solved at θ = {', '.join(f'{x:g}' for x in sp['angles_deg'])}° in {sp['seconds']:.1f} s. "
             f"Method: {sp['method']}; the estimate is the spread of the P2 element stresses at the peak "
             "vertex around their average."],
        ]
    if away:
        rows.append([f"structural peak of the P{away['element_order']} cycle's envelope",
                     f"{away['peak_von_mises_MPa']:.1f} MPa at ({away['at']['x_mm']:.2f}, {away['at']['y_mm']:.2f}) "
                     f"mm, {_where(away['at'])}, θ = {away['at']['theta_deg']:g}°"])
    rows.append(["contact-zone peak (under a footprint, mesh-dependent)",
                 f"{cz['peak_von_mises_MPa']:.1f} MPa at ({cz['at']['x_mm']:.2f}, {cz['at']['y_mm']:.2f}) mm, "
                 f"{_where(cz['at'])}, θ = {cz['at']['theta_deg']:g}°; depends on the footprint width and the mesh, "
                 "not a Hertz stress"])
    return rows


def _other_results(summary: dict) -> dict:
    """The table "Other results": stress peaks, largest load, pins in contact, stiffness, solver,
    then the rows of every result section that has some (:attr:`rvfem.results.section.Section.report`:
    the accuracy, and those of sections from outside rvfem)."""
    mx, pins = summary["max_bearing_load"], summary["pins_in_contact"]
    rows = _stress_rows(summary["stress"]) + [
        ["largest bearing load", f"{mx['flexible_N']:.0f} N, bearing {mx['bearing']}, θ = {mx['theta_deg']:.1f}°"],
        ["pins in contact", f"{pins['min']}–{pins['max']} of {pins['of']} (mean {pins['mean']:.1f})"],
        ["disc torque / mean carrier rotation (per disc)",
         f"{summary['torsional_stiffness_Nm_per_arcmin']:.2f} N·m/arcmin"],
        ["carrier rotation", f"{summary['carrier_rotation_arcmin']['mean']:.3f} arcmin (mean)"],
        ["equilibrium residual (max)", f"{summary['equilibrium_residual']:.2e}"],
        ["active-set iterations", f"max {summary['active_set_iterations']['max']}, mean "
                                  f"{summary['active_set_iterations']['mean']:.1f}"],
    ]
    rows += [row for section in sections() if section.report is not None for row in section.report(summary)]
    return _table(["quantity", "value"], rows, left=2)


def _attribution(summary: dict) -> dict:
    """The steps the flexibility delta is made of, one row per step and bearing."""
    rows = [[r["step"] + (" (this run)" if r["final"] else ""), f"{r['bearing']}", _num(r["max_N"], ".0f"),
             _num(r["delta_max_percent"], "+.1f"), _num(r["min_N"], ".0f"), _num(r["delta_min_percent"], "+.1f"),
             _num(r["equivalent_N"], ".0f"), _num(r["delta_equivalent_percent"], "+.1f"), _num(r["life_ratio"], ".3f")]
            for r in summary["attribution"]]
    labels = dict.fromkeys((r["step"], r["label"]) for r in summary["attribution"])
    return {"steps": [{"step": step, "label": label} for step, label in labels],
            "table": _table(["step", "bearing", "max N", "Δmax %", "min N", "Δmin %", "F_m N", "ΔF_m %",
                             "life ratio"], rows)}


def clearance_text(radial_clearance: float) -> str:
    """The crank bearing's play in words: a radial clearance (every roller open by half of it at
    zero load), a preload (a negative clearance: every roller compressed by half of it) or none."""
    if radial_clearance > 0:
        return f"radial clearance {radial_clearance * 1000:g} µm"
    if radial_clearance < 0:
        return f"preload {-radial_clearance * 1000:g} µm (negative radial clearance: every roller compressed at zero load)"
    return "no radial clearance and no preload"


def _depends_on(summary: dict, case: Case) -> str:
    """This run's modelling choices, for the section "What this delta depends on" (the measured
    sensitivity of the shipped fan-hole case is in notebooks/what_drives_the_flexibility_effect.ipynb)."""
    m, rs = summary["model"], summary["reducer_stage"]
    b, mod = case.crank_bearing, case.cycloid.modification
    law = b.stiffness_law if b.model == "rollers" else "isotropic spring"
    return (f"{rs['model']}; bearing model {m['bearing_model']} ({law}), {clearance_text(b.radial_clearance)}; "
            f"pin model {m['pin_model']}, friction μ = {case.analysis.friction:g}; "
            f"profile modification ΔRrp = {mod.equidistant:g} mm, ΔRp = {mod.shift:g} mm")


def _hertz(summary: dict) -> dict:
    """The Hertz pressures of the most loaded roller, from the FE roller loads and from Stribeck."""
    h = summary["hertz"]
    rows = []
    for key, label in (("fe_rollers", "FE roller loads (largest)"), ("stribeck_rigid", "rigid rings, handbook loads"),
                       ("stribeck_flexible", "rigid rings, FE bearing loads")):
        e = h.get(key)
        if not e:
            continue
        where = []
        if e.get("bearing"):
            where.append(f"bearing {e['bearing']}" + (f", roller {e['roller']}" if e.get("roller") else ""))
        if e.get("theta_deg") is not None:
            where.append(f"θ = {e['theta_deg']:.1f}°")
        rows.append([label, ", ".join(where), _num(e["roller_load_N"], ".0f"), _num(e.get("factor"), ".2f"),
                     _num(e["inner"]["peak_pressure_MPa"], ".0f"), _num(1000 * e["inner"]["half_width_mm"], ".1f"),
                     _num(e["outer"]["peak_pressure_MPa"], ".0f"), _num(1000 * e["outer"]["half_width_mm"], ".1f")])
    return _table(["source", "where", "Q_max N", "Q_max·Z/F", "p_inner MPa", "b_inner µm", "p_outer MPa", "b_outer µm"], rows, left=2)


def _roller_depth(summary: dict) -> dict | None:
    """The crank bearing in depth: per bearing and load model the pressure along the roller, film,
    κ, a_ISO and the three lives, and the flexible/rigid life ratios; None without FE rollers."""
    d = summary.get("crank_bearing_depth")
    if not d:
        return None
    rows = []
    for b in d["bearings"]:
        for model in ("rigid", "flexible"):
            e = b[model]
            if e is None:
                continue
            rows.append([f"bearing {b['bearing']}", model,
                         f"{_num(e.get('max_roller_load_N'), '.0f')} (θ = {_num(e.get('max_roller_theta_deg'), '.0f')}°)",
                         _num(e["roller_peak_pressure_MPa"], ".0f"),
                         _num(e["roller_edge_factor"], ".2f"), f"{e['peak_raceway']}, θ = {e['peak_theta_deg']:.0f}°",
                         _num(e["max_shear_MPa"], ".0f"), _num(1000 * e["max_shear_depth_mm"], ".0f"),
                         _num(e["film_thickness_min_um"], ".3f"), _num(e["kappa"], ".2f"), _num(e["a_iso"], ".2f"),
                         _num(e["L10h_h"], ".0f"), _num(e["L_nm_h"], ".0f"), _num(e["L10r_h"], ".0f")])
        if b["rigid"] is not None:
            rows.append([f"bearing {b['bearing']}", "flexible/rigid", "", "", "", "", "", "", "", "", "",
                         _num(b["L10h_ratio"], ".2f"), _num(b["L_nm_ratio"], ".2f"), _num(b["L10r_ratio"], ".2f")])
    table = _table(["bearing", "loads", "Q_max N", "p_max MPa", "edge factor", "where", "τ_max MPa", "depth µm", "h_min µm",
                    "κ", "a_ISO", "L10h h", "L_nm h", "L10r h"], rows, left=2)
    return {"table": table, "profile": d["profile"], "slices": d["slices"],
            "slope": _num(d["max_slope_mrad"], ".3f"), "rigid_tilt": _rigid_tilt_words(d)}


def _rigid_tilt_words(d: dict) -> str:
    """How the rigid slice model's rollers are tilted, from the tilts it used: the rigid model has
    no crankshaft slope, so only the case's misalignment (``crank_bearing.profile.misalignment_mrad``)
    tilts them."""
    tilts = [abs(b["rigid"]["peak_tilt_mrad"]) for b in d["bearings"]
             if b["rigid"] is not None and b["rigid"].get("peak_tilt_mrad") is not None]
    if not tilts or max(tilts) < 1e-9:
        return "untilted"
    return (f"tilted only by the case's misalignment (crank_bearing.profile.misalignment_mrad; up to "
            f"{max(tilts):.2f} mrad at the pressure peak)")


def _bearing_checks(summary: dict) -> list[str]:
    """Static safety, minimum load and support bearings as report lines (the screen's lines)."""
    return [line.strip() for line in bearing_check_lines(summary.get("bearing_checks"))]


def _duty_cycle(summary: dict) -> dict | None:
    """The duty-cycle lives (Palmgren–Miner) and their check by the flexible model at every torque;
    None without a duty cycle."""
    if "duty_cycle" not in summary:
        return None
    d = summary["duty_cycle"]
    rows = [[k, _num(d[k]["rated_life_h"], ".0f"), _num(d[k]["equivalent_torque_Nm"]),
             _num(d[k]["equivalent_speed_rpm"], ".2f"), _num(d[k]["service_life_h"], ".0f")] if d[k] else
            [k, "not defined for Zp − Zc ≠ 1", "", "", ""] for k in ("rigid", "flexible")]
    fe = d.get("flexible_fe")
    if fe:
        fe = {"torques": ", ".join(f"{t:g}" for t in fe["torques_Nm"]),
              "errors": ", ".join(f"{e:+.2f} %" for e in fe["linear_scaling_error_percent"]),
              "service_life": _num(fe["service_life_h"], ".0f"), "difference": _num(fe["life_difference_percent"], "+.1f"),
              "seconds": f"{fe['seconds']:.1f}"}
    return {"table": _table(["model", "rated life h", "equivalent torque N·m", "equivalent speed rpm",
                             "service life h"], rows, left=1), "fe": fe or None}


def _plots(summary: dict, root: Path) -> list[dict]:
    """The plots of the run, embedded, with their captions."""
    pl, refs = summary.get("plots", {}), summary["references"]
    handbook = refs["bearing_loads"] == "handbook"
    figures = [
        _figure(root, pl.get("bearing_loads"), "Bearing load over the crank angle: flexible (solid) "
                + ("and rigid handbook (dashed)." if handbook else
                   "and the equal share of the FE pin resultant (dashed).")),
        _figure(root, pl.get("pins_in_contact"), "Number of pins in contact over the crank angle."),
        _figure(root, pl.get("pin_forces"), "Pin forces at the angle of the largest bearing load: FE vs "
                + ("the classical rigid distribution." if refs["classical_pin_forces"]["defined"] else
                   "no rigid reference (the classical distribution is not defined for Zp − Zc ≠ 1).")),
        _figure(root, pl.get("roller_loads"), "Roller loads at the angle of the largest bearing load."),
        _figure(root, pl.get("roller_pressure"), "Pressure along the roller of the highest contact pressure of "
                "every bearing over the cycle (slice model; its load Q in the legend, which can be a little below the "
                "most loaded roller's when the crankshaft's tilt moves the peak): flexible (solid) and rigid (dashed)."),
        _figure(root, pl.get("roller_damage"), "Lamina damage per mm along the eccentric and the bore of every "
                "bearing (ISO/TS 16281 laminae, Palmgren–Miner over the cycle; roller_damage.csv): where spalling is "
                "likeliest to start. Flexible (solid) and rigid (dashed)."),
    ]
    return [f for f in figures if f]


def _images(summary: dict, case: Case, root: Path) -> dict | None:
    """The stress images: those of the key angles embedded (:func:`key_field_angles`), the others
    linked; the close-ups and the mesh. None if the run drew no images."""
    im = summary.get("images", {})
    if not im:
        return None
    key = key_field_angles(summary, case)
    fields, linked = [], []
    for f in summary.get("fields", []):
        if not f.get("image"):
            continue
        if any(math.isclose(f["theta_deg"], a, abs_tol=1e-6) for a in key):
            fields.append(_figure(root, f["image"], f"von Mises on the deformed disc at θ = {f['theta_deg']:.1f}° "
                                                    f"(ParaView: {f['vtu']})."))
        else:
            linked.append({"href": f["image"], "text": f"{f['theta_deg']:g}°"})
    closeups = [
        _figure(root, im.get("stress_away_from_contacts_closeup"),
                "Close-up at the structural peak away from the pin and roller contacts (ring)."),
        _figure(root, im.get("stress_peak_closeup"),
                "Close-up at the contact-zone peak (ring): mesh-dependent, under a footprint."),
    ]
    return {"fields": [f for f in fields if f], "linked": linked, "closeups": [f for f in closeups if f],
            "mesh": _figure(root, im.get("mesh"), "The mesh (linear triangles) and a close-up of the rim under bore 1.")}


_PROFILE_KEYS = {kind: ("kind", *keys, "misalignment_mrad", "slices") for kind, keys in ROLLER_PROFILE_KINDS.items()}
"""The keys of ``[crank_bearing.profile]`` each kind uses (the others do not enter its drop)."""


def _table_text(table, keys: tuple[str, ...] | None = None) -> str:
    """A case table's keys with their values and units (``span = 33 mm, shear = true``), those set
    (not None) and, with ``keys``, only those."""
    parts = []
    for spec in file_fields(type(table)):
        value = getattr(table, spec.name)
        if value is None or (keys is not None and spec.name not in keys):
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            text = toml_text(value)
        else:
            text = format_quantity(value, spec.param.unit)
        parts.append(f"{spec.name} = {text}")
    return ", ".join(parts)


def _case_rows(case: Case) -> list[list[str]]:
    """The case's parameters, one row per table (the hole shapes describe their own tables)."""
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
                          f"D_m = {b.pitch_diameter:g} mm, bore r = {b.bore_radius:g} mm, "
                          f"{clearance_text(b.radial_clearance)}, b_m = {b.b_m:g}, λ_ν = {b.lambda_nu:g}"],
        ["material", f"{mat.name}: E = {mat.youngs_modulus:g} MPa, ν = {mat.poissons_ratio:g}"],
        ["loads", f"T_out = {ld.torque_Nm:g} N·m, {ld.speed_rpm:g} rpm output, {ld.discs} discs"
                  + (f", duty cycle of {len(ld.duty_cycle)} rows" if ld.duty_cycle else "")],
        ["crank-bearing roller profile", _table_text(b.profile, _PROFILE_KEYS.get(b.profile.kind))],
        ["crank support (crankshaft as a beam)", _table_text(case.crank_support)
         if case.crank_support is not None else "none: rigid eccentrics (the crankshafts' flexibility left out)"],
        ["lubricant", _table_text(case.lubricant) if getattr(case, "lubricant", None) is not None else "none"],
        ["analysis", f"angle step {an.angle_step_deg:g}°, P{an.element_order}, p = {an.equivalent_load_exponent:.4g}, "
                     f"pin friction μ = {an.friction:g}, saved angles {', '.join(f'{a:g}°' for a in an.saved_angles_deg)}"],
        ["mesh sizes", f"flank {ms.size_flank:g} mm, bore {ms.size_bore:g} mm, interior {ms.size_interior:g} mm, holes "
                       + (f"{ms.size_hole:g} mm" if ms.size_hole is not None else
                          f"{min(2 * ms.size_bore, ms.size_interior):g} mm (default: 2 × bore size)")],
    ]
    for shape, table in case.hole_shapes():
        rows.append([shape.label, shape.describe(table)])
    return rows


def _case_section(summary: dict, case: Case) -> dict:
    """The case's parameters, the assumptions and the defaults the case file left."""
    c = summary["case"]
    defaults = c.get("defaults_used") or {}
    return {
        "case_rows": _table(["item", "value"], _case_rows(case), left=2),
        "assumptions": assumptions(summary, case),
        "defaults": _table(["key", "value"], [[[_code(k)], [_code(toml_text(v))]] for k, v in defaults.items()],
                           left=2) if defaults else None,
        "built_in_code": not c.get("matches_file"),
    }


# --------------------------------------------------------------------------------------------
# The report
# --------------------------------------------------------------------------------------------


def report_context(summary: dict, case: Case, root: str | os.PathLike) -> dict:
    """The context of the report's template: plain texts, tables and figures (see the module's
    docstring), from the ``summary.json`` content, the case and the PNG files under ``root``."""
    root = Path(root)
    t = summary["timings_s"]
    return {
        **_head(summary),
        "handbook": summary["references"]["bearing_loads"] == "handbook",
        "loads": _loads(summary),
        "other": _other_results(summary),
        "attribution": _attribution(summary),
        "depends_on": _depends_on(summary, case),
        "hertz": _hertz(summary),
        "roller_depth": _roller_depth(summary),
        "bearing_checks": _bearing_checks(summary),
        "mass_strength": mass_strength_report(summary),
        "duty_cycle": _duty_cycle(summary),
        "plots": _plots(summary, root),
        "images": _images(summary, case, root),
        **_case_section(summary, case),
        "files": list(summary["files"]),
        "timings": [f"{k} {v:.2f} s" for k, v in t.items() if isinstance(v, (int, float))],
    }


@functools.lru_cache(maxsize=1)
def template_environment() -> jinja2.Environment:
    """The one Jinja environment of rvfem's HTML pages: the templates of this package (found in an
    installed package as in a source checkout) — the run's report and the pages of a study, an
    optimisation and a comparison — every value escaped."""
    return jinja2.Environment(loader=jinja2.PackageLoader("rvfem.outputs", "templates"), autoescape=True,
                              undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True,
                              keep_trailing_newline=True)


def render_report(context: dict) -> str:
    """The HTML of the report for a :func:`report_context`."""
    return template_environment().get_template(TEMPLATE).render(context)


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
    path = Path(path)
    path.write_text(render_report(report_context(summary, case, root)), encoding="utf-8")
    return path
