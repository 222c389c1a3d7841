"""Disc geometry: cycloid profile, kinematics, pin gaps, features and geometry checks.

References are independent of the code under test: the classical parametric equation of the
one-tooth-difference cycloid profile and its closed-form radius of curvature (as in Liu et al.,
*Degradation law analysis and life estimation of transmission accuracy of RV reducer based on
tooth surface and bearing wear*, and the usual textbook form), brute-force sweeps of the pin ring,
and polar integration of the fan-hole area.
"""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest
from conftest import CASES_DIR
from scipy.integrate import quad
from scipy.optimize import brentq, minimize_scalar
from scipy.spatial import cKDTree

from rvfem.case.definition import load_case
from rvfem.errors import GeometryError
from rvfem.geometry import (
    FanHole,
    build_profile,
    crank_centres,
    disc_geometry,
    pin_centres,
    pin_profile_contacts,
    pitch_errors,
)

CASES = CASES_DIR


@pytest.fixture(scope="module")
def solid():
    return load_case(CASES / "rv40e_solid.toml")


@pytest.fixture(scope="module")
def fan():
    return load_case(CASES / "rv40e_fanholes.toml")


def with_cycloid(case, **changes):
    return case.replace(cycloid=dataclasses.replace(case.cycloid, **changes))


def with_modification(case, **changes):
    return with_cycloid(case, modification=dataclasses.replace(case.cycloid.modification, **changes))


# ------------------------------------------------------------------------------------------------
# Independent references
# ------------------------------------------------------------------------------------------------


def classical_profile(Rp, e, r, zp, n):
    """Classical one-tooth-difference cycloid profile (zc = zp − 1), dense polygon, (n, 2):

        x = Rp·cos φ − e·cos(Zp φ) − r·(cos φ − k·cos(Zp φ))/√S
        y = Rp·sin φ − e·sin(Zp φ) − r·(sin φ − k·sin(Zp φ))/√S,   k = e·Zp/Rp,
        S = 1 + k² − 2k·cos((Zp − 1)φ),   φ ∈ [0, 2π).
    """
    phi = 2 * np.pi * np.arange(n) / n
    k = e * zp / Rp
    S = np.sqrt(1 + k * k - 2 * k * np.cos((zp - 1) * phi))
    x = Rp * np.cos(phi) - e * np.cos(zp * phi) - r * (np.cos(phi) - k * np.cos(zp * phi)) / S
    y = Rp * np.sin(phi) - e * np.sin(zp * phi) - r * (np.sin(phi) - k * np.sin(zp * phi)) / S
    return np.stack([x, y], axis=1)


class ClassicalDistance:
    """Distance from points to the classical profile: nearest vertex of a 200k-point polygon, then
    point-to-segment distances on a 4001-point re-sampling of the equation around it (chord error
    below 1e-10 mm)."""

    def __init__(self, Rp, e, r, zp, n=200_000):
        self.args = (Rp, e, r, zp)
        self.n = n
        self.tree = cKDTree(classical_profile(Rp, e, r, zp, n))

    def __call__(self, pts):
        Rp, e, r, zp = self.args
        _, i = self.tree.query(pts)
        dphi = 2 * np.pi / self.n
        phi = (2 * np.pi * i / self.n)[:, None] + dphi * np.linspace(-3, 3, 4001)[None, :]
        k = e * zp / Rp
        S = np.sqrt(1 + k * k - 2 * k * np.cos((zp - 1) * phi))
        x = Rp * np.cos(phi) - e * np.cos(zp * phi) - r * (np.cos(phi) - k * np.cos(zp * phi)) / S
        y = Rp * np.sin(phi) - e * np.sin(zp * phi) - r * (np.sin(phi) - k * np.sin(zp * phi)) / S
        a = np.stack([x[:, :-1], y[:, :-1]], -1)
        b = np.stack([x[:, 1:], y[:, 1:]], -1)
        p = np.asarray(pts)[:, None, :]
        ab = b - a
        t = np.clip(np.sum((p - a) * ab, -1) / np.sum(ab * ab, -1), 0, 1)
        return np.min(np.linalg.norm(p - (a + t[..., None] * ab), axis=-1), axis=1)


