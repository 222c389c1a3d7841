"""The reducer stage: crankshaft influence coefficients against beam closed forms, and the two
discs on one carrier against the rigid limit, equilibrium, symmetry and their own mirror image."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import CASES_DIR
from conftest import coarse_case as coarse

from rvfem.case.definition import case_from_dict, case_to_dict, load_case
from rvfem.evaluate import rigid
from rvfem.fem import crankshaft
from rvfem.mesh import mesh_case
from rvfem.solve import cycle

STEP = np.radians(10.0)
THETA = np.arange(36) * STEP   # 10° steps: 180° and the 120° crank spacing are whole samples

# ------------------------------------------------------------------------------------------------
# crankshaft as a beam
# ------------------------------------------------------------------------------------------------

L, EI = 40.0, 2.0e9


def beam_by_integration(span, load_at, x, EI):
    """Deflection of a simply supported beam under a unit load by integrating M/EI twice
    (trapezoids on a fine grid) with y(0) = y(L) = 0: independent of the closed forms."""
    s = np.linspace(0.0, span, 200001)
    M = np.where(s <= load_at, (span - load_at) / span * s, load_at / span * (span - s))
    k = M / EI                                  # curvature; y'' = −k for sagging positive y
    slope = np.concatenate([[0.0], np.cumsum(0.5 * (k[1:] + k[:-1]) * np.diff(s))])
    y0 = np.concatenate([[0.0], np.cumsum(0.5 * (slope[1:] + slope[:-1]) * np.diff(s))])
    y = -(y0 - y0[-1] * s / span)               # add the rigid line that makes y(L) = 0
    return np.interp(x, s, y)


def test_central_load_gives_the_textbook_mid_span_deflection():
    f = crankshaft.beam_influence(L, [L / 2], EI)
    assert f[0, 0] == pytest.approx(L**3 / (48 * EI), rel=1e-14)


def test_two_loads_match_the_integrated_beam():
    z = np.array([13.0, 24.5])
    f = crankshaft.beam_influence(L, z, EI)
    for j in range(2):
        ref = beam_by_integration(L, z[j], z, EI)
        assert np.allclose(f[:, j], ref, rtol=1e-6)    # measured 2e-10 (grid of 2e5 steps)
    assert f[0, 1] == f[1, 0]                           # Maxwell–Betti


def test_support_compliance_alone_is_springs_and_a_lever():
    c1, c2 = 2e-6, 5e-6
    f = crankshaft.beam_influence(L, [L / 2], np.inf, None, (c1, c2))
    # a central load splits equally: the beam centre moves by the mean support deflection
    assert f[0, 0] == pytest.approx((c1 + c2) / 4, rel=1e-14)
    # a load near support 1 goes almost entirely into it
    g = crankshaft.beam_influence(L, [1e-6 * L], np.inf, None, (c1, c2))
    assert g[0, 0] == pytest.approx(c1, rel=1e-5)


def test_shear_alone_gives_the_timoshenko_mid_span_deflection():
    kGA = 3.0e7
    f = crankshaft.beam_influence(L, [L / 2], np.inf, kGA)
    assert f[0, 0] == pytest.approx(L / (4 * kGA), rel=1e-14)


def test_influence_matrix_is_symmetric_positive_definite_and_superposes():
    z = [12.0, 21.0]
    parts = [crankshaft.beam_influence(L, z, EI), crankshaft.beam_influence(L, z, np.inf, 3e7),
             crankshaft.beam_influence(L, z, np.inf, None, (1e-6, 2e-6))]
    f = crankshaft.beam_influence(L, z, EI, 3e7, (1e-6, 2e-6))
    assert np.allclose(f, sum(parts), rtol=1e-14)
    assert np.allclose(f, f.T, rtol=1e-14) and np.all(np.linalg.eigvalsh(f) > 0)


def test_crankshaft_influence_from_journal_diameter():
    """EI = E·π·d⁴/64 and κGA from the journal; supports and carrier in series."""
    E, nu, d = 206000.0, 0.3, 20.0
    support = SimpleNamespace(influence_mm_per_N=None, youngs_modulus=E, poissons_ratio=nu,
                              bending_stiffness_Nmm2=None, journal_diameter=d, shear=True, span=L,
                              eccentric_positions=(15.0, 25.0), support_stiffness_pair=(4e5, 5e5),
                              carrier_stiffness_pair=(1e6, None))
    f = crankshaft.crankshaft_influence(SimpleNamespace(crank_support=support))
    kappa = 6 * (1 + nu) / (7 + 6 * nu)
    ref = crankshaft.beam_influence(L, [15.0, 25.0], E * math.pi * d**4 / 64,
                                 kappa * E / (2 * (1 + nu)) * math.pi * d * d / 4,
                                 (1 / 4e5 + 1 / 1e6, 1 / 5e5))
    assert np.array_equal(f, ref)


def test_second_disc_phase_is_half_a_tooth_pitch_for_one_tooth_difference():
    case = load_case(CASES_DIR / "rv40e.toml")
    assert cycle.second_disc_phase(case) == pytest.approx(math.pi / case.cycloid.teeth, rel=1e-14)
    # the pins disc B sees at θ (ring of the common housing, centre opposite its eccentric) are
    # the pins of θ + π − β turned by β
    from rvfem.geometry import pin_centres

    beta, th = cycle.second_disc_phase(case), 0.7
    zp, zc, e, rp = case.pins.count, case.cycloid.teeth, case.cycloid.eccentricity, case.pins.circle_radius
    ang = 2 * np.pi * np.arange(zp) / zp + th * (zp - zc) / zp
    seen_by_b = rp * np.stack([np.cos(ang), np.sin(ang)], 1) - e * np.array([math.cos(th + math.pi), math.sin(th + math.pi)])
    turned = pin_centres(case, th + math.pi - beta) @ cycle._rotation(beta).T
    dist = np.linalg.norm(seen_by_b[:, None] - turned[None], axis=2).min(axis=1)
    assert dist.max() < 1e-12


# ------------------------------------------------------------------------------------------------
# two discs on one carrier
# ------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def fan_system(tmp_path_factory):
    case = coarse("rv40e_fanholes")
    return cycle.build_system(case, mesh_case(case, tmp_path_factory.mktemp("meshes")))


@pytest.fixture(scope="module")
def fan_pair_cycle(fan_system):
    stage = cycle.build_stage(fan_system, discs=2, influence=None)
    return stage, cycle.load_cycle(fan_system, THETA, saved_angles_deg=(), stage=stage)


@pytest.mark.slow
def test_pair_equilibrium_of_both_discs_and_the_carrier(fan_pair_cycle):
    stage, result = fan_pair_cycle
    case = stage.first.case
    T = case.loads.torque_Nm * 1000.0
    # the carrier: the two discs' torques add up to the output torque at every angle
    assert np.allclose(result.disc_torque_Nmm.sum(axis=1), T, rtol=1e-12)
    # each disc: pins and bearings balance (force residual relative to the contact forces)
    assert result.equilibrium_residual.max() < 1e-12     # measured 4e-16
    e = case.cycloid.eccentricity
    for k in range(2):
        # about the reducer axis, at −e·u(θ_k) from disc k's centre (disc B at θ + π)
        th = result.theta + k * math.pi
        c = cycle.crank_centres(case)[None] + e * np.stack([np.cos(th), np.sin(th)], axis=-1)[:, None]
        f = result.disc_bearing_forces[:, k]
        moment = (c[..., 0] * f[..., 1] - c[..., 1] * f[..., 0]).sum(axis=1)
        assert np.allclose(moment, result.disc_torque_Nmm[:, k], rtol=1e-9)
    # the torque swings about T/2 (the stiffness of each disc changes as its loaded flank passes
    # bores, spokes and holes) by several per cent on the fan-hole disc
    share = result.disc_torque_Nmm[:, 0] / (T / 2)
    assert 0.02 < share.max() - 1 < 0.15 and 0.02 < 1 - share.min() < 0.15


@pytest.mark.slow
def test_mirrored_pairs_equal_direct_pair_solves(fan_system):
    """The second half of the cycle comes from disc B of the first half's pairs; solving those
    angles directly gives the same state to the solver's tolerance."""
    system = cycle.build_system(fan_system.case, fan_system.mesh, bearing_model="rigid_bore")
    stage = cycle.build_stage(system, discs=2, influence=None)
    result = cycle.load_cycle(system, THETA, saved_angles_deg=(), stage=stage)
    assert result.timings["pair_solves"] == len(THETA) // 6    # 180° swaps and 120° turns: 60° solved
    # the solver stops when the spring laws hold to 1e-8·T/r (≈ 6e-5 N here): two independent
    # solves of one state agree to that, not to round-off
    atol = 1e-8 * stage.carrier_torque_Nmm(cycle.OperatingPoint.of(system.case)) / float(np.abs(system.interface.points).max())
    for j in (20, 27, 35):
        direct = cycle.solve_pair(stage, float(THETA[j]))
        assert np.allclose(direct.bearing_forces[0], result.bearing_forces[j], rtol=0, atol=atol)
        assert np.allclose(direct.bearing_forces[1], result.disc_bearing_forces[j, 1], rtol=0, atol=atol)
        assert direct.torque_Nmm[0] == pytest.approx(result.disc_torque_Nmm[j, 0], rel=1e-9)


