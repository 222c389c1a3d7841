"""Case files: one TOML file describes one reducer and one analysis.

A case file is read with the standard library (:mod:`tomllib`) and turned into small frozen
dataclasses. Units follow the project convention: lengths in mm, forces in N, moduli in MPa,
torque in N·m and speeds in rpm *in the file* (keys say so: ``torque_Nm``, ``speed_rpm``), angles in
degrees in the file (``*_deg``). The dataclasses keep the file's units; helpers such as
:attr:`Loads.disc_torque_Nmm` convert.

Validation is complete before anything is returned: an unknown or misspelled key (with the closest
known key suggested), a missing required key, a wrong type or a non-physical value raises
:class:`~rvfem.errors.CaseError` naming the file and the key. Nothing is half-read.

Example
-------
>>> from rvfem.case import load_case
>>> case = load_case("cases/rv40e_fanholes.toml")    # doctest: +SKIP
>>> case.pins.count, case.cycloid.teeth                # doctest: +SKIP
(40, 39)
"""

from __future__ import annotations

import dataclasses
import difflib
import hashlib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

from .errors import CaseError
from .registry import bearing_model_names, pin_model_names

__all__ = [
    "Case",
    "Cycloid",
    "ProfileModification",
    "PitchError",
    "Pins",
    "Cranks",
    "CrankBearing",
    "FanHoles",
    "RoundHoles",
    "Material",
    "DutyRow",
    "Loads",
    "Analysis",
    "MeshSettings",
    "load_case",
    "parse_override",
    "apply_overrides",
    "case_from_dict",
    "case_to_dict",
]


# --------------------------------------------------------------------------------------------
# Dataclasses (units in the file's convention; see module docstring)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ProfileModification:
    """Standard cycloid profile modifications (sign convention of Liu et al., *Degradation law
    analysis and life estimation of transmission accuracy of RV reducer ...*).

    Attributes
    ----------
    equidistant : float
        ΔRrp, mm. Increase of the generating pin radius; positive removes material.
    shift : float
        ΔRp, mm. Increase of the generating pin-circle radius; positive adds material at the tip.
    rotation_deg : float
        Rotation of the profile about the disc centre, degrees.
    """

    equidistant: float = 0.0
    shift: float = 0.0
    rotation_deg: float = 0.0


@dataclass(frozen=True)
class PitchError:
    """Per-tooth pitch (angular position) errors of the cycloid teeth, as a tangential offset in mm.

    Either the sinusoidal pattern of Li et al. (*Life calculation of the swivel-arm bearing of an
    RV reducer considering cycloid pitch error*), E_t(k) = E_t,max · sin((k − 1)·π/2) for tooth
    k = 1…Zc (``amplitude`` = E_t,max), or an explicit list of ``values`` (one per tooth).
    """

    amplitude: float = 0.0
    values: tuple[float, ...] = ()


@dataclass(frozen=True)
class Cycloid:
    """The cycloid disc.

    Attributes
    ----------
    teeth : int
        Number of lobes Zc.
    eccentricity : float
        Crank eccentricity e, mm.
    thickness : float
        Disc thickness (face width) b, mm; plane-stress thickness.
    central_hole_radius : float
        Radius of the central hole, mm.
    modification : ProfileModification
    pitch_error : PitchError
    """

    teeth: int
    eccentricity: float
    thickness: float
    central_hole_radius: float
    modification: ProfileModification = ProfileModification()
    pitch_error: PitchError = PitchError()


@dataclass(frozen=True)
class Pins:
    """The pin (needle-pin) ring fixed in the housing.

    Attributes
    ----------
    count : int
        Number of pins Zp.
    circle_radius : float
        Pin-circle radius Rp, mm.
    radius : float
        Pin radius r_rp, mm.
    model : str
        ``"rigid"`` (Signorini contact with a rigid pin) or ``"hertz"`` (the pin–tooth line
        contact adds its Hertz approach).
    """

    count: int
    circle_radius: float
    radius: float
    model: str = "rigid"


@dataclass(frozen=True)
class Cranks:
    """The crankshafts (turning arms) carried by the output carrier.

    Attributes
    ----------
    count : int
        Number of cranks N.
    circle_radius : float
        Radius r0 of the circle of crank (and bore) centres, mm.
    angles_deg : tuple of float
        Angular positions of the cranks on that circle, degrees. Default: equally spaced,
        the first at 90°.
    """

    count: int
    circle_radius: float
    angles_deg: tuple[float, ...]


