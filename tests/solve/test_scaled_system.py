"""A disc's Young's modulus scaled on its own factorisation (:func:`rvfem.solve.cycle.scaled_system`)
against the disc assembled and factorised anew with the scaled modulus (:func:`build_system`):
linear elasticity is homogeneous in E, so the two agree to round-off."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import coarse_case

from rvfem.mesh import mesh_case
from rvfem.solve import cycle
from rvfem.solve.cycle import OperatingPoint

FACTOR = 1000.0
T_NMM = 412e3


@pytest.fixture(scope="module")
def systems(tmp_path_factory):
    case = coarse_case("rv40e_fanholes")
    mesh = mesh_case(case, tmp_path_factory.mktemp("meshes"))
    system = cycle.build_system(case, mesh)
    cycle.solve_angle(system, 0.0, op=OperatingPoint(T_NMM))      # some columns known before the scaling
    known = system.compliance.known.copy()
    return system, cycle.scaled_system(system, FACTOR), cycle.build_system(case, mesh, stiffness_scale=FACTOR), known


def test_the_scaled_compliance_is_the_rebuilt_one(systems):
    system, scaled, rebuilt, known = systems
    # the columns carried over and those back-substituted afterwards on the old factorisation
    later = np.flatnonzero(~known)[:40]
    columns = np.concatenate([np.flatnonzero(known)[:40], later])
    scaled.compliance.ensure(columns)
    rebuilt.compliance.ensure(columns)
    assert scaled.compliance.columns_solved < rebuilt.compliance.columns_solved
    a, b = scaled.compliance.C[:, columns], rebuilt.compliance.C[:, columns]
    assert np.max(np.abs(a - b)) <= 1e-9 * np.max(np.abs(b))
    np.testing.assert_allclose(system.compliance.C[:, columns[:40]] / FACTOR, a[:, :40], rtol=0, atol=1e-12 * np.max(np.abs(b)))
    # the original cache is untouched: the later columns are still unknown there
    assert not system.compliance.known[later].any()
    assert scaled.stiffness_scale == rebuilt.stiffness_scale == FACTOR
    assert scaled.model.youngs_modulus == pytest.approx(rebuilt.model.youngs_modulus, rel=1e-15)


def test_a_solve_on_the_scaled_disc_is_the_rebuilt_discs(systems):
    _, scaled, rebuilt, _ = systems
    for theta in (0.0, 0.3):
        a = cycle.solve_angle(scaled, theta, op=OperatingPoint(T_NMM))
        b = cycle.solve_angle(rebuilt, theta, op=OperatingPoint(T_NMM))
        np.testing.assert_allclose(a.bearing_forces, b.bearing_forces, rtol=1e-8, atol=1e-6)
        np.testing.assert_allclose(a.pin_forces, b.pin_forces, rtol=1e-8, atol=1e-6)
        assert a.carrier_rotation == pytest.approx(b.carrier_rotation, rel=1e-8)
    # displacements of the same load ÷ FACTOR; stresses of the same load unchanged
    load = np.zeros(rebuilt.model.n_dofs)
    load[0], load[-1] = 1.0, -1.0
    np.testing.assert_allclose(scaled.solve(load), rebuilt.solve(load), rtol=1e-8, atol=1e-14)


def test_a_factor_that_is_not_positive_is_refused(systems):
    system = systems[0]
    for factor in (0.0, -2.0, float("nan")):
        with pytest.raises(ValueError, match="must be positive"):
            cycle.scaled_system(system, factor)
