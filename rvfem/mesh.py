"""Meshing the disc with Gmsh (OpenCASCADE kernel), caching and previews.

The disc is one plane surface: the outer curve loop is the cycloid profile (one interpolating
spline per tooth space, :attr:`~rvfem.geometry.Profile.spline_points`), the inner loops are the
central hole, the crank-bearing bores and the lightening holes. Because :func:`~rvfem.geometry.
disc_geometry` has already proved that no two features touch, the surface is built directly with
holes (``occ.addPlaneSurface`` with several curve loops) — no boolean operations, so the curve tags
we create are the tags we group, and nothing has to be re-identified afterwards.

Mesh: linear triangles (the FE stage builds P2 on top), Frontal-Delaunay, sizes from a background
field only (``Mesh.MeshSizeExtendFromBoundary = 0``, ``Mesh.MeshSizeFromPoints = 0``,
``Mesh.MeshSizeFromCurvature = 0``): ``size_flank`` on the profile, ``size_bore`` on the bores,
``size_hole`` (default ``HOLE_SIZE_FACTOR·size_bore``, capped by ``size_interior``) on the central
hole and the lightening holes, each held over a band and then growing linearly (``SIZE_GROWTH`` mm per mm) to
``size_interior``.

Physical groups: curves ``profile``, ``central_hole``, ``bore_0`` …, ``hole_0`` … (fan holes
first, then round holes) and the surface ``disc``.

Cache: the ``.msh`` is written to ``cache_dir/<case name>-<key>.msh`` where ``key`` hashes only the
inputs that shape the mesh (profile and feature geometry, mesh sizes, the mesher version); loads,
material, thickness and analysis options do not invalidate it. A cached file is read back through
Gmsh, so a cache hit returns exactly the arrays a fresh mesh would. Files appear atomically (a
unique temporary file in the cache folder, then :func:`os.replace`), so processes that build the
same mesh at the same time never see or leave a partial file.

Gmsh's global state is only ever touched inside :func:`gmsh_session`.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import gmsh
import numpy as np

from ._arrays import chain_edges
from .case import Case, case_to_dict
from .errors import MeshError
from .geometry import SPLINE_POINTS_PER_SEGMENT, Arc, DiscGeometry, Feature, LineSegment, disc_geometry

__all__ = [
    "DiscMesh",
    "gmsh_session",
    "mesh_key",
    "mesh_path",
    "mesh_case",
    "mesh_geometry",
    "read_msh",
    "mesh_preview_png",
    "QUALITY_MEASURE",
]

MESHER_VERSION = 1
"""Bumped whenever a change here changes the mesh for the same inputs (invalidates caches)."""

QUALITY_MEASURE = "minSICN"
"""Gmsh's element quality reported as :attr:`DiscMesh.min_quality`: the minimal signed inverse
condition number (1 for an equilateral triangle, 0 for a degenerate one, < 0 inverted)."""

SIZE_GROWTH = 0.25
"""Growth of the target element size away from a refined curve, mm per mm."""

HOLE_SIZE_FACTOR = 2.0
"""Element size on the central hole and the lightening holes, as a multiple of ``size_bore``."""

BAND_FACTOR = 2.0
"""Width of the band held at the fine size next to a refined curve, in elements."""


# ------------------------------------------------------------------------------------------------
# The mesh
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class DiscMesh:
    """A linear triangle mesh of the disc.

    Attributes
    ----------
    points : ndarray (n, 2) float64, C-contiguous
        Node coordinates, mm (disc frame).
    triangles : ndarray (m, 3) int64, C-contiguous
        Node indices, counter-clockwise.
    boundaries : dict[str, ndarray (k, 2)]
        Boundary name → edges (node index pairs) ordered along the closed curve so that
        ``edges[i, 1] == edges[i + 1, 0]`` and the last edge ends where the first starts. The
        disc lies on the left of every loop: the profile runs counter-clockwise, the holes
        clockwise.
    path : Path
        The ``.msh`` file (Gmsh 4.1 format).
    min_quality : float
        Smallest element quality, measured as :data:`quality_measure`.
    quality_measure : str
        ``"minSICN"`` (Gmsh's minimal signed inverse condition number).
    from_cache : bool
        True if the mesh was read from an existing file rather than generated.
    """

    points: np.ndarray = field(repr=False)
    triangles: np.ndarray = field(repr=False)
    boundaries: dict = field(repr=False)
    path: Path
    min_quality: float
    quality_measure: str = QUALITY_MEASURE
    from_cache: bool = False

    @property
    def n_nodes(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.triangles.shape[0])

    @property
    def area(self) -> float:
        """Sum of the triangle areas, mm²."""
        p = self.points[self.triangles]
        a = p[:, 1] - p[:, 0]
        b = p[:, 2] - p[:, 0]
        return float(0.5 * np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]))

    def boundary_nodes(self, name: str) -> np.ndarray:
        """Node indices of a named boundary in order along the curve (each node once)."""
        try:
            return self.boundaries[name][:, 0].copy()
        except KeyError:
            raise MeshError(f"no boundary named {name!r}; the mesh has {sorted(self.boundaries)}") from None


# ------------------------------------------------------------------------------------------------
# Gmsh session
# ------------------------------------------------------------------------------------------------


@contextlib.contextmanager
def gmsh_session(model: str = "disc"):
    """The only place where Gmsh is initialised: yields the ``gmsh`` module with a fresh model.

    Gmsh prints nothing (``General.Terminal = 0``); its messages are collected by its logger and
    appended to any :class:`~rvfem.errors.MeshError` raised inside the block. Gmsh is always
    finalised on leaving, also on errors. Sessions cannot nest (Gmsh has one global state).
    """
    if gmsh.isInitialized():
        raise MeshError("a Gmsh session is already open; Gmsh sessions cannot nest")
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.logger.start()
        gmsh.model.add(model)
        try:
            yield gmsh
        except MeshError:
            raise
        except Exception as exc:  # Gmsh raises plain Exceptions
            log = [m for m in gmsh.logger.get() if m.startswith(("Error", "Warning"))][-5:]
            raise MeshError(f"Gmsh failed: {exc}" + ("\n  " + "\n  ".join(log) if log else "")) from exc
    finally:
        try:
            gmsh.logger.stop()
        finally:
            gmsh.finalize()


# ------------------------------------------------------------------------------------------------
# Cache key
# ------------------------------------------------------------------------------------------------


def mesh_key(case: Case) -> str:
    """sha256 (hex) of the inputs that shape the mesh.

    Included: cycloid teeth, eccentricity, central hole, modifications and pitch errors; pin count,
    pin-circle radius and pin radius; cranks; the bore radius; fan and round holes; the three mesh
    sizes; :data:`MESHER_VERSION`, the number of spline points per tooth space and the Gmsh version. Not included: thickness, material, loads,
    analysis options, bearing data other than the bore radius, ``mesh.min_wall`` (a check, not a
    shape) and the case name.
    """
    d = case_to_dict(case)
    cyc = {k: v for k, v in d["cycloid"].items() if k != "thickness"}
    shaping = {
        "cycloid": cyc,
        "pins": {k: d["pins"][k] for k in ("count", "circle_radius", "radius")},
        "cranks": d["cranks"],
        "bore_radius": d["crank_bearing"]["bore_radius"],
        "fan_holes": d.get("fan_holes"),
        "round_holes": d.get("round_holes"),
        "mesh": {k: d["mesh"].get(k) for k in ("size_flank", "size_bore", "size_interior", "size_hole")},
        "mesher": MESHER_VERSION,
        "spline_points": SPLINE_POINTS_PER_SEGMENT,
        "gmsh": gmsh.__version__,
    }
    return hashlib.sha256(json.dumps(shaping, sort_keys=True).encode()).hexdigest()


def mesh_path(case: Case, cache_dir: str | os.PathLike = "meshes") -> Path:
    """Where the mesh of ``case`` is cached: ``cache_dir/<name>-<first 12 hex of key>.msh``."""
    safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in case.name)
    return Path(cache_dir) / f"{safe}-{mesh_key(case)[:12]}.msh"


# ------------------------------------------------------------------------------------------------
# Building the Gmsh model
# ------------------------------------------------------------------------------------------------


def _add_point(g, xy) -> int:
    return g.model.occ.addPoint(float(xy[0]), float(xy[1]), 0.0)


def _add_outline(g, feature: Feature) -> list[int]:
    """Curves of one hole outline (:meth:`~rvfem.geometry.Feature.outline`); returns the curve tags
    in order. A full circle becomes one OCC circle; otherwise consecutive primitives share their
    end points, and arcs are split into pieces below 135° (OCC arcs must be below π)."""
    occ = g.model.occ
    prims = feature.outline()
    if len(prims) == 1 and isinstance(prims[0], Arc) and prims[0].sweep >= 2 * math.pi:
        c = prims[0]
        return [occ.addCircle(c.centre[0], c.centre[1], 0.0, c.radius,
                              angle1=c.start_angle, angle2=c.start_angle + c.sweep)]
    # shared end points: the start of every primitive (closed loop)
    starts = [_add_point(g, p.start) for p in prims]
    tags = []
    for i, p in enumerate(prims):
        a, b = starts[i], starts[(i + 1) % len(prims)]
        if isinstance(p, LineSegment):
            tags.append(occ.addLine(a, b))
        elif isinstance(p, Arc):
            n = max(1, int(math.ceil(abs(p.sweep) / (0.75 * math.pi))))  # arcs below π
            c = _add_point(g, p.centre)
            prev = a
            for k in range(1, n + 1):
                nxt = b if k == n else _add_point(g, p.point(p.start_angle + p.sweep * k / n))
                tags.append(occ.addCircleArc(prev, c, nxt))
                prev = nxt
        else:
            raise MeshError(f"{feature.name}: cannot mesh an outline piece of type {type(p).__name__}")
    return tags


def _polyline_length(xy: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1)))


def _threshold(g, curves: list[int], size: float, size_max: float, sampling: int) -> int:
    f = g.model.mesh.field
    dist = f.add("Distance")
    f.setNumbers(dist, "CurvesList", curves)
    f.setNumber(dist, "Sampling", sampling)
    th = f.add("Threshold")
    f.setNumber(th, "InField", dist)
    f.setNumber(th, "SizeMin", size)
    f.setNumber(th, "SizeMax", size_max)
    band = BAND_FACTOR * size
    f.setNumber(th, "DistMin", band)
    f.setNumber(th, "DistMax", band + max(size_max - size, 0.0) / SIZE_GROWTH)
    return th


def _build_model(g, geom: DiscGeometry) -> dict[str, list[int]]:
    """Create the OCC geometry, physical groups and size fields; return name → curve tags."""
    occ = g.model.occ
    prof = geom.profile
    spl = prof.spline_points
    zc = spl.shape[0]
    tips = [_add_point(g, spl[j, 0]) for j in range(zc)]
    profile_curves = []
    for j in range(zc):
        inner = [_add_point(g, xy) for xy in spl[j, 1:-1]]
        profile_curves.append(occ.addSpline([tips[j]] + inner + [tips[(j + 1) % zc]]))
    loops = [occ.addCurveLoop(profile_curves)]
    groups: dict[str, list[int]] = {"profile": profile_curves}
    for feat in geom.features:
        curves = _add_outline(g, feat)
        groups[feat.name] = curves
        loops.append(occ.addCurveLoop(curves))
    surface = occ.addPlaneSurface(loops)
    occ.synchronize()

    for name, curves in groups.items():
        g.model.addPhysicalGroup(1, curves, name=name)
    g.model.addPhysicalGroup(2, [surface], name="disc")

    ms = geom.case.mesh
    hmax = ms.size_interior
    h_hole = ms.size_hole if ms.size_hole is not None else min(hmax, HOLE_SIZE_FACTOR * ms.size_bore)
    seg_len = max(_polyline_length(spl[j]) for j in range(zc))
    fields = [_threshold(g, profile_curves, ms.size_flank, hmax,
                         max(20, int(math.ceil(4 * seg_len / ms.size_flank))))]
    bore_curves = [c for b in geom.bores for c in groups[b.name]]
    fields.append(_threshold(g, bore_curves, ms.size_bore, hmax,
                             max(20, int(math.ceil(4 * 2 * math.pi * geom.bores[0].radius / ms.size_bore)))))
    other = [c for f in (geom.central_hole,) + geom.holes for c in groups[f.name]]
    longest = max(f.sampling_length for f in (geom.central_hole,) + geom.holes)
    fields.append(_threshold(g, other, h_hole, hmax, max(20, int(math.ceil(4 * longest / h_hole)))))
    fmin = g.model.mesh.field.add("Min")
    g.model.mesh.field.setNumbers(fmin, "FieldsList", fields)
    g.model.mesh.field.setAsBackgroundMesh(fmin)

    opt = g.option.setNumber
    opt("Mesh.MeshSizeExtendFromBoundary", 0)
    opt("Mesh.MeshSizeFromPoints", 0)
    opt("Mesh.MeshSizeFromCurvature", 0)
    opt("Mesh.MeshSizeMax", hmax)
    opt("Mesh.Algorithm", 6)          # Frontal-Delaunay
    opt("Mesh.ElementOrder", 1)
    opt("Mesh.RecombineAll", 0)
    opt("Mesh.MshFileVersion", 4.1)
    opt("Mesh.Binary", 1)            # exact coordinates on read-back
    return groups


# ------------------------------------------------------------------------------------------------
# Reading the mesh out of Gmsh
# ------------------------------------------------------------------------------------------------


def _extract(g, path: Path, from_cache: bool) -> DiscMesh:
    """Arrays of the current Gmsh model's mesh (physical groups only)."""
    names = {}
    for dim, tag in g.model.getPhysicalGroups():
        names[(dim, g.model.getPhysicalName(dim, tag))] = tag
    if (2, "disc") not in names:
        raise MeshError(f"{path}: no physical surface 'disc'")
    tri_tags, tri_nodes = [], []
    for ent in g.model.getEntitiesForPhysicalGroup(2, names[(2, "disc")]):
        types, etags, enodes = g.model.mesh.getElements(2, int(ent))
        for t, et, en in zip(types, etags, enodes):
            if t != 2:
                raise MeshError(f"{path}: unexpected element type {t} in the disc (want 3-node triangles)")
            tri_tags.append(et)
            tri_nodes.append(en)
    tri_tags = np.concatenate(tri_tags)
    tri = np.concatenate(tri_nodes).astype(np.int64).reshape(-1, 3)

    node_tags, coords, _ = g.model.mesh.getNodes()
    node_tags = node_tags.astype(np.int64)
    xyz = coords.reshape(-1, 3)
    used = np.unique(tri)
    # remap Gmsh's non-contiguous node tags to 0..n-1 (only nodes used by triangles)
    lookup = np.full(int(node_tags.max()) + 1, -1, dtype=np.int64)
    lookup[node_tags] = np.arange(len(node_tags))
    if np.any(lookup[used] < 0):
        raise MeshError(f"{path}: triangles reference unknown nodes")
    index = np.full(int(max(node_tags.max(), used.max())) + 1, -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    points = np.ascontiguousarray(xyz[lookup[used], :2], dtype=np.float64)
    triangles = index[tri]
    p = points[triangles]
    area2 = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) \
        - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    flip = area2 < 0
    triangles[flip] = triangles[flip][:, [0, 2, 1]]
    triangles = np.ascontiguousarray(triangles)

    boundaries = {}
    for (dim, name), tag in sorted(names.items(), key=lambda kv: kv[1]):
        if dim != 1:
            continue
        edges = []
        for ent in g.model.getEntitiesForPhysicalGroup(1, tag):
            types, _, enodes = g.model.mesh.getElements(1, int(ent))
            for t, en in zip(types, enodes):
                if t != 1:
                    raise MeshError(f"{path}: unexpected element type {t} on {name!r}")
                edges.append(en.astype(np.int64).reshape(-1, 2))
        e = index[np.concatenate(edges)]
        if np.any(e < 0):
            raise MeshError(f"{path}: boundary {name!r} has nodes that belong to no triangle")
        try:
            chains = chain_edges(e)
        except MeshError as exc:
            raise MeshError(f"{path}: boundary {name!r}: {exc}") from None
        if len(chains) != 1 or not chains[0][1] or len(chains[0][0]) - 1 != len(e):
            raise MeshError(f"boundary {name!r} is not one closed loop ({len(chains)} pieces, "
                            f"{sum(len(c) - 1 for c, _ in chains)} of {len(e)} edges in order)")
        loop = chains[0][0][:-1]                    # starts at the smallest node index
        xy = points[loop]
        signed = 0.5 * np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1])
        if (signed < 0) == (name == "profile"):     # profile CCW, holes CW (disc on the left)
            loop = np.concatenate([loop[:1], loop[:0:-1]])
        boundaries[name] = np.ascontiguousarray(np.stack([loop, np.roll(loop, -1)], axis=1))

    q = g.model.mesh.getElementQualities(tri_tags, QUALITY_MEASURE)
    return DiscMesh(points=points, triangles=triangles, boundaries=boundaries, path=Path(path),
                    min_quality=float(np.min(q)), from_cache=from_cache)


