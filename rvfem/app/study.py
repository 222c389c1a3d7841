"""Design studies: many variants of one case, each a full analysis, run on Dask distributed.

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

:func:`run_study` runs each variant as :func:`rvfem.app.run.run_case` (images off) on a Dask
cluster — a :class:`distributed.LocalCluster` with one single-threaded worker process per core
by default, or an existing scheduler by address — and writes::

    DIR/variants/<id>/      the variant's result folder (summary.json, CSV, VTK, plots, report)
    DIR/study.csv           one row per variant: parameters, loads, deltas, lives, stress, status
    DIR/study.json          the study as run: base case, overrides and digest of every variant
    DIR/plots/*.png         response curves (grid), tornado chart (sensitivity), bar chart (list)
    DIR/report.html         self-contained report

Where the results go: every worker writes its variant's result folder directly into
``DIR/variants/<id>/`` (atomically, by :func:`~rvfem.app.run.run_case`), so ``DIR`` must be on a
file system the workers share with the client — the usual set-up of a cluster (NFS, Lustre) and
trivially true on one machine. Only the small ``summary.json`` content travels back through
Dask (about 10 kB per variant); the VTK files and tables (megabytes) never pass through the
scheduler. The client checks that it sees each folder and says so if it does not.

Robustness: a variant that fails (bad geometry, contact not converging, worker lost) is recorded
with its message and the study goes on; a rerun skips every variant whose folder holds a
``summary.json`` of the same case digest (resume); Ctrl-C cancels the futures and leaves no
half-written variant folder (nor plots folder: both are written through
:func:`rvfem.outputs.summary.result_folder`); a lock file refuses a second study writing into the same
folder.
"""

from __future__ import annotations

import base64
import contextlib
import csv
import hashlib
import html
import io
import itertools
import json
import logging
import math
import os
import re
import shutil
import signal
import socket
import threading
import time
import tomllib
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

from threadpoolctl import threadpool_limits

from rvfem._files import write_text_atomic
from rvfem.app.run import run_case
from rvfem.case.definition import case_to_dict, load_case, parse_override
from rvfem.case.schema import param, read_table, toml_literal
from rvfem.errors import CaseError, OutputError, RvfemError
from rvfem.outputs.summary import check_output_folder, prepare_output_folder, result_folder

log = logging.getLogger(__name__)

__all__ = [
    "STUDY_KINDS",
    "ClusterError",
    "Parameter",
    "Variant",
    "Study",
    "VariantTask",
    "StudyResult",
    "load_study",
    "run_variant",
    "run_study",
    "local_cluster",
    "SingleThreadedBlas",
    "study_rows",
    "study_figures",
    "read_study_csv",
    "toml_literal",
]

STUDY_KINDS = ("grid", "sensitivity", "list")
"""The three ways a study file can vary its base case."""

LOCK_NAME = ".study.lock"
"""Lock file in the study folder while a study writes into it."""

BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                         "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")
"""Environment variables set to 1 in the workers of a local cluster (one core, one thread)."""

_ID_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._=,+-]*$")
_SAFE = re.compile(r"[^A-Za-z0-9._=,+-]")


class ClusterError(RvfemError, RuntimeError):
    """The Dask cluster cannot be reached or started."""


# --------------------------------------------------------------------------------------------
# Study file
# --------------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------------
# One variant (runs in a Dask worker)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class VariantTask:
    """What a worker needs to run one variant (small, picklable; absolute paths).

    Attributes
    ----------
    variant_id : str
    base_case : str
        Absolute path of the base case file.
    overrides : tuple of str
    digest : str
        Expected case digest (a worker seeing another case file refuses).
    out_dir : str
        Absolute path of the variant's result folder (on a file system shared with the client).
    cache_dir : str
        Absolute path of the mesh cache.
    """

    variant_id: str
    base_case: str
    overrides: tuple[str, ...]
    digest: str
    out_dir: str
    cache_dir: str


class _Cancelled(Exception):
    """The client cancelled the variant while it ran (raised from run_case's progress callback)."""


def _cancellation_check() -> Callable[[str, int, int], None] | None:
    """A progress callback for :func:`~rvfem.app.run.run_case` that aborts the run once the client has
    cancelled its Dask task (Ctrl-C, or the client went away): run_case then removes its temporary
    folder, so a cancelled variant leaves nothing behind. None outside a Dask worker."""
    try:
        from distributed import (
            get_worker,  # studies only: Dask's scheduler is a heavy import
        )
        from distributed.worker import (
            thread_state,  # studies only: Dask's scheduler is a heavy import
        )

        worker, key = get_worker(), thread_state.key
    except (ImportError, ValueError, AttributeError):
        return None

    def check(stage: str, done: int, total: int) -> None:
        ts = worker.state.tasks.get(key)
        if ts is None or ts.state in ("cancelled", "released", "forgotten"):
            raise _Cancelled(f"cancelled during stage {stage}")

    return check


