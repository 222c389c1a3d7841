"""Declarative schema of the case file: every key is declared once, on a dataclass field.

A key of the case file is a field of one of the frozen dataclasses of :mod:`rvfem.case.definition`, declared
with :func:`param`::

    eccentricity: float = param(unit="mm", low=0.01, high=50.0, doc="crank eccentricity e")

The field's type annotation gives the TOML type (``int``, ``float``, ``str``, ``bool``, a list of
numbers ``tuple[float, ...]``, a matrix ``tuple[tuple[float, ...], ...]``, a number or a list
``float | tuple[float, ...]``, a sub-table (another dataclass), an optional sub-table
``Dataclass | None``, an array of tables ``tuple[Dataclass, ...]``, or ``Any``: any TOML value,
passed on unchecked for the caller to interpret); ``X | None`` makes a key optional with the
default None. The metadata gives the unit, the bounds, the choices, the
documentation and, for a default that depends on other keys, the function that computes it.

From these declarations

* :func:`read_table` reads and checks any table of a parsed TOML file (unknown keys first, with
  the closest known key suggested, then missing keys, wrong types, non-finite numbers, bounds and
  choices), naming the file and the full dotted key in a one-line :class:`~rvfem.errors.CaseError`;
* :func:`check_fields` applies the same per-key checks to a dataclass built in code (and converts
  ints to floats and lists to tuples, so that a case built in code equals the same case read from
  a file);
* :func:`markdown_table` writes the reference tables of ``docs/case-format.md``;
  ``python -m rvfem.case.format_doc docs/case-format.md`` rewrites them in place (``--check`` only reports
  whether they are stale).

Checks that involve several keys (cross-field checks) are not declared here; they live with the
dataclasses in :mod:`rvfem.case.definition`.
"""

from __future__ import annotations

import dataclasses
import difflib
import json
import math
import re
import sys
import types
import typing
from dataclasses import MISSING, dataclass
from typing import Any, Callable, Iterator, Mapping

from rvfem.errors import CaseError

__all__ = [
    "toml_literal",
    "Param",
    "param",
    "FieldSpec",
    "file_fields",
    "read_table",
    "check_fields",
    "table_error",
    "closest",
    "format_quantity",
    "markdown_table",
]

_META = "rvfem"


@dataclass(frozen=True)
class Param:
    """Declaration of one case-file key (stored in the dataclass field's metadata).

    Attributes
    ----------
    unit : str
        Unit in the file: ``"mm"``, ``"deg"``, ``"MPa"``, ``"N/mm"``, ... ("" for dimensionless).
    low, high : float or None
        Bounds of a number (of every element of a list or matrix). None: unbounded on that side.
    low_open, high_open : bool
        True excludes the bound itself.
    choices : tuple or callable or None
        Allowed values (a callable is called at validation time, e.g. a registry's names).
    labels : mapping or None
        Short explanation of each choice, used in messages and docs (``{1: "P1", 2: "P2"}``).
    doc : str
        Meaning of the key (Markdown, one line).
    default_doc : str or None
        How the docs show a default computed by ``default_from``.
    default_from : callable or None
        ``f(values)`` computing the default of a key absent from the file from the values read so
        far (a mapping of dotted key to value, plus ``"<source>"``, the file name).
    max_length : int or None
        Longest allowed string, list or array of tables.
    in_file : bool
        False for fields that are not keys of the file (bookkeeping such as the source path).
    """

    unit: str = ""
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple | Callable[[], tuple] | None = None
    labels: Mapping[Any, str] | None = None
    doc: str = ""
    default_doc: str | None = None
    default_from: Callable[[Mapping[str, Any]], Any] | None = None
    max_length: int | None = None
    in_file: bool = True

    def allowed(self) -> tuple | None:
        """The allowed choices now (calls a callable ``choices``)."""
        return self.choices() if callable(self.choices) else self.choices


def param(default: Any = MISSING, **declaration: Any) -> Any:
    """A dataclass field declaring a case-file key; see :class:`Param` for the keywords.

    ``compare=False`` (a dataclass option) may be passed for bookkeeping fields.
    """
    compare = declaration.pop("compare", True)
    return dataclasses.field(default=default, compare=compare, metadata={_META: Param(**declaration)})