# ------------------------------------------------------------------------------------------------
# Public entry points
# ------------------------------------------------------------------------------------------------


def read_msh(path: str | os.PathLike, from_cache: bool = True) -> DiscMesh:
    """Read a disc mesh written by :func:`mesh_case` (physical groups as described above)."""
    path = Path(path)
    if not path.is_file():
        raise MeshError(f"{path}: no such mesh file")
    with gmsh_session() as g:
        g.open(str(path))
        return _extract(g, path, from_cache)


def mesh_geometry(geom: DiscGeometry, path: str | os.PathLike) -> DiscMesh:
    """Mesh a checked :class:`~rvfem.geometry.DiscGeometry` and write the ``.msh`` to ``path``.

    The file is written under a unique temporary name in the same folder and moved into place with
    :func:`os.replace` (atomic on POSIX and Windows), so a crash never leaves a half file, and
    several processes meshing the same case at once each publish a complete file: a reader sees
    either no file or a whole one (the last writer wins; the meshes are identical).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp.msh")
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        with gmsh_session() as g:
            _build_model(g, geom)
            g.model.mesh.generate(2)
            mesh = _extract(g, path, from_cache=False)
            if mesh.min_quality <= 0:
                raise MeshError(f"Gmsh produced inverted or degenerate triangles "
                                f"(min {QUALITY_MEASURE} = {mesh.min_quality:.3g})")
            g.write(str(tmp))
        os.chmod(tmp, 0o644)                 # mkstemp creates 0600; a cache is shared
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return mesh


def mesh_case(case: Case, cache_dir: str | os.PathLike = "meshes", *, use_cache: bool = True,
              geometry: DiscGeometry | None = None) -> DiscMesh:
    """Mesh the disc of a case, or reuse the cached mesh.

    Parameters
    ----------
    case : Case
    cache_dir : path
        Directory of cached meshes (created if missing), relative to the working directory.
    use_cache : bool
        Reuse ``mesh_path(case, cache_dir)`` if it exists (default); False always re-meshes.
    geometry : DiscGeometry, optional
        The already built geometry of ``case`` (built and checked here otherwise). The geometry is
        checked on every call, also on a cache hit, so a geometry error is never hidden by a cache.

    Returns
    -------
    DiscMesh

    Raises
    ------
    GeometryError
        The geometry check failed (nothing is meshed).
    MeshError
        Gmsh failed or produced an unusable mesh.
    """
    geom = geometry if geometry is not None else disc_geometry(case)
    path = mesh_path(case, cache_dir)
    if use_cache and path.is_file():
        try:
            return read_msh(path, from_cache=True)
        except MeshError:
            pass     # unreadable cache entry: re-mesh; the new file replaces it atomically
    return mesh_geometry(geom, path)


def mesh_preview_png(mesh: DiscMesh, path: str | os.PathLike, *, title: str | None = None,
                     dpi: int = 150) -> Path:
    """Write an off-screen PNG of the mesh: the whole disc and a close-up of the rim under bore 1
    and the teeth next to it, boundaries coloured (:func:`rvfem.plots.mesh_plot`, matplotlib Agg;
    no display needed). Returns the path."""
    from .plots import mesh_plot

    x, y = mesh.points[:, 0], mesh.points[:, 1]
    # close-up: around the point of bore_0 farthest from the centre (rim under the bore)
    if "bore_0" in mesh.boundaries:
        b = mesh.boundary_nodes("bore_0")
        c = mesh.points[b[np.argmax(np.hypot(x[b], y[b]))]]
        c = c * (1 + 3.0 / np.hypot(*c))
    else:
        c = mesh.points[mesh.boundary_nodes("profile")[0]]
    return mesh_plot(path, mesh.points, mesh.triangles, mesh.boundaries,
                     closeup_centre=(float(c[0]), float(c[1])), title=title or f"{mesh.path.stem}",
                     subtitle=f"{mesh.n_nodes} nodes, {mesh.n_elements} triangles (P1), "
                              f"min {mesh.quality_measure} = {mesh.min_quality:.3f}",
                     closeup_title="close-up: rim under bore_0 and teeth", dpi=dpi)

