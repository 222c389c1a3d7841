"""A kind of lightening hole is one class: a hole shape defined only in this test module (slots,
registered by a fixture) is read from a case file, placed and checked on the disc, meshed and
cached (a changed dimension gives a new mesh), turned for disc B of the half-pitch model and
solved with the reducer stage, without any change to rvfem."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import CASES_DIR, CaseText

from rvfem.case.definition import (
    case_from_dict,
    case_to_dict,
    hole_table_names,
    load_case,
)
from rvfem.case.schema import param
from rvfem.errors import CaseError, GeometryError
from rvfem.geometry import (
    WALL_SPACING,
    Arc,
    HoleShape,
    LineSegment,
    default_angle_offset,
    disc_geometry,
    hole_shape,
    register_hole_shape,
    unregister_hole_shape,
)
from rvfem.mesh import mesh_case, mesh_key, mesh_path
from rvfem.solve import cycle

# ------------------------------------------------------------------------------------------------
# The slot holes: a table, a feature and a hole shape, nothing more
# ------------------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class SlotHoles:
    """Straight slots with round ends on a circle, each along the circle's tangent."""

    radius: float = param(unit="mm", low=0.5, high=2000.0, doc="radius of the circle of slot centres")
    length: float = param(unit="mm", low=0.1, high=1000.0, doc="overall length of a slot, > `width`")
    width: float = param(unit="mm", low=0.1, high=1000.0, doc="width of a slot")
    count: int = param(low=1, high=60, default_from=lambda values: values["cranks.count"],
                       default_doc="`cranks.count`", doc="number of slots")
    angle_deg: float | None = param(None, unit="deg", low=-360.0, high=360.0,
                                    default_doc="midway between the first two cranks",
                                    doc="angular position of the first slot's centre")

    def check(self, fail):
        if self.length <= self.width:
            raise fail("length", f"must exceed width ({self.width:g} mm)")

    @property
    def outline_length(self) -> float:
        return self.count * (2.0 * (self.length - self.width) + math.pi * self.width)


@dataclasses.dataclass(frozen=True)
class Slot:
    """One slot (a stadium): the points within width/2 of a segment of length − width along
    ``direction`` (rad) through ``centre``."""

    name: str
    centre: tuple[float, float]
    direction: float
    length: float
    width: float

    def _frame(self):
        t = np.array([math.cos(self.direction), math.sin(self.direction)])
        n = np.array([-t[1], t[0]])
        return np.asarray(self.centre), t, n, 0.5 * (self.length - self.width), 0.5 * self.width

    def validate(self) -> None:
        if not 0.0 < self.width < self.length:
            raise GeometryError(f"{self.name}: a slot must be longer than it is wide")

    def outline(self):
        c, t, n, a, r = self._frame()
        p, q = c - a * t, c + a * t

        def xy(v):
            return (float(v[0]), float(v[1]))

        return (LineSegment(xy(p - r * n), xy(q - r * n)),
                Arc(xy(q), r, self.direction - math.pi / 2, math.pi),
                LineSegment(xy(q + r * n), xy(p + r * n)),
                Arc(xy(p), r, self.direction + math.pi / 2, math.pi))

    def signed_distance(self, pts):
        c, t, _, a, r = self._frame()
        s = np.clip((pts - c) @ t, -a, a)
        return np.linalg.norm(pts - (c + s[:, None] * t), axis=1) - r

    def sample(self, spacing=WALL_SPACING):
        return np.concatenate([piece.sample(spacing)[:-1] for piece in self.outline()])

    @property
    def area(self) -> float:
        return (self.length - self.width) * self.width + math.pi * (0.5 * self.width) ** 2

    @property
    def sampling_length(self) -> float:
        return 2.0 * (self.length - self.width) + math.pi * self.width


class SlotHoleShape(HoleShape):
    name = "slot_holes"
    table = SlotHoles
    label = "slot holes"

    @classmethod
    def features(cls, case, table, context):
        first = default_angle_offset(case) if table.angle_deg is None else math.radians(table.angle_deg)
        slots = []
        for i in range(table.count):
            a = first + 2.0 * math.pi * i / table.count
            centre = (table.radius * math.cos(a), table.radius * math.sin(a))
            slots.append(Slot(context.name(i), centre, a + math.pi / 2, table.length, table.width))
        return tuple(slots)

    @classmethod
    def turned(cls, table, beta_deg):
        if table.angle_deg is None:
            return table
        return dataclasses.replace(table, angle_deg=table.angle_deg - beta_deg)

    @classmethod
    def describe(cls, table):
        return f"{table.count} × {table.length:g} × {table.width:g} mm on r = {table.radius:g} mm"

    @classmethod
    def case_keys(cls, table, other):
        return ["slot_holes.radius", "slot_holes.length", "slot_holes.width"]