@dataclass(frozen=True)
class CrankBearing:
    """The crank (turning-arm) bearing: rollers between the eccentric and the disc bore.

    Attributes
    ----------
    rollers : int
        Number of rollers Z.
    roller_diameter : float
        D_we, mm.
    roller_length : float
        Effective roller length L_we, mm.
    pitch_diameter : float
        D_m, mm.
    bore_radius : float
        Radius of the disc bore (outer raceway), mm; D_m/2 + D_we/2 for a full-complement
        bearing running directly on the disc.
    radial_clearance : float
        Diametral play of the bearing expressed as the radial clearance, mm (half of it on each
        side when centred).
    b_m, lambda_nu : float
        ISO 281 rating factors (material/manufacturing and edge-stress reduction).
    model : str
        ``"rollers"`` (discrete compression-only roller springs) or ``"rigid_bore"`` (bore tied to
        a rigid ring with one isotropic bearing spring).
    stiffness_law : str
        ``"palmgren"`` (line-contact load–deflection, both raceways) or ``"linear"``.
    linear_stiffness_N_per_mm : float or None
        Roller stiffness for the linear law, N/mm.
    rigid_bore_stiffness_N_per_mm : float
        Isotropic bearing stiffness of the ``rigid_bore`` model, N/mm.
    """

    rollers: int
    roller_diameter: float
    roller_length: float
    pitch_diameter: float
    bore_radius: float
    radial_clearance: float = 0.0
    b_m: float = 1.1
    lambda_nu: float = 0.83
    model: str = "rollers"
    stiffness_law: str = "palmgren"
    linear_stiffness_N_per_mm: float | None = None
    rigid_bore_stiffness_N_per_mm: float = 7.0e5

    @property
    def inner_raceway_radius(self) -> float:
        """Radius of the inner raceway (on the eccentric), mm."""
        return 0.5 * (self.pitch_diameter - self.roller_diameter)

    @property
    def outer_raceway_radius(self) -> float:
        """Radius of the outer raceway (the disc bore), mm."""
        return 0.5 * (self.pitch_diameter + self.roller_diameter)


@dataclass(frozen=True)
class FanHoles:
    """Fan-shaped lightening holes: annular sectors between the bores.

    Attributes
    ----------
    count : int
        Number of holes (default: one between each pair of neighbouring cranks).
    inner_radius, outer_radius : float
        Radial extent of the sector, mm.
    span_deg : float or None
        Angular span of a hole, degrees. Give this or ``ligament``.
    ligament : float or None
        Narrowest wall between a hole and the neighbouring bores, mm; the span follows from it.
    fillet_radius : float
        Corner fillet radius, mm.
    angle_offset_deg : float or None
        Angular position of the first hole's centre line, degrees; default midway between the
        first two cranks.
    """

    inner_radius: float
    outer_radius: float
    count: int
    span_deg: float | None = None
    ligament: float | None = None
    fillet_radius: float = 1.0
    angle_offset_deg: float | None = None


@dataclass(frozen=True)
class RoundHoles:
    """Round lightening holes on a circle (radius, circle radius, count)."""

    radius: float
    circle_radius: float
    count: int
    angle_offset_deg: float | None = None


@dataclass(frozen=True)
class Material:
    """Linear elastic material of the disc (and, for Hertz, of pins and rollers)."""

    name: str = "bearing steel"
    youngs_modulus: float = 206000.0
    poissons_ratio: float = 0.3


@dataclass(frozen=True)
class DutyRow:
    """One row of a duty cycle: share of time, output speed (rpm), output torque (N·m)."""

    time_share: float
    speed_rpm: float
    torque_Nm: float


@dataclass(frozen=True)
class Loads:
    """Operating point of the reducer.

    Attributes
    ----------
    torque_Nm : float
        Output torque T, N·m (the whole reducer).
    speed_rpm : float
        Output speed, rpm.
    discs : int
        Number of cycloid discs sharing the torque.
    duty_cycle : tuple of DutyRow
        Optional load spectrum.
    """

    torque_Nm: float
    speed_rpm: float
    discs: int = 2
    duty_cycle: tuple[DutyRow, ...] = ()

    @property
    def disc_torque_Nmm(self) -> float:
        """Torque carried by one disc, N·mm: T·1000 / discs (the handbook's T/2 for two discs)."""
        return self.torque_Nm * 1000.0 / self.discs


