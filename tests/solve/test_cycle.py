"""The flexible load cycle: rigid limits, equilibrium, symmetry and the flexibility effect.

Coarse meshes (0.6 mm at the flanks and bores) keep this file fast; the mesh-convergence study
with the default sizes lives in ``benchmarks/bench_convergence.py``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import coarse_case as coarse

from rvfem.case.definition import case_from_dict, case_to_dict
from rvfem.errors import ContactError
from rvfem.evaluate import compare, rigid
from rvfem.mesh import mesh_case
from rvfem.solve import contact, cycle

STEP = np.radians(10.0)
THETA = np.arange(36) * STEP   # 10° steps: the 120° shifts of three cranks are whole samples


@pytest.fixture(scope="module")
def mesh_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


@pytest.fixture(scope="module")
def solid(mesh_dir):
    case = coarse("rv40e_solid")
    return case, mesh_case(case, mesh_dir)


@pytest.fixture(scope="module")
def fanholes(mesh_dir):
    case = coarse("rv40e_fanholes")
    return case, mesh_case(case, mesh_dir)


# ------------------------------------------------------------------------------------------------
# rigid limits
# ------------------------------------------------------------------------------------------------


def test_rigid_limit_reproduces_handbook_and_classical_pin_forces(solid):
    """Disc 10⁶× stiffer, bearings 1000× stiffer, linear pin springs: the handbook's assumptions
    (rigid disc held at its centre, pin deflections ∝ the disc rotation's lever arms). Then the
    FE must give the classical pin forces and the handbook bearing loads. No friction: the
    handbook has none."""
    _, mesh = solid
    case = coarse("rv40e_solid", analysis={"friction": 0.0})
    system = cycle.build_system(case, mesh, stiffness_scale=1e6, bearing_model="rigid_bore",
                                bearing_stiffness_scale=1e3, pin_model="linear",
                                pin_stiffness_N_per_mm=3e5)
    result = cycle.load_cycle(system, THETA, saved_angles_deg=(), stage=cycle.single_disc_stage(system))
    # the carrier torque is a moment about the reducer axis; every pin normal passes through the
    # pitch point, e·Zp from the axis and e·Zc from the disc centre: the handbook's T/2 about the
    # disc centre is T/2·Zc/Zp
    case = case.replace(loads=dataclasses.replace(case.loads, torque_Nm=case.loads.torque_Nm
                                                  * case.cycloid.teeth / case.pins.count))
    hb = rigid.handbook_bearing_loads(case, THETA)
    f_max = hb.magnitude.max()
    assert np.abs(result.bearing_loads.T - hb.magnitude).max() <= 0.03 * f_max
    # the vectors too, not only the magnitudes
    hb_vec = np.stack([hb.fx, hb.fy], axis=-1).transpose(1, 0, 2)
    assert np.abs(result.bearing_forces - hb_vec).max() <= 0.03 * f_max
    pins = rigid.classical_pin_forces(case, THETA, exact_moment=True)
    classical = pins.magnitude.T
    assert np.abs(result.pin_forces - classical).max() <= 0.01 * classical.max()
    # half of the pins carry load (0 < φ < π), the other half touch without load
    assert set(result.pins_in_contact) == {case.pins.count // 2}


def test_rigid_disc_shares_load_equally_with_linear_rollers(solid):
    """Disc 1000× stiffer, zero clearance, linear roller springs: each bearing carries 1/N of the
    FE's own pin resultant plus the torque share (exact for linear springs on a rigid disc)."""
    _, mesh = solid
    case = coarse("rv40e_solid", crank_bearing={"stiffness_law": "linear", "linear_stiffness_N_per_mm": 2e5})
    system = cycle.build_system(case, mesh, stiffness_scale=1e3)
    result = cycle.load_cycle(system, THETA, saved_angles_deg=(), stage=cycle.single_disc_stage(system))
    share = compare.equal_share_forces(case, result)
    assert np.abs(result.bearing_forces - share).max() <= 0.005 * result.bearing_loads.max()


def test_rigid_disc_with_palmgren_rollers_deviates_from_equal_share_by_the_nonlinearity(solid):
    """With Palmgren's law (Q ∝ δ^1.11) the more deflected bearing is the stiffer one and draws
    more than its equal share; the deviation is small but clearly above the linear case's."""
    case, mesh = solid
    system = cycle.build_system(case, mesh, stiffness_scale=1e3)
    result = cycle.load_cycle(system, THETA, saved_angles_deg=(), stage=cycle.single_disc_stage(system))
    share = compare.equal_share_forces(case, result)
    dev = np.abs(result.bearing_forces - share).max() / result.bearing_loads.max()
    assert 0.005 < dev < 0.05


# ------------------------------------------------------------------------------------------------
# invariants of every solve
# ------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def solid_cycle(solid):
    case, mesh = solid
    system = cycle.build_system(case, mesh)
    return case, system, cycle.load_cycle(system, THETA, saved_angles_deg=(0.0,), stage=cycle.single_disc_stage(system))


def test_equilibrium_closes_to_round_off(solid_cycle):
    case, system, result = solid_cycle
    assert result.equilibrium_residual.max() < 1e-9
    # carrier: the bearings' moment about the reducer axis (at −e·u(θ) in the disc frame) is the
    # disc's torque share at every angle
    e = case.cycloid.eccentricity
    c = cycle.crank_centres(case)[None] + e * np.stack([np.cos(THETA), np.sin(THETA)], axis=-1)[:, None]
    f = result.bearing_forces
    moment = (c[..., 0] * f[..., 1] - c[..., 1] * f[..., 0]).sum(axis=1)
    assert np.allclose(moment, case.loads.disc_torque_Nmm, rtol=1e-9)
    # pins + bearings of one solution: no net force and no net moment on the disc
    for th in THETA[::6]:
        one = cycle.solve_angle(system, th)
        total = one.pin_vectors.sum(axis=0) + one.bearing_forces.sum(axis=0)
        assert np.abs(total).max() <= 1e-9 * one.bearing_loads.max()


def test_bearing_curves_are_shifts_by_360_over_n(solid_cycle):
    """Zc = 39 is divisible by N = 3: bearing i sees bearing 0's loads 120°·i later. The mesh is
    unstructured, so the symmetry holds to discretisation accuracy, not to round-off."""
    case, _, result = solid_cycle
    loads = result.bearing_loads
    shift = int(round(2 * math.pi / case.cranks.count / STEP))
    for i in range(1, case.cranks.count):
        assert np.abs(loads[:, i] - np.roll(loads[:, 0], i * shift)).max() <= 0.005 * loads.max()


def test_loads_scale_with_torque_only_nonlinearly_through_the_contacts(solid):
    """Doubling the torque doubles the handbook loads; the FE loads rise by almost exactly 2× too
    (the active sets barely change), a check that the torque enters with the right units."""
    case, mesh = solid
    double = coarse("rv40e_solid", loads={"torque_Nm": 2 * case.loads.torque_Nm})
    r1 = cycle.solve_angle(cycle.build_system(case, mesh), 0.3)
    r2 = cycle.solve_angle(cycle.build_system(double, mesh), 0.3)
    assert r2.bearing_loads == pytest.approx(2 * r1.bearing_loads, rel=0.05)


def test_clearance_and_modification_reduce_contact_and_stay_in_equilibrium(solid):
    case, mesh = solid
    data = case_to_dict(case)
    data["crank_bearing"]["radial_clearance"] = 0.005
    data["cycloid"]["modification"] = {"equidistant": 0.01, "shift": -0.005, "rotation_deg": 0.0}
    modified = case_from_dict(data, source="modified")
    system = cycle.build_system(modified, mesh_case(modified, mesh.path.parent))
    base = cycle.solve_angle(cycle.build_system(case, mesh), 0.0)
    mod = cycle.solve_angle(system, 0.0)
    assert mod.pins_in_contact < base.pins_in_contact
    assert mod.solution.residual["relative"] < 1e-9
    assert mod.bearing_loads.max() > base.bearing_loads.max()


def test_field_of_a_saved_angle_reproduces_the_contact_displacements(solid_cycle):
    case, system, result = solid_cycle
    (theta, u), = [(t, u) for t, u in result.fields.items() if abs(t) < 1e-12]
    one = cycle.solve_angle(system, theta)
    # the roller approach predicted by the small system equals the one read off the full field
    B, W = system.interface.B, one.contacts.W
    WL = W if one.contacts.W_load is None else one.contacts.W_load     # loads incl. pin friction
    v_field = np.asarray(W.T @ (B.T @ u))
    Rc = np.asarray(W.T @ system.interface.resultants)
    v_small = (np.asarray(W.T @ system.compliance.C @ WL @ one.solution.force)).ravel() + Rc @ one.solution.rigid
    assert np.allclose(v_field, v_small, atol=1e-9 * np.abs(v_field).max())


# ------------------------------------------------------------------------------------------------
# the flexibility effect and the comparison
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bearing_model", ["rollers", "rigid_bore"])
def test_fan_holes_raise_the_maximum_bearing_load(solid, fanholes, bearing_model):
    maxima = {}
    for name, (case, mesh) in (("solid", solid), ("fanholes", fanholes)):
        system = cycle.build_system(case, mesh, bearing_model=bearing_model)
        result = cycle.load_cycle(system, THETA, saved_angles_deg=(), stage=cycle.single_disc_stage(system))
        maxima[name] = compare.rigid_vs_flexible(case, result).bearings[0].delta_max_percent
    assert maxima["fanholes"] > maxima["solid"] + 3.0


def test_comparison_reports_life_ratio_consistent_with_loads(solid_cycle):
    case, _, result = solid_cycle
    comp = compare.rigid_vs_flexible(case, result)
    for b in comp.bearings:
        assert b.life_ratio == pytest.approx((b.rigid.equivalent_N / b.flexible.equivalent_N) ** (10 / 3))
        assert b.flexible.L10h / b.rigid.L10h == pytest.approx(b.life_ratio)
        assert b.delta_max_percent == pytest.approx(100 * (b.flexible.max_N / b.rigid.max_N - 1))


# ------------------------------------------------------------------------------------------------
# errors
# ------------------------------------------------------------------------------------------------


def test_pin_friction_tilts_the_pin_forces_by_atan_mu_and_keeps_equilibrium(solid):
    """Coulomb friction μ along the sliding direction: every loaded pin's force on the disc has
    the tangential part μ·λ (|F| = λ·√(1 + μ²)), and the disc and carrier stay in equilibrium."""
    _, mesh = solid
    mu = 0.05
    rough = coarse("rv40e_solid", analysis={"friction": mu})
    system = cycle.build_system(rough, mesh)
    one = cycle.solve_angle(system, 0.3)
    loaded = one.pin_forces > 0
    assert np.allclose(np.linalg.norm(one.pin_vectors[loaded], axis=1),
                       one.pin_forces[loaded] * math.sqrt(1 + mu * mu), rtol=1e-9)
    assert one.solution.residual["relative"] < 1e-9
    total = one.pin_vectors.sum(axis=0) + one.bearing_forces.sum(axis=0)
    assert np.abs(total).max() <= 1e-9 * one.bearing_loads.max()
    smooth = cycle.solve_angle(cycle.build_system(coarse("rv40e_solid", analysis={"friction": 0.0}), mesh), 0.3)
    # friction changes the loads by a few percent at μ = 0.05, not by tens of percent
    assert 0.0 < np.abs(one.bearing_loads - smooth.bearing_loads).max() < 0.1 * smooth.bearing_loads.max()


def test_active_set_bound_names_the_crank_angle(solid):
    case, mesh = solid
    data = case_to_dict(case)
    data["analysis"]["max_active_set_iterations"] = 1
    tight = case_from_dict(data, source="tight.toml")
    with pytest.raises(ContactError, match=r"crank angle 0\.00°"):
        cycle.solve_angle(cycle.build_system(tight, mesh), 0.0)


def test_stress_envelope_is_the_maximum_over_all_angles(solid):
    """The envelope tracked during the cycle equals the vertex von Mises of every angle's full
    field, maximised over the angles (all fields kept here to compare)."""
    from rvfem import fem

    case, mesh = solid
    system = cycle.build_system(case, mesh)
    thetas = np.radians([0.0, 25.0, 50.0, 75.0])
    result = cycle.load_cycle(system, thetas, saved_angles_deg=(0.0, 25.0, 50.0, 75.0), stress_envelope=True)
    vm = np.stack([fem.stress_fields(system.model, result.fields[t]).nodal.von_mises for t in sorted(result.fields)])
    assert np.allclose(result.von_mises_envelope, vm.max(axis=0), rtol=1e-9, atol=1e-9)
    assert np.allclose(result.von_mises_envelope_theta, thetas[np.argmax(vm, axis=0)])
    # and every angle's field can be rebuilt exactly from the kept solutions
    u = cycle.displacement(system, result.solutions[2])
    assert np.allclose(u, result.fields[thetas[2]], rtol=0, atol=1e-14)


def test_contacts_of_many_angles_are_those_built_one_by_one(fanholes):
    """The batched pin and roller contacts (one closest-point search, W built in CSC form) equal
    the contacts of each angle built on its own from coordinates, entry for entry."""
    import scipy.sparse as sp

    from rvfem.geometry import (
        crank_centres,
        pin_centres,
        pin_profile_contacts,
        profile_curvature,
    )

    case, mesh = fanholes
    system = cycle.build_system(case, mesh)
    thetas = np.radians([0.0, 7.0, 119.0, 359.0])
    batched = cycle.contact_sets(system, thetas, cycle.OperatingPoint.of(system.case))
    prof = system.interface.grids["profile"]
    centres = crank_centres(case)
    zp = case.pins.count
    for theta, (cset, names) in zip(thetas, batched):
        pc = pin_profile_contacts(system.geometry, theta)
        cols, wts = prof.columns_at(prof.arc_of(pc.point), -np.asarray(pc.normal))
        W_pins = sp.csc_matrix((wts.ravel(), (cols.ravel(), np.repeat(np.arange(zp), 4))),
                               shape=(system.interface.n_columns, zp))
        psi = cycle.roller_angles(case, theta)
        rows, contacts, vals = [], [], []
        for i, c in enumerate(centres):
            grid = system.interface.grids[f"bore_{i}"]
            pts = c + case.crank_bearing.bore_radius * np.stack([np.cos(psi[i]), np.sin(psi[i])], axis=1)
            cc, ww = grid.columns_at(grid.arc_of(pts))
            rows.append(cc.ravel())
            contacts.append(np.repeat(zp + i * psi.shape[1] + np.arange(psi.shape[1]), 2))
            vals.append(ww.ravel())
        W = sp.hstack([W_pins, sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(contacts) - zp)),
                                             shape=(system.interface.n_columns, psi.size))]).tocsc()
        assert cset.W.has_sorted_indices
        assert np.array_equal(cset.W.indptr, W.indptr) and np.array_equal(cset.W.indices, W.indices)
        assert np.array_equal(cset.W.data, W.data)
        mu = case.analysis.friction
        assert mu > 0
        inward = -np.asarray(pc.normal)
        tangent = np.stack([-inward[:, 1], inward[:, 0]], axis=1)
        h = 1e-6
        vel = (pin_centres(case, theta + h) - pin_centres(case, theta - h)) / (2 * h)
        slide = np.sign(np.einsum("ij,ij->i", vel, tangent))
        cols, wts = prof.columns_at(prof.arc_of(pc.point), inward + mu * slide[:, None] * tangent)
        W_load = sp.csc_matrix((wts.ravel(), (cols.ravel(), np.repeat(np.arange(zp), 4))),
                               shape=(system.interface.n_columns, zp))
        assert np.array_equal(cset.W_load[:, :zp].toarray(), W_load.toarray())
        assert np.array_equal(cset.W_load[:, zp:].toarray(), W[:, zp:].toarray())
        hertz = system.pins.law(pc, profile_curvature(system.geometry.profile, pc.segment, pc.param))
        delta = np.linspace(-1e-3, 5e-3, zp)
        assert np.array_equal(cset.laws[0][1](delta)[0], hertz(delta)[0])
        assert np.array_equal(cset.offset[:zp], -np.asarray(pc.gap))
        assert names[0] == "pin 1" and names[zp] == "bearing 1 roller 1" and len(names) == zp + psi.size