def classical_theoretical_radius(Rp, e, zp, psi):
    """Closed-form radius of curvature of the theoretical (pin-centre) profile, one tooth
    difference: ρ = Rp·(1 + k² − 2k cos ψ)^{3/2} / (1 + Zp·k² − (1 + Zp)·k·cos ψ), ψ the phase
    (Zp − 1)φ; positive where the profile is convex."""
    k = e * zp / Rp
    return Rp * (1 + k * k - 2 * k * np.cos(psi)) ** 1.5 / (1 + zp * k * k - (1 + zp) * k * np.cos(psi))


def critical_pin_radius(Rp, e, zp):
    """Largest generating pin radius without undercut: min of the convex theoretical radius."""
    res = minimize_scalar(lambda p: 1.0 / classical_theoretical_radius(Rp, e, zp, p) * -1.0,
                          bounds=(0.0, math.pi), method="bounded", options={"xatol": 1e-14})
    grid = np.linspace(0, math.pi, 20001)
    kap = 1.0 / classical_theoretical_radius(Rp, e, zp, grid)
    i = int(np.argmax(kap))
    best = max(-res.fun, kap[i])
    # refine around the grid maximum
    res2 = minimize_scalar(lambda p: -1.0 / classical_theoretical_radius(Rp, e, zp, p),
                           bounds=(grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]),
                           method="bounded", options={"xatol": 1e-14})
    return 1.0 / max(best, -res2.fun)


