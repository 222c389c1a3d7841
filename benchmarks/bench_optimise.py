"""rvfem optimise on a local cluster: wall time, time per design and what the best design saves.

Runs an optimisation file (default: studies/rv40e_fanholes_lightest.toml) into a folder and
prints:

- the wall time, the designs computed and their mean run time inside the workers, and the
  parallel efficiency Σ(design run times) / (workers × wall time);
- the base case's and the best feasible design's mass, inertia, load delta, life ratio, L10h and
  fatigue safety factor, and the mass saving of the best design against the base's holes and
  against the solid disc.

A rerun into the same folder resumes (designs already in trials.csv are not run again): give a
fresh folder for a timing. Run from the repository root::

    python benchmarks/bench_optimise.py -o results/bench_optimise --workers 2
    python benchmarks/bench_optimise.py studies/other.toml -o DIR --trials 10 --json DIR/bench.json

The machine should be otherwise idle: the load average before and after is printed.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
from pathlib import Path

from rvfem.app.optimise import load_problem, run_optimisation

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
    args = parser.parse_args()
    load_before = os.getloadavg()[0]
    problem = load_problem(args.problem, trials=args.trials)
    t0 = time.perf_counter()
    r = run_optimisation(problem, args.output, workers=args.workers, cache_dir=args.cache_dir)
    wall = time.perf_counter() - t0
    own = [row["wall_time_s"] for row in r.rows if row["computed"] and isinstance(row["wall_time_s"], float)
           and math.isfinite(row["wall_time_s"])]
    out = {"designs": len(r.rows), "computed": r.computed, "feasible": sum(1 for row in r.rows if row["feasible"]),
           "failed": sum(1 for row in r.rows if row["status"] != "ok"), "wall_time_s": wall,
           "mean_design_s": sum(own) / len(own) if own else None,
           "parallel_efficiency": sum(own) / (args.workers * wall) if own else None,
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
