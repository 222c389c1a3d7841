"""What the holes buy and cost beside the loads: the disc's mass properties and its strength.

:func:`design_checks` reads them off a complete analysis (:class:`rvfem.app.analysis.Analysis`,
duck-typed: ``case``, ``geometry`` and ``stress``): mass and polar inertia from the geometry
(:mod:`rvfem.geometry.mass`), the static safety factor at the structural (P2) peak and the fatigue
safety factor of every hot spot (:mod:`rvfem.evaluate.strength`). It is cheap (a few ms besides
the geometry the analysis already holds) and computed where it is shown (summary, screen, report).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from rvfem.evaluate import strength
from rvfem.geometry.mass import MassProperties, disc_mass_properties

if TYPE_CHECKING:   # for the annotations only: postprocess is a heavier module of the same layer
    from rvfem.evaluate.postprocess import PeakStress

__all__ = ["DesignChecks", "design_checks", "finite_or_none"]


@dataclass(frozen=True)
class DesignChecks:
    """Mass, inertia and safety factors of one analysed disc.

    Attributes
    ----------
    mass : MassProperties
    static_safety_factor : float or None
        R_p0.2 over the structural peak (P2 where re-solved), None without a structural peak.
    static_peak_MPa : float or None
        That peak's von Mises stress.
    static_peak : PeakStress or None
        Where it is.
    fatigue : tuple of rvfem.evaluate.strength.HotSpotFatigue
        Every hot spot (empty without a stress history).
    yield_strength_MPa : float
    """

    mass: MassProperties
    static_safety_factor: float | None
    static_peak_MPa: float | None
    static_peak: PeakStress | None
    fatigue: tuple[strength.HotSpotFatigue, ...]
    yield_strength_MPa: float

    @property
    def fatigue_governing(self):
        """The assessed hot spot (a fatigue factor: the structural one) with the smallest fatigue
        safety factor, or None."""
        return min((f for f in self.fatigue if f.safety_factor is not None), key=lambda f: f.safety_factor,
                   default=None)

    @property
    def fatigue_safety_factor(self) -> float | None:
        g = self.fatigue_governing
        return None if g is None else g.safety_factor


def design_checks(analysis) -> DesignChecks:
    """The :class:`DesignChecks` of an analysis (module docstring)."""
    case = analysis.case
    mat = case.material
    structural = analysis.stress.structural if analysis.stress is not None else None
    peak_vm = None if structural is None else float(structural.von_mises_MPa)
    history = getattr(analysis.stress, "history", None)
    fatigue = strength.hot_spot_fatigue(history, mat) if history is not None else ()
    return DesignChecks(mass=disc_mass_properties(analysis.geometry),
                        static_safety_factor=strength.static_safety_factor(peak_vm, mat.yield_strength),
                        static_peak_MPa=peak_vm, static_peak=structural, fatigue=fatigue,
                        yield_strength_MPa=float(mat.yield_strength))


def finite_or_none(x: float | None) -> float | None:
    """x, or None where it is None or not finite (for JSON)."""
    return None if x is None or not math.isfinite(x) else float(x)
