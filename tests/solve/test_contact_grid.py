"""The contact grid independent of the mesh (``mesh.contact_grid_flank`` / ``contact_grid_bore``,
docs/theory.md § 6): its columns, its symmetry, its loads under mesh refinement, its checks."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import CaseText, coarse_case

from rvfem.case.definition import case_from_dict, case_to_dict, load_case
from rvfem.errors import CaseError
from rvfem.mesh import mesh_case
from rvfem.solve import contact, cycle

THETA = np.radians(np.arange(0.0, 360.0, 10.0))


def _refined(case, factor: float, grid: tuple[float, float] | None):
    """The case with its flank, bore and interior sizes × ``factor``, and the contact grid fixed at
    ``grid`` (flank, bore spacing, mm) when given."""
    data = case_to_dict(case)
    for key in ("size_flank", "size_bore", "size_interior"):
        data["mesh"][key] *= factor
    if grid is not None:
        data["mesh"].update(contact_grid_flank=grid[0], contact_grid_bore=grid[1])
    return case_from_dict(data, source=f"{case.source} × {factor:g}")


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


@pytest.fixture(scope="module")
def fixed_grid_systems(meshes):
    """The coarse fan-hole disc at two mesh sizes (× 1 and × 0.6) with the contact grid of the
    coarse one fixed (0.6 mm), and the × 0.6 one with its own vertex grid."""
    base = coarse_case("rv40e_fanholes")
    out = {}
    for label, factor, grid in (("coarse", 1.0, (0.6, 0.6)), ("fine", 0.6, (0.6, 0.6)), ("fine_vertex", 0.6, None)):
        case = _refined(base, factor, grid)
        out[label] = cycle.build_system(case, mesh_case(case, meshes))
    return out


def _bearing_extremes(system) -> np.ndarray:
    result = cycle.load_cycle(system, THETA, saved_angles_deg=())
    F = np.linalg.norm(np.asarray(result.bearing_forces), axis=-1)
    return np.array([F.max(), F.min()])


def test_a_fixed_grid_has_the_same_columns_on_every_mesh(fixed_grid_systems):
    """The column count follows the spacing, not the mesh: the × 0.6 mesh keeps the coarse
    mesh's count (to the rounding of a loop whose polygon grows a little longer as it is refined),
    a multiple of the mesh's 3-fold symmetry, while its vertex grid grows with the mesh."""
    coarse, fine, vertex = (fixed_grid_systems[k] for k in ("coarse", "fine", "fine_vertex"))
    assert abs(coarse.interface.n_columns - fine.interface.n_columns) <= 0.01 * coarse.interface.n_columns
    assert vertex.interface.n_columns > 1.4 * fine.interface.n_columns
    for grid in fine.interface.grids.values():
        assert grid.count % 3 == 0
        steps = np.diff(grid.arcs)
        assert np.ptp(steps) < 1e-9 * steps.mean()                 # equal arc-length steps
        assert abs(steps.mean() - 0.6) < 0.3                        # about the spacing asked


def test_a_fixed_grid_keeps_the_rotation_symmetry(fixed_grid_systems):
    """Grid points at equal arc-length steps of an N-fold symmetric loop turn into each other:
    the columns of the other sectors are rotated copies, equal to back-substituted ones."""
    s = fixed_grid_systems["fine"]
    assert s.symmetry == 3 and s.compliance.symmetric
    direct = contact.Compliance(s.solve, s.interface.B, rigid_modes=s.rigid_modes,
                                vertex_dofs=s.model.node_dofs[:s.model.n_vertices].ravel())
    cols = np.random.default_rng(2).choice(s.interface.n_columns, 40, replace=False)
    s.compliance.ensure(cols)
    direct.ensure(cols)
    scale = np.abs(direct.C[:, cols]).max()
    assert np.abs(s.compliance.C[:, cols] - direct.C[:, cols]).max() <= 1e-9 * scale


def test_a_fixed_grid_footprint_carries_a_unit_force(fixed_grid_systems):
    """Each column is a unit force in its direction (the force part of Bᵀ·R), also where the grid
    point lies inside an element edge and its footprint spans several edges."""
    iface = fixed_grid_systems["fine"].interface
    assert np.allclose(iface.resultants[:, :2], iface.directions, rtol=0.0, atol=1e-12)


def test_with_the_contact_grid_fixed_the_bearing_loads_converge_under_refinement(fixed_grid_systems):
    """Refining the mesh under a fixed contact grid moves only the FE discretisation: the largest
    and smallest bearing loads of the cycle (36 angles) of the × 0.6 mesh agree with the coarse
    mesh's within 0.5 %, and with the × 0.6 mesh's own vertex grid (narrower footprints) within
    0.5 % as well."""
    coarse, fine, vertex = (_bearing_extremes(fixed_grid_systems[k]) for k in ("coarse", "fine", "fine_vertex"))
    assert np.abs(fine / coarse - 1.0).max() < 5e-3
    assert np.abs(fine / vertex - 1.0).max() < 5e-3


@pytest.mark.parametrize("key, words", [("contact_grid_flank", "too coarse for the teeth"),
                                         ("contact_grid_bore", "too coarse for the bores")])
def test_a_contact_grid_too_coarse_is_refused_by_its_key(key, words, tmp_path):
    path = CaseText.shipped("rv40e_fanholes").set("mesh", key, "20.0").write(tmp_path)
    with pytest.raises(CaseError, match=rf"mesh\.{key}.*{words}"):
        load_case(path)


def test_the_default_grid_is_the_vertex_grid(fixed_grid_systems):
    """Without the keys the columns sit at the boundary vertices (the contact model of earlier
    versions, unchanged)."""
    s = fixed_grid_systems["fine_vertex"]
    assert s.case.mesh.contact_grid_flank is None and s.case.mesh.contact_grid_bore is None
    for grid in s.interface.grids.values():
        assert np.array_equal(grid.arcs[:-1], grid.chain.s[:-1])