SLOTS = "[slot_holes]\nradius = 40.0\nlength = 16.0\nwidth = 6.0\nangle_deg = 30.0\n"
COARSE = {"size_flank": 0.6, "size_bore": 0.6, "size_interior": 4.0}
THETA = np.radians(np.arange(0.0, 360.0, 30.0))


@pytest.fixture(scope="module")
def slots():
    """SlotHoleShape registered for the module's tests, unregistered afterwards."""
    register_hole_shape(SlotHoleShape)
    try:
        yield SlotHoleShape
    finally:
        unregister_hole_shape(SlotHoleShape.name)
    assert "slot_holes" not in hole_table_names()


def slotted(**slot):
    """The shipped solid RV-40E disc on a coarse mesh with three slots (``slot`` changes them)."""
    data = case_to_dict(load_case(CASES_DIR / "rv40e_solid.toml"))
    data["mesh"].update(COARSE)
    data["slot_holes"] = {"radius": 40.0, "length": 16.0, "width": 6.0, "angle_deg": 30.0, **slot}
    return case_from_dict(data, source="rv40e_solid with slots (coarse)")


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


@pytest.fixture(scope="module")
def slot_case(slots):
    return slotted()


@pytest.fixture(scope="module")
def slot_mesh(slot_case, cache):
    return mesh_case(slot_case, cache)


# ------------------------------------------------------------------------------------------------
# (a) the case file
# ------------------------------------------------------------------------------------------------


def test_a_registered_table_is_read_from_the_case_file(slots, tmp_path):
    path = CaseText.shipped("rv40e_solid").append(SLOTS).write(tmp_path)
    case = load_case(path)
    assert case.hole_table("slot_holes") == SlotHoles(radius=40.0, length=16.0, width=6.0, count=3, angle_deg=30.0)
    assert case.hole_shapes() == ((SlotHoleShape, case.hole_table("slot_holes")),)
    assert hole_shape("slot_holes") is SlotHoleShape
    assert case_from_dict(case_to_dict(case), source=str(path)) == case              # round trip
    assert case_to_dict(case)["slot_holes"]["count"] == 3                             # default from the cranks
    assert SlotHoleShape.describe(case.hole_table("slot_holes")) == "3 × 16 × 6 mm on r = 40 mm"
    wide = load_case(path, overrides=("slot_holes.width=5.0",))                      # --set works on it
    assert wide.hole_table("slot_holes").width == 5.0 and wide != case
    assert case.replace(slot_holes=None).hole_tables() == ()
    assert case.replace(slot_holes=dataclasses.replace(case.hole_table("slot_holes"), count=2)) \
        .hole_table("slot_holes").count == 2


@pytest.mark.parametrize("text, message", [
    (SLOTS.replace("width", "widht"), r"'slot_holes.widht' is not a known key \(did you mean 'slot_holes.width'\?\)"),
    (SLOTS.replace("slot_holes", "slot_hole"), r"'slot_hole' is not a known key \(did you mean 'slot_holes'\?\)"),
    (SLOTS.replace("width = 6.0", "width = -6.0"), r"'slot_holes.width' must be positive"),
    (SLOTS.replace("length = 16.0", "length = 5.0"), r"'slot_holes.length' must exceed width \(6 mm\)"),
    (SLOTS.replace("radius = 40.0", ""), r"'slot_holes.radius' is missing"),
])
def test_a_registered_table_is_checked_like_the_others(slots, tmp_path, text, message):
    path = CaseText.shipped("rv40e_solid").append(text).write(tmp_path)
    with pytest.raises(CaseError, match=message):
        load_case(path)


def test_without_the_shape_the_table_is_unknown_and_other_keys_unchanged(slots, tmp_path):
    path = CaseText.shipped("rv40e_solid").append(SLOTS).write(tmp_path)
    solid = load_case(CASES_DIR / "rv40e_solid.toml")
    key = mesh_key(solid)
    unregister_hole_shape("slot_holes")
    try:
        with pytest.raises(CaseError, match=r"'slot_holes' is not a known key"):
            load_case(path)
        assert mesh_key(solid) == key         # a registered shape does not touch the keys of other discs
    finally:
        register_hole_shape(SlotHoleShape)


def test_registration_refuses_clashes(slots):
    class Other(SlotHoleShape):
        pass

    with pytest.raises(ValueError, match="registered by SlotHoleShape"):
        register_hole_shape(Other)
    with pytest.raises(ValueError, match="a table of the case format already"):
        register_hole_shape(type("Loads", (SlotHoleShape,), {"name": "loads"}))
    with pytest.raises(ValueError, match="cannot be unregistered"):
        unregister_hole_shape("fan_holes")
    with pytest.raises(TypeError, match="subclass of HoleShape"):
        register_hole_shape(SlotHoles)
    register_hole_shape(SlotHoleShape)        # registering it again changes nothing
    assert hole_table_names() == ("fan_holes", "round_holes", "slot_holes")


