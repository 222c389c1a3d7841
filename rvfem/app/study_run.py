"""Running a design study on Dask distributed: one variant per task, the study folder locked,
resumed and cleaned up.

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

import contextlib
import json
import logging
import functools
import math
import os
import shutil
import signal
import socket
import sys
import threading
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from threadpoolctl import threadpool_limits

from rvfem._files import write_text_atomic
from rvfem.app.design import run_design
from rvfem.app.run import run_case
from rvfem.app.study_definition import Study, Variant, load_study
from rvfem.app.study_outputs import report_html, study_csv_text, study_dict, study_rows, write_plots
from rvfem.case.definition import load_case
from rvfem.errors import CaseError, OutputError, RvfemError
from rvfem.outputs.summary import check_output_folder, prepare_output_folder

log = logging.getLogger(__name__)

__all__ = ["LOCK_NAME", "ClusterError", "VariantTask", "StudyResult", "ProgressCallback", "run_variant",
           "run_study", "local_cluster", "SingleThreadedBlas"]

LOCK_NAME = ".study.lock"
"""Lock file in the study folder while a study writes into it."""

BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                         "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")
"""Environment variables set to 1 in the workers of a local cluster (one core, one thread)."""

class ClusterError(RvfemError, RuntimeError):
    """The Dask cluster cannot be reached or started."""



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
    design_only : bool
        Compute and write only what an optimiser design reads (:func:`rvfem.app.design.run_design`)
        instead of the full :func:`~rvfem.app.run.run_case`.
    """

    variant_id: str
    base_case: str
    overrides: tuple[str, ...]
    digest: str
    out_dir: str
    cache_dir: str
    design_only: bool = False


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
        if task.design_only:
            record["summary"] = run_design(case, task.out_dir, cache_dir=task.cache_dir, progress=_cancellation_check())
        else:
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


def _one_line(text: object) -> str:
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


class _SingleThreadedBlasSetup:
    """Worker plugin: one worker, one core.

    Limits the BLAS/OpenMP thread pools of the worker to one thread (also in workers started by
    hand, without the nanny's environment). With ``local=True`` (the workers of
    :func:`local_cluster`, which share this process's terminal) it also

    - pins the worker process to one core of the machine, worker ``i`` to the ``i``-th allowed
      core, so that the few threads an analysis starts itself (the parallel back-substitutions of
      the contact columns) share that core instead of competing with the other workers (Linux;
      elsewhere a no-op);
    - keeps Dask's own log messages in the worker to critical ones. A local worker writes to the
      user's terminal, and what it would say there is either reported by the study itself (a
      variant that fails is a record with its error; a worker that dies is a ``KilledWorker``) or
      noise of a shutdown: after Ctrl-C the scheduler may close while a worker's heartbeat is in
      flight, and the worker would print "Failed to communicate with scheduler during heartbeat"
      with its traceback under the command's one line "interrupted";
    - ends a local worker's process at once when it is closed under a running variant (Ctrl-C:
      this process cancels the variants and closes the cluster; the variant's temporary folder is
      removed by the study afterwards). Its Python would otherwise finalise while the variant's
      thread (a daemon thread of Dask's) is still inside a compiled library, and stop that
      thread there: seen once as the C++ runtime's "terminate called without an active
      exception" on the user's terminal (Dask reports the like as "Fatal Python error ... at
      interpreter shutdown, possibly due to daemon threads").
    """

    name = "rvfem-single-threaded-blas"
    idempotent = True

    def __init__(self, local: bool = False):
        self.local = local

    def setup(self, worker) -> None:
        try:
            self._limits = threadpool_limits(limits=1)
        except Exception:  # a library threadpoolctl cannot control: leave it
            log.debug("threadpoolctl could not limit the thread pools", exc_info=True)
        if self.local:
            for name in ("distributed", "tornado"):
                logging.getLogger(name).setLevel(logging.CRITICAL)
        if self.local and isinstance(worker.name, int) and hasattr(os, "sched_setaffinity"):
            try:
                cores = sorted(os.sched_getaffinity(0))
                core = {cores[worker.name % len(cores)]}
                for tid in os.listdir("/proc/self/task"):  # every thread of the process, and the
                    os.sched_setaffinity(int(tid), core)   # threads started later inherit it
            except OSError:
                log.debug("could not pin worker %s to a core", worker.name, exc_info=True)

    def teardown(self, worker) -> None:
        if self.local and getattr(worker, "active_threads", None):   # closed under a running variant
            for stream in (sys.stdout, sys.stderr):
                with contextlib.suppress(Exception):
                    stream.flush()
            os._exit(0)


@functools.cache
def _plugin_class() -> type:
    """``SingleThreadedBlas``: the plugin's behaviour on Dask's ``WorkerPlugin`` base class, which
    Dask needs to register it by type, made on first use and named after this module, so that
    it pickles by reference to the workers."""
    from distributed import WorkerPlugin  # Dask is a heavy import (about 0.5 s): studies and optimisations only
    return type("SingleThreadedBlas", (_SingleThreadedBlasSetup, WorkerPlugin),
                {"__module__": __name__, "__doc__": _SingleThreadedBlasSetup.__doc__})


def __getattr__(name: str):
    """``SingleThreadedBlas`` (:func:`_plugin_class`), made on first use: no command but the studies
    and the optimiser pays for Dask's import."""
    if name == "SingleThreadedBlas":
        return _plugin_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _single_threaded_blas_plugin(local: bool = False):
    """A ``SingleThreadedBlas`` plugin (:func:`_plugin_class`)."""
    return _plugin_class()(local=local)


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
                                plugins=(_single_threaded_blas_plugin(local=True),))
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
    first: dict[str, Variant] = {}
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
    write_text_atomic(out_dir / "study.json", json.dumps(study_dict(study), indent=2, allow_nan=False) + "\n")
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
            write_text_atomic(out_dir / "study.csv", study_csv_text(rows))
    _same_case_records(study, records, first_of)
    rows = study_rows(study, records)
    files = {"csv": out_dir / "study.csv", "json": out_dir / "study.json"}
    write_text_atomic(files["csv"], study_csv_text(rows))
    plot_files = write_plots(study, rows, out_dir / "plots") if plots else {}
    files.update(plot_files)
    files["report"] = out_dir / "report.html"
    compute = _compute_time(records)
    wall = time.perf_counter() - started
    write_text_atomic(files["report"], report_html(study, rows, plot_files, wall, compute))
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
            client.register_plugin(_single_threaded_blas_plugin())
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
