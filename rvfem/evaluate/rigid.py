"""Rigid (handbook) model of the crank-bearing loads and of the pin forces.

Everything here assumes rigid bodies, zero clearances, no friction and an unmodified profile: the
textbook load sharing that the finite-element chain must reproduce in its rigid limit.

Sources
-------
* Gao, Li, Zhang, Ji, Wang, *Lifespan evaluation for a standard RV reducer based on fatigue
  strength theory* (CRV-80E), eqs. 4-10: pin-force resultant, its split over the N crank
  bearings, the bearing load F(θ) over one crank turn and its fourth-power mean.
* Li et al., *Life calculation of the swivel-arm bearing of an RV reducer considering cycloid pitch
  error*, eqs. 1-13: the same model written out, with F_3 = ΣP_y / N (Gao et al.'s eq. 6 prints
  F_3 = (k_y / N)·ΣP_y; their numbers only come out with ΣP_y / N, which is what is used here).
* The classical pin-force distribution of cycloid drives,
  F_i = F_max sin φ_i / √(1 + K1² − 2 K1 cos φ_i), F_max = 4 T_disc / (K1 Zc Rp).

Tooth difference
----------------
The handbook model and the classical pin-force distribution are derived for a one-tooth difference
Zp − Zc = 1. For any other difference they are "not defined" (:func:`handbook_applicable`,
:func:`classical_applicable` say why) and the flexible results are compared with the reference
that holds for any tooth difference, the equal share of the FE pin resultant
(:func:`references`, :func:`rvfem.evaluate.compare.equal_share_forces`).

Conventions (shared with the flexible model)
--------------------------------------------
Carrier frame
    Origin on the reducer axis, axes fixed to the output carrier. Crank i sits at
    r0·(cos α_i, sin α_i), α_i = ``case.cranks.angles_deg[i]``.
Crank angle θ
    Angle of the eccentric (the vector from a crank's axis to the centre of its eccentric) measured
    counter-clockwise from the carrier x axis. All cranks turn together, so one θ describes the
    mechanism. θ is in radians in this module.
Disc frame
    Origin at the disc centre, axes parallel to the carrier's: relative to the carrier the disc
    translates on a circle of radius e and does not rotate. The disc centre is at e·(cos θ, sin θ)
    in the carrier frame, bore i at r0·(cos α_i, sin α_i) in the disc frame, and the pin-ring
    centre at −e·(cos θ, sin θ) in the disc frame. All force vectors below are in this frame.
Pins
    Pin j (j = 0 … Zp − 1) is at angle ψ_j = 2πj/Zp + θ·(Zp − Zc)/Zp about the pin-ring centre
    (seen from the disc the ring turns by one pin pitch per crank turn for a one-tooth
    difference). φ_j = ψ_j − θ is its angle measured from the eccentricity direction.
Torque
    T_disc = T_out / discs (N·mm) is the moment of the pin forces about the **disc centre**, the
    convention behind the handbook's ΣP_x = T / (2 e Zc) (= T_disc / (e Zc) for two discs). About
    the reducer axis the same forces have the moment T_disc·Zp/Zc. For positive torque the pins
    with 0 < φ < π are loaded and act on the disc with the clockwise moment −T_disc; the crank
    bearings act on the disc with +T_disc. A negative torque (reversed) loads the pins with
    −π < φ < 0, the mirror image about the eccentricity axis.
Bearing loads
    The force of bearing i on the disc is F_i = F2·u⊥ − F3·u + F1·t_i with u = (cos θ, sin θ),
    u⊥ = (−sin θ, cos θ) and t_i = (−sin α_i, cos α_i). In the bearing's own radial/tangential
    axes this is the handbook's F_t = F1 + F2 cos β − F3 sin β (along t_i) and
    F_r = F2 sin β + F3 cos β (towards the disc centre) with the local angle β = θ − α_i, so
    the N curves are the same curve shifted by the crank positions (360°/N for equal spacing).
"""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rvfem._arrays import readonly
from rvfem.case.definition import Case
from rvfem.errors import CaseError
from rvfem.evaluate.iso281 import rating_life_hours
from rvfem.geometry.kinematics import load_cycle_angles