@dataclass(frozen=True)
class Analysis:
    """Analysis options.

    Attributes
    ----------
    equivalent_load_exponent : float
        Exponent p of the equivalent load (mean F^p)^(1/p); 10/3 for roller bearings (ISO 281),
        4 to reproduce Gao et al.
    angle_step_deg : float
        Crank-angle step of the load cycle, degrees.
    element_order : int
        1 (P1) or 2 (P2) triangles.
    friction : float
        Coulomb friction coefficient at the pins (force μ·λ along the known sliding direction,
        the pin centre's velocity relative to the disc).
    max_active_set_iterations : int
        Bound of the contact active-set loop.
    saved_angles_deg : tuple of float
        Crank angles at which displacement/stress fields are kept for output.
    """

    equivalent_load_exponent: float = 10.0 / 3.0
    angle_step_deg: float = 1.0
    element_order: int = 1
    friction: float = 0.0
    max_active_set_iterations: int = 50
    saved_angles_deg: tuple[float, ...] = (0.0, 90.0, 180.0, 270.0)


@dataclass(frozen=True)
class MeshSettings:
    """Target element sizes (mm) and the thinnest wall the geometry check accepts.

    ``size_hole`` is the size on the central hole and the lightening holes (their fillets carry
    the structural stress peaks); None means twice ``size_bore``, capped by ``size_interior``.
    """

    size_flank: float = 0.4
    size_bore: float = 0.4
    size_interior: float = 2.5
    min_wall: float = 1.0
    size_hole: float | None = None


@dataclass(frozen=True)
class Case:
    """One reducer and one analysis, validated. See the module docstring for units."""

    name: str
    cycloid: Cycloid
    pins: Pins
    cranks: Cranks
    crank_bearing: CrankBearing
    material: Material
    loads: Loads
    analysis: Analysis = Analysis()
    mesh: MeshSettings = MeshSettings()
    fan_holes: FanHoles | None = None
    round_holes: RoundHoles | None = None
    description: str = ""
    source: str = field(default="<code>", compare=False)
    overrides: tuple[str, ...] = field(default=(), compare=False)

    @property
    def short_amplitude_coefficient(self) -> float:
        """k = e·Zp/Rp (must be < 1 for a non-looping epitrochoid)."""
        return self.cycloid.eccentricity * self.pins.count / self.pins.circle_radius

    def replace(self, **changes: Any) -> "Case":
        """A copy with top-level fields replaced (validated again)."""
        data = case_to_dict(dataclasses.replace(self, **changes))
        return case_from_dict(data, source=self.source)

    def digest(self) -> str:
        """sha256 of the canonical case data (used to name cached meshes and results)."""
        return hashlib.sha256(repr(case_to_dict(self)).encode()).hexdigest()


# --------------------------------------------------------------------------------------------
# Reading and validation
# --------------------------------------------------------------------------------------------


class _Table:
    """Reads keys from one TOML table, remembering which were used, and reports problems with the
    full dotted key and the file name."""

    def __init__(self, data: Any, path: str, source: str):
        self.path = path
        self.source = source
        if not isinstance(data, dict):
            raise self.error(path or "<top>", f"must be a table, got {type(data).__name__}")
        self.data = data
        self.used: set[str] = set()

    def key(self, name: str) -> str:
        return f"{self.path}.{name}" if self.path else name

    def error(self, key: str, message: str) -> CaseError:
        return CaseError(f"{self.source}: '{key}' {message}")

    def has(self, name: str) -> bool:
        return name in self.data

    def get(self, name: str, kind: str, default: Any = ..., *, choices: tuple[str, ...] = ()) -> Any:
        """Value of ``name`` converted to ``kind`` ('int', 'float', 'str', 'floats')."""
        self.used.add(name)
        key = self.key(name)
        if name not in self.data:
            if default is ...:
                raise self.error(key, "is missing (required)")
            return default
        value = self.data[name]
        if kind == "int":
            if isinstance(value, bool) or not isinstance(value, int):
                raise self.error(key, f"must be an integer, got {value!r}")
        elif kind == "float":
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise self.error(key, f"must be a number, got {value!r}")
            value = float(value)
            if not math.isfinite(value):
                raise self.error(key, f"must be finite, got {value!r}")
        elif kind == "str":
            if not isinstance(value, str):
                raise self.error(key, f"must be a string, got {value!r}")
            if choices and value not in choices:
                hint = _closest(value, choices)
                raise self.error(
                    key,
                    f"must be one of {', '.join(repr(c) for c in choices)}, got {value!r}"
                    + (f" (did you mean {hint!r}?)" if hint else ""),
                )
        elif kind == "floats":
            if not isinstance(value, list) or any(
                isinstance(v, bool) or not isinstance(v, (int, float)) for v in value
            ):
                raise self.error(key, f"must be a list of numbers, got {value!r}")
            value = tuple(float(v) for v in value)
        else:  # pragma: no cover - programming error
            raise AssertionError(kind)
        return value

    def sub(self, name: str, required: bool = True) -> "_Table | None":
        self.used.add(name)
        if name not in self.data:
            if required:
                raise self.error(self.key(name), "is missing (required table)")
            return None
        return _Table(self.data[name], self.key(name), self.source)

    def finish(self, known: tuple[str, ...] = ()) -> None:
        """Raise on any key that was not read (misspelled or unknown)."""
        for name in self.data:
            if name not in self.used:
                hint = _closest(name, tuple(self.used) + known)
                raise self.error(
                    self.key(name),
                    "is not a known key"
                    + (f" (did you mean '{self.key(hint)}'?)" if hint else "")
                    + "; remove it or check the spelling",
                )


