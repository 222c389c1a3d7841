"""The mass-and-strength section: disc mass and inertia, static and fatigue safety
(:mod:`rvfem.evaluate.design_checks`).

Top-level keys scripts can rely on: ``disc_mass_kg``, ``disc_polar_inertia_kg_mm2``,
``static_safety_factor``, ``fatigue_safety_factor`` and ``fatigue_safety_factor_at`` (the hot spot
with the smallest factor), and the details under ``mass_strength`` (docs/outputs.md).
"""

from __future__ import annotations

from typing import Any

from rvfem.evaluate.design_checks import DesignChecks, design_checks, finite_or_none
from rvfem.evaluate.postprocess import PeakStress, feature_label, user_feature_label, user_feature_name
from rvfem.evaluate.strength import FATIGUE_CRITERION, SHEAR_FATIGUE_FACTOR, fatigue_field, findley_constants
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ["SECTION", "fatigue_point_data", "mass_strength_dict", "mass_strength_lines", "mass_strength_report",
           "compute", "summary"]


def _where(peak: PeakStress) -> dict[str, Any]:
    return {"x_mm": peak.x_mm, "y_mm": peak.y_mm, "theta_deg": peak.theta_deg,
            "feature": None if peak.feature is None else user_feature_name(peak.feature),
            "feature_label": None if peak.feature is None else feature_label(peak.feature)}


def _findley_dict(f: Any) -> dict[str, Any] | None:
    c = f.findley
    if c is None:
        return None
    return {"parameter_MPa": c.parameter_MPa, "shear_amplitude_MPa": c.shear_amplitude_MPa,
            "normal_stress_max_MPa": c.normal_max_MPa, "plane_normal": list(c.normal)}


def mass_strength_dict(checks: DesignChecks, material: Any) -> dict[str, Any]:
    """The keys of the piece from a :class:`~rvfem.evaluate.design_checks.DesignChecks`."""
    m = checks.mass
    gov = checks.fatigue_governing
    tau_w = SHEAR_FATIGUE_FACTOR * material.fatigue_limit
    k, f_findley = findley_constants(material.fatigue_limit, tau_w)
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
            "shear_fatigue_limit_MPa": tau_w,
            "findley_k": k,
            "findley_f_MPa": f_findley,
            "fatigue_hot_spots": [{
                "name": f.name, "at": _where(f.peak), "amplitude_MPa": f.amplitude_MPa, "mean_MPa": f.mean_MPa,
                "signed_von_mises_max_MPa": f.max_MPa, "signed_von_mises_min_MPa": f.min_MPa,
                "p2_factor": f.p2_factor, "safety_factor": finite_or_none(f.safety_factor),
                "findley": _findley_dict(f),
                "goodman_safety_factor": finite_or_none(f.goodman_safety_factor),
                "assessed_as": f.assessed_as,
            } for f in checks.fatigue],
        },
    }


def compute(inputs: Any) -> DesignChecks:
    """Mass, inertia, static and fatigue safety of the disc (:func:`rvfem.evaluate.design_checks.design_checks`)."""
    return design_checks(inputs["analysis"])


def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    """Mass, inertia and safety factors of an analysis (its top-level keys of ``summary.json``;
    computed here for an analysis made without them)."""
    checks = a.mass_strength if a.mass_strength is not None else design_checks(a)
    return mass_strength_dict(checks, a.case.material)


def _words(at: dict[str, Any]) -> str:
    """The feature of a location in words (``bore 1``; from its ``feature`` in a summary written
    before ``feature_label`` was), or ``?``."""
    if at.get("feature_label"):
        return at["feature_label"]
    return user_feature_label(at["feature"]) if at.get("feature") else "?"


def _factor(x: float | None) -> str:
    return "–" if x is None else f"{x:.3g}"