@pytest.mark.slow
def test_mirrored_and_turned_pairs_with_rollers_equal_direct_pair_solves(fan_pair_cycle):
    """Exact with rollers too: their cages take one revolution's phases (rvfem.solve.models.roller_angles)."""
    stage, result = fan_pair_cycle
    for j in (20, 35):
        direct = cycle.solve_pair(stage, float(THETA[j]))
        assert np.abs(direct.bearing_forces[0] - result.bearing_forces[j]).max() < 1e-8 * result.bearing_loads.max()


@pytest.mark.slow
def test_pair_keeps_the_n_fold_symmetry(fan_pair_cycle):
    """Bearing i + 1 at θ + 120° carries what bearing i carries at θ (within the unstructured
    mesh's asymmetry; 0.11 % for one disc)."""
    _, result = fan_pair_cycle
    F = result.bearing_loads
    shift = 12                                    # 120° in 10° steps
    for i in range(2):
        assert np.abs(np.roll(F[:, i], shift) - F[:, i + 1]).max() < 0.005 * F.max()


@pytest.mark.slow
def test_two_discs_lower_the_fan_hole_peak_against_one_disc_with_half_the_torque(fan_system, fan_pair_cycle):
    """Sharing the carrier lets the stiffer disc take more torque: on the fan-hole disc the
    maximum bearing load falls (an independent full-system solver: +20.3 % → +13.8 % over the
    handbook on the default mesh)."""
    _, pair = fan_pair_cycle
    one = cycle.load_cycle(fan_system, THETA, saved_angles_deg=(), stage=cycle.single_disc_stage(fan_system))
    hb = rigid.handbook_bearing_loads(fan_system.case, THETA).magnitude.max()
    assert pair.bearing_loads.max() < one.bearing_loads.max()
    assert 0.08 < pair.bearing_loads.max() / hb - 1 < 0.20


