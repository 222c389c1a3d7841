"""Reading the mesh out of Gmsh: the nodes, the counter-clockwise triangles, the named boundaries as
closed loops, the symmetry a file records and the element quality."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rvfem._arrays import chain_edges
from rvfem.errors import MeshError
from rvfem.mesh.disc_mesh import QUALITY_MEASURE, DiscMesh
from rvfem.mesh.symmetry import rotation_permutation

SYMMETRY_GROUP = "symmetry_"
"""Prefix of the surface physical group that records the symmetry order N in a mesh file
(``symmetry_3``); absent in a mesh of the whole disc."""


def _closed_loop(edges: np.ndarray, points: np.ndarray, name: str, where: str) -> np.ndarray:
    """The edges of one named boundary as one closed loop: ``(k, 2)`` node pairs in order along
    the curve, starting at its smallest node index, the disc on the left (``profile``
    counter-clockwise, every other boundary clockwise)."""
    try:
        chains = chain_edges(edges)
    except MeshError as exc:
        raise MeshError(f"{where}: boundary {name!r}: {exc}") from None
    if len(chains) != 1 or not chains[0][1] or len(chains[0][0]) - 1 != len(edges):
        raise MeshError(f"boundary {name!r} is not one closed loop ({len(chains)} pieces, "
                        f"{sum(len(c) - 1 for c, _ in chains)} of {len(edges)} edges in order)")
    loop = chains[0][0][:-1]                    # starts at the smallest node index
    xy = points[loop]
    signed = 0.5 * np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1])
    if (signed < 0) == (name == "profile"):     # profile CCW, holes CW (disc on the left)
        loop = np.concatenate([loop[:1], loop[:0:-1]])
    return np.ascontiguousarray(np.stack([loop, np.roll(loop, -1)], axis=1))


def _mesh_arrays(g, surface: int, curves: dict[str, list[int]], where) -> tuple:
    """Points, counter-clockwise triangles (only the nodes they use, renumbered 0…n−1 in Gmsh's
    node order), triangle element tags and name → edges (unordered) of the given curves, read
    from the current Gmsh model."""
    tri_tags: list[np.ndarray] = []
    tri_nodes: list[np.ndarray] = []
    types, etags, enodes = g.model.mesh.getElements(2, int(surface))
    for t, et, en in zip(types, etags, enodes):
        if t != 2:
            raise MeshError(f"{where}: unexpected element type {t} in the disc (want 3-node triangles)")
        tri_tags.append(et)
        tri_nodes.append(en)
    if not tri_tags:
        raise MeshError(f"{where}: the disc has no triangles")
    tri_tag_array = np.concatenate(tri_tags)
    tri = np.concatenate(tri_nodes).astype(np.int64).reshape(-1, 3)

    node_tags, coords, _ = g.model.mesh.getNodes()
    node_tags = node_tags.astype(np.int64)
    xyz = coords.reshape(-1, 3)
    used = np.unique(tri)
    # remap Gmsh's non-contiguous node tags to 0..n-1 (only nodes used by triangles)
    lookup = np.full(int(max(node_tags.max(), used.max())) + 1, -1, dtype=np.int64)
    lookup[node_tags] = np.arange(len(node_tags))
    if np.any(lookup[used] < 0):
        raise MeshError(f"{where}: triangles reference unknown nodes")
    index = np.full(len(lookup), -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    points = np.ascontiguousarray(xyz[lookup[used], :2], dtype=np.float64)
    triangles = index[tri]
    p = points[triangles]
    area2 = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) \
        - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    flip = area2 < 0
    triangles[flip] = triangles[flip][:, [0, 2, 1]]
    triangles = np.ascontiguousarray(triangles)

    edges = {}
    for name, tags in curves.items():
        parts: list[np.ndarray] = []
        for ent in tags:
            types, _, enodes = g.model.mesh.getElements(1, int(ent))
            for t, en in zip(types, enodes):
                if t != 1:
                    raise MeshError(f"{where}: unexpected element type {t} on {name!r}")
                parts.append(en.astype(np.int64).reshape(-1, 2))
        e = np.concatenate(parts) if parts else np.empty((0, 2), dtype=np.int64)
        if e.size and (e.max() >= len(index) or np.any(index[e] < 0)):
            raise MeshError(f"{where}: boundary {name!r} has nodes that belong to no triangle")
        edges[name] = index[e]
    return points, triangles, tri_tag_array, edges


def _extract(g, path: Path, from_cache: bool) -> DiscMesh:
    """Arrays of the current Gmsh model's mesh (physical groups only)."""
    names = {}
    for dim, tag in g.model.getPhysicalGroups():
        names[(dim, g.model.getPhysicalName(dim, tag))] = tag
    if (2, "disc") not in names:
        raise MeshError(f"{path}: no physical surface 'disc'")
    surfaces = g.model.getEntitiesForPhysicalGroup(2, names[(2, "disc")])
    if len(surfaces) != 1:
        raise MeshError(f"{path}: the physical surface 'disc' has {len(surfaces)} entities (want 1)")
    curves = {name: [int(c) for c in g.model.getEntitiesForPhysicalGroup(1, tag)]
              for (dim, name), tag in sorted(names.items(), key=lambda kv: kv[1]) if dim == 1}
    points, triangles, tri_tags, edges = _mesh_arrays(g, int(surfaces[0]), curves, path)
    boundaries = {name: _closed_loop(e, points, name, str(path)) for name, e in edges.items()}

    orders = [int(name[len(SYMMETRY_GROUP):]) for dim, name in names
              if dim == 2 and name.startswith(SYMMETRY_GROUP) and name[len(SYMMETRY_GROUP):].isdigit()]
    if len(orders) > 1:
        raise MeshError(f"{path}: several symmetry groups {sorted(orders)}")
    symmetry = orders[0] if orders else 1
    if symmetry > 1:
        rotation_permutation(points, symmetry)      # the file's claim holds (raises otherwise)

    q = g.model.mesh.getElementQualities(tri_tags, QUALITY_MEASURE)
    return DiscMesh(points=points, triangles=triangles, boundaries=boundaries, path=Path(path),
                    min_quality=float(np.min(q)), from_cache=from_cache, symmetry=symmetry)