def run_variant(task: VariantTask) -> dict:
    """Run one variant into its result folder and return a small record.

    Errors a user can cause (:class:`~rvfem.errors.RvfemError`) and bugs are recorded, never
    raised: the record's ``status`` is ``"ok"``, ``"failed"`` (an RvfemError) or ``"error"`` (any
    other exception; its traceback is logged on the worker).

    Returns
    -------
    dict
        ``id``, ``status``, ``error`` (one line or ""), ``wall_time_s``, ``computed`` (True),
        ``host``, ``pid`` and ``summary`` (the content of ``summary.json``, or None).
    """

    started = time.perf_counter()
    record = {"id": task.variant_id, "status": "ok", "error": "", "computed": True,
              "host": socket.gethostname(), "pid": os.getpid(), "summary": None}
    try:
        case = load_case(task.base_case, task.overrides)
        if case.digest() != task.digest:
            raise CaseError(f"{task.base_case}: the case file changed since the study was checked "
                            "(the variant's case digest differs); run the study again")
        result = run_case(case, task.out_dir, images=False, overwrite=True, cache_dir=task.cache_dir,
                          progress=_cancellation_check())
        record["summary"] = result.summary
    except _Cancelled as exc:
        record.update(status="cancelled", error=str(exc))
    except RvfemError as exc:
        record.update(status="failed", error=_one_line(f"{type(exc).__name__}: {exc}"))
    except Exception as exc:  # a bug: keep the study going, log the traceback where it happened
        log.exception("variant %s: unexpected error", task.variant_id)
        record.update(status="error", error=_one_line(f"{type(exc).__name__}: {exc}"))
    record["wall_time_s"] = time.perf_counter() - started
    return record


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


# --------------------------------------------------------------------------------------------
# Study folder: lock, resume, clean-up
# --------------------------------------------------------------------------------------------


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _acquire_lock(out_dir: Path) -> Path:
    """Create ``out_dir/.study.lock`` exclusively; a stale lock of a dead process on this host is
    taken over."""
    lock = out_dir / LOCK_NAME
    me = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:
            try:
                owner = json.loads(lock.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                owner = {}
            if owner.get("host") == me["host"] and isinstance(owner.get("pid"), int) and not _pid_alive(owner["pid"]):
                log.warning("removing the stale lock %s of process %s, which no longer runs", lock, owner["pid"])
                lock.unlink(missing_ok=True)
                continue
            raise OutputError(f"{out_dir} is in use by another study (lock file {lock}: process "
                              f"{owner.get('pid', '?')} on {owner.get('host', '?')} since {owner.get('started', '?')}); "
                              "wait for it, or delete the lock file if that study no longer runs") from None
        except OSError as exc:
            raise OutputError(f"cannot write the lock file {lock}: {exc.strerror or exc}") from None
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(me, f)
        return lock
    raise OutputError(f"cannot take the lock file {lock}")


def _remove_partials(folder: Path) -> None:
    """Remove the temporary folders ``.<name>.partial-*`` of :func:`rvfem.outputs.summary.result_folder`
    that a killed process left behind in ``folder`` (variant folders of a killed worker, the
    plots of a killed study)."""
    if folder.is_dir():
        for p in folder.glob(".*.partial-*"):
            shutil.rmtree(p, ignore_errors=True)


def _existing_record(variant: Variant, folder: Path) -> dict | None:
    """The record of a complete earlier result of the same case digest, else None."""
    try:
        summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(summary, dict) or summary.get("case", {}).get("digest") != variant.digest:
        return None
    return {"id": variant.id, "status": "ok", "error": "", "computed": False, "host": "", "pid": None,
            "summary": summary, "wall_time_s": float(summary.get("timings_s", {}).get("total", float("nan")))}


# --------------------------------------------------------------------------------------------
# Dask
# --------------------------------------------------------------------------------------------


try:  # a declared dependency; the base class lets the plugin be registered by type
    from distributed import WorkerPlugin as _WorkerPluginBase
except ImportError:  # pragma: no cover
    _WorkerPluginBase = object


class SingleThreadedBlas(_WorkerPluginBase):
    """Worker plugin: one worker, one core.

    Limits the BLAS/OpenMP thread pools of the worker to one thread (also in workers started by
    hand, without the nanny's environment). With ``pin_core=True`` (the workers of
    :func:`local_cluster`) it also pins the worker process to one core of the machine, worker
    ``i`` to the ``i``-th allowed core, so that the few threads an analysis starts itself (the
    parallel back-substitutions of the contact columns) share that core instead of competing with
    the other workers (Linux; elsewhere a no-op).
    """

    name = "rvfem-single-threaded-blas"
    idempotent = True

    def __init__(self, pin_core: bool = False):
        self.pin_core = pin_core

    def setup(self, worker) -> None:
        try:

            self._limits = threadpool_limits(limits=1)
        except Exception:  # a library threadpoolctl cannot control: leave it
            log.debug("threadpoolctl could not limit the thread pools", exc_info=True)
        if self.pin_core and isinstance(worker.name, int) and hasattr(os, "sched_setaffinity"):
            try:
                cores = sorted(os.sched_getaffinity(0))
                core = {cores[worker.name % len(cores)]}
                for tid in os.listdir("/proc/self/task"):  # every thread of the process, and the
                    os.sched_setaffinity(int(tid), core)   # threads started later inherit it
            except OSError:
                log.debug("could not pin worker %s to a core", worker.name, exc_info=True)


def local_cluster(workers: int | None = None):
    """A :class:`distributed.LocalCluster` for studies: ``workers`` processes (default: one per
    core), one thread each, BLAS/OpenMP pinned to one thread and each worker to its own core,
    listening on 127.0.0.1 only, no dashboard.

    Raises
    ------
    ClusterError
        The cluster cannot be started.
    """
    from distributed import (
        LocalCluster,  # studies only: Dask's scheduler is a heavy import
    )

    n = workers or os.cpu_count() or 1
    env = {name: "1" for name in BLAS_THREAD_VARIABLES}
    if os.environ.get("PYTHONPATH"):
        env["PYTHONPATH"] = os.environ["PYTHONPATH"]
    try:
        with _sigint_ignored_by_children():
            # no dashboard; the scheduler's small HTTP server (health, metrics) on a free port, not
            # on 8787, which another cluster may hold ("Port 8787 is already in use" otherwise)
            return LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                                env=env, silence_logs=logging.ERROR, host="127.0.0.1",
                                plugins=(SingleThreadedBlas(pin_core=True),))
    except Exception as exc:
        raise ClusterError(f"cannot start a local Dask cluster of {n} workers: {_one_line(exc)}") from None