__all__ = [
    "HandbookComponents",
    "RigidLoads",
    "BearingLoadSummary",
    "PinForces",
    "load_cycle_angles",
    "handbook_applicable",
    "classical_applicable",
    "Reference",
    "References",
    "references",
    "undefined_loads",
    "handbook_components",
    "handbook_bearing_loads",
    "handbook_load_extremes",
    "equivalent_load",
    "summarize_bearing_loads",
    "summarize_loads",
    "with_rating_life",
    "classical_pin_forces",
]

logger = logging.getLogger(__name__)


# --------------------------------------------------------------------------------------------
# Results
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class HandbookComponents:
    """The constant force components of the handbook model (Gao et al., eqs. 4-6).

    Attributes
    ----------
    k : float
        Short-amplitude coefficient k = e·Zp/Rp, dimensionless.
    k_y : float
        Ratio of the radial to the tangential pin-force resultant,
        k_y = (2/π)·[1/k + (k² − 1)/(2k²)·ln((1 + k)/(1 − k))], dimensionless (eq. 5).
    disc_torque_Nmm : float
        T_disc = T_out / discs, N·mm: moment of the pin forces about the disc centre.
    sum_px : float
        ΣP_x = T_disc / (e·Zc), N: tangential pin-force resultant (eq. 4 for two discs).
    sum_py : float
        ΣP_y = k_y·ΣP_x, N: radial pin-force resultant.
    f1 : float
        F1 = T_disc / (N·r0), N: torque share of one bearing, tangential to the crank circle.
    f2 : float
        F2 = ΣP_x / N, N.
    f3 : float
        F3 = ΣP_y / N, N (not the misprinted (k_y/N)·ΣP_y of Gao et al.'s eq. 6).
    """

    k: float
    k_y: float
    disc_torque_Nmm: float
    sum_px: float
    sum_py: float
    f1: float
    f2: float
    f3: float


@dataclass(frozen=True, eq=False)
class RigidLoads:
    """Crank-bearing loads of the rigid handbook model over a set of crank angles.

    Attributes
    ----------
    theta : ndarray, shape (n_theta,)
        Crank angles θ, rad (see the module docstring).
    crank_angles : ndarray, shape (N,)
        Angular positions α_i of the cranks, rad.
    fx, fy : ndarray, shape (N, n_theta)
        Force of each bearing on the disc, N, in the disc frame.
    magnitude : ndarray, shape (N, n_theta)
        |F_i|, N (the handbook F(θ − α_i), eq. 8).
    tangential : ndarray, shape (N, n_theta)
        Handbook F_t, N: component along the crank-circle tangent t_i (eq. 7).
    radial : ndarray, shape (N, n_theta)
        Handbook F_r, N: component towards the disc centre (eq. 7).
    components : HandbookComponents
        The constant components the curves are made of.
    """

    theta: np.ndarray
    crank_angles: np.ndarray
    fx: np.ndarray
    fy: np.ndarray
    magnitude: np.ndarray
    tangential: np.ndarray
    radial: np.ndarray
    components: HandbookComponents

    @property
    def bearing_count(self) -> int:
        """Number of crank bearings N."""
        return int(self.magnitude.shape[0])


@dataclass(frozen=True)
class BearingLoadSummary:
    """Extremes, equivalent value and life of one bearing's load over a sampled cycle.

    The one load-statistics record of rvfem, for the handbook, the finite-element and the
    equal-share curves alike (:func:`summarize_loads`, :func:`rvfem.evaluate.compare.rigid_vs_flexible`).

    Attributes
    ----------
    bearing : int
        Bearing index (0-based, order of ``case.cranks.angles_deg``).
    max_N, min_N : float
        Largest and smallest sampled load magnitude, N.
    max_at_deg, min_at_deg : float
        Crank angle θ at which they occur, degrees in [0, 360).
    equivalent_N : float
        (mean F^p)^(1/p) over the cycle, N.
    exponent : float
        The exponent p used.
    L10h : float or None
        ISO 281 rating life with this equivalent load, hours (:func:`rvfem.evaluate.iso281.rating_life_hours`);
        None until a rating and a speed are applied (:func:`with_rating_life`).
    """

    bearing: int
    max_N: float
    max_at_deg: float
    min_N: float
    min_at_deg: float
    equivalent_N: float
    exponent: float
    L10h: float | None = None


