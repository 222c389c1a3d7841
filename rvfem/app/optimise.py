"""The lightest disc within budgets: a constrained optimisation over the hole parameters, each
design a full analysis on the same Dask machinery as studies (:mod:`rvfem.app.study`).

An **optimisation file** (TOML) names a base case, what to minimise, the parameters and the
budgets::

    name = "rv40e_fanholes_lightest"
    base_case = "../cases/rv40e_fanholes.toml"  # relative to the file
    objective = "disc_mass_kg"                  # or "disc_polar_inertia_kg_mm2"
    trials = 32                                 # designs evaluated (the base is not one of them)
    seed = 29                                   # the sampler's seed: same file, same designs
    batch = 2                                   # designs proposed and run at once (default: workers)

    [overrides]                                 # applied to the base and to every design
    "analysis.angle_step_deg" = 2.0

    [[parameter]]                               # a case key and its range (step: a grid of values)
    key = "fan_holes.outer_radius"
    low = 45.0
    high = 52.0
    step = 0.1

    [budget]                                    # each optional
    max_load_delta_percent = 12.0               # largest bearing load vs the case's reference, %
    life_ratio = 0.75                           # shortest L10h / the reference's, at least
    fatigue_safety_factor = 1.5                 # at least
    static_safety_factor = 2.0                  # at least

    [screening]                                 # optional: screen on a coarse mesh (below)
    mesh_scale = 2.0                            # the coarse mesh: every [mesh] size × this
    band_factor = 2.0                           # the error band: this × the largest coarse–fine difference
    confirm = "front"                           # on the fine mesh: "front" (and best) or "best" only

Each design is a design-only analysis (:func:`rvfem.app.design.run_design`): the mesh, the load
cycle, the P2 structural peak and the mass and strength at the case's own fidelity, without the
sections and files no response reads (attribution, crank bearing in depth, accuracy, Hertz and
pin-flank checks, tables, VTK, plots); the responses are those of a full ``rvfem run``.

**Screening.** With a ``[screening]`` table every design runs on the coarse mesh (the sampler is
told the coarse results); the base case runs on both meshes. Then every coarse design whose fine
result could change what is reported — the best feasible design or the Pareto front of the report
(mass against life ratio; objective against g for the analytic problem) — is re-evaluated on the
fine mesh (:func:`to_confirm`): each screened response's fine value is taken to lie within
``band_factor`` × the largest coarse–fine difference of that response over every design run on
both meshes (:func:`error_bands`); a coarse design stays coarse only if, anywhere in those bands,
it is surely infeasible, or surely beaten by a surely feasible design, and surely dominated on
the front. Each confirmation adds a coarse–fine pair, the bands are recomputed and the test is
repeated until no coarse design is left to confirm. The reported front and best design are then
fine-mesh results, and they are those of evaluating every design on the fine mesh whenever the
coarse errors lie within the bands (``tests/app/test_optimise.py`` checks this against the fine
evaluation of every design). With ``confirm = "best"`` only the best feasible design is held to
that: a coarse design is confirmed only if it could be the best, and the front's other designs may
keep their coarse values (marked coarse; worth it where nearly every design lies on the front, as
mass against life ratio does: 36 of 40 designs of the shipped problem were confirmed for the front,
docs/scaling.md). ``trials.csv`` says per design which mesh its row comes from
(``fidelity``), ``screening.csv`` holds every coarse result and ``optimisation.json`` the bands.

The responses of a design come from its ``summary.json`` (:func:`design_responses`): the
objective keys, the safety factors and, per bearing, the deltas of the flexible loads against the
case's rigid reference (``bearings[].delta_max_percent``, ``bearings[].life_ratio``; the
handbook for the shipped cases). Manufacturability is the case validation and the geometry check
(walls ≥ ``mesh.min_wall``, fillets that fit): a design they reject is recorded as infeasible
with its message, never fatal.

The optimiser is Optuna's TPE sampler with constraints (Watanabe, "Tree-structured Parzen
estimator: understanding its algorithm components and their roles for better empirical
performance", 2023; the constrained variant of Watanabe and Hutter, "c-TPE", 2023): a seeded
sampler that proposes ``batch`` designs at a time (ask), which run in parallel on Dask and are
told back in proposal order (tell), so the same file gives the same designs. A rerun into the same
folder replays the same proposals and takes every design already in ``trials.csv`` from there
(same parameters and case digest) instead of running it again: it resumes where the last run
stopped, and a finished optimisation with more ``trials`` goes on from its end.

Outputs in DIR: ``trials.csv`` (one row per design: parameters, responses, feasibility, status),
``best.toml`` (the best feasible design as a complete case file), ``trials/<id>/`` (every design's
result folder: ``summary.json`` and ``case.json``; ``trials/<id>-coarse/`` when screened), ``pareto.png`` (mass against life ratio coloured by the fatigue safety factor, the
feasible Pareto front drawn), ``optimisation.json`` and ``report.html``.

``analytic`` problems (``problem = "analytic"``, no base case) evaluate :func:`analytic_responses`
instead of a case, through the same loop and the same Dask client: the check that the optimiser
finds a known optimum.
"""