@contextlib.contextmanager
def _sigint_ignored_by_children():
    """SIGINT ignored while the local cluster starts its worker processes, which keep it ignored.

    Ctrl-C at a terminal (and a notebook's "interrupt kernel") signals the whole process group:
    without this every worker process would print the traceback of its own KeyboardInterrupt.
    The workers are stopped by this process instead, which cancels the variants and closes the
    cluster. A no-op outside the main thread (only it can change signal handlers).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextlib.contextmanager
def _dask_logging_silenced():
    """Dask's loggers (and those of tornado, its event loop) silenced but for critical messages
    (restored afterwards): the warnings of a cluster shut down after Ctrl-C ("Worker process still
    alive after 4.0 seconds, killing") and the errors of callbacks cut short by it (a cancel that
    raced the interrupt: "NameError: cannot access free variable 'future'" in distributed's
    ``sync``) say nothing the interrupted study does not."""
    loggers = [logging.getLogger("distributed"), logging.getLogger("tornado")] + [
        logger for name, logger in logging.root.manager.loggerDict.items()
        if name.startswith(("distributed.", "tornado.")) and isinstance(logger, logging.Logger)]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels):
            logger.setLevel(level)


def _connect(scheduler: str, timeout_s: float):
    from distributed import Client  # studies only: Dask's scheduler is a heavy import

    try:
        return Client(scheduler, timeout=timeout_s, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise ClusterError(f"cannot connect to the Dask scheduler at {scheduler}: {_one_line(exc)}") from None
    except ValueError as exc:
        raise ClusterError(f"--scheduler {scheduler!r}: {_one_line(exc)} (expected tcp://HOST:PORT)") from None


# --------------------------------------------------------------------------------------------
# Running a study
# --------------------------------------------------------------------------------------------


ProgressCallback = Callable[[int, int, dict], None]
"""``progress(done, total, record)`` after each variant computed in this run (the reused ones are
counted in ``done`` from the start)."""


@dataclass(frozen=True)
class StudyResult:
    """Outcome of :func:`run_study`.

    Attributes
    ----------
    out_dir : Path
    study : Study
    rows : tuple of dict
        The rows of ``study.csv`` (numbers as floats, missing values None), in variant order.
    computed, reused, failed : int
        Variants computed in this run, taken from an earlier run, failed (of both).
    files : dict
        ``"csv"``, ``"json"``, ``"report"`` and the plots (name → path).
    wall_time_s : float
        Wall time of this call, seconds.
    compute_time_s : float
        The variants' own run times added up, seconds: those computed in this call and those
        taken from an earlier run (their recorded time), each case once (a variant ``same_as``
        another is not counted again); failed variants count, cancelled ones do not.
    """

    out_dir: Path
    study: Study
    rows: tuple[dict, ...]
    computed: int
    reused: int
    failed: int
    files: dict
    wall_time_s: float
    compute_time_s: float = 0.0


def run_study(study: Study | str | os.PathLike, out_dir: str | os.PathLike, *, scheduler: str | None = None,
              workers: int | None = None, client=None, cache_dir: str | os.PathLike = "meshes",
              progress: ProgressCallback | None = None, plots: bool = True,
              connect_timeout_s: float = 30.0) -> StudyResult:
    """Run every variant of a study on Dask and write the study folder.

    Parameters
    ----------
    study : Study or path
        A study (:func:`load_study`) or the path of a study file.
    out_dir : path
        Study folder; created if missing. An earlier run's results in it are reused where the
        case digest matches (resume).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://HOST:PORT``); default: a local cluster.
    workers : int, optional
        Workers of the local cluster (default: one per core). Ignored with ``scheduler``/``client``.
    client : distributed.Client, optional
        Use this client (e.g. from a notebook) instead of creating one; it is not closed.
    cache_dir : path
        Mesh cache (shared by the workers; relative paths are taken from the working directory).
    progress : callable, optional
        See :data:`ProgressCallback`.
    plots : bool
        Write the plots and embed them in the report.
    connect_timeout_s : float
        How long to try to reach ``scheduler``, seconds.

    Returns
    -------
    StudyResult

    Raises
    ------
    CaseError
        From :func:`load_study`.
    OutputError
        ``out_dir`` is locked by another study or cannot be written.
    ClusterError
        The scheduler cannot be reached or the local cluster not started.
    KeyboardInterrupt
        After cancelling the futures and writing ``study.csv`` of what was done.
    """
    started = time.perf_counter()
    if not isinstance(study, Study):
        study = load_study(study)
    out_dir = Path(out_dir).resolve()
    cache = Path(cache_dir).resolve()
    check_output_folder(out_dir, overwrite=True)   # a non-empty folder rvfem did not write is refused
    own_client = None
    if client is None and scheduler and _work_left(study, out_dir / "variants"):
        # reach the scheduler before anything is created: an unreachable one leaves no folder behind
        client = own_client = _connect(scheduler, connect_timeout_s)
    try:
        with _removed_if_new_on(ClusterError, out_dir):
            prepare_output_folder(out_dir, "study", ("variants",))
            lock = _acquire_lock(out_dir)
            try:
                return _run_locked(study, out_dir, cache, scheduler=scheduler, workers=workers, client=client,
                                   progress=progress, plots=plots, connect_timeout_s=connect_timeout_s,
                                   started=started)
            finally:
                lock.unlink(missing_ok=True)
    finally:
        if own_client is not None:
            with _dask_logging_silenced():
                own_client.close()


def _work_left(study: Study, variants_dir: Path) -> bool:
    """True if a case of ``study`` has no complete earlier result in ``variants_dir`` (a variant
    of the same case as an earlier one is computed once, in the earlier one's folder)."""
    first = {}
    for v in study.variants:
        first.setdefault(v.digest, v)
    return any(_existing_record(v, variants_dir / v.id) is None for v in first.values())


@contextlib.contextmanager
def _removed_if_new_on(error: type[BaseException], folder: Path):
    """Remove ``folder`` and the parents created with it if the block raises ``error`` and the
    folder did not exist before: a study or optimisation that cannot start (no cluster) leaves
    nothing behind. An existing folder (a run taken up again) is left as it is."""
    new = [p for p in (folder, *folder.parents) if not p.exists()]
    try:
        yield
    except error:
        for p in new[:1]:
            shutil.rmtree(p, ignore_errors=True)
        for p in new[1:]:
            try:
                p.rmdir()
            except OSError:
                break
        raise


def _run_locked(study: Study, out_dir: Path, cache: Path, *, scheduler, workers, client, progress, plots,
                connect_timeout_s, started) -> StudyResult:
    variants_dir = out_dir / "variants"
    _remove_partials(variants_dir)
    _remove_partials(out_dir)
    write_text_atomic(out_dir / "study.json", json.dumps(_study_dict(study), indent=2, allow_nan=False) + "\n")
    records: dict[str, dict] = {}
    todo: list[Variant] = []
    first_of: dict[str, str] = {}  # case digest -> id of the variant that computes it
    for v in study.variants:
        if v.digest in first_of:  # the same case as an earlier variant (e.g. the base in a grid)
            continue
        first_of[v.digest] = v.id
        earlier = _existing_record(v, variants_dir / v.id)
        if earlier is not None:
            records[v.id] = earlier
        else:
            todo.append(v)
    if records:
        log.info("study %s: %d of %d variants reused from an earlier run", study.name, len(records), len(first_of))
    total = len(first_of)
    interrupted = False
    if todo:
        try:
            _compute(study, todo, variants_dir, cache, records, total, scheduler=scheduler, workers=workers,
                     client=client, progress=progress, connect_timeout_s=connect_timeout_s)
        except KeyboardInterrupt:
            interrupted = True
            raise
        finally:
            for v in study.variants:
                records.setdefault(first_of[v.digest], {
                    "id": v.id, "status": "cancelled" if interrupted else "not run",
                    "error": "interrupted before it finished" if interrupted else "",
                    "computed": False, "summary": None, "wall_time_s": float("nan")})
            _same_case_records(study, records, first_of)
            rows = study_rows(study, records)
            write_text_atomic(out_dir / "study.csv", _csv_text(rows))
    _same_case_records(study, records, first_of)
    rows = study_rows(study, records)
    files = {"csv": out_dir / "study.csv", "json": out_dir / "study.json"}
    write_text_atomic(files["csv"], _csv_text(rows))
    plot_files = _plots(study, rows, out_dir / "plots") if plots else {}
    files.update(plot_files)
    files["report"] = out_dir / "report.html"
    compute = _compute_time(records)
    wall = time.perf_counter() - started
    write_text_atomic(files["report"], _report_html(study, rows, plot_files, wall, compute))
    computed = sum(1 for r in records.values() if r["computed"])
    failed = sum(1 for r in records.values() if r["status"] != "ok")
    return StudyResult(out_dir=out_dir, study=study, rows=tuple(rows), computed=computed,
                       reused=sum(1 for r in records.values()
                                  if not r["computed"] and r["status"] == "ok" and not r.get("same_as")),
                       failed=failed, files=files, wall_time_s=wall, compute_time_s=compute)


def _compute_time(records: dict) -> float:
    """The variants' recorded run times added up (each case once; unknown times left out)."""
    times = (r.get("wall_time_s") for r in records.values() if not r.get("same_as"))
    return math.fsum(t for t in times if isinstance(t, (int, float)) and math.isfinite(t))


def _same_case_records(study: Study, records: dict, first_of: dict) -> None:
    """Records of the variants whose case another variant computed (same digest)."""
    for v in study.variants:
        first = first_of[v.digest]
        if first != v.id:
            records[v.id] = {**records[first], "id": v.id, "computed": False, "same_as": first}


def _compute(study: Study, todo: list[Variant], variants_dir: Path, cache: Path, records: dict, total: int, *,
             scheduler, workers, client, progress, connect_timeout_s) -> None:
    from distributed import (
        as_completed,  # studies only: Dask's scheduler is a heavy import
    )

    cluster = None
    own_client = client is None
    if own_client:
        if scheduler:
            client = _connect(scheduler, connect_timeout_s)
        else:
            cluster = local_cluster(workers)
            from distributed import (
                Client,  # studies only: Dask's scheduler is a heavy import
            )

            client = Client(cluster, set_as_default=False)
    futures = []
    interrupted = False
    try:
        try:
            client.register_plugin(SingleThreadedBlas())
        except Exception:
            log.debug("could not register the single-threaded BLAS plugin", exc_info=True)
        token = uuid.uuid4().hex[:8]
        by_key = {}
        for v in todo:
            task = VariantTask(v.id, str(study.base_case), v.overrides, v.digest, str(variants_dir / v.id), str(cache))
            fut = client.submit(run_variant, task, key=f"rvfem-variant-{v.id}-{token}", pure=False)
            futures.append(fut)
            by_key[fut.key] = v
        done = len(records)
        for fut in as_completed(futures, loop=client.loop):
            v = by_key[fut.key]
            if fut.status == "finished":
                record = fut.result()
            else:  # the task itself raised (e.g. the worker died running it: KilledWorker)
                exc = fut.exception()
                record = {"id": v.id, "status": "failed", "computed": True, "summary": None,
                          "error": _one_line(f"{type(exc).__name__}: {exc}"), "wall_time_s": float("nan")}
            if record["status"] == "ok" and not (variants_dir / v.id / "summary.json").is_file():
                record.update(status="failed", error=f"the worker wrote its results, but {variants_dir / v.id} is "
                              "not visible here: the study folder must be on a file system shared by the workers")
            if record["status"] != "ok":
                log.info("variant %s failed: %s", v.id, record["error"])
            records[v.id] = record
            done += 1
            if progress is not None:
                progress(done, total, record)
    except BaseException as exc:
        interrupted = isinstance(exc, KeyboardInterrupt)
        if futures:
            with _dask_logging_silenced() if interrupted else contextlib.nullcontext():
                try:
                    client.cancel(futures, force=True)
                except Exception:
                    log.debug("cancelling the futures failed", exc_info=True)
        raise
    finally:
        with _dask_logging_silenced() if interrupted else contextlib.nullcontext():
            if own_client:
                client.close()
            if cluster is not None:
                cluster.close()
        if cluster is not None:
            _remove_partials(variants_dir)  # the local workers are gone: nothing writes there any more


# --------------------------------------------------------------------------------------------
# study.csv
# --------------------------------------------------------------------------------------------


def _pct(value: float | None, ref: float | None) -> float | None:
    if value is None or ref is None or not ref:
        return None
    return 100.0 * (value - ref) / ref


def _ratio(value: float | None, ref: float | None) -> float | None:
    if value is None or ref is None or not ref:
        return None
    return value / ref


def _get(d: Any, *keys: str) -> Any:
    for k in keys:
        if not isinstance(d, dict):
            return None
        d = d.get(k)
    return d


def study_rows(study: Study, records: dict[str, dict]) -> list[dict]:
    """The rows of ``study.csv`` from the records of :func:`run_variant` (keyed by variant id).

    Per variant: the parameters, status, and from its ``summary.json`` the flexible max / min /
    F_m / L10h of every bearing, the handbook (rigid) values, deltas in % against the handbook
    and against the base variant, life ratios, the largest load and the stress peaks.
    """
    base_summary = (records.get("base") or {}).get("summary")
    n_bearings = max((len(r["summary"]["bearings"]) for r in records.values() if r.get("summary")), default=0)
    rows = []
    for v in study.variants:
        r = records.get(v.id, {})
        s = r.get("summary")
        settings = dict(v.settings)
        row: dict[str, Any] = {"id": v.id, "role": v.role,
                               "varied": ",".join(k for k, _ in v.settings)}
        for p in study.parameters:
            row[p.key] = settings.get(p.key, p.base_value)
        row.update(status=r.get("status", "not run"), computed=r.get("computed", False),
                   same_as=r.get("same_as", ""), error=r.get("error", ""),
                   wall_time_s=r.get("wall_time_s"), digest=v.digest,
                   overrides=";".join(f"{k}={toml_literal(val)}" for k, val in v.settings))
        bearings = s["bearings"] if s else []
        base_bearings = base_summary["bearings"] if base_summary else []
        flex = [b["flexible"] for b in bearings]
        rigid = [b["rigid"] for b in bearings if b.get("rigid")]   # none where the handbook is not defined
        max_load = max((f["max_load_N"] for f in flex), default=None)
        fm = max((f["equivalent_load_N"] for f in flex), default=None)
        life = min((f["L10h_h"] for f in flex), default=None)
        rigid_max = max((f["max_load_N"] for f in rigid), default=None)
        rigid_fm = max((f["equivalent_load_N"] for f in rigid), default=None)
        rigid_life = min((f["L10h_h"] for f in rigid), default=None)
        b_flex = [b["flexible"] for b in base_bearings]
        base_max = max((f["max_load_N"] for f in b_flex), default=None)
        base_fm = max((f["equivalent_load_N"] for f in b_flex), default=None)
        base_life = min((f["L10h_h"] for f in b_flex), default=None)
        row.update({
            "max_load_N": max_load,
            "max_load_bearing": _get(s, "max_bearing_load", "bearing"),
            "equivalent_load_N": fm,
            "L10h_h": life,
            "handbook_max_load_N": rigid_max,
            "handbook_equivalent_load_N": rigid_fm,
            "handbook_L10h_h": rigid_life,
            "max_vs_handbook_percent": _pct(max_load, rigid_max),
            "equivalent_vs_handbook_percent": _pct(fm, rigid_fm),
            "life_ratio": _ratio(life, rigid_life),
            "max_vs_base_percent": _pct(max_load, base_max),
            "equivalent_vs_base_percent": _pct(fm, base_fm),
            "life_ratio_vs_base": _ratio(life, base_life),
            "peak_von_mises_MPa": _get(s, "peak_von_mises_MPa"),
            "peak_away_from_contacts_MPa": _get(s, "stress", "away_from_contacts", "peak_von_mises_MPa"),
            "peak_vs_base_percent": _pct(_get(s, "peak_von_mises_MPa"), _get(base_summary, "peak_von_mises_MPa")),
            "disc_mass_kg": _get(s, "disc_mass_kg"),
            "disc_polar_inertia_kg_mm2": _get(s, "disc_polar_inertia_kg_mm2"),
            "mass_vs_base_percent": _pct(_get(s, "disc_mass_kg"), _get(base_summary, "disc_mass_kg")),
            "static_safety_factor": _get(s, "static_safety_factor"),
            "fatigue_safety_factor": _get(s, "fatigue_safety_factor"),
        })
        for i in range(n_bearings):
            pre = f"bearing{i + 1}_"
            b = bearings[i] if i < len(bearings) else None
            bb = base_bearings[i] if i < len(base_bearings) else None
            f, g = (b or {}).get("flexible", {}), (b or {}).get("rigid") or {}
            vs_handbook = bool(g)   # the deltas are against the equal share where there is no handbook
            fb = (bb or {}).get("flexible", {})
            row.update({
                pre + "max_N": f.get("max_load_N"), pre + "min_N": f.get("min_load_N"),
                pre + "Fm_N": f.get("equivalent_load_N"), pre + "L10h_h": f.get("L10h_h"),
                pre + "handbook_max_N": g.get("max_load_N"), pre + "handbook_Fm_N": g.get("equivalent_load_N"),
                pre + "max_vs_handbook_percent": (b or {}).get("delta_max_percent") if vs_handbook else None,
                pre + "Fm_vs_handbook_percent": (b or {}).get("delta_equivalent_percent") if vs_handbook else None,
                pre + "life_ratio": (b or {}).get("life_ratio") if vs_handbook else None,
                pre + "max_vs_base_percent": _pct(f.get("max_load_N"), fb.get("max_load_N")),
                pre + "Fm_vs_base_percent": _pct(f.get("equivalent_load_N"), fb.get("equivalent_load_N")),
            })
        rows.append(row)
    return rows


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)  # repr round-trips: bit-identical numbers
    return str(value)


