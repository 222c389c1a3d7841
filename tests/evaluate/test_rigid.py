"""Rigid handbook model against published numbers, closed forms and invariants."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import CASES_DIR

from rvfem.case.definition import load_case
from rvfem.errors import CaseError
from rvfem.evaluate.rigid import (
    classical_pin_forces,
    equivalent_load,
    handbook_bearing_loads,
    handbook_components,
    handbook_load_extremes,
    load_cycle_angles,
    summarize_bearing_loads,
)


@pytest.fixture(scope="module")
def crv80e():
    return load_case(CASES_DIR / "crv80e.toml")


@pytest.fixture(scope="module")
def rv40e():
    return load_case(CASES_DIR / "rv40e.toml")


# --------------------------------------------------------------------------------------------
# Published numbers: Gao et al., CRV-80E (T = 784 N·m, e = 1.45, Rp = 76.5, Zp = 40, r0 = 42, N = 3)
# --------------------------------------------------------------------------------------------


def test_crv80e_maximum_load_matches_the_paper(crv80e):
    loads = handbook_bearing_loads(crv80e)            # 1° sampling
    summary = summarize_bearing_loads(loads, 4.0)
    f_max_exact, beta_max, _, _ = handbook_load_extremes(loads.components)
    # published values are rounded to 0.1 N: half a unit of the last digit is the tolerance
    assert f_max_exact == pytest.approx(5576.9, abs=0.05)       # exact maximum (measured +0.039 N)
    for s in summary:
        assert s.max_N == pytest.approx(5576.2, rel=2.5e-4)     # the paper's value (measured 1.25e-4, 1° sampling)
    # the paper's maximum contact stress occurs at θ = 340° in its bearing frame (= local angle β)
    assert math.degrees(beta_max) == pytest.approx(340.0, abs=0.5)   # paper in whole degrees (measured −0.44°)


def test_crv80e_fourth_power_mean_matches_the_paper(crv80e):
    summary = summarize_bearing_loads(handbook_bearing_loads(crv80e), 4.0)
    for s in summary:
        assert s.equivalent_N == pytest.approx(4374.1, abs=0.05)   # measured −0.0098 N


def test_crv80e_iso_exponent_equivalent_load(crv80e):
    # 10/3 mean of the same curve; reference value noted with the seed papers (4267.6 N).
    f = handbook_bearing_loads(crv80e).magnitude[0]
    assert equivalent_load(f, 10 / 3) == pytest.approx(4267.6, abs=0.05)   # measured −0.032 N


def test_each_bearing_takes_an_equal_share_of_the_pin_resultant_and_of_the_torque(crv80e):
    """Statics instead of the handbook's own formulas: with rigid bodies and equal cranks, bearing i
    acts on the disc with F_i = −P̄/N + (T_disc/(N·r0))·t_i, where P̄ is the resultant of the
    classical pin forces averaged over one pin pitch (taken from the pin-force distribution, not
    from eq. 4-7) and t_i = (−sin α_i, cos α_i) the tangent at the crank (moment balance
    N·r0·F1 = T_disc)."""
    zc, n, r0 = crv80e.cycloid.teeth, len(crv80e.cranks.angles_deg), crv80e.cranks.circle_radius
    th = 2 * np.pi / zc * np.arange(256) / 256
    pins = classical_pin_forces(crv80e, th)
    fx, fy = pins.fx.sum(axis=0), pins.fy.sum(axis=0)
    p_u = np.mean(fx * np.cos(th) + fy * np.sin(th))            # along the eccentricity
    p_perp = np.mean(-fx * np.sin(th) + fy * np.cos(th))        # perpendicular to it
    loads = handbook_bearing_loads(crv80e)
    t = loads.theta
    share = crv80e.loads.disc_torque_Nmm / (n * r0)
    scale = np.abs(loads.magnitude).max()
    for i, alpha in enumerate(np.radians(crv80e.cranks.angles_deg)):
        ref_x = -(p_u * np.cos(t) - p_perp * np.sin(t)) / n - share * np.sin(alpha)
        ref_y = -(p_u * np.sin(t) + p_perp * np.cos(t)) / n + share * np.cos(alpha)
        # measured 3.0e-8·F_max: k_y of eq. 5 is the continuous (Zp → ∞) value of the pitch average
        np.testing.assert_allclose(loads.fx[i], ref_x, rtol=0, atol=8e-8 * scale)
        np.testing.assert_allclose(loads.fy[i], ref_y, rtol=0, atol=8e-8 * scale)


def test_closed_form_K_of_eq10_equals_the_numerical_fourth_power_mean(crv80e):
    e, zc, r0, n, t0 = 1.45, 39, 42.0, 3, 784e3
    c = handbook_components(crv80e)
    k_y = c.k_y
    big_k = 1 / (2 * n * e * zc * r0) * (
        4 * (1 + k_y**2) * (e * zc) ** 2 * r0**2 + (1 + k_y**2) ** 2 * r0**4 + (e * zc) ** 4
    ) ** 0.25
    # F⁴ is a trigonometric polynomial of degree 2 in θ, so 8 samples integrate it exactly.
    loads = handbook_bearing_loads(crv80e, load_cycle_angles(45.0))
    assert equivalent_load(loads.magnitude[0], 4.0) == pytest.approx(big_k * t0, rel=5e-16)   # measured 2.2e-16
    assert big_k * t0 == pytest.approx(4374.1, abs=0.05)                    # measured −0.0098 N


def test_exact_extremes_bound_the_sampled_curve(crv80e):
    loads = handbook_bearing_loads(crv80e, load_cycle_angles(0.01))
    f_max, beta_max, f_min, beta_min = handbook_load_extremes(loads.components)
    assert loads.magnitude.max() == pytest.approx(f_max, rel=2e-9)     # measured 6.8e-10 (0.01° sampling)
    assert loads.magnitude.min() == pytest.approx(f_min, rel=1.5e-7)   # measured 5.1e-8
    alpha0 = math.radians(crv80e.cranks.angles_deg[0])
    at_max = handbook_bearing_loads(crv80e, beta_max + alpha0).magnitude[0, 0]
    at_min = handbook_bearing_loads(crv80e, beta_min + alpha0).magnitude[0, 0]
    # measured 1.1e-16, 2.2e-16
    assert (at_max, at_min) == (pytest.approx(f_max, rel=3e-16), pytest.approx(f_min, rel=5e-16))


# --------------------------------------------------------------------------------------------
# Invariants
# --------------------------------------------------------------------------------------------


def test_bearing_curves_are_shifts_and_vectors_rotate_with_the_cranks(rv40e):
    loads = handbook_bearing_loads(rv40e)            # 1° steps, cranks 120° apart
    n = loads.theta.size
    for i in range(1, 3):
        shift = round(n * i / 3)
        np.testing.assert_allclose(loads.magnitude[i], np.roll(loads.magnitude[0], shift), rtol=5e-15)   # measured 2.2e-15
        # the vector of bearing i at θ is bearing 0's vector at θ − 120°·i turned by 120°·i
        rot = 2 * math.pi * i / 3
        fx0, fy0 = np.roll(loads.fx[0], shift), np.roll(loads.fy[0], shift)
        # measured 2.5e-12 N on loads of 3.4 kN
        np.testing.assert_allclose(loads.fx[i], math.cos(rot) * fx0 - math.sin(rot) * fy0, rtol=0, atol=6e-12)
        np.testing.assert_allclose(loads.fy[i], math.sin(rot) * fx0 + math.cos(rot) * fy0, rtol=0, atol=6e-12)


def test_loads_are_linear_in_torque(rv40e):
    double = rv40e.replace(loads=dataclasses.replace(rv40e.loads, torque_Nm=2 * rv40e.loads.torque_Nm))
    a, b = handbook_bearing_loads(rv40e), handbook_bearing_loads(double)
    np.testing.assert_allclose(b.fx, 2 * a.fx, rtol=2e-16, atol=0)             # measured 0
    np.testing.assert_allclose(b.magnitude, 2 * a.magnitude, rtol=2e-16)       # measured 0


def test_four_discs_halve_the_load_of_two(rv40e):
    four = rv40e.replace(loads=dataclasses.replace(rv40e.loads, discs=4, torque_split="equal"), crank_support=None)
    np.testing.assert_allclose(handbook_bearing_loads(four).magnitude,
                               0.5 * handbook_bearing_loads(rv40e).magnitude, rtol=2e-16)   # measured 0


def test_bearing_forces_balance_the_pin_resultant_and_the_disc_torque(rv40e):
    loads = handbook_bearing_loads(rv40e)
    c = loads.components
    u = np.stack([np.cos(loads.theta), np.sin(loads.theta)])
    u_perp = np.stack([-np.sin(loads.theta), np.cos(loads.theta)])
    total = np.stack([loads.fx.sum(axis=0), loads.fy.sum(axis=0)])
    # The pins push on the disc with −ΣPx along u⊥ and +ΣPy along u; the bearings take the rest.
    np.testing.assert_allclose(total, c.sum_px * u_perp - c.sum_py * u, rtol=0, atol=6e-12)   # measured 2.3e-12 N
    r0 = rv40e.cranks.circle_radius
    bx, by = r0 * np.cos(loads.crank_angles)[:, None], r0 * np.sin(loads.crank_angles)[:, None]
    moment = (bx * loads.fy - by * loads.fx).sum(axis=0)
    np.testing.assert_allclose(moment, c.disc_torque_Nmm, rtol=1e-15)   # measured 4.4e-16


def test_handbook_needs_equally_spaced_cranks(rv40e):
    skewed = rv40e.replace(cranks=dataclasses.replace(rv40e.cranks, angles_deg=(90.0, 200.0, 330.0)))
    with pytest.raises(CaseError, match="equally spaced"):
        handbook_bearing_loads(skewed)


def test_handbook_needs_a_one_tooth_difference(rv40e):
    two = rv40e.replace(cycloid=dataclasses.replace(rv40e.cycloid, teeth=38))
    with pytest.raises(CaseError, match="one-tooth difference"):
        handbook_components(two)


def test_equivalent_load_properties():
    assert equivalent_load([3.0, 3.0, 3.0], 10 / 3) == pytest.approx(3.0, rel=2e-16)   # measured 0
    f = np.array([1.0, 2.0, 5.0, 0.5])
    assert equivalent_load(f, 10 / 3) < equivalent_load(f, 4.0) < f.max()
    assert equivalent_load(f, 1.0) == pytest.approx(f.mean(), rel=2e-16)            # measured 0
    np.testing.assert_allclose(equivalent_load(np.stack([f, 2 * f]), 3.0),
                               [equivalent_load(f, 3.0), 2 * equivalent_load(f, 3.0)], rtol=2e-16)   # measured 0
    with pytest.raises(ValueError):
        equivalent_load(f, 0.0)
    with pytest.raises(ValueError):
        equivalent_load(-f, 3.0)


def test_load_cycle_angles_cover_one_turn_without_the_endpoint():
    th = load_cycle_angles(1.0)
    assert th.size == 360 and th[0] == 0.0 and th[-1] == pytest.approx(math.radians(359.0), abs=2e-15)   # measured 8.9e-16
    assert load_cycle_angles(0.7).size == 514


def test_summary_angles_of_the_extremes(crv80e):
    s = summarize_bearing_loads(handbook_bearing_loads(crv80e), 4.0)[0]
    # bearing 0 sits at α = 90°: extremes at θ = β + 90° (maximum at β = 339.6°, minimum at 159.6°)
    assert s.max_at_deg == pytest.approx(70.0, abs=1e-13)    # measured 0
    assert s.min_at_deg == pytest.approx(250.0, abs=1e-13)   # measured 2.8e-14°


# --------------------------------------------------------------------------------------------
# Classical pin forces
# --------------------------------------------------------------------------------------------


def _pin_moment(pins):
    return (pins.x * pins.fy - pins.y * pins.fx).sum(axis=0)


def test_pin_force_moment_about_the_disc_centre_is_the_disc_torque(crv80e):
    zc = crv80e.cycloid.teeth
    t_disc = crv80e.loads.disc_torque_Nmm
    # Over one pin pitch of the mechanism (θ from 0 to 2π/Zc) the textbook distribution carries
    # exactly T_disc on average ...
    theta = 2 * np.pi / zc * np.arange(64) / 64
    pins = classical_pin_forces(crv80e, theta)
    moment = _pin_moment(pins)
    assert -moment.mean() == pytest.approx(t_disc, rel=4e-16)        # measured 0
    # ... and within 0.1 % at every angle: F_max assumes Σ sin²φ/(1 + K1² − 2K1 cos φ) = Zp/4,
    # the integral value, while the sum over 40 discrete pins deviates by O((2π/Zp)³) (about
    # 7.6e-4 here, from the Euler–Maclaurin endpoint terms of the half-range sum).
    np.testing.assert_allclose(-moment, t_disc, rtol=1e-3)           # measured 7.6e-4 (the physics above)
    # With exact_moment the amplitude is set from the discrete sum.
    exact = classical_pin_forces(crv80e, theta, exact_moment=True)
    np.testing.assert_allclose(-_pin_moment(exact), t_disc, rtol=2e-15)   # measured 7.8e-16


def test_pin_forces_act_through_the_pitch_point_on_the_loaded_half(crv80e):
    theta = np.radians([0.0, 13.0, 100.0, 271.5])
    pins = classical_pin_forces(crv80e, theta)
    e, zc = crv80e.cycloid.eccentricity, crv80e.cycloid.teeth
    px, py = e * zc * np.cos(theta), e * zc * np.sin(theta)
    # (P − pin) × F = 0: the line of action passes through the pitch point
    cross = (px - pins.x) * pins.fy - (py - pins.y) * pins.fx
    np.testing.assert_allclose(cross, 0.0, atol=2e-11)               # measured 7.3e-12 N·mm
    # pushing from the pin centre towards P
    dot = (px - pins.x) * pins.fx + (py - pins.y) * pins.fy
    assert np.all(dot >= 0)
    # which pins push: those on the half of the pin circle with 0 < φ < π, φ measured from the
    # eccentricity direction about the pin-circle centre (taken here from the pin positions)
    e_x, e_y = -e * np.cos(theta), -e * np.sin(theta)               # pin-circle centre
    phi = np.mod(np.arctan2(pins.y - e_y, pins.x - e_x) - theta, 2 * np.pi)
    on_loaded_half = (phi > 1e-9) & (phi < np.pi - 1e-9)
    loaded = pins.magnitude > 1e-9 * pins.f_max
    np.testing.assert_array_equal(loaded, on_loaded_half)
    assert np.all((pins.magnitude <= 2e-16 * pins.f_max)[~loaded])   # measured 7.0e-17·F_max (φ = π)
    np.testing.assert_allclose(np.hypot(pins.fx, pins.fy), pins.magnitude, rtol=5e-16)   # measured 2.2e-16
    # pins sit on the pin circle, whose centre is at −e·u from the disc centre
    np.testing.assert_allclose(np.hypot(pins.x + e * np.cos(theta), pins.y + e * np.sin(theta)),
                               crv80e.pins.circle_radius, rtol=5e-16)   # measured 2.2e-16


def test_about_half_the_pins_are_loaded(crv80e):
    """Classically (zero clearance, rigid disc, unmodified profile) a pin pushes on the disc only
    on the half of the pin circle where the disc's rolling motion about the pitch point closes the
    contact: 0 < φ < π measured from the eccentricity direction. The two pins on the line of
    centres (φ = 0 and φ = π) touch but carry nothing: their line of action through the pitch point
    runs through the disc centre, so it cannot transmit torque. With Zp = 40 pins that is 20
    loaded pins at a generic crank angle, and 19 when the ring puts a pin exactly on the line of
    centres (θ·Zc/Zp a multiple of the pin pitch 2π/Zp, e.g. θ = 0), never more than Zp/2."""
    zp, zc = crv80e.pins.count, crv80e.cycloid.teeth
    pitch = 2 * np.pi / zp
    # φ_j = 2πj/Zp − θ(1 − (Zp − Zc)/Zp): a pin lies on the line of centres when θ·Zc/Zp is a
    # multiple of the pin pitch
    on_line = np.array([0.0, pitch * zp / zc, 2 * pitch * zp / zc])
    generic = on_line + 0.37 * pitch * zp / zc
    for theta, expected in ((on_line, zp // 2 - 1), (generic, zp // 2)):
        pins = classical_pin_forces(crv80e, theta)
        count = np.sum(pins.magnitude > 1e-9 * pins.f_max, axis=0)
        np.testing.assert_array_equal(count, expected)


def test_pin_force_peak_follows_the_textbook_amplitude(crv80e):
    k1 = crv80e.short_amplitude_coefficient
    f_max = 4 * crv80e.loads.disc_torque_Nmm / (k1 * crv80e.cycloid.teeth * crv80e.pins.circle_radius)
    pins = classical_pin_forces(crv80e, np.linspace(0, 2 * np.pi / 39, 50))
    assert pins.magnitude.max() <= f_max * (1 + 1e-12)
    # the continuous maximum of sin φ/√(1 + K1² − 2K1 cos φ) is 1 at cos φ = K1
    assert pins.magnitude.max() == pytest.approx(f_max, rel=3e-6)   # measured −9.4e-7 (50 samples)


def test_pin_resultant_over_a_pitch_matches_the_handbook_components(crv80e):
    """Averaged over a pin pitch the classical pins give ΣP_x and ΣP_y = k_y ΣP_x of eq. 4."""
    zc = crv80e.cycloid.teeth
    theta = 2 * np.pi / zc * np.arange(256) / 256
    pins = classical_pin_forces(crv80e, theta)
    c = handbook_components(crv80e)
    fx, fy = pins.fx.sum(axis=0), pins.fy.sum(axis=0)
    radial = fx * np.cos(theta) + fy * np.sin(theta)
    tangential = -fx * np.sin(theta) + fy * np.cos(theta)
    assert -tangential.mean() == pytest.approx(c.sum_px, rel=3e-16)   # measured 1.1e-16
    assert radial.mean() == pytest.approx(c.sum_py, rel=5e-7)         # measured 1.9e-7 (k_y is the Zp → ∞ value)
    # and they balance the handbook bearing loads: pins + bearings = 0 on average
    bearings = handbook_bearing_loads(crv80e, theta)
    bx, by = bearings.fx.sum(axis=0), bearings.fy.sum(axis=0)
    b_radial = bx * np.cos(theta) + by * np.sin(theta)
    assert (radial + b_radial).mean() == pytest.approx(0.0, abs=5e-7 * c.sum_py)   # measured 1.9e-7·ΣP_y


# --------------------------------------------------------------------------------------------
# Reverse torque and the applicability of the handbook
# --------------------------------------------------------------------------------------------


def _reversed(case, crank_angles=None):
    cranks = case.cranks if crank_angles is None else dataclasses.replace(case.cranks, angles_deg=crank_angles)
    return case.replace(loads=dataclasses.replace(case.loads, torque_Nm=-case.loads.torque_Nm), cranks=cranks)


def test_reverse_torque_is_the_mirror_image_of_forward_torque(rv40e):
    """Cranks at 0°, 120°, 240° (symmetric about the x axis, as is the unmodified profile and the
    pin ring at θ = 0): reversing the torque at −θ gives the mirror image (x, −y) of forward
    torque at θ, bearing at α mapped to the bearing at −α, pin j to pin Zp − j."""
    fwd = rv40e.replace(cranks=dataclasses.replace(rv40e.cranks, angles_deg=(0.0, 120.0, 240.0)))
    rev = _reversed(fwd)
    theta = np.radians(np.arange(0.0, 360.0, 7.0))
    a, b = handbook_bearing_loads(fwd, theta), handbook_bearing_loads(rev, -theta)
    mirror = [0, 2, 1]
    scale = a.magnitude.max()
    np.testing.assert_allclose(b.fx[mirror], a.fx, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(b.fy[mirror], -a.fy, rtol=0, atol=1e-12 * scale)
    pa, pb = classical_pin_forces(fwd, theta), classical_pin_forces(rev, -theta)
    zp = fwd.pins.count
    pins = (zp - np.arange(zp)) % zp
    np.testing.assert_allclose(pb.fx[pins], pa.fx, rtol=0, atol=1e-12 * pa.magnitude.max())
    np.testing.assert_allclose(pb.fy[pins], -pa.fy, rtol=0, atol=1e-12 * pa.magnitude.max())
    # the extremes of a reversed torque: the same magnitudes, the local angles mirrored
    fa, fb = handbook_load_extremes(a.components), handbook_load_extremes(b.components)
    assert fb[0] == pytest.approx(fa[0], rel=1e-15) and fb[2] == pytest.approx(fa[2], rel=1e-15)
    assert (fb[1] + fa[1]) % (2 * math.pi) == pytest.approx(0.0, abs=1e-12) or \
        (fb[1] + fa[1]) % (2 * math.pi) == pytest.approx(2 * math.pi, abs=1e-12)


def test_reversed_bearing_forces_balance_the_reversed_pins(rv40e):
    rev = _reversed(rv40e)
    zc = rev.cycloid.teeth
    theta = 2 * np.pi / zc * np.arange(256) / 256
    pins = classical_pin_forces(rev, theta, exact_moment=True)
    bearings = handbook_bearing_loads(rev, theta)
    # the classical pins' moment about the disc centre is −T_disc (here +|T_disc|)
    moment = (pins.x * pins.fy - pins.y * pins.fx).sum(axis=0)
    np.testing.assert_allclose(moment, -rev.loads.disc_torque_Nmm, rtol=1e-12)
    r0 = rev.cranks.circle_radius
    bx, by = r0 * np.cos(bearings.crank_angles)[:, None], r0 * np.sin(bearings.crank_angles)[:, None]
    np.testing.assert_allclose((bx * bearings.fy - by * bearings.fx).sum(axis=0), rev.loads.disc_torque_Nmm, rtol=1e-14)
    # on average over a pin pitch the reversed pins push with +|ΣP_x| along u⊥ and ΣP_y along u
    # (the mirror image of forward torque: the radial part does not change sign)
    c = handbook_components(rev)
    pins = classical_pin_forces(rev, theta)
    fx, fy = pins.fx.sum(axis=0), pins.fy.sum(axis=0)
    radial = fx * np.cos(theta) + fy * np.sin(theta)
    tangential = -fx * np.sin(theta) + fy * np.cos(theta)
    assert c.sum_px < 0 < c.sum_py
    assert -tangential.mean() == pytest.approx(c.sum_px, rel=3e-16)
    assert radial.mean() == pytest.approx(c.sum_py, rel=5e-7)


def test_handbook_applicable_says_why_not(rv40e):
    from rvfem.evaluate.rigid import handbook_applicable

    assert handbook_applicable(rv40e) == (True, "")
    ok, reason = handbook_applicable(rv40e.replace(cycloid=dataclasses.replace(rv40e.cycloid, teeth=38)))
    assert not ok and reason.startswith("not defined for Zp − Zc ≠ 1") and "pins.count" in reason


def test_duty_cycle_rows_with_reversed_torque_count_with_their_magnitude(rv40e):
    from rvfem.case.definition import DutyRow
    from rvfem.evaluate.iso281 import case_duty_cycle_life

    rows = (DutyRow(0.5, 15.0, 412.0), DutyRow(0.5, 15.0, 300.0))
    fwd = rv40e.replace(loads=dataclasses.replace(rv40e.loads, duty_cycle=rows))
    mixed = rv40e.replace(loads=dataclasses.replace(
        rv40e.loads, torque_Nm=-412.0, duty_cycle=(DutyRow(0.5, 15.0, -412.0), DutyRow(0.5, 15.0, 300.0))))
    a, b = case_duty_cycle_life(fwd, [1000.0]), case_duty_cycle_life(mixed, [1000.0])
    assert b.service_life_h == pytest.approx(a.service_life_h, rel=1e-15)
    assert b.equivalent_torque_Nm == pytest.approx(a.equivalent_torque_Nm, rel=1e-15)


# --------------------------------------------------------------------------------------------
# Any tooth difference: which references exist
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def two_teeth():
    return load_case(CASES_DIR / "rv40e_two_teeth.toml")


def test_references_of_one_and_two_tooth_differences(rv40e, two_teeth):
    from rvfem.evaluate.rigid import references

    one = references(rv40e)
    assert one.handbook.defined and one.classical_pin_forces.defined and one.equal_share.defined
    assert one.bearing_loads == "handbook"
    two = references(two_teeth)
    assert two_teeth.pins.count - two_teeth.cycloid.teeth == 2
    assert not two.handbook.defined and not two.classical_pin_forces.defined and two.equal_share.defined
    assert two.bearing_loads == "equal_share"
    for ref in (two.handbook, two.classical_pin_forces):
        assert ref.why.startswith("not defined for Zp − Zc ≠ 1") and "'pins.count' − 'cycloid.teeth' = 2" in ref.why
    assert "any tooth difference" in two.equal_share.why
    # the rigid evaluation alone has no FE pin resultant to share
    alone = references(two_teeth, fe=False)
    assert not alone.equal_share.defined and "rvfem run" in alone.equal_share.why
    # unequally spaced cranks: equal sharing does not hold either
    skewed = references(two_teeth.replace(cranks=dataclasses.replace(two_teeth.cranks, angles_deg=(90.0, 200.0, 330.0))))
    assert not skewed.equal_share.defined and "equally spaced" in skewed.equal_share.why


def test_classical_pin_forces_need_a_one_tooth_difference_not_equal_cranks(rv40e, two_teeth):
    with pytest.raises(CaseError, match="not defined for Zp − Zc ≠ 1"):
        classical_pin_forces(two_teeth)
    # the distribution does not involve the cranks
    skewed = rv40e.replace(cranks=dataclasses.replace(rv40e.cranks, angles_deg=(90.0, 200.0, 330.0)))
    theta = load_cycle_angles(30.0)
    np.testing.assert_array_equal(classical_pin_forces(skewed, theta).magnitude,
                                  classical_pin_forces(rv40e, theta).magnitude)


def test_rigid_evaluation_of_a_two_tooth_difference_is_not_defined(two_teeth):
    """NaN loads in the layout of the handbook curves, no bearing rows, the reason; the torque share
    F1 = T_disc/(N·r0) and k = e·Zp/Rp, which do not depend on the pin forces, are numbers."""
    from rvfem.app.analysis import analyse_rigid
    from rvfem.evaluate.rigid import undefined_loads

    result = analyse_rigid(two_teeth)
    assert not result.defined and result.bearings == () and result.duty_cycle is None
    assert result.references.bearing_loads == "equal_share"
    assert result.loads.magnitude.shape == (3, 360) and np.isnan(result.loads.magnitude).all()
    c = undefined_loads(two_teeth).components
    assert c.f1 == pytest.approx(206000.0 / (3 * 36.0), rel=1e-15)
    assert c.k == pytest.approx(1.3 * 40 / 64.0, rel=1e-15)
    assert all(math.isnan(x) for x in (c.k_y, c.sum_px, c.sum_py, c.f2, c.f3))
    assert result.bearing_speed_rpm == pytest.approx(15.0 * 40 / 2, rel=1e-15)   # n_out·Zp/(Zp − Zc)


def _touching_pin_distribution(case, theta):
    """The classical distribution's derivation applied as it stands to any tooth difference: the
    pins that touch the unmodified profile (gap below 1 nm), forces along the line through the pitch
    point e·Zc/(Zp − Zc)·u(θ), each in proportion to its lever arm, moment T_disc exactly. Returns
    the forces (n, Zp), N, and the largest |sin| between a touching pin's contact normal and the
    line to the pitch point."""
    from rvfem.geometry import disc_geometry, pin_profile_contacts

    geom = disc_geometry(case)
    zp, zc, e = case.pins.count, case.cycloid.teeth, case.cycloid.eccentricity
    t_disc = case.loads.disc_torque_Nmm
    forces, off_normal = np.zeros((len(theta), zp)), 0.0
    for k, th in enumerate(theta):
        pc = pin_profile_contacts(geom, th)
        touching = np.abs(pc.gap) < 1e-6
        v = e * zc / (zp - zc) * np.array([math.cos(th), math.sin(th)]) - pc.centres
        v /= np.linalg.norm(v, axis=1)[:, None]
        sin = v[:, 0] * pc.normal[:, 1] - v[:, 1] * pc.normal[:, 0]
        off_normal = max(off_normal, float(np.abs(sin[touching]).max()))
        arm = pc.centres[:, 0] * v[:, 1] - pc.centres[:, 1] * v[:, 0]
        loaded = touching & (-math.copysign(1.0, t_disc) * arm > 1e-9)
        forces[k] = np.where(loaded, abs(t_disc) * np.abs(arm) / np.sum(arm[loaded] ** 2), 0.0)
    return forces, off_normal


@pytest.mark.slow
def test_two_teeth_rigid_limit_keeps_the_equal_share_but_not_the_classical_distribution(tmp_path):
    """Why rvfem gives no rigid pin-force reference for Zp − Zc ≠ 1, but keeps the equal share:
    in the stiff limit (disc 10⁶×, bores 10³× stiffer, linear pins of 3e5 N/mm, as the verification
    manual's rigid-limit section) the touching pins' normals pass through the pitch point, yet the
    FE departs from the touching-pin distribution by most of the peak pin force (a pin entering over
    a trimmed tip corner through a micrometre gap takes load the rigid distribution does not give
    it), while the FE bearing forces stay the equal share of the FE pin resultant."""
    from conftest import coarse_case

    from rvfem.evaluate.compare import equal_share_forces
    from rvfem.mesh import mesh_case
    from rvfem.solve.cycle import build_system, load_cycle, single_disc_stage

    case = coarse_case("rv40e_solid", cycloid={"teeth": 38})
    theta = load_cycle_angles(10.0)
    system = build_system(case, mesh_case(case, tmp_path), stiffness_scale=1e6, bearing_model="rigid_bore",
                          bearing_stiffness_scale=1e3, pin_model="linear", pin_stiffness_N_per_mm=3e5)
    fe = load_cycle(system, theta, saved_angles_deg=(), stage=single_disc_stage(system))
    rigid, off_normal = _touching_pin_distribution(case, theta)
    assert off_normal < 1e-12                                              # measured 1.0e-14
    assert np.abs(fe.pin_forces - rigid).max() / rigid.max() > 0.5        # measured 0.80
    share = equal_share_forces(case, fe)
    assert np.abs(fe.bearing_forces - share).max() / fe.bearing_loads.max() < 2e-3   # measured 6.9e-4
