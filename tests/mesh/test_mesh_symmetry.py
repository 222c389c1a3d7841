"""Symmetric meshes: one 360°/N sector copied by rotation (exactly symmetric, conforming), the
symmetry decision, the node permutation of the rotation and the cache round trip.

Coarse meshes of the shipped fan-hole and solid RV-40E discs (three cranks, 39 teeth).
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np
import pytest
from conftest import coarse_case

from rvfem.errors import MeshError
from rvfem.geometry import disc_geometry
from rvfem.mesh import (
    mesh_case,
    mesh_key,
    read_msh,
    rotation_permutation,
    symmetry_order,
)

DISCS = ("rv40e_fanholes", "rv40e_solid")


def with_mesh(case, **changes):
    return case.replace(mesh=dataclasses.replace(case.mesh, **changes))


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


@pytest.fixture(scope="module")
def meshes(cache):
    """name → (case, symmetric mesh, mesh of the whole disc)."""
    out = {}
    for name in DISCS:
        case = coarse_case(name)
        out[name] = (case, mesh_case(case, cache), mesh_case(with_mesh(case, symmetric=False), cache))
    return out


def rotate(xy, order):
    a = 2 * math.pi / order
    return xy @ np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]]).T


def image_name(name, counts):
    """Name of the boundary a rotation by 360°/N maps ``name`` onto: bore_i → bore_{i+1} …"""
    if name in ("profile", "central_hole"):
        return name
    kind, i = name.rsplit("_", 1)
    return f"{kind}_{(int(i) + 1) % counts[kind]}"


def test_symmetry_order_is_decided_on_the_geometry():
    for name in DISCS:
        assert symmetry_order(disc_geometry(coarse_case(name))) == 3
    solid = coarse_case("rv40e_solid")
    assert symmetry_order(disc_geometry(with_mesh(solid, symmetric=False))) == 1
    pitch = coarse_case("rv40e_solid", cycloid={"pitch_error": {"amplitude": 0.005}})
    assert symmetry_order(disc_geometry(pitch)) == 1
    unequal = coarse_case("rv40e_solid", cranks={"angles_deg": [90.0, 210.0, 331.0]})
    assert symmetry_order(disc_geometry(unequal)) == 1
    teeth = coarse_case("rv40e_solid", cycloid={"teeth": 40}, pins={"count": 41})   # 40 % 3 ≠ 0
    assert symmetry_order(disc_geometry(teeth)) == 1
    two = coarse_case("rv40e_solid", cycloid={"teeth": 40}, pins={"count": 41},
                      cranks={"count": 2, "angles_deg": [90.0, 270.0]})
    assert symmetry_order(disc_geometry(two)) == 2
    # the fan holes follow the cranks, so turning them breaks the symmetry only if they no longer
    # repeat: equally spaced holes at another offset keep it
    fan = coarse_case("rv40e_fanholes", fan_holes={"angle_offset_deg": 40.0})
    assert symmetry_order(disc_geometry(fan)) == 3


@pytest.mark.parametrize("name", DISCS)
def test_symmetric_mesh_maps_onto_itself(meshes, name):
    _, m, _ = meshes[name]
    assert m.symmetry == 3
    n = m.n_nodes
    perm = rotation_permutation(m.points, 3)
    assert np.array_equal(perm, (np.arange(n) + n // 3) % n)        # copy after copy
    assert np.max(np.linalg.norm(rotate(m.points, 3) - m.points[perm], axis=1)) < 1e-9   # measured 5e-14 mm
    tris = {tuple(np.roll(t, -int(np.argmin(t)))) for t in perm[m.triangles].tolist()}
    assert tris == {tuple(np.roll(t, -int(np.argmin(t)))) for t in m.triangles.tolist()}
    counts = {k: sum(1 for b in m.boundaries if b.startswith(k + "_")) for k in ("bore", "hole")}
    for b, edges in m.boundaries.items():
        # directed edges: the rotation keeps the orientation of every loop
        assert {tuple(e) for e in perm[edges].tolist()} == \
            {tuple(e) for e in m.boundaries[image_name(b, counts)].tolist()}, b


@pytest.mark.parametrize("name", DISCS)
def test_symmetric_mesh_is_conforming(meshes, name):
    _, m, _ = meshes[name]
    t = m.triangles
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    assert count.max() == 2                                   # no edge shared by three triangles
    free = {tuple(x) for x in uniq[count == 1]}
    named = {tuple(sorted(x)) for edges in m.boundaries.values() for x in edges.tolist()}
    assert free == named                                      # the seams along the cuts are closed
    holes = len(m.boundaries) - 1
    assert m.n_nodes - len(uniq) + m.n_elements == 1 - holes  # Euler characteristic of the disc
    assert np.array_equal(np.unique(t), np.arange(m.n_nodes))
    a, b = m.points[t[:, 1]] - m.points[t[:, 0]], m.points[t[:, 2]] - m.points[t[:, 0]]
    assert np.all(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0] > 0)  # counter-clockwise
    assert m.min_quality > 0.6                                # measured 0.673 (fan holes), 0.719 (solid)


@pytest.mark.parametrize("name", DISCS)
def test_symmetric_and_whole_disc_meshes_agree(meshes, name):
    case, m, full = meshes[name]
    assert full.symmetry == 1 and full.path != m.path
    # measured 5.8e-7 (fan holes: 153 rather than 151 edges on the central hole), 0 (solid: 63
    # edges on the central hole either way, and a regular polygon's area does not depend on its phase)
    assert m.area == pytest.approx(full.area, rel=2e-6)
    assert m.n_nodes == pytest.approx(full.n_nodes, rel=0.02)
    assert set(m.boundaries) == set(full.boundaries)
    # every named boundary lies on the feature of that name (bore_i on the bore of crank i)
    geom = disc_geometry(case)
    for f in geom.features:
        xy = m.points[m.boundary_nodes(f.name)]
        assert np.max(np.abs(f.signed_distance(xy))) < 1e-12, f.name   # measured 7e-14 mm


def test_cache_round_trip_keeps_the_arrays_and_the_symmetry(meshes, cache):
    case, m, _ = meshes["rv40e_fanholes"]
    back = read_msh(m.path)
    assert back.symmetry == 3 and back.from_cache
    assert np.array_equal(back.points, m.points) and np.array_equal(back.triangles, m.triangles)
    assert back.boundaries.keys() == m.boundaries.keys()
    for name, edges in m.boundaries.items():
        assert np.array_equal(back.boundaries[name], edges), name
    assert back.min_quality == m.min_quality
    hit = mesh_case(case, cache)
    assert hit.from_cache and hit.symmetry == 3 and hit.path == m.path
    assert mesh_key(with_mesh(case, symmetric=False)) != mesh_key(case)


def test_rotation_permutation(meshes):
    _, _, full = meshes["rv40e_solid"]
    assert np.array_equal(rotation_permutation(full.points, 1), np.arange(full.n_nodes))
    with pytest.raises(MeshError, match="not 3-fold symmetric"):
        rotation_permutation(full.points, 3)                  # a free mesh of the whole disc
    a = 2 * np.pi * np.arange(6) / 6
    ring = np.stack([np.cos(a), np.sin(a)], axis=1)[[3, 0, 4, 1, 5, 2]]
    perm = rotation_permutation(ring, 3)                      # +120°: angle index k → k + 2
    np.testing.assert_allclose(ring[perm], rotate(ring, 3), atol=1e-15)
    assert sorted(perm.tolist()) == list(range(6))


def test_a_cut_too_close_to_a_hole_meshes_the_whole_disc(tmp_path, caplog):
    """The only cut of the fan-hole disc that clears the holes passes 1.33 mm from a fillet: 2.7
    element sizes of 0.5 mm, but only 1.3 of 1 mm. Then the whole disc is meshed, and the log says
    why."""
    case = with_mesh(coarse_case("rv40e_fanholes"), size_hole=1.0, size_flank=0.8, size_bore=0.8)
    assert symmetry_order(disc_geometry(case)) == 3
    with caplog.at_level(logging.INFO, logger="rvfem.mesh"):
        m = mesh_case(case, tmp_path)
    assert m.symmetry == 1
    assert "meshing the whole disc" in caplog.text and "1.33 mm" in caplog.text
