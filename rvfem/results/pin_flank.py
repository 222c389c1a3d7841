"""The pin–flank contact: the largest Hertz pressure of a pin on the cycloid flank over the cycle,
where it is (pin, crank angle, contact point and flank curvature), the subsurface shear and the
contact-fatigue safety (:mod:`rvfem.evaluate.pin_flank`), beside the rollers' Hertz pressures."""

from __future__ import annotations

import math
from typing import Any

from rvfem.evaluate import pin_flank as pin_flank_eval
from rvfem.evaluate.design_checks import finite_or_none
from rvfem.results.format import angle
from rvfem.results.screen_lines import sig
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ["SECTION", "compute", "summary", "pin_flank_lines"]


def compute(inputs: Any) -> pin_flank_eval.PinFlankHertz:
    """The pin–flank Hertz contact of the load cycle (:func:`rvfem.evaluate.pin_flank.pin_flank_hertz`)."""
    cycle = inputs["cycle"]
    return pin_flank_eval.pin_flank_hertz(inputs["case"], inputs["geometry"], cycle.theta, cycle.pin_forces)


def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    h = getattr(a, "pin_flank", None)
    if h is None:
        return {}
    return {"pin_flank": {
        "peak_pressure_MPa": h.peak_pressure_MPa,
        "load_N": h.load_N,
        "pin": h.pin + 1,
        "theta_deg": angle(h.theta_deg),
        "x_mm": h.x_mm, "y_mm": h.y_mm, "radius_mm": h.radius_mm,
        "flank_radius_mm": finite_or_none(h.flank_radius_mm),
        "flank": "convex" if h.flank_radius_mm > 0 else "concave",
        "relative_radius_mm": h.relative_radius_mm,
        "half_width_mm": h.half_width_mm,
        "length_mm": h.length_mm,
        "max_pin_load_N": h.max_load_N,
        "max_shear_MPa": h.max_shear_MPa, "max_shear_depth_mm": h.max_shear_depth_mm,
        "orthogonal_shear_MPa": h.orthogonal_shear_MPa, "orthogonal_shear_depth_mm": h.orthogonal_shear_depth_mm,
        "allowable_MPa": h.allowable_MPa,
        "allowable_source": "ISO 281:2007: the Hertz pressure of the fatigue load limit C_u, through-hardened bearing steel",
        "contact_fatigue_safety_factor": finite_or_none(h.safety_factor),
    }}


def pin_flank_lines(s: dict[str, Any]) -> list[str]:
    """The screen line of the pin–flank contact (none where absent), with the most loaded roller's
    pressures beside it."""
    h = s.get("pin_flank")
    if not h:
        return []
    fe = (s.get("hertz") or {}).get("fe_rollers") or (s.get("hertz") or {}).get("stribeck_flexible")
    rollers = ""
    if fe:
        rollers = (f"; rollers p_in {sig(fe['inner']['peak_pressure_MPa'], '.0f')} / p_out "
                   f"{sig(fe['outer']['peak_pressure_MPa'], '.0f')} MPa")
    fr = h["flank_radius_mm"]
    flank = "flat flank" if fr is None else f"{h['flank']} flank ρ = {abs(fr):.3g} mm"
    safety = h["contact_fatigue_safety_factor"]
    return [f"  Hertz, pin on flank: p_max {sig(h['peak_pressure_MPa'], '.0f')} MPa at pin {h['pin']}, "
            f"θ = {h['theta_deg']:g}°, r = {h['radius_mm']:.2f} mm ({flank}), Q = {sig(h['load_N'], '.0f')} N, "
            f"b = {h['half_width_mm'] * 1000:.0f} µm; τ_max {sig(h['max_shear_MPa'], '.0f')} MPa at "
            f"{h['max_shear_depth_mm'] * 1000:.0f} µm depth; contact-fatigue safety "
            f"{'–' if safety is None else f'{safety:.3g}'} against {h['allowable_MPa']:g} MPa (ISO 281:2007 "
            f"fatigue limit){rollers}"]


KEYS = (
    KeyRow('`pin_flank`',
           'object',
           "the pin–flank Hertz line contact over the cycle (docs/theory.md, \"Pin–flank contact pressure\"): each loaded pin a cylinder of radius `pins.radius` on the flank's local radius of curvature at the contact point, over the disc width; the contact with the largest pressure over the cycle and the pins"),
    KeyRow('`pin_flank.peak_pressure_MPa`, `pin_flank.load_N`',
           'float',
           "the largest Hertz pressure p_H = √(Q·E*/(π·L·R')) and that pin's normal load Q (the cycle's pin force without its friction part)"),
    KeyRow('`pin_flank.pin`, `pin_flank.theta_deg`',
           'int, float',
           'where: the pin, numbered from 1, and the crank angle'),
    KeyRow('`pin_flank.x_mm`, `pin_flank.y_mm`, `pin_flank.radius_mm`',
           'float',
           "the contact point on the profile, disc frame, and its distance from the disc centre (between the root and tip radii: the position on the tooth)"),
    KeyRow('`pin_flank.flank_radius_mm`, `pin_flank.flank`',
           'float or null, str',
           "the flank's radius of curvature there (1/κ, null where flat) and `convex` or `concave`"),
    KeyRow('`pin_flank.relative_radius_mm`, `pin_flank.half_width_mm`, `pin_flank.length_mm`',
           'float',
           "R' (1/R' = 1/r_rp + κ), the half-width b and the contact length L (the disc width)"),
    KeyRow('`pin_flank.max_pin_load_N`',
           'float',
           'the largest pin normal load over the cycle (not necessarily where the pressure peaks)'),
    KeyRow('`pin_flank.max_shear_MPa`, `pin_flank.max_shear_depth_mm`, `pin_flank.orthogonal_shear_MPa`, `pin_flank.orthogonal_shear_depth_mm`',
           'float',
           'subsurface shear of the peak contact (Johnson, Contact Mechanics, §4.3): τ_max = 0.300·p_H at 0.786·b, τ_zx,max = 0.250·p_H at 0.5·b'),
    KeyRow('`pin_flank.allowable_MPa`, `pin_flank.allowable_source`',
           'float, str',
           'the contact-fatigue allowable, 1500 MPa: the Hertz pressure that defines the fatigue load limit C_u of ISO 281:2007 (through-hardened bearing steel)'),
    KeyRow('`pin_flank.contact_fatigue_safety_factor`',
           'float or null',
           "allowable / p_H (on pressure; on load it is its square); the flank's contact-fatigue verdict (the disc's fatigue factor `fatigue_safety_factor` is the structural one)"),
)
"""Its rows of the key table (docs/outputs.md)."""

def pin_flank_report(s: dict[str, Any]) -> list[list[str]]:
    """Its row of the report's "Other results" table."""
    return [["pin–flank contact", line.strip()] for line in pin_flank_lines(s)]


SECTION = Section("pin_flank", summary, KEYS, requires=("case", "geometry", "cycle"), compute=compute,
                  stage="evaluation", screen=pin_flank_lines, screen_rank=46, report=pin_flank_report)
