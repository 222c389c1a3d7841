"""rvfem optimise on a local cluster: wall time, time per design and what the best design saves.

Runs an optimisation file (default: studies/rv40e_fanholes_lightest.toml) into a folder and
prints:

- the wall time, the designs computed and their mean and median run time inside the workers (per
  fidelity when screening), and the parallel efficiency Σ(design run times) / (workers × wall time);
- the base case's and the best feasible design's mass, inertia, load delta, life ratio, L10h and
  fatigue safety factor, and the mass saving of the best design against the base's holes and
  against the solid disc.

A rerun into the same folder resumes (designs already in trials.csv are not run again): give a
fresh folder for a timing. Run from the repository root::

    python benchmarks/bench_optimise.py -o results/bench_optimise --workers 2
    python benchmarks/bench_optimise.py studies/other.toml -o DIR --trials 10 --json DIR/bench.json
    python benchmarks/bench_optimise.py -o DIR --trials 8 --full-designs   # every design a full rvfem run (before)
    python benchmarks/bench_optimise.py -o DIR --trials 8 --screen 2       # screening, coarse mesh sizes x 2
    python benchmarks/bench_optimise.py -o DIR --screen 2 --confirm best   # the fine mesh confirms the best only

The machine should be otherwise idle: the load average before and after is printed.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import statistics
import time
from pathlib import Path

from rvfem.app.optimise import Screening, load_problem, run_optimisation

KEYS = ("disc_mass_kg", "disc_polar_inertia_kg_mm2", "max_load_delta_percent", "life_ratio", "L10h_h",
        "fatigue_safety_factor", "static_safety_factor")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("problem", nargs="?", default="studies/rv40e_fanholes_lightest.toml")
    parser.add_argument("-o", "--output", required=True)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--trials", type=int)
    parser.add_argument("--cache-dir", default="meshes")
    parser.add_argument("--json")
    parser.add_argument("--full-designs", action="store_true",
                        help="run every design as a full rvfem run (the optimiser before design-only analyses)")
    parser.add_argument("--screen", type=float, metavar="SCALE",
                        help="screen on a coarse mesh (sizes x SCALE), confirming the front on the case's mesh")
    parser.add_argument("--confirm", choices=("front", "best"), default="front",
                        help="with --screen: what the case's mesh confirms (the front and the best, or the best only)")
    args = parser.parse_args()
    load_before = os.getloadavg()[0]
    problem = load_problem(args.problem, trials=args.trials)
    if args.screen:
        problem = dataclasses.replace(problem, screening=Screening(mesh_scale=args.screen, confirm=args.confirm))
    t0 = time.perf_counter()
    r = run_optimisation(problem, args.output, workers=args.workers, cache_dir=args.cache_dir,
                         design_only=not args.full_designs)
    wall = time.perf_counter() - t0
    # every design run in the workers this time (the screened ones and the confirmations): trials.csv
    # holds one row per design, screening.csv the coarse runs
    from rvfem.app.optimise import read_trials

    runs = [row for row in read_trials(Path(args.output) / "trials.csv") + read_trials(Path(args.output) / "screening.csv")
            if row.get("computed") and isinstance(row.get("wall_time_s"), float) and math.isfinite(row["wall_time_s"])
            and row.get("status") == "ok"]
    seen, own = set(), []
    for row in runs:   # a confirmed design is in both files with its fine time in trials.csv only once
        key = (row["id"], row["fidelity"])
        if key not in seen:
            seen.add(key)
            own.append(row)
    times = {f: [row["wall_time_s"] for row in own if row["fidelity"] == f] for f in ("fine", "coarse")}
    every = [t for ts in times.values() for t in ts]
    out = {"designs": len(r.rows), "computed": r.computed, "feasible": sum(1 for row in r.rows if row["feasible"]),
           "failed": sum(1 for row in r.rows if row["status"] != "ok"), "wall_time_s": wall,
           "design_only": not args.full_designs, "screen_mesh_scale": args.screen,
           "runs_fine": len(times["fine"]), "runs_coarse": len(times["coarse"]),
           "median_fine_run_s": statistics.median(times["fine"]) if times["fine"] else None,
           "median_coarse_run_s": statistics.median(times["coarse"]) if times["coarse"] else None,
           "mean_design_s": sum(every) / len(every) if every else None,
           "wall_per_design_s": wall / max(len(r.rows), 1),
           "parallel_efficiency": sum(every) / (args.workers * wall) if every else None,
           "load_average_before": load_before, "load_average_after": os.getloadavg()[0],
           "base": {k: (r.base or {}).get(k) for k in KEYS}, "best": {k: (r.best or {}).get(k) for k in KEYS},
           "best_id": (r.best or {}).get("id"),
           "best_parameters": {p.key: (r.best or {}).get(p.key) for p in problem.parameters}}
    if r.base and r.best:
        out["mass_saving_vs_base_percent"] = 100 * (1 - r.best["disc_mass_kg"] / r.base["disc_mass_kg"])
    for k, v in out.items():
        print(f"{k}: {v}")
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
