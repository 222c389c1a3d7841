"""Drive kinematics in the disc frame: pin and crank centres, pin–profile gaps, closest points.

Everything is in the **disc's body frame**: the disc centre is the origin, the disc does not move,
and the pins move around it. Lengths are mm, angles radians.

Kinematics
----------
The crank angle θ is the angle of the eccentric relative to the carrier, counted counter-clockwise
(docs/theory.md, "Kinematics"). The disc is carried by the cranks, so it translates with the
eccentric but keeps the carrier's orientation. With the pin housing fixed, its pin ``j`` at ``Rp·u(2πj/Zp)`` (pin 0 on
the housing's x axis), the disc centre at ``e·u(β)`` and the disc turned by ψ, the rolling condition
of the internal gear pair relative to the eccentric gives ψ = −β·(Zp − Zc)/Zc, and θ = β − ψ =
β·Zp/Zc. Expressing the pin centres in the disc frame, ``R(−ψ)·(p_j − e·u(β))``, gives

    c_j(θ) = Rp·u(2πj/Zp + θ·(Zp − Zc)/Zp) − e·u(θ),      u(a) = (cos a, sin a),

i.e. seen from the disc the pin-circle centre sits at −e·u(θ) (opposite the eccentric) and the pin
ring has turned by **+θ·(Zp − Zc)/Zp** (counter-clockwise for a counter-clockwise crank angle).
:func:`pin_centres` implements this; the tests check the sign through the envelope property.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from rvfem import NOTICE
from rvfem._arrays import points_in_polygon
from rvfem._arrays import readonly as _readonly
from rvfem.case.definition import Case
from rvfem.geometry.profile import Profile, _c2xy, _u, build_profile, profile_eval

log = logging.getLogger(__name__)

__all__ = [
    "FlankDeviation",
    "load_cycle_angles",
    "pin_phases",
    "pin_centres",
    "crank_centres",
    "PinContacts",
    "pin_profile_contacts",
    "pin_profile_contacts_many",
    "closest_points",
]


def pin_centres(case: Case, theta: float) -> np.ndarray:
    """Pin centres in the disc frame at crank angle θ.

    c_j(θ) = Rp·u(2πj/Zp + θ·(Zp − Zc)/Zp) − e·u(θ), j = 0…Zp − 1 (see the module docstring for
    the derivation; pin 0 is the pin on the housing's x axis).

    Parameters
    ----------
    case : Case
    theta : float
        Crank angle θ, rad (eccentric relative to the carrier, counter-clockwise).

    Returns
    -------
    ndarray (Zp, 2)
        mm.
    """
    zp, zc = case.pins.count, case.cycloid.teeth
    j = np.arange(zp)
    c = case.pins.circle_radius * _u(2 * np.pi * j / zp + theta * (zp - zc) / zp) \
        - case.cycloid.eccentricity * _u(theta)
    return _c2xy(c)


def pin_phases(case: Case, theta: float) -> np.ndarray:
    """The phase ψ_j of every pin at crank angle θ: its angle about the pin-circle centre from the
    eccentric's direction, 2πj/Zp + θ·(Zp − Zc)/Zp − θ wrapped to (−π, π], rad (Zp,).

    Every tooth meets the pins alike: a pin at phase ψ touches the same point of a tooth's flank
    (ψ > 0 one flank of the tooth, ψ < 0 the other) whatever the pin and the tooth, so a property of
    every tooth's flank (its wear) is a function of ψ (:class:`FlankDeviation`).
    """
    zp, zc = case.pins.count, case.cycloid.teeth
    j = np.arange(zp)
    return np.angle(np.exp(1j * (2 * np.pi * j / zp + float(theta) * (zp - zc) / zp - float(theta))))


@dataclass(frozen=True)
class FlankDeviation:
    """A deviation of the pin–flank gaps from those of the nominal profile, the same for every
    tooth, as a function of the pin phase ψ (:func:`pin_phases`): the depth worn off the flank
    (and off the pin at the same contact), mm, added to the gap of each pin at each crank angle.

    Linear between the samples, the end values beyond them. Frozen and compared by value (tuples),
    so that a disc model's contact sets are keyed by it (:func:`rvfem.solve.cycle_contacts.contact_model_key`).

    Attributes
    ----------
    psi : tuple of float
        Pin phases |ψ|, rad, increasing, within [0, π].
    positive, negative : tuple of float
        Added gap, mm, of a pin at phase +|ψ| (the flanks a positive torque loads) and at −|ψ|.
    """

    psi: tuple[float, ...]
    positive: tuple[float, ...]
    negative: tuple[float, ...]

    def __post_init__(self) -> None:
        n = len(self.psi)
        if n < 2 or len(self.positive) != n or len(self.negative) != n:
            raise ValueError("a flank deviation needs at least two pin phases and one gap per phase on each flank")
        psi = np.asarray(self.psi, dtype=float)
        if not (np.all(np.diff(psi) > 0) and psi[0] >= 0.0 and psi[-1] <= math.pi):
            raise ValueError("the pin phases of a flank deviation must increase within [0, π]")
        if not (np.all(np.isfinite(self.positive)) and np.all(np.isfinite(self.negative))):
            raise ValueError("a flank deviation's gaps must be finite numbers (mm)")

    @classmethod
    def of(cls, psi, positive, negative) -> "FlankDeviation":
        """From arrays (rad, mm, mm)."""
        return cls(tuple(float(x) for x in psi), tuple(float(x) for x in positive),
                   tuple(float(x) for x in negative))

    def gap(self, psi) -> np.ndarray:
        """The added gap (mm) of pins at phases ``psi`` (rad, in (−π, π])."""
        psi = np.asarray(psi, dtype=float)
        a = np.abs(psi)
        return np.where(psi >= 0.0, np.interp(a, self.psi, self.positive), np.interp(a, self.psi, self.negative))


def crank_centres(case: Case) -> np.ndarray:
    """Centres of the crank-bearing bores in the disc frame, r0·u(α_i), (N, 2), mm."""
    a = np.radians(np.asarray(case.cranks.angles_deg, dtype=float))
    return _c2xy(case.cranks.circle_radius * _u(a))


@dataclass(frozen=True, eq=False)
class PinContacts:
    """Pin–profile geometry at one crank angle (disc frame).

    Attributes
    ----------
    theta : float
        Crank angle, rad.
    centres : ndarray (Zp, 2)
        Pin centres, mm.
    gap : ndarray (Zp,)
        Signed gap, mm: signed distance from the pin centre to the actual profile (positive
        outside the disc) minus the pin radius r_rp. Negative = overlap.
    point : ndarray (Zp, 2)
        Closest point on the profile, mm.
    normal : ndarray (Zp, 2)
        Unit outward normal of the profile at that point (towards the pin centre when the gap is
        above −r_rp).
    segment, param : ndarray (Zp,)
        Profile segment and base-curve parameter of the closest point.
    """

    theta: float
    centres: np.ndarray
    gap: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    segment: np.ndarray
    param: np.ndarray


def closest_points(profile: Profile, xy: np.ndarray):
    """Closest points on the actual profile to arbitrary points.

    Parameters
    ----------
    profile : Profile
    xy : ndarray (n, 2)
        Points, mm.

    Returns
    -------
    segment, param : ndarray (n,)
        Segment and base-curve parameter of each closest point.
    points, normals : ndarray (n, 2)
        The closest points (mm) and the unit outward normals there.

    Notes
    -----
    Start at the nearest dense sample, then Newton iterations on the stationarity condition
    f(s) = (P(s) − x)·P'(s) = 0 with f' = |P'|² + (P − x)·P'' (analytic derivatives), continuing
    across segment ends for Zp − Zc = 1 and stopping at the tip corners for Zp − Zc > 1. Converges
    to round-off.
    """
    xy = np.asarray(xy, dtype=float)
    seg, s, P, P1 = _closest_points(profile, xy[:, 0] + 1j * xy[:, 1])
    return seg, s, _c2xy(P), _c2xy(-1j * P1 / np.abs(P1))


def _closest_points(profile: Profile, c: np.ndarray, tol: float = 1e-15, max_iter: int = 50):
    """Closest points on the profile to complex points c (see :func:`closest_points`).
    Returns (segment, s, P, P1) with complex P, P1."""
    if profile.tree is not None:
        idx = profile.tree.query(_c2xy(c))[1]
    else:
        pts = profile.points[:, 0] + 1j * profile.points[:, 1]
        idx = np.argmin(np.abs(c[:, None] - pts[None, :]), axis=1)
    seg = profile.segment[idx].copy()
    s = profile.param[idx].copy()
    s_h = profile.half_range
    smooth = profile.tooth_difference == 1
    active = np.ones(len(c), bool)
    for _ in range(max_iter):
        P, P1, P2 = profile_eval(profile, seg, s, derivatives=True)
        diff = P - c
        f = np.real(np.conj(diff) * P1)
        fp = np.abs(P1) ** 2 + np.real(np.conj(diff) * P2)
        fp = np.where(fp > 0, fp, np.abs(P1) ** 2)
        step = np.clip(-f / fp, -0.25 * s_h, 0.25 * s_h)
        step[~active] = 0.0
        s = s + step
        if smooth:
            up = s > s_h
            seg[up] += 1
            s[up] -= 2 * s_h
            dn = s < -s_h
            seg[dn] -= 1
            s[dn] += 2 * s_h
            seg %= profile.teeth
        else:
            s = np.clip(s, -s_h, s_h)
        active &= np.abs(step) > tol
        if not active.any():
            break
    P, P1, _ = profile_eval(profile, seg, s, derivatives=True)
    return seg, s, P, P1


def pin_profile_contacts(geom_or_case, theta: float) -> PinContacts:
    """Gaps between every pin and the actual (modified, pitch-error) profile at crank angle θ.

    Parameters
    ----------
    geom_or_case : rvfem.geometry.DiscGeometry or Case
        Pass a :class:`~rvfem.geometry.features.DiscGeometry` when calling this for many angles; a Case is turned into a
        profile first (which repeats the profile construction and checks on every call).
    theta : float
        Crank angle, rad.

    Returns
    -------
    PinContacts
        Accuracy: the closest point is refined with Newton iterations on the parametric profile
        to round-off (≈1e-12 mm), not taken from the samples. For d > 1 a closest point beyond a
        tip corner is the corner itself.
    """
    return pin_profile_contacts_many(geom_or_case, [theta])[0]


def pin_profile_contacts_many(geom_or_case, thetas) -> list[PinContacts]:
    """:func:`pin_profile_contacts` at many crank angles, with one vectorised closest-point
    search for all of them (each point's Newton iteration is its own: the results are those of
    the angles one by one)."""
    if isinstance(geom_or_case, Case):
        case = geom_or_case
        profile = build_profile(case)
    elif isinstance(getattr(geom_or_case, "profile", None), Profile) and isinstance(
            getattr(geom_or_case, "case", None), Case):
        profile, case = geom_or_case.profile, geom_or_case.case     # a DiscGeometry
    else:
        raise TypeError("pin_profile_contacts needs a DiscGeometry or a Case")
    thetas = [float(t) for t in thetas]
    if not thetas:
        return []
    cxy_all = np.concatenate([pin_centres(case, t) for t in thetas])
    c_all = cxy_all[:, 0] + 1j * cxy_all[:, 1]
    seg_all, s_all, P_all, P1_all = _closest_points(profile, c_all)
    # every operation below is point by point: done for all angles at once, then split
    n = -1j * P1_all / np.abs(P1_all)
    diff = c_all - P_all
    dist = np.abs(diff)
    # signed distance: positive on the outward side. At a d > 1 corner the normal is undefined;
    # use the direction to the pin there.
    sd = np.real(np.conj(diff) * n)
    if profile.tooth_difference > 1:
        corner = np.abs(np.abs(s_all) - profile.half_range) < 1e-12
        if np.any(corner):
            inside = points_in_polygon(_c2xy(c_all[corner]), profile.points)
            sgn = np.where(inside, -1.0, 1.0)
            u = diff[corner] / np.where(dist[corner] > 0, dist[corner], 1.0)
            n[corner] = sgn * u
            sd[corner] = sgn * dist[corner]
    gap, point, normal = sd - case.pins.radius, _c2xy(P_all), _c2xy(n)
    zp = case.pins.count
    out = []
    for a, theta in enumerate(thetas):
        rows = slice(a * zp, (a + 1) * zp)
        out.append(PinContacts(
            theta=theta, centres=_readonly(cxy_all[rows]), gap=_readonly(gap[rows]),
            point=_readonly(point[rows]), normal=_readonly(normal[rows]), segment=_readonly(seg_all[rows]),
            param=_readonly(s_all[rows]),
        ))
    return out


def load_cycle_angles(step_deg: float) -> np.ndarray:
    """Uniformly spaced crank angles covering one full turn, endpoint excluded.

    The one crank-angle sampler of rvfem: the handbook model, the finite-element load cycle and the
    outputs all use these angles, so their curves line up sample by sample.

    Parameters
    ----------
    step_deg : float
        Requested step, degrees. The number of samples is n = round(360/step_deg), so the actual step
        is 360°/n (equal to the request whenever it divides 360°; otherwise a notice is logged,
        :data:`rvfem.NOTICE`).

    Returns
    -------
    ndarray, shape (n,)
        θ = 0, 2π/n, …, 2π(n − 1)/n, rad.
    """
    if not step_deg > 0:
        raise ValueError(f"step_deg must be positive, got {step_deg!r}")
    n = max(1, int(round(360.0 / step_deg)))
    if not math.isclose(n * step_deg, 360.0, rel_tol=1e-9):
        log.info("the crank-angle step %g° does not divide 360°: it is adjusted to %.6g° (%d angles)", step_deg,
                    360.0 / n, n, extra=NOTICE)
    return np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