def _csv_text(rows: list[dict]) -> str:
    if not rows:
        return ""
    columns: list[str] = []
    for row in rows:
        columns.extend(k for k in row if k not in columns)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_cell(row.get(c)) for c in columns])
    return out.getvalue()


def read_study_csv(path: str | os.PathLike) -> list[dict]:
    """Read ``study.csv`` back: numbers as floats (bit-identical to what was written), empty
    cells as None, other cells as strings."""
    rows = []
    with open(path, newline="", encoding="utf-8") as f:
        for raw in csv.DictReader(f):
            row = {}
            for k, text in raw.items():
                if text == "":
                    row[k] = None
                    continue
                try:
                    row[k] = float(text)
                except ValueError:
                    row[k] = text
            rows.append(row)
    return rows


def _study_dict(study: Study) -> dict:
    return {
        "name": study.name, "description": study.description,
        "study_file": str(study.path) if study.path else None, "base_case": str(study.base_case),
        "kind": study.kind, "overrides": list(study.overrides),
        "parameters": [{"key": p.key, "values": list(p.values), "base_value": p.base_value, "label": p.label}
                       for p in study.parameters],
        "variants": [{"id": v.id, "role": v.role, "settings": {k: val for k, val in v.settings},
                      "overrides": list(v.overrides), "digest": v.digest} for v in study.variants],
    }


