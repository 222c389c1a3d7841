"""The ``.vtu`` writer (:mod:`rvfem.outputs.vtkio`) on a small synthetic disc.

At meshio's zlib level and strategy the files are meshio's, byte for byte (but for meshio's comment
line); at the writer's own they read back with exactly the same arrays. The mesh encoded once
(``vtu_mesh``) gives the same files as the mesh encoded per file.
"""

from __future__ import annotations

import zlib
from types import SimpleNamespace

import meshio
import numpy as np
import pytest
from conftest import structured_annulus

from rvfem.outputs import vtkio


def _disc(n_r=5, n_t=40, r_in=8.0, r_out=30.0):
    points, triangles, _ = structured_annulus(r_in=r_in, r_out=r_out, n_r=n_r, n_t=n_t)
    return points, triangles


def _state(rng, n):
    sxx, syy, sxy = rng.normal(size=(3, n)) * 50.0
    s1, s2 = rng.normal(size=(2, n)) * 40.0
    return SimpleNamespace(sxx=sxx, syy=syy, sxy=sxy, von_mises=np.abs(rng.normal(size=n)) * 90.0, s1=s1, s2=s2,
                           angle1=rng.uniform(-np.pi, np.pi, n))


@pytest.fixture(scope="module")
def disc():
    rng = np.random.default_rng(7)
    points, triangles = _disc()
    snapshot = SimpleNamespace(displacement=rng.normal(size=points.shape) * 1e-3,
                               deformation=rng.normal(size=points.shape) * 1e-4,
                               stress=SimpleNamespace(nodal=_state(rng, len(points)),
                                                      element=_state(rng, len(triangles))))
    return points, triangles, snapshot


def _meshio_file(path, points, triangles, snapshot):
    """The file as meshio writes it (the writer before :mod:`rvfem.outputs.vtkio` had its own)."""
    nodal, element = snapshot.stress.nodal, snapshot.stress.element
    names = ("sxx", "syy", "sxy", "von_mises", "s1", "s2")
    xyz = lambda a: np.column_stack([a, np.zeros(len(a))])  # noqa: E731
    point_data = {"displacement_mm": xyz(snapshot.displacement), "deformation_mm": xyz(snapshot.deformation),
                  **{f"{k}_MPa": getattr(nodal, k) for k in names},
                  "s1_direction": np.column_stack([np.cos(nodal.angle1), np.sin(nodal.angle1),
                                                   np.zeros(len(points))])}
    cell_data = {f"{k}_MPa": [getattr(element, k)] for k in names}
    meshio.write(path, meshio.Mesh(xyz(points), [("triangle", triangles.astype(np.int64))], point_data=point_data,
                                   cell_data=cell_data), file_format="vtu", binary=True, compression="zlib")
    return path


def _lines(path):
    return [line for line in path.read_text().splitlines() if not line.startswith("<!--")]


def test_at_meshio_level_the_file_is_meshio_s(disc, tmp_path):
    points, triangles, snapshot = disc
    ours = vtkio.write_vtu(tmp_path / "ours.vtu", points, triangles, snapshot, level=6,
                           strategy=zlib.Z_DEFAULT_STRATEGY)
    theirs = _meshio_file(tmp_path / "theirs.vtu", points, triangles, snapshot)
    assert _lines(ours) == _lines(theirs)


def test_the_arrays_read_back_exactly(disc, tmp_path):
    points, triangles, snapshot = disc
    path = vtkio.write_vtu(tmp_path / "a.vtu", points, triangles, snapshot)
    ref = meshio.read(_meshio_file(tmp_path / "ref.vtu", points, triangles, snapshot))
    got = meshio.read(path)
    np.testing.assert_array_equal(got.points, ref.points)
    np.testing.assert_array_equal(got.cells[0].data, triangles)
    assert list(got.point_data) == list(vtkio.POINT_FIELDS) and list(got.cell_data) == list(vtkio.CELL_FIELDS)
    for name, values in ref.point_data.items():
        np.testing.assert_array_equal(got.point_data[name], values)
    for name, values in ref.cell_data.items():
        np.testing.assert_array_equal(got.cell_data[name][0], values[0])