def _closest(word: str, options: tuple[str, ...]) -> str | None:
    match = difflib.get_close_matches(word, options, n=1, cutoff=0.6)
    return match[0] if match else None


def _positive(t: _Table, name: str, value: float | int | None, *, allow_zero: bool = False) -> None:
    if value is None:
        return
    if value < 0 or (value == 0 and not allow_zero):
        need = "non-negative" if allow_zero else "positive"
        raise t.error(t.key(name), f"must be {need}, got {value!r}")


def _read_modification(t: _Table | None) -> ProfileModification:
    if t is None:
        return ProfileModification()
    m = ProfileModification(
        equidistant=t.get("equidistant", "float", 0.0),
        shift=t.get("shift", "float", 0.0),
        rotation_deg=t.get("rotation_deg", "float", 0.0),
    )
    t.finish()
    return m


def _read_pitch_error(t: _Table | None, teeth: int) -> PitchError:
    if t is None:
        return PitchError()
    p = PitchError(amplitude=t.get("amplitude", "float", 0.0), values=t.get("values", "floats", ()))
    t.finish()
    if p.values and len(p.values) != teeth:
        raise t.error(t.key("values"), f"must have one value per tooth ({teeth}), got {len(p.values)}")
    if p.values and p.amplitude:
        raise t.error(t.key("amplitude"), "and 'values' exclude each other; give one of them")
    return p


