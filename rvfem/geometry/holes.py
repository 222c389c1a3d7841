"""Hole shapes: one class for each kind of lightening hole.

A hole shape owns everything rvfem knows about one kind of lightening hole:

``name``, ``table``
    Its table of the case file (``[fan_holes]``) and the frozen dataclass it is read into, every
    key declared with :func:`rvfem.case.schema.param`. The dataclass has a property ``outline_length``
    (the length of all its holes' outlines, mm, for the mesh-size estimate) and may have a method
    ``check(fail)`` with the checks between its keys (:func:`rvfem.case.definition.register_hole_table`).
:meth:`HoleShape.features`
    The holes it cuts out of the disc, as :class:`~rvfem.geometry.Feature` objects named
    ``hole_<i>`` (:class:`~rvfem.geometry.HoleContext` gives the first index).
:meth:`HoleShape.mesh_key_part`
    What of its table shapes the mesh (:func:`rvfem.mesh.mesh_key`: a changed value gives a new
    cached mesh).
:meth:`HoleShape.turned`
    Its table for disc B of the half-pitch model, turned by −β
    (:func:`rvfem.solve.cycle.half_pitch_case`).
:meth:`HoleShape.describe`
    One line for the report and the screen, under the heading ``label``.
:meth:`HoleShape.case_keys`
    The case keys that move or resize its holes away from another feature (the geometry
    messages name them).

:func:`register_hole_shape` makes a shape known to the case reader (its table becomes a
top-level table of the case file), to :func:`~rvfem.geometry.disc_geometry`, to the mesh cache key
and to disc B; no other module names the kinds of holes. The holes are numbered in the order of
:func:`rvfem.case.definition.hole_table_names`: the fan holes, the round holes, then the registered shapes.

Example
-------
A shape defined outside the package (the test suite has one)::

    @register_hole_shape
    class SlotHoleShape(HoleShape):
        name, table, label = "slot_holes", SlotHoles, "slot holes"

        @classmethod
        def features(cls, case, table, context):
            return tuple(Slot(context.name(i), ...) for i in range(table.count))
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, ClassVar

import numpy as np
from scipy.optimize import brentq

from rvfem.case.definition import (
    Case,
    FanHoles,
    RoundHoles,
    register_hole_table,
    registered_hole_shapes,
    table_to_dict,
    unregister_hole_table,
)
from rvfem.errors import GeometryError
from rvfem.geometry.features import (
    Circle,
    FanHole,
    Feature,
    HoleContext,
    feature_text,
    length_text,
)
from rvfem.geometry.profile import Profile

__all__ = [
    "HoleShape",
    "FanHoleShape",
    "RoundHoleShape",
    "register_hole_shape",
    "unregister_hole_shape",
    "hole_shape",
    "default_angle_offset",
]


class HoleShape:
    """A kind of lightening hole (module docstring). Subclass it, set the class attributes and
    implement :meth:`features`; the other methods have defaults that fit a table with an
    ``angle_offset_deg`` key.

    Attributes
    ----------
    name : str
        The table's name in the case file, e.g. ``"fan_holes"``.
    table : type
        The frozen dataclass the table is read into.
    label : str
        What :meth:`describe` describes, e.g. ``"fan holes"``.
    always_in_mesh_key : bool
        The mesh key has an entry for the table even when the case has none (the built-in
        shapes: so that the keys, and the cached meshes, of earlier versions stay valid).
    """

    name: ClassVar[str] = ""
    table: ClassVar[type]
    label: ClassVar[str] = ""
    always_in_mesh_key: ClassVar[bool] = False

    @classmethod
    def features(cls, case: Case, table: Any, context: HoleContext) -> tuple[Feature, ...]:
        """The holes of ``table`` on the disc of ``case``, named ``context.name(0)``, … .

        Raises
        ------
        GeometryError
            The holes cannot be placed (naming the case keys to change).
        """
        raise NotImplementedError(f"{cls.__qualname__}.features")

    @classmethod
    def mesh_key_part(cls, table: Any) -> Any:
        """The part of the mesh cache key from ``table`` (JSON-serialisable): by default the whole
        table, as in the file (every key of a hole table shapes the mesh)."""
        return table_to_dict(table)

    @classmethod
    def turned(cls, table: Any, beta_deg: float) -> Any:
        """``table`` for the case turned by −β (disc B of the half-pitch model, whose cranks are
        turned by −β): by default an explicit ``angle_offset_deg`` is turned by −β; holes placed
        relative to the cranks (no offset given) follow the cranks unchanged."""
        offset = getattr(table, "angle_offset_deg", None)
        if offset is None:
            return table
        return dataclasses.replace(table, angle_offset_deg=offset - beta_deg)

    @classmethod
    def describe(cls, table: Any) -> str:
        """One line describing ``table`` (for the report and the screen): by default its keys."""
        return ", ".join(f"{k} = {v}" for k, v in table_to_dict(table).items())

    @classmethod
    def case_keys(cls, table: Any, other: str) -> list[str]:
        """The case keys that move or resize the holes away from feature ``other`` (a feature
        name: ``"profile"``, ``"central_hole"``, ``"bore_0"``, ``"hole_2"``, …); by default every
        key of the table."""
        return [f"{cls.name}.{f.name}" for f in dataclasses.fields(table)]


def register_hole_shape(cls: type) -> type:
    """Class decorator: make hole shape ``cls`` (a :class:`HoleShape`) known to the case reader,
    the geometry, the mesh cache and disc B (from any module, a test module included).

    Raises
    ------
    TypeError, ValueError
        ``cls`` is not a hole shape, or its table name or table cannot be registered
        (:func:`rvfem.case.definition.register_hole_table`).
    """
    if not (isinstance(cls, type) and issubclass(cls, HoleShape)):
        raise TypeError(f"a hole shape must be a subclass of HoleShape, got {cls!r}")
    register_hole_table(cls)
    return cls


def unregister_hole_shape(name: str) -> None:
    """Forget the hole shape of table ``name`` (not a built-in one)."""
    unregister_hole_table(name)


def hole_shape(name: str) -> type:
    """The registered hole shape of table ``name``.

    Raises
    ------
    KeyError
        No shape has that table.
    """
    shapes = {shape.name: shape for shape in registered_hole_shapes()}
    try:
        return shapes[name]
    except KeyError:
        raise KeyError(f"no hole shape has the table {name!r}; known: {', '.join(shapes)}") from None


def default_angle_offset(case: Case) -> float:
    """Where the first hole goes when its table gives no angle: midway between the first two
    cranks (circular mean), rad."""
    a = np.radians(case.cranks.angles_deg[:2])
    return float(np.angle(np.exp(1j * a[0]) + np.exp(1j * a[1])))


def _angle_offset(case: Case, table: Any) -> float:
    """The table's ``angle_offset_deg`` in rad, or :func:`default_angle_offset`."""
    return default_angle_offset(case) if table.angle_offset_deg is None else math.radians(table.angle_offset_deg)