@dataclass(frozen=True, eq=False)
class PinForces:
    """Classical rigid pin-force distribution over a set of crank angles.

    Attributes
    ----------
    theta : ndarray, shape (n_theta,)
        Crank angles θ, rad.
    pin_angle : ndarray, shape (Zp, n_theta)
        ψ_j, rad: angle of pin j about the pin-ring centre, in the disc/carrier axes.
    phi : ndarray, shape (Zp, n_theta)
        φ_j = ψ_j − θ wrapped to (−π, π], rad: pin angle from the eccentricity direction.
    x, y : ndarray, shape (Zp, n_theta)
        Pin centres in the disc frame, mm.
    magnitude : ndarray, shape (Zp, n_theta)
        Pin force, N (zero for the unloaded pins, sin φ ≤ 0).
    fx, fy : ndarray, shape (Zp, n_theta)
        Force of each pin on the disc, N, in the disc frame; it acts along the line from the pin
        centre through the pitch point.
    f_max : ndarray, shape (n_theta,)
        Amplitude F_max used at each angle, N.
    """

    theta: np.ndarray
    pin_angle: np.ndarray
    phi: np.ndarray
    x: np.ndarray
    y: np.ndarray
    magnitude: np.ndarray
    fx: np.ndarray
    fy: np.ndarray
    f_max: np.ndarray


# --------------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------------




def with_rating_life(summary: BearingLoadSummary, rating_N: float, bearing_speed_rpm: float) -> BearingLoadSummary:
    """``summary`` with its ISO 281 life L10h (hours) for the rating C (N) at the bearing speed n_b (rpm)."""

    return dataclasses.replace(summary, L10h=rating_life_hours(rating_N, summary.equivalent_N, bearing_speed_rpm))


def _as_theta(theta: float | Sequence[float] | np.ndarray) -> np.ndarray:
    th = np.atleast_1d(np.asarray(theta, dtype=float))
    if th.ndim != 1:
        raise ValueError(f"theta must be a scalar or a 1-D array, got shape {th.shape}")
    return th


def _tooth_difference_reason(case: Case, what: str, why: str) -> str:
    """"" for a one-tooth difference, else the reason ``what`` is not defined (one line)."""
    d = case.pins.count - case.cycloid.teeth
    if d == 1:
        return ""
    return f"not defined for Zp − Zc ≠ 1: 'pins.count' − 'cycloid.teeth' = {d}; {what} {why}"


def handbook_applicable(case: Case) -> tuple[bool, str]:
    """Whether the handbook crank-bearing model applies.

    Returns
    -------
    (bool, str)
        True and "" if it does; False and the reason (one line, naming the case keys) if not.
        It assumes a one-tooth difference (Zp = Zc + 1: the pitch point at e·Zc from the disc
        centre, k_y and ΣP_x = T/(e·Zc) of Gao et al.) and equally spaced cranks (equal sharing).
        For Zp − Zc ≠ 1 the FE model runs and is compared with the reference that exists, the
        equal share of its own pin resultant (:func:`references`); the handbook column is "not
        defined for Zp − Zc ≠ 1".
    """
    reason = _tooth_difference_reason(
        case, "the handbook crank-bearing model", "(Gao et al.'s pin-force resultant ΣP_x = T/(e·Zc), "
        "k_y) assumes a one-tooth difference (Zp = Zc + 1)")
    reason = reason or _crank_spacing_reason(case)
    return (not reason), reason


