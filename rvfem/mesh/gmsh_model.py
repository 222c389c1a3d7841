"""Building the Gmsh model of the disc: the OCC curves of the profile and the features, the plane
surface of the whole disc or of one sector with its periodic cuts, the physical groups."""

from __future__ import annotations

import math

import numpy as np

from rvfem.errors import MeshError
from rvfem.geometry import Arc, DiscGeometry, Feature, LineSegment
from rvfem.mesh.sizes import _size_field, is_fillet
from rvfem.mesh.symmetry import _Cut

def _add_point(g, xy) -> int:
    return g.model.occ.addPoint(float(xy[0]), float(xy[1]), 0.0)


def _add_outline(g, feature: Feature, fillets: list[int] | None = None) -> list[int]:
    """Curves of one hole outline (:meth:`~rvfem.geometry.Feature.outline`); returns the curve tags
    in order. A full circle becomes one OCC circle; otherwise consecutive primitives share their
    end points, and arcs are split into pieces below 135° (OCC arcs must be below π). The curves
    of the outline's corner fillets (:func:`rvfem.mesh.sizes.is_fillet`) are appended to
    ``fillets`` when it is given."""
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
            first = len(tags)
            for k in range(1, n + 1):
                nxt = b if k == n else _add_point(g, p.point(p.start_angle + p.sweep * k / n))
                tags.append(occ.addCircleArc(prev, c, nxt))
                prev = nxt
            if fillets is not None and is_fillet(p, prims):
                fillets.extend(tags[first:])
        else:
            raise MeshError(f"{feature.name}: cannot mesh an outline piece of type {type(p).__name__}")
    return tags



def _add_geometry(g, geom: DiscGeometry) -> tuple[list[int], dict[str, list[int]], list[int]]:
    """Every curve of the disc: one spline per tooth space and the outline of every feature.
    Returns the tip point tags, name → curve tags (``profile`` and the feature names) and the
    curve tags of the lightening holes' corner fillets."""
    occ = g.model.occ
    spl = geom.profile.spline_points
    zc = spl.shape[0]
    tips = [_add_point(g, spl[j, 0]) for j in range(zc)]
    profile_curves = []
    for j in range(zc):
        inner = [_add_point(g, xy) for xy in spl[j, 1:-1]]
        profile_curves.append(occ.addSpline([tips[j]] + inner + [tips[(j + 1) % zc]]))
    groups: dict[str, list[int]] = {"profile": profile_curves}
    fillets: list[int] = []
    holes = {id(h) for h in geom.holes}
    for feat in geom.features:
        groups[feat.name] = _add_outline(g, feat, fillets if id(feat) in holes else None)
    return tips, groups, fillets


def _build_model(g, geom: DiscGeometry) -> dict[str, list[int]]:
    """Create the OCC geometry of the whole disc, physical groups and size fields; return name →
    curve tags."""
    occ = g.model.occ
    _, groups, fillets = _add_geometry(g, geom)
    loops = [occ.addCurveLoop(curves) for curves in groups.values()]
    surface = occ.addPlaneSurface(loops)
    occ.synchronize()

    for name, curves in groups.items():
        g.model.addPhysicalGroup(1, curves, name=name)
    g.model.addPhysicalGroup(2, [surface], name="disc")
    _size_field(g, geom, groups, fillets)
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
    tips, groups, fillets = _add_geometry(g, geom)
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
    _size_field(g, geom, groups, fillets)
    return surface, sector, cut0, cut1