from __future__ import annotations

import contextlib
import csv
import json
import logging
import math
import os
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

from rvfem._files import write_text_atomic
from rvfem.app.study_run import (
    ClusterError,
    VariantTask,
    _acquire_lock,
    _connect,
    _one_line,
    _single_threaded_blas_plugin,
    _remove_partials,
    _removed_if_new_on,
    local_cluster,
    run_variant,
)
from rvfem.app.optimise_problem import (
    BUDGETS,
    INFEASIBLE_VIOLATION,
    OBJECTIVES,
    OptParameter,
    Problem,
    _design_overrides,
    _load_design,
    error_bands,
    Screening,
    load_problem,
    to_confirm,
)
from rvfem.case.definition import case_to_dict, load_case
from rvfem.case.schema import toml_literal
from rvfem.errors import RvfemError
from rvfem.outputs.csvfile import csv_text
from rvfem.outputs.figures import new_figure, save_figure
from rvfem.outputs.report import png_data_uri, template_environment
from rvfem.outputs.summary import prepare_output_folder

log = logging.getLogger(__name__)

__all__ = [
    "OBJECTIVES",
    "BUDGETS",
    "OptParameter",
    "Problem",
    "DesignTask",
    "OptimisationResult",
    "load_problem",
    "design_responses",
    "analytic_responses",
    "evaluate_design",
    "read_trials",
    "run_optimisation",
    "case_file_text",
    "pareto_front",
    "Screening",
    "error_bands",
    "to_confirm",
]


@dataclass(frozen=True)
class DesignTask:
    """What a worker needs for one design: the parameters, for a case its variant task, and the
    fidelity (``"fine"``, or ``"coarse"`` when screening)."""

    trial_id: str
    params: tuple[tuple[str, float], ...]
    variant: VariantTask | None = None
    fidelity: str = "fine"


@dataclass(frozen=True)
class OptimisationResult:
    """Outcome of :func:`run_optimisation`: the rows of ``trials.csv``, the best feasible row
    (None if none), the files, this run's wall time, the designs computed in this run."""

    out_dir: Path
    problem: Problem
    rows: tuple[dict, ...]
    best: dict | None
    files: dict
    wall_time_s: float
    computed: int
    base: dict | None = field(default=None)


# --------------------------------------------------------------------------------------------
# One design (runs in a Dask worker)
# --------------------------------------------------------------------------------------------


ANALYTIC_COARSE_ERROR = 0.05
"""Amplitude of the stand-in for a coarse mesh's error of the analytic problem (its ``coarse``
fidelity): f and g each off by at most this."""


def analytic_responses(params: dict[str, float], fidelity: str = "fine") -> dict[str, float]:
    """The analytic check problem: minimise f = (x − 1)² + (y − 2)² subject to g = x + y ≤ 2.
    Known optimum: the projection of (1, 2) onto the line x + y = 2, (0.5, 1.5), f* = 0.5.

    At fidelity ``"coarse"`` (screening) f and g carry a smooth error of amplitude
    :data:`ANALYTIC_COARSE_ERROR` (ε·sin(7x + 3y) and ε·cos(5x − 2y)): the stand-in for a coarse
    mesh, with which the screening's front is checked against the fine one."""
    x, y = float(params["x"]), float(params["y"])
    f, g = (x - 1.0) ** 2 + (y - 2.0) ** 2, x + y
    if fidelity == "coarse":
        f += ANALYTIC_COARSE_ERROR * math.sin(7.0 * x + 3.0 * y)
        g += ANALYTIC_COARSE_ERROR * math.cos(5.0 * x - 2.0 * y)
    return {"objective": f, "g": g}


