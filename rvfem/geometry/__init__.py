"""Disc geometry: the cycloid profile, the drive kinematics and the disc's holes.

Everything is in the **disc's body frame**: the disc centre is the origin, the disc does not move,
and the pins move around it. Lengths are mm, angles radians (the case file's degrees are converted
on reading). One module per concern, every public name re-exported here
(``from rvfem.geometry import disc_geometry``):

:mod:`rvfem.geometry.profile`
    The cycloid profile (envelope of the pin circles, equidistant/shift/rotation modifications,
    pitch errors), its curvature and the undercut check.
:mod:`rvfem.geometry.kinematics`
    Pin centres and crank centres at a crank angle, pin–profile gaps, closest points on the
    profile.
:mod:`rvfem.geometry.features`
    The :class:`Feature` protocol, its implementations (:class:`Circle`, :class:`FanHole`) and the
    checked :class:`DiscGeometry` (:func:`disc_geometry`: overlaps, thin walls).
:mod:`rvfem.geometry.holes`
    The hole shapes: one :class:`HoleShape` class for each kind of lightening hole (its case
    table, its holes, its part of the mesh key, its turn for disc B, its description), the
    built-in :class:`FanHoleShape` and :class:`RoundHoleShape`, and :func:`register_hole_shape`
    for more.

The derivations are in docs/theory.md ("Kinematics", "Profile envelope and modifications").
"""

from __future__ import annotations

from rvfem.geometry.features import (
    WALL_SPACING,
    Arc,
    Circle,
    DiscGeometry,
    FanHole,
    Feature,
    HoleContext,
    LineSegment,
    Wall,
    disc_geometry,
    feature_text,
)
from rvfem.geometry.holes import (
    FanHoleShape,
    HoleShape,
    RoundHoleShape,
    default_angle_offset,
    hole_shape,
    register_hole_shape,
    unregister_hole_shape,
)
from rvfem.geometry.kinematics import (
    FlankDeviation,
    PinContacts,
    closest_points,
    crank_centres,
    load_cycle_angles,
    pin_centres,
    pin_phases,
    pin_profile_contacts,
    pin_profile_contacts_many,
)
from rvfem.geometry.profile import (
    PITCH_BLEND_FRACTION,
    SAMPLES_PER_SEGMENT,
    SPLINE_POINTS_PER_SEGMENT,
    Profile,
    build_profile,
    check_undercut,
    pitch_errors,
    profile_curvature,
    profile_eval,
    trochoid_curvature,
)

__all__ = [
    "load_cycle_angles",
    "Profile",
    "Feature",
    "Circle",
    "LineSegment",
    "Arc",
    "FanHole",
    "HoleContext",
    "HoleShape",
    "FanHoleShape",
    "RoundHoleShape",
    "register_hole_shape",
    "unregister_hole_shape",
    "hole_shape",
    "default_angle_offset",
    "Wall",
    "DiscGeometry",
    "PinContacts",
    "build_profile",
    "profile_eval",
    "profile_curvature",
    "pin_centres",
    "pin_phases",
    "FlankDeviation",
    "crank_centres",
    "pin_profile_contacts",
    "pin_profile_contacts_many",
    "closest_points",
    "disc_geometry",
    "feature_text",
    "check_undercut",
    "trochoid_curvature",
    "pitch_errors",
    "SAMPLES_PER_SEGMENT",
    "SPLINE_POINTS_PER_SEGMENT",
    "PITCH_BLEND_FRACTION",
    "WALL_SPACING",
]