@pytest.mark.slow
def test_stiff_discs_share_the_torque_equally_and_give_the_handbook_loads(tmp_path_factory):
    """The rigid limit of the pair: discs 10⁶× stiffer, bearings 1000× stiffer, linear pins, no
    friction (the handbook has none)."""
    case = coarse("rv40e_solid", analysis={"friction": 0.0})
    system = cycle.build_system(case, mesh_case(case, tmp_path_factory.mktemp("meshes")),
                                stiffness_scale=1e6, bearing_model="rigid_bore",
                                bearing_stiffness_scale=1e3, pin_model="linear", pin_stiffness_N_per_mm=3e5)
    stage = cycle.build_stage(system, discs=2, influence=None)
    result = cycle.load_cycle(system, THETA, saved_angles_deg=(), stage=stage)
    T = case.loads.torque_Nm * 1000.0
    share = result.disc_torque_Nmm / (T / 2)
    assert np.abs(share - 1).max() < 0.005
    # the output torque about the reducer axis is T·Zc/Zp about the disc centres (the handbook's)
    case = case.replace(loads=dataclasses.replace(case.loads, torque_Nm=case.loads.torque_Nm
                                                  * case.cycloid.teeth / case.pins.count))
    hb = rigid.handbook_bearing_loads(case, THETA)
    assert np.abs(result.bearing_loads.T - hb.magnitude).max() <= 0.03 * hb.magnitude.max()


@pytest.mark.slow
def test_very_stiff_crankshafts_give_the_rigid_support_result(fan_system, fan_pair_cycle):
    _, rigid_support = fan_pair_cycle
    f = 1e-14 * np.array([[2.0, 1.0], [1.0, 2.0]])     # mm/N: 10¹⁴ N/mm
    stage = cycle.build_stage(fan_system, discs=2, influence=f)
    result = cycle.load_cycle(fan_system, THETA[:6], saved_angles_deg=(), stage=stage)
    ref = rigid_support.bearing_forces[:6]
    assert np.abs(result.bearing_forces - ref).max() <= 1e-6 * np.abs(ref).max()