# --------------------------------------------------------------------------------------------
# Field kinds from the type annotations
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FieldSpec:
    """One key of a table: the dataclass field, its declaration and its kind.

    ``kind`` is one of ``"int"``, ``"float"``, ``"str"``, ``"bool"``, ``"floats"``, ``"matrix"``,
    ``"float_or_floats"``, ``"table"``, ``"tables"``, ``"any"`` (any TOML value, unchecked);
    ``item`` is the dataclass of a table kind.
    """

    name: str
    field: dataclasses.Field
    param: Param
    kind: str
    optional: bool
    item: type[Any] | None = None

    @property
    def table(self) -> type[Any]:
        """The dataclass of a table kind (``"table"``, ``"tables"``)."""
        if self.item is None:
            raise TypeError(f"the case-file key {self.name!r} is a {self.kind}, not a table")
        return self.item

    @property
    def required(self) -> bool:
        """True if a file must give the key (no default, nothing to compute it from)."""
        return (self.field.default is MISSING and self.field.default_factory is MISSING
                and self.param.default_from is None and not self.optional)

    def default(self, values: Mapping[str, Any]) -> Any:
        if self.param.default_from is not None:
            return self.param.default_from(values)
        if self.field.default is not MISSING:
            return self.field.default
        if self.field.default_factory is not MISSING:
            return self.field.default_factory()
        return None


def _kind(hint: Any) -> tuple[str, bool, Any]:
    optional = False
    args = typing.get_args(hint)
    if isinstance(hint, types.UnionType) or typing.get_origin(hint) is typing.Union:
        rest = [a for a in args if a is not type(None)]
        optional = len(rest) < len(args)
        if len(rest) == 2 and float in rest and any(typing.get_origin(a) is tuple for a in rest):
            return "float_or_floats", optional, None
        if len(rest) != 1:
            raise TypeError(f"unsupported case-file annotation {hint!r}")
        hint, args = rest[0], typing.get_args(rest[0])
    if hint in (int, float, str, bool):
        return hint.__name__, optional, None
    if hint is Any:
        return "any", optional, None
    if dataclasses.is_dataclass(hint):
        return "table", optional, hint
    if typing.get_origin(hint) is tuple and len(args) == 2 and args[1] is Ellipsis:
        item = args[0]
        if item is float:
            return "floats", optional, None
        if typing.get_origin(item) is tuple:
            return "matrix", optional, None
        if dataclasses.is_dataclass(item):
            return "tables", optional, item
    raise TypeError(f"unsupported case-file annotation {hint!r}")


_SPECS: dict[type, tuple[FieldSpec, ...]] = {}


def file_fields(cls: type) -> tuple[FieldSpec, ...]:
    """The keys of the table described by dataclass ``cls``, in declaration order."""
    if cls not in _SPECS:
        hints = typing.get_type_hints(cls, vars(sys.modules[cls.__module__]))
        specs = []
        for f in dataclasses.fields(cls):
            p = f.metadata.get(_META)
            if p is None:
                raise TypeError(f"{cls.__name__}.{f.name} is not declared with rvfem.case.schema.param")
            if not p.in_file:
                continue
            kind, optional, item = _kind(hints[f.name])
            specs.append(FieldSpec(f.name, f, p, kind, optional, item))
        _SPECS[cls] = tuple(specs)
    return _SPECS[cls]


# --------------------------------------------------------------------------------------------
# Messages
# --------------------------------------------------------------------------------------------


def _printable(text: str) -> str:
    """``text`` with control characters escaped (messages stay on one line)."""
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)


def _short(value: Any, limit: int = 60) -> str:
    text = _printable(repr(value))
    return text if len(text) <= limit else text[: limit - 4] + " ..."


def table_error(source: str, key: str, message: str) -> CaseError:
    """The error for dotted ``key`` of the case ``source``: ``"<source>: '<key>' <message>"``."""
    return CaseError(f"{_printable(source)}: '{_printable(key)}' {_printable(message)}")


def closest(word: str, options: Iterator[str] | tuple[str, ...]) -> str | None:
    """The option closest to ``word`` (difflib, cutoff 0.6), or None."""
    match = difflib.get_close_matches(word, list(options), n=1, cutoff=0.6)
    return match[0] if match else None


_UNIT_SYMBOL = {"deg": "°"}


def format_quantity(value: float, unit: str = "") -> str:
    """``30°``, ``0.4 mm``, ``2`` (``%g`` formatting)."""
    text = f"{value:g}"
    if not unit:
        return text
    return text + _UNIT_SYMBOL[unit] if unit in _UNIT_SYMBOL else f"{text} {unit}"