# ------------------------------------------------------------------------------------------------
# Fan holes
# ------------------------------------------------------------------------------------------------


@register_hole_shape
class FanHoleShape(HoleShape):
    """Fan-shaped holes between the bores (:class:`rvfem.case.definition.FanHoles`): annular sectors with
    filleted corners, their span given or following from the ligament to the bores."""

    name = "fan_holes"
    table = FanHoles
    label = "fan holes"
    always_in_mesh_key = True

    @classmethod
    def features(cls, case: Case, table: FanHoles, context: HoleContext) -> tuple[FanHole, ...]:
        """The fan holes, the first centred on ``angle_offset_deg``; with ``ligament`` each span
        is the widest whose wall to every bore is the ligament (a root search)."""
        return tuple(_fan_holes(case, table, context))

    @classmethod
    def describe(cls, table: FanHoles) -> str:
        """E.g. ``3, r = 17…49 mm, ligament 4.5 mm, fillet 2 mm``."""
        span = f"span {table.span_deg:g}°" if table.span_deg is not None else f"ligament {table.ligament:g} mm"
        return (f"{table.count}, r = {table.inner_radius:g}…{table.outer_radius:g} mm, {span}, fillet "
                f"{table.fillet_radius:g} mm")

    @classmethod
    def case_keys(cls, table: FanHoles, other: str) -> list[str]:
        """The radius facing ``other``, or the span (or ligament) and the radii or the count."""
        span = "fan_holes.ligament" if table.ligament is not None else "fan_holes.span_deg"
        if other == "central_hole":
            return ["fan_holes.inner_radius"]
        if other == "profile":
            return ["fan_holes.outer_radius"]
        if other.startswith("bore_"):
            return [span, "fan_holes.inner_radius", "fan_holes.outer_radius"]
        return [span, "fan_holes.count"]


def _fan_hole(name: str, fan: FanHoles, angle: float, half_span: float) -> FanHole:
    return FanHole(name, fan.inner_radius, fan.outer_radius, angle, half_span, fan.fillet_radius)