def design_responses(summary: dict) -> dict[str, float | None]:
    """The responses of a design from its ``summary.json``: mass, inertia, safety factors, the
    largest bearing-load delta and the smallest life ratio against the case's reference, the
    shortest flexible L10h and the structural stress peak."""
    bearings = summary.get("bearings") or []
    deltas = [b.get("delta_max_percent") for b in bearings if b.get("delta_max_percent") is not None]
    ratios = [b.get("life_ratio") for b in bearings if b.get("life_ratio") is not None]
    lives = [b["flexible"]["L10h_h"] for b in bearings if b.get("flexible")]
    loads = [b["flexible"]["max_load_N"] for b in bearings if b.get("flexible")]
    return {
        "disc_mass_kg": summary.get("disc_mass_kg"),
        "disc_polar_inertia_kg_mm2": summary.get("disc_polar_inertia_kg_mm2"),
        "static_safety_factor": summary.get("static_safety_factor"),
        "fatigue_safety_factor": summary.get("fatigue_safety_factor"),
        "max_load_delta_percent": max(deltas, default=None),
        "life_ratio": min(ratios, default=None),
        "max_load_N": max(loads, default=None),
        "L10h_h": min(lives, default=None),
        "peak_von_mises_MPa": summary.get("peak_von_mises_MPa"),
    }


def evaluate_design(task: DesignTask) -> dict:
    """Evaluate one design (in a worker): the analytic responses, or the case run by
    :func:`rvfem.app.study.run_variant` into its trial folder. Never raises: a failure is a record
    with ``status`` ``"failed"`` or ``"error"`` and its message."""
    started = time.perf_counter()
    if task.variant is None:
        record: dict[str, Any] = {"status": "ok", "error": "", "computed": True,
                                  "responses": analytic_responses(dict(task.params), task.fidelity)}
    else:
        record = run_variant(task.variant)
        summary = record.pop("summary", None)
        record["responses"] = design_responses(summary) if summary else {}
    record.update(id=task.trial_id, wall_time_s=time.perf_counter() - started, fidelity=task.fidelity)
    return record


# --------------------------------------------------------------------------------------------
# Budgets and rows
# --------------------------------------------------------------------------------------------


def _violations(problem: Problem, responses: dict) -> list[float]:
    """Per budget the violation relative to its limit, > 0 when broken ((r − limit)/|limit| for an
    upper, (limit − r)/|limit| for a lower bound); a missing response is broken by
    :data:`INFEASIBLE_VIOLATION`."""
    out = []
    for name, limit in problem.budgets:
        key, sense = BUDGETS[name]
        r = responses.get(key)
        if r is None or math.isnan(float(r)):
            out.append(INFEASIBLE_VIOLATION)
            continue
        if math.isinf(float(r)):
            out.append(-1.0 if (sense == "min") == (float(r) > 0) else INFEASIBLE_VIOLATION)
            continue
        scale = abs(limit) or 1.0
        out.append((float(r) - limit) / scale if sense == "max" else (limit - float(r)) / scale)
    return out


def _row(problem: Problem, number: int, params: Sequence[tuple[str, float]], record: dict, digest: str) -> dict:
    responses = record.get("responses") or {}
    ok = record.get("status") == "ok" and responses.get(problem.objective) is not None
    violations = _violations(problem, responses) if ok else [INFEASIBLE_VIOLATION] * len(problem.budgets)
    row = {"number": number, "id": record.get("id", f"t{number:03d}"), "status": record.get("status", "failed"),
           "feasible": ok and all(v <= 0 for v in violations),
           "objective": responses.get(problem.objective) if ok else None,
           "violation": math.fsum(max(v, 0.0) for v in violations)}
    row.update({k: float(v) for k, v in params})
    row.update({k: responses.get(k) for k in _response_keys(problem)})
    row.update(error=record.get("error", ""), computed=bool(record.get("computed", False)),
               wall_time_s=record.get("wall_time_s"), digest=digest, fidelity=record.get("fidelity", "fine"))
    return row


def _response_keys(problem: Problem) -> tuple[str, ...]:
    if problem.kind == "analytic":
        return ("g",)
    return ("disc_mass_kg", "disc_polar_inertia_kg_mm2", "max_load_delta_percent", "life_ratio", "L10h_h",
            "max_load_N", "fatigue_safety_factor", "static_safety_factor", "peak_von_mises_MPa")


def _columns(problem: Problem) -> list[str]:
    return (["number", "id", "status", "feasible", "objective", "violation"] + [p.key for p in problem.parameters]
            + list(_response_keys(problem)) + ["error", "computed", "wall_time_s", "digest", "fidelity"])


def _csv_text(problem: Problem, rows: Sequence[dict]) -> str:
    columns = _columns(problem)
    return csv_text(columns, ([r.get(k) for k in columns] for r in rows), nan_as_empty=True)