def _interval(p: Param) -> str:
    lo = "−∞" if p.low is None else f"{p.low:g}"
    hi = "∞" if p.high is None else f"{p.high:g}"
    text = f"{'(' if p.low_open or p.low is None else '['}{lo}, {hi}{')' if p.high_open or p.high is None else ']'}"
    unit = _UNIT_SYMBOL.get(p.unit, f" {p.unit}" if p.unit else "")
    return text + unit


def _bounds_problem(value: float, p: Param) -> str | None:
    """Why ``value`` violates the bounds of ``p``, or None."""
    if p.low is not None and (value < p.low or (p.low_open and value == p.low)):
        if value <= 0 <= p.low:
            need = "non-negative" if p.low == 0 and not p.low_open else "positive"
            return f"must be {need}"
        return f"must be {'greater than' if p.low_open else 'at least'} {format_quantity(p.low, p.unit)}"
    if p.high is not None and (value > p.high or (p.high_open and value == p.high)):
        if p.high_open:
            return f"must lie in {_interval(p)}"
        return f"must be at most {format_quantity(p.high, p.unit)}"
    return None


def _choice_problem(value: Any, p: Param) -> str | None:
    allowed = p.allowed()
    if allowed is None or value in allowed:
        return None
    if p.labels:
        texts = [f"{c!r} ({p.labels[c]})" if c in p.labels else repr(c) for c in allowed]
        listed = " or ".join([", ".join(texts[:-1]), texts[-1]]) if len(texts) > 1 else texts[0]
        return f"must be {listed}, got {_short(value)}"
    message = f"must be one of {', '.join(repr(c) for c in allowed)}, got {_short(value)}"
    if isinstance(value, str):
        hint = closest(value, tuple(str(c) for c in allowed))
        if hint:
            message += f" (did you mean {hint!r}?)"
    return message


# --------------------------------------------------------------------------------------------
# Checking one value
# --------------------------------------------------------------------------------------------


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _number(value: Any, p: Param, key: str, fail: Callable[[str, str], CaseError], what: str) -> float:
    if not _is_number(value):
        raise fail(key, f"must be {what}, got {_short(value)}")
    try:
        number = float(value)
    except OverflowError:   # an integer too large for a float
        raise fail(key, f"must be finite, got {_short(value)}") from None
    if not math.isfinite(number):
        raise fail(key, f"must be finite, got {_short(value)}")
    problem = _bounds_problem(number, p)
    if problem:
        raise fail(key, f"{problem}, got {_short(value)}")
    return number


def _numbers(value: Any, p: Param, key: str, fail: Callable[[str, str], CaseError]) -> tuple[float, ...]:
    if not isinstance(value, (list, tuple)) or not all(_is_number(v) for v in value):
        raise fail(key, f"must be a list of numbers, got {_short(value)}")
    if p.max_length is not None and len(value) > p.max_length:
        raise fail(key, f"must have at most {p.max_length} values, got {len(value)}")
    return tuple(_number(v, p, f"{key}[{i}]", fail, "a number") for i, v in enumerate(value))


def check_value(spec: FieldSpec, value: Any, key: str, fail: Callable[[str, str], CaseError]) -> Any:
    """Check one value of a scalar or list key against its declaration; return it normalized
    (float for numbers, tuples for lists). Tables are handled by the callers."""
    p, kind = spec.param, spec.kind
    if value is None and spec.optional:
        return None
    if kind == "any":
        return value
    if kind == "bool":
        if not isinstance(value, bool):
            raise fail(key, f"must be true or false, got {_short(value)}")
        return value
    if kind == "int":
        if not isinstance(value, int) or isinstance(value, bool):
            raise fail(key, f"must be an integer, got {_short(value)}")
        problem = _choice_problem(value, p) or _bounds_problem(value, p)
        if problem:
            raise fail(key, problem if problem.endswith(_short(value)) else f"{problem}, got {value}")
        return value
    if kind == "float":
        return _number(value, p, key, fail, "a number")
    if kind == "str":
        if not isinstance(value, str):
            raise fail(key, f"must be a string, got {_short(value)}")
        if p.max_length is not None and len(value) > p.max_length:
            raise fail(key, f"must be at most {p.max_length} characters long, got {len(value)}")
        problem = _choice_problem(value, p)
        if problem:
            raise fail(key, problem)
        return value
    if kind == "floats":
        return _numbers(value, p, key, fail)
    if kind == "float_or_floats":
        if _is_number(value):
            return _number(value, p, key, fail, "a number or a list of numbers")
        if isinstance(value, (list, tuple)):
            return _numbers(value, p, key, fail)
        raise fail(key, f"must be a number or a list of numbers, got {_short(value)}")
    if kind == "matrix":
        if not isinstance(value, (list, tuple)) or not all(isinstance(row, (list, tuple)) for row in value):
            raise fail(key, f"must be a list of lists of numbers (a matrix), got {_short(value)}")
        if p.max_length is not None and len(value) > p.max_length:
            raise fail(key, f"must have at most {p.max_length} rows, got {len(value)}")
        return tuple(_numbers(row, p, f"{key}[{i}]", fail) for i, row in enumerate(value))
    raise AssertionError(kind)  # pragma: no cover - tables are read by read_table


