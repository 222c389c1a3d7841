"""One most loaded roller everywhere, and the bearing analyst's checks next to L10h: static safety
S0 (ISO 76), the minimum-load rule, the support bearings from beam statics, and the rigid
evaluation's κ, a_ISO, L_nm, L10r — against closed forms, hand values and equilibrium."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import CASES_DIR, coarse_case
from rvfem.case.definition import load_case
from rvfem.evaluate import bearing_checks as bc
from rvfem.evaluate import roller_slices as rs
from rvfem.evaluate.hertz import PALMGREN_COEFFICIENT, rigid_ring_factor

# --------------------------------------------------------------------------------------------
# The rigid most loaded roller: Stribeck's rigid rings
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("z", [8, 14, 15, 40])
def test_rigid_ring_factor_is_the_rigid_ring_distribution_with_a_roller_on_the_load_line(z):
    f = 3000.0
    q = rs.rigid_ring_roller_loads(np.array([f, 0.0]), 2 * np.pi * np.arange(z) / z)
    # Stribeck, line contact, no clearance: Q_j = Q_max·cos(ψ_j)^(10/9), Σ Q_j cos ψ_j = F
    c = np.clip(np.cos(2 * np.pi * np.arange(z) / z), 0, None)
    assert q.max() == pytest.approx(f / np.sum(c ** (19 / 9)), rel=1e-10)
    assert q.max() == pytest.approx(rigid_ring_factor(z) * f / z, rel=1e-10)


def test_rigid_ring_factor_tends_to_stribecks_4_08_for_line_contact():
    # Z/Σcos^(19/9) → 1/((1/2π)∫_{-π/2}^{π/2} cos^(19/9)ψ dψ) = 4.085 (Harris & Kotzalas: "about 4.08")
    integral = math.gamma(0.5) * math.gamma((19 / 9 + 1) / 2) / math.gamma(19 / 18 + 1) / (2 * math.pi)
    assert rigid_ring_factor(2000) == pytest.approx(1 / integral, rel=1e-6)
    assert round(1 / integral, 2) == 4.08


def test_rigid_ring_with_clearance_balances_the_force_and_follows_palmgren():
    z, length, c = 14, 9.0, 0.010
    psi = 2 * np.pi * np.arange(z) / z + 0.1
    f = np.array([2500.0, 800.0])
    q = rs.rigid_ring_roller_loads(f, psi, radial_clearance_mm=c, roller_length_mm=length)
    e = np.stack([np.cos(psi), np.sin(psi)], axis=1)
    assert q @ e == pytest.approx(f, rel=1e-9)
    # every loaded roller: its Palmgren approach (both raceways) + c/2 = d·e_j, one d for all
    delta = 2 * PALMGREN_COEFFICIENT * q ** 0.9 / length ** 0.8 + c / 2
    loaded = q > 1e-6 * q.max()
    d, *_ = np.linalg.lstsq(e[loaded], delta[loaded], rcond=None)
    assert e[loaded] @ d == pytest.approx(delta[loaded], rel=1e-8)
    # a clearance narrows the load zone: the most loaded roller carries more than without
    q0 = rs.rigid_ring_roller_loads(f, psi)
    assert q.max() > q0.max() and np.count_nonzero(loaded) < np.count_nonzero(q0 > 1e-6 * q0.max())


# --------------------------------------------------------------------------------------------
# Static safety, minimum load, support bearings
# --------------------------------------------------------------------------------------------


def test_static_safety_of_the_shipped_crank_bearing_by_hand():
    b = load_case(CASES_DIR / "rv40e_fanholes.toml").crank_bearing
    c0 = 44 * (1 - 5.0 / 31.0) * 14 * 9.0 * 5.0          # ISO 76, C0r = 44(1 − D cos α/D_pw)·i·Z·L_we·D_we cos α
    assert bc.crank_bearing_static_rating(b) == pytest.approx(c0, rel=1e-12)
    s = bc.static_safety(c0, 3000.0)
    assert s.s0 == pytest.approx(c0 / 3000.0) and s.verdict == "at least 2"
    assert bc.static_safety(c0, c0 / 1.5).verdict == "1 to 2"
    assert bc.static_safety(c0, 1.2 * c0).verdict == "below 1"


def test_minimum_load_rule():
    m = bc.minimum_load(300.0, 20000.0)
    assert m.fraction_of_C == pytest.approx(0.015) and m.below
    assert not bc.minimum_load(400.0, 20000.0).below


def test_support_reactions_balance_the_eccentric_loads_by_beam_statics():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(5, 2, 2)) * 1000.0                 # 5 states, 2 eccentrics, (x, y)
    z, span = np.array([11.5, 21.5]), 33.0
    r = bc.support_reactions(span, z, p)
    assert r.sum(axis=1) == pytest.approx(p.sum(axis=1), rel=1e-12)                     # forces
    assert (span * r[:, 1]) == pytest.approx(np.einsum("k,nkc->nc", z, p), rel=1e-12)  # moments about support 1
    # hand value: one load P at z on span L: R1 = P(L − z)/L, R2 = P·z/L
    one = bc.support_reactions(33.0, [11.5], np.array([[100.0, 0.0]]))
    assert one[0] == pytest.approx([100 * 21.5 / 33, 0.0]) and one[1] == pytest.approx([100 * 11.5 / 33, 0.0])


def test_support_bearing_life_is_iso_281_of_the_equivalent_load():
    theta = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    mag = 1000.0 + 500.0 * np.cos(theta)
    reactions = np.zeros((8, 1, 2, 2))
    reactions[:, 0, 0, 0] = mag
    reactions[:, 0, 1, 1] = 0.5 * mag
    s1, s2 = bc.support_bearings(theta, reactions, 600.0, rating_N=20000.0, exponent=10 / 3)
    fm = np.mean(mag ** (10 / 3)) ** 0.3
    assert s1.equivalent_N == pytest.approx(fm) and s1.max_N == 1500.0 and s1.min_N == 500.0
    assert s1.L10h == pytest.approx(1e6 / (60 * 600) * (20000 / fm) ** (10 / 3))
    assert s2.equivalent_N == pytest.approx(0.5 * fm)
    assert bc.support_bearings(theta, reactions, 600.0, rating_N=None, exponent=10 / 3)[0].L10h is None


# --------------------------------------------------------------------------------------------
# End to end: one most loaded roller in every table, support loads from the FE eccentric loads
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    from rvfem.app.analysis import analyse
    from rvfem.outputs.summary import SummaryContext, build_summary

    case = coarse_case("rv40e_fanholes", crank_support={"support_bearing_C_N": 30000.0})
    a = analyse(case, angle_step_deg=10.0, cache_dir=tmp_path_factory.mktemp("meshes"))
    return a, build_summary(a, SummaryContext(files=[], timings=dict(a.timings)))


def test_one_most_loaded_roller_in_the_hertz_and_the_depth_tables(run):
    a, s = run
    h, depth = s["hertz"], s["crank_bearing_depth"]["bearings"]
    for key, model in (("fe_rollers", "flexible"), ("stribeck_rigid", "rigid")):
        assert h[key]["roller_load_N"] == pytest.approx(max(b[model]["max_roller_load_N"] for b in depth), rel=1e-12)
        best = depth[h[key]["bearing"] - 1][model]           # the same bearing (equal bearings tie)
        assert best["max_roller"] == h[key]["roller"]
        assert best["max_roller_load_N"] == pytest.approx(h[key]["roller_load_N"], rel=1e-12)
        assert best["max_roller_theta_deg"] == h[key]["theta_deg"]
    # the rigid one is the rigid-ring distribution at the cage positions: between the closed forms
    # of a roller on the load line (the largest) and of two rollers astride it
    f_max = max(b.rigid.max_N for b in a.comparison.bearings)
    z = a.case.crank_bearing.rollers
    q = h["stribeck_rigid"]["roller_load_N"]
    c = np.clip(np.cos(2 * np.pi * (np.arange(z) + 0.5) / z), 0, None)
    assert c.max() / np.sum(c ** (19 / 9)) * f_max * 0.999 <= q <= rigid_ring_factor(z) * f_max / z * (1 + 1e-12)
    # the rigid handbook evaluation alone gives the same roller
    rigid_q = max(b.max_roller_load_N for b in a.rigid.bearings)
    assert rigid_q == pytest.approx(q, rel=1e-12)


def test_support_bearings_of_a_run_balance_both_discs_eccentric_loads(run):
    a, s = run
    checks = s["bearing_checks"]
    cs = a.case.crank_support
    forces = a.cycle.disc_bearing_forces                     # (n, discs, N, 2), on the discs
    total = -forces.sum(axis=1)                              # on each crankshaft's eccentrics
    moment = -np.einsum("k,nkbc->nbc", np.asarray(cs.eccentric_positions), forces)
    r2 = moment / cs.span
    r1 = total - r2
    mags = np.stack([np.linalg.norm(r1, axis=-1), np.linalg.norm(r2, axis=-1)], axis=-1)   # (n, N, 2)
    for entry in checks["support_bearings"]:
        col = mags[:, entry["crank"] - 1, entry["support"] - 1]
        assert entry["max_load_N"] == pytest.approx(col.max(), rel=1e-12)
        fm = np.mean(col ** (10 / 3)) ** 0.3
        assert entry["equivalent_load_N"] == pytest.approx(fm, rel=1e-12)
        assert entry["L10h_h"] == pytest.approx(1e6 / (60 * a.rigid.bearing_speed_rpm) * (30000 / fm) ** (10 / 3),
                                                rel=1e-12)
    st, mn = checks["static_safety"], checks["minimum_load"]
    c0 = bc.crank_bearing_static_rating(a.case.crank_bearing)
    assert st["flexible"]["S0"] == pytest.approx(c0 / max(b.flexible.max_N for b in a.comparison.bearings))
    assert mn["rigid"]["fraction_of_C"] == pytest.approx(
        min(b.rigid.min_N for b in a.comparison.bearings) / a.rigid.rating_N)


def test_rigid_evaluation_has_kappa_a_iso_and_the_lives_of_the_run(run):
    from rvfem.app.analysis import analyse_rigid
    from rvfem.outputs.summary import rigid_summary

    a, s = run
    r = rigid_summary(analyse_rigid(a.case, a.theta))
    for b, d in zip(r["bearings"], s["crank_bearing_depth"]["bearings"]):
        for key in ("kappa", "a_iso", "L_nm_h", "L10r_h"):
            assert b["depth"][key] == pytest.approx(d["rigid"][key], rel=1e-12)
        assert b["depth"]["L_nm_h"] == pytest.approx(b["depth"]["a_iso"] * b["L10h_h"], rel=1e-12)
    assert r["bearing_checks"]["static_safety"]["rigid"]["S0"] == pytest.approx(
        s["bearing_checks"]["static_safety"]["rigid"]["S0"], rel=1e-12)
