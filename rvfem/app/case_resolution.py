"""The case an analysis analyses: a case file or a case with overrides and options resolved, its
provenance (file, checksum, overrides, defaults used) and its crank angles."""

from __future__ import annotations

import dataclasses
import logging
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rvfem.case.definition import Case, apply_overrides, case_to_dict, file_sha256, load_case, parse_override
from rvfem.case.registry import bearing_model_names
from rvfem.errors import CaseError
from rvfem.evaluate import rigid
from rvfem.results.analysis import CaseProvenance

log = logging.getLogger("rvfem.app.analysis")

__all__ = ["MIN_ANGLES", "cycle_angles", "resolve_case"]

MIN_ANGLES = 4
"""Fewest crank angles per turn a load cycle may have."""


_WITH_OVERRIDES = " (with overrides)"  # suffix rvfem.case.definition.load_case gives Case.source with overrides


def _defaults_used(raw: dict, case: Case) -> tuple[tuple[str, Any], ...]:
    """Dotted keys of ``case`` that ``raw`` (the file's data) does not set, with their values."""
    out: list[tuple[str, Any]] = []

    def walk(full: Any, given: Any, prefix: str) -> None:
        if not isinstance(full, dict):
            return
        for key, value in full.items():
            dotted = f"{prefix}{key}"
            if not isinstance(given, dict) or key not in given:
                if value not in ([], {}, "", None):
                    out.append((dotted, value))
            elif isinstance(value, dict):
                walk(value, given[key], dotted + ".")

    walk(case_to_dict(case), raw, "")
    return tuple(out)


def _read_raw(path: Path) -> dict | None:
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return None


def resolve_case(case: Case | str | os.PathLike, *, overrides: tuple[str, ...] = (),
                 angle_step_deg: float | None = None, bearing_model: str | None = None,
                 order: int | None = None) -> tuple[Case, CaseProvenance]:
    """The case to analyse, with the options applied, and where it comes from.

    Parameters
    ----------
    case : Case or path
        A case (built in code, or read with :func:`rvfem.case.definition.load_case`, overrides included) or
        the path of a case file.
    overrides : tuple of str
        ``KEY=VALUE`` overrides applied when ``case`` is a path (see :func:`rvfem.case.definition.load_case`).
    angle_step_deg : float, optional
        Crank-angle step, degrees (overrides ``analysis.angle_step_deg``).
    bearing_model : str, optional
        Overrides ``crank_bearing.model`` (one of :func:`rvfem.case.registry.bearing_model_names`).
    order : {1, 2}, optional
        Overrides ``analysis.element_order``.

    Returns
    -------
    (Case, CaseProvenance)

    Raises
    ------
    CaseError
        A bad file, override or option (one line naming the key).
    """

    source = _case_source(case, overrides)
    given = _overrides_given(source.base)
    defaults = _file_defaults(source)
    effective, options = _with_options(source.base, angle_step_deg=angle_step_deg, order=order,
                                       bearing_model=bearing_model)
    given.update(options)
    path = source.path
    provenance = CaseProvenance(
        file=str(path) if path is not None else None,
        sha256=file_sha256(path) if path is not None else None,
        matches_file=source.matches and not given,
        overrides=given,
        defaults_used=defaults,
    )
    return effective, provenance


@dataclass(frozen=True, eq=False)
class _CaseSource:
    """A case before the options of :func:`resolve_case`, and its file.

    Attributes
    ----------
    base : Case
        The case as given, or as read from its file with the ``KEY=VALUE`` overrides.
    path : Path or None
        Its case file (None for a case whose ``source`` is no file).
    matches : bool
        True if ``base`` is exactly what its file and its overrides give.
    """

    base: Case
    path: Path | None
    matches: bool


def _case_source(case: Case | str | os.PathLike, overrides: tuple[str, ...]) -> _CaseSource:
    """The case to resolve: a :class:`Case` as given (its file found from ``Case.source`` and read
    again to tell whether the case is still the file's), or the case file ``case`` read with
    ``overrides``."""
    if not isinstance(case, Case):
        path = Path(case)
        return _CaseSource(base=load_case(path, overrides), path=path, matches=True)
    source = case.source[: -len(_WITH_OVERRIDES)] if case.source.endswith(_WITH_OVERRIDES) else case.source
    path = Path(source)
    if not path.is_file():
        return _CaseSource(base=case, path=None, matches=False)
    try:
        matches = load_case(path, case.overrides) == case
    except CaseError:
        matches = False
    return _CaseSource(base=case, path=path, matches=matches)


def _overrides_given(base: Case) -> dict[str, Any]:
    """Dotted case key → value of the case's ``KEY=VALUE`` overrides (:attr:`Case.overrides`)."""
    given: dict[str, Any] = {}
    for text in base.overrides:
        parts, value = parse_override(text)
        given[".".join(parts)] = value
    return given


def _file_defaults(source: _CaseSource) -> tuple[tuple[str, Any], ...]:
    """The defaults the case uses (:func:`_defaults_used`): keys that neither its file nor its
    overrides set; none known for a case that is not its file's (or whose file cannot be read)."""
    if source.path is None or not source.matches:
        return ()
    raw = _read_raw(source.path)
    if raw is None:
        return ()
    return _defaults_used(apply_overrides(raw, source.base.overrides), source.base)


def _with_options(base: Case, *, angle_step_deg: float | None, order: int | None,
                  bearing_model: str | None) -> tuple[Case, dict[str, Any]]:
    """``base`` with the options of :func:`resolve_case` applied (each checked; the case is checked
    again as a whole), and the options as dotted case key → value (empty without options: ``base``
    is returned as it is)."""
    options: dict[str, Any] = {}
    analysis, bearing = base.analysis, base.crank_bearing
    if angle_step_deg is not None:
        if not (isinstance(angle_step_deg, (int, float)) and angle_step_deg > 0):
            raise CaseError(f"the angle step must be positive, got {angle_step_deg!r}")
        analysis = dataclasses.replace(analysis, angle_step_deg=float(angle_step_deg))
        options["analysis.angle_step_deg"] = float(angle_step_deg)
    if order is not None:
        if order not in (1, 2):
            raise CaseError(f"the element order must be 1 or 2, got {order!r}")
        analysis = dataclasses.replace(analysis, element_order=int(order))
        options["analysis.element_order"] = int(order)
    if bearing_model is not None:
        names = bearing_model_names()
        if bearing_model not in names:
            raise CaseError(f"the bearing model must be one of {', '.join(repr(n) for n in names)}, "
                            f"got {bearing_model!r}")
        bearing = dataclasses.replace(bearing, model=bearing_model)
        options["crank_bearing.model"] = bearing_model
    if not options:
        return base, options
    try:
        effective = base.replace(analysis=analysis, crank_bearing=bearing)
    except CaseError as exc:
        text = ", ".join(f"{k} = {v}" for k, v in options.items())
        raise CaseError(f"the overrides ({text}) are not valid: {exc}") from None
    return dataclasses.replace(effective, overrides=base.overrides), options


def cycle_angles(case: Case) -> np.ndarray:
    """Crank angles of a load cycle of ``case``: :func:`rvfem.evaluate.rigid.load_cycle_angles` at
    ``analysis.angle_step_deg``, at least :data:`MIN_ANGLES` of them, rad.

    Raises
    ------
    CaseError
        If the step leaves fewer than four angles per turn.
    """
    step = case.analysis.angle_step_deg
    if int(round(360.0 / step)) < MIN_ANGLES:
        raise CaseError(f"the angle step {step:g}° leaves fewer than {MIN_ANGLES} angles per turn")
    return rigid.load_cycle_angles(step)