def test_a_shared_mesh_gives_the_same_files(disc, tmp_path):
    points, triangles, snapshot = disc
    mesh = vtkio.vtu_mesh(points, triangles)
    shared = vtkio.write_vtu(tmp_path / "shared.vtu", points, triangles, snapshot, mesh=mesh)
    alone = vtkio.write_vtu(tmp_path / "alone.vtu", points, triangles, snapshot)
    assert shared.read_bytes() == alone.read_bytes()
    vm, theta = snapshot.stress.nodal.von_mises, snapshot.stress.nodal.angle1
    env = vtkio.write_envelope_vtu(tmp_path / "env.vtu", points, triangles, vm, theta, mesh=mesh)
    assert env.read_bytes() == vtkio.write_envelope_vtu(tmp_path / "env2.vtu", points, triangles, vm, theta).read_bytes()
    back = meshio.read(env)
    np.testing.assert_array_equal(back.point_data["von_mises_envelope_P1_MPa"], vm)
    np.testing.assert_array_equal(back.point_data["envelope_theta_deg"], np.round(np.degrees(theta), vtkio.ANGLE_DECIMALS))


def test_envelope_angles_carry_no_float_noise(disc, tmp_path):
    """Angles computed from radians are rounded: 255°, not 255.00000000000003°."""
    points, triangles, snapshot = disc
    theta = np.full(len(points), np.radians(255.0))
    assert np.degrees(theta[0]) != 255.0                   # the noise this removes
    env = vtkio.write_envelope_vtu(tmp_path / "env.vtu", points, triangles, snapshot.stress.nodal.von_mises, theta)
    assert np.all(meshio.read(env).point_data["envelope_theta_deg"] == 255.0)


def test_a_long_array_spans_several_blocks(tmp_path):
    # more than one 32 KiB block per array, the last one partly filled
    points, triangles = _disc(n_r=30, n_t=200)
    vm = np.linspace(0.0, 1.0, len(points)) ** 3
    path = vtkio.write_envelope_vtu(tmp_path / "big.vtu", points, triangles, vm, vm)
    back = meshio.read(path)
    np.testing.assert_array_equal(back.points[:, :2], points)
    np.testing.assert_array_equal(back.cells[0].data, triangles)
    np.testing.assert_array_equal(back.point_data["von_mises_envelope_P1_MPa"], vm)


def test_the_envelope_says_its_element_order_and_the_headline_peak(disc, tmp_path):
    """The envelope is the cycle's (P1) field while the headline structural peak is re-solved on
    P2: the array name carries the element order, the field data the headline value and its order."""
    points, triangles, snapshot = disc
    vm, theta = snapshot.stress.nodal.von_mises, snapshot.stress.nodal.angle1
    path = vtkio.write_envelope_vtu(tmp_path / "env.vtu", points, triangles, vm, theta, element_order=1,
                                    structural_peak_MPa=110.25, structural_peak_order=2)
    back = meshio.read(path)
    assert list(back.point_data) == [vtkio.envelope_field(1), "envelope_theta_deg"]
    assert vtkio.envelope_field(1) == "von_mises_envelope_P1_MPa"
    np.testing.assert_array_equal(back.point_data["von_mises_envelope_P1_MPa"], vm)
    assert back.field_data["element_order"].tolist() == [1]
    assert back.field_data["structural_peak_von_mises_MPa"].tolist() == [110.25]
    assert back.field_data["structural_peak_element_order"].tolist() == [2]
    p2 = meshio.read(vtkio.write_envelope_vtu(tmp_path / "p2.vtu", points, triangles, vm, theta, element_order=2))
    assert list(p2.point_data) == ["von_mises_envelope_P2_MPa", "envelope_theta_deg"]
    assert p2.field_data["element_order"].tolist() == [2] and "structural_peak_von_mises_MPa" not in p2.field_data
