"""ISO 281 rating and life of the crank bearings: bearing speed, dynamic load rating, L10h,
life at another operating point, duty cycles (Palmgren-Miner) and life ratios.

Plain functions of numbers (loads in N, lengths in mm, speeds in rpm, lives in hours);
:func:`crank_bearing_rating` and :func:`case_duty_cycle_life` read a case for convenience. The
formulas and where each comes from are collected in docs/theory.md.

Sources
-------
* Gao, Li, Zhang, Ji, Wang, *Lifespan evaluation for a standard RV reducer based on fatigue
  strength theory* (eqs. 11-14 rating and life, 15-19 duty cycle).
* Li et al., *Life calculation of the swivel-arm bearing of an RV reducer considering cycloid pitch
  error* (eqs. 14-19, the same rating and life).
* ISO 281:2007, *Rolling bearings - Dynamic load ratings and rating life*, and its explanatory
  notes ISO/TR 1281-1.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass
from typing import Iterable, Sequence

from rvfem.case.definition import Case, CrankBearing, DutyRow

__all__ = [
    "ROLLER_LIFE_EXPONENT",
    "DutyCycleLife",
    "bearing_speed_rpm",
    "case_bearing_speed_rpm",
    "dynamic_load_rating",
    "crank_bearing_rating",
    "rating_life_hours",
    "constant_load_life_hours",
    "duty_cycle_life",
    "case_duty_cycle_life",
    "life_ratio",
]

logger = logging.getLogger(__name__)

#: Life exponent of roller bearings (ISO 281): L = (C/P)^(10/3).
ROLLER_LIFE_EXPONENT = 10.0 / 3.0


# --------------------------------------------------------------------------------------------
# Results
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class DutyCycleLife:
    """Equivalent operating point and service life of a load spectrum (Palmgren-Miner).

    Attributes
    ----------
    rated_life_h : float
        L0, the life at the rated point (n0, T0) the spectrum is scaled from, hours.
    equivalent_torque_Nm : float
        T_m = [Σ t_i n_i T_i^(10/3) / Σ t_i n_i]^(3/10), N·m.
    equivalent_speed_rpm : float
        n_m = Σ t_i n_i / Σ t_i, rpm (output speed).
    service_life_h : float
        L = L0·n0·T0^(10/3) / (n_m·T_m^(10/3)), hours.
    """

    rated_life_h: float
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
    return DutyCycleLife(rated_life_h=rated_life_h, equivalent_torque_Nm=t_m, equivalent_speed_rpm=n_m, service_life_h=life)


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


def case_bearing_speed_rpm(case: Case) -> float:
    """Crank-bearing speed n_b of a case, rpm (:func:`bearing_speed_rpm` with its output speed,
    Zp and Zc)."""
    return bearing_speed_rpm(case.loads.speed_rpm, case.pins.count, case.cycloid.teeth)


def case_duty_cycle_life(case: Case, rated_lives_h: Sequence[float]) -> DutyCycleLife | None:
    """Service life of a case's duty cycle, scaled from its shortest-lived crank bearing.

    The rated point is the case's output speed and torque (``loads.speed_rpm``, ``loads.torque_Nm``)
    at which ``rated_lives_h`` were computed; the shortest of them is L0 of :func:`duty_cycle_life`.
    Rows with a reversed (negative) torque count with |T|.

    Parameters
    ----------
    case : Case
    rated_lives_h : sequence of float
        L10h of every crank bearing at the rated point, hours (rigid or flexible model).

    Returns
    -------
    DutyCycleLife or None
        None if the case has no duty cycle.
    """
    if not case.loads.duty_cycle:
        return None
    # a reversed torque loads the bearings with the mirror image of the forward loads (exactly in
    # the handbook model): the bearing load scales with |T|

    rows = [dataclasses.replace(r, torque_Nm=abs(r.torque_Nm)) for r in case.loads.duty_cycle]
    return duty_cycle_life(rows, min(rated_lives_h), case.loads.speed_rpm, abs(case.loads.torque_Nm))