def _crank_spacing_reason(case: Case) -> str:
    """"" for equally spaced cranks, else why equal sharing does not apply (one line)."""
    n = case.cranks.count
    angles = np.sort(np.mod(case.cranks.angles_deg, 360.0))
    gaps = np.diff(np.append(angles, angles[0] + 360.0))
    if not np.allclose(gaps, 360.0 / n, rtol=0.0, atol=1e-6):
        return (f"'cranks.angles_deg' {list(case.cranks.angles_deg)} are not equally spaced by "
                f"{360.0 / n:g}°: the handbook equal-share model needs equally spaced cranks")
    return ""


def classical_applicable(case: Case) -> tuple[bool, str]:
    """Whether the classical rigid pin-force distribution applies (:func:`classical_pin_forces`).

    Returns
    -------
    (bool, str)
        True and "" for a one-tooth difference; False and the reason otherwise.

    Notes
    -----
    Its derivation: a rigid disc turns by a small angle about its centre against equally stiff
    pins with zero clearance, every pin on the loaded half touches the profile, and each contact
    normal passes through the pitch point, so each pin force is proportional to its lever arm.
    For Zp − Zc = 1 every pin touches the unmodified profile at every crank angle (the pin centres
    run along the one closed trochoid the profile is parallel to), and the stiff-disc FE
    reproduces the distribution within 0.1 % of the peak pin force. For Zp − Zc > 1 the tooth tips
    are trimmed corners: only about half the pins touch, and a pin engages over a tip corner
    through a gap that closes as the square of the crank angle (2.5 µm 10° before contact on the
    RV-40E stage with Zc = 38), so which pins carry load is set by the compliances, not by the
    geometry. The stiff-disc FE (disc 10⁶×, bores 10³× stiffer, linear pins of 3·10⁵ to
    3·10⁷ N/mm) departs from the touching-pin distribution by 76-80 % of the peak pin force there,
    so no rigid pin-force reference is given for Zp − Zc ≠ 1.
    """
    reason = _tooth_difference_reason(
        case, "the classical pin-force distribution", "assumes that every pin on the loaded half touches the "
        "profile; with trimmed tooth tips pins engage over the tip corners through micrometre gaps, so "
        "the load set depends on the compliances")
    return (not reason), reason


@dataclass(frozen=True)
class Reference:
    """One rigid reference of the flexible results: whether it is defined for a case, and why.

    Attributes
    ----------
    defined : bool
        True if the reference is computed and compared with.
    why : str
        One line: what the reference assumes and why it holds, or why it is not defined.
    """

    defined: bool
    why: str


@dataclass(frozen=True)
class References:
    """The rigid references of a case (:func:`references`).

    Attributes
    ----------
    handbook : Reference
        The handbook crank-bearing loads (Gao et al., eqs. 4-10).
    classical_pin_forces : Reference
        The classical rigid pin-force distribution (:func:`classical_pin_forces`).
    equal_share : Reference
        The equal share of the FE pin resultant (:func:`rvfem.evaluate.compare.equal_share_forces`).
    """

    handbook: Reference
    classical_pin_forces: Reference
    equal_share: Reference

    @property
    def bearing_loads(self) -> str:
        """The reference the flexible bearing loads are compared with (deltas, life ratios, the first
        attribution step): ``"handbook"`` where it is defined, else ``"equal_share"``."""
        return "handbook" if self.handbook.defined else "equal_share"

    def items(self) -> tuple[tuple[str, Reference], ...]:
        """(key, reference) pairs in the order the outputs list them."""
        return (("handbook", self.handbook), ("classical_pin_forces", self.classical_pin_forces),
                ("equal_share", self.equal_share))


REFERENCE_NAMES = {
    "handbook": "the handbook crank-bearing loads",
    "classical_pin_forces": "the classical pin-force distribution",
    "equal_share": "the equal share of the FE pin resultant",
}
"""The references in words (screen, report)."""


