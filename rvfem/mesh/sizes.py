"""The element sizes: the size on each curve of the disc and the background size field that holds
it over a band and lets it grow inwards, with the meshing options."""

from __future__ import annotations

import math

import numpy as np

from rvfem.geometry import Arc, DiscGeometry, Feature
from rvfem.mesh.session import _file_options

SIZE_GROWTH = 0.25
"""Growth of the target element size away from a refined curve, mm per mm."""

HOLE_SIZE_FACTOR = 2.0
"""Element size on the central hole and the lightening holes, as a multiple of ``size_bore``."""

BAND_FACTOR = 2.0
"""Width of the band held at the fine size next to a refined curve, in elements."""

FILLET_SIZE_FACTOR = 0.5
"""Element size on the corner fillets of the lightening holes, as a multiple of the hole size
(``mesh.size_fillet`` when not given). The structural stress peak of a disc with fan holes sits
on a fillet: with the holes at 0.5 mm and the fillets at 0.25 mm the P2 peak of the default case
is within 3 % of its converged value (docs/outputs.md, "The structural stress peak"), for a
fraction of the vertices that refining the whole hole outlines costs."""


def is_fillet(arc: Arc, outline: tuple) -> bool:
    """Whether an arc of a hole outline is a corner fillet (or a rounded end): an arc of an outline
    made of several pieces, not centred on the disc centre (the fan holes' inner and outer arcs
    are)."""
    return len(outline) > 1 and math.hypot(*arc.centre) > 1e-9


def _fillet_size(ms) -> float:
    """Element size on the corner fillets of the lightening holes, mm."""
    if ms.size_fillet is not None:
        return ms.size_fillet
    return FILLET_SIZE_FACTOR * _hole_size(ms)


def _feature_size(geom: DiscGeometry, f: Feature) -> float:
    """Target element size on a feature's outline, mm."""
    return geom.case.mesh.size_bore if any(f is b for b in geom.bores) else _hole_size(geom.case.mesh)


def _hole_size(ms) -> float:
    """Element size on the central hole and the lightening holes, mm."""
    if ms.size_hole is not None:
        return ms.size_hole
    return min(ms.size_interior, HOLE_SIZE_FACTOR * ms.size_bore)


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


def _size_field(g, geom: DiscGeometry, groups: dict[str, list[int]], fillets: list[int] | None = None) -> None:
    """Background size field (fine on the profile, the bores and the holes, finer on the holes'
    corner fillets, growing inwards) and the meshing options; ``groups`` holds the curves of the
    whole disc, ``fillets`` the curves of the lightening holes' corner fillets."""
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
    h_fillet = _fillet_size(ms)
    if fillets and h_fillet < h_hole:
        arc = max(g.model.occ.getMass(1, c) for c in fillets)      # the longest fillet curve, mm
        fields.append(_threshold(g, fillets, h_fillet, hmax, max(20, int(math.ceil(4 * arc / h_fillet)))))
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
