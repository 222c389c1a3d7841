"""The parts of the reducer outside the discs' contact problem, each against its closed form:
``[pin_housing]`` (the pin–groove Hertz contact, the pin's bending, the housing ring against Roark's
thick ring, the series law), ``[carrier]`` (the pillar frame against the clamped–guided beam, the
share of the torque through plate 2), ``[main_bearings]`` (Hertz point contact against the
circular-contact closed form, the pair's stiffness against the sums over its balls, no torsional
term) and the compliance shares of the three on a coarse linear stage."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import coarse_case

from rvfem.case.definition import load_case
from rvfem.solve.contact_laws import hertz_pin_approach, hertz_pin_law
from rvfem.solve.stage_carrier import CarrierTable, carrier_output_compliance, pillar_torsional_stiffness, plate_two_share
from rvfem.solve.stage_main_bearings import MainBearingsTable, ball_approach, ball_stiffness, pair_stiffness
from rvfem.solve.stage_parts import STIFFEN, component_names
from rvfem.solve.stage_pin_housing import (
    PinHousingTable,
    classical_pin_forces,
    groove_approach,
    pin_bending_compliance,
    ring_influence,
    seat_approach,
    series_law,
)

E, NU = 206000.0, 0.3


def test_the_three_parts_are_components_with_the_names_scripts_rely_on():
    names = component_names()
    for name in ("pin_housing", "carrier", "main_bearings"):
        assert name in names
    case = load_case("cases/rv40e_fanholes.toml")        # there by default, with their defaults
    assert case.component_table("pin_housing") == PinHousingTable()
    assert case.component_table("carrier") == CarrierTable()
    assert case.component_table("main_bearings") == MainBearingsTable()


# ------------------------------------------------------------------------------------------------
# [pin_housing]
# ------------------------------------------------------------------------------------------------


def test_the_groove_contact_is_johnsons_line_contact():
    """δ = P·c(2 ln(4r/a) − 1) + 2P·c(ln(2d/a) − ν/(2(1 − ν))), a = √(4PR/(πE*)),
    R = r·R_g/(R_g − r), written out here from Johnson, Contact Mechanics, §4.2/§5.6."""
    r, rg, L, d = 3.0, 3.01, 9.0, 14.0
    Q = np.array([50.0, 400.0, 2000.0])
    delta, slope = groove_approach(Q, length=L, pin_radius=r, groove_radius=rg, pin_modulus=E, pin_poisson=NU,
                                   housing_modulus=E, housing_poisson=NU, depth=d)
    c = (1 - NU ** 2) / (math.pi * E)
    e_star = E / (2 * (1 - NU ** 2))
    R = r * rg / (rg - r)
    for q, dl in zip(Q, delta):
        P = q / L
        a = math.sqrt(4 * P * R / (math.pi * e_star))
        ref = P * c * (2 * math.log(4 * r / a) - 1) + 2 * P * c * (math.log(2 * d / a) - NU / (2 * (1 - NU)))
        assert dl == pytest.approx(ref, rel=1e-12)
    h = 1e-3 * Q
    num = (groove_approach(Q + h, length=L, pin_radius=r, groove_radius=rg, pin_modulus=E, pin_poisson=NU,
                           housing_modulus=E, housing_poisson=NU, depth=d)[0] - groove_approach(
        Q - h, length=L, pin_radius=r, groove_radius=rg, pin_modulus=E, pin_poisson=NU, housing_modulus=E,
        housing_poisson=NU, depth=d)[0]) / (2 * h)
    np.testing.assert_allclose(slope, num, rtol=1e-6)


def test_the_pins_bending_is_the_simply_supported_timoshenko_beam():
    """Mid-span point load: PL³/(48EI) + PL/(4κGA) (Roark Table 8.1); off-centre: the unit-load
    integral ∫ M m/(EI) dx + ∫ V v/(κGA) dx evaluated numerically."""
    D, L = 6.0, 30.0
    I, A = math.pi * D ** 4 / 64, math.pi * D ** 2 / 4
    G = E / (2 * (1 + NU))
    k = 6 * (1 + NU) / (7 + 6 * NU)
    assert pin_bending_compliance(L, L / 2, D, E, NU) == pytest.approx(L ** 3 / (48 * E * I) + L / (4 * k * G * A), rel=1e-12)
    a = 8.0
    x = np.linspace(0.0, L, 200001)
    m = np.where(x < a, (L - a) / L * x, a / L * (L - x))
    v = np.where(x < a, (L - a) / L, -a / L)
    ref = np.trapezoid(m * m, x) / (E * I) + np.trapezoid(v * v, x) / (k * G * A)
    assert pin_bending_compliance(L, a, D, E, NU) == pytest.approx(ref, rel=1e-6)
    assert pin_bending_compliance(0.0, 0.0, D, E, NU) == 0.0          # seated along its length


@pytest.mark.parametrize("h", [5.0, 30.0])
def test_the_ring_under_a_diametral_pair_is_roarks_thick_ring(h):
    """Two equal inward forces W along a diameter: ΔD along them = −(WR³/EI)(K1·π/4 − 2K2²/π),
    K1 = 1 − α + β, K2 = 1 − α, α = I/(AR²), β = F·EI/(GAR²), F = 6/5 (Roark, Formulas for Stress
    and Strain, Table 9.2 case 1: thick rings, hoop stress and radial shear)."""
    R, b = 80.0, 20.0
    A, I = b * h, b * h ** 3 / 12
    G = E / (2 * (1 + NU))
    Gm = ring_influence(np.array([0.0, math.pi]), R, E, NU, A, I, 1.2, modes=4000)
    w = Gm @ np.array([-1.0, 0.0, -1.0, 0.0])
    alpha, beta = I / (A * R * R), 1.2 * E * I / (G * A * R * R)
    K1, K2 = 1 - alpha + beta, 1 - alpha
    ref = -(K1 * math.pi / 4 - 2 * K2 ** 2 / math.pi) * R ** 3 / (E * I)
    assert w[0] + w[2] == pytest.approx(ref, rel=1e-3)


def test_a_thin_ring_widens_across_a_diametral_pair_as_timoshenkos():
    """The diameter across the loads grows by (2/π − 1/2)·WR³/EI (thin ring, Timoshenko)."""
    R, b, h = 80.0, 20.0, 0.2
    Gm = ring_influence(np.array([0.0, math.pi, math.pi / 2, 1.5 * math.pi]), R, E, NU, b * h, b * h ** 3 / 12, 1.2,
                        modes=4000)
    w = Gm @ np.array([-1.0, 0, -1.0, 0, 0, 0, 0, 0])
    assert w[4] + w[6] == pytest.approx((2 / math.pi - 0.5) * R ** 3 / (E * b * h ** 3 / 12), rel=1e-3)


def test_the_ring_is_reciprocal():
    psi = 2 * math.pi * np.arange(12) / 12 + 0.1 * np.sin(np.arange(12))
    Gm = ring_influence(psi, 80.0, E, NU, 600.0, 45000.0)
    np.testing.assert_allclose(Gm, Gm.T, rtol=0, atol=1e-12 * np.abs(Gm).max())    # Maxwell–Betti
    assert np.all(np.linalg.eigvalsh(0.5 * (Gm + Gm.T)) > -1e-12 * np.abs(Gm).max())   # an energy


def test_the_classical_pin_forces_carry_the_discs_torque():
    case = load_case("cases/rv40e_fanholes.toml")
    T = 412.0
    _, f = classical_pin_forces(case, T, 0.3)
    zp, e, rp = case.pins.count, case.cycloid.eccentricity, case.pins.circle_radius
    psi = 2 * math.pi * np.arange(zp) / zp
    c = rp * np.column_stack([np.cos(psi), np.sin(psi)]) - e * np.array([math.cos(0.3), math.sin(0.3)])
    moment = np.sum(c[:, 0] * f[:, 1] - c[:, 1] * f[:, 0])
    assert abs(moment) == pytest.approx(T * 1e3 / case.loads.discs, rel=1e-12)


def test_the_series_law_adds_the_seats_approach_to_the_flanks():
    kw = dict(length=9.0, pin_radius=3.0, flank_curvature=np.array([0.05, -0.02, 0.1]), pin_modulus=E,
              pin_poisson=NU, disc_modulus=E, disc_poisson=NU, footprint_half_width=0.7)
    case = load_case("cases/rv40e_fanholes.toml")
    seat = seat_approach(case, PinHousingTable())
    law = series_law(hertz_pin_law(**kw), seat)
    Q = np.array([30.0, 500.0, 3000.0])
    delta = hertz_pin_approach(Q, **kw)[0] + seat(Q)[0]
    q, dq = law(delta)
    np.testing.assert_allclose(q, Q, rtol=1e-9)
    kf = 1.0 / hertz_pin_approach(Q, **kw)[1]
    ks = 1.0 / seat(Q)[1]
    np.testing.assert_allclose(dq, 1.0 / (1.0 / kf + 1.0 / ks), rtol=1e-9)
    assert np.all(law(np.array([-1e-3, 0.0, -1.0]))[0] == 0.0)


# ------------------------------------------------------------------------------------------------
# [carrier]
# ------------------------------------------------------------------------------------------------


def test_the_pillar_frame_is_the_clamped_guided_timoshenko_beam():
    """A pillar clamped in both plates, one end moved sideways by δ: F = δ/(L³/(12EI) + L/(κGA))
    (Roark Table 8.1, both ends fixed against rotation); n pillars at r: k_p = n·r²·F/δ."""
    t = CarrierTable()
    b, s, L = t.pillar_radial_size, t.pillar_tangential_size, t.pillar_length
    G = E / (2 * (1 + NU))
    k = 10 * (1 + NU) / (12 + 11 * NU)
    per_force = L ** 3 / (12 * E * b * s ** 3 / 12) + L / (k * G * b * s)
    assert pillar_torsional_stiffness(t) == pytest.approx(t.pillars * t.pillar_radius ** 2 / per_force, rel=1e-12)


def test_the_carrier_compliance_is_the_square_of_plate_twos_share_over_the_pillars():
    case = load_case("cases/rv40e_fanholes.toml")
    cs = case.crank_support
    f = (cs.eccentric_positions[0] + cs.eccentric_positions[1]) / (2 * cs.span)   # the beam's reactions
    assert plate_two_share(case) == pytest.approx(f, rel=1e-12)
    t = CarrierTable()
    assert carrier_output_compliance(case, t) == pytest.approx(f * f / pillar_torsional_stiffness(t), rel=1e-12)


# ------------------------------------------------------------------------------------------------
# [main_bearings]
# ------------------------------------------------------------------------------------------------


def test_the_point_contact_is_hertz():
    """A circular contact (R_x = R_y = r: a ball of radius r on a flat) is Hertz's sphere on a flat,
    δ = (9Q²/(16E*²r))^(1/3); an elliptic one agrees with Hamrock & Brewe's fits of k, 𝓚, 𝓔
    (k = 1.0339ρ^0.636, 𝓔 = 1.0003 + 0.5968/ρ, 𝓕 = 1.5277 + 0.6023 ln ρ, ρ = R_y/R_x) within the
    1 % they hold for 5 ≤ ρ ≤ 30 (a ball bearing's raceway contacts)."""
    r = 4.0
    e_star = E / (2 * (1 - NU ** 2))
    for Q in (10.0, 500.0):
        assert ball_approach(Q, r, r, E, NU) == pytest.approx((9 * Q * Q / (16 * e_star ** 2 * r)) ** (1 / 3), rel=1e-9)
    for rho in (5.0, 10.0, 29.0):
        rx, ry, Q = 3.6, 3.6 * rho, 500.0
        k, ell_e, ell_f = 1.0339 * rho ** 0.636, 1.0003 + 0.5968 / rho, 1.5277 + 0.6023 * math.log(rho)
        R = 1 / (1 / rx + 1 / ry)
        fit = ell_f * (9 / (2 * ell_e * R) * (Q / (math.pi * k * E / (1 - NU ** 2))) ** 2) ** (1 / 3)
        assert ball_approach(Q, rx, ry, E, NU) == pytest.approx(fit, rel=0.01)


def test_the_pairs_stiffness_is_the_sum_over_its_balls_in_closed_form():
    """Back-to-back pair, Z balls per row of stiffness k_n: radial Z·k_n·cos²α, axial 2Z·k_n·sin²α,
    tilt Z·k_n·(r_m·sin α + s/2·cos α)², torsion 0 (Harris & Kotzalas, the bearing's stiffness as the
    sum of its balls')."""
    t = MainBearingsTable()
    K = pair_stiffness(t)
    k = ball_stiffness(t)
    a = math.radians(t.contact_angle_deg)
    rm, s, Z = t.pitch_diameter / 2, t.row_spacing, t.balls
    assert K[0, 0] == pytest.approx(Z * k * math.cos(a) ** 2, rel=1e-12)
    assert K[2, 2] == pytest.approx(2 * Z * k * math.sin(a) ** 2, rel=1e-12)
    assert K[3, 3] == pytest.approx(Z * k * (rm * math.sin(a) + s / 2 * math.cos(a)) ** 2, rel=1e-12)
    assert abs(K[5, 5]) < 1e-12 * K[3, 3] and np.abs(K[5]).max() < 1e-12 * K[3, 3]
    # the ball stiffness: 3Q0/(2δ0) with δ0 the two contacts' approaches at Q0 = F_a0/(Z sin α)
    q0 = t.preload / (Z * math.sin(a))
    h = 1e-4 * q0
    # k_n = dQ/dδ of the two contacts in series at Q0, by a central difference of their approach
    D, dm = t.ball_diameter, t.pitch_diameter
    g = D * math.cos(a) / dm
    radii = [(D * (1 - g) / 2, t.inner_conformity * D / (2 * t.inner_conformity - 1)),
             (D * (1 + g) / 2, t.outer_conformity * D / (2 * t.outer_conformity - 1))]

    def approach(q):
        return sum(ball_approach(q, min(r), max(r), E, NU) for r in radii)

    assert k == pytest.approx(2 * h / (approach(q0 + h) - approach(q0 - h)), rel=1e-6)


# ------------------------------------------------------------------------------------------------
# The three in the stage: compliance shares
# ------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def shares(tmp_path_factory):
    """The compliance shares of the coarse RV-40E stage (Hertz pins: the seats apply) at crank angle
    0, friction 0, with and without the three parts."""
    from rvfem.app.hysteresis import accuracy_study
    cache = tmp_path_factory.mktemp("meshes")
    out = {}
    base = coarse_case("rv40e")
    for key, case in (("with", base),
                      ("without", base.replace(component_tables=(
                          ("pin_housing", PinHousingTable(enabled=False)), ("carrier", CarrierTable(enabled=False)),
                          ("main_bearings", MainBearingsTable(enabled=False)))))):
        folder = tmp_path_factory.mktemp(key) / "accuracy"
        out[key] = accuracy_study(case, folder, angles_deg=(0.0,), steps=8, friction=0.0, cache_dir=cache)
    return out


@pytest.mark.slow
def test_the_shares_of_the_three_parts_and_their_sum(shares):
    new, old = shares["with"]["compliance_shares"], shares["without"]["compliance_shares"]
    for name in ("pin_housing", "carrier", "main_bearings"):
        assert name in new["shares"] and name not in old["shares"]
    assert new["shares"]["main_bearings"] == 0.0                    # no torque through the main bearings
    a_new, a_old = new["rotation_arcmin"], old["rotation_arcmin"]
    assert a_new > a_old
    # the carrier is in series with the whole stage: its share is (1 − 1/STIFFEN)·Δφ_c/a_new
    case = coarse_case("rv40e")
    c = carrier_output_compliance(case, CarrierTable())
    d = 0.97 * 412.0e3 * c * 60 * 180 / math.pi
    assert new["shares"]["carrier"] == pytest.approx((1 - 1 / STIFFEN) * d / a_new, rel=1e-6)
    # series parts: the shares sum to one less what stiffening leaves (1/STIFFEN each) and less the
    # interaction of the contacts' load sharing (a few per cent, as without the three parts)
    assert new["total"] == pytest.approx(1.0, abs=0.05)
    assert abs(new["total"] - old["total"]) < 0.03


@pytest.mark.parametrize("scale", [1.0, 1.0 / STIFFEN])
def test_the_hertz_pins_in_series_with_their_seats_invert_the_summed_approach(scale):
    """The Hertz pin model with its seats (the closed-form inversion): at the approach
    δ_f(Q) + scale·δ_s(Q) the law gives back Q, and dQ/dδ = 1/(dδ_f/dQ + scale·dδ_s/dQ)."""
    from rvfem.solve.models import HertzPins, hertz_pin_parameters
    from rvfem.solve.stage_pin_housing import SeriesPins
    case = load_case("cases/rv40e_fanholes.toml")
    seat = seat_approach(case, PinHousingTable())
    curvature = np.linspace(-0.05, 0.1, 40)
    law = SeriesPins(HertzPins(case), seat, scale).law(None, curvature)
    Q = np.geomspace(1.0, 5000.0, 40)
    df, ddf = hertz_pin_approach(Q, **hertz_pin_parameters(case, curvature))
    ds, dds = seat(Q)
    q, dq = law(df + scale * ds)
    np.testing.assert_allclose(q, Q, rtol=1e-10)
    np.testing.assert_allclose(dq, 1.0 / (ddf + scale * dds), rtol=1e-10)