# ------------------------------------------------------------------------------------------------
# (b) the geometry and the mesh, (c) the cache
# ------------------------------------------------------------------------------------------------


def test_slots_are_placed_checked_and_meshed(slot_case, slot_mesh):
    geom = disc_geometry(slot_case)
    assert [type(h) for h in geom.holes] == [Slot] * 3
    assert [h.name for h in geom.holes] == ["hole_0", "hole_1", "hole_2"]
    assert not slot_mesh.from_cache and slot_mesh.symmetry == 3
    for hole in geom.holes:
        xy = slot_mesh.points[slot_mesh.boundary_nodes(hole.name)]
        assert np.abs(hole.signed_distance(xy)).max() < 1e-9        # the boundary nodes lie on the slot
    assert slot_mesh.area == pytest.approx(geom.area, rel=1e-3)
    keys = r"'slot_holes.radius', 'slot_holes.length' or 'slot_holes.width'"     # the shape's keys
    with pytest.raises(GeometryError, match=r"hole [1-3] cuts into the teeth .*" + keys):
        disc_geometry(slotted(radius=57.0))


def test_the_cache_is_reused_and_a_changed_dimension_gives_a_new_mesh(slot_case, slot_mesh, cache):
    again = mesh_case(slot_case, cache)
    assert again.from_cache and again.path == slot_mesh.path == mesh_path(slot_case, cache)
    assert np.array_equal(again.points, slot_mesh.points)
    wider = slotted(width=7.0)
    assert mesh_key(wider) != mesh_key(slot_case)
    assert mesh_key(slot_case.replace(loads=dataclasses.replace(slot_case.loads, torque_Nm=99.0))) == \
        mesh_key(slot_case)                                           # not a shaping input: the same mesh
    new = mesh_case(wider, cache)
    assert not new.from_cache and new.path != slot_mesh.path
    assert new.area == pytest.approx(disc_geometry(wider).area, rel=1e-3) and new.area < slot_mesh.area - 30.0
    assert mesh_case(wider, cache).from_cache


# ------------------------------------------------------------------------------------------------
# (e) disc B, (d) the stage end to end
# ------------------------------------------------------------------------------------------------


def rotated(points, angle):
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, -s], [s, c]]).T


@pytest.mark.parametrize("angle_deg", [30.0, None])
def test_half_pitch_case_turns_the_slots_with_the_shapes_own_turn(slots, angle_deg):
    case = slotted(angle_deg=angle_deg)
    beta = cycle.second_disc_phase(case)
    b = cycle.half_pitch_case(case)
    if angle_deg is None:        # placed from the cranks: follows them unchanged
        assert b.hole_table("slot_holes") == case.hole_table("slot_holes")
    else:                        # placed by its own angle: turned by −β
        assert b.hole_table("slot_holes").angle_deg == pytest.approx(angle_deg - math.degrees(beta), abs=1e-12)
    # disc B's slots turned back by β are disc A's: they stay where the bores are
    holes_a, holes_b = disc_geometry(case).holes, disc_geometry(b).holes
    for ha, hb in zip(holes_a, holes_b):
        assert np.abs(ha.signed_distance(rotated(hb.sample(0.5), beta))).max() < 1e-9


def check_stage(result, case):
    assert all(r.solution.residual["relative"] < 1e-9 for r in result.solutions)
    assert result.equilibrium_residual.max() < 1e-9
    torque = case.loads.torque_Nm * 1000.0
    assert np.allclose(result.disc_torque_Nmm.sum(axis=1), torque, rtol=1e-9)   # the carrier balances
    assert np.all(np.isfinite(result.bearing_loads)) and result.bearing_loads.min() > 0


def test_the_slotted_disc_runs_the_two_disc_stage(slot_case, slot_mesh, cache):
    system = cycle.build_system(slot_case, slot_mesh)
    pair = cycle.load_cycle(system, THETA, saved_angles_deg=())
    assert pair.disc_torque_Nmm.shape == (len(THETA), 2)
    check_stage(pair, slot_case)
    b = cycle.half_pitch_case(slot_case)
    system_b = cycle.build_system(b, mesh_case(b, cache))
    stage = cycle.case_stage(system, second=system_b, second_disc="half_pitch")
    exact = cycle.load_cycle(system, THETA, saved_angles_deg=(), stage=stage)
    check_stage(exact, slot_case)
    # disc B's own model changes the loads a little, not wholesale
    assert exact.bearing_loads.max() == pytest.approx(pair.bearing_loads.max(), rel=0.05)