def mass_strength_lines(summary: dict[str, Any]) -> list[str]:
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
        tau = ms.get("shear_fatigue_limit_MPa")
        fat = (f"; fatigue safety {_factor(summary.get('fatigue_safety_factor'))} ({where['hot_spot']} hot spot, "
               f"{_words(where)} at ({where['x_mm']:.1f}, {where['y_mm']:.1f}) mm; "
               f"{ms['fatigue_criterion']}, σ_W = {ms['fatigue_limit_MPa']:g} MPa"
               + ("" if tau is None else f", τ_W = {tau:.0f} MPa") + ")")
    lines.append(f"  static safety against yield {_factor(summary.get('static_safety_factor'))} "
                 f"(R_p0.2 = {ms['yield_strength_MPa']:g} MPa at the structural peak){fat}")
    return lines


def mass_strength_report(summary: dict[str, Any]) -> list[str]:
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
                     f"{_factor(f['safety_factor'])}"
                     + (f" (Findley: τ_a = {f['findley']['shear_amplitude_MPa']:.1f} MPa, σ_n,max = "
                        f"{f['findley']['normal_stress_max_MPa']:.1f} MPa on the critical plane; the signed von Mises "
                        f"stress on the Goodman line gives {_factor(f.get('goodman_safety_factor'))})"
                        if f.get("findley") else "")
                     + (f"; assessed as {f['assessed_as']}" if f.get("assessed_as") else "") + ".")
    return lines


def fatigue_point_data(analysis: Any) -> dict[str, Any]:
    """The envelope's fatigue field: ``fatigue_safety_factor_P<order>`` (the former criterion's
    Goodman safety factor of the signed von Mises stress of every vertex, from the cycle's own vertex
    stresses, not scaled to P2; capped at 1000 for
    the colour scale), empty where the cycle has no signed von Mises envelope."""
    cy = analysis.cycle
    if getattr(cy, "signed_von_mises_max", None) is None:
        return {}
    return {f"fatigue_safety_factor_P{analysis.system.model.order}":
            fatigue_field(cy.signed_von_mises_max, cy.signed_von_mises_min, analysis.case.material)}