def polygon_area(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def swept_pin_centres(case, n_theta, wrong_sign=False):
    """All pin centres over one crank turn, written out from the kinematics (not the code)."""
    zp, zc = case.pins.count, case.cycloid.teeth
    Rp, e = case.pins.circle_radius, case.cycloid.eccentricity
    th = 2 * np.pi * np.arange(n_theta) / n_theta
    j = np.arange(zp)
    sgn = -1.0 if wrong_sign else 1.0
    ang = 2 * np.pi * j[None, :] / zp + sgn * th[:, None] * (zp - zc) / zp
    c = Rp * np.exp(1j * ang) - e * np.exp(1j * th)[:, None]
    return np.stack([c.real.ravel(), c.imag.ravel()], axis=1)


# ------------------------------------------------------------------------------------------------
# Kinematics
# ------------------------------------------------------------------------------------------------


def test_pin_centres_ring_offset_and_rotation(solid):
    """Seen from the disc: ring centre at −e·u(θ), ring turned by +θ(Zp − Zc)/Zp."""
    zp, zc = solid.pins.count, solid.cycloid.teeth
    Rp, e = solid.pins.circle_radius, solid.cycloid.eccentricity
    for theta in (0.0, 0.7, 2.0, 5.5):
        c = pin_centres(solid, theta)
        assert c.shape == (zp, 2)
        centre = c.mean(axis=0)
        # measured 6.9e-15 mm
        np.testing.assert_allclose(centre, [-e * math.cos(theta), -e * math.sin(theta)], rtol=0, atol=2e-14)
        rel = c[0] - centre
        assert math.hypot(*rel) == pytest.approx(Rp, abs=3e-14)      # measured 1.4e-14 mm
        turned = math.atan2(rel[1], rel[0])
        # measured 8.6e-17 rad
        assert math.remainder(turned - theta * (zp - zc) / zp, 2 * math.pi) == pytest.approx(0, abs=2e-16)
    # θ = 0: pin 0 sits deepest in the tooth space on the +x axis, at Rp − e
    np.testing.assert_allclose(pin_centres(solid, 0.0)[0], [Rp - e, 0.0], rtol=0, atol=1e-14)   # measured 0


def test_crank_centres(solid):
    np.testing.assert_allclose(
        crank_centres(solid),
        [[36 * math.cos(math.radians(a)), 36 * math.sin(math.radians(a))] for a in (90, 210, 330)],
        rtol=0, atol=1e-14)                                                  # measured 0


# ------------------------------------------------------------------------------------------------
# Envelope property
# ------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def classical_distance(solid):
    return ClassicalDistance(solid.pins.circle_radius, solid.cycloid.eccentricity, solid.pins.radius,
                             solid.pins.count)


@pytest.mark.parametrize("theta", [0.0, 0.123, 1.0, 2.5, 4.0, 6.1])
def test_envelope_every_pin_touches_for_one_tooth_difference(solid, classical_distance, theta):
    """One might expect contact on "about half" the pins. For the unmodified
    one-tooth-difference profile the truth is *every* pin: each pin centre runs along the same
    closed trochoid the profile is the parallel curve of, so all Zp pins are at exactly r_rp from
    it at every θ (only about half of them can push, which is what "about half" describes: the
    loaded pins, not the touching ones). Reference: distance to the classical profile equation,
    evaluated independently (:class:`ClassicalDistance`)."""
    r = solid.pins.radius
    c = pin_centres(solid, theta)
    dist = classical_distance(c)
    # the reference polygon's chords limit these two to ~1e-11 mm
    assert np.all(dist - r >= -6e-11)                     # measured −2.3e-11 mm
    assert np.all(dist - r <= 1e-12)                      # measured 3.2e-13 mm
    pc = pin_profile_contacts(disc_geometry(solid), theta)
    assert np.max(np.abs(pc.gap)) < 1e-13                 # measured 4.3e-14 mm
    # closest points lie on the classical polygon and normals point from the profile to the pins
    assert np.max(classical_distance(pc.point)) < 6e-11   # measured 2.3e-11 mm
    np.testing.assert_allclose(pc.point + r * pc.normal, c, rtol=0, atol=1e-13)   # measured 4.3e-14 mm


def test_wrong_ring_rotation_sign_violates_the_envelope(solid):
    """With the ring turned the other way (−θ(Zp − Zc)/Zp) pins cut deep into the profile: the sign
    of pin_centres is not a convention but fixed by the envelope property."""
    c = swept_pin_centres(solid, 90, wrong_sign=True)
    tree = cKDTree(classical_profile(64.0, 1.3, 3.0, 40, 200_000))
    dist, _ = tree.query(c)
    assert np.min(dist) - solid.pins.radius < -1.3                 # measured −2.60 mm
    assert np.min(cKDTree(c).query(classical_profile(64.0, 1.3, 3.0, 40, 200_000))[0]) < 1.0   # measured 0.40 mm


@pytest.mark.parametrize("teeth", [39, 38])
def test_profile_is_the_tight_envelope_of_the_swept_pins(solid, teeth):
    """Zp − Zc = 1 and 2: over a full crank turn no pin enters the profile, and every profile point
    is touched by some pin (the profile is the boundary of the region the pins never reach)."""
    case = with_cycloid(solid, teeth=teeth)
    geom = disc_geometry(case)
    tree = cKDTree(swept_pin_centres(case, 6000))
    dist, _ = tree.query(geom.profile.points[::4])
    clearance = dist - case.pins.radius
    assert clearance.min() > -3e-14         # no interference (measured −9.3e-15 mm)
    assert clearance.max() < 1e-6           # tight up to the θ-sampling of the sweep (measured 4.3e-7 mm)


def test_two_tooth_difference_about_half_the_pins_touch(solid):
    """For Zp − Zc = 2 the tooth tips are trimmed corners; at any θ all pins clear the profile and
    about half of them touch (20 or 21 of 40 here)."""
    case = with_cycloid(solid, teeth=38)
    geom = disc_geometry(case)
    for theta in np.linspace(0, 2 * np.pi, 9):
        pc = pin_profile_contacts(geom, theta)
        assert pc.gap.min() > -1e-13                      # measured −3.0e-14 mm
        touching = int(np.sum(np.abs(pc.gap) < 1e-6))
        assert touching in (20, 21)                       # measured 20, 21


# ------------------------------------------------------------------------------------------------
# Lobes, modifications, curvature, undercut, pitch errors
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("teeth", [39, 38, 35])
def test_profile_has_zc_lobes(solid, teeth):
    prof = build_profile(with_cycloid(solid, teeth=teeth))
    rad = np.hypot(prof.points[:, 0], prof.points[:, 1])
    is_max = (rad > np.roll(rad, 1)) & (rad >= np.roll(rad, -1))
    is_min = (rad < np.roll(rad, 1)) & (rad <= np.roll(rad, -1))
    assert is_max.sum() == teeth
    assert is_min.sum() == teeth
    # Zc-fold symmetry: rotating the samples by one lobe maps them onto themselves
    z = prof.points[:, 0] + 1j * prof.points[:, 1]
    n = len(z) // teeth
    np.testing.assert_allclose(np.roll(z, -n), z * np.exp(2j * np.pi / teeth), rtol=0, atol=2e-13)   # measured 8.6e-14 mm


@pytest.mark.parametrize("equidistant, shift", [(0.0, 0.0), (0.01, 0.0), (0.0, -0.02),
                                                (-0.004, -0.017), (0.05, 0.03)])
def test_modifications_change_tip_and_root_by_shift_minus_equidistant(solid, equidistant, shift):
    Rp, e, r = solid.pins.circle_radius, solid.cycloid.eccentricity, solid.pins.radius
    prof = build_profile(with_modification(solid, equidistant=equidistant, shift=shift))
    rad = np.hypot(prof.points[:, 0], prof.points[:, 1])
    assert rad.max() - (Rp + e - r) == pytest.approx(shift - equidistant, abs=5e-14)   # measured 1.8e-14 mm
    assert rad.min() - (Rp - e - r) == pytest.approx(shift - equidistant, abs=5e-14)   # measured 1.2e-14 mm


@pytest.mark.parametrize("theta", [0.0, 0.4, 3.0])
def test_modified_profile_gaps(solid, theta):
    """Liu et al.'s negative equidistant + negative shift (ΔRrp = −0.004, ΔRp = −0.017 mm) at fixed
    disc orientation. Exact reference: distance from the pins (Rp, r_rp) to the classical profile
    generated with Rp + ΔRp and r_rp + ΔRrp. First-order reference: the gap of the pin at trochoid
    phase φ is the normal offset of the profile there, g ≈ ΔRrp − ΔRp·(1 − k·cos ψ)/√(1 + k² −
    2k·cos ψ), ψ = (Zp − 1)φ, φ = 2πj/Zp + θ/Zp; it holds to ~0.3 µm (second-order terms are
    largest next to the roots, where pin and profile are nearly conformal). So 13 µm at root and
    tip, about 6 µm on the flanks, and no pin touches."""
    d_rrp, d_rp = -0.004, -0.017
    case = with_modification(solid, equidistant=d_rrp, shift=d_rp)
    pc = pin_profile_contacts(disc_geometry(case), theta)
    Rp, e, r, zp = solid.pins.circle_radius, solid.cycloid.eccentricity, solid.pins.radius, solid.pins.count
    exact = ClassicalDistance(Rp + d_rp, e, r + d_rrp, zp)(pin_centres(case, theta)) - r
    np.testing.assert_allclose(pc.gap, exact, rtol=0, atol=6e-11)       # measured 2.4e-11 mm (reference chords)
    k = solid.short_amplitude_coefficient
    psi = (zp - 1) * (2 * np.pi * np.arange(zp) / zp + theta / zp)
    first_order = d_rrp - d_rp * (1 - k * np.cos(psi)) / np.sqrt(1 + k * k - 2 * k * np.cos(psi))
    np.testing.assert_allclose(pc.gap, first_order, rtol=0, atol=4e-4)  # measured 2.9e-4 mm
    assert 0.005 < pc.gap.min() and pc.gap.max() < 0.013 + 1.5e-14   # 13 µm at root and tip (min 5.9 µm)
    if theta == 0.0:
        assert pc.gap[0] == pytest.approx(0.013, abs=1.5e-14)        # pin 0 deepest in a root (measured 5.2e-15)


def test_rotation_modification_rotates_the_profile(solid):
    base = build_profile(solid)
    rot = build_profile(with_modification(solid, rotation_deg=0.05))
    d = math.radians(0.05)
    z0 = base.points[:, 0] + 1j * base.points[:, 1]
    z1 = rot.points[:, 0] + 1j * rot.points[:, 1]
    np.testing.assert_allclose(z1, z0 * np.exp(1j * d), rtol=0, atol=6e-14)   # measured 2.2e-14 mm
    # the roots (minimum radius, where s = 0) moved by +0.05°
    zc = solid.cycloid.teeth
    roots = np.angle(z1[np.isclose(np.abs(z1), np.abs(z1).min(), atol=1e-12, rtol=0)])
    # measured 9.7e-16 rad
    np.testing.assert_allclose(np.mod(roots - d + np.pi / zc, 2 * np.pi / zc) - np.pi / zc, 0, atol=3e-15)
    # turning the profile counter-clockwise at θ = 0 presses the flanks into the pins on one side
    # of the eccentric line and opens the gaps on the other
    pc = pin_profile_contacts(disc_geometry(with_modification(solid, rotation_deg=0.05)), 0.0)
    assert np.all(pc.gap[1:20] < 0) and np.all(pc.gap[21:] > 0)


def test_curvature_matches_closed_form_and_three_point_circles(solid):
    """Sampled curvature vs the closed-form radius of the theoretical profile minus r_rp, and vs
    circles through three consecutive points of the independent classical polygon."""
    Rp, e, r, zp = solid.pins.circle_radius, solid.cycloid.eccentricity, solid.pins.radius, solid.pins.count
    prof = build_profile(solid)
    psi = (zp - 1) * prof.param                       # phase of the base parameter
    rho_t = classical_theoretical_radius(Rp, e, zp, psi)
    kappa_ref = 1.0 / (rho_t - r)
    np.testing.assert_allclose(prof.curvature, kappa_ref, rtol=8e-13, atol=1e-14)   # measured 2.7e-13 relative
    # three-point circles on the classical polygon at the same angles
    n = 400_000
    poly = classical_profile(Rp, e, r, zp, n)
    i = (np.arange(0, n, 997))
    a, b, c = poly[i - 1], poly[i], poly[(i + 1) % n]
    ab, bc, ca = np.linalg.norm(a - b, axis=1), np.linalg.norm(b - c, axis=1), np.linalg.norm(c - a, axis=1)
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    kappa_3 = 2 * cross / (ab * bc * ca)
    phi = 2 * np.pi * i / n
    kappa_cf = 1.0 / (classical_theoretical_radius(Rp, e, zp, (zp - 1) * phi) - r)
    np.testing.assert_allclose(kappa_3, kappa_cf, rtol=0, atol=4e-6)   # measured 1.5e-6 1/mm (O(h²) of the three points)


def test_undercut_check_fires_exactly_at_zero_radius_via_pin_radius(solid):
    Rp, e, r, zp = solid.pins.circle_radius, solid.cycloid.eccentricity, solid.pins.radius, solid.pins.count
    r_crit = critical_pin_radius(Rp, e, zp)
    assert 4.60 < r_crit < 4.62                     # measured 4.6117 mm for the RV-40E data
    build_profile(with_modification(solid, equidistant=r_crit - r - 1e-6))
    with pytest.raises(GeometryError, match="undercut") as info:
        build_profile(with_modification(solid, equidistant=r_crit - r + 1e-6))
    msg = str(info.value)
    assert "minimum radius of curvature" in msg and "profile angle" in msg and "pins.radius" in msg


def test_undercut_check_fires_exactly_via_eccentricity(solid):
    Rp, r, zp = solid.pins.circle_radius, solid.pins.radius, solid.pins.count
    e_crit = brentq(lambda e: critical_pin_radius(Rp, e, zp) - r, 1.3, 1.59, xtol=1e-12)
    build_profile(with_cycloid(solid, eccentricity=e_crit - 1e-5))
    with pytest.raises(GeometryError, match="undercut"):
        build_profile(with_cycloid(solid, eccentricity=e_crit + 1e-5))


def test_pitch_errors_rotate_each_tooth(solid):
    """Tooth k (tip at (2k − 1)π/Zc) turns by E_t(k)/R_m, E_t(k) = E_max·sin((k − 1)π/2)."""
    amp = 0.02
    case = with_cycloid(solid, pitch_error=dataclasses.replace(solid.cycloid.pitch_error, amplitude=amp))
    zc = case.cycloid.teeth
    k = np.arange(1, zc + 1)
    expected = amp * np.resize([0.0, 1.0, 0.0, -1.0], zc)       # sin((k − 1)π/2) for k = 1, 2, 3, 4, …
    np.testing.assert_allclose(pitch_errors(case), expected, rtol=0, atol=3e-16)   # measured 1.2e-16 mm (sin kπ)
    ideal, err = build_profile(solid), build_profile(case)
    r_m = solid.pins.circle_radius - solid.pins.radius
    tip_ideal = ideal.spline_points[:, -1]          # right end of segment j = tip of tooth j + 1
    tip_err = err.spline_points[:, -1]
    dang = np.arctan2(tip_err[:, 1], tip_err[:, 0]) - np.arctan2(tip_ideal[:, 1], tip_ideal[:, 0])
    np.testing.assert_allclose(dang, expected / r_m, rtol=0, atol=8e-16)    # measured 2.6e-16 rad
    np.testing.assert_allclose(np.arctan2(tip_ideal[:, 1], tip_ideal[:, 0]) % (2 * np.pi),
                               ((2 * k - 1) * np.pi / zc) % (2 * np.pi), rtol=0, atol=2.5e-15)   # measured 8.9e-16
    # pins whose closest point lies on a tooth outside the root blends: exactly zero gap on the
    # unrotated teeth (k odd), and to first order −δ_k·(P × n) on the rotated ones
    geom = disc_geometry(case)
    for theta in (0.0, 0.5, 1.7):
        pc = pin_profile_contacts(geom, theta)
        w = err.blend_half_width
        side = np.where(pc.param > w, 0, np.where(pc.param < -w, -1, 99))
        on_tooth = side != 99
        tooth_idx = np.mod(pc.segment + side, zc)[on_tooth]       # 0-based k − 1
        delta = expected[tooth_idx] / r_m
        p, nrm = pc.point[on_tooth], pc.normal[on_tooth]
        first_order = -delta * (p[:, 0] * nrm[:, 1] - p[:, 1] * nrm[:, 0])
        gaps = pc.gap[on_tooth]
        assert np.all(np.abs(gaps[delta == 0]) < 6e-14)          # measured 2.5e-14 mm
        np.testing.assert_allclose(gaps, first_order, rtol=0, atol=1e-4)   # measured 3.3e-5 mm
        assert np.max(np.abs(gaps)) > 0.0075                       # measured 0.0151 mm


# ------------------------------------------------------------------------------------------------
# Features
# ------------------------------------------------------------------------------------------------


def fan_hole_area_polar(h: FanHole) -> float:
    """Area of a filleted annular sector by polar integration: at radius ρ the hole spans
    ±φ_max(ρ), φ_max = α inside the straight part, else α − γ + ψ(ρ) with ψ from the law of
    cosines on the fillet circle (centre at ρ_c, angle α − γ from the centre line)."""
    ri, ro, a, f = h.inner_radius, h.outer_radius, h.half_span, h.fillet_radius
    go, gi = math.asin(f / (ro - f)), math.asin(f / (ri + f))

    def half_width(rho):
        for rc, g in ((ro - f, go), (ri + f, gi)):
            t = rc * math.cos(g)                      # radius of the tangent point on the side
            if (rc == ro - f and rho > t) or (rc == ri + f and rho < t):
                cpsi = (rho * rho + rc * rc - f * f) / (2 * rho * rc)
                return a - g + math.acos(max(-1.0, min(1.0, cpsi)))
        return a

    breaks = [ri, (ri + f) * math.cos(gi), (ro - f) * math.cos(go), ro]
    return sum(quad(lambda p: 2 * half_width(p) * p, lo, hi, epsabs=1e-12, epsrel=1e-12)[0]
               for lo, hi in zip(breaks[:-1], breaks[1:]))


def test_fan_holes_from_ligament(fan):
    geom = disc_geometry(fan)
    assert [h.name for h in geom.holes] == ["hole_0", "hole_1", "hole_2"]
    # centred between the cranks (90°, 210°, 330°) → 150°, 270°, 30°
    np.testing.assert_allclose(np.degrees([h.centre_angle for h in geom.holes]) % 360, [150, 270, 30],
                               atol=1.5e-13)                               # measured 5.7e-14°
    # the straight side is nearest the bore: r0·sin(Δ) − R_b = ligament, Δ = 60° − half span
    r0, rb, lig = 36.0, 18.0, 4.5
    expected_half = math.radians(60.0) - math.asin((rb + lig) / r0)
    for h in geom.holes:
        assert h.half_span == pytest.approx(expected_half, abs=5e-14)     # measured 1.9e-14 rad
        assert h.area == pytest.approx(fan_hole_area_polar(h), rel=5e-16)  # measured 1.1e-16
    walls = {(w.first, w.second): w.thickness for w in geom.walls}
    assert walls[("bore_0", "hole_0")] == pytest.approx(lig, abs=5e-7)   # measured 2.0e-7 mm (wall sampling)


def test_solid_disc_area_and_walls(solid):
    geom = disc_geometry(solid)
    poly = classical_profile(64.0, 1.3, 3.0, 40, 400_000)
    exact = polygon_area(poly) - math.pi * 12**2 - 3 * math.pi * 18**2
    assert geom.area == pytest.approx(exact, rel=4e-7)          # measured 1.6e-7 (polygon of samples)
    walls = {(w.first, w.second): w.thickness for w in geom.walls}
    assert walls[("central_hole", "bore_0")] == pytest.approx(36 - 18 - 12, abs=4e-6)   # measured 1.4e-6 mm
    assert walls[("profile", "central_hole")] == pytest.approx(59.7 - 12, abs=2e-14)    # measured 7.1e-15 mm


def test_error_hole_cuts_a_bore(fan):
    case = fan.replace(fan_holes=dataclasses.replace(fan.fan_holes, ligament=None, span_deg=90.0))
    with pytest.raises(GeometryError, match=r"hole [1-3] overlaps bore [1-3] by \d+\.\d{3} mm .*'fan_holes\.span_deg'"):
        disc_geometry(case)


def test_error_round_hole_cuts_the_profile(solid):
    from rvfem.case.definition import RoundHoles
    case = solid.replace(round_holes=RoundHoles(radius=3.0, circle_radius=58.0, count=3))
    with pytest.raises(GeometryError, match=r"hole [1-3] cuts into the teeth by 0\.\d{3} mm .*'round_holes\.radius'"):
        disc_geometry(case)


def test_error_rim_too_thin(solid):
    """Bores of radius 22 on r0 = 36 leave about 1.77 mm to the tooth flanks (< min_wall 2); the
    message names the thinnest wall, its value and the two features."""
    case = solid.replace(crank_bearing=dataclasses.replace(solid.crank_bearing, bore_radius=22.0),
                         cycloid=dataclasses.replace(solid.cycloid, central_hole_radius=8.0))
    with pytest.raises(GeometryError, match=r"between the tooth profile and bore [1-3] is only 1\.7\d\d mm thick "
                                            r"\(mesh\.min_wall = 2\.0 mm\)"):
        disc_geometry(case)
    # the same disc passes when thinner walls are allowed
    thin = case.replace(mesh=dataclasses.replace(case.mesh, min_wall=1.5))
    wall = disc_geometry(thin).walls[0]
    assert wall.first == "profile" and wall.second.startswith("bore_")
    # independent: min over the classical profile of the distance to the bore centre, minus 22
    poly = classical_profile(64.0, 1.3, 3.0, 40, 400_000)
    ref = np.min(np.hypot(poly[:, 0], poly[:, 1] - 36.0)) - 22.0
    assert wall.thickness == pytest.approx(ref, abs=1e-4)       # measured 4.2e-5 mm (wall sampling)


def test_error_ligament_unreachable_and_fillet_too_large(fan):
    with pytest.raises(GeometryError, match="ligament"):
        disc_geometry(fan.replace(fan_holes=dataclasses.replace(fan.fan_holes, ligament=40.0)))
    with pytest.raises(GeometryError, match="fillet radius 16.5 mm does not fit the radial height"):
        disc_geometry(fan.replace(fan_holes=dataclasses.replace(fan.fan_holes, fillet_radius=16.5)))
    with pytest.raises(GeometryError, match="too narrow for fillets"):
        disc_geometry(fan.replace(fan_holes=dataclasses.replace(fan.fan_holes, ligament=None, span_deg=8.0)))


def test_error_central_hole_into_bores(solid):
    case = with_cycloid(solid, central_hole_radius=19.0)
    with pytest.raises(GeometryError, match=r"bore [1-3] overlaps the central hole by 1\.000 mm"):
        disc_geometry(case)


def with_fan(case, **changes):
    return case.replace(fan_holes=dataclasses.replace(case.fan_holes, **changes))


def test_feature_names_in_messages_are_numbered_from_1():
    from rvfem.geometry import feature_text

    assert [feature_text(n) for n in ("bore_0", "bore_2", "hole_0", "hole_11", "central_hole", "profile")] == [
        "bore 1", "bore 3", "hole 1", "hole 12", "the central hole", "the tooth profile"]


def test_geometry_errors_name_the_source_and_a_key(fan):
    """Every geometry error starts with the case's source and quotes the keys to change (the command
    line's one-line errors name a key or a cause)."""
    with pytest.raises(GeometryError) as info:
        disc_geometry(with_fan(fan, ligament=0.5))
    message = str(info.value)
    assert message.startswith(f"{fan.source}: the wall between bore ") and "and hole " in message
    assert "is only 0.500 mm thick" in message and "'fan_holes.ligament'" in message
    assert not re.search(r"\b(bore|hole)_\d", message)      # no 0-based feature names


def test_fan_holes_beyond_the_teeth_are_blamed_on_the_teeth(fan):
    """Fan holes at radii 100–120 mm (with a ligament) used to be reported as holes that 'would meet
    each other'; they lie in (beyond) the teeth."""
    with pytest.raises(GeometryError, match=r"fan holes at radii 100–120 mm cut the teeth \(root radius 59\.700 mm\)"
                                            r": 'fan_holes\.outer_radius' must stay below 57\.700 mm") as info:
        disc_geometry(with_fan(fan, inner_radius=100.0, outer_radius=120.0))
    assert "meet" not in str(info.value)
    with pytest.raises(GeometryError, match="fan holes at radii 5–10 mm overlap the central hole"):
        disc_geometry(with_fan(fan, inner_radius=5.0, outer_radius=10.0, fillet_radius=1.0))
    # with a span instead of a ligament, the overlap check names the hole and the teeth
    with pytest.raises(GeometryError, match=r"hole 1 (lies entirely outside the cycloid profile|cuts into the teeth)"):
        disc_geometry(with_fan(fan, inner_radius=100.0, outer_radius=120.0, ligament=None, span_deg=30.0))


def test_a_ligament_the_holes_never_reach_says_so(fan):
    """Holes at radii 14–16 mm stay about 2 mm from the bores (36 − 18 − 16) even at their widest, so a
    1 mm ligament cannot set their span."""
    with pytest.raises(GeometryError, match=r"hole 1: even at its widest \(a span of 120°, where neighbouring fan "
                                            r"holes meet\) it stays 2\.0\d\d mm from the bores, more than "
                                            r"'fan_holes\.ligament' = 1 mm.*give 'fan_holes\.span_deg'"):
        disc_geometry(with_fan(fan, inner_radius=14.0, outer_radius=16.0, fillet_radius=0.5, ligament=1.0))


def test_a_near_touch_is_given_in_micrometres(solid):
    """An overlap of 0.2 µm used to read "overlap -0.000 mm"."""
    with pytest.raises(GeometryError, match=r"bore [1-3] overlaps the central hole by 0\.\d+ µm") as info:
        disc_geometry(with_cycloid(solid, central_hole_radius=18.0002))
    assert "0.000 mm" not in str(info.value)
    with pytest.raises(GeometryError, match=r"between the central hole and bore [1-3] is only 50 µm thick"):
        disc_geometry(with_cycloid(solid, central_hole_radius=17.95))


def test_a_disc_of_metres_is_checked_on_capped_samples():
    """The fan-hole disc scaled 30×: its outlines are sampled at most WALL_SAMPLES times per feature
    length (not every 0.02 mm), and the walls still come out right (the ligament 30 × 4.5 mm)."""
    from rvfem.geometry.features import WALL_SAMPLES

    sets = ["pins.circle_radius=1920", "pins.radius=90", "cycloid.eccentricity=39", "cycloid.central_hole_radius=360",
            "cranks.circle_radius=1080", "crank_bearing.bore_radius=540", "crank_bearing.pitch_diameter=930",
            "crank_bearing.roller_diameter=150", "fan_holes.inner_radius=510", "fan_holes.outer_radius=1470",
            "fan_holes.ligament=135", "fan_holes.fillet_radius=60", "mesh.size_interior=75", "mesh.size_flank=10",
            "mesh.size_bore=12", "mesh.size_hole=15", "mesh.min_wall=60"]
    geom = disc_geometry(load_case(CASES / "rv40e_fanholes.toml", sets))
    assert WALL_SAMPLES * 0.02 == pytest.approx(400.0)
    wall = geom.walls[0]
    assert {wall.first[:5], wall.second[:5]} == {"bore_", "hole_"}
    assert wall.thickness == pytest.approx(135.0, abs=1e-3)