def case_from_dict(data: dict, source: str = "<dict>") -> Case:
    """Validate a parsed case (a dict shaped like the TOML file) and build a :class:`Case`.

    Raises
    ------
    CaseError
        With the file (``source``) and the dotted key of the first problem found.
    """
    top = _Table(data, "", source)
    name = top.get("name", "str", Path(source).stem if source.endswith(".toml") else "case")
    description = top.get("description", "str", "")

    # cycloid ---------------------------------------------------------------------------------
    t = top.sub("cycloid")
    teeth = t.get("teeth", "int")
    ecc = t.get("eccentricity", "float")
    thick = t.get("thickness", "float")
    hole = t.get("central_hole_radius", "float")
    modification = _read_modification(t.sub("modification", required=False))
    pitch_error = _read_pitch_error(t.sub("pitch_error", required=False), teeth)
    t.finish()
    _positive(t, "teeth", teeth)
    for key, val in (("eccentricity", ecc), ("thickness", thick), ("central_hole_radius", hole)):
        _positive(t, key, val)
    cycloid = Cycloid(teeth, ecc, thick, hole, modification, pitch_error)

    # pins ------------------------------------------------------------------------------------
    t = top.sub("pins")
    pins = Pins(
        count=t.get("count", "int"),
        circle_radius=t.get("circle_radius", "float"),
        radius=t.get("radius", "float"),
        model=t.get("model", "str", "rigid", choices=pin_model_names()),
    )
    t.finish()
    for key in ("count", "circle_radius", "radius"):
        _positive(t, key, getattr(pins, key))
    if pins.count <= teeth:
        raise t.error(
            t.key("count"),
            f"(Zp = {pins.count}) must exceed cycloid.teeth (Zc = {teeth}); "
            "a cycloid drive needs more pins than lobes",
        )
    k = ecc * pins.count / pins.circle_radius
    if k >= 1.0:
        raise top.error(
            "cycloid.eccentricity",
            f"is too large: the short-amplitude coefficient k = e·Zp/Rp = {k:.3f} must be < 1 "
            "(reduce the eccentricity or enlarge pins.circle_radius)",
        )
    if pins.radius >= pins.circle_radius * math.sin(math.pi / pins.count):
        raise t.error(t.key("radius"), f"({pins.radius} mm) is too large: neighbouring pins overlap")

    # cranks ----------------------------------------------------------------------------------
    t = top.sub("cranks")
    n = t.get("count", "int")
    _positive(t, "count", n)
    if n < 2:
        raise t.error(t.key("count"), f"must be at least 2, got {n}")
    r0 = t.get("circle_radius", "float")
    _positive(t, "circle_radius", r0)
    angles = t.get("angles_deg", "floats", tuple(90.0 + 360.0 * i / n for i in range(n)))
    t.finish()
    if len(angles) != n:
        raise t.error(t.key("angles_deg"), f"must list {n} angles (cranks.count), got {len(angles)}")
    cranks = Cranks(n, r0, angles)

    # crank bearing ---------------------------------------------------------------------------
    t = top.sub("crank_bearing")
    bearing = CrankBearing(
        rollers=t.get("rollers", "int"),
        roller_diameter=t.get("roller_diameter", "float"),
        roller_length=t.get("roller_length", "float"),
        pitch_diameter=t.get("pitch_diameter", "float"),
        bore_radius=t.get("bore_radius", "float"),
        radial_clearance=t.get("radial_clearance", "float", 0.0),
        b_m=t.get("b_m", "float", 1.1),
        lambda_nu=t.get("lambda_nu", "float", 0.83),
        model=t.get("model", "str", "rollers", choices=bearing_model_names()),
        stiffness_law=t.get("stiffness_law", "str", "palmgren", choices=("palmgren", "linear")),
        linear_stiffness_N_per_mm=t.get("linear_stiffness_N_per_mm", "float", None),
        rigid_bore_stiffness_N_per_mm=t.get("rigid_bore_stiffness_N_per_mm", "float", 7.0e5),
    )
    t.finish()
    for key in ("rollers", "roller_diameter", "roller_length", "pitch_diameter", "bore_radius",
                "b_m", "lambda_nu", "rigid_bore_stiffness_N_per_mm"):
        _positive(t, key, getattr(bearing, key))
    _positive(t, "radial_clearance", bearing.radial_clearance, allow_zero=True)
    _positive(t, "linear_stiffness_N_per_mm", bearing.linear_stiffness_N_per_mm)
    if bearing.stiffness_law == "linear" and bearing.linear_stiffness_N_per_mm is None:
        raise t.error(t.key("linear_stiffness_N_per_mm"), "is missing (required when stiffness_law = 'linear')")
    if bearing.roller_diameter >= bearing.pitch_diameter:
        raise t.error(t.key("roller_diameter"), "must be smaller than pitch_diameter")
    gap = math.pi * bearing.pitch_diameter - bearing.rollers * bearing.roller_diameter
    if gap <= 0:
        raise t.error(
            t.key("rollers"),
            f": {bearing.rollers} rollers of {bearing.roller_diameter} mm do not fit the pitch circle "
            f"of {bearing.pitch_diameter} mm (circumference {math.pi * bearing.pitch_diameter:.2f} mm)",
        )
    if bearing.bore_radius <= 0.5 * bearing.pitch_diameter:
        raise t.error(
            t.key("bore_radius"),
            f"({bearing.bore_radius} mm) must exceed half the pitch diameter ({0.5 * bearing.pitch_diameter} mm)",
        )

    # holes -----------------------------------------------------------------------------------
    fan = None
    t = top.sub("fan_holes", required=False)
    if t is not None:
        fan = FanHoles(
            inner_radius=t.get("inner_radius", "float"),
            outer_radius=t.get("outer_radius", "float"),
            count=t.get("count", "int", n),
            span_deg=t.get("span_deg", "float", None),
            ligament=t.get("ligament", "float", None),
            fillet_radius=t.get("fillet_radius", "float", 1.0),
            angle_offset_deg=t.get("angle_offset_deg", "float", None),
        )
        t.finish()
        for key in ("inner_radius", "outer_radius", "count", "span_deg", "ligament"):
            _positive(t, key, getattr(fan, key))
        _positive(t, "fillet_radius", fan.fillet_radius, allow_zero=True)
        if fan.outer_radius <= fan.inner_radius:
            raise t.error(t.key("outer_radius"), "must exceed inner_radius")
        if (fan.span_deg is None) == (fan.ligament is None):
            raise t.error(t.key("span_deg"), "or 'ligament': give exactly one of them")
        if fan.span_deg is not None and fan.span_deg * fan.count >= 360.0:
            raise t.error(t.key("span_deg"), f"× count must stay below 360°, got {fan.span_deg * fan.count}°")
    rnd = None
    t = top.sub("round_holes", required=False)
    if t is not None:
        rnd = RoundHoles(
            radius=t.get("radius", "float"),
            circle_radius=t.get("circle_radius", "float"),
            count=t.get("count", "int", n),
            angle_offset_deg=t.get("angle_offset_deg", "float", None),
        )
        t.finish()
        for key in ("radius", "circle_radius", "count"):
            _positive(t, key, getattr(rnd, key))

    # material --------------------------------------------------------------------------------
    t = top.sub("material", required=False) or _Table({}, "material", source)
    material = Material(
        name=t.get("name", "str", "bearing steel"),
        youngs_modulus=t.get("youngs_modulus", "float", 206000.0),
        poissons_ratio=t.get("poissons_ratio", "float", 0.3),
    )
    t.finish()
    _positive(t, "youngs_modulus", material.youngs_modulus)
    if not 0.0 <= material.poissons_ratio < 0.5:
        raise t.error(t.key("poissons_ratio"), f"must lie in [0, 0.5), got {material.poissons_ratio}")

    # loads -----------------------------------------------------------------------------------
    t = top.sub("loads")
    rows = []
    raw_rows = t.data.get("duty_cycle", [])
    t.used.add("duty_cycle")
    if not isinstance(raw_rows, list):
        raise t.error(t.key("duty_cycle"), "must be an array of tables ([[loads.duty_cycle]])")
    for i, raw in enumerate(raw_rows):
        r = _Table(raw, f"{t.key('duty_cycle')}[{i}]", source)
        row = DutyRow(r.get("time_share", "float"), r.get("speed_rpm", "float"), r.get("torque_Nm", "float"))
        r.finish()
        _positive(r, "time_share", row.time_share)
        _positive(r, "speed_rpm", row.speed_rpm)
        _positive(r, "torque_Nm", row.torque_Nm, allow_zero=True)
        rows.append(row)
    loads = Loads(
        torque_Nm=t.get("torque_Nm", "float"),
        speed_rpm=t.get("speed_rpm", "float"),
        discs=t.get("discs", "int", 2),
        duty_cycle=tuple(rows),
    )
    t.finish()
    for key in ("torque_Nm", "speed_rpm", "discs"):
        _positive(t, key, getattr(loads, key))

    # analysis --------------------------------------------------------------------------------
    t = top.sub("analysis", required=False) or _Table({}, "analysis", source)
    analysis = Analysis(
        equivalent_load_exponent=t.get("equivalent_load_exponent", "float", 10.0 / 3.0),
        angle_step_deg=t.get("angle_step_deg", "float", 1.0),
        element_order=t.get("element_order", "int", 1),
        friction=t.get("friction", "float", 0.0),
        max_active_set_iterations=t.get("max_active_set_iterations", "int", 50),
        saved_angles_deg=t.get("saved_angles_deg", "floats", (0.0, 90.0, 180.0, 270.0)),
    )
    t.finish()
    _positive(t, "equivalent_load_exponent", analysis.equivalent_load_exponent)
    _positive(t, "angle_step_deg", analysis.angle_step_deg)
    _positive(t, "friction", analysis.friction, allow_zero=True)
    _positive(t, "max_active_set_iterations", analysis.max_active_set_iterations)
    if analysis.element_order not in (1, 2):
        raise t.error(t.key("element_order"), f"must be 1 (P1) or 2 (P2), got {analysis.element_order}")
    if analysis.angle_step_deg > 30.0:
        raise t.error(t.key("angle_step_deg"), f"must be at most 30°, got {analysis.angle_step_deg}")

    # mesh ------------------------------------------------------------------------------------
    t = top.sub("mesh", required=False) or _Table({}, "mesh", source)
    mesh = MeshSettings(
        size_flank=t.get("size_flank", "float", 0.4),
        size_bore=t.get("size_bore", "float", 0.4),
        size_interior=t.get("size_interior", "float", 2.5),
        min_wall=t.get("min_wall", "float", 1.0),
        size_hole=t.get("size_hole", "float", None),
    )
    t.finish()
    for key in ("size_flank", "size_bore", "size_interior", "min_wall", "size_hole"):
        _positive(t, key, getattr(mesh, key))

    top.finish()
    return Case(
        name=name,
        description=description,
        cycloid=cycloid,
        pins=pins,
        cranks=cranks,
        crank_bearing=bearing,
        material=material,
        loads=loads,
        analysis=analysis,
        mesh=mesh,
        fan_holes=fan,
        round_holes=rnd,
        source=source,
    )


