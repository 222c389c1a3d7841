"""The disc's rotational symmetry: its order, the permutation of the nodes by the rotation, and the
cut of the one sector that is meshed and copied round the disc."""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from rvfem import NOTICE
from rvfem.errors import MeshError
from rvfem.geometry import DiscGeometry, Feature, LineSegment
from rvfem.mesh.sizes import _feature_size

log = logging.getLogger(__name__)

CUT_CLEARANCE = 1.5
"""Smallest clearance between a sector cut and a feature, in element sizes on that feature
(``size_bore`` for a bore, the hole size for a hole); a disc whose best cut is closer is meshed
whole. Measured on the coarse fan-hole disc (holes at 0.8 mm, the cut 1.67 sizes from a fillet):
worst triangle 0.722 (minSICN) against 0.718 for the whole disc."""

SYMMETRY_TOLERANCE = 1e-9
"""Tolerance of the symmetry checks and of the merging of copied nodes, relative to the largest
radius."""


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
