"""Sector meshes: the first sector meshed, copied round the disc by rotation, merged along the cuts and
put back into Gmsh as discrete entities."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from rvfem.errors import MeshError
from rvfem.geometry import DiscGeometry
from rvfem.mesh.extract import SYMMETRY_GROUP, _closed_loop, _mesh_arrays
from rvfem.mesh.gmsh_model import _build_sector_model
from rvfem.mesh.session import _file_options
from rvfem.mesh.symmetry import _Cut, _rotation, _symmetry_tolerance

@dataclass(frozen=True, eq=False)
class _Assembled:
    """A mesh of the whole disc assembled from sector copies (arrays as in :class:`DiscMesh`)."""

    points: np.ndarray
    triangles: np.ndarray
    boundaries: dict
    order: int


def _replicate(geom: DiscGeometry, cut: _Cut, points: np.ndarray, triangles: np.ndarray,
               edges: dict[str, np.ndarray], cut0: np.ndarray, cut1: np.ndarray) -> _Assembled:
    """Copy the sector mesh N times by rotation and merge the copies along the cuts.

    The nodes of the second cut (``cut1``, edges) are the nodes of the first cut (``cut0``) of the
    next copy, rotated: they are dropped, and copy k keeps the sector's other nodes, rotated by
    2πk/N, in their order. So the assembled mesh lists copy after copy and the rotation by 2π/N
    maps node i onto node (i + n/N) mod n. The named boundaries of the copies are given the names
    of the geometry's features they land on.
    """
    n = cut.order
    tol = _symmetry_tolerance(geom)
    c0, c1 = np.unique(cut0), np.unique(cut1)
    if len(c0) != len(c1) or len(c0) < 2 or np.intersect1d(c0, c1).size:
        raise MeshError(f"the sector cuts have {len(c0)} and {len(c1)} nodes (want the same number, "
                        "no node shared): the periodic meshing of the cuts failed")
    dist, hit = cKDTree(points[c1]).query(points[c0] @ _rotation(2 * math.pi / n).T,
                                          distance_upper_bound=tol)
    if not np.all(np.isfinite(dist)) or len(np.unique(hit)) != len(c1):
        raise MeshError(f"the nodes of the two sector cuts do not match under the rotation by "
                        f"360°/{n} ({int(np.sum(~np.isfinite(dist)))} of {len(c0)} without a partner "
                        f"within {tol:.3g} mm)")
    keep = np.setdiff1d(np.arange(len(points)), c1)
    local = np.full(len(points), -1, dtype=np.int64)
    local[keep] = np.arange(len(keep))
    nk = len(keep)
    partner = np.empty(len(points), dtype=np.int64)
    partner[c1[hit]] = c0                       # cut1 node → the cut0 node it is the image of
    names = {name: name for name in edges}
    all_points, all_triangles = [], []
    all_edges: dict[str, list[np.ndarray]] = {}
    for k in range(n):
        index = k * nk + local
        index[c1] = ((k + 1) % n) * nk + local[partner[c1]]
        all_points.append(points[keep] @ _rotation(2 * math.pi * k / n).T)
        all_triangles.append(index[triangles])
        for name, e in edges.items():
            all_edges.setdefault(names[name], []).append(index[e])
        names = {name: cut.images.get(image, image) for name, image in names.items()}
    points = np.ascontiguousarray(np.concatenate(all_points))
    triangles = np.ascontiguousarray(np.concatenate(all_triangles))
    expected = ["profile", "central_hole"] + [f.name for f in geom.bores + geom.holes]
    if sorted(all_edges) != sorted(expected):
        raise MeshError(f"the sector copies carry the boundaries {sorted(all_edges)}, "
                        f"want {sorted(expected)}")
    pairs = cKDTree(points).query_pairs(tol)
    if pairs:
        raise MeshError(f"{len(pairs)} pairs of nodes coincide after merging the sector copies "
                        "along the cuts (the copies overlap)")
    boundaries = {name: _closed_loop(np.concatenate(all_edges[name]), points, name, "sector copies")
                  for name in expected}
    return _Assembled(points=points, triangles=triangles, boundaries=boundaries, order=n)


def _mesh_sector(g, geom: DiscGeometry, cut: _Cut) -> _Assembled:
    """Mesh the first sector in the current Gmsh model and assemble the whole disc from it."""
    surface, curves, cut0, cut1 = _build_sector_model(g, geom, cut)
    g.model.mesh.generate(2)
    points, triangles, _, edges = _mesh_arrays(g, surface, dict(curves, _cut0=[cut0], _cut1=[cut1]),
                                               "sector mesh")
    c0, c1 = edges.pop("_cut0"), edges.pop("_cut1")
    return _replicate(geom, cut, points, triangles, edges, c0, c1)


def _add_discrete(g, mesh: _Assembled) -> None:
    """Put an assembled mesh into the current (empty) Gmsh model: one discrete surface holding
    every node (tags 1…n in order) and the triangles, one discrete curve per named boundary (its
    edges in loop order), the physical groups ``disc`` and ``symmetry_<N>`` (surface) and one per
    boundary name (curve)."""
    model = g.model
    surface = model.addDiscreteEntity(2)
    n = len(mesh.points)
    xyz = np.zeros((n, 3))
    xyz[:, :2] = mesh.points
    model.mesh.addNodes(2, surface, np.arange(1, n + 1), xyz.ravel())
    model.mesh.addElementsByType(surface, 2, [], (mesh.triangles + 1).ravel())
    for name, edges in mesh.boundaries.items():
        curve = model.addDiscreteEntity(1)
        model.mesh.addElementsByType(curve, 1, [], (edges + 1).ravel())
        model.addPhysicalGroup(1, [curve], name=name)
    model.addPhysicalGroup(2, [surface], name="disc")
    model.addPhysicalGroup(2, [surface], name=f"{SYMMETRY_GROUP}{mesh.order}")
    _file_options(g)
