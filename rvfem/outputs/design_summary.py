"""The mass-and-strength piece of ``summary.json`` (:data:`rvfem.outputs.summary.SUMMARY_PIECES`).

Top-level keys scripts can rely on: ``disc_mass_kg``, ``disc_polar_inertia_kg_mm2``,
``static_safety_factor``, ``fatigue_safety_factor`` and ``fatigue_safety_factor_at`` (the hot spot
with the smallest factor), and the details under ``mass_strength`` (docs/outputs.md).
"""

from __future__ import annotations

import math
from typing import Any

from rvfem.evaluate.design_checks import DesignChecks, design_checks, finite_or_none
from rvfem.evaluate.postprocess import PeakStress, feature_label, user_feature_label, user_feature_name
from rvfem.evaluate.strength import FATIGUE_CRITERION, fatigue_field

__all__ = ["piece_mass_strength", "mass_strength_dict", "mass_strength_lines", "mass_strength_report",
           "fatigue_point_data"]


def _where(peak: PeakStress) -> dict[str, Any]:
    return {"x_mm": peak.x_mm, "y_mm": peak.y_mm, "theta_deg": peak.theta_deg,
            "feature": None if peak.feature is None else user_feature_name(peak.feature),
            "feature_label": None if peak.feature is None else feature_label(peak.feature)}


def mass_strength_dict(checks: DesignChecks, material) -> dict[str, Any]:
    """The keys of the piece from a :class:`~rvfem.evaluate.design_checks.DesignChecks`."""
    m = checks.mass
    gov = checks.fatigue_governing
    return {
        "disc_mass_kg": m.mass_kg,
        "disc_polar_inertia_kg_mm2": m.polar_inertia_kg_mm2,
        "static_safety_factor": finite_or_none(checks.static_safety_factor),
        "fatigue_safety_factor": None if gov is None else finite_or_none(gov.safety_factor),
        "fatigue_safety_factor_at": None if gov is None else {"hot_spot": gov.name, **_where(gov.peak)},
        "mass_strength": {
            "disc_area_mm2": m.area_mm2,
            "disc_polar_moment_mm4": m.polar_mm4,
            "solid_disc_mass_kg": m.solid_mass_kg,
            "solid_disc_polar_inertia_kg_mm2": m.solid_polar_inertia_kg_mm2,
            "mass_saving_percent": m.mass_saving_percent,
            "inertia_saving_percent": m.inertia_saving_percent,
            "density_kg_m3": m.density_kg_m3,
            "thickness_mm": m.thickness_mm,
            "yield_strength_MPa": material.yield_strength,
            "ultimate_strength_MPa": material.ultimate_strength,
            "fatigue_limit_MPa": material.fatigue_limit,
            "static_peak_von_mises_MPa": checks.static_peak_MPa,
            "static_peak_at": None if checks.static_peak is None else _where(checks.static_peak),
            "fatigue_criterion": FATIGUE_CRITERION,
            "fatigue_hot_spots": [{
                "name": f.name, "at": _where(f.peak), "amplitude_MPa": f.amplitude_MPa, "mean_MPa": f.mean_MPa,
                "signed_von_mises_max_MPa": f.max_MPa, "signed_von_mises_min_MPa": f.min_MPa,
                "p2_factor": f.p2_factor, "safety_factor": finite_or_none(f.safety_factor),
            } for f in checks.fatigue],
        },
    }


def piece_mass_strength(a, ctx) -> dict[str, Any]:
    """Summary piece: mass, inertia and safety factors of an analysis."""
    return mass_strength_dict(design_checks(a), a.case.material)


def _words(at: dict) -> str:
    """The feature of a location in words (``bore 1``; from its ``feature`` in a summary written
    before ``feature_label`` was), or ``?``."""
    if at.get("feature_label"):
        return at["feature_label"]
    return user_feature_label(at["feature"]) if at.get("feature") else "?"


def _factor(x: float | None) -> str:
    return "–" if x is None else f"{x:.3g}"