# --------------------------------------------------------------------------------------------
# Plots and report
# --------------------------------------------------------------------------------------------


def _numeric(values: Sequence[Any]) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def _figure(size: tuple[float, float], **subplots):
    """A figure on an Agg canvas (never :mod:`matplotlib.pyplot`: the caller's backend, e.g. a
    notebook's inline backend, is left alone) and its axes."""
    from matplotlib.backends.backend_agg import (
        FigureCanvasAgg,  # drawing only: matplotlib is a heavy import the solver never needs
    )
    from matplotlib.figure import (
        Figure,  # drawing only: matplotlib is a heavy import the solver never needs
    )

    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(**subplots)


def _response_figure(study: Study, p: Parameter, ok: Sequence[dict]):
    """Grid: the largest bearing load against parameter ``p``, one curve per combination of the
    other parameters, the handbook dotted."""
    others = [q for q in study.parameters if q is not p]
    fig, ax = _figure((6.4, 4.2))
    groups: dict[tuple, list[dict]] = {}
    for r in ok:
        if r["role"] == "grid":
            groups.setdefault(tuple(r[q.key] for q in others), []).append(r)
    numeric = _numeric(p.values)
    positions = {v: i for i, v in enumerate(p.values)}
    for combo, members in sorted(groups.items(), key=lambda kv: repr(kv[0])):
        members.sort(key=lambda r: positions.get(r[p.key], 0))
        x = [r[p.key] if numeric else positions[r[p.key]] for r in members]
        label = ", ".join(f"{q.label} = {_value_text(c)}" for q, c in zip(others, combo)) or "flexible"
        line, = ax.plot(x, [r["max_load_N"] for r in members], "o-", label=label)
        ax.plot(x, [r["handbook_max_load_N"] for r in members], ":", color=line.get_color(), lw=1)
    if not numeric:
        ax.set_xticks(range(len(p.values)), [str(v) for v in p.values])
    ax.set_xlabel(p.label)
    ax.set_ylabel("largest crank-bearing load, N")
    ax.set_title(f"{study.name}: largest bearing load vs {p.label}\n(dotted: rigid handbook)", fontsize=10)
    ax.grid(alpha=0.3)
    if len(groups) <= 8:
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def _tornado_bars(study: Study, ok: Sequence[dict], base: dict) -> list[tuple]:
    """Per parameter ``(span, parameter, [load % low, high], [L10h %], [stress peak %], [mass %])``, smallest span
    first (a side equal to the base value is the base itself)."""
    bars = []
    for p in study.parameters:
        lo, hi = (base if p.values[i] == p.base_value else
                  next((r for r in ok if r["role"] == role and r["varied"] == p.key), None)
                  for i, role in enumerate(("low", "high")))
        d = [r["max_vs_base_percent"] if r else float("nan") for r in (lo, hi)]
        life = [100.0 * (r["life_ratio_vs_base"] - 1.0) if r and r["life_ratio_vs_base"] else float("nan")
                for r in (lo, hi)]
        stress, mass = ([r.get(key) if r and r.get(key) is not None else float("nan") for r in (lo, hi)]
                        for key in ("peak_vs_base_percent", "mass_vs_base_percent"))
        span = max((abs(x) for x in d if not math.isnan(x)), default=0.0)
        bars.append((span, p, d, life, stress, mass))
    bars.sort(key=lambda b: b[0])
    return bars


