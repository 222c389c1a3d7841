"""Disc geometry: the cycloid profile, the drive kinematics and the disc's holes.

Everything here is in the **disc's body frame**: the disc centre is the origin, the disc does not
move, and the pins move around it. Lengths are mm, angles radians (the case file's degrees are
converted on reading).

Kinematics
----------
The crank angle θ is the angle of the eccentric relative to the carrier, counted counter-clockwise
(design notes §2). The disc is carried by the cranks, so it translates with the eccentric but keeps
the carrier's orientation. With the pin housing fixed, its pin ``j`` at ``Rp·u(2πj/Zp)`` (pin 0 on
the housing's x axis), the disc centre at ``e·u(β)`` and the disc turned by ψ, the rolling condition
of the internal gear pair relative to the eccentric gives ψ = −β·(Zp − Zc)/Zc, and θ = β − ψ =
β·Zp/Zc. Expressing the pin centres in the disc frame, ``R(−ψ)·(p_j − e·u(β))``, gives

    c_j(θ) = Rp·u(2πj/Zp + θ·(Zp − Zc)/Zp) − e·u(θ),      u(a) = (cos a, sin a),

i.e. seen from the disc the pin-circle centre sits at −e·u(θ) (opposite the eccentric) and the pin
ring has turned by **+θ·(Zp − Zc)/Zp** (counter-clockwise for a counter-clockwise crank angle).
:func:`pin_centres` implements this; the tests check the sign through the envelope property.

Profile
-------
The ideal profile is the envelope of the pin circles c_j(θ) of radius r_rp. With d = Zp − Zc and
a = Zp/d, every pin centre lies on (a rotation by a multiple of 2π/Zc of) the trochoid

    T(s) = Rp·u(s) − e·u(a·s),

and the profile is its inward parallel curve at distance r_rp, P(s) = T(s) − r_rp·n_T(s) (n_T the
outward unit normal). For d = 1 this is the classical epitrochoid-equidistant cycloid profile (e.g.
Liu et al., *Degradation law analysis and life estimation of transmission accuracy of RV reducer
based on tooth surface and bearing wear*, contact-point equations with k1 = e·Zp/Rp); one lobe spans
s ∈ [−π/Zc, π/Zc] and every pin touches the ideal profile at every θ. For d > 1 the trochoid winds d
times around the origin and the profile is the inner envelope of its copies: each tooth space is
bounded by the piece of P around its root, trimmed where it meets its neighbour on the bisector
between two roots, so the tips are sharp corners and only part of the pins touch.

The profile is stored as Zc **segments**, one per tooth space: segment j spans the parameter
s ∈ [−s_h, s_h] of the base curve rotated by 2πj/Zc, has its root (radius Rp − e − r_rp) at polar
angle 2πj/Zc and its ends at the tips on either side.

Modifications (sign convention of Liu et al.): the profile is generated with the pin radius
r_rp + ΔRrp (``equidistant``; positive removes material) and the pin-circle radius Rp + ΔRp
(``shift``; positive adds material at the tip), so the tip and root radii change by ΔRp − ΔRrp, and
the whole profile is rotated by ``rotation_deg`` about the disc centre (positive counter-clockwise).
The pins themselves keep Rp and r_rp.

Pitch errors (Li et al., *Life calculation of the swivel-arm bearing of an RV reducer considering
cycloid pitch error*): teeth are numbered k = 1…Zc counter-clockwise from the +x axis, tooth k
being the lobe whose tip is at polar angle (2k − 1)·π/Zc (plus the rotation modification). The
pitch error E_t(k) (mm; E_t,max·sin((k − 1)·π/2) or an explicit list) is a tangential displacement
of the whole tooth at the mean profile radius R_m = (Rp + ΔRp) − (r_rp + ΔRrp), modelled as a rigid
rotation of tooth k about the disc centre by δ_k = E_t(k)/R_m (positive counter-clockwise). Between
two teeth the rotation blends smoothly (a C² quintic step) across the middle 30 % of the tooth
space around the root, where a pin carries little load, so the profile stays smooth.

Features
--------
A central hole, N crank-bearing bores (radius ``crank_bearing.bore_radius``) at r0·u(α_i), optional
fan-shaped holes (annular sectors with filleted corners) and round holes. :func:`disc_geometry`
builds a :class:`DiscGeometry` and checks it (undercut, overlaps, thin walls) before anything is
meshed; every problem is a :class:`~rvfem.errors.GeometryError` that says what to change.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from matplotlib.path import Path as _MplPath
from scipy.optimize import brentq, minimize_scalar
from scipy.spatial import cKDTree

from .case import Case
from ._arrays import readonly as _readonly
from .errors import GeometryError

__all__ = [
    "Profile",
    "Circle",
    "LineSegment",
    "Arc",
    "FanHole",
    "Wall",
    "DiscGeometry",
    "PinContacts",
    "build_profile",
    "profile_eval",
    "pin_centres",
    "crank_centres",
    "pin_profile_contacts",
    "closest_points",
    "disc_geometry",
    "check_undercut",
    "pitch_errors",
]

SAMPLES_PER_SEGMENT = 256
"""Dense samples per tooth space (profile segment) stored in :attr:`Profile.points`."""

SPLINE_POINTS_PER_SEGMENT = 96
"""Interpolation points per segment handed to Gmsh (one OCC spline per tooth space)."""

PITCH_BLEND_FRACTION = 0.3
"""Fraction of a tooth space (around its root) over which the pitch-error rotation blends."""

WALL_SPACING = 0.02
"""Spacing (mm) of the points used to measure walls between features."""


def _u(a):
    """Unit complex number e^{ia} (the direction u(a) as a complex number)."""
    return np.exp(1j * np.asarray(a, dtype=float))


def _c2xy(z) -> np.ndarray:
    """Complex array → (..., 2) float array."""
    z = np.asarray(z)
    return np.ascontiguousarray(np.stack([z.real, z.imag], axis=-1))




# ------------------------------------------------------------------------------------------------
# Profile
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Profile:
    """The cycloid profile (modified, with pitch errors) in the disc frame.

    Attributes
    ----------
    teeth, pins : int
        Zc and Zp.
    eccentricity : float
        e, mm.
    generating_circle_radius : float
        Rp + ΔRp, mm (pin-circle radius the profile is generated with).
    generating_pin_radius : float
        r_rp + ΔRrp, mm (pin radius the profile is generated with).
    rotation : float
        Rotation modification, rad (positive counter-clockwise).
    tooth_rotations : ndarray (Zc,)
        Pitch-error rotation δ_k of tooth k = 1…Zc (index k − 1), rad.
    half_range : float
        s_h: segment j covers the base-curve parameter s ∈ [−s_h, s_h], rad.
    blend_half_width : float
        Half-width in s of the pitch-error blend around each root, rad.
    points, normals : ndarray (Zc·SAMPLES_PER_SEGMENT, 2)
        Dense samples, counter-clockwise, equally spaced in arc length within each segment,
        starting at the tip before segment 0, closed (the first point is not repeated), and the
        unit outward normals there. The roots (s = 0) and tips (s = ±s_h) are samples.
    curvature : ndarray
        Signed curvature at the samples, 1/mm: positive where the profile is convex (tips),
        negative where concave (tooth spaces).
    segment, param : ndarray
        Segment index j and base-curve parameter s of every sample.
    spline_points : ndarray (Zc, SPLINE_POINTS_PER_SEGMENT, 2)
        Points per segment for Gmsh, tip to tip, equally spaced in arc length; the last point of
        segment j equals the first of segment j + 1.
    """

    teeth: int
    pins: int
    eccentricity: float
    generating_circle_radius: float
    generating_pin_radius: float
    rotation: float
    tooth_rotations: np.ndarray
    half_range: float
    blend_half_width: float
    points: np.ndarray = field(repr=False)
    normals: np.ndarray = field(repr=False)
    curvature: np.ndarray = field(repr=False)
    segment: np.ndarray = field(repr=False)
    param: np.ndarray = field(repr=False)
    spline_points: np.ndarray = field(repr=False)
    tree: cKDTree | None = field(default=None, repr=False)
    """k-d tree of :attr:`points` (start values of the closest-point search)."""

    @property
    def tooth_difference(self) -> int:
        """d = Zp − Zc."""
        return self.pins - self.teeth

    @property
    def tip_radius(self) -> float:
        """Nominal tip radius (Rp + ΔRp) + e − (r_rp + ΔRrp), mm (d = 1; for d > 1 the tips are
        trimmed corners and lie lower)."""
        return self.generating_circle_radius + self.eccentricity - self.generating_pin_radius

    @property
    def root_radius(self) -> float:
        """Root radius (Rp + ΔRp) − e − (r_rp + ΔRrp), mm."""
        return self.generating_circle_radius - self.eccentricity - self.generating_pin_radius

    @property
    def mean_radius(self) -> float:
        """R_m = (Rp + ΔRp) − (r_rp + ΔRrp), mm, the radius at which pitch errors are applied."""
        return self.generating_circle_radius - self.generating_pin_radius

    @property
    def radius_of_curvature(self) -> np.ndarray:
        """Signed radius of curvature at the samples, mm (1/curvature; ±inf at inflections)."""
        with np.errstate(divide="ignore"):
            return 1.0 / self.curvature

    @property
    def polar_angles(self) -> np.ndarray:
        """Polar angle of every sample, rad, in [0, 2π)."""
        return np.mod(np.arctan2(self.points[:, 1], self.points[:, 0]), 2 * np.pi)


def pitch_errors(case: Case) -> np.ndarray:
    """Per-tooth pitch errors E_t(k), k = 1…Zc, in mm (tangential, positive counter-clockwise).

    E_t(k) = E_t,max·sin((k − 1)·π/2) (Li et al., eq. 21) when ``amplitude`` is given, else the
    explicit ``values``, else zeros.
    """
    zc = case.cycloid.teeth
    pe = case.cycloid.pitch_error
    if pe.values:
        return np.asarray(pe.values, dtype=float)
    k = np.arange(1, zc + 1)
    return pe.amplitude * np.sin((k - 1) * np.pi / 2.0)


def _base_curve(R: float, e: float, a: float, r: float, s: np.ndarray):
    """Base profile P(s) = T(s) − r·n_T(s) and its first two s-derivatives (complex).

    T(s) = R·e^{is} − e·e^{ias}; the outward normal of the counter-clockwise trochoid is
    n_T = −i·T'/|T'|, so P = T + i·r·t with t = T'/|T'|.
    """
    eis = np.exp(1j * s)
    eas = np.exp(1j * a * s)
    T = R * eis - e * eas
    T1 = 1j * (R * eis - a * e * eas)
    T2 = -(R * eis - a * a * e * eas)
    T3 = -1j * (R * eis - a**3 * e * eas)
    g = np.abs(T1)
    g1 = np.real(T2 * np.conj(T1)) / g
    g2 = (np.real(T3 * np.conj(T1)) + np.abs(T2) ** 2) / g - g1 * g1 / g
    t = T1 / g
    t1 = T2 / g - T1 * g1 / g**2
    t2 = T3 / g - 2 * T2 * g1 / g**2 - T1 * g2 / g**2 + 2 * T1 * g1**2 / g**3
    return T + 1j * r * t, T1 + 1j * r * t1, T2 + 1j * r * t2


def trochoid_curvature(R: float, e: float, a: float, s: np.ndarray) -> np.ndarray:
    """Signed curvature of the pin-centre trochoid T(s) = R·u(s) − e·u(a·s), 1/mm.

    κ_T = [1 + a·k² − (a + 1)·k·cos ψ] / (R·(1 + k² − 2k·cos ψ)^{3/2}),  k = a·e/R,  ψ = (a − 1)·s,

    from κ = (T'×T'')/|T'|³. For d = 1 (a = Zp) k is the short-amplitude coefficient e·Zp/Rp. The
    profile (parallel curve at distance r inward) has curvature κ_T/(1 − r·κ_T): it is free of
    undercut as long as 1 − r·κ_T > 0 everywhere, i.e. r < min over the convex part of 1/κ_T.
    """
    k = a * e / R
    psi = (a - 1.0) * np.asarray(s, dtype=float)
    return (1 + a * k * k - (a + 1) * k * np.cos(psi)) / (R * (1 + k * k - 2 * k * np.cos(psi)) ** 1.5)


def _blend(s, w):
    """Quintic smooth step H(x), x = (s + w)/(2w) clipped to [0, 1], and dH/ds, d²H/ds²."""
    x = np.clip((np.asarray(s, dtype=float) + w) / (2 * w), 0.0, 1.0)
    h = x**3 * (10 - 15 * x + 6 * x * x)
    dx = 1.0 / (2 * w)
    h1 = 30 * x * x * (1 - x) ** 2 * dx
    h2 = 60 * x * (1 - x) * (1 - 2 * x) * dx * dx
    return h, h1, h2


def profile_eval(profile: Profile, segment, s, derivatives: bool = False):
    """Points (and derivatives) of the actual profile at base parameter ``s`` of ``segment``.

    Parameters
    ----------
    profile : Profile
    segment : int or int array
        Segment (tooth-space) index j, taken modulo Zc.
    s : float or array
        Base-curve parameter, rad; meaningful in [−s_h, s_h] (for d = 1 any value works and
        continues smoothly into the neighbouring segments).
    derivatives : bool
        Also return dP/ds and d²P/ds².

    Returns
    -------
    P or (P, P1, P2) : complex arrays
        Points as complex numbers x + iy (mm) and their s-derivatives. The segment's rotation is
        Φ(s) = 2πj/Zc + rotation + δ(s), δ blending from tooth j to tooth j + 1 across the root.
    """
    zc = profile.teeth
    j = np.mod(np.asarray(segment, dtype=int), zc)
    s = np.asarray(s, dtype=float)
    P, P1, P2 = _base_curve(profile.generating_circle_radius, profile.eccentricity,
                            profile.pins / profile.tooth_difference, profile.generating_pin_radius, s)
    rot = profile.tooth_rotations
    d_left = rot[np.mod(j - 1, zc)]
    d_right = rot[j]
    h, h1, h2 = _blend(s, profile.blend_half_width)
    dd = d_right - d_left
    delta = d_left + dd * h
    phase = np.exp(1j * (2 * np.pi * j / zc + profile.rotation + delta))
    if not derivatives:
        return phase * P
    dl1 = dd * h1
    dl2 = dd * h2
    Q1 = P1 + 1j * dl1 * P
    Q2 = P2 + 2j * dl1 * P1 + 1j * dl2 * P - dl1 * dl1 * P
    return phase * P, phase * Q1, phase * Q2


def _half_range(R: float, e: float, a: float, r: float, zc: int, d: int) -> float:
    """s_h: for d = 1 the tip at s = π/Zc; for d > 1 the parameter where the base profile crosses
    the bisector between two roots (polar angle π/Zc)."""
    if d == 1:
        return math.pi / zc

    def f(s):
        return float(np.angle(_base_curve(R, e, a, r, np.array(s))[0])) - math.pi / zc

    hi = math.pi * d / zc
    if f(hi) <= 0:
        raise GeometryError(
            f"the profile for Zp − Zc = {d} does not close: neighbouring tooth spaces do not meet; "
            "reduce the pin radius or the eccentricity")
    return brentq(f, 0.0, hi, xtol=1e-15)


def _arc_length_params(R: float, e: float, a: float, r: float, s_h: float, n: int) -> np.ndarray:
    """n + 1 parameters from −s_h to s_h, equally spaced in arc length of the base profile,
    symmetric about the root (s = 0 is included for even n, the ends are exactly ±s_h)."""
    half = n // 2
    fine = np.linspace(0.0, s_h, 64 * max(half, 1) + 1)
    speed = np.abs(_base_curve(R, e, a, r, fine)[1])
    arc = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(fine))])
    if n % 2 == 0:
        u = arc[-1] * np.arange(half + 1) / half
        pos = np.interp(u, arc, fine)
        pos[0], pos[-1] = 0.0, s_h
        return np.concatenate([-pos[:0:-1], pos])
    u = arc[-1] * (np.arange(half + 1) + 0.5) / (half + 0.5)
    pos = np.interp(u, arc, fine)
    pos[-1] = s_h
    return np.concatenate([-pos[::-1], pos])


def check_undercut(R: float, e: float, a: float, r: float, s_h: float) -> tuple[float, float]:
    """Minimum radius of curvature of the convex part of the profile, and the parameter s there.

    The profile's signed radius of curvature is 1/κ_T − r where the trochoid is convex
    (κ_T > 0); the minimum over one segment is found on a dense grid and refined with a bounded
    scalar minimisation. A value ≤ 0 means undercut (a cusp or a loop).

    Returns
    -------
    (rho_min, s_min) : float, float
        mm and rad. ``rho_min = inf`` if the profile has no convex part in the segment.
    """
    s = np.linspace(-s_h, s_h, 4001)
    kap = trochoid_curvature(R, e, a, s)
    if not np.any(kap > 0):
        return math.inf, 0.0
    i = int(np.argmax(kap))
    lo, hi = s[max(i - 1, 0)], s[min(i + 1, len(s) - 1)]
    if hi > lo:
        res = minimize_scalar(lambda x: -trochoid_curvature(R, e, a, x), bounds=(lo, hi),
                              method="bounded", options={"xatol": 1e-13})
        s_best = float(res.x) if -res.fun >= kap[i] else float(s[i])
    else:
        s_best = float(s[i])
    kmax = float(trochoid_curvature(R, e, a, s_best))
    return 1.0 / kmax - r, s_best


def build_profile(case: Case, samples_per_segment: int = SAMPLES_PER_SEGMENT,
                  spline_points: int = SPLINE_POINTS_PER_SEGMENT) -> Profile:
    """Build and check the cycloid profile of a case.

    Raises
    ------
    GeometryError
        On undercut (minimum convex radius of curvature ≤ 0: reports the value and the profile
        angle, and what to change), on a profile that folds over itself (pitch errors too large)
        or, for Zp − Zc > 1, when neighbouring tooth spaces do not meet.
    """
    cyc, pins = case.cycloid, case.pins
    zc, zp = cyc.teeth, pins.count
    d = zp - zc
    mod = cyc.modification
    R = pins.circle_radius + mod.shift
    r = pins.radius + mod.equidistant
    e = cyc.eccentricity
    a = zp / d
    if r <= 0:
        raise GeometryError(
            f"the generating pin radius r_rp + ΔRrp = {pins.radius} + {mod.equidistant} = {r:.4g} mm "
            "must be positive; reduce the magnitude of cycloid.modification.equidistant")
    if a * e / R >= 1.0:
        raise GeometryError(
            f"the trochoid loops: k = e·Zp/(d·(Rp + ΔRp)) = {a * e / R:.4f} ≥ 1; reduce the "
            "eccentricity or the negative shift modification")
    s_h = _half_range(R, e, a, r, zc, d)
    rho_min, s_min = check_undercut(R, e, a, r, s_h)
    if rho_min <= 0.0:
        p = _base_curve(R, e, a, r, np.array(s_min))[0]            # root of the base curve at 0°
        ang = math.degrees(math.atan2(p.imag, p.real)) % (360.0 / zc)
        r_crit = r + rho_min
        raise GeometryError(
            f"undercut cycloid profile: the minimum radius of curvature of the convex part of the teeth is "
            f"{rho_min:.4g} mm (≤ 0) at profile angle {ang:.3f}° from a root (repeats on every "
            f"lobe); the generating pin radius r_rp + ΔRrp = {r:.4g} mm must stay below "
            f"{r_crit:.4g} mm for e = {e} mm, Rp + ΔRp = {R:.4g} mm — reduce pins.radius or "
            "cycloid.modification.equidistant, or the eccentricity, or enlarge pins.circle_radius")

    r_mean = R - r
    rot = pitch_errors(case) / r_mean
    blend_w = PITCH_BLEND_FRACTION * s_h
    prof = Profile(
        teeth=zc, pins=zp, eccentricity=e, generating_circle_radius=R, generating_pin_radius=r,
        rotation=math.radians(mod.rotation_deg), tooth_rotations=_readonly(rot), half_range=s_h,
        blend_half_width=blend_w,
        points=np.empty((0, 2)), normals=np.empty((0, 2)), curvature=np.empty(0),
        segment=np.empty(0, int), param=np.empty(0), spline_points=np.empty((0, 0, 2)),
    )
    # dense samples: equal arc length, [−s_h, s_h) per segment, counter-clockwise
    n = samples_per_segment
    s1 = _arc_length_params(R, e, a, r, s_h, n)[:-1]
    seg = np.repeat(np.arange(zc), n)
    ss = np.tile(s1, zc)
    P, P1, P2 = profile_eval(prof, seg, ss, derivatives=True)
    speed = np.abs(P1)
    normal = -1j * P1 / speed
    kappa = np.imag(np.conj(P1) * P2) / speed**3
    # the profile must advance with the base curve (no fold from large pitch-error blends)
    B0, B1, _ = _base_curve(R, e, a, r, ss)
    fold = np.real(P1 * np.conj(B1 * (P / B0)))
    if np.any(fold <= 0):
        raise GeometryError(
            "the profile folds over itself where the pitch-error rotation blends between teeth; "
            f"the pitch errors (max |E_t| = {np.max(np.abs(pitch_errors(case))):.4g} mm) are far "
            "too large — they are meant to be micrometres")
    sp = _arc_length_params(R, e, a, r, s_h, spline_points - 1)
    spl = profile_eval(prof, np.repeat(np.arange(zc), spline_points), np.tile(sp, zc))
    spl = spl.reshape(zc, spline_points)
    # make tip points shared exactly (round-off) between neighbouring segments
    spl[:, -1] = np.roll(spl[:, 0], -1)
    return Profile(
        teeth=zc, pins=zp, eccentricity=e, generating_circle_radius=R, generating_pin_radius=r,
        rotation=prof.rotation, tooth_rotations=prof.tooth_rotations, half_range=s_h,
        blend_half_width=blend_w,
        points=_readonly(_c2xy(P)), normals=_readonly(_c2xy(normal)),
        curvature=_readonly(kappa), segment=_readonly(seg), param=_readonly(ss),
        spline_points=_readonly(_c2xy(spl)), tree=cKDTree(_c2xy(P)),
    )


# ------------------------------------------------------------------------------------------------
# Kinematics and pin contact
# ------------------------------------------------------------------------------------------------


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
    geom_or_case : DiscGeometry or Case
        Pass a :class:`DiscGeometry` when calling this for many angles; a Case is turned into a
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
    if isinstance(geom_or_case, DiscGeometry):
        profile, case = geom_or_case.profile, geom_or_case.case
    elif isinstance(geom_or_case, Case):
        case = geom_or_case
        profile = build_profile(case)
    else:
        raise TypeError("pin_profile_contacts needs a DiscGeometry or a Case")
    cxy = pin_centres(case, theta)
    c = cxy[:, 0] + 1j * cxy[:, 1]
    seg, s, P, P1 = _closest_points(profile, c)
    n = -1j * P1 / np.abs(P1)
    diff = c - P
    dist = np.abs(diff)
    # signed distance: positive on the outward side. At a d > 1 corner the normal is undefined;
    # use the direction to the pin there.
    sd = np.real(np.conj(diff) * n)
    if profile.tooth_difference > 1:
        corner = np.abs(np.abs(s) - profile.half_range) < 1e-12
        if np.any(corner):
            inside = _MplPath(profile.points).contains_points(_c2xy(c[corner]))
            sgn = np.where(inside, -1.0, 1.0)
            u = diff[corner] / np.where(dist[corner] > 0, dist[corner], 1.0)
            n = n.copy()
            n[corner] = sgn * u
            sd = sd.copy()
            sd[corner] = sgn * dist[corner]
    return PinContacts(
        theta=float(theta), centres=_readonly(cxy), gap=_readonly(sd - case.pins.radius),
        point=_readonly(_c2xy(P)), normal=_readonly(_c2xy(n)), segment=_readonly(seg),
        param=_readonly(s),
    )


# ------------------------------------------------------------------------------------------------
# Features
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LineSegment:
    """A straight piece of a hole outline from ``start`` to ``end`` (mm)."""

    start: tuple[float, float]
    end: tuple[float, float]

    def distance(self, p: np.ndarray) -> np.ndarray:
        """Distance from points (n, 2) to the segment, mm."""
        a, b = np.asarray(self.start), np.asarray(self.end)
        ab = b - a
        L2 = float(ab @ ab)
        t = np.clip(((p - a) @ ab) / L2, 0.0, 1.0) if L2 > 0 else np.zeros(len(p))
        return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)

    def sample(self, spacing: float) -> np.ndarray:
        n = max(2, int(math.ceil(self.length / spacing)) + 1)
        t = np.linspace(0, 1, n)[:, None]
        return (1 - t) * np.asarray(self.start) + t * np.asarray(self.end)

    @property
    def length(self) -> float:
        return float(np.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1]))

    def area_term(self) -> float:
        """½∮(x dy − y dx) over this piece (Green's theorem)."""
        return 0.5 * (self.start[0] * self.end[1] - self.start[1] * self.end[0])


@dataclass(frozen=True)
class Arc:
    """A circular arc of a hole outline: centre, radius (mm), start angle and signed sweep (rad,
    positive counter-clockwise)."""

    centre: tuple[float, float]
    radius: float
    start_angle: float
    sweep: float

    def point(self, angle: float) -> tuple[float, float]:
        return (self.centre[0] + self.radius * math.cos(angle),
                self.centre[1] + self.radius * math.sin(angle))

    @property
    def start(self) -> tuple[float, float]:
        return self.point(self.start_angle)

    @property
    def end(self) -> tuple[float, float]:
        return self.point(self.start_angle + self.sweep)

    @property
    def length(self) -> float:
        return abs(self.sweep) * self.radius

    def distance(self, p: np.ndarray) -> np.ndarray:
        """Distance from points (n, 2) to the arc, mm (exact)."""
        c = np.asarray(self.centre)
        v = p - c
        ang = np.arctan2(v[:, 1], v[:, 0])
        lo = self.start_angle if self.sweep >= 0 else self.start_angle + self.sweep
        inside = np.mod(ang - lo, 2 * np.pi) <= abs(self.sweep)
        d_arc = np.abs(np.linalg.norm(v, axis=1) - self.radius)
        d_end = np.minimum(np.linalg.norm(p - np.asarray(self.start), axis=1),
                           np.linalg.norm(p - np.asarray(self.end), axis=1))
        return np.where(inside, d_arc, d_end)

    def sample(self, spacing: float) -> np.ndarray:
        n = max(2, int(math.ceil(self.length / spacing)) + 1)
        a = self.start_angle + self.sweep * np.linspace(0, 1, n)
        return np.stack([self.centre[0] + self.radius * np.cos(a),
                         self.centre[1] + self.radius * np.sin(a)], axis=1)

    def area_term(self) -> float:
        """½∮(x dy − y dx) over this arc: ½[R·(c_x·Δsin − c_y·Δcos) + R²·sweep]."""
        a1, a2 = self.start_angle, self.start_angle + self.sweep
        cx, cy = self.centre
        R = self.radius
        return 0.5 * (R * (cx * (math.sin(a2) - math.sin(a1)) - cy * (math.cos(a2) - math.cos(a1)))
                      + R * R * self.sweep)


@dataclass(frozen=True)
class Circle:
    """A circular hole (central hole, crank-bearing bore, round lightening hole)."""

    name: str
    centre: tuple[float, float]
    radius: float

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        """Distance from points (n, 2) to the hole, mm; negative inside the hole."""
        return np.hypot(p[:, 0] - self.centre[0], p[:, 1] - self.centre[1]) - self.radius

    def sample(self, spacing: float = WALL_SPACING) -> np.ndarray:
        n = max(16, int(math.ceil(2 * math.pi * self.radius / spacing)))
        a = 2 * np.pi * np.arange(n) / n
        return np.stack([self.centre[0] + self.radius * np.cos(a),
                         self.centre[1] + self.radius * np.sin(a)], axis=1)

    @property
    def area(self) -> float:
        return math.pi * self.radius**2


@dataclass(frozen=True)
class FanHole:
    """A fan-shaped hole: the annular sector r_i ≤ ρ ≤ r_o, |φ − φ_c| ≤ half_span with its four
    corners rounded by fillets of radius f (tangent to the arcs and to the radial sides).

    Attributes
    ----------
    name : str
    inner_radius, outer_radius : float
        mm.
    centre_angle, half_span : float
        Angle of the centre line and half the angular span between the radial sides, rad.
    fillet_radius : float
        mm (0 = sharp corners).
    """

    name: str
    inner_radius: float
    outer_radius: float
    centre_angle: float
    half_span: float
    fillet_radius: float

    @property
    def fillet_angles(self) -> tuple[float, float]:
        """(γ_o, γ_i): angular offsets of the outer/inner fillet centres from the sides,
        sin γ_o = f/(r_o − f), sin γ_i = f/(r_i + f)."""
        f = self.fillet_radius
        return (math.asin(f / (self.outer_radius - f)), math.asin(f / (self.inner_radius + f)))

    def validate(self) -> None:
        """Raise GeometryError if the fillets do not fit the sector."""
        f, ri, ro, al = self.fillet_radius, self.inner_radius, self.outer_radius, self.half_span
        if ro - ri <= 2 * f:
            raise GeometryError(
                f"{self.name}: fillet radius {f} mm does not fit the radial height "
                f"{ro - ri:.3g} mm of the fan hole (needs fillet < half the height); reduce "
                "fan_holes.fillet_radius or widen the hole")
        go, gi = self.fillet_angles
        if al <= max(go, gi) or (ro - f) * math.cos(go) <= (ri + f) * math.cos(gi):
            raise GeometryError(
                f"{self.name}: span {math.degrees(2 * al):.3g}° is too narrow for fillets of "
                f"{f} mm (needs more than {math.degrees(2 * max(go, gi)):.3g}°); widen the hole "
                "or reduce fan_holes.fillet_radius")

    def primitives(self) -> tuple:
        """The outline as lines and arcs, counter-clockwise around the hole (hole on the left)."""
        f, ri, ro = self.fillet_radius, self.inner_radius, self.outer_radius
        bc, al = self.centre_angle, self.half_span
        bp, bm = bc + al, bc - al            # the two radial sides
        if f == 0:
            ul = (math.cos(bp), math.sin(bp))
            ur = (math.cos(bm), math.sin(bm))
            return (
                Arc((0.0, 0.0), ro, bm, 2 * al),
                LineSegment((ro * ul[0], ro * ul[1]), (ri * ul[0], ri * ul[1])),
                Arc((0.0, 0.0), ri, bp, -2 * al),
                LineSegment((ri * ur[0], ri * ur[1]), (ro * ur[0], ro * ur[1])),
            )
        go, gi = self.fillet_angles
        rco, rci = ro - f, ri + f
        co_p = (rco * math.cos(bp - go), rco * math.sin(bp - go))
        ci_p = (rci * math.cos(bp - gi), rci * math.sin(bp - gi))
        ci_m = (rci * math.cos(bm + gi), rci * math.sin(bm + gi))
        co_m = (rco * math.cos(bm + go), rco * math.sin(bm + go))
        lo, li = rco * math.cos(go), rci * math.cos(gi)   # tangent points on the sides
        return (
            Arc((0.0, 0.0), ro, bm + go, 2 * (al - go)),
            Arc(co_p, f, bp - go, math.pi / 2 + go),
            LineSegment((lo * math.cos(bp), lo * math.sin(bp)), (li * math.cos(bp), li * math.sin(bp))),
            Arc(ci_p, f, bp + math.pi / 2, math.pi / 2 - gi),
            Arc((0.0, 0.0), ri, bp - gi, -2 * (al - gi)),
            Arc(ci_m, f, bm + gi + math.pi, math.pi / 2 - gi),
            LineSegment((li * math.cos(bm), li * math.sin(bm)), (lo * math.cos(bm), lo * math.sin(bm))),
            Arc(co_m, f, bm - math.pi / 2, math.pi / 2 + go),
        )

    def sample(self, spacing: float = WALL_SPACING) -> np.ndarray:
        """Points along the outline (closed polygon, last point not repeated), mm."""
        return np.concatenate([p.sample(spacing)[:-1] for p in self.primitives()])

    @property
    def area(self) -> float:
        """Exact area from Green's theorem over the outline, mm²."""
        return sum(p.area_term() for p in self.primitives())

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        """Distance from points (n, 2) to the hole, mm; negative inside."""
        prims = self.primitives()
        d = np.min([q.distance(p) for q in prims], axis=0)
        return np.where(self.contains(p), -d, d)

    def contains(self, p: np.ndarray) -> np.ndarray:
        """True for points (n, 2) inside the hole: inside the annular sector and not in one of
        the corner regions cut off by the fillets (a corner region is the part of the sector seen
        from a fillet centre within the fillet arc's sweep, beyond the fillet radius)."""
        rho = np.hypot(p[:, 0], p[:, 1])
        dphi = np.angle(np.exp(1j * (np.arctan2(p[:, 1], p[:, 0]) - self.centre_angle)))
        inside = (rho >= self.inner_radius) & (rho <= self.outer_radius) & (np.abs(dphi) <= self.half_span)
        if self.fillet_radius > 0:
            for q in self.primitives():
                if isinstance(q, Arc) and q.centre != (0.0, 0.0):
                    v = p - np.asarray(q.centre)
                    a = np.mod(np.arctan2(v[:, 1], v[:, 0]) - q.start_angle, 2 * np.pi)
                    corner = (a <= q.sweep) & (np.hypot(v[:, 0], v[:, 1]) > q.radius)
                    inside &= ~corner
        return inside


@dataclass(frozen=True)
class Wall:
    """The thinnest wall between two features (negative: they overlap)."""

    first: str
    second: str
    thickness: float
    location: tuple[float, float]


@dataclass(frozen=True, eq=False)
class DiscGeometry:
    """Everything the mesher and the contact model need to know about the disc.

    Attributes
    ----------
    case : Case
    profile : Profile
    central_hole : Circle
    bores : tuple of Circle
        ``bore_0`` … ``bore_{N−1}`` at r0·u(α_i).
    holes : tuple of FanHole or Circle
        Lightening holes ``hole_0`` …: the fan holes first, then the round holes.
    walls : tuple of Wall
        The thinnest wall between every pair of features (and each feature and the profile),
        thinnest first.
    """

    case: Case
    profile: Profile
    central_hole: Circle
    bores: tuple[Circle, ...]
    holes: tuple
    walls: tuple[Wall, ...]

    @property
    def features(self) -> tuple:
        """Central hole, bores and holes (everything cut out of the profile)."""
        return (self.central_hole,) + self.bores + self.holes

    @property
    def bore_centres(self) -> np.ndarray:
        return np.array([b.centre for b in self.bores])

    @property
    def area(self) -> float:
        """Disc area, mm²: profile polygon (dense samples) minus the exact hole areas."""
        x, y = self.profile.points[:, 0], self.profile.points[:, 1]
        a = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
        return a - sum(f.area for f in self.features)


def _fan_hole(name: str, fan, angle: float, half_span: float) -> FanHole:
    return FanHole(name, fan.inner_radius, fan.outer_radius, angle, half_span, fan.fillet_radius)


def _default_offset(case: Case) -> float:
    """Midway between the first two cranks (circular mean), rad."""
    a = np.radians(case.cranks.angles_deg[:2])
    return float(np.angle(np.exp(1j * a[0]) + np.exp(1j * a[1])))


def _fan_holes(case: Case, bores: tuple[Circle, ...]) -> list[FanHole]:
    fan = case.fan_holes
    if fan is None:
        return []
    offset = _default_offset(case) if fan.angle_offset_deg is None else math.radians(fan.angle_offset_deg)
    angles = [offset + 2 * math.pi * i / fan.count for i in range(fan.count)]
    if fan.span_deg is not None:
        holes = [_fan_hole(f"hole_{i}", fan, a, math.radians(fan.span_deg) / 2) for i, a in enumerate(angles)]
        for h in holes:
            h.validate()
        return holes
    if fan.outer_radius - fan.inner_radius <= 2 * fan.fillet_radius:
        _fan_hole("hole_0", fan, angles[0], math.pi / fan.count).validate()   # raises the message
    # span from the ligament: the widest hole whose wall to every bore is ≥ ligament
    L = fan.ligament

    def wall(half_span: float, angle: float) -> float:
        return _hole_bore_wall(_fan_hole("probe", fan, angle, half_span), bores)

    holes = []
    for i, a in enumerate(angles):
        lo = _min_valid_half_span(fan, a)
        hi = math.pi / fan.count
        if wall(lo, a) < L:
            raise GeometryError(
                f"hole_{i}: the fan-hole ligament of {L} mm cannot be kept: even the narrowest "
                f"hole with fillets of {fan.fillet_radius} mm leaves only {wall(lo, a):.3g} mm to "
                "the nearest bore; reduce fan_holes.ligament, move the hole radially, or shrink "
                "the bores")
        if wall(hi, a) >= L:
            raise GeometryError(
                f"hole_{i}: with fan_holes.ligament = {L} mm the fan holes would meet each other "
                "before they come that close to a bore; give fan_holes.span_deg instead")
        half = brentq(lambda x: wall(x, a) - L, lo, hi, xtol=1e-12)
        h = _fan_hole(f"hole_{i}", fan, a, half)
        h.validate()
        holes.append(h)
    return holes


def _min_valid_half_span(fan, angle: float) -> float:
    """Smallest half-span for which the fillets fit (bisection on FanHole.validate)."""
    lo, hi = 0.0, math.pi / fan.count
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        try:
            _fan_hole("probe", fan, angle, mid).validate()
            hi = mid
        except GeometryError:
            lo = mid
    return hi


def _hole_bore_wall(hole: FanHole, bores) -> float:
    """Smallest wall between a fan hole and the bores, mm (exact distance from each bore centre to
    the outline, minus the bore radius; negative when a bore centre region overlaps)."""
    prims = hole.primitives()
    best = math.inf
    for b in bores:
        c = np.array([b.centre])
        dist = min(float(q.distance(c)[0]) for q in prims)
        inside = bool(hole.contains(c)[0])
        best = min(best, (-dist if inside else dist) - b.radius)
    return best


def _round_holes(case: Case, first_index: int) -> list[Circle]:
    rh = case.round_holes
    if rh is None:
        return []
    offset = _default_offset(case) if rh.angle_offset_deg is None else math.radians(rh.angle_offset_deg)
    out = []
    for i in range(rh.count):
        a = offset + 2 * math.pi * i / rh.count
        out.append(Circle(f"hole_{first_index + i}", (rh.circle_radius * math.cos(a),
                                                       rh.circle_radius * math.sin(a)), rh.radius))
    return out


def _wall(a, b) -> Wall:
    """Thinnest wall between features a and b: min over dense points on a's outline of b's exact
    signed distance (and the other way round)."""
    best = None
    for f, g in ((a, b), (b, a)):
        pts = f.sample(WALL_SPACING)
        d = g.signed_distance(pts)
        i = int(np.argmin(d))
        if best is None or d[i] < best[0]:
            best = (float(d[i]), (float(pts[i, 0]), float(pts[i, 1])))
    return Wall(a.name, b.name, best[0], best[1])


def _profile_wall(profile: Profile, f) -> Wall:
    """Thinnest wall between the profile (its dense samples) and a feature (exact distance). A
    feature entirely outside the profile is caught separately in :func:`disc_geometry`."""
    pts = profile.points
    d = f.signed_distance(pts)
    i = int(np.argmin(d))
    return Wall("profile", f.name, float(d[i]), (float(pts[i, 0]), float(pts[i, 1])))


def disc_geometry(case: Case) -> DiscGeometry:
    """Build the disc geometry of a case and check it before any meshing.

    Checks (each failure is a GeometryError naming the features and what to change):

    * the profile has no undercut (see :func:`build_profile`);
    * fan holes: fillets fit, the ligament to the bores can be kept;
    * every feature lies inside the profile and no two features (or a feature and the profile)
      overlap;
    * no wall (feature–feature or feature–profile) is thinner than ``mesh.min_wall``; the message
      gives the thinnest wall, its thickness and the two features.

    Parameters
    ----------
    case : Case

    Returns
    -------
    DiscGeometry
    """
    profile = build_profile(case)
    central = Circle("central_hole", (0.0, 0.0), case.cycloid.central_hole_radius)
    bores = tuple(Circle(f"bore_{i}", (float(x), float(y)), case.crank_bearing.bore_radius)
                  for i, (x, y) in enumerate(crank_centres(case)))
    fans = _fan_holes(case, bores)
    holes = tuple(fans) + tuple(_round_holes(case, len(fans)))
    features = (central,) + bores + holes

    # every feature inside the profile
    outline = _MplPath(profile.points)
    for f in features:
        pts = f.sample(0.5)
        outside = ~outline.contains_points(pts)
        if np.all(outside):
            raise GeometryError(
                f"{f.name} lies entirely outside the cycloid profile (root radius "
                f"{profile.root_radius:.3f} mm); check its position and size")

    walls = [_profile_wall(profile, f) for f in features]
    for i, f in enumerate(features):
        for g in features[i + 1:]:
            walls.append(_wall(f, g))
    walls.sort(key=lambda w: w.thickness)
    thinnest = walls[0]
    min_wall = case.mesh.min_wall
    if thinnest.thickness <= 0:
        if thinnest.first == "profile":
            msg = (f"{thinnest.second} cuts the cycloid profile (overlap {-thinnest.thickness:.3f} mm; "
                   f"root radius {profile.root_radius:.3f} mm)")
        else:
            msg = f"{thinnest.second} overlaps {thinnest.first} (overlap {-thinnest.thickness:.3f} mm)"
        raise GeometryError(
            f"{msg} near ({thinnest.location[0]:.2f}, {thinnest.location[1]:.2f}) mm; move or "
            "shrink the features (fan_holes / round_holes / crank_bearing.bore_radius / "
            "cranks.circle_radius / cycloid.central_hole_radius)")
    if thinnest.thickness < min_wall:
        raise GeometryError(
            f"the wall between {thinnest.first} and {thinnest.second} is only "
            f"{thinnest.thickness:.3f} mm thick (mesh.min_wall = {min_wall} mm), near "
            f"({thinnest.location[0]:.2f}, {thinnest.location[1]:.2f}) mm; move or shrink the "
            "features, or lower mesh.min_wall if such a thin wall is intended")
    return DiscGeometry(case=case, profile=profile, central_hole=central, bores=bores,
                        holes=holes, walls=tuple(walls))