KEYS = (
    KeyRow('`disc_mass_kg`',
           'float',
           "**disc mass** m = ρ·b·A, kg: area A of the disc with its holes (Green's theorem over the outlines, `rvfem.geometry.mass`), width b = `cycloid.thickness`, ρ = `material.density_kg_m3`"),
    KeyRow('`disc_polar_inertia_kg_mm2`',
           'float',
           '**polar moment of inertia** of the disc about its own axis through the disc centre, I = ρ·b·∬(x² + y²) dA, kg·mm²'),
    KeyRow('`static_safety_factor`',
           'float or null',
           '**static safety against yield** R_p0.2/σ_vM at the structural peak (`peak_von_mises_MPa`, P2 away from contacts); null without a structural peak'),
    KeyRow('`fatigue_safety_factor`',
           'float or null',
           '**fatigue safety factor** of the disc at its structural hot spot (`mass_strength.fatigue_hot_spots[]` with a factor; P2-consistent stresses away from the contact footprints): Findley\'s critical-plane criterion on the stress-tensor history over the cycle, f/max(τ_a + k·σ_n,max) with k and f from σ_W and τ_W = 0.577·σ_W (docs/theory.md, "Mass and strength"); the contact zones are assessed as what they are (`mass_strength.fatigue_hot_spots[].assessed_as`, `pin_flank`); null if infinite or without a structural hot spot'),
    KeyRow('`fatigue_safety_factor_at`, `mass_strength.static_peak_at`, `mass_strength.fatigue_hot_spots[].at`',
           'object or null',
           "where the governing hot spot, the static check's peak, each hot spot is"),
    KeyRow('&nbsp;&nbsp;`.x_mm`, `.y_mm`, `.theta_deg`, `.feature`, `.feature_label`',
           'float, float, float, str, str',
           'position, the crank angle of its von Mises peak and the nearest boundary, numbered from 1 (`bore_1`), and the same in words (`bore 1`)'),
    KeyRow('`fatigue_safety_factor_at.hot_spot`',
           'str',
           'which hot spot governs (`structural`)'),
    KeyRow('`mass_strength`',
           'object',
           'the details of the four keys above'),
    KeyRow('`mass_strength.disc_area_mm2`, `mass_strength.disc_polar_moment_mm4`',
           'float',
           'A and ∬(x² + y²) dA of the disc with its holes'),
    KeyRow('`mass_strength.solid_disc_mass_kg`, `mass_strength.solid_disc_polar_inertia_kg_mm2`',
           'float',
           'the same disc without the lightening holes (central hole and bores kept)'),
    KeyRow('`mass_strength.mass_saving_percent`, `mass_strength.inertia_saving_percent`',
           'float',
           'what the lightening holes save against that solid disc, %'),
    KeyRow('`mass_strength.density_kg_m3`, `mass_strength.thickness_mm`',
           'float',
           'ρ and b'),
    KeyRow('`mass_strength.yield_strength_MPa`, `mass_strength.ultimate_strength_MPa`, `mass_strength.fatigue_limit_MPa`',
           'float',
           "the material's R_p0.2, R_m and σ_W (`[material]`)"),
    KeyRow('`mass_strength.static_peak_von_mises_MPa`',
           'float',
           'the stress of the static check (where: `mass_strength.static_peak_at`)'),
    KeyRow('`mass_strength.fatigue_criterion`',
           'str',
           'the criterion in words'),
    KeyRow('`mass_strength.shear_fatigue_limit_MPa`, `mass_strength.findley_k`, `mass_strength.findley_f_MPa`',
           'float',
           "τ_W = f_W,τ·σ_W (f_W,τ = 0.577 for steel, FKM guideline) and Findley's constants k = q/√(1 − q²), f = τ_W·√(1 + k²) with q = 2τ_W/σ_W − 1"),
    KeyRow('`mass_strength.fatigue_hot_spots[]`',
           'array',
           'one entry per hot spot of `stress.hot_spots[]`'),
    KeyRow('`mass_strength.fatigue_hot_spots[].name`',
           'str',
           'the hot spot (where: `.at`, above)'),
    KeyRow('`mass_strength.fatigue_hot_spots[].amplitude_MPa`, `mass_strength.fatigue_hot_spots[].mean_MPa`',
           'float',
           "σ_a = (max − min)/2 and σ_m = (max + min)/2 of the signed von Mises stress over the cycle (the cycle's history times `p2_factor`)"),
    KeyRow('`mass_strength.fatigue_hot_spots[].signed_von_mises_max_MPa`, `mass_strength.fatigue_hot_spots[].signed_von_mises_min_MPa`',
           'float',
           'its largest and smallest value'),
    KeyRow('`mass_strength.fatigue_hot_spots[].p2_factor`, `mass_strength.fatigue_hot_spots[].safety_factor`',
           'float, float or null',
           "the P2/P1 factor applied; Findley's safety factor (null if infinite, and for the contact zone, which is assessed as `assessed_as` says)"),
    KeyRow('`mass_strength.fatigue_hot_spots[].findley`',
           'object or null',
           'the critical plane of the structural hot spot (keys below); null for the contact zone'),
    KeyRow('&nbsp;&nbsp;`.parameter_MPa`, `.shear_amplitude_MPa`, `.normal_stress_max_MPa`, `.plane_normal`',
           'float, float, float, array',
           "Findley's τ_a + k·σ_n,max; τ_a, half the longest chord of the shear path on the plane; σ_n,max; the plane's unit normal (x, y, z; z the disc axis)"),
    KeyRow('`mass_strength.fatigue_hot_spots[].goodman_safety_factor`',
           'float or null',
           "the former criterion, for comparison: the signed von Mises stress's amplitude and mean on the Goodman line of σ_W and R_m (its sign flips near pure shear)"),
    KeyRow('`mass_strength.fatigue_hot_spots[].assessed_as`',
           'str or null',
           "for the contact zone: what it is assessed as instead — a bore is the crank bearing's outer raceway (its rolling-contact fatigue is in L10r), the flank the pin–flank Hertz contact (`pin_flank`); null for the structural hot spot"),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("mass_strength", summary, KEYS, requires=("analysis",), compute=compute, screen=mass_strength_lines, screen_rank=40)