def _tornado_figure(study: Study, ok: Sequence[dict], base: dict):
    """Sensitivity: change of the largest load, of L10h, of the structural stress peak and of the
    disc mass against the base, per parameter."""
    bars = _tornado_bars(study, ok, base)
    fig, axes = _figure((16, 1.2 + 0.55 * len(bars)), nrows=1, ncols=4, sharey=True)
    y = range(len(bars))
    for ax, idx, title in ((axes[0], 2, "largest bearing load vs base, %"),
                           (axes[1], 3, "L10h vs base, %"),
                           (axes[2], 4, "structural stress peak vs base, %"),
                           (axes[3], 5, "disc mass vs base, %")):
        for yi, bar in zip(y, bars):
            lo, hi = bar[idx]
            ax.barh(yi, lo, color="tab:blue", height=0.6, label="low" if yi == 0 else None)
            ax.barh(yi, hi, color="tab:red", height=0.6, alpha=0.8, label="high" if yi == 0 else None)
        ax.axvline(0.0, color="k", lw=0.8)
        ax.set_xlabel(title)
        ax.grid(axis="x", alpha=0.3)
    axes[0].set_yticks(list(y), [f"{b[1].label}\n{_value_text(b[1].values[0])} / {_value_text(b[1].values[1])}"
                                 for b in bars], fontsize=8)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"{study.name}: one-at-a-time sensitivity around the base "
                 f"(largest load {base['max_load_N']:.0f} N)", fontsize=10)
    fig.tight_layout()
    return fig


