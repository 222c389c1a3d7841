"""Reading a case: a parsed file (a dict) or a TOML file into a validated :class:`Case`, the
``KEY=VALUE`` overrides (``--set``) applied before validation, the table class at a dotted key and
the sha256 of a case file.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import tomllib
from pathlib import Path
from typing import Any, Sequence

from rvfem.case.schema import closest, file_fields, read_table, table_error
from rvfem.case.whole_case import _COMPONENT_TABLES, _HOLE_SHAPES, Case, _component_table_names, _other_hole_names
from rvfem.errors import CaseError

__all__ = [
    "case_from_dict",
    "table_class",
    "parse_override",
    "apply_overrides",
    "load_case",
    "file_sha256",
]


# --------------------------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------------------------


def case_from_dict(data: dict, source: str = "<dict>") -> Case:
    """Validate a parsed case (a dict shaped like the TOML file) and build a :class:`Case`.

    The tables of registered hole shapes and stage components are top-level tables like the
    built-in ones (:attr:`Case.other_holes`, :attr:`Case.component_tables`).

    Raises
    ------
    CaseError
        With the file (``source``) and the dotted key of the first problem found.
    """
    holes, components = _other_hole_names(), _component_table_names()
    others = holes + components
    if not others or not isinstance(data, dict):
        return read_table(Case, data, "", source, extra={"source": source})
    known = tuple(spec.name for spec in file_fields(Case)) + others
    for name in data:
        if name not in known:
            hint = closest(name, known)
            raise table_error(source, name, "is not a known key" + (f" (did you mean '{hint}'?)" if hint else "")
                              + "; remove it or check the spelling")
    values: dict[str, Any] = {"<source>": source}
    case = read_table(Case, {k: v for k, v in data.items() if k not in others}, "", source, values,
                      extra={"source": source})
    changes: dict[str, Any] = {}
    tables = tuple((name, read_table(_HOLE_SHAPES[name].table, data[name], name, source, values))
                   for name in holes if name in data)
    if tables:
        changes["other_holes"] = tables
    given = tuple((name, read_table(_COMPONENT_TABLES[name].schema, data[name], name, source, values))
                  for name in components if name in data)
    if given:   # a table there by default and not given is added by Case, with its defaults
        changes["component_tables"] = given
    return dataclasses.replace(case, **changes) if changes else case


def table_class(dotted: str) -> type:
    """The dataclass of the table at dotted key ``dotted`` ("" for the top level, e.g.
    ``"cycloid.modification"``, ``"loads.duty_cycle"``)."""
    cls: type = Case
    parts = [p for p in dotted.split(".") if p]
    if parts and parts[0] in _other_hole_names():
        cls, parts = _HOLE_SHAPES[parts[0]].table, parts[1:]
    elif parts and parts[0] in _component_table_names():
        cls, parts = _COMPONENT_TABLES[parts[0]].schema, parts[1:]
    for part in parts:
        spec = {s.name: s for s in file_fields(cls)}.get(part)
        if spec is None or spec.item is None:
            raise KeyError(f"no table {dotted!r} in the case format")
        cls = spec.item
    return cls


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


def file_sha256(path: str | Path) -> str:
    """sha256 of a file's bytes (recorded in results so they can be traced to their case file)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()
