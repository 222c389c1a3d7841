"""Evaluation of crank-bearing loads: speed, ISO 281 rating and life, duty cycles, Hertz contact.

Plain functions of numbers (loads in N, lengths in mm, moduli and pressures in MPa, speeds in rpm,
lives in hours); :func:`crank_bearing_rating` and :func:`crank_bearing_hertz` read a
:class:`~rvfem.case.CrankBearing` for convenience.

Sources
-------
* Gao, Li, Zhang, Ji, Wang, *Lifespan evaluation for a standard RV reducer based on fatigue
  strength theory* (eqs. 11-14 rating and life, 16-19 duty cycle, 20-22 Hertz, with the Stribeck
  roller load).
* Li et al., *Life calculation of the swivel-arm bearing of an RV reducer considering cycloid pitch
  error* (eqs. 14-19, the same rating and life).
* ISO 281:2007, *Rolling bearings - Dynamic load ratings and rating life*, and its explanatory
  notes ISO/TR 1281-1.
* K. L. Johnson, *Contact Mechanics*, Cambridge University Press 1985, §4.3 (two cylinders in line
  contact).
* T. A. Harris, M. N. Kotzalas, *Rolling Bearing Analysis* (Palmgren's load-deflection relation of
  a roller-raceway line contact; Stribeck's maximum roller load).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Iterable

from .case import CrankBearing, DutyRow

__all__ = [
    "HertzLineContact",
    "DutyCycleLife",
    "bearing_speed_rpm",
    "dynamic_load_rating",
    "crank_bearing_rating",
    "rating_life_hours",
    "duty_cycle_life",
    "constant_load_life_hours",
    "composite_modulus",
    "reduced_radius",
    "hertz_half_width",
    "hertz_peak_pressure",
    "palmgren_approach",
    "hertz_line_contact",
    "stribeck_max_roller_load",
    "crank_bearing_hertz",
    "roller_raceway_contacts",
    "life_ratio",
    "ROLLER_LIFE_EXPONENT",
    "STRIBECK_FACTOR",
]

logger = logging.getLogger(__name__)

#: Life exponent of roller bearings (ISO 281): L = (C/P)^(10/3).
ROLLER_LIFE_EXPONENT = 10.0 / 3.0

#: Stribeck factor of Gao et al.'s eq. 21, Q_max = 4.6·F_r/Z (see :func:`stribeck_max_roller_load`).
STRIBECK_FACTOR = 4.6


# --------------------------------------------------------------------------------------------
# Results
# --------------------------------------------------------------------------------------------


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
class DutyCycleLife:
    """Equivalent operating point and service life of a load spectrum (Palmgren-Miner).

    Attributes
    ----------
    equivalent_torque_Nm : float
        T_m = [Σ t_i n_i T_i^(10/3) / Σ t_i n_i]^(3/10), N·m.
    equivalent_speed_rpm : float
        n_m = Σ t_i n_i / Σ t_i, rpm (output speed).
    service_life_h : float
        L = L0·n0·T0^(10/3) / (n_m·T_m^(10/3)), hours.
    """

    equivalent_torque_Nm: float
    equivalent_speed_rpm: float
    service_life_h: float


# --------------------------------------------------------------------------------------------
# Speed, rating, life
# --------------------------------------------------------------------------------------------


def bearing_speed_rpm(output_speed_rpm: float, pin_count: int, teeth: int) -> float:
    """Speed of the crank bearing: eccentric relative to the disc.

    n_b = n_out·Zp/(Zp − Zc). For a one-tooth difference this is n_out·Zc + n_out (Gao et al.,
    text before eq. 14: 15 rpm × 39 + 15 rpm = 600 rpm for the CRV-80E).

    Parameters
    ----------
    output_speed_rpm : float
        Output (carrier) speed n_out, rpm.
    pin_count, teeth : int
        Zp and Zc.

    Returns
    -------
    float
        n_b, rpm.
    """
    if pin_count <= teeth:
        raise ValueError(f"pin_count ({pin_count}) must exceed teeth ({teeth})")
    return output_speed_rpm * pin_count / (pin_count - teeth)


def dynamic_load_rating(
    rollers: int,
    roller_diameter: float,
    roller_length: float,
    pitch_diameter: float,
    *,
    b_m: float = 1.1,
    lambda_nu: float = 0.83,
    rows: int = 1,
    contact_angle_deg: float = 0.0,
    fc_constant: float = 208.0,
) -> float:
    """Basic dynamic radial load rating C of a radial roller bearing (ISO 281, line contact).

    C = b_m·f_c·(i·L_we·cos α)^(7/9)·Z^(3/4)·D_we^(29/27) with

    f_c = 208·λν·γ^(2/9)·(1 − γ)^(29/27)/(1 + γ)^(1/4)
          ·{1 + [1.04·((1 − γ)/(1 + γ))^(143/108)]^(9/2)}^(−2/9),  γ = D_we·cos α / D_m.

    Gao et al., eqs. 11-13 (and Li et al., eqs. 15-19) write the single-row, α = 0 form. Both
    papers print the constant as 208, which reproduces their ratings (21948.7 N and 28378.5 N);
    ISO/TR 1281-1 derives it as 207.9 (0.05 % lower), available through ``fc_constant``.

    Parameters
    ----------
    rollers : int
        Number of rollers per row Z.
    roller_diameter : float
        D_we, mm.
    roller_length : float
        Effective roller length L_we, mm.
    pitch_diameter : float
        D_m (D_pw), mm.
    b_m : float
        Rating factor for contemporary material and manufacturing quality (1.1 for radial roller
        bearings in ISO 281).
    lambda_nu : float
        Product λ·ν of the edge-stress and ring-accuracy reduction factors (0.83 in both papers).
    rows : int
        Number of rows i.
    contact_angle_deg : float
        Nominal contact angle α, degrees (0 for a radial cylindrical/needle roller bearing).
    fc_constant : float
        Leading constant of f_c (see above).

    Returns
    -------
    float
        C, N.
    """
    if min(rollers, roller_diameter, roller_length, pitch_diameter, rows) <= 0:
        raise ValueError("rollers, roller_diameter, roller_length, pitch_diameter and rows must be positive")
    cos_a = math.cos(math.radians(contact_angle_deg))
    gamma = roller_diameter * cos_a / pitch_diameter
    if not 0.0 < gamma < 1.0:
        raise ValueError(f"gamma = D_we cos(alpha)/D_m must lie in (0, 1), got {gamma}")
    ratio = (1.0 - gamma) / (1.0 + gamma)
    f_c = (
        fc_constant
        * lambda_nu
        * gamma ** (2.0 / 9.0)
        * (1.0 - gamma) ** (29.0 / 27.0)
        / (1.0 + gamma) ** 0.25
        * (1.0 + (1.04 * ratio ** (143.0 / 108.0)) ** 4.5) ** (-2.0 / 9.0)
    )
    return (
        b_m
        * f_c
        * (rows * roller_length * cos_a) ** (7.0 / 9.0)
        * rollers**0.75
        * roller_diameter ** (29.0 / 27.0)
    )


def crank_bearing_rating(bearing: CrankBearing) -> float:
    """Dynamic load rating C of a case's crank bearing (single row, α = 0), N.

    See :func:`dynamic_load_rating`; uses Z, D_we, L_we, D_m, b_m and λν from the case.
    """
    return dynamic_load_rating(
        bearing.rollers,
        bearing.roller_diameter,
        bearing.roller_length,
        bearing.pitch_diameter,
        b_m=bearing.b_m,
        lambda_nu=bearing.lambda_nu,
    )


def rating_life_hours(
    rating_N: float, equivalent_load_N: float, bearing_speed_rpm: float,
    exponent: float = ROLLER_LIFE_EXPONENT,
) -> float:
    """Basic rating life L10h in hours (ISO 281).

    L10h = 10⁶/(60·n_b)·(C/F_m)^(10/3).

    Gao et al.'s eq. 14 carries an extra Z_p in the denominator; their L0 = 6008 h for the CRV-80E
    only comes out without it (at n_b = 600 rpm), so it is left out here, as in Li et al., eq. 14.

    Parameters
    ----------
    rating_N : float
        Dynamic load rating C, N.
    equivalent_load_N : float
        Equivalent bearing load F_m over the load cycle, N.
    bearing_speed_rpm : float
        Speed of the bearing n_b (eccentric relative to the disc), rpm.
    exponent : float
        Life exponent (10/3 for roller bearings).

    Returns
    -------
    float
        L10h, hours (infinite for zero load).
    """
    if rating_N <= 0 or bearing_speed_rpm <= 0:
        raise ValueError("rating_N and bearing_speed_rpm must be positive")
    if equivalent_load_N < 0:
        raise ValueError(f"equivalent_load_N must be non-negative, got {equivalent_load_N}")
    if equivalent_load_N == 0:
        return math.inf
    return 1.0e6 / (60.0 * bearing_speed_rpm) * (rating_N / equivalent_load_N) ** exponent


def constant_load_life_hours(
    rated_life_h: float, rated_speed_rpm: float, rated_torque_Nm: float,
    speed_rpm: float, torque_Nm: float, exponent: float = ROLLER_LIFE_EXPONENT,
) -> float:
    """Life at another constant operating point, scaled from the rated life.

    The bearing load is proportional to the torque and the bearing speed to the output speed, so
    L = L0·(n0/n)·(T0/T)^(10/3) (Gao et al., eq. 15 rearranged).

    Parameters
    ----------
    rated_life_h : float
        L0 at (n0, T0), hours.
    rated_speed_rpm, rated_torque_Nm : float
        n0 (output, rpm) and T0 (N·m).
    speed_rpm, torque_Nm : float
        The operating point (output speed rpm, torque N·m).
    exponent : float
        Life exponent.

    Returns
    -------
    float
        Life, hours (infinite at zero torque).
    """
    if torque_Nm == 0:
        return math.inf
    return rated_life_h * (rated_speed_rpm / speed_rpm) * (rated_torque_Nm / torque_Nm) ** exponent


def duty_cycle_life(
    rows: Iterable[DutyRow],
    rated_life_h: float,
    rated_speed_rpm: float,
    rated_torque_Nm: float,
    exponent: float = ROLLER_LIFE_EXPONENT,
) -> DutyCycleLife:
    """Equivalent torque, equivalent speed and service life of a load spectrum.

    Gao et al., eqs. 17-18 (Palmgren-Miner linear damage):

    T_m = [Σ t_i n_i T_i^(10/3) / Σ t_i n_i]^(3/10),   n_m = Σ t_i n_i / Σ t_i,
    L = L0·n0·T0^(10/3) / (n_m·T_m^(10/3)).

    This equals 1 / Σ (s_i / L_i) with s_i = t_i/Σt the time shares and L_i the constant-load
    lives of :func:`constant_load_life_hours`.

    Parameters
    ----------
    rows : iterable of DutyRow
        Time shares t_i (any positive unit; only ratios matter), output speeds n_i (rpm) and
        output torques T_i (N·m), e.g. ``case.loads.duty_cycle``.
    rated_life_h : float
        L0 at the rated point (n0, T0), hours.
    rated_speed_rpm, rated_torque_Nm : float
        n0 (rpm) and T0 (N·m) at which L0 was computed.
    exponent : float
        Life exponent (10/3).

    Returns
    -------
    DutyCycleLife
        T_m (N·m), n_m (rpm) and L (hours).
    """
    rows = tuple(rows)
    if not rows:
        raise ValueError("duty_cycle_life needs at least one row")
    t = [r.time_share for r in rows]
    n = [r.speed_rpm for r in rows]
    tq = [r.torque_Nm for r in rows]
    if min(t) <= 0 or min(n) <= 0 or min(tq) < 0:
        raise ValueError("duty-cycle rows need positive time shares and speeds and non-negative torques")
    sum_t = sum(t)
    sum_tn = sum(ti * ni for ti, ni in zip(t, n))
    sum_tnT = sum(ti * ni * Ti**exponent for ti, ni, Ti in zip(t, n, tq))
    t_m = (sum_tnT / sum_tn) ** (1.0 / exponent)
    n_m = sum_tn / sum_t
    damage_rate = sum_tnT / sum_t  # = n_m·T_m^p
    life = math.inf if damage_rate == 0 else rated_life_h * rated_speed_rpm * rated_torque_Nm**exponent / damage_rate
    return DutyCycleLife(equivalent_torque_Nm=t_m, equivalent_speed_rpm=n_m, service_life_h=life)


def life_ratio(rigid_load_N: float, flexible_load_N: float, exponent: float = ROLLER_LIFE_EXPONENT) -> float:
    """Ratio of the flexible-model life to the rigid-model life, L_flex/L_rigid = (F_rigid/F_flex)^(10/3).

    Parameters
    ----------
    rigid_load_N, flexible_load_N : float
        Equivalent bearing loads of the two models, N.
    exponent : float
        Life exponent (10/3 for roller bearings).

    Returns
    -------
    float
        Dimensionless ratio; e.g. +15 % load gives 1.15^(−10/3) ≈ 0.63 (37 % less life).
    """
    if rigid_load_N < 0 or flexible_load_N <= 0:
        raise ValueError("loads must be positive")
    return (rigid_load_N / flexible_load_N) ** exponent


# --------------------------------------------------------------------------------------------
# Hertz line contact
# --------------------------------------------------------------------------------------------


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


PALMGREN_COEFFICIENT = 3.84e-5
"""Palmgren's line-contact approach coefficient, steel on steel: δ = 3.84e-5·Q^0.9/L^0.8 (mm, N)."""


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
