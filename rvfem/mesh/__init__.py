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
first, then round holes, then the holes of registered hole shapes) and the surface ``disc``.
Bores and holes are numbered from 0 (Python indexing; ``bore_0`` is the bore of bearing 1), in
the file as in :attr:`DiscMesh.boundaries`; what users read is numbered from 1
(:func:`rvfem.evaluate.postprocess.user_feature_name`).

Symmetric discs: when the disc maps onto itself under a rotation by 2π/N about its centre (N the
number of cranks; :func:`symmetry_order`) and ``mesh.symmetric`` is true, only one 360°/N sector is
meshed and the mesh is copied N times by rotation, so the mesh is exactly N-fold symmetric and
conforming. The sector is bounded by Zc/N profile splines, an arc of the central hole and two
radial *cuts* from the central hole to a tooth tip, the second the first rotated by 2π/N; the cuts
are periodic in Gmsh (``setPeriodic``), so their nodes match and the copies are merged along them.
The tip is the one of a sector whose cut keeps the widest clearance to the features, counted in
element sizes of each feature; below :data:`CUT_CLEARANCE` element sizes the whole disc is meshed
instead. Every curve of the disc is still built (the sector surface uses its own), so the size
field is that of the whole disc. The assembled mesh is written through Gmsh as discrete entities
with the same physical groups (plus a surface group ``symmetry_<N>``), and read back by the same
code as any other mesh file.

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
import ctypes
import hashlib
import json
import logging
import math
import os
import signal
import tempfile
import threading
from dataclasses import dataclass, field
from pathlib import Path

import gmsh
import numpy as np
from scipy.spatial import cKDTree

from rvfem import NOTICE
from rvfem._arrays import chain_edges
from rvfem.case.definition import Case, case_to_dict, registered_hole_shapes
from rvfem.errors import MeshError, OutputError
from rvfem.geometry import (
    SPLINE_POINTS_PER_SEGMENT,
    Arc,
    DiscGeometry,
    Feature,
    LineSegment,
    disc_geometry,
)

__all__ = [
    "DiscMesh",
    "gmsh_session",
    "mesh_key",
    "mesh_path",
    "mesh_case",
    "mesh_geometry",
    "read_msh",
    "rotation_permutation",
    "symmetry_order",
    "QUALITY_MEASURE",
]

log = logging.getLogger(__name__)

MESHER_VERSION = 3
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

CUT_CLEARANCE = 1.5
"""Smallest clearance between a sector cut and a feature, in element sizes on that feature
(``size_bore`` for a bore, the hole size for a hole); a disc whose best cut is closer is meshed
whole. Measured on the coarse fan-hole disc (holes at 0.8 mm, the cut 1.67 sizes from a fillet):
worst triangle 0.722 (minSICN) against 0.718 for the whole disc."""

SYMMETRY_TOLERANCE = 1e-9
"""Tolerance of the symmetry checks and of the merging of copied nodes, relative to the largest
radius."""