def references(case: Case, *, fe: bool = True) -> References:
    """Which rigid references a case is compared with, and why.

    Parameters
    ----------
    case : Case
    fe : bool
        True for a run with the FE load cycle (``rvfem run``); False for the rigid evaluation alone
        (``rvfem rigid``), where the equal share of the FE pin resultant is not computed.

    Returns
    -------
    References
        The handbook and the classical pin-force distribution are defined for a one-tooth
        difference (:func:`handbook_applicable`, :func:`classical_applicable`); the equal share of
        the FE pin resultant assumes only a rigid disc on rigid, equally loaded eccentrics and is
        defined for any tooth difference (with equally spaced cranks).
    """
    ok, reason = handbook_applicable(case)
    handbook = Reference(ok, reason if not ok else
                         "rigid disc on rigid eccentrics sharing the classical pin-force resultant equally "
                         "(Gao et al., eqs. 4-10); derived for a one-tooth difference")
    ok, reason = classical_applicable(case)
    classical = Reference(ok, reason if not ok else
                          "every pin touches the unmodified one-tooth-difference profile with its contact normal "
                          "through the pitch point, so a rigid disc loads each pin in proportion to its lever arm")
    spacing = _crank_spacing_reason(case)
    if spacing:
        share = Reference(False, spacing)
    elif fe:
        share = Reference(True, "each bearing carries 1/N of the FE pin-force resultant plus the torque share "
                                "T_disc/(N·r0) along its tangent: a rigid disc on rigid, equally loaded eccentrics, "
                                "for any tooth difference")
    else:
        share = Reference(False, "needs the FE pin-force resultant: computed by rvfem run, not by rvfem rigid")
    return References(handbook=handbook, classical_pin_forces=classical, equal_share=share)


def _check_handbook_applicable(case: Case) -> None:
    """Raise :class:`CaseError` where :func:`handbook_applicable` says no."""
    ok, reason = handbook_applicable(case)
    if not ok:
        raise CaseError(f"{case.source}: {reason}")


# --------------------------------------------------------------------------------------------
# Handbook crank-bearing loads
# --------------------------------------------------------------------------------------------


def handbook_components(case: Case) -> HandbookComponents:
    """Constant components of the handbook crank-bearing load (Gao et al., eqs. 4-6).

    Parameters
    ----------
    case : Case
        Uses e, Zc, Zp, Rp, N, r0, the output torque (N·m) and the number of discs.

    Returns
    -------
    HandbookComponents
        k, k_y, T_disc (N·mm), ΣP_x, ΣP_y, F1, F2, F3 (N).

    Raises
    ------
    CaseError
        If the cranks are not equally spaced or Zp − Zc ≠ 1 (outside the model's assumptions).

    Notes
    -----
    ΣP_x = T_disc/(e·Zc) with T_disc = T_out/discs is Gao et al.'s T/(2eZc) for two discs; T_disc
    is the moment about the disc centre (see the module docstring). A negative (reversed) torque
    loads the other half of the pins, the mirror image about the eccentricity axis: ΣP_x, F1 and F2
    change sign, ΣP_y = k_y·|ΣP_x| and F3 do not.
    """
    _check_handbook_applicable(case)
    e = case.cycloid.eccentricity
    zc = case.cycloid.teeth
    k = case.short_amplitude_coefficient
    k_y = (2.0 / math.pi) * (1.0 / k + (k * k - 1.0) / (2.0 * k * k) * math.log((1.0 + k) / (1.0 - k)))
    t_disc = case.loads.disc_torque_Nmm
    n = case.cranks.count
    sum_px = t_disc / (e * zc)
    # a reversed torque loads the mirror-image half of the pins (mirror about the eccentricity
    # axis): the torque-carrying ΣP_x changes sign, the component along the eccentricity does not
    sum_py = k_y * abs(sum_px)
    comp = HandbookComponents(
        k=k,
        k_y=k_y,
        disc_torque_Nmm=t_disc,
        sum_px=sum_px,
        sum_py=sum_py,
        f1=sum_px * e * zc / (n * case.cranks.circle_radius),
        f2=sum_px / n,
        f3=sum_py / n,
    )
    logger.debug("handbook components for %s: %s", case.name, comp)
    return comp