def parse_override(text: str) -> tuple[tuple[str, ...], Any]:
    """Split an override ``KEY=VALUE`` into the dotted key's parts and the value.

    The value is a TOML literal (``4.5``, ``"rigid_bore"``, ``[1.0, 2.0]``, ``true``); a bare word
    that is not a TOML literal is taken as a string (``crank_bearing.model=rigid_bore``).
    """
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep or not key or any(not part.strip() for part in key.split(".")):
        raise CaseError(f"override {text!r}: expected KEY=VALUE with a dotted key of the case format, "
                        "e.g. fan_holes.ligament=4.0")
    value = value.strip()
    try:
        parsed = tomllib.loads(f"v = {value}")["v"]
    except tomllib.TOMLDecodeError:
        if not value or any(c in value for c in "[]{}\"\'=,"):
            raise CaseError(f"override {text!r}: {value!r} is not a TOML value") from None
        parsed = value
    return tuple(part.strip() for part in key.split(".")), parsed


def apply_overrides(data: dict, overrides: Sequence[str]) -> dict:
    """A copy of the parsed case ``data`` with the ``KEY=VALUE`` overrides applied (not validated:
    :func:`case_from_dict` validates the result like a file, unknown keys included)."""
    import copy

    data = copy.deepcopy(data)
    for text in overrides:
        parts, value = parse_override(text)
        table = data
        for depth, part in enumerate(parts[:-1]):
            nxt = table.setdefault(part, {})
            if not isinstance(nxt, dict):
                raise CaseError(f"override {text!r}: {'.'.join(parts[:depth + 1])} is not a table")
            table = nxt
        table[parts[-1]] = value
    return data


