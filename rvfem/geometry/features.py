"""The disc's features (holes and bores), the Feature protocol and the checked DiscGeometry.

Everything is in the disc's body frame (origin at the disc centre), lengths mm, angles radians.

Features
--------
A central hole, N crank-bearing bores (radius ``crank_bearing.bore_radius``) at r0·u(α_i) and the
lightening holes of the case's hole tables (fan-shaped holes, round holes, any registered hole
shape). Every one of them is a :class:`Feature`: a name, a closed outline of lines and arcs, an
exact signed distance, samples, an exact area and a self-check. :class:`Circle` and
:class:`FanHole` implement it. A new kind of hole is one :class:`~rvfem.geometry.holes.HoleShape`
(its case table and the features it adds, :mod:`rvfem.geometry.holes`) with one frozen dataclass
of these members for its outline; neither the checks here nor the mesher (:mod:`rvfem.mesh`) need
to know its type.

:func:`disc_geometry` builds a :class:`DiscGeometry` and checks it (undercut, overlaps, thin walls)
before anything is meshed; every problem is a :class:`~rvfem.errors.GeometryError` that says what
to change. Areas follow from Green's theorem over the outline, ½∮(x dy − y dx); walls are the
minimum of the exact signed distance of one feature over dense samples of the other's outline
(docs/theory.md, "Features").

Names: a feature's :attr:`~Feature.name` is also the name of its mesh boundary (physical group)
and is numbered from 0 like Python indices (``bore_0`` is the bore of bearing 1, ``hole_0`` the
first lightening hole); messages give them numbered from 1, as everything users read
(:func:`feature_text`: ``bore_0`` → "bore 1", ``hole_0`` → "hole 1"), with the case keys that
change them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, Union

import numpy as np

from rvfem._arrays import points_in_polygon
from rvfem.case.definition import Case
from rvfem.errors import GeometryError
from rvfem.geometry.kinematics import crank_centres
from rvfem.names import feature_text
from rvfem.geometry.profile import Profile, build_profile

__all__ = [
    "Feature",
    "HoleContext",
    "LineSegment",
    "Arc",
    "Circle",
    "FanHole",
    "Wall",
    "DiscGeometry",
    "disc_geometry",
    "feature_text",
    "WALL_SPACING",
]

WALL_SPACING = 0.02
"""Spacing (mm) of the points used to measure walls between features (widened on features longer
than WALL_SAMPLES·WALL_SPACING = 400 mm, see :data:`WALL_SAMPLES`)."""

WALL_SAMPLES = 20_000
"""Most points per :attr:`Feature.sampling_length` when walls are measured: a feature longer than
400 mm (a bore of more than 64 mm radius; discs far larger than the largest RV reducers) is sampled
at sampling_length/WALL_SAMPLES instead of WALL_SPACING, so that checking a large disc stays cheap.
The error of a wall measured on samples is about spacing²/(8·radius of curvature): 0.05 µm for a
1 mm fillet at 0.02 mm spacing, 1.3 µm at 0.1 mm."""


def length_text(x: float) -> str:
    """A wall or an overlap for a message: mm with three decimals, or µm below 0.1 mm (so that a
    near-touch is not "0.000 mm")."""
    x = abs(x)
    return f"{x:.3f} mm" if x >= 0.1 else f"{1000.0 * x:.3g} µm"


def _keys_text(keys) -> str:
    """'a', 'b' or 'c'."""
    quoted = [f"'{k}'" for k in dict.fromkeys(keys)]
    return quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]


@dataclass(frozen=True)
class LineSegment:
    """A straight piece of a hole outline from ``start`` to ``end`` (mm)."""

    start: tuple[float, float]
    end: tuple[float, float]

    def distance(self, p: np.ndarray) -> np.ndarray:
        """Distance from points (n, 2) to the segment, mm."""
        a, b = np.asarray(self.start), np.asarray(self.end)
        ab = b - a
        L2 = float(ab @ ab)
        t = np.clip(((p - a) @ ab) / L2, 0.0, 1.0) if L2 > 0 else np.zeros(len(p))
        return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)

    def sample(self, spacing: float) -> np.ndarray:
        n = max(2, int(math.ceil(self.length / spacing)) + 1)
        t = np.linspace(0, 1, n)[:, None]
        return (1 - t) * np.asarray(self.start) + t * np.asarray(self.end)

    @property
    def length(self) -> float:
        return float(np.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1]))

    def area_term(self) -> float:
        """½∮(x dy − y dx) over this piece (Green's theorem)."""
        return 0.5 * (self.start[0] * self.end[1] - self.start[1] * self.end[0])


@dataclass(frozen=True)
class Arc:
    """A circular arc of a hole outline: centre, radius (mm), start angle and signed sweep (rad,
    positive counter-clockwise)."""

    centre: tuple[float, float]
    radius: float
    start_angle: float
    sweep: float

    def point(self, angle: float) -> tuple[float, float]:
        return (self.centre[0] + self.radius * math.cos(angle),
                self.centre[1] + self.radius * math.sin(angle))

    @property
    def start(self) -> tuple[float, float]:
        return self.point(self.start_angle)

    @property
    def end(self) -> tuple[float, float]:
        return self.point(self.start_angle + self.sweep)

    @property
    def length(self) -> float:
        return abs(self.sweep) * self.radius

    def distance(self, p: np.ndarray) -> np.ndarray:
        """Distance from points (n, 2) to the arc, mm (exact)."""
        c = np.asarray(self.centre)
        v = p - c
        ang = np.arctan2(v[:, 1], v[:, 0])
        lo = self.start_angle if self.sweep >= 0 else self.start_angle + self.sweep
        inside = np.mod(ang - lo, 2 * np.pi) <= abs(self.sweep)
        d_arc = np.abs(np.linalg.norm(v, axis=1) - self.radius)
        d_end = np.minimum(np.linalg.norm(p - np.asarray(self.start), axis=1),
                           np.linalg.norm(p - np.asarray(self.end), axis=1))
        return np.where(inside, d_arc, d_end)

    def sample(self, spacing: float) -> np.ndarray:
        n = max(2, int(math.ceil(self.length / spacing)) + 1)
        a = self.start_angle + self.sweep * np.linspace(0, 1, n)
        return np.stack([self.centre[0] + self.radius * np.cos(a),
                         self.centre[1] + self.radius * np.sin(a)], axis=1)

    def area_term(self) -> float:
        """½∮(x dy − y dx) over this arc: ½[R·(c_x·Δsin − c_y·Δcos) + R²·sweep]."""
        a1, a2 = self.start_angle, self.start_angle + self.sweep
        cx, cy = self.centre
        R = self.radius
        return 0.5 * (R * (cx * (math.sin(a2) - math.sin(a1)) - cy * (math.cos(a2) - math.cos(a1)))
                      + R * R * self.sweep)


Primitive = Union[LineSegment, Arc]
"""A piece of an outline: a straight segment or a circular arc."""


class Feature(Protocol):
    """What the geometry checks and the mesher need to know about a hole cut out of the disc.

    A new hole shape is one frozen dataclass with these members; :func:`disc_geometry` checks it
    and :mod:`rvfem.mesh` meshes it without knowing its type (it builds the Gmsh curves from
    :meth:`outline`, one per primitive, and sizes the distance field by :attr:`sampling_length`).

    Attributes
    ----------
    name : str
        Name of the feature and of the mesh boundary (physical group) along its outline, e.g.
        ``"bore_0"``, ``"hole_2"``.
    """

    @property
    def name(self) -> str:   # read-only: a frozen dataclass's field satisfies it
        """Name of the feature and of its mesh boundary."""

    def validate(self) -> None:
        """Raise :class:`~rvfem.errors.GeometryError` (naming the feature and the case key to
        change) if the shape is impossible by itself, before it is compared with the others."""

    def outline(self) -> tuple[Primitive, ...]:
        """The boundary as a closed chain of lines and arcs, counter-clockwise around the hole
        (each primitive starts where the previous ends; a full circle is one :class:`Arc` of sweep
        2π). The mesher makes one Gmsh curve per primitive (arcs above 135° split in pieces)."""

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        """Exact distance from points ``(n, 2)`` (mm) to the outline, negative inside the hole."""

    def sample(self, spacing: float = ...) -> np.ndarray:
        """Points along the outline, at most ``spacing`` mm apart, ``(m, 2)``, mm (closed polygon,
        last point not repeated); used to measure walls and to test containment in the profile."""

    @property
    def area(self) -> float:
        """Exact area of the hole, mm²."""

    @property
    def sampling_length(self) -> float:
        """A length of the outline, mm, by which the mesher sets how densely its distance field
        samples the hole's curves (about four points per element size along this length)."""


@dataclass(frozen=True)
class Circle:
    """A circular hole (central hole, crank-bearing bore, round lightening hole).

    Attributes
    ----------
    name : str
    centre : (float, float)
        mm.
    radius : float
        mm.
    """

    name: str
    centre: tuple[float, float]
    radius: float

    def validate(self) -> None:
        """Raise GeometryError for a non-positive radius."""
        if not self.radius > 0:
            raise GeometryError(f"{feature_text(self.name)}: the radius must be positive, got {self.radius} mm")

    def outline(self) -> tuple["Arc"]:
        """One full counter-clockwise circle (start angle 0, sweep 2π)."""
        return (Arc(self.centre, self.radius, 0.0, 2 * math.pi),)

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        """Distance from points (n, 2) to the hole, mm; negative inside the hole."""
        return np.hypot(p[:, 0] - self.centre[0], p[:, 1] - self.centre[1]) - self.radius

    def sample(self, spacing: float = WALL_SPACING) -> np.ndarray:
        """Points along the circle (closed polygon, last point not repeated, at least 16), mm."""
        n = max(16, int(math.ceil(2 * math.pi * self.radius / spacing)))
        a = 2 * np.pi * np.arange(n) / n
        return np.stack([self.centre[0] + self.radius * np.cos(a),
                         self.centre[1] + self.radius * np.sin(a)], axis=1)

    @property
    def area(self) -> float:
        """πR², mm²."""
        return math.pi * self.radius**2

    @property
    def sampling_length(self) -> float:
        """The circumference 2πR, mm."""
        return 2 * math.pi * self.radius


@dataclass(frozen=True)
class FanHole:
    """A fan-shaped hole: the annular sector r_i ≤ ρ ≤ r_o, |φ − φ_c| ≤ half_span with its four
    corners rounded by fillets of radius f (tangent to the arcs and to the radial sides).

    Attributes
    ----------
    name : str
    inner_radius, outer_radius : float
        mm.
    centre_angle, half_span : float
        Angle of the centre line and half the angular span between the radial sides, rad.
    fillet_radius : float
        mm (0 = sharp corners).
    """

    name: str
    inner_radius: float
    outer_radius: float
    centre_angle: float
    half_span: float
    fillet_radius: float

    @property
    def fillet_angles(self) -> tuple[float, float]:
        """(γ_o, γ_i): angular offsets of the outer/inner fillet centres from the sides,
        sin γ_o = f/(r_o − f), sin γ_i = f/(r_i + f)."""
        f = self.fillet_radius
        return (math.asin(f / (self.outer_radius - f)), math.asin(f / (self.inner_radius + f)))

    def validate(self) -> None:
        """Raise GeometryError if the fillets do not fit the sector."""
        f, ri, ro, al = self.fillet_radius, self.inner_radius, self.outer_radius, self.half_span
        if ro - ri <= 2 * f:
            raise GeometryError(
                f"{feature_text(self.name)}: fillet radius {f} mm does not fit the radial height "
                f"{ro - ri:.3g} mm of the fan hole (needs fillet < half the height); reduce "
                "'fan_holes.fillet_radius' or widen the hole ('fan_holes.inner_radius', 'fan_holes.outer_radius')")
        go, gi = self.fillet_angles
        if al <= max(go, gi) or (ro - f) * math.cos(go) <= (ri + f) * math.cos(gi):
            raise GeometryError(
                f"{feature_text(self.name)}: span {math.degrees(2 * al):.3g}° is too narrow for fillets of "
                f"{f} mm (needs more than {math.degrees(2 * max(go, gi)):.3g}°); widen the hole "
                "('fan_holes.span_deg', or a smaller 'fan_holes.ligament') or reduce 'fan_holes.fillet_radius'")

    def outline(self) -> tuple:
        """The outline as lines and arcs, counter-clockwise around the hole (hole on the left)."""
        f, ri, ro = self.fillet_radius, self.inner_radius, self.outer_radius
        bc, al = self.centre_angle, self.half_span
        bp, bm = bc + al, bc - al            # the two radial sides
        if f == 0:
            ul = (math.cos(bp), math.sin(bp))
            ur = (math.cos(bm), math.sin(bm))
            return (
                Arc((0.0, 0.0), ro, bm, 2 * al),
                LineSegment((ro * ul[0], ro * ul[1]), (ri * ul[0], ri * ul[1])),
                Arc((0.0, 0.0), ri, bp, -2 * al),
                LineSegment((ri * ur[0], ri * ur[1]), (ro * ur[0], ro * ur[1])),
            )
        go, gi = self.fillet_angles
        rco, rci = ro - f, ri + f
        co_p = (rco * math.cos(bp - go), rco * math.sin(bp - go))
        ci_p = (rci * math.cos(bp - gi), rci * math.sin(bp - gi))
        ci_m = (rci * math.cos(bm + gi), rci * math.sin(bm + gi))
        co_m = (rco * math.cos(bm + go), rco * math.sin(bm + go))
        lo, li = rco * math.cos(go), rci * math.cos(gi)   # tangent points on the sides
        return (
            Arc((0.0, 0.0), ro, bm + go, 2 * (al - go)),
            Arc(co_p, f, bp - go, math.pi / 2 + go),
            LineSegment((lo * math.cos(bp), lo * math.sin(bp)), (li * math.cos(bp), li * math.sin(bp))),
            Arc(ci_p, f, bp + math.pi / 2, math.pi / 2 - gi),
            Arc((0.0, 0.0), ri, bp - gi, -2 * (al - gi)),
            Arc(ci_m, f, bm + gi + math.pi, math.pi / 2 - gi),
            LineSegment((li * math.cos(bm), li * math.sin(bm)), (lo * math.cos(bm), lo * math.sin(bm))),
            Arc(co_m, f, bm - math.pi / 2, math.pi / 2 + go),
        )

    def sample(self, spacing: float = WALL_SPACING) -> np.ndarray:
        """Points along the outline (closed polygon, last point not repeated), mm."""
        return np.concatenate([p.sample(spacing)[:-1] for p in self.outline()])

    @property
    def area(self) -> float:
        """Exact area from Green's theorem over the outline, mm²."""
        return sum(p.area_term() for p in self.outline())

    @property
    def sampling_length(self) -> float:
        """The outer arc of the unfilleted sector, r_o·2α, mm."""
        return self.outer_radius * 2 * self.half_span

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        """Distance from points (n, 2) to the hole, mm; negative inside."""
        prims = self.outline()
        d = np.min([q.distance(p) for q in prims], axis=0)
        return np.where(self.contains(p), -d, d)

    def contains(self, p: np.ndarray) -> np.ndarray:
        """True for points (n, 2) inside the hole: inside the annular sector and not in one of
        the corner regions cut off by the fillets (a corner region is the part of the sector seen
        from a fillet centre within the fillet arc's sweep, beyond the fillet radius)."""
        rho = np.hypot(p[:, 0], p[:, 1])
        dphi = np.angle(np.exp(1j * (np.arctan2(p[:, 1], p[:, 0]) - self.centre_angle)))
        inside = (rho >= self.inner_radius) & (rho <= self.outer_radius) & (np.abs(dphi) <= self.half_span)
        if self.fillet_radius > 0:
            for q in self.outline():
                if isinstance(q, Arc) and q.centre != (0.0, 0.0):
                    v = p - np.asarray(q.centre)
                    a = np.mod(np.arctan2(v[:, 1], v[:, 0]) - q.start_angle, 2 * np.pi)
                    corner = (a <= q.sweep) & (np.hypot(v[:, 0], v[:, 1]) > q.radius)
                    inside &= ~corner
        return inside


@dataclass(frozen=True)
class Wall:
    """The thinnest wall between two features (negative: they overlap)."""

    first: str
    second: str
    thickness: float
    location: tuple[float, float]


@dataclass(frozen=True, eq=False)
class DiscGeometry:
    """Everything the mesher and the contact model need to know about the disc.

    Attributes
    ----------
    case : Case
    profile : Profile
    central_hole : Circle
    bores : tuple of Circle
        ``bore_0`` … ``bore_{N−1}`` at r0·u(α_i).
    holes : tuple of Feature
        Lightening holes ``hole_0`` …, table by table in the order of
        :func:`rvfem.case.definition.hole_table_names`: the fan holes (:class:`FanHole`), the round holes
        (:class:`Circle`), then the holes of registered hole shapes.
    walls : tuple of Wall
        The thinnest wall between every pair of features (and each feature and the profile),
        thinnest first.
    """

    case: Case
    profile: Profile
    central_hole: Circle
    bores: tuple[Circle, ...]
    holes: tuple[Feature, ...]
    walls: tuple[Wall, ...]

    @property
    def features(self) -> tuple[Feature, ...]:
        """Central hole, bores and holes (everything cut out of the profile)."""
        return (self.central_hole,) + self.bores + self.holes

    @property
    def area(self) -> float:
        """Disc area, mm²: profile polygon (dense samples) minus the exact hole areas."""
        x, y = self.profile.points[:, 0], self.profile.points[:, 1]
        a = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
        return a - sum(f.area for f in self.features)


@dataclass(frozen=True)
class HoleContext:
    """What a hole shape (:meth:`rvfem.geometry.holes.HoleShape.features`) is given besides its
    table to place its holes.

    Attributes
    ----------
    first_index : int
        Index of its first hole: its holes are ``hole_<first_index>``, ``hole_<first_index + 1>``, …
    bores : tuple of Circle
        The crank-bearing bores.
    profile : Profile
        The tooth profile.
    """

    first_index: int
    bores: tuple[Circle, ...]
    profile: Profile

    def name(self, i: int) -> str:
        """Name of the shape's hole ``i`` (from 0): ``hole_<first_index + i>``."""
        return f"hole_{self.first_index + i}"


def _wall(a, b) -> Wall:
    """Thinnest wall between features a and b: min over dense points on a's outline of b's exact
    signed distance (and the other way round)."""
    best: tuple[float, tuple[float, float]] | None = None
    for f, g in ((a, b), (b, a)):
        pts = f.sample(max(WALL_SPACING, f.sampling_length / WALL_SAMPLES))
        d = g.signed_distance(pts)
        i = int(np.argmin(d))
        if best is None or d[i] < best[0]:
            best = (float(d[i]), (float(pts[i, 0]), float(pts[i, 1])))
    assert best is not None   # the loop runs twice
    return Wall(a.name, b.name, best[0], best[1])


def _profile_wall(profile: Profile, f) -> Wall:
    """Thinnest wall between the profile (its dense samples) and a feature (exact distance). A
    feature entirely outside the profile is caught separately in :func:`disc_geometry`."""
    pts = profile.points
    d = f.signed_distance(pts)
    i = int(np.argmin(d))
    return Wall("profile", f.name, float(d[i]), (float(pts[i, 0]), float(pts[i, 1])))


def _feature_keys(owners: dict, name: str, other: str) -> list[str]:
    """The case keys that move or resize feature ``name`` away from feature ``other``; ``owners``
    maps a hole's name to its (hole shape, table)."""
    if name == "central_hole":
        return ["cycloid.central_hole_radius"]
    if name == "profile":
        return []
    if name.startswith("bore_"):
        return ["crank_bearing.bore_radius", "cranks.circle_radius"]
    shape, table = owners[name]
    return list(shape.case_keys(table, other))


def _pair_keys(owners: dict, first: str, second: str) -> str:
    return _keys_text(_feature_keys(owners, second, first) + _feature_keys(owners, first, second))


def _holes(case: Case, bores: tuple[Circle, ...], profile: Profile) -> tuple[tuple[Feature, ...], dict]:
    """The lightening holes of every hole table of the case, numbered in table order, and the map
    of a hole's name to its (hole shape, table)."""
    holes: list = []
    owners: dict = {}
    for shape, table in case.hole_shapes():
        made = tuple(shape.features(case, table, HoleContext(len(holes), bores, profile)))
        expected = [f"hole_{len(holes) + i}" for i in range(len(made))]
        if [f.name for f in made] != expected:
            raise ValueError(f"hole shape {shape.__qualname__} named its holes {[f.name for f in made]}, "
                             f"expected {expected} (HoleContext.name)")
        owners.update((f.name, (shape, table)) for f in made)
        holes.extend(made)
    return tuple(holes), owners


def disc_geometry(case: Case) -> DiscGeometry:
    """Build the disc geometry of a case and check it before any meshing.

    Checks (each failure is a GeometryError that starts with the case's source, names the
    features, numbered from 1 ("bore 1", "hole 2"), and the case keys to change):

    * the profile has no undercut (see :func:`build_profile`);
    * each hole shape's own checks while it places its holes (:mod:`rvfem.geometry.holes`; fan
      holes: fillets fit, the ligament to the bores can be kept or, where the span cannot follow
      from it, why: holes in the teeth or in the central hole, or holes that never come that close
      to a bore);
    * every feature lies inside the profile and no two features (or a feature and the profile)
      overlap;
    * no wall (feature–feature or feature–profile) is thinner than ``mesh.min_wall``; the message
      gives the thinnest wall, its thickness and the two features.

    These checks are cheap (a fraction of a second) and are all of what meshing checks before
    Gmsh runs: ``rvfem check`` runs them too.

    Parameters
    ----------
    case : Case

    Returns
    -------
    DiscGeometry
    """
    try:
        return _disc_geometry(case)
    except GeometryError as exc:
        raise GeometryError(f"{case.source}: {exc}") from None


def _disc_geometry(case: Case) -> DiscGeometry:
    profile = build_profile(case)
    central = Circle("central_hole", (0.0, 0.0), case.cycloid.central_hole_radius)
    bores = tuple(Circle(f"bore_{i}", (float(x), float(y)), case.crank_bearing.bore_radius)
                  for i, (x, y) in enumerate(crank_centres(case)))
    holes, owners = _holes(case, bores, profile)
    features = (central,) + bores + holes
    for f in features:
        f.validate()

    # every feature inside the profile
    for f in features:
        pts = f.sample(max(0.5, f.sampling_length / 1000.0))   # enough to tell "entirely outside"
        outside = ~points_in_polygon(pts, profile.points)
        if np.all(outside):
            raise GeometryError(
                f"{feature_text(f.name)} lies entirely outside the cycloid profile (root radius "
                f"{profile.root_radius:.3f} mm); check its position and size "
                f"({_keys_text(_feature_keys(owners, f.name, 'profile'))})")

    walls = [_profile_wall(profile, f) for f in features]
    for i, f in enumerate(features):
        for g in features[i + 1:]:
            walls.append(_wall(f, g))
    walls.sort(key=lambda w: w.thickness)
    thinnest = walls[0]
    min_wall = case.mesh.min_wall
    first, second = feature_text(thinnest.first), feature_text(thinnest.second)
    near = f"near ({thinnest.location[0]:.2f}, {thinnest.location[1]:.2f}) mm"
    keys = _pair_keys(owners, thinnest.first, thinnest.second)
    if thinnest.thickness <= 0:
        depth = "touches" if thinnest.thickness == 0 else f"by {length_text(thinnest.thickness)}"
        if thinnest.first == "profile":
            what = "touches the teeth" if thinnest.thickness == 0 else f"cuts into the teeth {depth}"
            msg = f"{second} {what} (root radius {profile.root_radius:.3f} mm)"
        else:
            msg = f"{second} {'touches' if thinnest.thickness == 0 else 'overlaps'} {first}" \
                  + ("" if thinnest.thickness == 0 else f" {depth}")
        them = "it" if thinnest.first == "profile" else "them"
        raise GeometryError(f"{msg} {near}; move or shrink {them} ({keys})")
    if thinnest.thickness < min_wall:
        raise GeometryError(
            f"the wall between {first} and {second} is only {length_text(thinnest.thickness)} thick "
            f"(mesh.min_wall = {min_wall} mm), {near}; move or shrink the features ({keys}), or lower "
            "'mesh.min_wall' if such a thin wall is intended")
    return DiscGeometry(case=case, profile=profile, central_hole=central, bores=bores,
                        holes=holes, walls=tuple(walls))
