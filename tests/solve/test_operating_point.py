"""The operating point is an argument: a torque sweep (and a duty cycle) is a loop over operating
points on one disc model, with no new factorisation and no compliance column computed twice, and
its results are those of a case built at each torque."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import coarse_case

from rvfem import fem
from rvfem.mesh import mesh_case
from rvfem.solve import cycle

THETA = np.radians(np.arange(0.0, 360.0, 30.0))


@pytest.fixture(scope="module")
def solid(tmp_path_factory):
    case = coarse_case("rv40e_solid")
    return case, mesh_case(case, tmp_path_factory.mktemp("meshes"))


def test_the_case_operating_point_is_its_torque_and_friction(solid):
    case, _ = solid
    op = cycle.OperatingPoint.of(case)
    assert op == cycle.OperatingPoint(case.loads.torque_Nm, case.analysis.friction)
    assert op.disc_torque_Nmm(case) == case.loads.disc_torque_Nmm


def test_a_torque_sweep_reuses_one_factorisation_and_never_recomputes_a_column(solid, monkeypatch):
    case, mesh = solid
    system = cycle.build_system(case, mesh)
    calls = []
    real = fem.factorize
    monkeypatch.setattr(fem, "factorize", lambda *a, **k: calls.append(1) or real(*a, **k))
    T = case.loads.torque_Nm
    torques = np.linspace(0.05, 1.0, 20) * T
    sweep = [cycle.load_cycle(system, THETA, op=cycle.OperatingPoint(t, case.analysis.friction),
                              saved_angles_deg=()) for t in torques]
    assert calls == []
    solved = system.compliance.columns_solved
    assert solved <= system.interface.n_columns
    # the same sweep again computes no column at all
    again = [cycle.load_cycle(system, THETA, op=cycle.OperatingPoint(t, case.analysis.friction),
                              saved_angles_deg=()) for t in torques]
    assert system.compliance.columns_solved == solved
    for a, b in zip(sweep, again):
        assert np.allclose(a.bearing_forces, b.bearing_forces, rtol=1e-9, atol=1e-9 * np.abs(a.bearing_forces).max())
    # every point carries its own torque on the carrier (two discs: T_out)
    for t, c in zip(torques, sweep):
        assert c.disc_torque_Nmm.sum(axis=1) == pytest.approx(np.full(len(THETA), t * 1000.0), rel=1e-9)


def test_an_operating_point_gives_the_cycle_of_a_case_built_at_that_torque(solid):
    """The sweep on one system against an independent system built from a case with that torque
    and friction: the same loads (the contact sets and the solve see only the operating point)."""
    case, mesh = solid
    system = cycle.build_system(case, mesh)
    for torque, mu in ((0.4 * case.loads.torque_Nm, case.analysis.friction), (-case.loads.torque_Nm, 0.0)):
        swept = cycle.load_cycle(system, THETA, op=cycle.OperatingPoint(torque, mu), saved_angles_deg=())
        other = coarse_case("rv40e_solid", loads={"torque_Nm": torque}, analysis={"friction": mu})
        direct = cycle.load_cycle(cycle.build_system(other, mesh), THETA, saved_angles_deg=())
        scale = np.abs(direct.bearing_forces).max()
        assert np.abs(swept.bearing_forces - direct.bearing_forces).max() <= 1e-7 * scale
        assert np.abs(swept.pin_forces - direct.pin_forces).max() <= 1e-7 * scale


def test_reversed_torque_reverses_the_carrier_rotation_and_keeps_equilibrium(solid):
    case, mesh = solid
    system = cycle.build_system(case, mesh)
    fwd = cycle.solve_angle(system, 0.4)
    rev = cycle.solve_angle(system, 0.4, op=cycle.OperatingPoint(-case.loads.torque_Nm, case.analysis.friction))
    assert np.sign(rev.carrier_rotation) == -np.sign(fwd.carrier_rotation)
    assert rev.solution.residual["torque_Nmm"] == pytest.approx(-case.loads.disc_torque_Nmm, rel=1e-9)
    assert rev.solution.residual["relative"] < 1e-9