SYMMETRY_GROUP = "symmetry_"
"""Prefix of the surface physical group that records the symmetry order N in a mesh file
(``symmetry_3``); absent in a mesh of the whole disc."""


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
    symmetry : int
        N if the mesh was built from one 360°/N sector, else 1. The mesh is then exactly N-fold
        symmetric: ``rotation_permutation(points, N)`` maps it onto itself (nodes, triangles,
        ``profile`` onto ``profile``, the central hole onto itself, every bore onto a bore and every
        hole onto a hole: ``bore_i`` onto ``bore_{i+1}`` for cranks numbered counter-clockwise).
    """

    points: np.ndarray = field(repr=False)
    triangles: np.ndarray = field(repr=False)
    boundaries: dict = field(repr=False)
    path: Path
    min_quality: float
    quality_measure: str = QUALITY_MEASURE
    from_cache: bool = False
    symmetry: int = 1

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


def _ignore_sigpipe_again() -> None:
    """Undo what ``gmsh.initialize`` does to SIGPIPE when Python ignores it (its default).

    Gmsh sets the signal back to its default action, which ends the process: a write to a pipe
    whose reader is gone (a child process that has ended) would then kill the run instead of
    raising ``BrokenPipeError``. Python's choice is put back for the whole process (from the main
    thread by ``signal``, from another thread by the C library's ``signal``).
    """
    if not hasattr(signal, "SIGPIPE") or signal.getsignal(signal.SIGPIPE) is not signal.SIG_IGN:
        return
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)
        return

    try:
        ctypes.CDLL(None).signal(int(signal.SIGPIPE), ctypes.c_void_p(1))          # SIG_IGN
    except (OSError, AttributeError):  # pragma: no cover - no C library to ask
        log.debug("SIGPIPE left as Gmsh set it")


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
    _ignore_sigpipe_again()
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
    pin-circle radius and pin radius; cranks; the bore radius; the holes (each hole shape's
    :meth:`~rvfem.geometry.HoleShape.mesh_key_part` of its table); the mesh sizes and
    ``mesh.symmetric``; :data:`MESHER_VERSION`, the number of spline points per tooth space and
    the Gmsh version. Not included: thickness, material, loads, analysis options, bearing data
    other than the bore radius, ``mesh.min_wall`` (a check, not a shape) and the case name.
    """
    d = case_to_dict(case)
    cyc = {k: v for k, v in d["cycloid"].items() if k != "thickness"}
    shaping = {
        "cycloid": cyc,
        "pins": {k: d["pins"][k] for k in ("count", "circle_radius", "radius")},
        "cranks": d["cranks"],
        "bore_radius": d["crank_bearing"]["bore_radius"],
        "mesh": {k: d["mesh"].get(k) for k in ("size_flank", "size_bore", "size_interior", "size_hole",
                                               "symmetric")},
        "mesher": MESHER_VERSION,
        "spline_points": SPLINE_POINTS_PER_SEGMENT,
        "gmsh": gmsh.__version__,
    }
    shaping.update(_holes_key(case))
    return hashlib.sha256(json.dumps(shaping, sort_keys=True).encode()).hexdigest()


def _holes_key(case: Case) -> dict:
    """The holes' part of the mesh key: each registered hole shape's part of its table. The
    built-in shapes (:attr:`~rvfem.geometry.HoleShape.always_in_mesh_key`) have a top-level entry,
    None without a table, as in the keys of earlier versions (their cached meshes stay valid);
    the other shapes appear under ``"holes"`` when the case has their table."""
    out: dict = {}
    for shape in registered_hole_shapes():
        table = case.hole_table(shape.name)
        part = None if table is None else shape.mesh_key_part(table)
        if shape.always_in_mesh_key:
            out[shape.name] = part
        elif table is not None:
            out.setdefault("holes", {})[shape.name] = part
    return out


def mesh_path(case: Case, cache_dir: str | os.PathLike = "meshes") -> Path:
    """Where the mesh of ``case`` is cached: ``cache_dir/<name>-<first 12 hex of key>.msh``."""
    safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in case.name)
    return Path(cache_dir) / f"{safe}-{mesh_key(case)[:12]}.msh"


# ------------------------------------------------------------------------------------------------
# Symmetry
# ------------------------------------------------------------------------------------------------