def handbook_bearing_loads(case: Case, theta: float | Sequence[float] | np.ndarray | None = None) -> RigidLoads:
    """Force of every crank bearing on the disc over the crank angles ``theta`` (rigid model).

    Parameters
    ----------
    case : Case
        The reducer (see :func:`handbook_components` for what is used).
    theta : float or array_like, optional
        Crank angles θ, rad (module docstring). Default: one full turn sampled with
        ``case.analysis.angle_step_deg`` (:func:`load_cycle_angles`).

    Returns
    -------
    RigidLoads
        Vectors (disc frame), magnitudes and handbook F_t, F_r of each bearing, N.

    Notes
    -----
    Bearing i sees the local angle β_i = θ − α_i; with it, Gao et al.'s eqs. 7-8 give
    F_t = F1 + F2 cos β − F3 sin β, F_r = F2 sin β + F3 cos β, F = √(F_t² + F_r²).
    """
    comp = handbook_components(case)
    th = load_cycle_angles(case.analysis.angle_step_deg) if theta is None else _as_theta(theta)
    logger.info("rigid handbook loads of %s: %d bearings at %d crank angles", case.name, case.cranks.count, th.size)
    alpha = np.radians(np.asarray(case.cranks.angles_deg, dtype=float))
    beta = th[None, :] - alpha[:, None]
    f_t = comp.f1 + comp.f2 * np.cos(beta) - comp.f3 * np.sin(beta)
    f_r = comp.f2 * np.sin(beta) + comp.f3 * np.cos(beta)
    # Back to the disc frame: F = F_t·t_i − F_r·a_i with a_i = (cos α, sin α), t_i = (−sin α, cos α).
    ca, sa = np.cos(alpha)[:, None], np.sin(alpha)[:, None]
    fx = -f_t * sa - f_r * ca
    fy = f_t * ca - f_r * sa
    return RigidLoads(
        theta=readonly(th, dtype=float),
        crank_angles=readonly(alpha, dtype=float),
        fx=readonly(fx, dtype=float),
        fy=readonly(fy, dtype=float),
        magnitude=readonly(np.hypot(f_t, f_r), dtype=float),
        tangential=readonly(f_t, dtype=float),
        radial=readonly(f_r, dtype=float),
        components=comp,
    )


def undefined_loads(case: Case, theta: float | Sequence[float] | np.ndarray | None = None) -> RigidLoads:
    """The handbook curves of a case outside the handbook model: every force NaN.

    Where :func:`handbook_applicable` says no (Zp − Zc ≠ 1), the rigid evaluation still has the
    layout of :class:`RigidLoads` so that code drawing or tabulating it needs no branch; NaN is
    "not defined" (``null`` in the JSON outputs). Only k = e·Zp/Rp, T_disc and the torque share
    F1 = T_disc/(N·r0) of the components are numbers; k_y, ΣP_x, ΣP_y, F2 and F3 are NaN.

    Parameters
    ----------
    case : Case
    theta : float or array_like, optional
        Crank angles θ, rad; default one turn at ``case.analysis.angle_step_deg``.
    """
    th = load_cycle_angles(case.analysis.angle_step_deg) if theta is None else _as_theta(theta)
    alpha = np.radians(np.asarray(case.cranks.angles_deg, dtype=float))
    nan = np.full((alpha.size, th.size), np.nan)
    t_disc = case.loads.disc_torque_Nmm
    comp = HandbookComponents(k=case.short_amplitude_coefficient, k_y=math.nan, disc_torque_Nmm=t_disc,
                              sum_px=math.nan, sum_py=math.nan,
                              f1=t_disc / (case.cranks.count * case.cranks.circle_radius), f2=math.nan, f3=math.nan)
    return RigidLoads(theta=readonly(th, dtype=float), crank_angles=readonly(alpha, dtype=float),
                      fx=readonly(nan), fy=readonly(nan), magnitude=readonly(nan), tangential=readonly(nan),
                      radial=readonly(nan), components=comp)