def _parse_cell(text: str) -> Any:
    if text == "":
        return None
    if text in ("yes", "no"):
        return text == "yes"
    try:
        return float(text)
    except ValueError:
        return text


def read_trials(path: str | os.PathLike) -> list[dict]:
    """The rows of a ``trials.csv`` (numbers as floats, empty cells None); [] if there is none."""
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = [{k: _parse_cell(v) for k, v in r.items()} for r in csv.DictReader(f)]
    except OSError:
        return []
    for r in rows:
        for k in ("id", "status", "error", "digest"):
            r[k] = "" if r.get(k) is None else str(r[k])
        r["fidelity"] = str(r.get("fidelity") or "fine")
    return rows


def _tidy(value: float, p: OptParameter) -> float:
    """A stepped value without the float noise of low + k·step (3.4000000000000004 → 3.4): the
    case files and tables show what the grid means."""
    return float(round(value, 10)) if p.step is not None else float(value)


def _key(params: Sequence[tuple[str, float]]) -> str:
    return json.dumps([[k, round(float(v), 10)] for k, v in params])


def _earlier(problem: Problem, rows: Sequence[dict]) -> dict[str, dict]:
    """Designs of an earlier run by fidelity and parameters (ok or rejected, not interrupted ones)."""
    out = {}
    for r in rows:
        if r.get("status") not in ("ok", "failed") or any(r.get(p.key) is None for p in problem.parameters):
            continue
        out[r.get("fidelity", "fine") + _key([(p.key, r[p.key]) for p in problem.parameters])] = r
    return out



# --------------------------------------------------------------------------------------------
# The loop
# --------------------------------------------------------------------------------------------


ProgressCallback = Callable[[int, int, dict], None]
"""``progress(done, total, row)`` after every design."""


@contextlib.contextmanager
def _dask_client(scheduler: str | None, workers: int | None, client, connect_timeout_s: float = 30.0):
    """The client of :func:`rvfem.app.study.run_study`: the given one (not closed), one connected to
    ``scheduler``, or one of a new :func:`~rvfem.app.study.local_cluster`."""
    if client is not None:
        yield client
        return
    cluster = None
    if scheduler:
        own = _connect(scheduler, connect_timeout_s)
    else:
        from distributed import (
            Client,  # optimisation only: Dask's scheduler is a heavy import
        )

        cluster = local_cluster(workers)
        own = Client(cluster, set_as_default=False)
    try:
        try:
            own.register_plugin(_single_threaded_blas_plugin())
        except Exception:
            log.debug("could not register the single-threaded BLAS plugin", exc_info=True)
        yield own
    finally:
        own.close()
        if cluster is not None:
            cluster.close()


def _trial_folder(trials_dir: Path, trial_id: str, fidelity: str) -> Path:
    """``trials/<id>/``, or ``trials/<id>-coarse/`` for a design screened on the coarse mesh."""
    return trials_dir / (trial_id if fidelity == "fine" else f"{trial_id}-{fidelity}")


def _task(problem: Problem, trial_id: str, params: tuple, trials_dir: Path, cache: Path, fidelity: str = "fine",
          design_only: bool = True) -> tuple[DesignTask | None, str, dict | None]:
    """(task, case digest, record of a design the case validation rejects)."""
    if problem.kind == "analytic":
        return DesignTask(trial_id, params, fidelity=fidelity), "", None
    try:
        case = _load_design(problem, params, fidelity)
    except RvfemError as exc:
        return None, "", {"id": trial_id, "status": "failed", "error": _one_line(f"{type(exc).__name__}: {exc}"),
                          "computed": True, "responses": {}, "wall_time_s": 0.0, "rejected": True,
                          "fidelity": fidelity}
    digest = case.digest()
    variant = VariantTask(trial_id, str(problem.base_case), _design_overrides(problem, params, fidelity), digest,
                          str(_trial_folder(trials_dir, trial_id, fidelity)), str(cache), design_only=design_only)
    return DesignTask(trial_id, params, variant, fidelity), digest, None