def _rotation(angle: float) -> np.ndarray:
    """2×2 matrix of the rotation by ``angle`` (rad, counter-clockwise); rotate row points with
    ``p @ _rotation(angle).T``."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def _symmetry_tolerance(geom: DiscGeometry) -> float:
    """Absolute tolerance of the symmetry checks, mm: :data:`SYMMETRY_TOLERANCE` × the largest
    profile radius."""
    return SYMMETRY_TOLERANCE * float(np.max(np.hypot(*geom.profile.spline_points.reshape(-1, 2).T)))


def _coincide(f: Feature, g: Feature, angle: float, tol: float) -> bool:
    """True if the outline of ``f`` rotated by ``angle`` is the outline of ``g``: same type, and the
    samples of each lie on the other (exact signed distances within ``tol``)."""
    if type(f) is not type(g):
        return False
    spacing = 0.01 * min(f.sampling_length, g.sampling_length)
    pf = f.sample(spacing) @ _rotation(angle).T
    if np.max(np.abs(g.signed_distance(pf))) > tol:
        return False
    pg = g.sample(spacing) @ _rotation(-angle).T
    return bool(np.max(np.abs(f.signed_distance(pg))) <= tol)


def _feature_images(geom: DiscGeometry, order: int) -> dict[str, str] | None:
    """Name of the feature onto which the rotation by +2π/order maps each bore and hole (bores
    onto bores, holes onto holes, one-to-one), or None if some feature has no image."""
    tol = _symmetry_tolerance(geom)
    angle = 2 * math.pi / order
    images = {}
    for group in (geom.bores, geom.holes):
        for f in group:
            hits = [g.name for g in group if _coincide(f, g, angle, tol)]
            if len(hits) != 1:
                return None
            images[f.name] = hits[0]
    if len(set(images.values())) != len(images):
        return None
    return images


def _symmetry_reason(geom: DiscGeometry) -> tuple[int, str]:
    """(N, "") if the disc is N-fold symmetric (N = number of cranks), else (1, why not)."""
    case = geom.case
    n = case.cranks.count
    if not case.mesh.symmetric:
        return 1, "mesh.symmetric is false"
    spl = geom.profile.spline_points
    zc = spl.shape[0]
    if n < 2 or zc % n:
        return 1, f"the {zc} teeth do not repeat {n} times"
    tol = _symmetry_tolerance(geom)
    if float(np.hypot(*geom.central_hole.centre)) > tol:
        return 1, "the central hole is off the disc centre"
    rotated = spl.reshape(-1, 2) @ _rotation(2 * math.pi / n).T
    further = np.roll(spl, -(zc // n), axis=0).reshape(-1, 2)      # the teeth 360°/N further on
    mismatch = float(np.max(np.linalg.norm(rotated - further, axis=1)))
    if mismatch > tol:
        return 1, (f"the profile is not {n}-fold symmetric (pitch errors?): rotated by 360°/{n} it "
                   f"misses itself by {mismatch:.3g} mm")
    if _feature_images(geom, n) is None:
        return 1, f"the bores and holes do not repeat at 360°/{n} (unequal crank angles?)"
    return n, ""


def symmetry_order(geom: DiscGeometry) -> int:
    """Order of the rotational symmetry the mesher uses: N or 1.

    N (the number of cranks) if the disc maps onto itself under the rotation by 2π/N about its
    centre, else 1. Decided on the geometry itself, within :data:`SYMMETRY_TOLERANCE` × the largest
    profile radius: Zc is divisible by N and the profile's spline points rotated by 2π/N are those
    Zc/N teeth further on; the central hole is centred; every bore (every hole) rotated by 2π/N
    coincides with a bore (a hole) of the same type. Pitch errors or unequal crank angles therefore
    give 1. Also 1 when ``mesh.symmetric`` is false.

    Parameters
    ----------
    geom : DiscGeometry

    Returns
    -------
    int
    """
    return _symmetry_reason(geom)[0]


def rotation_permutation(points: np.ndarray, order: int, tol: float | None = None) -> np.ndarray:
    """The permutation of the nodes by the rotation through +2π/order about the origin.

    Parameters
    ----------
    points : ndarray (n, 2)
        Node coordinates, mm.
    order : int
        N ≥ 1 (1 gives the identity).
    tol : float, optional
        Largest distance between a rotated node and its partner, mm; default
        :data:`SYMMETRY_TOLERANCE` × the largest node radius.

    Returns
    -------
    ndarray (n,) int64
        ``perm`` such that node ``i`` rotated by 2π/order is node ``perm[i]``.

    Raises
    ------
    MeshError
        If some rotated node has no partner within ``tol`` (or two share one).
    """
    p = np.asarray(points, dtype=np.float64)
    n = len(p)
    if order < 1:
        raise MeshError(f"the symmetry order must be at least 1, got {order}")
    if order == 1:
        return np.arange(n, dtype=np.int64)
    if tol is None:
        tol = SYMMETRY_TOLERANCE * float(np.max(np.hypot(p[:, 0], p[:, 1])))
    dist, perm = cKDTree(p).query(p @ _rotation(2 * math.pi / order).T, distance_upper_bound=tol)
    missing = ~np.isfinite(dist)
    if np.any(missing):
        raise MeshError(f"the mesh is not {order}-fold symmetric: {int(missing.sum())} of {n} nodes "
                        f"rotated by 360°/{order} have no node within {tol:.3g} mm")
    if len(np.unique(perm)) != n:
        raise MeshError(f"the mesh is not {order}-fold symmetric: rotated by 360°/{order}, two nodes "
                        "land on the same node")
    return perm.astype(np.int64)


@dataclass(frozen=True)
class _Cut:
    """Where the sector of a symmetric disc is cut: the radial line from the central hole to tip
    ``tip`` (``spline_points[tip, 0]``) at polar angle ``angle``, and its image rotated by 2π/N."""

    order: int
    tip: int
    angle: float
    clearance: float
    """Smallest distance from the cut to a bore or hole, mm."""
    margin: float
    """Smallest clearance in element sizes of the feature concerned."""
    images: dict = field(repr=False)
    """Feature name → name of its image under the rotation by 2π/N."""


def _feature_size(geom: DiscGeometry, f: Feature) -> float:
    """Target element size on a feature's outline, mm."""
    return geom.case.mesh.size_bore if any(f is b for b in geom.bores) else _hole_size(geom.case.mesh)


