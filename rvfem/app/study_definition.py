"""The study file: what a design study varies and its variants, read and checked up front.

A **study file** (TOML) names a base case and how to vary it::

    name = "rv40e_ligament"
    base_case = "../cases/rv40e_fanholes.toml"   # relative to the study file
    kind = "grid"                                # "grid", "sensitivity" or "list"

    [overrides]                                  # applied to the base and to every variant
    "analysis.angle_step_deg" = 2.0

    [[parameter]]                                # grid: every combination of the values
    key = "fan_holes.ligament"
    values = [3.5, 4.5, 5.5]

    [[parameter]]                                # sensitivity: one at a time, low and high
    key = "loads.torque_Nm"                      # around the base (tornado chart)
    low = 300.0
    high = 500.0

    [[variant]]                                  # list: explicit variants
    id = "rigid-bore"
    set = { "crank_bearing.model" = "rigid_bore" }

Keys are the dotted keys of the case format (``docs/case-format.md``); a value may be a number or
a model choice (``crank_bearing.model``, ``pins.model``). :func:`load_study` validates the file and
every variant's case up front (through :func:`rvfem.case.definition.load_case`, so an unknown key gets a
"did you mean"), and always adds the base case itself as variant ``base``.
"""

from __future__ import annotations

import hashlib
import itertools
import os
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from rvfem.case.definition import case_to_dict, load_case, parse_override
from rvfem.case.schema import param, read_table, toml_literal
from rvfem.errors import CaseError

__all__ = ["STUDY_KINDS", "MAX_ID_LENGTH", "Parameter", "Variant", "Study", "load_study", "short_id"]

STUDY_KINDS = ("grid", "sensitivity", "list")
"""The three ways a study file can vary its base case."""

_ID_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._=,+-]*$")
_SAFE = re.compile(r"[^A-Za-z0-9._=,+-]")


@dataclass(frozen=True)
class Parameter:
    """One varied case key.

    Attributes
    ----------
    key : str
        Dotted case key, e.g. ``"fan_holes.ligament"``.
    values : tuple
        Grid: the values; sensitivity: ``(low, high)``; list: the values the variants set.
    base_value : object
        The value in the base case (after the study's overrides); None if the case has no such key.
    label : str
        For plots and tables (the key unless the study file gives one).
    """

    key: str
    values: tuple
    base_value: Any
    label: str


@dataclass(frozen=True)
class Variant:
    """One analysis of a study.

    Attributes
    ----------
    id : str
        Folder name under ``DIR/variants/`` (stable for the same study file).
    role : str
        ``"base"``, ``"grid"``, ``"low"``, ``"high"`` or ``"list"``.
    settings : tuple of (str, object)
        The variant's own parameter values (dotted key, value), in parameter order.
    overrides : tuple of str
        Every ``KEY=VALUE`` given to :func:`~rvfem.case.definition.load_case`: the study's, then the variant's.
    digest : str
        :meth:`rvfem.case.definition.Case.digest` of the variant's case (identifies its results on resume).
    """

    id: str
    role: str
    settings: tuple[tuple[str, Any], ...]
    overrides: tuple[str, ...]
    digest: str


@dataclass(frozen=True)
class Study:
    """A validated study file.

    Attributes
    ----------
    name, description : str
    path : Path or None
        The study file (None for a study built in code).
    base_case : Path
        The base case file (absolute).
    overrides : tuple of str
        ``KEY=VALUE`` applied to the base and every variant.
    kind : str
        One of :data:`STUDY_KINDS`.
    parameters : tuple of Parameter
    variants : tuple of Variant
        The base first.
    """

    name: str
    description: str
    path: Path | None
    base_case: Path
    overrides: tuple[str, ...]
    kind: str
    parameters: tuple[Parameter, ...]
    variants: tuple[Variant, ...]

    @property
    def base(self) -> Variant:
        return self.variants[0]


def _value_text(value: Any) -> str:
    """Short text of a parameter value for variant ids and tables."""
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return f"{value:.1f}"
    if isinstance(value, float):
        return f"{value:g}" if float(f"{value:g}") == value else repr(value)
    return str(value)


MAX_ID_LENGTH = 64
"""Longest variant id made from the settings; a longer one is shortened (see :func:`short_id`)."""


