"""The cycloid profile: envelope of the pin circles, modifications, pitch errors, undercut.

Everything is in the **disc's body frame** (disc centre at the origin). Lengths are mm, angles
radians. The derivation (envelope, parallel curve, curvature and undercut, modifications) is written
out in docs/theory.md ("Profile envelope and modifications").

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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq, minimize_scalar
from scipy.spatial import cKDTree

from rvfem._arrays import readonly as _readonly
from rvfem.case.definition import Case
from rvfem.errors import GeometryError

__all__ = [
    "Profile",
    "build_profile",
    "profile_eval",
    "profile_curvature",
    "pitch_errors",
    "trochoid_curvature",
    "check_undercut",
    "SAMPLES_PER_SEGMENT",
    "SPLINE_POINTS_PER_SEGMENT",
    "PITCH_BLEND_FRACTION",
]

SAMPLES_PER_SEGMENT = 256
"""Dense samples per tooth space (profile segment) stored in :attr:`Profile.points`."""

SPLINE_POINTS_PER_SEGMENT = 96
"""Interpolation points per segment handed to Gmsh (one OCC spline per tooth space)."""

PITCH_BLEND_FRACTION = 0.3
"""Fraction of a tooth space (around its root) over which the pitch-error rotation blends."""


def _u(a):
    """Unit complex number e^{ia} (the direction u(a) as a complex number)."""
    return np.exp(1j * np.asarray(a, dtype=float))


def _c2xy(z) -> np.ndarray:
    """Complex array → (..., 2) float array."""
    z = np.asarray(z)
    return np.ascontiguousarray(np.stack([z.real, z.imag], axis=-1))





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
    def root_radius(self) -> float:
        """Root radius (Rp + ΔRp) − e − (r_rp + ΔRrp), mm."""
        return self.generating_circle_radius - self.eccentricity - self.generating_pin_radius



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


def trochoid_curvature(R: float, e: float, a: float, s: float | np.ndarray) -> np.ndarray:
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


def profile_curvature(profile: Profile, segment, s) -> np.ndarray:
    """Signed curvature of the actual profile at base parameter ``s`` of ``segment``, 1/mm.

    κ = Im(conj(P′)·P″)/|P′|³ from the exact derivatives of :func:`profile_eval` (modifications
    and pitch-error blends included). The profile runs counter-clockwise, so κ > 0 where it is
    convex (near the tips) and κ < 0 where it is concave (near the roots); 1/|κ| is the local
    radius of curvature of the flank.
    """
    _, P1, P2 = profile_eval(profile, segment, s, derivatives=True)
    return np.imag(np.conj(P1) * P2) / np.abs(P1) ** 3


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
            "reduce 'pins.radius' or 'cycloid.eccentricity'")
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
            "must be positive; reduce the magnitude of 'cycloid.modification.equidistant'")
    if a * e / R >= 1.0:
        raise GeometryError(
            f"the trochoid loops: k = e·Zp/(d·(Rp + ΔRp)) = {a * e / R:.4f} ≥ 1; reduce "
            "'cycloid.eccentricity' or the negative 'cycloid.modification.shift'")
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
            f"{r_crit:.4g} mm for e = {e} mm, Rp + ΔRp = {R:.4g} mm — reduce 'pins.radius' or "
            "'cycloid.modification.equidistant', or 'cycloid.eccentricity', or enlarge 'pins.circle_radius'")

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
            "too large — they are meant to be micrometres ('cycloid.pitch_error')")
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