def _run_batch(problem: Problem, client, batch: Sequence[tuple[str, tuple]], earlier: dict, trials_dir: Path,
               cache: Path, fidelity: str = "fine", design_only: bool = True) -> list[tuple[dict, str]]:
    """(record, digest) of every design of a batch, in order: taken from an earlier run where
    its parameters, fidelity and case digest match, else run on the client."""
    out: list = [None] * len(batch)
    futures = {}
    for i, (trial_id, params) in enumerate(batch):
        task, digest, rejected = _task(problem, trial_id, params, trials_dir, cache, fidelity, design_only)
        old = earlier.get(fidelity + _key(params))
        if old is not None and (old.get("digest") or "") == digest:
            responses = {k: old.get(k) for k in (*_response_keys(problem), problem.objective)}
            out[i] = ({"id": trial_id, "status": old["status"], "error": old.get("error", ""), "computed": False,
                       "responses": responses if old["status"] == "ok" else {}, "fidelity": fidelity,
                       "wall_time_s": old.get("wall_time_s")}, digest)
        elif rejected is not None:
            out[i] = (rejected, digest)
        else:
            futures[i] = (client.submit(evaluate_design, task, key=f"rvfem-design-{trial_id}-{os.urandom(4).hex()}",
                                        pure=False), digest)
    for i, (fut, digest) in futures.items():
        try:
            out[i] = (fut.result(), digest)
        except Exception as exc:   # the task itself raised (a worker lost): recorded, never fatal
            out[i] = ({"id": batch[i][0], "status": "failed", "computed": True, "responses": {},
                       "error": _one_line(f"{type(exc).__name__}: {exc}"), "wall_time_s": float("nan")}, digest)
        out[i][0]["fidelity"] = fidelity
    return out


def _optuna():
    """Optuna, the optional dependency of the optimiser (the ``optimise`` extra).

    Raises
    ------
    RvfemError
        Optuna is not installed: the message says how to install it.
    """
    try:
        import optuna  # optimisation only: an optional dependency (the "optimise" extra)
    except ImportError:
        raise RvfemError("rvfem optimise needs Optuna, an optional dependency: install it with "
                         "pip install 'rvfem[optimise]' (make test installs it with the dev extra)") from None
    return optuna


def _sampler(problem: Problem):
    optuna = _optuna()
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)
    # constraints: Trial.set_constraint since Optuna 5, the sampler's constraints_func before
    legacy = {} if _modern_constraints() else {"constraints_func": lambda t: t.user_attrs["constraints"]}
    sampler = optuna.samplers.TPESampler(seed=problem.seed, multivariate=True,
                                         n_startup_trials=max(8, 3 * len(problem.parameters)), **legacy)
    return optuna.create_study(direction="minimize", sampler=sampler)


def _modern_constraints() -> bool:
    return hasattr(_optuna().trial.Trial, "set_constraint")


def _tell_constraints(problem: Problem, trial, violations: Sequence[float]) -> None:
    trial.set_user_attr("constraints", list(violations))
    if _modern_constraints():
        for (name, _), v in zip(problem.budgets, violations):
            trial.set_constraint(name, float(v))


def _loop(problem: Problem, client, out_dir: Path, cache: Path, earlier: dict, fallback: float,
          progress: ProgressCallback | None, head: Sequence[dict] = (), design_only: bool = True) -> list[dict]:
    """Ask a batch, run it (on the coarse mesh when screening), tell it in order; ``trials.csv``
    (``screening.csv`` when screening) after every batch."""
    fidelity = "coarse" if problem.screening is not None else "fine"
    table = out_dir / ("screening.csv" if fidelity == "coarse" else "trials.csv")
    study = _sampler(problem)
    rows: list[dict] = []
    batch = problem.batch or max(1, len(client.scheduler_info().get("workers", {})) or 1)
    while len(rows) < problem.trials:
        trials = [study.ask() for _ in range(min(batch, problem.trials - len(rows)))]
        params = [tuple((p.key, _tidy(t.suggest_float(p.key, p.low, p.high, step=p.step), p)) for p in problem.parameters)
                  for t in trials]
        done = _run_batch(problem, client, [(f"t{t.number:03d}", prm) for t, prm in zip(trials, params)], earlier,
                          out_dir / "trials", cache, fidelity, design_only)
        for t, prm, (record, digest) in zip(trials, params, done):
            row = _row(problem, t.number, prm, record, digest)
            _tell_constraints(problem, t, _violations(problem, record.get("responses") or {})
                              if row["objective"] is not None else [INFEASIBLE_VIOLATION] * len(problem.budgets))
            study.tell(t, row["objective"] if row["objective"] is not None else fallback)
            rows.append(row)
            if progress is not None:
                progress(len(rows), problem.trials, row)
        write_text_atomic(table, _csv_text(problem, [*head, *rows]))
    return rows


