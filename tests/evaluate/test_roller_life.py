"""Lubrication, a_ISO, the lamina life and the crankshaft tilt of the crank bearing against hand
calculations with the standards' formulas, the rating's own definition and the beam closed form."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from rvfem.case.definition import load_case
from rvfem.evaluate import iso281, lubrication as lb, roller_life as rl, roller_slices as rs, validity
from rvfem.evaluate.hertz import composite_modulus, reduced_radius
from rvfem.errors import CaseError
from rvfem.fem.crankshaft import beam_influence
from rvfem.solve.models import roller_angles

from conftest import CASES_DIR

E_STAR = composite_modulus(206000.0, 0.3)


@pytest.fixture(scope="module")
def case():
    return load_case(CASES_DIR / "rv40e_fanholes.toml")


# --------------------------------------------------------------------------------------------
# Viscosity, speed, film
# --------------------------------------------------------------------------------------------


def test_walther_goes_through_its_two_points_and_between():
    assert lb.walther_viscosity(68.0, 8.7, 40.0) == pytest.approx(68.0, rel=1e-12)
    assert lb.walther_viscosity(68.0, 8.7, 100.0) == pytest.approx(8.7, rel=1e-12)
    # hand calculation, ASTM D341: log log(ν + 0.7) linear in log T (K)
    a1, a2 = math.log10(math.log10(68.7)), math.log10(math.log10(9.4))
    t = (math.log10(333.15) - math.log10(313.15)) / (math.log10(373.15) - math.log10(313.15))
    assert lb.walther_viscosity(68.0, 8.7, 60.0) == pytest.approx(10 ** 10 ** (a1 + t * (a2 - a1)) - 0.7, rel=1e-12)


def test_entrainment_speed_by_hand():
    # n_b = 600 rpm, D_m = 31 mm, D_we = 5 mm: u = ω·D_m·(1 − γ²)/4
    u = 2 * math.pi * 10.0 * 0.031 * (1 - (5 / 31) ** 2) / 4
    assert lb.entrainment_speed(600.0, 31.0, 5.0) == pytest.approx(u, rel=1e-12)
    assert u == pytest.approx(0.4743, abs=1e-4)


def test_pan_hamrock_film_against_dowson_higginson():
    # two independently fitted line-contact formulas agree within 10 % over the crank bearing's range
    r = reduced_radius(2.5, 13.0, concave=False)
    for w, eta, u in [(50.0, 0.02, 0.2), (140.0, 0.03, 0.47), (400.0, 0.1, 2.0)]:
        pan = lb.pan_hamrock_film(w, r, E_STAR, eta, u, 20.0)
        dh = lb.dowson_higginson_min_film(w, r, E_STAR, eta, u, 20.0)
        assert pan.minimum_um == pytest.approx(dh, rel=0.10)
        assert pan.central_um > pan.minimum_um
    # the dimensional form of Pan & Hamrock's h_min: 1.714·w'^−0.128·(η0·u)^0.694·α^0.568·E'^0.002·R'^0.434
    w, eta, u, alpha = 140.0e3, 0.03, 0.47, 20e-9
    e1, rr = 2 * E_STAR * 1e6, r * 1e-3
    h = 1.714 * w**-0.128 * (eta * u) ** 0.694 * alpha**0.568 * e1 ** (0.128 - 0.694 + 0.568) * rr ** (1 + 0.128 - 0.694)
    assert lb.pan_hamrock_film(140.0, r, E_STAR, eta, u, 20.0).minimum_um == pytest.approx(h * 1e6, rel=1e-9)


# --------------------------------------------------------------------------------------------
# ISO 281 ν1, κ, a_ISO; ISO 76 C0, ISO 281 Annex B C_u
# --------------------------------------------------------------------------------------------


def test_reference_viscosity_by_hand():
    assert lb.reference_viscosity(600.0, 31.0) == pytest.approx(45000 * 600**-0.83 / math.sqrt(31), rel=1e-12)
    assert lb.reference_viscosity(600.0, 31.0) == pytest.approx(39.96, abs=0.01)
    assert lb.reference_viscosity(3000.0, 31.0) == pytest.approx(4500 / math.sqrt(3000 * 31), rel=1e-12)


@pytest.mark.parametrize("kappa, x, a_iso", [
    (0.3, 0.1, 0.140834), (0.3, 0.564288, 0.200845),     # 0.1 ≤ κ < 0.4: 1.5859 − 1.3993/κ^0.054381
    (0.7, 0.1, 0.277425), (0.7, 0.564288, 0.872362),     # 0.4 ≤ κ < 1:   1.5859 − 1.2348/κ^0.19087
    (2.0, 0.1, 0.516097), (2.0, 0.564288, 3.794975),     # 1 ≤ κ ≤ 4:     1.5859 − 1.2348/κ^0.071739
])
def test_a_iso_by_hand_in_each_kappa_branch(kappa, x, a_iso):
    """ISO 281:2007 eqs. (34)–(36), radial roller bearings, 0.1·[1 − (…)·x^0.4]^−9.185, worked by
    hand to six digits; x = 0.564288 is e_C·C_u/P of the shipped bearing (normal cleanliness)."""
    assert lb.a_iso_roller(kappa, x) == pytest.approx(a_iso, rel=2e-6)


@pytest.mark.parametrize("kappa", [0.4, 1.0])
def test_a_iso_branches_meet(kappa):
    """The standard's constants make a_ISO continuous where its κ branches meet (a mistyped
    constant or a ball-bearing constant would not)."""
    for x in (0.05, 0.3, 1.0):
        assert lb.a_iso_roller(kappa * (1 - 1e-9), x) == pytest.approx(lb.a_iso_roller(kappa, x), rel=1e-4)


def test_a_iso_limits():
    assert lb.a_iso_roller(1.0, 0.0) == pytest.approx(0.1)          # no fatigue limit margin: 0.1
    assert lb.a_iso_roller(4.0, 5.0) == lb.A_ISO_MAX                 # capped at 50
    assert lb.a_iso_roller(10.0, 0.3) == lb.a_iso_roller(4.0, 0.3)   # κ > 4 counts as 4


def test_static_rating_and_fatigue_limit_by_hand():
    c0 = 44 * (1 - 5 / 31) * 14 * 9 * 5
    assert lb.static_load_rating(14, 5.0, 9.0, 31.0) == pytest.approx(c0, rel=1e-12)
    assert lb.fatigue_load_limit(c0, 31.0) == pytest.approx(c0 / 8.2, rel=1e-12)
    assert lb.fatigue_load_limit(c0, 200.0) == pytest.approx(c0 / 8.2 * 0.5**0.3, rel=1e-12)


# --------------------------------------------------------------------------------------------
# The lamina life (ISO/TS 16281) against the rating's definition
# --------------------------------------------------------------------------------------------


def _uniform_life(case, force, slices=30, phases=8):
    qci, qce = rl.lamina_ratings(case, slices)
    z = case.crank_bearing.rollers
    damage = []
    for phase in np.linspace(0, 2 * math.pi / z, phases, endpoint=False):
        q = rs.rigid_ring_roller_loads(np.array([force, 0.0]), phase + 2 * np.pi * np.arange(z) / z)
        lam = np.repeat(q[:, None] / slices, slices, axis=1)
        damage.append(1.0 / rl.lamina_life_mrev(lam, lam, qci, qce, inner_rotates=True))
    return 1.0 / np.mean(damage)


def test_lamina_life_is_one_million_revolutions_at_the_rating(case):
    # C is the load for 10⁶ revolutions: the lamina ratings (552·…, ISO/TS 16281) and ISO 281's
    # C (207.9·…) rest on the same Lundberg–Palmgren integrals, with the rigid-ring load zone of
    # ±90° that C assumes. ISO/TS 16281 rates the laminae from C/λν (λν, ISO 281's allowance for
    # edge stresses and non-uniform stress, is what the lamina loads compute): with λν = 1 the
    # lamina life at P = C is C's 10⁶ revolutions, with the default 0.83 it is 0.83^−4 of it
    exact = dataclasses.replace(case, crank_bearing=dataclasses.replace(case.crank_bearing, lambda_nu=1.0))
    assert _uniform_life(exact, iso281.crank_bearing_rating(exact.crank_bearing)) == pytest.approx(1.0, rel=0.01)
    c = iso281.crank_bearing_rating(case.crank_bearing)
    assert case.crank_bearing.lambda_nu == 0.83
    assert _uniform_life(case, c) == pytest.approx(0.83**-4, rel=0.01)
    assert _uniform_life(case, c / 0.83) == pytest.approx(1.0, rel=0.01)
    # line contact: L ∝ P^−4 (ISO 281's 10/3 is a compromise for all roller bearings)
    assert _uniform_life(case, c / 8) == pytest.approx(8.0**4 * _uniform_life(case, c), rel=1e-9)
    # independent of the number of laminae
    assert _uniform_life(case, c / 3, slices=7) == pytest.approx(_uniform_life(case, c / 3, slices=40), rel=1e-9)


def _din_26281_slice_springs(angles, f_rad, slices, length):
    """Roller loads of a cylindrical roller bearing of straight rollers without clearance after the
    independent slice springs of DIN 26281 / ISO/TS 16281 (the algorithm of ``tribology``'s
    ``fcylrolbear``, written out here): slice stiffness 35948·L^(8/9)/n_s, slice load
    c·δ_jk^(10/9), δ_jk = δ_r·cos ψ_j, the ring approach δ_r found by the secant method."""
    c = 35948.0 * length ** (8 / 9) / slices
    cos = np.cos(angles)

    def force(dr):
        d = np.clip(dr * cos, 0, None)
        return c * slices * d ** (10 / 9), np.sum(c * slices * d ** (10 / 9) * cos)

    d0, d1 = 1e-4, 2e-3
    f0, f1 = force(d0)[1] - f_rad, force(d1)[1] - f_rad
    for _ in range(100):
        d0, d1, f0 = d1, d1 - f1 * (d1 - d0) / (f1 - f0), f1
        f1 = force(d1)[1] - f_rad
        if abs(f1) < 1e-10 * f_rad:
            break
    return force(d1)[0]


def test_rigid_ring_roller_loads_against_din_26281_slice_springs():
    angles = 2 * np.pi * np.arange(14) / 14
    din = _din_26281_slice_springs(angles, 2763.0, 30, 9.0)
    ours = rs.rigid_ring_roller_loads(np.array([2763.0, 0.0]), angles)
    np.testing.assert_allclose(ours, din, rtol=1e-8, atol=1e-9)


# --------------------------------------------------------------------------------------------
# Tilt from the crankshaft beam
# --------------------------------------------------------------------------------------------


def test_beam_slope_against_the_closed_form_and_the_deflection():
    span, ei = 33.0, 206000.0 * math.pi * 20.0**4 / 64
    # a central load turns the beam's ends by P·L²/(16·EI) (Roark) and not its centre
    g = rl.beam_slope_influence(span, [1e-9, span / 2], ei)
    assert g[0, 1] == pytest.approx(span**2 / (16 * ei), rel=1e-6)
    assert g[1, 1] == pytest.approx(0.0, abs=1e-18)
    # the slope at each eccentric is the derivative of the (independently coded) deflection line
    pos, h = [11.5, 21.5], 1e-4
    comp = (2e-6, 3e-6)
    g = rl.beam_slope_influence(span, pos, ei, comp)
    for i, x in enumerate(pos):
        for j, b in enumerate(pos):
            # central difference (the deflection line is smooth through the load point too)
            fd = (beam_influence(span, [x + h, b], ei, None, comp)[0, 1]
                  - beam_influence(span, [x - h, b], ei, None, comp)[0, 1]) / (2 * h)
            assert g[i, j] == pytest.approx(fd, rel=1e-5, abs=1e-15)


def _cycle(case, n=8):
    rng = np.random.default_rng(0)
    f = rng.normal(size=(n, case.loads.discs, case.cranks.count, 2)) * 1000.0
    return SimpleNamespace(bearing_forces=f[:, 0], disc_bearing_forces=f)


def test_tilt_is_zero_on_rigid_support_and_vanishes_with_a_stiff_crankshaft(case):
    cyc = _cycle(case)
    assert not np.any(rl.eccentric_slopes(case.replace(crank_support=None), cyc))
    base = np.abs(rl.eccentric_slopes(case, cyc)).max()
    assert base > 0
    cs = case.crank_support
    stiff = case.replace(crank_support=cs.__class__(**{**cs.__dict__, "journal_diameter": 10 * cs.journal_diameter,
                                                       "support_stiffness_N_per_mm": 1e10}))
    assert np.abs(rl.eccentric_slopes(stiff, cyc)).max() < 1e-3 * base


def test_profile_kind_is_settable_and_checked():
    c = load_case(CASES_DIR / "rv40e_fanholes.toml", overrides=("crank_bearing.profile.kind=combined",
                                                                 "lubricant.iso_vg=100"))
    assert c.crank_bearing.profile.kind == "combined" and c.lubricant.iso_vg == 100
    with pytest.raises(CaseError, match="crank_bearing.profile.kind"):
        load_case(CASES_DIR / "rv40e_fanholes.toml", overrides=("crank_bearing.profile.kind=barrel",))
    # the shipped cases keep their numbers: the new tables have defaults
    base = load_case(CASES_DIR / "rv40e_fanholes.toml")
    assert base.crank_bearing.profile.kind == "straight" and base.lubricant.iso_vg == 68


@pytest.mark.parametrize("overrides, key, cause", [
    (("crank_bearing.profile.kind=combined", "crank_bearing.profile.modification_length=5"),
     "crank_bearing.profile.modification_length", "shorter than half the roller length"),
    (("lubricant.nu40=100",), "lubricant.nu100", "is missing"),
    (("lubricant.nu100=10",), "lubricant.nu40", "is missing"),
    (("lubricant.nu40=10", "lubricant.nu100=20"), "lubricant.nu100", "must be below 'lubricant.nu40'"),
])
def test_profile_and_oil_that_cannot_be_used_give_one_line_errors(overrides, key, cause):
    """A modified segment longer than half the 9 mm roller, one viscosity without the other, an oil
    that thickens as it warms: each is refused naming its key, never used silently."""
    with pytest.raises(CaseError, match=f"'{key}'.*{cause}"):
        load_case(CASES_DIR / "rv40e_fanholes.toml", overrides=overrides)


def test_roller_depth_warnings_one_line_each():
    def depth(peak, kappa):
        d = SimpleNamespace(roller_peak_pressure_MPa=peak, bearing=0, model="flexible", raceway="eccentric",
                            kappa=kappa)
        return SimpleNamespace(rigid=(), flexible=(d,))

    assert validity.roller_depth_warnings(None) == ()
    assert validity.roller_depth_warnings(depth(1900.0, 0.72)) == ()
    codes = [w.code for w in validity.roller_depth_warnings(depth(4500.0, 0.05))]
    assert codes == ["roller_pressure", "kappa_range"]
    high = validity.roller_depth_warnings(depth(1000.0, 6.0))
    assert [w.code for w in high] == ["kappa_range"] and "\n" not in high[0].message


# --------------------------------------------------------------------------------------------
# The flexible/rigid L10r ratio in steps
# --------------------------------------------------------------------------------------------


def _steps_cycle(case, theta, forces, scale_rollers=1.0):
    """A cycle whose bearing forces are ``forces`` and whose rollers carry the rigid rings' loads of
    them (× ``scale_rollers`` on the most loaded roller of each angle and bearing)."""
    import types

    loads = rs.case_rigid_roller_loads(case, theta, forces)
    if scale_rollers != 1.0:
        top = loads == loads.max(axis=-1, keepdims=True)
        loads = np.where(top, scale_rollers * loads, loads)
    return types.SimpleNamespace(bearing_forces=forces, roller_loads=loads, disc_bearing_forces=None,
                                 roller_angles=roller_angles(case, theta))


def test_l10r_steps_multiply_to_the_ratio_and_are_one_where_nothing_changes(case):
    from rvfem.evaluate import rigid

    theta = np.radians(np.arange(0.0, 360.0, 10.0))
    hb = rigid.handbook_bearing_loads(case, theta)
    handbook = np.stack([hb.fx.T, hb.fy.T], axis=2)
    speed = iso281.case_bearing_speed_rpm(case)
    # the flexible disc's forces are the handbook's and its rollers carry the rigid rings' loads:
    # the force, friction and sharing factors are exactly 1; the tilt is the crankshaft's
    same = rl.l10r_steps(case, theta, _steps_cycle(case, theta, handbook), handbook, handbook, speed, bearings=[0])[0]
    assert same.factors["pin_friction"] == same.factors["bearing_forces"] == same.factors["load_sharing"] == 1.0
    assert 0.9 < same.factors["tilt"] <= 1.0
    # the handbook step is the in-depth rigid column
    column = rl.rigid_bearing_depths(case, theta, handbook, {0: 2500.0}, 20000.0, speed)[0]
    assert same.L10r_h["handbook"] == pytest.approx(column.L10r_h, rel=1e-12)
    # larger forces, friction and a heavier most loaded roller: each factor below 1, their product the ratio
    frictionless = 1.05 * handbook
    steps = rl.l10r_steps(case, theta, _steps_cycle(case, theta, 1.1 * handbook, 1.2), handbook, frictionless,
                          speed, bearings=[0])[0]
    assert all(steps.factors[k] < 1.0 for k in ("pin_friction", "bearing_forces", "load_sharing"))
    assert math.prod(steps.factors.values()) == pytest.approx(steps.ratio, rel=1e-12)
    assert steps.ratio == pytest.approx(steps.L10r_h["flexible"] / steps.L10r_h["handbook"], rel=1e-12)
    # line contact: L10r ∝ load^−4 when every roller load scales (rigid rings without clearance)
    assert steps.factors["bearing_forces"] == pytest.approx(1.05**-4, rel=0.02)


# --------------------------------------------------------------------------------------------
# The lamina damage along the roller (where spalling starts)
# --------------------------------------------------------------------------------------------


def test_lamina_damage_sums_to_the_lamina_life_of_every_load_state(case):
    # the laminae share 1/L10r of each state in proportion to (q_e/q_c)^(9/2): the shares add up to
    # ISO/TS 16281's [Σ (q_c/q_e)^(−9/2)]^(8/9) whatever the loads and the laminae's widths
    rng = np.random.default_rng(3)
    _, dx = rs.slice_layout(case.crank_bearing.profile, case.crank_bearing.roller_length)
    qci, qce = rl.lamina_ratings(case, dx)
    inner = rng.uniform(0.0, 40.0, (5, 14, dx.size)) * dx
    outer = rng.uniform(0.0, 40.0, (5, 14, dx.size)) * dx
    for rotates in (True, False):
        damage = rl.lamina_damage_mrev(inner, outer, qci, qce, inner_rotates=rotates)
        assert damage.shape == (5, 2, dx.size)
        life = rl.lamina_life_mrev(inner, outer, qci, qce, inner_rotates=rotates)
        assert np.sum(damage, axis=(-2, -1)) == pytest.approx(1.0 / life, rel=1e-12)
    # without load: no damage, and no division by zero
    assert not np.any(rl.lamina_damage_mrev(0 * inner, 0 * outer, qci, qce))


def test_uniform_line_load_gives_a_uniform_damage_per_length_on_unequal_laminae(case):
    # q_c ∝ w^(7/9) and q_e ∝ w for a uniform load per length: (q_e/q_c)^(9/2) ∝ w, so the damage
    # per mm is the same on the end-refined laminae as on the wide middle ones (the exact share
    # 1/L_total of the whole for every mm)
    prof = case.crank_bearing.profile
    length = case.crank_bearing.roller_length
    x, dx = rs.slice_layout(prof, length)
    assert dx.max() / dx.min() > 50                    # really unequal laminae
    qci, qce = rl.lamina_ratings(case, dx)
    z = case.crank_bearing.rollers
    q = rs.rigid_ring_roller_loads(np.array([8000.0, 0.0]), 2 * np.pi * np.arange(z) / z)
    lam = q[:, None] / dx.sum() * dx[None, :]
    damage = rl.lamina_damage_mrev(lam, lam, qci, qce, inner_rotates=True)
    density = damage / dx
    assert density / density.mean(axis=1, keepdims=True) == pytest.approx(np.ones_like(density), rel=1e-12)
    where = rl.damage_location(x, dx, damage, dx.sum())
    assert where.raceway == "eccentric"                # the smaller R' and the rotating ring rate lower
    assert where.peak_over_mean == pytest.approx(1.0, rel=1e-9)
    assert where.spread_mm == pytest.approx(dx.sum(), rel=1e-12)
    assert where.middle_share == pytest.approx(0.5, rel=1e-12)


def test_damage_along_a_uniformly_loaded_roller_is_uniform_away_from_its_corners(case):
    # the logarithmic roller at its design load presses evenly along the roller (Johns and Gohar:
    # the crown is the sag of a uniform strip load): one roller at Q_d on a raceway of rigid rings,
    # its damage per mm over the inner 80 % within 1 % of its mean there (pressure within
    # 0.2 %, damage ∝ p^9 on line loads ∝ p²), and the corners beyond L carry next to none
    b = case.crank_bearing
    prof = dataclasses.replace(b.profile, kind="logarithmic", design_load_N=2000.0, slices=60)
    log_case = dataclasses.replace(case, crank_bearing=dataclasses.replace(b, profile=prof))
    geoms = rl.raceways(log_case)
    loads = np.zeros((1, b.rollers))
    loads[0, 0] = 2000.0
    slices = [rl.cycle_slices(loads, np.zeros_like(loads), b.roller_length, g, prof) for g in geoms]
    x, dx = rs.slice_layout(prof, b.roller_length)
    damage = rl._cycle_lamina_damage(log_case, slices, dx)
    assert np.sum(damage) == pytest.approx(rl._cycle_damage(log_case, slices, dx), rel=1e-12)
    density = damage / dx
    inner = np.abs(x) <= 0.4 * b.roller_length
    for row in density:
        assert np.max(np.abs(row[inner] / row[inner].mean() - 1.0)) < 0.01
    corners = np.abs(x) > 0.5 * b.roller_length
    assert np.sum(damage[:, corners]) < 1e-3 * np.sum(damage)


def test_damage_csv_rows_sum_to_the_lamina_damage_of_l10r(case, tmp_path):
    from rvfem.evaluate import rigid
    from rvfem.outputs import roller_outputs

    theta = np.radians(np.arange(0.0, 360.0, 15.0))
    hb = rigid.handbook_bearing_loads(case, theta)
    handbook = np.stack([hb.fx.T, hb.fy.T], axis=2)
    speed = iso281.case_bearing_speed_rpm(case)
    depths = rl.rigid_bearing_depths(case, theta, handbook, {0: 2500.0, 1: 2500.0}, 20000.0, speed)
    analysis = SimpleNamespace(roller_depth=SimpleNamespace(rigid=depths, flexible=()))
    [path] = roller_outputs.write_roller_damage_csv(analysis, tmp_path)
    import csv

    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0]) == roller_outputs.DAMAGE_COLUMNS
    for d in depths:
        mine = [r for r in rows if int(r["bearing"]) == d.bearing + 1]
        assert len(mine) == d.x_mm.size and {r["model"] for r in mine} == {"rigid"}
        total = sum(float(r["eccentric_damage_per_h"]) + float(r["bore_damage_per_h"]) for r in mine)
        assert total * d.L10r_h == pytest.approx(1.0, rel=1e-9)          # the CSV is printed to full precision
        for r in mine:
            assert float(r["eccentric_damage_per_h_mm"]) * float(r["width_mm"]) == pytest.approx(
                float(r["eccentric_damage_per_h"]), rel=1e-12, abs=1e-300)
        # straight rollers on rigid rings: the damage peaks at the ends of the effective length
        assert d.damage is not None and abs(abs(d.damage.x_mm) - 0.5 * case.crank_bearing.roller_length) < 0.1
    # bearings that carry the same loads 120° apart (15° steps) share one curve of the plot
    labels = [label for label, _ in roller_outputs.roller_damage_curves(depths)]
    assert len(labels) == 1 and labels[0].startswith("bearings 1–2 (identical) rigid: L10r ")
    png = roller_outputs.roller_damage_plot(tmp_path / "roller_damage.png", depths, "straight",
                                            case.crank_bearing.roller_length)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 5000