def mass_strength_lines(summary: dict) -> list[str]:
    """The screen lines of the mass-and-strength keys of a ``summary.json`` (none where absent)."""
    ms = summary.get("mass_strength")
    if not ms:
        return []
    head = (f"  disc mass {summary['disc_mass_kg']:.4g} kg, polar inertia {summary['disc_polar_inertia_kg_mm2']:.4g} "
            "kg·mm² about its centre; ")
    if ms["mass_saving_percent"] == 0.0 and ms["inertia_saving_percent"] == 0.0:   # the same outlines: no holes
        lines = [head + "no lightening holes (a solid disc)"]
    else:
        lines = [head + f"the lightening holes save {ms['mass_saving_percent']:.1f} % of the mass and "
                 f"{ms['inertia_saving_percent']:.1f} % of the inertia of the solid disc "
                 f"({ms['solid_disc_mass_kg']:.4g} kg, {ms['solid_disc_polar_inertia_kg_mm2']:.4g} kg·mm²)"]
    where = summary.get("fatigue_safety_factor_at") or {}
    fat = ""
    if where:
        fat = (f"; fatigue safety {_factor(summary.get('fatigue_safety_factor'))} ({where['hot_spot']} hot spot, "
               f"{_words(where)} at ({where['x_mm']:.1f}, {where['y_mm']:.1f}) mm; "
               f"{ms['fatigue_criterion']}, σ_W = {ms['fatigue_limit_MPa']:g} MPa)")
    lines.append(f"  static safety against yield {_factor(summary.get('static_safety_factor'))} "
                 f"(R_p0.2 = {ms['yield_strength_MPa']:g} MPa at the structural peak){fat}")
    return lines


def mass_strength_report(summary: dict) -> list[str]:
    """The paragraphs of the report's "Mass, inertia and strength" section (none where absent):
    the screen lines and one line per hot spot."""
    ms = summary.get("mass_strength")
    if not ms:
        return []
    lines = [line.strip() for line in mass_strength_lines(summary)]
    for f in ms["fatigue_hot_spots"]:
        at = f["at"] or {}
        lines.append(f"Hot spot {f['name']} ({_words(at)} at ({at.get('x_mm', 0.0):.1f}, "
                     f"{at.get('y_mm', 0.0):.1f}) mm): signed von Mises {f['signed_von_mises_min_MPa']:.1f} … "
                     f"{f['signed_von_mises_max_MPa']:.1f} MPa (P1 history × {f['p2_factor']:.3f}), σ_a = "
                     f"{f['amplitude_MPa']:.1f} MPa, σ_m = {f['mean_MPa']:.1f} MPa, fatigue safety factor "
                     f"{_factor(f['safety_factor'])}.")
    return lines


def fatigue_point_data(analysis) -> dict:
    """The envelope's fatigue field: ``fatigue_safety_factor_P<order>`` (the Goodman safety factor
    of every vertex from the cycle's own vertex stresses, not scaled to P2; capped at 1000 for
    the colour scale), empty where the cycle has no signed von Mises envelope."""
    cy = analysis.cycle
    if getattr(cy, "signed_von_mises_max", None) is None:
        return {}
    return {f"fatigue_safety_factor_P{analysis.system.model.order}":
            fatigue_field(cy.signed_von_mises_max, cy.signed_von_mises_min, analysis.case.material)}


def _fmt(value, fmt: str) -> str:
    """A number for a line, a dash for None, ``inf`` for infinity."""
    if value is None:
        return "–"
    return format(float(value), fmt) if math.isfinite(float(value)) else "inf"


def bearing_check_lines(checks: dict | None) -> list[str]:
    """The crank bearing's static safety S0 and minimum load (rigid and flexible, where there) and the
    support bearings' loads and lives (the ``bearing_checks`` object of summary.json or ``rvfem rigid
    --json``)."""
    if not checks:
        return []
    models = [m for m in ("rigid", "flexible") if m in checks["static_safety"]]
    st, mn = checks["static_safety"], checks["minimum_load"]
    lines = ["  static safety S0 = C0/P0 (ISO 76, C0 = " + f"{st[models[0]]['C0_N']:.0f} N): " + ", ".join(
        f"{m} {_fmt(st[m]['S0'], '.2f')}" for m in models) + "; makers ask ≥ 1, ≥ 2 with shock or high accuracy"]
    change = mn.get("flexible_vs_rigid_percent")
    lines.append("  minimum load (skidding): smallest bearing load " + ", ".join(
        f"{m} {mn[m]['min_load_N']:.0f} N = {100 * mn[m]['fraction_of_C']:.2f} % of C" for m in models)
        + (f" (flexible {change:+.0f} %)" if change is not None else "")
        + f"; makers' rule ≥ {100 * mn['required_fraction_of_C']:g} % of C")
    sup = checks.get("support_bearings")
    if sup:
        lines.append("  support bearings (crankshaft beam): " + "; ".join(
            f"{b['support']} max {b['max_load_N']:.0f} N, F_m {b['equivalent_load_N']:.0f} N"
            + (f", L10h {_fmt(b['L10h_h'], '.0f')} h" if b["L10h_h"] is not None else "") for b in sup)
            + (f" ({checks['support_note']})" if checks.get("support_note") else ""))
    elif checks.get("support_note"):
        lines.append(f"  support bearings: {checks['support_note']}")
    return lines