def _base_row(problem: Problem, client, out_dir: Path, cache: Path, earlier_rows: Sequence[dict],
              fidelity: str = "fine", design_only: bool = True) -> dict | None:
    """The base case itself (``trials/base``), the reference of the report and the value told
    for failed designs (on the coarse mesh, ``trials/base-coarse``, the first coarse–fine pair of
    a screening); None for an analytic problem."""
    if problem.kind == "analytic":
        return None
    assert problem.base_case is not None   # not analytic, checked just above
    overrides = _design_overrides(problem, (), fidelity)
    case = load_case(problem.base_case, overrides)
    old = next((r for r in earlier_rows if r.get("id") == "base" and r.get("digest") == case.digest()
                and r.get("status") == "ok"), None)
    if old is not None:
        return {**old, "computed": False}
    task = DesignTask("base", (), VariantTask("base", str(problem.base_case), overrides, case.digest(),
                                              str(_trial_folder(out_dir / "trials", "base", fidelity)), str(cache),
                                              design_only=design_only), fidelity)
    record = client.submit(evaluate_design, task, key=f"rvfem-design-base-{os.urandom(4).hex()}", pure=False).result()
    return _row(problem, -1, (), record, case.digest())


def _confirm(problem: Problem, client, out_dir: Path, cache: Path, rows: list[dict], pairs: list[tuple[dict, dict]],
             earlier: dict, design_only: bool) -> tuple[list[dict], dict[str, float], int]:
    """Re-evaluate on the fine mesh every coarse row :func:`to_confirm` returns, widen the bands
    with the new coarse–fine pairs and repeat until no coarse row is left to confirm. Returns the
    rows (confirmed ones replaced by their fine result), the final bands and how many rows were
    confirmed."""
    confirmed = 0
    while True:
        bands = error_bands(problem, pairs)
        todo = to_confirm(problem, rows, bands)
        if not todo:
            return rows, bands, confirmed
        log.info("%s: %d designs within the coarse-fine band of the %s, on the fine mesh", problem.name, len(todo),
                 "front or the best" if problem.screening is None or problem.screening.confirm == "front" else "best")
        params = [tuple((p.key, r[p.key]) for p in problem.parameters) for r in todo]
        done = _run_batch(problem, client, [(r["id"], prm) for r, prm in zip(todo, params)], earlier,
                          out_dir / "trials", cache, "fine", design_only)
        index = {id(r): i for i, r in enumerate(rows)}
        for coarse, prm, (record, digest) in zip(todo, params, done):
            fine = _row(problem, int(coarse["number"]), prm, record, digest)
            if coarse.get("status") == "ok" and fine["status"] == "ok":
                pairs.append((coarse, fine))
            rows[index[id(coarse)]] = fine
            confirmed += 1


def run_optimisation(problem: Problem | str | os.PathLike, out_dir: str | os.PathLike, *,
                     scheduler: str | None = None, workers: int | None = None, client=None,
                     cache_dir: str | os.PathLike = "meshes", progress: ProgressCallback | None = None,
                     plots: bool = True, design_only: bool = True) -> OptimisationResult:
    """Run an optimisation (module docstring) and write its folder.

    Parameters
    ----------
    problem : Problem or path
    out_dir : path
        Folder; a rerun into it resumes (designs already in ``trials.csv`` are not run again).
    scheduler, workers, client, cache_dir, progress, plots
        As :func:`rvfem.app.study.run_study`.
    design_only : bool
        Each design computes and writes only what its responses read
        (:func:`rvfem.app.design.run_design`; the same responses); False runs every design as a
        full ``rvfem run`` (every result, table and plot in ``trials/<id>/``, several times the cost).

    Raises
    ------
    CaseError, OutputError, ClusterError
        A bad file, a locked folder, no cluster. Failing designs are recorded, never raised.
    """
    started = time.perf_counter()
    if not isinstance(problem, Problem):
        problem = load_problem(problem)
    _optuna()  # before any folder or cluster: a missing optional dependency is said first
    out_dir = Path(out_dir).resolve()
    cache = Path(cache_dir).resolve()
    with _removed_if_new_on(ClusterError, out_dir):   # no cluster: a new folder is not left behind
        prepare_output_folder(out_dir, "optimise", ("trials",))   # a non-empty folder rvfem did not write is refused
        lock = _acquire_lock(out_dir)
        try:
            _remove_partials(out_dir / "trials")
            earlier_rows = read_trials(out_dir / "trials.csv") + read_trials(out_dir / "screening.csv")
            earlier = _earlier(problem, earlier_rows)
            screening = None
            with _dask_client(scheduler, workers, client) as c:
                base = _base_row(problem, c, out_dir, cache, earlier_rows, design_only=design_only)
                fallback = base["objective"] if base and base.get("objective") is not None else 0.0
                pairs: list[tuple[dict, dict]] = []
                coarse_head = []
                if problem.screening is not None and base is not None:
                    coarse_base = _base_row(problem, c, out_dir, cache, earlier_rows, "coarse", design_only)
                    assert coarse_base is not None   # a case problem
                    coarse_head = [coarse_base]
                    if coarse_base["status"] == "ok" and base["status"] == "ok":
                        pairs.append((coarse_base, base))
                rows = _loop(problem, c, out_dir, cache, earlier, fallback, progress,
                             head=coarse_head if problem.screening is not None else [base] if base else [],
                             design_only=design_only)
                if problem.screening is not None:
                    screened = list(rows)
                    rows, bands, confirmed = _confirm(problem, c, out_dir, cache, list(rows), pairs, earlier,
                                                      design_only)
                    screening = {"mesh_scale": problem.screening.mesh_scale,
                                 "band_factor": problem.screening.band_factor,
                                 "confirm": problem.screening.confirm, "bands": bands,
                                 "pairs": len(pairs), "confirmed_on_fine_mesh": confirmed,
                                 "coarse_designs": sum(1 for r in screened if r.get("status") == "ok")}
            all_rows = ([base] if base else []) + rows
            write_text_atomic(out_dir / "trials.csv", _csv_text(problem, all_rows))
            best = min((r for r in rows if r["feasible"]), key=lambda r: r["objective"], default=None)
            files = _write_outputs(problem, out_dir, rows, base, best, plots, time.perf_counter() - started,
                                   screening)
        finally:
            lock.unlink(missing_ok=True)
    return OptimisationResult(out_dir=out_dir, problem=problem, rows=tuple(rows), best=best, files=files,
                              wall_time_s=time.perf_counter() - started,
                              computed=sum(1 for r in rows if r["computed"]), base=base)