def load_case(path: str | Path, overrides: Sequence[str] = ()) -> Case:
    """Read and validate a TOML case file, optionally with overrides.

    Parameters
    ----------
    path : path
    overrides : sequence of str
        ``KEY=VALUE`` strings (see :func:`parse_override`), applied to the file's data before
        validation, so an override is checked exactly like the file (an unknown key gets a
        "did you mean"). They are recorded in :attr:`Case.overrides`.

    Raises
    ------
    CaseError
        If the file is missing, is not valid TOML, or any key is missing, unknown, mistyped or
        non-physical. The message names the file and the key.
    """
    path = Path(path)
    try:
        text = path.read_bytes()
    except OSError as exc:
        raise CaseError(f"{path}: cannot read the case file ({exc.strerror or exc})") from None
    try:
        data = tomllib.loads(text.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise CaseError(f"{path}: not a valid TOML file ({exc})") from None
    overrides = tuple(overrides)
    if not overrides:
        return case_from_dict(data, source=str(path))
    case = case_from_dict(apply_overrides(data, overrides), source=f"{path} (with overrides)")
    return dataclasses.replace(case, overrides=overrides)


def case_to_dict(case: Case) -> dict:
    """The case as a plain dict in the file's layout (round-trips through :func:`case_from_dict`)."""

    def clean(obj: Any) -> Any:
        if dataclasses.is_dataclass(obj):
            return {f.name: clean(getattr(obj, f.name)) for f in dataclasses.fields(obj)
                    if getattr(obj, f.name) is not None and f.name not in ("source", "overrides")}
        if isinstance(obj, tuple):
            return [clean(v) for v in obj]
        return obj

    data = clean(case)
    data["loads"]["duty_cycle"] = data["loads"].get("duty_cycle", [])
    return data


def file_sha256(path: str | Path) -> str:
    """sha256 of a file's bytes (recorded in results so they can be traced to their case file)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()
