"""The optimisation file of ``rvfem optimise`` (:class:`Problem`, :func:`load_problem`) and the
screening's error bands (:func:`error_bands`, :func:`to_confirm`); the format and the screening
are described in :mod:`rvfem.app.optimise`."""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from rvfem.case.definition import load_case, parse_override
from rvfem.case.schema import toml_literal
from rvfem.errors import CaseError

__all__ = ["OBJECTIVES", "BUDGETS", "INFEASIBLE_VIOLATION", "MESH_SIZE_KEYS", "FRONT_AXES", "OptParameter",
           "Screening", "Problem", "load_problem", "error_bands", "to_confirm"]

OBJECTIVES = ("disc_mass_kg", "disc_polar_inertia_kg_mm2", "objective")
"""What can be minimised (``objective`` is the analytic problem's)."""

BUDGETS = {
    "max_load_delta_percent": ("max_load_delta_percent", "max"),
    "life_ratio": ("life_ratio", "min"),
    "fatigue_safety_factor": ("fatigue_safety_factor", "min"),
    "static_safety_factor": ("static_safety_factor", "min"),
    "g": ("g", "max"),
}
"""Budget name → (response, ``"max"``: the response may not exceed the limit, ``"min"``: may not
fall below it). ``g`` is the analytic problem's constraint."""

INFEASIBLE_VIOLATION = 1.0e3
"""Constraint violation told to the sampler for a design that failed (rejected geometry)."""


@dataclass(frozen=True)
class OptParameter:
    """A varied case key over [low, high] (on a grid of ``step`` if given)."""

    key: str
    low: float
    high: float
    step: float | None = None


@dataclass(frozen=True)
class Screening:
    """Screening on a coarse mesh (the ``[screening]`` table; module docstring, "Screening").

    Attributes
    ----------
    mesh_scale : float
        Every element size of the base case's ``[mesh]`` table (``size_flank``, ``size_bore``,
        ``size_interior`` and ``size_hole``/``size_fillet`` where set) times this for the coarse
        designs (> 1).
    band_factor : float
        The coarse–fine error band of a response is this times the largest coarse–fine difference
        of that response over every design evaluated on both meshes (≥ 1).
    confirm : {"front", "best"}
        What the fine mesh must get right (:func:`to_confirm`): ``"front"`` the best feasible
        design and the Pareto front of the report, ``"best"`` the best feasible design only (the
        front's other designs may stay coarse; for a problem whose designs nearly all lie on the
        front, as mass against life ratio, this is what saves fine runs).
    """

    mesh_scale: float = 2.0
    band_factor: float = 2.0
    confirm: str = "front"


@dataclass(frozen=True)
class Problem:
    """A validated optimisation file (module docstring)."""

    name: str
    description: str
    path: Path | None
    kind: str                       # "case" or "analytic"
    base_case: Path | None
    overrides: tuple[str, ...]
    objective: str
    parameters: tuple[OptParameter, ...]
    budgets: tuple[tuple[str, float], ...]
    trials: int
    seed: int
    batch: int | None = None
    screening: Screening | None = None


# --------------------------------------------------------------------------------------------
# The file
# --------------------------------------------------------------------------------------------


def _fail(where: str, key: str, message: str) -> CaseError:
    return CaseError(f"{where}: {key}: {message}")