# --------------------------------------------------------------------------------------------
# Outputs
# --------------------------------------------------------------------------------------------


def case_file_text(case, comment: str = "") -> str:
    """A complete case file (TOML) of ``case``: every key, top-level keys first, then one table
    each (sub-tables and arrays of tables inline). Reading it back gives the same case digest."""
    data = case_to_dict(case)
    lines = [f"# {line}" for line in comment.splitlines()]
    tables = {k: v for k, v in data.items() if isinstance(v, dict)}
    lines += [f"{k} = {toml_literal(v, bare_keys=True)}" for k, v in data.items() if k not in tables]
    for name, table in tables.items():
        lines += ["", f"[{name}]"]
        lines += [f"{k} = {toml_literal(v, bare_keys=True)}" for k, v in table.items() if v is not None]
    return "\n".join(lines) + "\n"


def pareto_front(rows: Sequence[dict], x: str = "disc_mass_kg", y: str = "life_ratio") -> list[dict]:
    """The rows not dominated in (smallest ``x``, largest ``y``) among those that have both, by ``x``."""
    pts = sorted((r for r in rows if r.get(x) is not None and r.get(y) is not None), key=lambda r: (r[x], -r[y]))
    front, best_y = [], -math.inf
    for r in pts:
        if r[y] > best_y:
            front.append(r)
            best_y = r[y]
    return front