def _fan_holes(case: Case, fan: FanHoles, context: HoleContext) -> list[FanHole]:
    bores, profile = context.bores, context.profile
    offset = _angle_offset(case, fan)
    angles = [offset + 2 * math.pi * i / fan.count for i in range(fan.count)]
    if fan.span_deg is not None:
        holes = [_fan_hole(context.name(i), fan, a, math.radians(fan.span_deg) / 2) for i, a in enumerate(angles)]
        for h in holes:
            h.validate()
        return holes
    if fan.outer_radius - fan.inner_radius <= 2 * fan.fillet_radius:
        _fan_hole(context.name(0), fan, angles[0], math.pi / fan.count).validate()   # raises the message
    # span from the ligament: the widest hole whose wall to every bore is ≥ ligament
    L = fan.ligament
    assert L is not None   # the span is given by span_deg or by the ligament (checked with the case)

    def wall(half_span: float, angle: float) -> float:
        return _hole_bore_wall(_fan_hole("probe", fan, angle, half_span), bores)

    holes = []
    for i, a in enumerate(angles):
        lo = _min_valid_half_span(fan, a)
        hi = math.pi / fan.count
        if wall(lo, a) < L or wall(hi, a) >= L:
            _fan_radii_outside_disc(case, fan, profile)   # the hole is in the wrong place: say so first
        if wall(lo, a) < L:
            raise GeometryError(
                f"{feature_text(context.name(i))}: 'fan_holes.ligament' = {L:g} mm cannot be kept: even the "
                f"narrowest hole with fillets of {fan.fillet_radius:g} mm leaves only {length_text(wall(lo, a))} "
                "to the nearest bore; reduce 'fan_holes.ligament', move the hole radially ('fan_holes.inner_radius', "
                "'fan_holes.outer_radius') or shrink the bores ('crank_bearing.bore_radius')")
        if wall(hi, a) >= L:
            raise GeometryError(
                f"{feature_text(context.name(i))}: even at its widest (a span of {360.0 / fan.count:.4g}°, where "
                f"neighbouring fan holes meet) it stays {length_text(wall(hi, a))} from the bores, more than "
                f"'fan_holes.ligament' = {L:g} mm, so the ligament cannot set the span; give 'fan_holes.span_deg' "
                "instead")
        half = brentq(lambda x: wall(x, a) - L, lo, hi, xtol=1e-12)
        h = _fan_hole(context.name(i), fan, a, half)
        h.validate()
        holes.append(h)
    return holes


def _fan_radii_outside_disc(case: Case, fan: FanHoles, profile: Profile) -> None:
    """Raise GeometryError if the fan holes' radii put them into the teeth or the central hole (for
    any span); called where the span cannot follow from the ligament, to give the reason that
    applies."""
    root = profile.root_radius
    central = case.cycloid.central_hole_radius
    if fan.outer_radius >= root:
        raise GeometryError(
            f"the fan holes at radii {fan.inner_radius:g}–{fan.outer_radius:g} mm cut the teeth (root radius "
            f"{root:.3f} mm): 'fan_holes.outer_radius' must stay below {root - case.mesh.min_wall:.3f} mm "
            "(the root radius less mesh.min_wall)")
    if fan.inner_radius <= central:
        raise GeometryError(
            f"the fan holes at radii {fan.inner_radius:g}–{fan.outer_radius:g} mm overlap the central hole "
            f"(radius {central:g} mm): 'fan_holes.inner_radius' must exceed {central + case.mesh.min_wall:g} mm "
            "(cycloid.central_hole_radius plus mesh.min_wall)")


def _min_valid_half_span(fan: FanHoles, angle: float) -> float:
    """Smallest half-span for which the fillets fit (bisection on FanHole.validate)."""
    lo, hi = 0.0, math.pi / fan.count
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        try:
            _fan_hole("probe", fan, angle, mid).validate()
            hi = mid
        except GeometryError:
            lo = mid
    return hi


def _hole_bore_wall(hole: Feature, bores: tuple[Circle, ...]) -> float:
    """Smallest wall between a hole and the bores, mm: the hole's exact signed distance to each bore
    centre minus the bore radius (negative when they overlap)."""
    centres = np.array([b.centre for b in bores], dtype=float)
    return float(np.min(hole.signed_distance(centres) - np.array([b.radius for b in bores])))


# ------------------------------------------------------------------------------------------------
# Round holes
# ------------------------------------------------------------------------------------------------


@register_hole_shape
class RoundHoleShape(HoleShape):
    """Round lightening holes on a circle (:class:`rvfem.case.definition.RoundHoles`)."""

    name = "round_holes"
    table = RoundHoles
    label = "round holes"
    always_in_mesh_key = True

    @classmethod
    def features(cls, case: Case, table: RoundHoles, context: HoleContext) -> tuple[Circle, ...]:
        """``count`` circles of ``radius`` on ``circle_radius``, the first at ``angle_offset_deg``."""
        offset = _angle_offset(case, table)
        out = []
        for i in range(table.count):
            a = offset + 2 * math.pi * i / table.count
            out.append(Circle(context.name(i), (table.circle_radius * math.cos(a),
                                                table.circle_radius * math.sin(a)), table.radius))
        return tuple(out)

    @classmethod
    def describe(cls, table: RoundHoles) -> str:
        """E.g. ``3 × r = 6 mm on r = 35 mm``."""
        return f"{table.count} × r = {table.radius:g} mm on r = {table.circle_radius:g} mm"

    @classmethod
    def case_keys(cls, table: RoundHoles, other: str) -> list[str]:
        """The hole radius and the radius of their circle."""
        return ["round_holes.radius", "round_holes.circle_radius"]