def _number(where: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise _fail(where, key, f"expected a number, got {value!r}")
    return float(value)


def _read_parameters(where: str, raw: Any) -> tuple[OptParameter, ...]:
    if not isinstance(raw, list) or not raw:
        raise _fail(where, "parameter", "give at least one [[parameter]] table with key, low and high")
    out = []
    for i, p in enumerate(raw, start=1):
        w = f"parameter {i}"
        if not isinstance(p, dict) or set(p) - {"key", "low", "high", "step", "label"} or "key" not in p:
            raise _fail(where, w, "expected a table of key, low, high and optionally step")
        low, high = _number(where, f"{w}.low", p.get("low")), _number(where, f"{w}.high", p.get("high"))
        if not low < high:
            raise _fail(where, f"{w}.high", f"must exceed low ({low:g}), got {high:g}")
        step = None if p.get("step") is None else _number(where, f"{w}.step", p["step"])
        out.append(OptParameter(str(p["key"]), low, high, step))
    return tuple(out)


def _read_budgets(where: str, raw: Any) -> tuple[tuple[str, float], ...]:
    if not isinstance(raw, dict):
        raise _fail(where, "budget", "expected a table, e.g. life_ratio = 0.75")
    for name in raw:
        if name not in BUDGETS:
            raise _fail(where, f"budget.{name}", f"unknown budget; known: {', '.join(BUDGETS)}")
    return tuple((name, _number(where, f"budget.{name}", v)) for name, v in raw.items())


_TOP_KEYS = {"name", "description", "problem", "base_case", "objective", "trials", "seed", "batch", "overrides",
             "parameter", "budget", "screening"}


CONFIRM = ("front", "best")
"""The values of ``screening.confirm`` (:class:`Screening`)."""


def _read_screening(where: str, raw: Any) -> Screening | None:
    if raw is None:
        return None
    if not isinstance(raw, dict) or set(raw) - {"mesh_scale", "band_factor", "confirm"}:
        raise _fail(where, "screening", "expected a table of mesh_scale (> 1), band_factor (≥ 1) and "
                    f"confirm (one of {', '.join(CONFIRM)})")
    confirm = raw.get("confirm", "front")
    if confirm not in CONFIRM:
        raise _fail(where, "screening.confirm", f"must be one of {', '.join(repr(c) for c in CONFIRM)}, got {confirm!r}")
    out = Screening(**{k: _number(where, f"screening.{k}", v) for k, v in raw.items() if k != "confirm"},
                    confirm=confirm)
    if not out.mesh_scale > 1.0:
        raise _fail(where, "screening.mesh_scale", f"must exceed 1 (the coarse mesh's sizes / the case's), got {out.mesh_scale:g}")
    if not out.band_factor >= 1.0:
        raise _fail(where, "screening.band_factor", f"must be at least 1, got {out.band_factor:g}")
    return out


def load_problem(path: str | os.PathLike, extra_overrides: Sequence[str] = (), trials: int | None = None) -> Problem:
    """Read and check an optimisation file; the base case and one design at the middle of the
    ranges are loaded (unknown case keys get their one-line error here).

    Raises
    ------
    CaseError
        One line naming the file and the key.
    """
    path = Path(path)
    where = str(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise CaseError(f"{where}: cannot read the optimisation file ({exc.strerror or exc})") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise CaseError(f"{where}: not a valid TOML file ({exc})") from None
    unknown = set(data) - _TOP_KEYS
    if unknown:
        raise _fail(where, sorted(unknown)[0], f"unknown key; known: {', '.join(sorted(_TOP_KEYS))}")
    kind = data.get("problem", "case")
    if kind not in ("case", "analytic"):
        raise _fail(where, "problem", f"expected \"case\" or \"analytic\", got {kind!r}")
    objective = data.get("objective", "disc_mass_kg" if kind == "case" else "objective")
    if objective not in OBJECTIVES:
        raise _fail(where, "objective", f"expected one of {', '.join(OBJECTIVES)}, got {objective!r}")
    overrides = tuple(f"{k}={toml_literal(v)}" for k, v in (data.get("overrides") or {}).items())
    overrides += tuple(extra_overrides)
    for text in overrides:
        parse_override(text)
    base = None
    if kind == "case":
        if "base_case" not in data:
            raise _fail(where, "base_case", "missing: the case file the designs vary")
        base = (path.parent / str(data["base_case"])).resolve()
    n = int(trials if trials is not None else data.get("trials", 30))
    problem = Problem(name=str(data.get("name", path.stem)), description=str(data.get("description", "")),
                      path=path.resolve(), kind=kind, base_case=base, overrides=overrides, objective=objective,
                      parameters=_read_parameters(where, data.get("parameter")),
                      budgets=_read_budgets(where, data.get("budget", {})), trials=max(1, n),
                      seed=int(data.get("seed", 0)), batch=None if data.get("batch") is None else int(data["batch"]),
                      screening=_read_screening(where, data.get("screening")))
    if base is not None:
        middle = tuple((p.key, 0.5 * (p.low + p.high)) for p in problem.parameters)
        _load_design(problem, middle)
    return problem


def _design_overrides(problem: Problem, params: Sequence[tuple[str, float]], fidelity: str = "fine") -> tuple[str, ...]:
    coarse = _coarse_overrides(problem) if fidelity == "coarse" else ()
    return problem.overrides + tuple(f"{k}={toml_literal(float(v))}" for k, v in params) + coarse


def _load_design(problem: Problem, params: Sequence[tuple[str, float]], fidelity: str = "fine"):
    assert problem.base_case is not None   # a case problem has its base case (load_problem)
    return load_case(problem.base_case, _design_overrides(problem, params, fidelity))


MESH_SIZE_KEYS = ("size_flank", "size_bore", "size_interior", "size_hole", "size_fillet")
"""The ``[mesh]`` sizes a coarse design scales (those left at None follow the others)."""


def _coarse_overrides(problem: Problem) -> tuple[str, ...]:
    """The overrides of the coarse mesh: every size of the base case's mesh times the screening's
    ``mesh_scale`` (none without screening)."""
    if problem.screening is None or problem.base_case is None:
        return ()
    mesh = load_case(problem.base_case, problem.overrides).mesh
    return tuple(f"mesh.{k}={toml_literal(getattr(mesh, k) * problem.screening.mesh_scale)}"
                 for k in MESH_SIZE_KEYS if getattr(mesh, k) is not None)


# --------------------------------------------------------------------------------------------
# Screening: the coarse designs whose results could change the front or the best, on the fine mesh
# --------------------------------------------------------------------------------------------


FRONT_AXES = {"case": ("disc_mass_kg", "life_ratio"), "analytic": ("objective", "g")}
"""The Pareto front's axes by problem kind: (smaller is better, larger is better)."""


def _screened_keys(problem: Problem) -> tuple[str, ...]:
    """The responses the reported results depend on: the objective, the front's axes and every
    budget's response."""
    keys = [problem.objective, *FRONT_AXES[problem.kind], *(BUDGETS[name][0] for name, _ in problem.budgets)]
    return tuple(dict.fromkeys(keys))


def _value(row: dict, key: str) -> float | None:
    v = row.get(key)
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)


def error_bands(problem: Problem, pairs: Sequence[tuple[dict, dict]]) -> dict[str, float]:
    """The coarse–fine error band of every screened response: ``band_factor`` times the largest
    |coarse − fine| over the designs evaluated on both meshes (``pairs`` of rows; 0 without one)."""
    assert problem.screening is not None
    out = {}
    for key in _screened_keys(problem):
        diffs = [abs(c - f) for c, f in ((_value(a, key), _value(b, key)) for a, b in pairs)
                 if c is not None and f is not None]
        out[key] = problem.screening.band_factor * max(diffs, default=0.0)
    return out


def _interval(row: dict, key: str, bands: dict[str, float]) -> tuple[float, float]:
    """Where the fine value of ``key`` can be: the value itself for a fine row, the coarse value ±
    its band for a coarse one, anywhere when the coarse run gave none."""
    v = _value(row, key)
    if v is None:
        return (-math.inf, math.inf) if row.get("fidelity") == "coarse" else (math.nan, math.nan)
    band = bands.get(key, 0.0) if row.get("fidelity") == "coarse" else 0.0
    return v - band, v + band


def to_confirm(problem: Problem, rows: Sequence[dict], bands: dict[str, float]) -> list[dict]:
    """The coarse rows whose fine result could change the reported front or best design (the
    best design only with ``screening.confirm = "best"``).

    A coarse row is kept on the coarse mesh only if, wherever in its band the fine values lie,
    it is neither the best feasible design nor on the Pareto front: it is surely infeasible
    (a budget broken even at the favourable end of the band) or some other design surely beats
    it (a surely feasible design with a smaller objective at the unfavourable ends of both
    bands; for the front, a design better in both axes at the unfavourable ends). Every other
    coarse row is returned. A coarse run that failed after the case validation is returned too
    (the fine mesh may succeed); one the validation rejected is the same on both meshes.

    When every fine value lies within its band, the front and the best design of the rows with
    every returned row replaced by its fine result are those of all rows evaluated on the fine
    mesh: every row left coarse is dominated (or beaten, or infeasible) in both.
    """
    x, y = FRONT_AXES[problem.kind]

    def ok(r: dict) -> bool:
        return r.get("status") == "ok"

    def possibly_feasible(r: dict) -> bool:
        for name, limit in problem.budgets:
            key, sense = BUDGETS[name]
            lo, hi = _interval(r, key, bands)
            if math.isnan(lo) or (lo > limit if sense == "max" else hi < limit):
                return False
        return True

    def surely_feasible(r: dict) -> bool:
        for name, limit in problem.budgets:
            key, sense = BUDGETS[name]
            lo, hi = _interval(r, key, bands)
            if math.isnan(lo) or not (hi <= limit if sense == "max" else lo >= limit):
                return False
        return True

    good = [r for r in rows if ok(r)]
    bound = min((_interval(r, problem.objective, bands)[1] for r in good if surely_feasible(r)), default=math.inf)
    boxes = {id(r): (_interval(r, x, bands), _interval(r, y, bands)) for r in good}

    def beaten_on_front(r: dict) -> bool:
        (xlo, _), (_, yhi) = boxes[id(r)]
        for s in good:
            if s is r:
                continue
            (_, sxhi), (sylo, _) = boxes[id(s)]
            if sxhi <= xlo and sylo >= yhi and (sxhi < xlo or sylo > yhi):
                return True
        return False

    keep_front = problem.screening is None or problem.screening.confirm == "front"
    out = []
    for r in rows:
        if r.get("fidelity") != "coarse":
            continue
        if not ok(r):
            if r.get("digest"):   # failed after the validation (which gives no digest): try the fine mesh
                out.append(r)
            continue
        best = possibly_feasible(r) and _interval(r, problem.objective, bands)[0] <= bound
        if best or (keep_front and not beaten_on_front(r)):
            out.append(r)
    return out