def _pareto_png(problem: Problem, rows: Sequence[dict], base: dict | None, best: dict | None, path: Path) -> Path:
    fig = new_figure((8, 5.5))
    ax = fig.subplots()
    ok = [r for r in rows if r.get("disc_mass_kg") is not None and r.get("life_ratio") is not None]
    sf = [min(r.get("fatigue_safety_factor") or 0.0, 50.0) for r in ok]
    budgets = ", ".join(f"{n} {'≤' if BUDGETS[n][1] == 'max' else '≥'} {v:g}" for n, v in problem.budgets) or "none"
    for feasible, marker in ((True, "o"), (False, "x")):
        pick = [i for i, r in enumerate(ok) if bool(r["feasible"]) == feasible]
        if pick:
            sc = ax.scatter([ok[i]["disc_mass_kg"] for i in pick], [ok[i]["life_ratio"] for i in pick],
                            c=[sf[i] for i in pick], cmap="viridis", vmin=min(sf), vmax=max(sf), marker=marker, s=40,
                            label="within the budgets" if feasible else f"outside a budget ({budgets})")
    if ok:
        fig.colorbar(sc, ax=ax, label="fatigue safety factor")
    front = pareto_front(ok)
    ax.step([r["disc_mass_kg"] for r in front], [r["life_ratio"] for r in front], where="post", color="0.4", lw=1,
            label="Pareto front (all designs)")
    if base is not None and base.get("disc_mass_kg") is not None:
        ax.plot(base["disc_mass_kg"], base["life_ratio"], "r*", ms=14, label="base case")
    if best is not None:
        ax.plot(best["disc_mass_kg"], best["life_ratio"], "o", mfc="none", mec="r", ms=16, mew=2,
                label=f"best feasible ({best['id']})")
    for name, limit in problem.budgets:
        if name == "life_ratio":
            ax.axhline(limit, color="r", ls=":", lw=1, label=f"life-ratio budget {limit:g}")
    ax.set_xlabel("disc mass, kg")
    ax.set_ylabel("life ratio (shortest L10h / reference)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, frameon=False)
    ax.set_title(f"{problem.name}: {len(rows)} designs; budgets: {budgets}", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def _fmt(v: Any, spec: str) -> str:
    return "–" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


OPTIMISE_TEMPLATE = "optimise.html.j2"
"""The optimisation report's template, in the templates of :mod:`rvfem.outputs`."""


def _report_context(problem: Problem, rows: Sequence[dict], base: dict | None, best: dict | None,
                    png: Path | None, wall_s: float) -> dict:
    """The context of ``optimise.html.j2``: texts, the base and best designs, the Pareto plot as a
    data URI and the table of designs, numbers formatted ("–" where missing)."""
    keys = [p.key for p in problem.parameters] + list(_response_keys(problem))
    return {
        "name": problem.name, "description": problem.description, "objective": problem.objective,
        "parameters": [p.key for p in problem.parameters],
        "budgets": [f"{n} {'≤' if BUDGETS[n][1] == 'max' else '≥'} {v:g}" for n, v in problem.budgets],
        "designs": len(rows), "seed": problem.seed, "wall_s": f"{wall_s:.0f}",
        "highlights": [{"title": title, "values": [(k, _fmt(r.get(k), ".4g")) for k in keys]}
                       for title, r in (("Base case", base), ("Best feasible design", best)) if r is not None],
        "pareto": png_data_uri(png) if png is not None else None,
        "keys": keys,
        "rows": [{"id": r["id"], "status": r["status"], "feasible": bool(r["feasible"]),
                  "objective": _fmt(r["objective"], ".5g"), "values": [_fmt(r.get(k), ".4g") for k in keys],
                  "error": r.get("error") or ""} for r in rows],
    }


def _report(problem: Problem, rows: Sequence[dict], base: dict | None, best: dict | None, png: Path | None,
            wall_s: float) -> str:
    """The optimisation's ``report.html``, rendered by ``optimise.html.j2``."""
    return template_environment().get_template(OPTIMISE_TEMPLATE).render(
        _report_context(problem, rows, base, best, png, wall_s))


def _write_outputs(problem: Problem, out_dir: Path, rows: list[dict], base: dict | None, best: dict | None,
                   plots: bool, wall_s: float, screening: dict | None = None) -> dict:
    files = {"csv": out_dir / "trials.csv"}
    if best is not None and problem.kind == "case":
        params = tuple((p.key, best[p.key]) for p in problem.parameters)
        case = _load_design(problem, params)
        files["best"] = out_dir / "best.toml"
        write_text_atomic(files["best"], case_file_text(case, (
            f"The lightest feasible design of {problem.name} ({best['id']}): {problem.objective} = "
            f"{best['objective']:.6g}\nbudgets: " + ", ".join(f"{n} {v:g}" for n, v in problem.budgets)
            + "\n" + ", ".join(f"{k} = {v:g}" for k, v in params))))
    png = None
    if plots and problem.kind == "case":
        png = files["pareto"] = _pareto_png(problem, rows, base, best, out_dir / "pareto.png")
    files["json"] = out_dir / "optimisation.json"
    doc = {"name": problem.name, "objective": problem.objective, "seed": problem.seed, "trials": problem.trials,
           "parameters": [vars(p) for p in problem.parameters], "budgets": dict(problem.budgets),
           "overrides": list(problem.overrides), "base": base, "best": best,
           "designs": len(rows), "feasible": sum(1 for r in rows if r["feasible"]), "wall_time_s": wall_s,
           "screening": screening}
    write_text_atomic(files["json"], json.dumps(doc, indent=2, default=str) + "\n")
    files["report"] = out_dir / "report.html"
    write_text_atomic(files["report"], _report(problem, rows, base, best, png, wall_s))
    return files
