"""Bearing evaluation formulas, under their former module name.

The formulas live in modules named for what they are: :mod:`rvfem.iso281` (bearing speed, ISO 281
rating and life, duty cycles, life ratios) and :mod:`rvfem.hertz` (Hertz line contact, Palmgren's
approach, Stribeck's most loaded roller). This module re-exports them so that existing imports
(``from rvfem.evaluation import PALMGREN_COEFFICIENT``) keep working; new code imports from those
two modules.
"""

from __future__ import annotations

from .hertz import (
    PALMGREN_COEFFICIENT,
    STRIBECK_FACTOR,
    HertzLineContact,
    RollerHertz,
    composite_modulus,
    crank_bearing_hertz,
    hertz_half_width,
    hertz_line_contact,
    hertz_peak_pressure,
    most_loaded_roller_hertz,
    palmgren_approach,
    reduced_radius,
    roller_raceway_contacts,
    stribeck_max_roller_load,
)
from .iso281 import (
    ROLLER_LIFE_EXPONENT,
    DutyCycleLife,
    bearing_speed_rpm,
    case_bearing_speed_rpm,
    case_duty_cycle_life,
    constant_load_life_hours,
    crank_bearing_rating,
    duty_cycle_life,
    dynamic_load_rating,
    life_ratio,
    rating_life_hours,
)

__all__ = [
    "PALMGREN_COEFFICIENT", "STRIBECK_FACTOR", "HertzLineContact", "RollerHertz", "composite_modulus",
    "crank_bearing_hertz", "hertz_half_width", "hertz_line_contact", "hertz_peak_pressure",
    "most_loaded_roller_hertz", "palmgren_approach", "reduced_radius", "roller_raceway_contacts",
    "stribeck_max_roller_load", "ROLLER_LIFE_EXPONENT", "DutyCycleLife", "bearing_speed_rpm",
    "case_bearing_speed_rpm", "case_duty_cycle_life", "constant_load_life_hours", "crank_bearing_rating",
    "duty_cycle_life", "dynamic_load_rating", "life_ratio", "rating_life_hours",
]