def _variants_figure(study: Study, rows: Sequence[dict]):
    """Every variant: flexible largest load and F_m as bars, the handbook maximum as a tick."""
    fig, ax = _figure((max(6.4, 0.45 * len(rows) + 2) + 1.8, 4.2))   # + the legend's column
    x = range(len(rows))
    ax.bar([i - 0.2 for i in x], [r["max_load_N"] or 0.0 for r in rows], width=0.4, label="flexible, largest load")
    ax.bar([i + 0.2 for i in x], [r["equivalent_load_N"] or 0.0 for r in rows], width=0.4, label="flexible, F_m")
    ax.plot(list(x), [r["handbook_max_load_N"] or float("nan") for r in rows], "k_", ms=14, label="handbook max")
    ax.set_xticks(list(x), [r["id"] for r in rows], rotation=60, ha="right", fontsize=7)
    ax.set_ylabel("crank-bearing load, N")
    ax.set_title(f"{study.name}: all variants", fontsize=10)
    # right of the axes: inside it would hide bars
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    return fig


def study_figures(study: Study, rows: Sequence[dict]) -> dict:
    """The plots of a study as :class:`matplotlib.figure.Figure` objects, by name.

    ``"response_<key>"`` per parameter (grid), ``"tornado"`` (sensitivity, when the base is ok) and
    ``"variants"`` (always, once a variant is ok); empty if no variant is ok. ``rows`` are the rows
    of ``study.csv`` (:attr:`StudyResult.rows` or :func:`read_study_csv`). The figures are drawn
    without :mod:`matplotlib.pyplot`, so the caller's backend is left alone; in a notebook, show
    one with ``display(fig)`` or as a cell's last value.
    """
    ok = [r for r in rows if r["status"] == "ok"]
    figures: dict[str, Any] = {}
    if not ok:
        return figures
    if study.kind == "grid":
        for p in study.parameters:
            figures[f"response_{p.key}"] = _response_figure(study, p, ok)
    elif study.kind == "sensitivity":
        base = {r["id"]: r for r in rows}.get("base")
        if base and base["status"] == "ok":
            figures["tornado"] = _tornado_figure(study, ok, base)
    figures["variants"] = _variants_figure(study, rows)
    return figures


