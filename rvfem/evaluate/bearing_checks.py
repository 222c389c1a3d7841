"""What a bearing analyst checks next to L10h: the crank bearing's static safety S0 = C0/P0, its
minimum load against skidding, and the loads and lives of the crankshaft's support bearings.

Plain functions of numbers (loads in N, lengths in mm, speeds in rpm, lives in hours);
:func:`static_safety` and :func:`minimum_load` read a crank bearing for convenience. The formulas
are collected in docs/theory.md ("Static safety, minimum load and the support bearings").

Sources
-------
* ISO 76:2006, *Rolling bearings - Static load ratings* (C0r of radial roller bearings; P0r = F_r
  for a purely radial load; C0 is the load at which the most loaded roller-raceway contact
  reaches 4000 MPa).
* ISO 281:2007, *Rolling bearings - Dynamic load ratings and rating life* (L10 = (C/P)^p).
* Limits of S0 and the minimum load are bearing makers' rules, not ISO: SKF, *Rolling bearings*
  catalogue (static safety factor s0 ≥ 1 for normal operation of roller bearings, ≥ 2 for shock
  loads or high demands on running accuracy and smoothness; minimum load of cylindrical roller
  bearings P_min ≈ 0.02·C, below which the rollers may skid).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rvfem.case.definition import Case, CrankBearing
from rvfem.evaluate import lubrication

__all__ = [
    "STATIC_SAFETY_NORMAL",
    "STATIC_SAFETY_SHOCK",
    "MINIMUM_LOAD_FRACTION",
    "crank_bearing_static_rating",
    "StaticSafety",
    "static_safety",
    "MinimumLoad",
    "minimum_load",
    "support_reactions",
    "SupportBearing",
    "support_bearings",
    "BearingChecks",
    "case_bearing_checks",
]

#: Smallest static safety S0 = C0/P0 of a roller bearing in normal operation (SKF catalogue rule).
STATIC_SAFETY_NORMAL = 1.0
#: S0 asked for shock loads or high demands on running accuracy (SKF catalogue rule).
STATIC_SAFETY_SHOCK = 2.0
#: Minimum load of a cylindrical roller bearing as a fraction of C, P_min ≈ 0.02·C (SKF catalogue
#: rule; a manufacturer's rule, not ISO): below it the rollers may skid.
MINIMUM_LOAD_FRACTION = 0.02


def crank_bearing_static_rating(bearing: CrankBearing) -> float:
    """C0 of a case's crank bearing, N: ``static_load_rating_N`` if given, else ISO 76's C0r
    (:func:`rvfem.evaluate.lubrication.static_load_rating`)."""
    return bearing.static_load_rating_N or lubrication.static_load_rating(
        bearing.rollers, bearing.roller_diameter, bearing.roller_length, bearing.pitch_diameter)


@dataclass(frozen=True)
class StaticSafety:
    """Static safety of a radial roller bearing (ISO 76).

    Attributes
    ----------
    static_rating_N : float
        C0, N.
    p0_N : float
        Equivalent static load P0 = F_r,max (pure radial load), N.
    s0 : float
        C0/P0.
    """

    static_rating_N: float
    p0_N: float
    s0: float

    @property
    def verdict(self) -> str:
        """``"below 1"``, ``"1 to 2"`` or ``"at least 2"`` (:data:`STATIC_SAFETY_NORMAL`, :data:`STATIC_SAFETY_SHOCK`)."""
        if self.s0 < STATIC_SAFETY_NORMAL:
            return "below 1"
        return "1 to 2" if self.s0 < STATIC_SAFETY_SHOCK else "at least 2"


def static_safety(static_rating_N: float, max_radial_load_N: float) -> StaticSafety:
    """S0 = C0/P0 with P0 = F_r (ISO 76: P0r = X0·F_r + Y0·F_a, X0 = 1 for a purely radial load;
    for a radial roller bearing P0r = F_r). The load is the largest over the cycle.

    Parameters
    ----------
    static_rating_N : float
        C0, N (> 0).
    max_radial_load_N : float
        F_r,max, N (≥ 0).
    """
    if static_rating_N <= 0 or max_radial_load_N < 0:
        raise ValueError("static_safety needs C0 > 0 and a non-negative load")
    s0 = math.inf if max_radial_load_N == 0 else static_rating_N / max_radial_load_N
    return StaticSafety(static_rating_N=float(static_rating_N), p0_N=float(max_radial_load_N), s0=float(s0))


@dataclass(frozen=True)
class MinimumLoad:
    """Smallest bearing load of a cycle against the minimum-load rule.

    Attributes
    ----------
    min_load_N : float
        Smallest |F| over the cycle and the bearings, N.
    fraction_of_C : float
        min_load_N / C.
    required_fraction : float
        :data:`MINIMUM_LOAD_FRACTION`.
    """

    min_load_N: float
    fraction_of_C: float
    required_fraction: float = MINIMUM_LOAD_FRACTION

    @property
    def below(self) -> bool:
        """True if the smallest load is under the rule (the rollers may skid)."""
        return self.fraction_of_C < self.required_fraction


def minimum_load(min_load_N: float, rating_N: float) -> MinimumLoad:
    """The minimum-load check P_min ≥ 0.02·C (SKF's rule for cylindrical roller bearings)."""
    if rating_N <= 0:
        raise ValueError("rating_N must be positive")
    return MinimumLoad(min_load_N=float(min_load_N), fraction_of_C=float(min_load_N) / rating_N)


def support_reactions(span_mm: float, eccentric_positions_mm: Sequence[float] | np.ndarray, eccentric_forces: np.ndarray) -> np.ndarray:
    """Forces of the two support bearings on a crankshaft beam carrying point loads, N.

    Beam statics of a shaft on two supports (the span's ends): with P_k the force on the eccentric at
    z_k from support 1, R_2 = Σ_k P_k·z_k/L and R_1 = Σ_k P_k − R_2 are the loads the supports
    take (moment about support 1 and force balance; statically determinate, so independent of the
    support stiffnesses and of EI).

    Parameters
    ----------
    span_mm : float
        L, mm.
    eccentric_positions_mm : sequence of float (discs,)
        z_k, mm.
    eccentric_forces : ndarray (..., discs, 2)
        P_k (any frame), N.

    Returns
    -------
    ndarray (..., 2, 2)
        R_1 and R_2 (same frame), N.
    """
    p = np.asarray(eccentric_forces, dtype=float)
    z = np.asarray(eccentric_positions_mm, dtype=float)
    r2 = np.einsum("k,...kc->...c", z / float(span_mm), p)
    r1 = p.sum(axis=-2) - r2
    return np.stack([r1, r2], axis=-2)


@dataclass(frozen=True)
class SupportBearing:
    """Loads (and life, given a rating) of one support bearing over the cycle, the most loaded crank.

    Attributes
    ----------
    support : int
        1 or 2 (support 1 at z = 0).
    crank : int
        0-based crank of the largest equivalent load.
    max_N, min_N, equivalent_N : float
        Largest, smallest and equivalent radial load F_m = (mean F^p)^(1/p) over the cycle, N.
    max_at_deg : float
        Crank angle of the largest load, degrees.
    L10h : float or None
        ISO 281 basic rating life at n_b, h (None without ``support_bearing_C_N``).
    """

    support: int
    crank: int
    max_N: float
    min_N: float
    max_at_deg: float
    equivalent_N: float
    L10h: float | None


def support_bearings(theta: np.ndarray, reactions: np.ndarray, speed_rpm: float, *, rating_N: float | None,
                     exponent: float) -> tuple[SupportBearing, SupportBearing]:
    """Loads and lives of the two support bearings, each on the crank where it lasts least.

    Parameters
    ----------
    theta : ndarray (n,)
        Crank angles, rad, equally spaced over one revolution.
    reactions : ndarray (n, N, 2, 2)
        :func:`support_reactions` of every crank at every angle, N.
    speed_rpm : float
        Speed of the crankshaft relative to the carrier (= the crank bearings' n_b), rpm.
    rating_N : float or None
        C of a support bearing, N (None: loads only).
    exponent : float
        Life exponent p of the support bearing (10/3 roller, 3 ball bearings), also the exponent of
        its equivalent load over the cycle (ISO 281's variable load).
    """
    mag = np.linalg.norm(np.asarray(reactions, dtype=float), axis=-1)          # (n, N, 2)
    fm = np.mean(mag ** exponent, axis=0) ** (1.0 / exponent)        # (N, 2)
    out = []
    for s in range(2):
        i = int(np.argmax(np.round(fm[:, s], 6)))
        k = int(np.argmax(mag[:, i, s]))
        life = None
        if rating_N is not None:
            life = math.inf if fm[i, s] == 0 else 1.0e6 / (60.0 * speed_rpm) * (rating_N / fm[i, s]) ** exponent
        out.append(SupportBearing(support=s + 1, crank=i, max_N=float(mag[k, i, s]), min_N=float(mag[:, i, s].min()),
                                  max_at_deg=math.degrees(float(theta[k])), equivalent_N=float(fm[i, s]), L10h=life))
    return out[0], out[1]


@dataclass(frozen=True)
class BearingChecks:
    """The checks of :func:`case_bearing_checks`.

    Attributes
    ----------
    static : dict of str to StaticSafety
        ``"rigid"`` (where the handbook is defined) and ``"flexible"``: S0 of the crank bearing at
        the largest bearing load of the cycle.
    minimum : dict of str to MinimumLoad
        The same models: the smallest bearing load of the cycle against 0.02·C.
    support : tuple of SupportBearing or None
        Support bearings 1 and 2 from the flexible model's eccentric loads (None: see ``support_note``).
    support_note : str
        Why there are no support loads, or why there is no support life; "" when both are there.
    """

    static: dict[str, StaticSafety]
    minimum: dict[str, MinimumLoad]
    support: tuple[SupportBearing, ...] | None
    support_note: str


def case_bearing_checks(case: Case, theta: np.ndarray, rating_N: float, speed_rpm: float, max_loads_N: dict[str, float],
                        min_loads_N: dict[str, float], disc_bearing_forces: np.ndarray | None) -> BearingChecks:
    """Static safety, minimum load and support bearings of a case's load cycle.

    Parameters
    ----------
    case : Case
    theta : ndarray (n,)
        Crank angles, rad, equally spaced over one revolution.
    rating_N, speed_rpm : float
        The crank bearing's C (N) and n_b (rpm; the crankshaft turns at the same speed relative to
        the carrier as the eccentric relative to the disc).
    max_loads_N, min_loads_N : dict of str to float
        Largest and smallest crank-bearing load of the cycle over all bearings per model
        (``"rigid"``, ``"flexible"``), N.
    disc_bearing_forces : ndarray (n, discs, N, 2) or None
        Force of every bearing on each disc (carrier frame), N; None when the stage has one disc.
    """
    c0 = crank_bearing_static_rating(case.crank_bearing)
    static = {m: static_safety(c0, f) for m, f in max_loads_N.items()}
    minimum = {m: minimum_load(f, rating_N) for m, f in min_loads_N.items()}
    cs = case.crank_support
    if cs is None:
        return BearingChecks(static, minimum, None, "rigid crank support: no support bearings in the model")
    if cs.span is None or cs.eccentric_positions is None:
        return BearingChecks(static, minimum, None, "support-bearing loads need crank_support.span and "
                                                    "eccentric_positions (an influence matrix gives no beam)")
    if disc_bearing_forces is None:
        return BearingChecks(static, minimum, None, "support-bearing loads need the two discs' eccentric forces")
    # the disc pushes each eccentric with −F (F the bearing's force on the disc)
    forces = -np.moveaxis(np.asarray(disc_bearing_forces, dtype=float), 1, 2)              # (n, N, discs, 2)
    reactions = support_reactions(cs.span, cs.eccentric_positions, forces)
    support = support_bearings(theta, reactions, speed_rpm, rating_N=cs.support_bearing_C_N,
                               exponent=cs.support_bearing_life_exponent)
    note = "" if cs.support_bearing_C_N else \
        "life needs crank_support.support_bearing_C_N, the dynamic load rating"
    return BearingChecks(static, minimum, support, note)