def _hole_size(ms) -> float:
    """Element size on the central hole and the lightening holes, mm."""
    if ms.size_hole is not None:
        return ms.size_hole
    return min(ms.size_interior, HOLE_SIZE_FACTOR * ms.size_bore)


def _sector_cut(geom: DiscGeometry) -> _Cut | None:
    """The cut of the sector mesh, or None (and why, logged) if the whole disc must be meshed."""
    order, why = _symmetry_reason(geom)
    if order == 1:   # a notice (shown without -v) unless the case asks for the whole disc
        log.info("meshing the whole disc: %s", why, extra=NOTICE if geom.case.mesh.symmetric else {})
        return None
    spl = geom.profile.spline_points
    rc = geom.central_hole.radius
    feats = geom.bores + geom.holes
    sizes = np.array([_feature_size(geom, f) for f in feats])
    best: tuple[float, int, float, float] | None = None
    for j in range(spl.shape[0] // order):          # the tips of one sector
        tip = spl[j, 0]
        a = math.atan2(tip[1], tip[0])
        seg = LineSegment((rc * math.cos(a), rc * math.sin(a)), (float(tip[0]), float(tip[1])))
        pts = seg.sample(0.1 * float(sizes.min()))
        d = np.array([float(np.min(f.signed_distance(pts))) for f in feats])
        margin = float(np.min(d / sizes))
        if best is None or margin > best[0] * (1 + 1e-9):
            best = (margin, j, a, float(d.min()))
    assert best is not None   # a profile has tips
    margin, j, a, clearance = best
    if margin < CUT_CLEARANCE:
        log.info("meshing the whole disc: it is %d-fold symmetric, but the best sector cut (to tip %d "
                 "at %.3f°) passes %.3g mm from a feature, %.2f element sizes (needs %.2f)",
                 order, j, math.degrees(a), clearance, margin, CUT_CLEARANCE, extra=NOTICE)
        return None
    images = _feature_images(geom, order)
    assert images is not None   # _symmetry_reason gave this order only if every feature has an image
    return _Cut(order=order, tip=j, angle=a, clearance=clearance, margin=margin, images=images)


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
        circle = prims[0]
        return [occ.addCircle(circle.centre[0], circle.centre[1], 0.0, circle.radius,
                              angle1=circle.start_angle, angle2=circle.start_angle + circle.sweep)]
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


def _add_geometry(g, geom: DiscGeometry) -> tuple[list[int], dict[str, list[int]]]:
    """Every curve of the disc: one spline per tooth space and the outline of every feature.
    Returns the tip point tags and name → curve tags (``profile`` and the feature names)."""
    occ = g.model.occ
    spl = geom.profile.spline_points
    zc = spl.shape[0]
    tips = [_add_point(g, spl[j, 0]) for j in range(zc)]
    profile_curves = []
    for j in range(zc):
        inner = [_add_point(g, xy) for xy in spl[j, 1:-1]]
        profile_curves.append(occ.addSpline([tips[j]] + inner + [tips[(j + 1) % zc]]))
    groups: dict[str, list[int]] = {"profile": profile_curves}
    for feat in geom.features:
        groups[feat.name] = _add_outline(g, feat)
    return tips, groups


def _size_field(g, geom: DiscGeometry, groups: dict[str, list[int]]) -> None:
    """Background size field (fine on the profile, the bores and the holes, growing inwards) and
    the meshing options; ``groups`` holds the curves of the whole disc."""
    ms = geom.case.mesh
    spl = geom.profile.spline_points
    hmax = ms.size_interior
    h_hole = _hole_size(ms)
    seg_len = max(_polyline_length(spl[j]) for j in range(spl.shape[0]))
    fields = [_threshold(g, groups["profile"], ms.size_flank, hmax,
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
    _file_options(g)


def _file_options(g) -> None:
    g.option.setNumber("Mesh.MshFileVersion", 4.1)
    g.option.setNumber("Mesh.Binary", 1)            # exact coordinates on read-back


def _build_model(g, geom: DiscGeometry) -> dict[str, list[int]]:
    """Create the OCC geometry of the whole disc, physical groups and size fields; return name →
    curve tags."""
    occ = g.model.occ
    _, groups = _add_geometry(g, geom)
    loops = [occ.addCurveLoop(curves) for curves in groups.values()]
    surface = occ.addPlaneSurface(loops)
    occ.synchronize()

    for name, curves in groups.items():
        g.model.addPhysicalGroup(1, curves, name=name)
    g.model.addPhysicalGroup(2, [surface], name="disc")
    _size_field(g, geom, groups)
    return groups


def _sector_of(f: Feature, cut: _Cut) -> int:
    """Index k of the sector [a0 + 2πk/N, a0 + 2π(k+1)/N) that holds the feature (-1 if it straddles
    a cut)."""
    p = f.sample(0.01 * f.sampling_length)
    turn = np.mod(np.arctan2(p[:, 1], p[:, 0]) - cut.angle, 2 * math.pi)
    k = np.minimum(np.floor(turn / (2 * math.pi / cut.order)).astype(int), cut.order - 1)
    return int(k[0]) if np.all(k == k[0]) else -1


def _build_sector_model(g, geom: DiscGeometry, cut: _Cut) -> tuple[int, dict[str, list[int]], int, int]:
    """Create the OCC geometry of the whole disc plus the surface of the first sector and the size
    field of the whole disc; make the two cuts periodic.

    Returns the sector surface tag, name → curve tags of the sector's boundary (``profile``: its
    Zc/N splines, ``central_hole``: the arc between the cuts, the features inside the sector: their
    outlines) and the tags of the cuts at ``cut.angle`` and ``cut.angle + 2π/N``, both running from
    the central hole out to the tip.
    """
    occ = g.model.occ
    tips, groups = _add_geometry(g, geom)
    zc, n = len(tips), cut.order
    m = zc // n
    sweep = 2 * math.pi / n
    rc = geom.central_hole.radius
    ends = [_add_point(g, (rc * math.cos(cut.angle + k * sweep), rc * math.sin(cut.angle + k * sweep)))
            for k in (0, 1)]
    cut0 = occ.addLine(ends[0], tips[cut.tip])
    cut1 = occ.addLine(ends[1], tips[(cut.tip + m) % zc])
    pieces = max(1, int(math.ceil(sweep / (0.75 * math.pi))))     # OCC arcs below π
    centre = _add_point(g, (0.0, 0.0))
    arc, prev = [], ends[0]
    for k in range(1, pieces + 1):
        a = cut.angle + sweep * k / pieces
        nxt = ends[1] if k == pieces else _add_point(g, (rc * math.cos(a), rc * math.sin(a)))
        arc.append(occ.addCircleArc(prev, centre, nxt))
        prev = nxt
    profile = [groups["profile"][(cut.tip + i) % zc] for i in range(m)]
    outer = occ.addCurveLoop(profile + [cut1] + arc[::-1] + [cut0])
    sector = {"profile": profile, "central_hole": arc}
    for f in geom.bores + geom.holes:
        k = _sector_of(f, cut)
        if k < 0:
            raise MeshError(f"{f.name} straddles the sector cut at {math.degrees(cut.angle):.3f}°")
        if k == 0:
            sector[f.name] = groups[f.name]
    surface = occ.addPlaneSurface([outer] + [occ.addCurveLoop(sector[name]) for name in list(sector)[2:]])
    occ.synchronize()
    c, s = math.cos(sweep), math.sin(sweep)
    g.model.mesh.setPeriodic(1, [cut1], [cut0], [c, -s, 0, 0, s, c, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])
    _size_field(g, geom, groups)
    return surface, sector, cut0, cut1


# ------------------------------------------------------------------------------------------------
# Reading the mesh out of Gmsh
# ------------------------------------------------------------------------------------------------


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


# ------------------------------------------------------------------------------------------------
# Sector meshes: copying one sector round the disc
# ------------------------------------------------------------------------------------------------


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


def _cache_file(path: Path) -> tuple[int, str]:
    """Create the folder of ``path`` (the mesh cache) and a temporary file in it; ``(fd, name)``.

    Raises
    ------
    OutputError
        The folder is a file, or cannot be created or written (the error names the mesh cache,
        not the results).
    """
    folder = path.parent
    blocked = next((p for p in (folder, *folder.parents) if p.exists() and not p.is_dir()), None)
    if blocked is not None:
        raise OutputError(f"the mesh cache folder {folder} cannot be used: {blocked} is a file, not a folder; "
                          "choose another mesh cache folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        return tempfile.mkstemp(dir=folder, prefix=f".{path.stem}.", suffix=".tmp.msh")
    except OSError as exc:
        raise OutputError(f"cannot write into the mesh cache folder {folder}: {exc.strerror or exc}; choose another "
                          "mesh cache folder") from None


def mesh_geometry(geom: DiscGeometry, path: str | os.PathLike) -> DiscMesh:
    """Mesh a checked :class:`~rvfem.geometry.DiscGeometry` and write the ``.msh`` to ``path``.

    An N-fold symmetric disc (:func:`symmetry_order`) is meshed as one sector copied N times when
    a sector cut clears the features (:data:`CUT_CLEARANCE`); the mesh then has ``symmetry == N``.
    Otherwise the whole disc is meshed (``symmetry == 1``).

    The file is written under a unique temporary name in the same folder and moved into place with
    :func:`os.replace` (atomic on POSIX and Windows), so a crash never leaves a half file, and
    several processes meshing the same case at once each publish a complete file: a reader sees
    either no file or a whole one (the last writer wins; the meshes are identical).
    """
    path = Path(path)
    cut = _sector_cut(geom)
    fd, tmp_name = _cache_file(path)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        with gmsh_session() as g:
            if cut is None:
                _build_model(g, geom)
                g.model.mesh.generate(2)
            else:
                assembled = _mesh_sector(g, geom, cut)
                g.clear()
                _add_discrete(g, assembled)
            mesh = _extract(g, path, from_cache=False)
            if cut is not None and not (np.array_equal(mesh.points, assembled.points)
                                        and np.array_equal(mesh.triangles, assembled.triangles)
                                        and all(np.array_equal(mesh.boundaries[k], v)
                                                for k, v in assembled.boundaries.items())):
                raise MeshError("the assembled sector mesh does not read back from Gmsh unchanged")
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
    OutputError
        ``cache_dir`` is a file or cannot be written.
    """
    geom = geometry if geometry is not None else disc_geometry(case)
    path = mesh_path(case, cache_dir)
    if use_cache and path.is_file():
        try:
            mesh = read_msh(path, from_cache=True)
            if mesh.symmetry == 1:
                _sector_cut(geom)    # says why the whole disc is meshed (a notice), as when it was meshed
            return mesh
        except MeshError:
            pass     # unreadable cache entry: re-mesh; the new file replaces it atomically
    return mesh_geometry(geom, path)