def _plot_file_name(name: str) -> str:
    return f"{_SAFE.sub('_', name)}.png"


def _plots(study: Study, rows: list[dict], folder: Path) -> dict:
    """Write :func:`study_figures` into ``folder`` as PNG files; name → path.

    The folder is written as a whole through :func:`rvfem.outputs.summary.result_folder`: it holds the
    plots of one run, and an interrupted run leaves the earlier plots as they were.
    """
    files: dict[str, Path] = {}
    with result_folder(folder, overwrite=True, what="study plots") as tmp:
        for name, fig in study_figures(study, rows).items():
            fig.savefig(tmp / _plot_file_name(name), dpi=110)
            files[name] = folder / _plot_file_name(name)
    return files


def _fmt(value: Any, spec: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return format(value, spec)
    return html.escape(str(value))


STUDY_KEY_RESULTS = ("max_load_N", "max_vs_base_percent", "L10h_h", "life_ratio_vs_base", "peak_von_mises_MPa")
"""The columns of the study report's table right after the id and the status: what a variant gives."""


def study_table_columns(study: Study) -> list[tuple[str, str, str]]:
    """The columns of the study report's table, (key, CSS class, format): the id and the status,
    the key results (:data:`STUDY_KEY_RESULTS`), the other results, then the parameter values and
    the run's wall time and error, so that the results are on screen with many parameters."""
    results = [("max_load_N", "", ".1f"), ("max_vs_base_percent", "", "+.1f"), ("L10h_h", "", ".0f"),
               ("life_ratio_vs_base", "", ".3f"), ("peak_von_mises_MPa", "", ".1f"),
               ("handbook_max_load_N", "", ".1f"), ("max_vs_handbook_percent", "", "+.1f"),
               ("equivalent_load_N", "", ".1f"), ("equivalent_vs_base_percent", "", "+.1f"),
               ("life_ratio", "", ".3f")]
    return [("id", "l id", "s"), ("status", "l", "s"), *results, *[(p.key, "l", "s") for p in study.parameters],
            ("wall_time_s", "", ".1f"), ("error", "l", "s")]


def _report_html(study: Study, rows: list[dict], plots: dict, wall_s: float, compute_s: float) -> str:
    e = html.escape
    parts = [
        "<!DOCTYPE html><html><head><meta charset='utf-8'>",
        f"<title>rvfem study {e(study.name)}</title>",
        "<style>body{font-family:sans-serif;margin:2em;max-width:1400px}table{border-collapse:collapse;"
        "font-size:12px}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}"
        "td.l,th.l{text-align:left}.failed{background:#fdd}img{max-width:100%}"
        "div.scroll{overflow-x:auto;max-width:100%}td.id,th.id{position:sticky;left:0;background:#fff}"
        "tr.failed td.id{background:#fdd}</style></head><body>",
        f"<h1>Study {e(study.name)}</h1>",
        f"<p>{e(study.description)}</p>" if study.description else "",
        f"<p>Kind: <b>{e(study.kind)}</b>; base case <code>{e(study.base_case.name)}</code>"
        + (f" with overrides <code>{e('; '.join(study.overrides))}</code>" if study.overrides else "")
        + f"; {len(rows)} variants, {sum(r['status'] == 'ok' for r in rows)} ok "
        f"({sum(r['status'] == 'ok' and not r['computed'] and not r['same_as'] for r in rows)} from an earlier run); "
        f"compute time of the variants {compute_s:.1f} s (their run times added up, earlier runs included); "
        f"wall time of this run {wall_s:.1f} s.</p>",
        "<p>Loads are the flexible (finite-element) crank-bearing loads of each variant's own analysis; "
        "'handbook' is the rigid model of the same variant; 'vs base' compares with the base case. "
        "peak_von_mises_MPa is the structural stress peak away from contacts that rvfem run reports "
        "(re-solved on P2 by default; study.csv also has the P1 cycle's peak_away_from_contacts_MPa). "
        "Life ratio = L10h / L10h of the reference (shortest-lived bearing). Each variant's full results "
        "are in <code>variants/&lt;id&gt;/</code>.</p>",
    ]
    for name, path in plots.items():
        data = base64.b64encode(Path(path).read_bytes()).decode()
        parts.append(f"<h2>{e(name)}</h2><img src='data:image/png;base64,{data}' alt='{e(name)}'>")
    cols = study_table_columns(study)
    parts.append("<h2>Variants</h2><p>The results first, then the parameter values of each variant (the table "
                 "scrolls sideways; the variant's id stays in view).</p><div class='scroll'><table><tr>"
                 + "".join(f"<th class='{c}'>{e(n)}</th>" for n, c, _ in cols) + "</tr>")
    for r in rows:
        cls = "" if r["status"] == "ok" else " class='failed'"
        parts.append(f"<tr{cls}>" + "".join(
            f"<td class='{c}'>{_fmt(r.get(n), spec) if spec != 's' else e(_value_text(r.get(n)) if r.get(n) is not None else '')}</td>"
            for n, c, spec in cols) + "</tr>")
    parts.append("</table></div><p>All numbers at full precision: <code>study.csv</code>.</p></body></html>")
    return "\n".join(parts)
