"""Speed, ISO 281 rating and life, duty cycle (rvfem.evaluate.iso281) and Hertz contact (rvfem.evaluate.hertz) against
published numbers and closed forms."""

from __future__ import annotations

import math

import pytest
from conftest import CASES_DIR

from rvfem.case.definition import DutyRow, load_case
from rvfem.evaluate.hertz import (
    composite_modulus,
    crank_bearing_hertz,
    hertz_half_width,
    hertz_line_contact,
    hertz_peak_pressure,
    palmgren_approach,
    reduced_radius,
    stribeck_max_roller_load,
)
from rvfem.evaluate.iso281 import (
    bearing_speed_rpm,
    case_duty_cycle_life,
    constant_load_life_hours,
    crank_bearing_rating,
    duty_cycle_life,
    dynamic_load_rating,
    life_ratio,
    rating_life_hours,
)
from rvfem.evaluate.rigid import handbook_bearing_loads, summarize_bearing_loads

STEEL_E, STEEL_NU = 206000.0, 0.3


# --------------------------------------------------------------------------------------------
# Speed, rating, life
# --------------------------------------------------------------------------------------------


def test_bearing_speed_of_a_one_tooth_difference():
    # Gao et al.: n·Zc + n = 15·39 + 15 = 600 rpm
    assert bearing_speed_rpm(15.0, 40, 39) == pytest.approx(600.0)
    assert bearing_speed_rpm(15.0, 40, 38) == pytest.approx(300.0)
    with pytest.raises(ValueError):
        bearing_speed_rpm(15.0, 39, 39)


def test_dynamic_load_rating_crv80e():
    # Gao et al., eqs. 11-13: D_we = 5, L_we = 9, Z = 14, D_m = 31, b_m = 1.1, λν = 0.83
    assert dynamic_load_rating(14, 5.0, 9.0, 31.0, b_m=1.1, lambda_nu=0.83) == pytest.approx(21948.7, abs=0.05)
    assert crank_bearing_rating(load_case(CASES_DIR / "crv80e.toml").crank_bearing) == pytest.approx(21948.7, abs=0.05)


def test_dynamic_load_rating_rv110e():
    # Li et al., Table 2: D_w = 6, Z = 13, D = 42, d = 30 (D_m = 36); b_m = 1 and L = 11.8 mm
    # reproduce their C = 28378.5 N (printed to 0.1 N, truncated)
    c = dynamic_load_rating(13, 6.0, 11.8, 36.0, b_m=1.0, lambda_nu=0.83)
    assert c == pytest.approx(28378.5, abs=0.1)
    assert crank_bearing_rating(load_case(CASES_DIR / "rv110e.toml").crank_bearing) == pytest.approx(c, rel=1e-15)


def test_iso_constant_and_rating_scaling():
    base = dynamic_load_rating(14, 5.0, 9.0, 31.0)
    assert dynamic_load_rating(14, 5.0, 9.0, 31.0, fc_constant=207.9) == pytest.approx(base * 207.9 / 208.0)
    # C ∝ (i·L_we)^(7/9) and ∝ Z^(3/4) at fixed γ
    assert dynamic_load_rating(14, 5.0, 9.0, 31.0, rows=2) == pytest.approx(base * 2 ** (7 / 9))
    assert dynamic_load_rating(14, 5.0, 18.0, 31.0) == pytest.approx(base * 2 ** (7 / 9))
    assert dynamic_load_rating(7, 5.0, 9.0, 31.0) == pytest.approx(base * 0.5**0.75)


def test_rating_life_rv110e():
    # Li et al.: C = 28378.5 N, P_eq = 6115.8 N, 600 rpm → L = 4629.0 h
    assert rating_life_hours(28378.5, 6115.8, 600.0) == pytest.approx(4629.0, abs=0.1)


def test_rated_life_crv80e_fourth_power_and_iso():
    case = load_case(CASES_DIR / "crv80e.toml")
    loads = handbook_bearing_loads(case)
    c = crank_bearing_rating(case.crank_bearing)
    n_b = bearing_speed_rpm(case.loads.speed_rpm, case.pins.count, case.cycloid.teeth)
    f_m4 = summarize_bearing_loads(loads, 4.0)[0].equivalent_N
    # Gao et al.: L0 = 6008 h with the fourth-power equivalent load (their eq. 14 without Z_p)
    assert rating_life_hours(c, f_m4, n_b) == pytest.approx(6008.0, abs=1.0)
    # the ISO 281 equivalent load (p = 10/3) is smaller, so the life is longer by (F_m4/F_m10/3)^(10/3)
    f_m103 = summarize_bearing_loads(loads, 10 / 3)[0].equivalent_N
    life_iso = rating_life_hours(c, f_m103, n_b)
    assert life_iso == pytest.approx(6008.5 * (f_m4 / f_m103) ** (10 / 3), rel=1e-4)
    assert life_iso == pytest.approx(6523.0, abs=1.0)