def handbook_load_extremes(components: HandbookComponents) -> tuple[float, float, float, float]:
    """Exact maximum and minimum of the handbook bearing load over a turn.

    Since F² = F1² + F2² + F3² + 2·F1·√(F2² + F3²)·cos(β + δ) with δ = atan2(F3, F2),
    F_max = |F1| + √(F2² + F3²) at β = −δ and F_min = |F1 − √(F2² + F3²)| at β = π − δ (for a
    reversed torque, F1 < 0, the two angles swap).

    Parameters
    ----------
    components : HandbookComponents

    Returns
    -------
    (F_max, beta_max, F_min, beta_min) : tuple of float
        Loads in N, local angles β = θ − α_i in rad, wrapped to [0, 2π).
    """
    amp = math.hypot(components.f2, components.f3)
    delta = math.atan2(components.f3, components.f2)
    two_pi = 2.0 * math.pi
    f1 = components.f1
    # F² = F1² + amp² + 2·F1·amp·cos(β + δ): the maximum where cos(β + δ) has the sign of F1
    at_max, at_min = ((-delta, math.pi - delta) if f1 >= 0 else (math.pi - delta, -delta))
    return (
        abs(f1) + amp,
        at_max % two_pi,
        abs(abs(f1) - amp),
        at_min % two_pi,
    )


def equivalent_load(load: np.ndarray | Sequence[float], exponent: float) -> np.ndarray | float:
    """Equivalent (power-mean) load over a uniformly sampled full cycle.

    F_m = (mean F^p)^(1/p), the discrete form of ((1/2π)∫F(θ)^p dθ)^(1/p) (Gao et al., eq. 9,
    with p = 4; ISO 281 uses p = 10/3 for roller bearings).

    Parameters
    ----------
    load : array_like
        Load magnitudes, N, sampled uniformly over one full cycle without repeating the end
        point; the mean is taken along the last axis.
    exponent : float
        p > 0.

    Returns
    -------
    float or ndarray
        F_m, N (one value per row for a 2-D input).
    """
    if not exponent > 0:
        raise ValueError(f"exponent must be positive, got {exponent!r}")
    f = np.asarray(load, dtype=float)
    if f.size == 0:
        raise ValueError("equivalent_load needs at least one sample")
    if np.any(f < 0):
        raise ValueError("equivalent_load expects load magnitudes (non-negative)")
    result = np.mean(f**exponent, axis=-1) ** (1.0 / exponent)
    return float(result) if np.ndim(result) == 0 else result


def summarize_bearing_loads(loads: RigidLoads, exponent: float) -> tuple[BearingLoadSummary, ...]:
    """Maximum, minimum (with the crank angles where they occur) and equivalent load per bearing.

    Parameters
    ----------
    loads : RigidLoads
        Loads sampled uniformly over one full turn (as :func:`handbook_bearing_loads` returns by
        default); the extremes are those of the samples.
    exponent : float
        Exponent p of the equivalent load.

    Returns
    -------
    tuple of BearingLoadSummary
        One per bearing, loads in N, angles in degrees.
    """
    return summarize_loads(loads.theta, loads.magnitude, exponent)


def summarize_loads(theta: np.ndarray, magnitude: np.ndarray, exponent: float) -> tuple[BearingLoadSummary, ...]:
    """:func:`summarize_bearing_loads` for any sampled load curves (rigid or finite-element).

    Parameters
    ----------
    theta : ndarray (n,)
        Crank angles, rad, uniformly covering one turn.
    magnitude : ndarray (N, n)
        Load magnitude of each bearing, N.
    exponent : float
        Exponent p of the equivalent load.
    """
    mags = np.asarray(magnitude, dtype=float)
    theta_deg = np.degrees(np.asarray(theta, dtype=float)) % 360.0
    eq = np.atleast_1d(equivalent_load(mags, exponent))
    out = []
    for i in range(mags.shape[0]):
        imax, imin = int(np.argmax(mags[i])), int(np.argmin(mags[i]))
        out.append(
            BearingLoadSummary(
                bearing=i,
                max_N=float(mags[i, imax]),
                max_at_deg=float(theta_deg[imax]),
                min_N=float(mags[i, imin]),
                min_at_deg=float(theta_deg[imin]),
                equivalent_N=float(eq[i]),
                exponent=float(exponent),
            )
        )
    return tuple(out)


# --------------------------------------------------------------------------------------------
# Classical pin forces
# --------------------------------------------------------------------------------------------