# --------------------------------------------------------------------------------------------
# Reading a parsed TOML table
# --------------------------------------------------------------------------------------------


def _dotted(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


def read_table(cls: type, data: Any, prefix: str, source: str, values: dict[str, Any] | None = None,
               extra: Mapping[str, Any] | None = None, *, explain: bool = False) -> Any:
    """Read the table ``data`` (parsed TOML) at dotted key ``prefix`` into dataclass ``cls``.

    Order of the checks: the value is a table; no unknown key (the closest known key is
    suggested); then key by key in declaration order: present or defaulted (else "is missing"),
    type, finiteness, bounds, choices; sub-tables recursively. The first problem raises.

    Parameters
    ----------
    cls : dataclass type
    data : Any
        The parsed table.
    prefix : str
        Dotted key of the table ("" for the top level).
    source : str
        File name for messages.
    values : dict or None
        Values read so far by dotted key (for defaults computed from other keys); filled in.
    extra : mapping or None
        Further constructor arguments (fields that are not keys of the file).
    explain : bool
        Longer messages for small tables (a study file's): an unknown key lists the known keys
        (instead of "remove it or check the spelling") and a missing key gives its ``doc``.

    Raises
    ------
    CaseError
    """
    values = {"<source>": source} if values is None else values

    def fail(key: str, message: str) -> CaseError:
        return table_error(source, key, message)

    if not isinstance(data, dict):
        kind = "an array of tables" if isinstance(data, list) else type(data).__name__
        raise fail(prefix or "<top>", f"must be a table, got {kind}")
    specs = file_fields(cls)
    names = tuple(s.name for s in specs)
    for name in data:
        if name not in names:
            hint = closest(name, names)
            raise fail(_dotted(prefix, name), "is not a known key"
                       + (f" (did you mean '{_dotted(prefix, hint)}'?)" if hint else "")
                       + (f"; known keys: {', '.join(names)}" if explain else "; remove it or check the spelling"))
    kwargs: dict[str, Any] = {}
    for spec in specs:
        key = _dotted(prefix, spec.name)
        if spec.name not in data:
            if spec.required:
                what = "required table" if spec.kind == "table" else "required"
                raise fail(key, f"is missing ({what}: {spec.param.doc})" if explain and spec.param.doc
                           else f"is missing ({what})")
            value = spec.default(values)
        elif spec.kind == "table":
            value = read_table(spec.table, data[spec.name], key, source, values, explain=explain)
        elif spec.kind == "tables":
            rows = data[spec.name]
            if not isinstance(rows, list):
                raise fail(key, f"must be an array of tables ([[{key}]])")
            if spec.param.max_length is not None and len(rows) > spec.param.max_length:
                raise fail(key, f"must have at most {spec.param.max_length} rows, got {len(rows)}")
            value = tuple(read_table(spec.table, row, f"{key}[{i}]", source, values, explain=explain)
                          for i, row in enumerate(rows))
        else:
            value = check_value(spec, data[spec.name], key, fail)
        kwargs[spec.name] = value
        values[key] = value
    return cls(**kwargs, **(extra or {}))


def check_fields(obj: Any, prefix: str, source: str) -> None:
    """Check every key of the dataclass instance ``obj`` (and of its sub-tables) against its
    declaration, as :func:`read_table` does for a file; normalize numbers to float and lists to
    tuples in place (the instances are frozen; this runs while a case is being constructed).

    Raises
    ------
    CaseError
        Naming ``source`` and the dotted key.
    """

    def fail(key: str, message: str) -> CaseError:
        return table_error(source, key, message)

    for spec in file_fields(type(obj)):
        key = _dotted(prefix, spec.name)
        value = getattr(obj, spec.name)
        if spec.kind == "table":
            if value is None and spec.optional:
                continue
            if not isinstance(value, spec.table):
                raise fail(key, f"must be a {spec.table.__name__}, got {_short(value)}")
            check_fields(value, key, source)
        elif spec.kind == "tables":
            if not isinstance(value, (list, tuple)) or not all(isinstance(v, spec.table) for v in value):
                raise fail(key, f"must be a sequence of {spec.table.__name__}, got {_short(value)}")
            if spec.param.max_length is not None and len(value) > spec.param.max_length:
                raise fail(key, f"must have at most {spec.param.max_length} rows, got {len(value)}")
            for i, row in enumerate(value):
                check_fields(row, f"{key}[{i}]", source)
            object.__setattr__(obj, spec.name, tuple(value))
        else:
            if value is None and not spec.optional:
                raise fail(key, "is missing (required)")
            object.__setattr__(obj, spec.name, check_value(spec, value, key, fail))


# --------------------------------------------------------------------------------------------
# Documentation
# --------------------------------------------------------------------------------------------

_TYPE_TEXT = {
    "int": "integer", "float": "number", "str": "string", "bool": "boolean", "floats": "list of numbers",
    "matrix": "list of lists of numbers", "float_or_floats": "number or list of numbers", "any": "any value",
}


def _default_text(spec: FieldSpec) -> str:
    if spec.param.default_doc is not None:
        return spec.param.default_doc
    if spec.required:
        return "required"
    default = spec.default({})
    if default is None:
        return "none"
    if isinstance(default, bool):
        return f"`{str(default).lower()}`"
    if isinstance(default, str):
        return f'`"{default}"`'
    if isinstance(default, tuple):
        return "`[" + ", ".join(f"{v:g}" for v in default) + "]`"
    if isinstance(default, float):
        if math.isclose(default, 10.0 / 3.0):
            return "10/3"
        return f"{default:g}"
    return str(default)


def _allowed_text(spec: FieldSpec) -> str:
    p = spec.param
    parts = []
    allowed = p.allowed()
    if allowed is not None:
        parts.append(" or ".join(f'`"{c}"`' if isinstance(c, str) else f"`{c}`" for c in allowed))
    if p.low is not None or p.high is not None:
        text = _interval(p)
        parts.append(f"each in {text}" if spec.kind in ("floats", "matrix") else text)
    if p.max_length is not None:
        unit = {"str": "characters", "tables": "rows", "matrix": "rows"}.get(spec.kind, "values")
        parts.append(f"at most {p.max_length} {unit}")
    return "; ".join(parts) or "–"


def markdown_table(cls: type) -> str:
    """Markdown reference table of the scalar and list keys of the table ``cls`` (sub-tables are
    documented in their own sections)."""
    lines = ["| key | type | unit | default | allowed | meaning |", "|---|---|---|---|---|---|"]
    for spec in file_fields(cls):
        if spec.kind in ("table", "tables"):
            continue
        p = spec.param
        lines.append(
            f"| `{spec.name}` | {_TYPE_TEXT[spec.kind]} | {p.unit or '–'} | {_default_text(spec)} | "
            f"{_allowed_text(spec)} | {p.doc} |"
        )
    return "\n".join(lines)


_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def toml_literal(value: Any, *, bare_keys: bool = False) -> str:
    """``value`` as a TOML literal: ``true``, ``0.5``, ``"text"``, ``[1.0, 2.0]``,
    ``{"equidistant" = 0.0}`` (the right-hand side of an override ``KEY=VALUE``, or a case value as
    a case file writes it). ``bare_keys`` writes the keys of inline tables unquoted where TOML
    allows (``{equidistant = 0.0}``).

    Raises
    ------
    CaseError
        For a value TOML cannot hold.

    Examples
    --------
    >>> toml_literal({"symmetric": True, "values": [0.5, 1]}, bare_keys=True)
    '{symmetric = true, values = [0.5, 1]}'
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_literal(v, bare_keys=bare_keys) for v in value) + "]"
    if isinstance(value, dict):
        def key(k):
            return str(k) if bare_keys and _BARE_KEY.match(str(k)) else json.dumps(str(k))
        return "{" + ", ".join(f"{key(k)} = {toml_literal(v, bare_keys=bare_keys)}" for k, v in value.items()) + "}"
    raise CaseError(f"{value!r} cannot be written as a TOML value")