def test_rating_life_edge_cases():
    assert rating_life_hours(1000.0, 0.0, 600.0) == math.inf
    assert rating_life_hours(1000.0, 1000.0, 1e6 / 60) == pytest.approx(1.0)
    with pytest.raises(ValueError):
        rating_life_hours(1000.0, -1.0, 600.0)


def test_life_ratio_of_a_fifteen_percent_load_rise():
    assert life_ratio(1.0, 1.15) == pytest.approx(0.6276, abs=1e-4)   # ≈ 37 % less life
    assert life_ratio(5.0, 5.0) == 1.0


# --------------------------------------------------------------------------------------------
# Duty cycle (Gao et al., eqs. 17-18)
# --------------------------------------------------------------------------------------------


def test_duty_cycle_with_one_rated_row_is_the_rated_life():
    d = duty_cycle_life([DutyRow(1.0, 15.0, 784.0)], 6008.0, 15.0, 784.0)
    assert (d.equivalent_torque_Nm, d.equivalent_speed_rpm) == (pytest.approx(784.0), pytest.approx(15.0))
    assert d.service_life_h == pytest.approx(6008.0)


def test_duty_cycle_with_one_other_row_is_the_scaled_life():
    d = duty_cycle_life([DutyRow(3.0, 10.0, 1000.0)], 6008.0, 15.0, 784.0)
    assert d.service_life_h == pytest.approx(6008.0 * (15 / 10) * (784 / 1000) ** (10 / 3))
    assert d.service_life_h == pytest.approx(constant_load_life_hours(6008.0, 15.0, 784.0, 10.0, 1000.0))


def test_duty_cycle_obeys_palmgren_miner():
    rows = [DutyRow(0.2, 15.0, 1960.0), DutyRow(0.5, 15.0, 784.0), DutyRow(0.2, 7.5, 400.0), DutyRow(0.1, 1.0, 0.0)]
    l0, n0, t0 = 6008.0, 15.0, 784.0
    d = duty_cycle_life(rows, l0, n0, t0)
    # Miner: a fraction s_i of the time at life L_i uses s_i/L_i of the bearing per hour.
    total = sum(r.time_share for r in rows)
    damage_per_hour = sum(
        (r.time_share / total) / (l0 * (n0 / r.speed_rpm) * (t0 / r.torque_Nm) ** (10 / 3))
        for r in rows if r.torque_Nm > 0
    )
    assert d.service_life_h == pytest.approx(1.0 / damage_per_hour, rel=1e-12)
    assert d.equivalent_speed_rpm == pytest.approx((0.2 * 15 + 0.5 * 15 + 0.2 * 7.5 + 0.1 * 1) / 1.0)
    # eq. 17 evaluated directly
    tn = [r.time_share * r.speed_rpm for r in rows]
    t_m = (sum(w * r.torque_Nm ** (10 / 3) for w, r in zip(tn, rows)) / sum(tn)) ** 0.3
    assert d.equivalent_torque_Nm == pytest.approx(t_m, rel=1e-12)


def test_duty_cycle_time_units_do_not_matter():
    a = duty_cycle_life([DutyRow(1.0, 15.0, 500.0), DutyRow(3.0, 5.0, 900.0)], 6000.0, 15.0, 784.0)
    b = duty_cycle_life([DutyRow(60.0, 15.0, 500.0), DutyRow(180.0, 5.0, 900.0)], 6000.0, 15.0, 784.0)
    assert a.service_life_h == pytest.approx(b.service_life_h, rel=1e-14)
    assert a.equivalent_torque_Nm == pytest.approx(b.equivalent_torque_Nm, rel=1e-14)


# --------------------------------------------------------------------------------------------
# Hertz line contact
# --------------------------------------------------------------------------------------------


def test_peak_pressure_zhang_et_al():
    # Zhang et al.: Q = 1978 N, L_r = 8.5 mm, b_w = 95 µm → p_h = 1.56 GPa
    assert hertz_peak_pressure(1978.0, 8.5, 0.095) == pytest.approx(1560.0, rel=5e-4)


def test_half_width_against_johnson_two_cylinders():
    """Johnson, Contact Mechanics §4.3, written out for two steel cylinders of radii R1, R2:
    b² = 4P/(π) · (R1 R2/(R1 + R2)) · [(1 − ν²)/E + (1 − ν²)/E], P = Q/L."""
    q, length, r1, r2 = 1832.4, 9.0, 2.5, 13.0
    p = q / length
    b_ref = math.sqrt(4 * p / math.pi * (r1 * r2 / (r1 + r2)) * 2 * (1 - STEEL_NU**2) / STEEL_E)
    contact = hertz_line_contact(q, length, r1, r2, concave=False)
    assert contact.half_width_mm == pytest.approx(b_ref, rel=1e-13)
    # concave outer raceway: R' = R1 R2/(R2 − R1)
    r_out = 18.0
    b_out = math.sqrt(4 * p / math.pi * (r1 * r_out / (r_out - r1)) * 2 * (1 - STEEL_NU**2) / STEEL_E)
    assert hertz_line_contact(q, length, r1, r_out, concave=True).half_width_mm == pytest.approx(b_out, rel=1e-13)


