"""Roller-raceway contact of the crank bearings: Hertz line contact (half-width, peak pressure),
Palmgren's load-deflection approach and Stribeck's most loaded roller, and the Hertz pressures of the
most loaded roller of a load cycle.

Plain functions of numbers (loads in N, lengths in mm, moduli and pressures in MPa);
:func:`crank_bearing_hertz`, :func:`roller_raceway_contacts` and :func:`most_loaded_roller_hertz`
read a case for convenience. The formulas are collected in docs/theory.md.

Sources
-------
* K. L. Johnson, *Contact Mechanics*, Cambridge University Press 1985, §4.2-4.3 (two cylinders in
  line contact).
* T. A. Harris, M. N. Kotzalas, *Rolling Bearing Analysis* (Palmgren's load-deflection relation of
  a roller-raceway line contact; Stribeck's maximum roller load).
* Gao, Li, Zhang, Ji, Wang, *Lifespan evaluation for a standard RV reducer based on fatigue
  strength theory* (eqs. 20-22 Hertz, with the Stribeck roller load of eq. 21).
* Zhang, Wang, Wu, Guan, Chen, *Contact load and elastohydrodynamic lubrication analysis of
  eccentric bearings in RV reducer considering the effects of roller profile modification* (eq. 14).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rvfem._arrays import first_max, max_load_index
from rvfem.case.definition import Case, CrankBearing
from rvfem.solve.contact import PALMGREN_COEFFICIENT

__all__ = [
    "PALMGREN_COEFFICIENT",
    "STRIBECK_FACTOR",
    "HertzLineContact",
    "RollerHertz",
    "composite_modulus",
    "reduced_radius",
    "hertz_half_width",
    "hertz_peak_pressure",
    "palmgren_approach",
    "hertz_line_contact",
    "stribeck_max_roller_load",
    "rigid_ring_factor",
    "RIGID_ROLLER_MODEL",
    "crank_bearing_hertz",
    "roller_raceway_contacts",
    "most_loaded_roller_hertz",
]

#: Stribeck factor of Gao et al.'s eq. 21, Q_max = 4.6·F_r/Z (see :func:`stribeck_max_roller_load`).
STRIBECK_FACTOR = 4.6


@dataclass(frozen=True)
class HertzLineContact:
    """A Hertz line contact between a roller and a raceway.

    Attributes
    ----------
    half_width_mm : float
        Semi-width b of the contact strip, mm.
    peak_pressure_MPa : float
        Maximum contact pressure p_h = 2Q/(π·L·b), MPa.
    approach_mm : float
        Elastic approach of the roller and this raceway (Palmgren), mm.
    """

    half_width_mm: float
    peak_pressure_MPa: float
    approach_mm: float


@dataclass(frozen=True)
class RollerHertz:
    """Hertz line contact of one roller on both raceways.

    Attributes
    ----------
    source : str
        ``"fe_rollers"`` (largest roller load of the FE cycle), ``"stribeck_rigid"`` (largest
        roller load of rigid rings under the handbook forces, :data:`RIGID_ROLLER_MODEL`) or
        ``"stribeck_flexible"`` (the same under the FE bearing forces).
    roller_load_N : float
        Q, N.
    inner : HertzLineContact
        Roller on the eccentric (convex raceway).
    outer : HertzLineContact
        Roller in the disc bore (concave raceway).
    bearing : int or None
        0-based bearing of that roller (or of the bearing load of a Stribeck estimate).
    roller : int or None
        0-based roller index (FE only).
    theta_deg : float or None
        Crank angle at which it carries Q, degrees.
    factor : float or None
        Z·Q/|F| with F that bearing's force at that angle (the k of Stribeck's Q_max = k·F/Z).
    """

    source: str
    roller_load_N: float
    inner: HertzLineContact
    outer: HertzLineContact
    bearing: int | None = None
    roller: int | None = None
    theta_deg: float | None = None
    factor: float | None = None


def composite_modulus(
    youngs_modulus_1: float, poissons_ratio_1: float,
    youngs_modulus_2: float | None = None, poissons_ratio_2: float | None = None,
) -> float:
    """Plane-strain composite modulus E*, MPa (Johnson, Contact Mechanics, §4.2).

    1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2; the second body defaults to the first material.
    """
    e2 = youngs_modulus_1 if youngs_modulus_2 is None else youngs_modulus_2
    nu2 = poissons_ratio_1 if poissons_ratio_2 is None else poissons_ratio_2
    return 1.0 / ((1.0 - poissons_ratio_1**2) / youngs_modulus_1 + (1.0 - nu2**2) / e2)


def reduced_radius(roller_radius: float, raceway_radius: float, *, concave: bool) -> float:
    """Relative radius of curvature R' of a roller on a raceway, mm.

    1/R' = 1/R1 + 1/R2 for a convex raceway (roller on the inner ring, the eccentric) and
    1/R' = 1/R1 − 1/R2 for a concave one (roller in the bore, the outer raceway).

    Parameters
    ----------
    roller_radius : float
        R1 = D_we/2, mm.
    raceway_radius : float
        R2, mm (positive; ``concave`` says which side).
    concave : bool
        True for the outer (concave) raceway.
    """
    if roller_radius <= 0 or raceway_radius <= 0:
        raise ValueError("radii must be positive")
    curvature = 1.0 / roller_radius + (-1.0 if concave else 1.0) / raceway_radius
    if curvature <= 0:
        raise ValueError("a concave raceway must be larger than the roller")
    return 1.0 / curvature


def hertz_half_width(load_N: float, length_mm: float, reduced_radius_mm: float, composite_modulus_MPa: float) -> float:
    """Half-width of a Hertz line contact, mm (Johnson, Contact Mechanics, §4.3).

    b = √(4·Q·R' / (π·L·E*)), Q the load on the contact (N), L the contact length (mm), R' the
    relative radius (mm), E* the composite modulus (MPa).
    """
    if load_N < 0 or length_mm <= 0 or reduced_radius_mm <= 0 or composite_modulus_MPa <= 0:
        raise ValueError("hertz_half_width needs a non-negative load and positive length, radius and modulus")
    return math.sqrt(4.0 * load_N * reduced_radius_mm / (math.pi * length_mm * composite_modulus_MPa))


def hertz_peak_pressure(load_N: float, length_mm: float, half_width_mm: float) -> float:
    """Peak pressure of a Hertz line contact, MPa: p_h = 2Q/(π·L·b) (Johnson, Contact Mechanics, §4.3).

    Gao et al., eq. 20; Zhang et al. (*Contact load and EHL analysis of eccentric bearings in RV
    reducer ...*), eq. 14.
    """
    if half_width_mm <= 0 or length_mm <= 0:
        if load_N == 0:
            return 0.0
        raise ValueError("half_width_mm and length_mm must be positive")
    return 2.0 * load_N / (math.pi * length_mm * half_width_mm)


def palmgren_approach(load_N: float, length_mm: float) -> float:
    """Elastic approach of one steel roller-raceway line contact, mm (Palmgren).

    δ = 3.84·10⁻⁵·Q^0.9 / L^0.8 (Q in N, L in mm; Harris & Kotzalas). It is empirical, for steel
    on steel, and independent of the radii. A roller between two raceways deflects by the sum
    over both contacts. Chosen over Johnson's logarithmic two-cylinder formula (and Gao et al.'s
    eq. 23) because those depend on an assumed depth of the elastic bodies.
    """
    if load_N < 0 or length_mm <= 0:
        raise ValueError("palmgren_approach needs a non-negative load and a positive length")
    return PALMGREN_COEFFICIENT * load_N**0.9 / length_mm**0.8


def hertz_line_contact(
    load_N: float,
    length_mm: float,
    roller_radius_mm: float,
    raceway_radius_mm: float,
    *,
    concave: bool,
    youngs_modulus_MPa: float = 206000.0,
    poissons_ratio: float = 0.3,
) -> HertzLineContact:
    """Hertz line contact of a roller on a raceway (both bodies of the same material).

    Parameters
    ----------
    load_N : float
        Contact load Q, N.
    length_mm : float
        Effective contact length L (L_we), mm.
    roller_radius_mm : float
        D_we/2, mm.
    raceway_radius_mm : float
        Raceway radius, mm.
    concave : bool
        False for the inner raceway (convex–convex), True for the outer one (convex–concave).
    youngs_modulus_MPa, poissons_ratio : float
        E (MPa) and ν of roller and raceway.

    Returns
    -------
    HertzLineContact
        Half-width b (mm), peak pressure p_h (MPa) and Palmgren approach (mm) of this contact.

    Notes
    -----
    b = √(4QR'/(πLE*)), p_h = 2Q/(πLb) (Johnson, Contact Mechanics, §4.3). For steel
    (E = 206 GPa, ν = 0.3) b = 3.354·10⁻³·√(Q/(L·Σρ)), Gao et al.'s eq. 22 with Σρ = 1/R'.
    """
    r_red = reduced_radius(roller_radius_mm, raceway_radius_mm, concave=concave)
    e_star = composite_modulus(youngs_modulus_MPa, poissons_ratio)
    b = hertz_half_width(load_N, length_mm, r_red, e_star)
    return HertzLineContact(
        half_width_mm=b,
        peak_pressure_MPa=hertz_peak_pressure(load_N, length_mm, b),
        approach_mm=palmgren_approach(load_N, length_mm),
    )


def stribeck_max_roller_load(bearing_load_N: float, rollers: int, factor: float = STRIBECK_FACTOR) -> float:
    """Load on the most loaded roller of a radially loaded bearing, N: Q_max = factor·F_r/Z.

    The default 4.6 is Gao et al.'s eq. 21. For zero clearance the line-contact load integral
    gives about 4.08 (Harris & Kotzalas); Stribeck's 4.37 is the point-contact value and larger
    factors (4.6, 5) allow for clearance. Pass ``factor`` to choose.

    Parameters
    ----------
    bearing_load_N : float
        Radial bearing load F_r, N.
    rollers : int
        Number of rollers Z.
    factor : float
        Stribeck factor.
    """
    if rollers <= 0:
        raise ValueError("rollers must be positive")
    return factor * bearing_load_N / rollers


def crank_bearing_hertz(
    bearing: CrankBearing,
    bearing_load_N: float,
    *,
    youngs_modulus_MPa: float = 206000.0,
    poissons_ratio: float = 0.3,
    stribeck_factor: float = STRIBECK_FACTOR,
) -> tuple[HertzLineContact, HertzLineContact]:
    """Hertz contacts of the most loaded roller of a crank bearing (rigid estimate).

    The roller load is Stribeck's Q_max = 4.6·F/Z (:func:`stribeck_max_roller_load`); the
    inner raceway is the eccentric, radius (D_m − D_we)/2, convex; the outer raceway is the disc
    bore, radius ``bearing.bore_radius``, concave; the contact length is L_we.

    Parameters
    ----------
    bearing : CrankBearing
    bearing_load_N : float
        Bearing load F, N (e.g. the maximum of the load cycle).
    youngs_modulus_MPa, poissons_ratio : float
        Material of rollers and raceways.
    stribeck_factor : float
        See :func:`stribeck_max_roller_load`.

    Returns
    -------
    (inner, outer) : tuple of HertzLineContact
    """
    q = stribeck_max_roller_load(bearing_load_N, bearing.rollers, stribeck_factor)
    return roller_raceway_contacts(bearing, q, youngs_modulus_MPa=youngs_modulus_MPa,
                                   poissons_ratio=poissons_ratio)


def roller_raceway_contacts(
    bearing: CrankBearing,
    roller_load_N: float,
    *,
    youngs_modulus_MPa: float = 206000.0,
    poissons_ratio: float = 0.3,
) -> tuple[HertzLineContact, HertzLineContact]:
    """Hertz contacts of one roller carrying ``roller_load_N`` (N) with its two raceways.

    Inner raceway: the eccentric, radius (D_m − D_we)/2, convex; outer raceway: the disc bore,
    radius ``bearing.bore_radius``, concave; contact length L_we (:func:`hertz_line_contact`).

    Returns
    -------
    (inner, outer) : tuple of HertzLineContact
    """
    r_roller = 0.5 * bearing.roller_diameter
    common = dict(youngs_modulus_MPa=youngs_modulus_MPa, poissons_ratio=poissons_ratio)
    inner = hertz_line_contact(roller_load_N, bearing.roller_length, r_roller, bearing.inner_raceway_radius,
                               concave=False, **common)
    outer = hertz_line_contact(roller_load_N, bearing.roller_length, r_roller, bearing.bore_radius,
                               concave=True, **common)
    return inner, outer


def _case_contacts(case: Case, q: float) -> tuple[HertzLineContact, HertzLineContact]:
    return roller_raceway_contacts(case.crank_bearing, q, youngs_modulus_MPa=case.material.youngs_modulus,
                                   poissons_ratio=case.material.poissons_ratio)


def rigid_ring_factor(rollers: int) -> float:
    """k of the rigid-ring most loaded roller Q_max = k·F_r/Z of a radially loaded line-contact
    bearing without clearance, one roller on the load line (the largest over the cage positions):
    k = Z/Σ_j cos(2πj/Z)₊^(19/9) (Stribeck's method with the line contact's load-deflection
    exponent 10/9; Harris & Kotzalas). 4.086 for Z = 14, → 4.08 for many rollers (the classic
    4.6 or 5 allow for a clearance, Gao et al.'s eq. 21 uses 4.6)."""
    if rollers <= 0:
        raise ValueError("rollers must be positive")
    c = np.clip(np.cos(2.0 * np.pi * np.arange(rollers) / rollers), 0.0, None)
    return float(rollers / np.sum(c ** (19.0 / 9.0)))


#: What the rigid most loaded roller is, for reports and summary.json (one definition everywhere).
RIGID_ROLLER_MODEL = ("rigid rings (Stribeck's method): the bearing force shared by the rollers at their cage "
                      "positions, Palmgren line contact, the case's radial clearance")


def _largest_roller(case: Case, theta: np.ndarray, forces: np.ndarray, loads: np.ndarray, source: str) -> RollerHertz:
    """The largest of a cycle's roller loads (n, N, Z) as a RollerHertz, with its factor Z·Q/|F|."""
    k, i, j = first_max(loads)
    q = float(loads[k, i, j])
    f = float(np.linalg.norm(forces[k, i]))
    factor = case.crank_bearing.rollers * q / f if f > 0 else None
    return RollerHertz(source, q, *_case_contacts(case, q), bearing=int(i), roller=int(j),
                       theta_deg=math.degrees(float(theta[k])), factor=factor)


def most_loaded_roller_hertz(case: Case, theta: np.ndarray, bearing_forces: np.ndarray,
                             roller_loads: np.ndarray | None, rigid_forces: np.ndarray | None,
                             rigid_roller_loads: np.ndarray | None,
                             flexible_ring_loads: np.ndarray) -> dict[str, RollerHertz]:
    """Hertz pressures of the most loaded roller of a load cycle: the largest roller load over the
    cycle's crank angles, bearings and rollers, from the FE rollers, from the rigid rings
    (:data:`RIGID_ROLLER_MODEL`) under the handbook forces and under the FE bearing forces.

    Parameters
    ----------
    case : Case
        Crank bearing and material (rollers and raceways of the disc's material).
    theta : ndarray (n,)
        Crank angles of the cycle, rad.
    bearing_forces : ndarray (n, N, 2)
        FE force of every bearing on the disc, N.
    roller_loads : ndarray (n, N, Z) or None
        FE roller loads, N (None for a bearing model without discrete rollers).
    rigid_forces : ndarray (n, N, 2) or None
        Handbook bearing forces, N; None where the handbook is not defined (Zp − Zc ≠ 1).
    rigid_roller_loads : ndarray (n, N, Z) or None
        Their rigid-ring roller loads (:func:`rvfem.evaluate.roller_slices.case_rigid_roller_loads`), N.
    flexible_ring_loads : ndarray (n, N, Z)
        The rigid-ring roller loads under the FE bearing forces, N.

    Returns
    -------
    dict of str to RollerHertz
        ``"stribeck_flexible"`` always, ``"stribeck_rigid"`` with a handbook load and ``"fe_rollers"``
        when ``roller_loads`` is given.
    """
    out = {}
    if roller_loads is not None:
        out["fe_rollers"] = _largest_roller(case, theta, bearing_forces, roller_loads, "fe_rollers")
    if rigid_forces is not None and rigid_roller_loads is not None:
        out["stribeck_rigid"] = _largest_roller(case, theta, rigid_forces, rigid_roller_loads, "stribeck_rigid")
    out["stribeck_flexible"] = _largest_roller(case, theta, bearing_forces, flexible_ring_loads, "stribeck_flexible")
    return out