def test_extrapolated_start_gives_the_solution_of_the_last_angle_as_start(solid):
    """An angle started from the extrapolation of the two before it converges to the solution
    started from the last one (within the iteration's tolerance) in fewer iterations; a start
    that does not settle falls back to the last solution."""
    case, mesh = solid
    system = cycle.build_system(case, mesh)
    a, b = (cycle.solve_angle(system, t) for t in (0.0, STEP / 10))
    theta = 2 * STEP / 10
    plain = cycle.solve_angle(system, theta, b)
    extrapolated = cycle.solve_from_last(lambda start: cycle.solve_angle(system, theta, start), [a, b])
    scale = plain.bearing_loads.max()
    assert np.abs(extrapolated.bearing_forces - plain.bearing_forces).max() <= 1e-8 * scale
    assert extrapolated.solution.iterations < plain.solution.iterations

    def refuses_extrapolation(start):
        if start is not b:
            raise ContactError("does not settle")
        return cycle.solve_angle(system, theta, start)

    fallback = cycle.solve_from_last(refuses_extrapolation, [a, b])
    assert np.array_equal(fallback.bearing_forces, plain.bearing_forces)


def test_cold_start_on_the_torque_side_gives_the_solution_of_all_springs_engaged(fanholes, monkeypatch):
    """The first, linearised solve of a cycle engages only the bearings and the pins that resist
    the torque: it converges to the solution that every spring engaged gives (the start is only a
    start; a flexible disc may still load a pin of the other side, which the Newton steps engage),
    with fewer compliance columns; and when that start does not settle, every spring is engaged."""
    case, mesh = fanholes
    theta = 0.3
    torque_side = cycle.build_system(case, mesh)
    reduced = cycle.solve_angle(torque_side, theta)
    engaged = contact._torque_side(contact.Body(reduced.contacts, torque_side.interface, None),
                                   case.loads.disc_torque_Nmm)
    zp = case.pins.count
    assert engaged[zp:].all() and 0 < engaged[:zp].sum() < zp

    everything = cycle.build_system(case, mesh)
    with monkeypatch.context() as m:
        m.setattr(contact, "_torque_side", lambda body, torque: np.ones(body.cset.W.shape[1], dtype=bool))
        full = cycle.solve_angle(everything, theta)
    scale = full.bearing_loads.max()
    assert np.abs(reduced.bearing_forces - full.bearing_forces).max() <= 1e-8 * scale
    assert np.abs(reduced.pin_forces - full.pin_forces).max() <= 1e-8 * scale
    assert torque_side.compliance.columns_solved < everything.compliance.columns_solved

    calls = []
    original = contact._newton

    def refuses_the_torque_side(*args, engaged=None, **kw):
        calls.append(None if engaged is None else bool(engaged.all()))
        if engaged is not None and not engaged.all():
            raise ContactError("does not settle")
        return original(*args, engaged=engaged, **kw)

    monkeypatch.setattr(contact, "_newton", refuses_the_torque_side)
    fallback = cycle.solve_angle(cycle.build_system(case, mesh), theta)
    assert calls[:2] == [False, True]
    assert np.abs(fallback.bearing_forces - full.bearing_forces).max() <= 1e-8 * scale