def test_half_width_matches_the_steel_shortcut_of_gao_et_al():
    # Gao et al., eq. 22: b = 3.35e-3·√(Q/(L·Σρ)) for steel (the exact constant is 3.354e-3)
    q, length, r1, r2 = 1832.4, 9.0, 2.5, 13.0
    sum_rho = 1 / r1 + 1 / r2
    b = hertz_line_contact(q, length, r1, r2, concave=False).half_width_mm
    assert b == pytest.approx(3.35e-3 * math.sqrt(q / (length * sum_rho)), rel=2e-3)


def test_peak_pressure_identity_p0_equals_a_estar_over_2r():
    # Johnson: p0 = a·E*/(2R) = √(P E*/(π R))
    q, length, r1, r2 = 2500.0, 11.8, 3.0, 21.0
    r_red = reduced_radius(r1, r2, concave=True)
    e_star = composite_modulus(STEEL_E, STEEL_NU)
    c = hertz_line_contact(q, length, r1, r2, concave=True)
    assert c.peak_pressure_MPa == pytest.approx(c.half_width_mm * e_star / (2 * r_red), rel=1e-13)
    assert c.peak_pressure_MPa == pytest.approx(math.sqrt(q / length * e_star / (math.pi * r_red)), rel=1e-13)


def test_composite_modulus_of_two_materials():
    # steel on aluminium: 1/E* = (1 − 0.3²)/206000 + (1 − 0.33²)/70000
    assert composite_modulus(206000.0, 0.3, 70000.0, 0.33) == pytest.approx(
        1 / ((1 - 0.09) / 206000.0 + (1 - 0.1089) / 70000.0), rel=1e-14
    )
    assert hertz_half_width(0.0, 9.0, 2.0, 1e5) == 0.0


def test_reduced_radius_rejects_a_raceway_smaller_than_the_roller():
    with pytest.raises(ValueError):
        reduced_radius(3.0, 2.0, concave=True)


def test_palmgren_approach():
    # δ = 3.84e-5 Q^0.9 / L^0.8 mm: 1000 N on 10 mm → 3.0505 µm
    assert palmgren_approach(1000.0, 10.0) == pytest.approx(3.84e-5 * 1000**0.9 / 10**0.8, rel=1e-14)
    assert palmgren_approach(1000.0, 10.0) == pytest.approx(3.0505e-3, rel=1e-4)
    assert palmgren_approach(2000.0, 10.0) / palmgren_approach(1000.0, 10.0) == pytest.approx(2**0.9)


def test_stribeck_and_crank_bearing_hertz_crv80e():
    case = load_case(CASES_DIR / "crv80e.toml")
    f = 5576.9
    assert stribeck_max_roller_load(f, 14) == pytest.approx(4.6 * f / 14)
    assert stribeck_max_roller_load(f, 14, factor=4.08) == pytest.approx(4.08 * f / 14)
    inner, outer = crank_bearing_hertz(case.crank_bearing, f)
    q = 4.6 * f / 14
    assert inner == hertz_line_contact(q, 9.0, 2.5, 13.0, concave=False)
    assert outer == hertz_line_contact(q, 9.0, 2.5, 18.0, concave=True)
    assert inner.peak_pressure_MPa > outer.peak_pressure_MPa   # convex inner raceway is the critical one


def test_case_duty_cycle_uses_the_shortest_life():
    case = load_case(CASES_DIR / "crv80e.toml")
    assert case_duty_cycle_life(case, [6008.0, 7000.0]) is None        # no duty cycle in the file
    rows = (DutyRow(0.25, 15.0, 1568.0), DutyRow(0.75, 15.0, 784.0))
    loads = case.loads.__class__(**{**case.loads.__dict__, "duty_cycle": rows})
    with_duty = case.replace(loads=loads)
    d = case_duty_cycle_life(with_duty, [7000.0, 6008.0, 9000.0])
    assert d.rated_life_h == 6008.0
    assert d == duty_cycle_life(rows, 6008.0, 15.0, 784.0)
    # a quarter of the time at twice the rated torque: damage rate 0.25·2^(10/3) + 0.75
    assert d.service_life_h == pytest.approx(6008.0 / (0.25 * 2 ** (10 / 3) + 0.75), rel=1e-12)