def classical_pin_forces(case: Case, theta: float | Sequence[float] | np.ndarray | None = None, *, exact_moment: bool = False) -> PinForces:
    """Classical rigid pin-force distribution (zero clearance, unmodified profile).

    F_j = F_max·sin φ_j / √(1 + K1² − 2·K1·cos φ_j) for the pins with sin φ_j > 0, zero for the
    others, with K1 = e·Zp/Rp and F_max = 4·T_disc/(K1·Zc·Rp); for a reversed torque (T_disc < 0)
    the pins with sin φ_j < 0 carry |F_max|·|sin φ_j|/√(…), the mirror image. Each force acts on the disc along
    the line from the pin centre through the pitch point P, which lies on the line of centres at
    e·Zc from the disc centre, on the side of the eccentric: P = e·Zc·(cos θ, sin θ) in the disc
    frame. Pin positions and φ_j follow the module docstring.

    Parameters
    ----------
    case : Case
    theta : float or array_like, optional
        Crank angles θ, rad. Default: one turn at ``case.analysis.angle_step_deg``.
    exact_moment : bool
        The textbook F_max replaces Σ sin²φ_j/(1 + K1² − 2K1 cos φ_j) over the loaded pins by its
        integral value Zp/4, so the moment of the pin forces about the disc centre equals T_disc
        only on average over a pin pitch (within about 0.1 % at any angle for Zp = 40). With
        ``exact_moment=True`` F_max is set at each angle from the discrete sum so that the moment
        is exactly T_disc (the form to compare with a finite-element solution in equilibrium).

    Returns
    -------
    PinForces
        Pin positions (mm) and forces (N) in the disc frame.

    Raises
    ------
    CaseError
        For Zp − Zc ≠ 1, where the distribution does not hold (:func:`classical_applicable` says
        why). It does not depend on the crank positions.
    """
    ok, reason = classical_applicable(case)
    if not ok:
        raise CaseError(f"{case.source}: {reason}")
    th = load_cycle_angles(case.analysis.angle_step_deg) if theta is None else _as_theta(theta)
    zp, zc = case.pins.count, case.cycloid.teeth
    rp, e = case.pins.circle_radius, case.cycloid.eccentricity
    k1 = e * zp / rp
    t_disc = case.loads.disc_torque_Nmm

    psi = 2.0 * np.pi * np.arange(zp)[:, None] / zp + th[None, :] * (zp - zc) / zp
    phi = np.angle(np.exp(1j * (psi - th[None, :])))  # wrapped to (−π, π]
    s2 = 1.0 + k1 * k1 - 2.0 * k1 * np.cos(phi)
    sin_phi = np.sin(phi) * math.copysign(1.0, t_disc)   # a reversed torque loads the other half
    loaded = sin_phi > 0.0
    shape = np.where(loaded, sin_phi / np.sqrt(s2), 0.0)
    if exact_moment:
        moment_sum = np.sum(np.where(loaded, sin_phi**2 / s2, 0.0), axis=0)
        f_max = abs(t_disc) / (e * zc * moment_sum)
    else:
        f_max = np.full(th.shape, 4.0 * abs(t_disc) / (k1 * zc * rp))
    magnitude = f_max[None, :] * shape

    ux, uy = np.cos(th)[None, :], np.sin(th)[None, :]
    x = rp * np.cos(psi) - e * ux
    y = rp * np.sin(psi) - e * uy
    dx = e * zc * ux - x
    dy = e * zc * uy - y
    dist = np.hypot(dx, dy)  # = Rp·√(1 + K1² − 2K1 cos φ)
    return PinForces(
        theta=readonly(th, dtype=float),
        pin_angle=readonly(psi, dtype=float),
        phi=readonly(phi, dtype=float),
        x=readonly(x, dtype=float),
        y=readonly(y, dtype=float),
        magnitude=readonly(magnitude, dtype=float),
        fx=readonly(magnitude * dx / dist, dtype=float),
        fy=readonly(magnitude * dy / dist, dtype=float),
        f_max=readonly(f_max, dtype=float),
    )