def short_id(text: str, width: int = MAX_ID_LENGTH) -> str:
    """``text`` if it has at most ``width`` characters, else its beginning and ``--`` and six hex
    digits of its hash: readable, and two different texts stay different."""
    if len(text) <= width:
        return text
    digest = hashlib.sha1(text.encode("utf-8")).hexdigest()[:6]
    return text[:max(width - 8, 1)] + "--" + digest


def _variant_id(settings: Sequence[tuple[str, Any]]) -> str:
    """``key=value`` joined by commas. Longer than :data:`MAX_ID_LENGTH`, the keys lose their
    table (``ligament=3.5``), the rest is cut and six hex digits of the full text's hash are
    appended, so that ids stay distinct."""
    full = _SAFE.sub("_", ",".join(f"{key}={_value_text(value)}" for key, value in settings))
    if len(full) <= MAX_ID_LENGTH:
        return full
    brief = _SAFE.sub("_", ",".join(f"{key.rsplit('.', 1)[-1]}={_value_text(value)}" for key, value in settings))
    digest = hashlib.sha1(full.encode("utf-8")).hexdigest()[:6]
    return brief[:MAX_ID_LENGTH - 8].rstrip(",=") + "--" + digest


def _lookup(data: dict, key: str) -> Any:
    node: Any = data
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _check_value(where: str, value: Any) -> None:
    if isinstance(value, dict) or (isinstance(value, list) and any(isinstance(v, dict) for v in value)):
        raise CaseError(f"{where}: expected a number, string, boolean or array, got a table")


# The tables of a study file, declared for :func:`rvfem.case.schema.read_table` (which checks unknown
# and missing keys and the types; what a value means is checked below).


@dataclass(frozen=True, kw_only=True)
class _StudyTable:
    """The top level of a study file."""

    name: str | None = param(None, doc="study name")
    description: str = param("", doc="text")
    base_case: str = param(doc="path of the base case file, relative to the study file")
    kind: str = param(choices=STUDY_KINDS, doc=f"one of {', '.join(STUDY_KINDS)}")
    overrides: Any = param(None, doc="table of dotted case keys")
    parameter: Any = param((), doc="array of tables [[parameter]]")
    variant: Any = param((), doc="array of tables [[variant]]")


@dataclass(frozen=True, kw_only=True)
class _GridParameterTable:
    """A ``[[parameter]]`` table of a grid study."""

    key: str = param(doc="dotted case key")
    values: Any = param(doc="array of values")
    label: str | None = param(None, doc="text for plots")


@dataclass(frozen=True, kw_only=True)
class _SensitivityParameterTable:
    """A ``[[parameter]]`` table of a sensitivity study."""

    key: str = param(doc="dotted case key")
    low: Any = param(doc="low value")
    high: Any = param(doc="high value")
    label: str | None = param(None, doc="text for plots")


@dataclass(frozen=True, kw_only=True)
class _VariantTable:
    """A ``[[variant]]`` table of a list study."""

    id: str | None = param(None, doc="folder name of the variant")
    set: Any = param(doc="table of dotted case keys")


def _overrides_table(where: str, table: Any) -> tuple[tuple[str, Any], ...]:
    if not isinstance(table, dict):
        raise CaseError(f"{where}: expected a table of dotted case keys, e.g. \"mesh.size_flank\" = 1.0")
    out = []
    for key, value in table.items():
        if isinstance(value, dict):  # written as [overrides.mesh] size_flank = 1.0
            for sub_key, sub_value in _overrides_table(f"{where}.{key}", value):
                out.append((f"{key}.{sub_key}", sub_value))
            continue
        _check_value(f"{where}.{key}", value)
        out.append((key, value))
    return tuple(out)


def _validated_case(base_case: Path, overrides: tuple[str, ...], where: str):
    try:
        return load_case(base_case, overrides)
    except CaseError as exc:
        raise CaseError(f"{where}: {exc}") from None


@dataclass(frozen=True)
class _StudyHeader:
    """The top level of a study file, checked.

    ``overrides`` are the study's then the extra ones (``--set``); ``raw_parameters`` and
    ``raw_variants`` are the ``[[parameter]]`` and ``[[variant]]`` arrays as parsed.
    """

    path: Path
    name: str
    description: str
    kind: str
    base_case: Path
    overrides: tuple[str, ...]
    raw_parameters: Any
    raw_variants: Any

    @property
    def where(self) -> str:
        """Where the messages point: the study file as given."""
        return f"{self.path}"

    def read_table(self, cls: type, data: Any, prefix: str):
        """One table of this study file read through :func:`rvfem.case.schema.read_table`."""
        return read_table(cls, data, prefix, str(self.path), explain=True)