@pytest.mark.slow
def test_crankshaft_deflection_follows_the_influence_matrix(fan_system):
    """The reported eccentric displacements are −f·F of the forces on both discs, and a softer
    crank support moves the eccentrics more."""
    f = crankshaft.beam_influence(40.0, [15.0, 25.0], 2e9, 3e7, (2e-6, 2e-6))
    stage = cycle.build_stage(fan_system, discs=2, influence=f)
    pair = cycle.solve_pair(stage, 0.3)
    w = -np.einsum("kl,lnj->knj", f, pair.bearing_forces)
    assert np.allclose(pair.eccentric_displacement, w, rtol=1e-12)
    softer = cycle.solve_pair(cycle.build_stage(fan_system, discs=2, influence=2 * f), 0.3)
    assert np.abs(softer.eccentric_displacement).max() > 1.5 * np.abs(pair.eccentric_displacement).max()
    assert softer.torque_Nmm.sum() == pytest.approx(fan_system.case.loads.torque_Nm * 1000.0, rel=1e-12)


def test_pin_friction_converges_on_two_discs_with_rigid_bores_and_keeps_each_disc_in_equilibrium(tmp_path_factory):
    """Hertz pins with Coulomb friction μ = 0.05, two discs on one carrier, crankshafts from the
    case, bores on rigid rings (two bilateral springs per bearing), each angle solved from a cold
    start. The first, linearised solve once made the bearings' x and y springs compression-only;
    with friction the active set then cycled without end at these angles. Each disc stays in
    equilibrium with the friction forces to round-off, and the two discs' torques add up to T."""
    mu = 0.05
    case = coarse("rv40e_solid", analysis={"friction": mu}, crank_bearing={"model": "rigid_bore"})
    system = cycle.build_system(case, mesh_case(case, tmp_path_factory.mktemp("meshes")))
    stage = cycle.case_stage(system)
    assert stage.discs == 2 and stage.influence is not None
    T = case.loads.torque_Nm * 1000.0
    for theta in (-0.02, 0.0, 0.02):
        pair = cycle.solve_pair(stage, theta)
        assert pair.torque_Nmm.sum() == pytest.approx(T, rel=1e-12)
        for r in pair.results:
            res = r.solution.residual
            assert r.solution.iterations <= 8                # measured 3
            loaded = r.pin_forces > 0
            # the friction is there: every loaded pin pushes at atan(μ) to the flank normal
            assert np.allclose(np.linalg.norm(r.pin_vectors[loaded], axis=1),
                               r.pin_forces[loaded] * math.sqrt(1 + mu * mu), rtol=1e-9)
            scale = r.bearing_loads.max()
            total = r.pin_vectors.sum(axis=0) + r.bearing_forces.sum(axis=0)
            assert np.abs(total).max() <= 1e-12 * scale
            assert res["force_N"] <= 1e-12 * scale and res["relative"] < 1e-14
            assert res["moment_Nmm"] <= 1e-12 * scale * case.cranks.circle_radius


def test_pin_friction_converges_with_clearance_all_round_and_stiff_bores(tmp_path_factory):
    """An equidistant modification (5 µm clearance at every pin) with bores on 1000× stiffer rings:
    the first, linearised solve opens every pin spring of a disc, which leaves its rotation and the
    carrier's free (a singular Newton matrix; with friction the iteration cycled). The start falls
    back to open springs with a weak stiffness, and the pair settles."""
    case = coarse("rv40e_solid", analysis={"friction": 0.05},
                  crank_bearing={"model": "rigid_bore", "rigid_bore_stiffness_N_per_mm": 7e8})
    data = case_to_dict(case)
    data["cycloid"]["modification"]["equidistant"] = 0.005
    case = case_from_dict(data, source="clearance all round")
    system = cycle.build_system(case, mesh_case(case, tmp_path_factory.mktemp("meshes")))
    stage = cycle.build_stage(system, discs=2, influence=None)
    pair = cycle.solve_pair(stage, 0.0)
    assert pair.torque_Nmm.sum() == pytest.approx(case.loads.torque_Nm * 1000.0, rel=1e-12)
    for r in pair.results:
        assert r.solution.iterations <= 8                    # measured 3
        assert r.solution.residual["relative"] < 1e-14
        assert 0 < r.pins_in_contact < case.pins.count
