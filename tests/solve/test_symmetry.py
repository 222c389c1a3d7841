"""N-fold symmetry: compliance columns by rotation and crank angles by turning, against the same
quantities computed directly on the same exactly symmetric mesh (equal to round-off), and the
symmetric mesh against the full-disc mesh (equal within the mesh's discretisation error)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import coarse_case as coarse

from rvfem.mesh import mesh_case
from rvfem.solve import contact, cycle

STEP = np.radians(10.0)
THETA = np.arange(36) * STEP   # 10° steps: 120° and 180° are whole samples


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


@pytest.fixture(scope="module")
def fan(meshes):
    case = coarse("rv40e_fanholes")
    return case, mesh_case(case, meshes)


@pytest.fixture(scope="module")
def fan_full(fan, meshes):
    """The same case meshed as a whole disc (``mesh.symmetric = false``)."""
    case, _ = fan
    full = dataclasses.replace(case, mesh=dataclasses.replace(case.mesh, symmetric=False))
    return cycle.build_system(full, mesh_case(full, meshes))


@pytest.fixture(scope="module")
def fan_system(fan):
    case, mesh = fan
    return cycle.build_system(case, mesh)


# ------------------------------------------------------------------------------------------------
# the plan: which angles are solved
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("order, mirror, solved", [(1, False, 36), (3, False, 12), (1, True, 18),
                                                   (3, True, 6), (2, True, 18), (4, True, 9)])
def test_plan_solves_one_period_and_reaches_every_angle_exactly(order, mirror, solved):
    solve, source = cycle.symmetry_plan(THETA, order, mirror)
    assert len(solve) == solved
    turn = 2 * math.pi / order
    for j, (i, swap, k) in enumerate(source):
        assert i in solve
        # no wrap past 2π: every result carries the angle θ_j itself
        assert THETA[i] + swap * math.pi + k * turn == pytest.approx(THETA[j], abs=1e-12)


def test_plan_solves_everything_for_non_uniform_angles():
    thetas = np.array([0.0, 0.1, 0.5, 2.0])
    solve, source = cycle.symmetry_plan(thetas, 3, True)
    assert list(solve) == [0, 1, 2, 3] and all(k == 0 and s == 0 for _, s, k in source)


# ------------------------------------------------------------------------------------------------
# compliance by rotation
# ------------------------------------------------------------------------------------------------


def test_the_shipped_fan_hole_disc_is_meshed_symmetric(fan_system):
    assert fan_system.mesh.symmetry == 3 and fan_system.symmetry == 3
    assert fan_system.compliance.symmetric


def test_rotated_columns_equal_back_substituted_columns(fan_system):
    """Columns of the other two sectors obtained by rotation against the same columns computed
    by back-substitution (the floating compliance, no rotation map)."""
    s = fan_system
    direct = contact.Compliance(s.solve, s.interface.B, rigid_modes=s.rigid_modes,
                                vertex_dofs=s.model.node_dofs[:s.model.n_vertices].ravel())
    mapped = contact.Compliance(s.solve, s.interface.B, rigid_modes=s.rigid_modes,
                                vertex_dofs=s.model.node_dofs[:s.model.n_vertices].ravel(),
                                rotation=contact.column_rotation(s.interface, 3), order=3)
    rng = np.random.default_rng(1)
    cols = rng.choice(s.interface.n_columns, 60, replace=False)
    mapped.ensure(cols)
    direct.ensure(cols)
    assert mapped.columns_mapped > 0 and mapped.columns_solved < s.interface.n_columns / 2
    scale = np.abs(direct.C[:, cols]).max()
    assert np.abs(mapped.C[:, cols] - direct.C[:, cols]).max() <= 1e-9 * scale


def test_floating_compliance_gives_the_supported_contact_forces(fan_full):
    """The support-free compliance differs from Bᵀ K_s⁻¹ B by rigid-motion terms only: the
    contact forces of an angle agree to round-off (full-disc mesh, so the supported form is
    the one every earlier version used)."""
    system = fan_full
    case = system.case
    cset, names = cycle.contact_set(system, 0.4)
    supported = contact.Compliance(system.solve, system.interface.B)
    a = contact.solve_contact(cset, system.interface, supported, case.loads.disc_torque_Nmm, names=names)
    b = contact.solve_contact(cset, system.interface, system.compliance, case.loads.disc_torque_Nmm, names=names)
    assert np.abs(a.force - b.force).max() <= 1e-8 * a.force.max()
    assert a.carrier_rotation == pytest.approx(b.carrier_rotation, rel=1e-8)


# ------------------------------------------------------------------------------------------------
# crank angles by turning
# ------------------------------------------------------------------------------------------------


def test_turned_angles_equal_directly_solved_angles(fan_system):
    s = fan_system
    result = cycle.load_cycle(s, THETA, saved_angles_deg=(), stage=cycle.single_disc_stage(s))
    assert result.timings["pair_solves"] == 12
    assert all(r.origin is not None for r in result.solutions[12:])    # none solved directly
    for j in (13, 25, 31):          # turned once or twice
        direct = cycle.solve_angle(s, float(THETA[j]))
        scale = direct.bearing_loads.max()
        assert np.abs(direct.bearing_forces - result.bearing_forces[j]).max() <= 1e-7 * scale
        assert np.abs(direct.pin_forces - result.pin_forces[j]).max() <= 1e-7 * scale
        assert np.abs(direct.roller_loads - result.roller_loads[j]).max() <= 1e-7 * scale
        assert direct.carrier_rotation == pytest.approx(result.carrier_rotation[j], rel=1e-7)
        # the rebuilt displacement field is the directly solved one
        u_direct = cycle.displacement(s, direct)
        u_turned = cycle.displacement(s, result.solutions[j])
        assert np.abs(u_direct - u_turned).max() <= 1e-7 * np.abs(u_direct).max()


def test_turned_pairs_equal_directly_solved_pairs(fan_system):
    stage = cycle.case_stage(fan_system)
    result = cycle.load_cycle(fan_system, THETA, saved_angles_deg=(), stage=stage)
    assert result.timings["pair_solves"] == 6       # 60° of pairs: 120° turns and 180° swaps
    assert sum(r.origin is None for r in result.solutions) == 12       # 6 solved, 6 swapped
    for j in (7, 20, 33):
        direct = cycle.solve_pair(stage, float(THETA[j]))
        scale = np.abs(direct.bearing_forces).max()
        assert np.abs(direct.bearing_forces[0] - result.bearing_forces[j]).max() <= 1e-7 * scale
        assert np.abs(direct.torque_Nmm - result.disc_torque_Nmm[j]).max() <= 1e-7 * abs(stage.carrier_torque_Nmm(cycle.OperatingPoint.of(stage.first.case)))
        # disc B's loads, turned without its contacts, in the carrier frame, and the eccentrics
        assert np.abs(direct.bearing_forces - result.disc_bearing_forces[j]).max() <= 1e-7 * scale
        w = np.abs(direct.eccentric_displacement).max()
        assert w > 0 and np.abs(direct.eccentric_displacement - result.eccentric_displacement[j]).max() <= 1e-7 * w


def test_symmetric_mesh_agrees_with_the_full_mesh_within_the_discretisation(fan_system, fan_full):
    system = fan_full
    assert system.symmetry == 1
    a = cycle.load_cycle(fan_system, THETA, saved_angles_deg=(), stage=cycle.single_disc_stage(fan_system)).bearing_loads
    b = cycle.load_cycle(system, THETA, saved_angles_deg=(), stage=cycle.single_disc_stage(system)).bearing_loads
    # two different meshes of the same disc at 0.6 mm: measured 0.x % of the peak
    assert np.abs(a - b).max() <= 0.01 * b.max()


def test_stress_envelope_from_turned_fields_equals_the_one_from_every_field(fan_system):
    """The envelope turns each solved angle's von Mises field instead of rebuilding every field:
    the same as rebuilding each field from its own contact forces."""
    from rvfem.fem import nodal_stress_operator

    s = fan_system
    result = cycle.load_cycle(s, THETA, saved_angles_deg=(), stage=cycle.single_disc_stage(s), stress_envelope=True)
    op = nodal_stress_operator(s.model)
    nv = s.model.n_vertices
    vm = []
    for r in result.solutions:
        sxx, syy, sxy = (op @ cycle.displacement(s, dataclasses.replace(r, origin=None))).reshape(3, nv)
        vm.append(np.sqrt(sxx * sxx - sxx * syy + syy * syy + 3.0 * sxy * sxy))
    direct = np.max(vm, axis=0)
    assert np.abs(result.von_mises_envelope - direct).max() <= 1e-8 * direct.max()


def test_turning_onto_contacts_that_are_not_the_turned_ones_is_refused(fan_system):
    """The contact map is checked: contacts of another angle are not a turned copy."""
    s = fan_system
    solved = cycle.solve_angle(s, 0.3)
    wrong, _ = cycle.contact_set(s, 0.3 + 2 * math.pi / 3 + 0.01)
    with pytest.raises(ValueError, match="turned contacts"):
        cycle.turn_result(s, solved, 1, wrong)
    right, _ = cycle.contact_set(s, 0.3 + 2 * math.pi / 3)
    assert cycle.turn_result(s, solved, 1, right).origin == (solved, 1)


def test_probe_map_is_the_column_by_column_map_of_the_turned_contacts(fan_system):
    """The permutation of pins and rollers found with random probes is the map found by matching
    the turned weight columns one by one; contacts that turn into combinations of contacts (the
    x and y springs of a rigid bore) have none, and the least-squares map takes over."""
    s = fan_system
    for theta, k in ((0.3, 1), (1.1, 2)):
        old, _ = cycle.contact_set(s, theta)
        new, _ = cycle.contact_set(s, theta + k * 2 * math.pi / 3)
        pairs = [(old.W, new.W), (old.load_weights, new.load_weights)]
        probe = cycle._permutation_map(s.compliance.rotation_power(k), *pairs)
        dense = cycle._contact_map(s.compliance.rotation_power(k), *pairs)
        # the same permutation; the factors of the column-by-column map are 1 to round-off
        assert probe is not None and np.array_equal(probe != 0, np.abs(dense) > 1e-9)
        assert np.abs(probe - dense).max() <= 1e-10
        assert np.array_equal(probe.sum(axis=0), np.ones(len(probe)))
    bore = cycle.build_system(s.case, s.mesh, bearing_model="rigid_bore")
    old, _ = cycle.contact_set(bore, 0.3)
    new, _ = cycle.contact_set(bore, 0.3 + 2 * math.pi / 3)
    assert cycle._permutation_map(bore.compliance.rotation_power(1), (old.W, new.W)) is None
    turned = cycle.turn_result(bore, cycle.solve_angle(bore, 0.3), 1, new)
    direct = cycle.solve_angle(bore, 0.3 + 2 * math.pi / 3)
    assert np.abs(turned.bearing_forces - direct.bearing_forces).max() <= 1e-7 * direct.bearing_loads.max()


def test_columns_on_the_free_dofs_equal_the_projected_back_substitution(fan_system):
    """The columns back-substituted on the free DOFs by superposition (sparse right-hand sides,
    the rigid-mode part solved once) against the balanced load solved through the whole DOF
    numbering, the definition C = Bᵀ Π K_s⁻¹ Πᵀ B."""
    s = fan_system
    vertex_dofs = s.model.node_dofs[:s.model.n_vertices].ravel()
    plain = contact.Compliance(s.solve, s.interface.B, rigid_modes=s.rigid_modes, vertex_dofs=vertex_dofs)
    assert s.compliance._free is not None
    cols = np.random.default_rng(2).choice(s.interface.n_columns, 40, replace=False)
    plain.ensure(cols)
    factor = s.solve.__self__              # the system's Factorization
    fresh = contact.Compliance(s.solve, s.interface.B, rigid_modes=s.rigid_modes, vertex_dofs=vertex_dofs,
                               free=(factor.free_dofs, factor.solve_free))
    fresh.ensure(cols)
    scale = np.abs(plain.C[:, cols]).max()
    assert np.abs(fresh.C[:, cols] - plain.C[:, cols]).max() <= 1e-12 * scale