@dataclass(frozen=True)
class _VariantSpec:
    """A variant before its case is checked: its role, its settings and the id the file gives."""

    role: str
    settings: tuple[tuple[str, Any], ...]
    id: str | None = None


@dataclass(frozen=True)
class _StudyPlan:
    """What a study varies: its parameters and the variants beside the base, in order."""

    parameters: tuple[Parameter, ...]
    specs: tuple[_VariantSpec, ...]


def _parse_study_file(path: Path) -> dict:
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise CaseError(f"{path}: cannot read the study file ({exc.strerror or exc})") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise CaseError(f"{path}: not a valid TOML file ({exc})") from None


def _read_header(path: Path, extra_overrides: Sequence[str]) -> _StudyHeader:
    """The top level of the study file: name, description, kind, base case and overrides."""
    top = read_table(_StudyTable, _parse_study_file(path), "", str(path), explain=True)
    where = f"{path}"
    name = path.stem if top.name is None else top.name
    if not name.strip() or _SAFE.search(name):
        raise CaseError(f"{where}: name: expected a non-empty name of letters, digits and ._=,+-, got {name!r}")
    base_case = (path.parent / top.base_case).resolve()
    if not base_case.is_file():
        raise CaseError(f"{where}: base_case: no case file {top.base_case!r} next to the study file "
                        f"({base_case} does not exist)")
    overrides = {} if top.overrides is None else top.overrides
    study_overrides = tuple(f"{k}={toml_literal(v)}" for k, v in _overrides_table(f"{where}: overrides", overrides))
    for text in extra_overrides:
        parse_override(text)  # its own one-line error
    return _StudyHeader(path=path, name=name, description=top.description, kind=top.kind, base_case=base_case,
                        overrides=study_overrides + tuple(extra_overrides), raw_parameters=top.parameter,
                        raw_variants=top.variant)


def _read_parameter(head: _StudyHeader, i: int, raw: Any, earlier: Sequence[Parameter],
                    base_data: dict) -> Parameter:
    """The ``i``-th ``[[parameter]]`` table (from 1) of a grid or sensitivity study, each of its
    values checked on the base case."""
    pw = f"{head.where}: parameter[{i}]"
    table = _GridParameterTable if head.kind == "grid" else _SensitivityParameterTable
    row = head.read_table(table, raw, f"parameter[{i}]")
    key = row.key
    if not key:
        raise CaseError(f"{pw}.key: expected a dotted case key such as \"fan_holes.ligament\"")
    if any(p.key == key for p in earlier):
        raise CaseError(f"{pw}.key: {key!r} is varied twice")
    if head.kind == "grid":
        values = row.values
        if not isinstance(values, list) or not values:
            raise CaseError(f"{pw}.values: expected a non-empty array")
        if len(set(map(repr, values))) != len(values):
            raise CaseError(f"{pw}.values: a value appears twice")
    else:
        values = [row.low, row.high]
    for v in values:
        _check_value(f"{pw} ({key})", v)
    for v in values:  # each value on its own: the error names the parameter and the key
        _validated_case(head.base_case, head.overrides + (f"{key}={toml_literal(v)}",), f"{pw} (key {key})")
    return Parameter(key, tuple(values), _lookup(base_data, key), key if row.label is None else row.label)


def _parameter_plan(head: _StudyHeader, base_data: dict) -> _StudyPlan:
    """The variants of a grid study (every combination) or of a sensitivity study (one parameter
    at a time to its low and its high value)."""
    where, kind = head.where, head.kind
    if head.raw_variants:
        raise CaseError(f"{where}: variant: only a study of kind 'list' has [[variant]] tables")
    if not head.raw_parameters:
        raise CaseError(f"{where}: parameter: a {kind} study needs at least one [[parameter]] table")
    parameters: list[Parameter] = []
    for i, raw in enumerate(head.raw_parameters, start=1):
        parameters.append(_read_parameter(head, i, raw, parameters, base_data))
    if kind == "grid":
        specs = tuple(_VariantSpec("grid", tuple((p.key, v) for p, v in zip(parameters, combo)))
                      for combo in itertools.product(*(p.values for p in parameters)))
    else:  # a side equal to the base value is the base itself: not run twice
        specs = tuple(_VariantSpec(role, ((p.key, value),)) for p in parameters
                      for role, value in zip(("low", "high"), p.values) if value != p.base_value)
    return _StudyPlan(tuple(parameters), specs)


