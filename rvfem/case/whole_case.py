"""The whole case: :class:`Case` over the tables of :mod:`rvfem.case.tables`, the rule for its
name, the registry of hole tables, the checks across keys and tables that :class:`Case` runs on
construction (in the order of ``_CROSS_CHECKS``; they need no geometry: the mesh-size limits are
estimates from the case's numbers) and the case as a plain dict in the file's layout.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from rvfem.case.registry import model_requires
from rvfem.case.schema import check_fields, file_fields, param, table_error
from rvfem.case.tables import (
    ROLLER_PROFILE_KINDS,
    Analysis,
    CrankBearing,
    Cranks,
    CrankSupport,
    Cycloid,
    FanHoles,
    Loads,
    Lubricant,
    Wear,
    Material,
    MeshSettings,
    Pins,
    RollerProfile,
    RoundHoles,
)
from rvfem.case.mesh_checks import (
    BORE_FOOTPRINT_FRACTION,
    FLANK_FOOTPRINT_FRACTION,
    FOOTPRINT_ELEMENTS,
    MAX_MESH_NODES,
    check_mesh,
    check_mesh_sizes,
    estimated_mesh_nodes,
    max_element_sizes,
)
from rvfem.errors import CaseError

__all__ = [
    "MAX_NAME_LENGTH",
    "NAME_CHARACTERS",
    "name_problem",
    "Case",
    "BUILTIN_HOLE_TABLES",
    "register_hole_table",
    "unregister_hole_table",
    "hole_table_names",
    "registered_hole_shapes",
    "ComponentTable",
    "register_component_table",
    "unregister_component_table",
    "component_tables",
    "MIN_DUTY_TORQUE_NM",
    "MAX_MESH_NODES",
    "estimated_mesh_nodes",
    "FOOTPRINT_ELEMENTS",
    "BORE_FOOTPRINT_FRACTION",
    "FLANK_FOOTPRINT_FRACTION",
    "max_element_sizes",
    "table_to_dict",
    "case_to_dict",
]


# --------------------------------------------------------------------------------------------
# Hole tables. A kind of lightening hole is one hole shape (rvfem.geometry.holes.HoleShape) that
# owns one table of the case file. The built-in tables are fields of Case; the table of a shape
# registered later (rvfem.geometry.holes.register_hole_shape, from any module, a test module
# included) is read into Case.other_holes and is a top-level table of the file like them.
# --------------------------------------------------------------------------------------------

BUILTIN_HOLE_TABLES = ("fan_holes", "round_holes")
"""The hole tables that are fields of :class:`Case`, in the order their holes are numbered."""

_BUILTIN_HOLE_CLASSES = {"fan_holes": FanHoles, "round_holes": RoundHoles}
_HOLE_SHAPES: dict[str, type[Any]] = {}


def register_hole_table(shape: type) -> None:
    """Make ``shape.table`` (a frozen dataclass declared with :func:`~rvfem.case.schema.param`) the table
    ``[shape.name]`` of the case format. Use :func:`rvfem.geometry.holes.register_hole_shape`,
    which calls this.

    The table class must have a property ``outline_length`` (the length of all its holes'
    outlines, mm, for :func:`estimated_mesh_nodes`) and may have a method ``check(fail)`` with
    the checks between its keys (``fail(key, message)`` returns the error to raise).

    Raises
    ------
    ValueError
        ``shape.name`` is not a valid table name, names another table of the case format, or is
        registered by another shape.
    TypeError
        ``shape.table`` is not such a dataclass.
    """
    name, table = getattr(shape, "name", None), getattr(shape, "table", None)
    if not (isinstance(name, str) and name.isidentifier()):
        raise ValueError(f"a hole shape needs a table name (a Python identifier), got {name!r}")
    if name in _BUILTIN_HOLE_CLASSES and table is not _BUILTIN_HOLE_CLASSES[name]:
        raise ValueError(f"the table {name!r} is read as {_BUILTIN_HOLE_CLASSES[name].__name__}")
    if name not in _BUILTIN_HOLE_CLASSES and (name in {f.name for f in dataclasses.fields(Case)}
                                              or name in _COMPONENT_TABLES):
        raise ValueError(f"{name!r} is a table of the case format already")
    if _HOLE_SHAPES.get(name, shape) is not shape:
        raise ValueError(f"the hole table {name!r} is registered by {_HOLE_SHAPES[name].__qualname__} already")
    if not (isinstance(table, type) and dataclasses.is_dataclass(table) and getattr(table, "__dataclass_params__").frozen):
        raise TypeError(f"the table of hole shape {name!r} must be a frozen dataclass, got {table!r}")
    file_fields(table)     # every key declared with param (raises TypeError otherwise)
    if not hasattr(table, "outline_length"):
        raise TypeError(f"{table.__name__} (table {name!r}) needs a property 'outline_length'")
    _HOLE_SHAPES[name] = shape


def unregister_hole_table(name: str) -> None:
    """Remove the table ``name`` of a registered hole shape from the case format (a built-in
    table cannot be removed; an unknown name is ignored)."""
    if name in BUILTIN_HOLE_TABLES:
        raise ValueError(f"the built-in hole table {name!r} cannot be unregistered")
    _HOLE_SHAPES.pop(name, None)


def hole_table_names() -> tuple[str, ...]:
    """The hole tables of the case format, in the order their holes are numbered: the built-in
    ones, then those of the registered hole shapes in the order they were registered."""
    return tuple(dict.fromkeys([*BUILTIN_HOLE_TABLES, *_HOLE_SHAPES]))


def registered_hole_shapes() -> tuple[type[Any], ...]:
    """The registered hole shapes, in the order of :func:`hole_table_names`."""
    return tuple(_HOLE_SHAPES[name] for name in hole_table_names() if name in _HOLE_SHAPES)


def _other_hole_names() -> tuple[str, ...]:
    """The registered hole tables that are not fields of :class:`Case`."""
    return tuple(name for name in _HOLE_SHAPES if name not in BUILTIN_HOLE_TABLES)


# --------------------------------------------------------------------------------------------
# Tables of stage components. A part of the reducer stage registered from outside the case's
# fields (rvfem.solve.stage_parts.register_stage_component, from any module, a test module
# included) may own a table of the case file: the one registration point for its schema is
# register_component_table. Its table is read into Case.component_tables and is a top-level
# table of the file like the built-in ones; unknown keys in it are refused as anywhere else.
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ComponentTable:
    """The table of a stage component in the case format.

    Attributes
    ----------
    name : str
        The table's name in the case file (``[name]``).
    schema : type
        Its keys: a frozen dataclass whose fields are declared with
        :func:`~rvfem.case.schema.param` (type, unit, default, bounds, meaning). It may have a
        method ``check(fail)`` with the checks between its keys (``fail(key, message)`` returns the
        error to raise).
    by_default : bool
        True: a case that does not give the table has it with its defaults (every key then needs a
        default); False: without the table the case does not have the component.
    owner : str
        The component's name, for messages.
    """

    name: str
    schema: type[Any]
    by_default: bool = False
    owner: str = ""


_COMPONENT_TABLES: dict[str, ComponentTable] = {}


def register_component_table(name: str, schema: type, *, by_default: bool = False, owner: str = "") -> None:
    """Make ``schema`` the table ``[name]`` of the case format, owned by the stage component
    ``owner``. Use :func:`rvfem.solve.stage_parts.register_stage_component`, which calls this for a
    component with a table.

    Raises
    ------
    ValueError
        ``name`` is not a valid table name, names another table of the case format (a field of
        :class:`Case`, a hole table) or is registered by another component; or ``by_default``
        with a key that has no default.
    TypeError
        ``schema`` is not a frozen dataclass whose fields are declared with
        :func:`~rvfem.case.schema.param`.
    """
    if not (isinstance(name, str) and name.isidentifier()):
        raise ValueError(f"a stage component's table needs a name (a Python identifier), got {name!r}")
    if name in {f.name for f in dataclasses.fields(Case)} or name in hole_table_names():
        raise ValueError(f"{name!r} is a table of the case format already")
    known = _COMPONENT_TABLES.get(name)
    if known is not None and (known.schema is not schema or known.owner != owner):
        raise ValueError(f"the table {name!r} is registered by the component {known.owner!r} already")
    if not (isinstance(schema, type) and dataclasses.is_dataclass(schema)
            and getattr(schema, "__dataclass_params__").frozen):
        raise TypeError(f"the table {name!r} of component {owner!r} must be a frozen dataclass, got {schema!r}")
    specs = file_fields(schema)     # every key declared with param (raises TypeError otherwise)
    missing = [spec.name for spec in specs if spec.required]
    if by_default and missing:
        raise ValueError(f"the table {name!r} of component {owner!r} is there by default, so every key needs a "
                         f"default; {', '.join(missing)} has none")
    _COMPONENT_TABLES[name] = ComponentTable(name, schema, bool(by_default), owner)


def unregister_component_table(name: str) -> None:
    """Remove the table ``name`` of a registered component from the case format (an unknown name is
    ignored)."""
    _COMPONENT_TABLES.pop(name, None)


def component_tables() -> tuple[ComponentTable, ...]:
    """The registered tables of stage components, in the order they were registered."""
    return tuple(_COMPONENT_TABLES.values())


def _component_table_names() -> tuple[str, ...]:
    return tuple(_COMPONENT_TABLES)


MAX_NAME_LENGTH = 100
"""Longest case name, characters (it names result folders, with suffixes such as ``-accuracy``)."""

NAME_CHARACTERS = "letters A–Z a–z, digits and . _ + -"
"""What a case name may hold, in words (:data:`_NAME_PATTERN`)."""

_NAME_PATTERN = re.compile(r"[A-Za-z0-9_+][A-Za-z0-9._+-]*")
"""A case name is one portable file-name component: the POSIX portable file-name characters and
``+``, not starting with ``.`` (a hidden file; ``.`` and ``..``) or ``-`` (read as an option)."""


def name_problem(name: str) -> str | None:
    """Why ``name`` cannot be a case name (it names the result folder ``results/<name>``), or
    None if it can: 1 to :data:`MAX_NAME_LENGTH` characters of :data:`NAME_CHARACTERS`, not
    starting with ``.`` or ``-`` (so no path separator, no ``.`` or ``..``, nothing hidden)."""
    rule = (f"one file-name component (it names the result folder): 1–{MAX_NAME_LENGTH} {NAME_CHARACTERS}, "
            "not starting with '.' or '-'")
    if not isinstance(name, str) or not name:
        return f"must be {rule}; got an empty name"
    if len(name) > MAX_NAME_LENGTH:
        return f"must be {rule}; got {len(name)} characters"
    if _NAME_PATTERN.fullmatch(name) is None:
        bad = sorted({c for c in name if not re.fullmatch(r"[A-Za-z0-9._+-]", c)})
        what = (f"it holds {', '.join(repr(c) for c in bad)}" if bad else f"it starts with {name[0]!r}")
        return f"must be {rule}; {what} in {name!r}"
    return None


def _file_stem(values: Mapping[str, Any]) -> str:
    """The default case name: the file name without ``.toml``, each character outside
    :data:`NAME_CHARACTERS` replaced by ``_`` (and a leading ``.`` or ``-`` too)."""
    source = values.get("<source>", "")
    if not source.endswith(".toml"):
        return "case"
    stem = re.sub(r"[^A-Za-z0-9._+-]", "_", Path(source).stem)[:MAX_NAME_LENGTH]
    stem = re.sub(r"^[.-]", "_", stem)
    return stem or "case"


@dataclass(frozen=True, kw_only=True)
class Case:
    """One reducer and one analysis, validated on construction (see :mod:`rvfem.case.definition`).

    All arguments are keywords. ``source`` names the file (or ``"<code>"``) in error messages;
    ``overrides`` records the ``KEY=VALUE`` overrides applied on reading. ``other_holes`` holds
    the tables of the registered hole shapes that are not fields (:func:`register_hole_table`) as
    ``(table name, table)`` pairs; :meth:`replace` sets them by name like fields, and
    :meth:`hole_tables` lists every hole table of the case. ``component_tables`` holds the tables
    of the registered stage components (:func:`register_component_table`) the same way
    (:meth:`component_table` reads one).
    """

    name: str = param(max_length=MAX_NAME_LENGTH, default_from=_file_stem,
                      default_doc="file name without `.toml` (other characters replaced by `_`)",
                      doc="case name used in reports and as the result folder `results/<name>`: one file-name "
                          "component of letters, digits and `._+-`, not starting with `.` or `-`")
    cycloid: Cycloid = param()
    pins: Pins = param()
    cranks: Cranks = param()
    crank_bearing: CrankBearing = param()
    material: Material = param(Material())
    loads: Loads = param()
    analysis: Analysis = param(Analysis())
    mesh: MeshSettings = param(MeshSettings())
    fan_holes: FanHoles | None = param(None)
    round_holes: RoundHoles | None = param(None)
    crank_support: CrankSupport | None = param(None)
    lubricant: Lubricant = param(Lubricant())
    wear: Wear = param(Wear())
    description: str = param("", max_length=10000, doc="free text")
    source: str = param("<code>", compare=False, in_file=False)
    overrides: tuple[str, ...] = param((), compare=False, in_file=False)
    other_holes: tuple[tuple[str, Any], ...] = param((), in_file=False)
    component_tables: tuple[tuple[str, Any], ...] = param((), in_file=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "overrides", tuple(self.overrides))
        check_fields(self, "", self.source)
        _check_other_holes(self)
        _check_component_tables(self)
        for check in _CROSS_CHECKS:
            check(self)

    def hole_tables(self) -> tuple[tuple[str, Any], ...]:
        """``(table name, table)`` of every hole table the case has, in the order the holes are
        numbered (:func:`hole_table_names`)."""
        builtin = tuple((name, getattr(self, name)) for name in BUILTIN_HOLE_TABLES if getattr(self, name) is not None)
        return builtin + self.other_holes

    def hole_shapes(self) -> tuple[tuple[type[Any], Any], ...]:
        """``(hole shape, table)`` of every hole table the case has, in the order of
        :meth:`hole_tables` (the shapes are :class:`rvfem.geometry.holes.HoleShape` classes,
        registered when :mod:`rvfem.geometry` is imported).

        Raises
        ------
        LookupError
            A table's shape is not registered.
        """
        try:
            return tuple((_HOLE_SHAPES[name], table) for name, table in self.hole_tables())
        except KeyError as exc:
            raise LookupError(f"no hole shape is registered for the table {exc.args[0]!r} "
                              "(the built-in ones are registered by importing rvfem.geometry)") from None

    def component_table(self, name: str) -> Any:
        """The table ``name`` of a registered stage component (:func:`register_component_table`),
        or None if the case does not have it."""
        return dict(self.component_tables).get(name)

    def hole_table(self, name: str) -> Any:
        """The hole table ``name`` of the case, or None if the case has none."""
        return dict(self.hole_tables()).get(name)

    @property
    def short_amplitude_coefficient(self) -> float:
        """k = e·Zp/Rp (must be < 1 for a non-looping epitrochoid)."""
        return self.cycloid.eccentricity * self.pins.count / self.pins.circle_radius

    def replace(self, **changes: Any) -> "Case":
        """A copy with top-level fields replaced (validated again); the table of a registered hole
        shape or stage component is replaced by its name like a field (None removes it; a table
        there by default comes back with its defaults)."""
        for field, names in (("other_holes", _other_hole_names()), ("component_tables", _component_table_names())):
            given = {name: changes.pop(name) for name in names if name in changes}
            if given:
                tables = {**dict(changes.get(field, getattr(self, field))), **given}
                changes[field] = tuple((name, t) for name, t in tables.items() if t is not None)
        return dataclasses.replace(self, **changes)

    def digest(self) -> str:
        """sha256 of the canonical case data (used to name cached meshes and results)."""
        return hashlib.sha256(repr(case_to_dict(self)).encode()).hexdigest()


# --------------------------------------------------------------------------------------------
# Cross-field checks (run by Case.__post_init__, in this order)
# --------------------------------------------------------------------------------------------


def _error(case: Case, key: str, message: str) -> CaseError:
    return table_error(case.source, key, message)


def _check_name(case: Case) -> None:
    problem = name_problem(case.name)
    if problem is not None:
        raise _error(case, "name", problem)


def _check_cycloid_and_pins(case: Case) -> None:
    cyc, pins = case.cycloid, case.pins
    p = cyc.pitch_error
    if p.values and len(p.values) != cyc.teeth:
        raise _error(case, "cycloid.pitch_error.values",
                     f"must have one value per tooth ({cyc.teeth}), got {len(p.values)}")
    if p.values and p.amplitude:
        raise _error(case, "cycloid.pitch_error.amplitude", "and 'values' exclude each other; give one of them")
    if pins.count <= cyc.teeth:
        raise _error(case, "pins.count", f"(Zp = {pins.count}) must exceed cycloid.teeth (Zc = {cyc.teeth}); "
                                         "a cycloid drive needs more pins than lobes")
    k = case.short_amplitude_coefficient
    if k >= 1.0:
        raise _error(case, "cycloid.eccentricity",
                     f"is too large: the short-amplitude coefficient k = e·Zp/Rp = {k:.3f} must be < 1 "
                     "(reduce the eccentricity or enlarge pins.circle_radius)")
    if pins.radius >= pins.circle_radius * math.sin(math.pi / pins.count):
        raise _error(case, "pins.radius", f"({pins.radius} mm) is too large: neighbouring pins overlap")


def _check_cranks(case: Case) -> None:
    cranks = case.cranks
    if len(cranks.angles_deg) != cranks.count:
        raise _error(case, "cranks.angles_deg",
                     f"must list {cranks.count} angles (cranks.count), got {len(cranks.angles_deg)}")
    wrapped = sorted(a % 360.0 for a in cranks.angles_deg)
    gaps = [b - a for a, b in zip(wrapped, wrapped[1:] + [wrapped[0] + 360.0])]
    if min(gaps) < 1e-6:
        raise _error(case, "cranks.angles_deg", f"must be distinct angles (mod 360°), got {list(cranks.angles_deg)}")


def _check_crank_bearing(case: Case) -> None:
    b = case.crank_bearing
    key = "crank_bearing."
    for table, kind, model in (("pins", "pin", case.pins.model), ("crank_bearing", "bearing", b.model)):
        for name in model_requires(kind, model):   # the keys the model declares it needs
            if getattr(getattr(case, table), name) is None:
                raise _error(case, f"{table}.{name}", f"is missing (required when {table}.model = {model!r})")
    if b.stiffness_law == "linear" and b.linear_stiffness_N_per_mm is None:
        raise _error(case, key + "linear_stiffness_N_per_mm", "is missing (required when stiffness_law = 'linear')")
    if b.roller_diameter >= b.pitch_diameter:   # γ = D_we/D_m in (0, 1): ISO 281 f_c, inner raceway > 0
        raise _error(case, key + "roller_diameter", "must be smaller than pitch_diameter")
    if math.pi * b.pitch_diameter - b.rollers * b.roller_diameter <= 0:
        raise _error(case, key + "rollers",
                     f": {b.rollers} rollers of {b.roller_diameter} mm do not fit the pitch circle of "
                     f"{b.pitch_diameter} mm (circumference {math.pi * b.pitch_diameter:.2f} mm)")
    if b.bore_radius <= 0.5 * b.pitch_diameter:
        raise _error(case, key + "bore_radius",
                     f"({b.bore_radius} mm) must exceed half the pitch diameter ({0.5 * b.pitch_diameter} mm)")
    outer = b.outer_raceway_radius
    if b.bore_radius < outer * (1.0 - 1e-9):
        raise _error(case, key + "bore_radius",
                     f"({b.bore_radius} mm) must be at least the outer raceway radius (D_m + D_we)/2 = {outer:g} mm: "
                     "the rollers do not fit between the eccentric and the bore")


def _named_tables(case: Case, key: str, names: tuple[str, ...], owners: str) -> list[tuple[str, Any]]:
    """The (table name, table) pairs of ``case.<key>`` (a mapping or pairs), each name one of
    ``names`` (the tables of the registered ``owners``) and given once."""
    given = getattr(case, key)
    pairs = list(given.items()) if isinstance(given, Mapping) else list(given)
    seen: set[str] = set()
    for pair in pairs:
        if not (isinstance(pair, tuple) and len(pair) == 2 and pair[0] in names):
            known = ", ".join(names) or "none"
            raise _error(case, key, f"must hold (table name, table) pairs of the registered {owners} ({known}), "
                                    f"got {pair!r}")
        if pair[0] in seen:
            raise _error(case, pair[0], "is given twice")
        seen.add(pair[0])
    return pairs


def _check_other_holes(case: Case) -> None:
    """Check the tables of :attr:`Case.other_holes` like the fields (each against its declaration)
    and put them in the order of :func:`hole_table_names`."""
    names = _other_hole_names()
    pairs = _named_tables(case, "other_holes", names, "hole shapes")
    for name, table in pairs:
        if table is None:
            continue
        cls = _HOLE_SHAPES[name].table
        if not isinstance(table, cls):
            raise _error(case, name, f"must be a {cls.__name__}, got {table!r}")
        check_fields(table, name, case.source)
    ordered = tuple(sorted((p for p in pairs if p[1] is not None), key=lambda p: names.index(p[0])))
    object.__setattr__(case, "other_holes", ordered)


def _check_component_tables(case: Case) -> None:
    """Check the tables of :attr:`Case.component_tables` against their declarations, add those
    there by default that are missing (with their defaults), run each table's own ``check`` and
    put them in the order of :func:`component_tables`."""
    tables = dict(_named_tables(case, "component_tables", _component_table_names(), "stage components"))
    ordered = []
    for entry in component_tables():
        table = tables.get(entry.name)
        if table is None and entry.by_default:
            table = entry.schema()
        if table is None:
            continue
        if not isinstance(table, entry.schema):
            raise _error(case, entry.name, f"must be a {entry.schema.__name__}, got {table!r}")
        check_fields(table, entry.name, case.source)
        check = getattr(table, "check", None)
        if check is not None:
            check(lambda key, message, name=entry.name: _error(case, f"{name}.{key}", message))
        ordered.append((entry.name, table))
    object.__setattr__(case, "component_tables", tuple(ordered))


def _check_holes(case: Case) -> None:
    for name, table in case.hole_tables():
        check = getattr(table, "check", None)
        if check is not None:
            check(lambda key, message, name=name: _error(case, f"{name}.{key}", message))


MIN_DUTY_TORQUE_NM = 1.0e-3
"""Smallest non-zero torque of a duty-cycle row, N·m (a smaller one is a zero in disguise whose
T^p underflows and makes the service life infinite)."""


def _check_loads(case: Case) -> None:
    loads = case.loads
    if loads.torque_split == "stiffness" and loads.discs > 2:
        raise _error(case, "loads.torque_split",
                     f"= 'stiffness' needs 1 or 2 discs (loads.discs = {loads.discs}); use 'equal'")
    if abs(loads.torque_Nm) < MIN_DUTY_TORQUE_NM:
        raise _error(case, "loads.torque_Nm",
                     f"must be at least {MIN_DUTY_TORQUE_NM:g} N·m in magnitude (negative reverses it), "
                     f"got {loads.torque_Nm!r}")
    for i, row in enumerate(loads.duty_cycle):
        if 0.0 < abs(row.torque_Nm) < MIN_DUTY_TORQUE_NM:
            raise _error(case, f"loads.duty_cycle[{i}].torque_Nm",
                         f"must be 0 or at least {MIN_DUTY_TORQUE_NM:g} N·m in magnitude, got {row.torque_Nm!r}")
    if loads.duty_cycle and not any(row.torque_Nm != 0 for row in loads.duty_cycle):
        raise _error(case, "loads.duty_cycle", "needs at least one row with a non-zero torque_Nm")



def _check_crank_support(case: Case) -> None:
    s = case.crank_support
    if s is None:
        return
    discs = case.loads.discs
    key = "crank_support."
    beam_keys = ("span", "eccentric_positions", "journal_diameter", "bending_stiffness_Nmm2",
                 "support_stiffness_N_per_mm", "carrier_stiffness_N_per_mm")
    if s.influence_mm_per_N is not None:
        for name in beam_keys:
            if getattr(s, name) is not None:
                raise _error(case, key + name, "and 'influence_mm_per_N' exclude each other: the influence "
                                               "matrix replaces the beam model; give one of them")
        defaults = {f.name: f.default for f in dataclasses.fields(CrankSupport)}
        for name in ("youngs_modulus", "poissons_ratio", "shear"):
            if getattr(s, name) != defaults[name]:
                raise _error(case, key + name, "only applies to the beam model, not with 'influence_mm_per_N'")
        matrix = s.influence_mm_per_N
        if len(matrix) != discs or any(len(row) != discs for row in matrix):
            shape = f"{len(matrix)}×{'/'.join(sorted({str(len(r)) for r in matrix})) or 0}"
            raise _error(case, key + "influence_mm_per_N",
                         f"must be a {discs}×{discs} matrix (loads.discs = {discs}), got {shape}")
        scale = max(abs(v) for row in matrix for v in row)
        for i in range(discs):
            for j in range(i):
                if abs(matrix[i][j] - matrix[j][i]) > 1e-9 * scale:
                    raise _error(case, key + "influence_mm_per_N",
                                 f"must be symmetric, got [{i}][{j}] = {matrix[i][j]!r} and [{j}][{i}] = {matrix[j][i]!r}")
        if not _positive_definite(matrix):
            raise _error(case, key + "influence_mm_per_N", "must be positive definite (a compliance matrix)")
        return
    for name in ("span", "eccentric_positions"):
        if getattr(s, name) is None:
            raise _error(case, key + name, "is missing (required for the beam model; or give 'influence_mm_per_N')")
    positions = s.eccentric_positions
    assert positions is not None and s.span is not None   # both checked just above
    if len(positions) != discs:
        raise _error(case, key + "eccentric_positions",
                     f"must list {discs} positions (loads.discs), got {len(positions)}")
    for i, x in enumerate(positions):
        if not 0.0 < x < s.span:
            raise _error(case, f"{key}eccentric_positions[{i}]",
                         f"({x:g} mm) must lie strictly between the supports, in (0, {s.span:g}) mm (crank_support.span)")
    if len(set(positions)) != len(positions):
        raise _error(case, key + "eccentric_positions", f"must be distinct, got {list(positions)}")
    if (s.journal_diameter is None) == (s.bending_stiffness_Nmm2 is None):
        raise _error(case, key + "journal_diameter",
                     "or 'bending_stiffness_Nmm2': give exactly one of them (or 'influence_mm_per_N' instead of the beam)")
    if s.shear and s.journal_diameter is None:
        raise _error(case, key + "shear", "= true needs 'journal_diameter' (the shear area); set shear = false "
                                          "with bending_stiffness_Nmm2")
    for name in ("support_stiffness_N_per_mm", "carrier_stiffness_N_per_mm"):
        value = getattr(s, name)
        if isinstance(value, tuple) and len(value) != 2:
            raise _error(case, key + name, f"must be one number or a list of 2 (support 1, support 2), got {len(value)} values")


def _positive_definite(matrix: tuple[tuple[float, ...], ...]) -> bool:
    """Cholesky factorization succeeds (symmetric input)."""
    n = len(matrix)
    low = [[0.0] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1):
            s = matrix[i][j] - sum(low[i][k] * low[j][k] for k in range(j))
            if i == j:
                if not s > 0.0:
                    return False
                low[i][i] = math.sqrt(s)
            else:
                low[i][j] = s / low[j][j]
    return True


def _check_roller_profile(case: Case) -> None:
    """A crowned roller's drop has to fit its length: the combined profile's modified segment within
    half the roller, the arc's radius beyond it; the corner's axial length at most its radius and
    shorter than half the roller (docs/theory.md § 12)."""
    b, key = case.crank_bearing, "crank_bearing.profile."
    half = 0.5 * b.roller_length
    if b.profile.kind == "combined" and b.profile.modification_length >= half:
        raise _error(case, key + "modification_length", f"({b.profile.modification_length:g} mm) must be shorter than "
                     f"half the roller length ({half:g} mm): the modified segment runs from each end inwards")
    if b.profile.kind == "arc" and b.profile.crown_radius <= half:
        raise _error(case, key + "crown_radius", f"({b.profile.crown_radius:g} mm) must exceed half the roller "
                     f"length ({half:g} mm)")
    prof = b.profile
    if prof.chamfer_length is not None and prof.chamfer_length > prof.corner_radius:
        raise _error(case, key + "chamfer_length", f"({prof.chamfer_length:g} mm) must not exceed "
                     f"{key}corner_radius ({prof.corner_radius:g} mm): the corner's arc of radius r reaches the end "
                     "face within r; give a larger corner_radius or a shorter chamfer_length")
    corner = prof.corner_radius if prof.chamfer_length is None else prof.chamfer_length
    if prof.corner_radius > 0.0 and corner >= half:
        name = "corner_radius" if prof.chamfer_length is None else "chamfer_length"
        raise _error(case, key + name, f"({corner:g} mm) must be shorter than half the roller length ({half:g} mm): "
                     "the corner is the short rounded end beyond the effective length")
    defaults = {f.name: f.default for f in dataclasses.fields(RollerProfile)}
    for name, kind in _profile_key_kind().items():
        value = getattr(b.profile, name)
        if b.profile.kind != kind and value != defaults[name]:
            raise _error(case, key + name, f"= {value:g} is given, but kind = {b.profile.kind!r} does not use it "
                         f"(it shapes the {kind!r} profile): set {key}kind = {kind!r}, or leave {name} out")


def _profile_key_kind() -> dict[str, str]:
    """The profile keys that only one ``kind`` uses (kinds registered since included). Given with
    another kind they are refused, unless they hold their default (a case written out whole, as
    ``case.json``, holds every key)."""
    return {key: kind for kind, keys in ROLLER_PROFILE_KINDS.items() for key in keys}


def _check_lubricant(case: Case) -> None:
    """Two viscosities or none (then ``iso_vg``), and the oil thinner when hot (Walther's line)."""
    oil = case.lubricant
    if (oil.nu40 is None) != (oil.nu100 is None):
        given, missing = ("lubricant.nu40", "lubricant.nu100") if oil.nu100 is None else ("lubricant.nu100",
                                                                                        "lubricant.nu40")
        raise _error(case, missing, f"is missing: '{given}' alone does not fix the viscosity–temperature line; "
                     "give both, or neither and 'lubricant.iso_vg'")
    if oil.nu40 is not None and oil.iso_vg is not None:
        raise _error(case, "lubricant.iso_vg", f"= {oil.iso_vg} and 'lubricant.nu40'/'lubricant.nu100' "
                     f"({oil.nu40:g}/{oil.nu100:g} mm²/s) are both given: give the grade or the two viscosities, "
                     "not both")
    if oil.nu40 is not None and oil.nu100 is not None and oil.nu100 >= oil.nu40:
        raise _error(case, "lubricant.nu100", f"({oil.nu100:g} mm²/s) must be below 'lubricant.nu40' "
                     f"({oil.nu40:g} mm²/s): an oil thins as it warms")


_MATERIAL_DEFAULT_FATIGUE_LIMIT = next(f.default for f in dataclasses.fields(Material) if f.name == "fatigue_limit")


def _check_material(case: Case) -> None:
    """σ_W < R_m, R_p0.2 ≤ R_m (the fatigue check's Goodman line, docs/theory.md "Mass and strength") and
    σ_W ≤ R_p0.2: a fully reversed stress amplitude above the yield strength yields the material in
    every cycle, so it cannot be an endurance limit (for steels σ_W ≈ 0.4–0.5·R_m, below R_p0.2)."""
    m = case.material
    if m.yield_strength < m.fatigue_limit:
        raise _error(case, "material.yield_strength", f"{m.yield_strength:g} MPa is below the fatigue limit "
                     f"'material.fatigue_limit' = {m.fatigue_limit:g} MPa ({_MATERIAL_DEFAULT_FATIGUE_LIMIT:g} MPa, that of 100Cr6, when not given): a "
                     "fatigue limit above the yield strength is not physical (the material would yield in every "
                     "cycle); give the strengths of the disc's material together")
    if m.yield_strength > m.ultimate_strength:
        raise _error(case, "material.yield_strength", f"{m.yield_strength:g} MPa is above the ultimate strength "
                     f"{m.ultimate_strength:g} MPa; give a yield strength ≤ 'material.ultimate_strength'")
    if m.fatigue_limit >= m.ultimate_strength:
        raise _error(case, "material.fatigue_limit", f"{m.fatigue_limit:g} MPa is not below the ultimate strength "
                     f"{m.ultimate_strength:g} MPa; lower it")


_CROSS_CHECKS = (_check_name, _check_cycloid_and_pins, _check_cranks, _check_crank_bearing, _check_roller_profile, _check_holes,
                 _check_loads, check_mesh, check_mesh_sizes, _check_crank_support, _check_lubricant, _check_material)


# --------------------------------------------------------------------------------------------
# The case as a plain dict
# --------------------------------------------------------------------------------------------


_NOT_IN_FILE = ("source", "overrides", "other_holes", "component_tables")


def table_to_dict(table: Any) -> Any:
    """A table (a dataclass of the case format) as plain dicts and lists in the file's layout; keys
    whose value is None are left out."""
    if dataclasses.is_dataclass(table):
        return {f.name: table_to_dict(getattr(table, f.name)) for f in dataclasses.fields(table)
                if getattr(table, f.name) is not None and f.name not in _NOT_IN_FILE}
    if isinstance(table, tuple):
        return [table_to_dict(v) for v in table]
    return table


def case_to_dict(case: Case) -> dict:
    """The case as a plain dict in the file's layout (round-trips through :func:`case_from_dict`);
    the tables of registered hole shapes (:attr:`Case.other_holes`) and stage components
    (:attr:`Case.component_tables`) are top-level tables."""
    data = table_to_dict(case)
    data["loads"]["duty_cycle"] = data["loads"].get("duty_cycle", [])
    for name, table in case.other_holes + case.component_tables:
        data[name] = table_to_dict(table)
    return data