def _read_list_variant(head: _StudyHeader, i: int, raw: Any) -> _VariantSpec:
    """The ``i``-th ``[[variant]]`` table (from 1) of a list study."""
    vw = f"{head.where}: variant[{i}]"
    row = head.read_table(_VariantTable, raw, f"variant[{i}]")
    settings = _overrides_table(f"{vw}.set", row.set)
    if not settings:
        raise CaseError(f"{vw}.set: empty (the base case is always run as variant 'base')")
    if row.id is not None and not _ID_PATTERN.match(row.id):
        raise CaseError(f"{vw}.id: expected letters, digits and ._=,+- (a folder name), got {row.id!r}")
    return _VariantSpec("list", settings, row.id)


def _list_plan(head: _StudyHeader, base_data: dict) -> _StudyPlan:
    """The variants of a list study; its parameters are the keys the variants set."""
    where = head.where
    if head.raw_parameters:
        raise CaseError(f"{where}: parameter: a study of kind 'list' names its variants in [[variant]] tables")
    if not head.raw_variants:
        raise CaseError(f"{where}: variant: a list study needs at least one [[variant]] table")
    specs = tuple(_read_list_variant(head, i, raw) for i, raw in enumerate(head.raw_variants, start=1))
    keys: dict[str, list] = {}
    for spec in specs:
        for key, value in spec.settings:
            keys.setdefault(key, []).append(value)
    parameters = tuple(Parameter(k, tuple(v), _lookup(base_data, k), k) for k, v in keys.items())
    return _StudyPlan(parameters, specs)


def _variants(head: _StudyHeader, base_digest: str, plan: _StudyPlan) -> tuple[Variant, ...]:
    """The base and the variants of ``plan`` with their ids, each variant's case checked."""
    variants = [Variant("base", "base", (), head.overrides, base_digest)]
    ids = {"base": "the base case"}
    for n, spec in enumerate(plan.specs, start=1):
        vid = spec.id or _variant_id(spec.settings)
        vw = f"{head.where}: variant {vid!r}"
        if vid in ids:
            raise CaseError(f"{vw}: two variants have this id (the other: {ids[vid]}); give distinct values or ids")
        ids[vid] = f"variant {n}"
        own = tuple(f"{k}={toml_literal(v)}" for k, v in spec.settings)
        case = _validated_case(head.base_case, head.overrides + own, vw)
        variants.append(Variant(vid, spec.role, spec.settings, head.overrides + own, case.digest()))
    return tuple(variants)


def load_study(path: str | os.PathLike, extra_overrides: Sequence[str] = ()) -> Study:
    """Read and validate a study file; validate every variant's case.

    Parameters
    ----------
    path : path
        The study file (TOML).
    extra_overrides : sequence of str
        ``KEY=VALUE`` applied after the study file's ``[overrides]`` (the command line's ``--set``).

    Returns
    -------
    Study

    Raises
    ------
    CaseError
        One line naming the study file and the key: unknown or missing study keys, a parameter
        key the case format does not know (with a "did you mean"), a value the case rejects, two
        variants with the same id.
    """
    path = Path(path)
    head = _read_header(path, extra_overrides)
    base = _validated_case(head.base_case, head.overrides, f"{head.where}: overrides")
    if not isinstance(head.raw_parameters, (list, tuple)) or not isinstance(head.raw_variants, (list, tuple)):
        raise CaseError(f"{head.where}: parameter and variant must be arrays of tables ([[parameter]], [[variant]])")
    base_data = case_to_dict(base)
    plan = _list_plan(head, base_data) if head.kind == "list" else _parameter_plan(head, base_data)
    return Study(name=head.name, description=head.description, path=path.resolve(), base_case=head.base_case,
                 overrides=head.overrides, kind=head.kind, parameters=plan.parameters,
                 variants=_variants(head, base.digest(), plan))
