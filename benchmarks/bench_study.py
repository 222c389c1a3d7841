"""Design studies on Dask: the same N variants on 1 and on 2 workers.

Measures, on a local cluster of single-threaded worker processes:

- the wall time of the study on 1 worker and on 2 workers, and the speed-up;
- the scheduling overhead per variant: (study wall time on 1 worker − Σ the variants' own run
  times measured inside the workers) / N, as a fraction of a variant's mean run time — the cost of
  submitting, scheduling, shipping the small summary back and bookkeeping;
- the cluster start-up (once per study) separately;
- a projection of a 1000-variant study on a 64-core cluster from the measured per-variant cost.

The variants differ in torque only (one mesh, built and cached before timing), so both runs do the
same work; the workers import rvfem before the clock starts (a long study pays that once per
worker). Run from the repository root::

    python benchmarks/bench_study.py                  # 6 variants, the case's mesh, 2° steps
    python benchmarks/bench_study.py --variants 8 --step 5 --repeat 2   # best of 2, alternating
    python benchmarks/bench_study.py --json results/bench_study.json

The machine should be otherwise idle: the load average before and after is printed.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _study_file(folder: Path, n: int, step: float) -> Path:
    torques = [300.0 + 200.0 * i / max(n - 2, 1) for i in range(n - 1)]  # n − 1 variants + the base
    values = ", ".join(repr(t) for t in torques)
    path = folder / "bench.toml"
    path.write_text(f'name = "bench_study"\nbase_case = "{(ROOT / "cases" / "rv40e_fanholes.toml").as_posix()}"\n'
                    f'kind = "grid"\n\n[overrides]\n"analysis.angle_step_deg" = {step!r}\n\n'
                    f'[[parameter]]\nkey = "loads.torque_Nm"\nvalues = [{values}]\n', encoding="utf-8")
    return path


def _run(study_path: Path, workers: int, out: Path, cache: Path) -> dict:
    from distributed import Client

    from rvfem.app.study import load_study, local_cluster, run_study

    study = load_study(study_path)
    t0 = time.perf_counter()
    with local_cluster(workers) as cluster, Client(cluster) as client:
        client.run(__import__, "rvfem.app.run")  # warm the workers: imports are paid once per worker
        client.run(__import__, "rvfem.app.study")
        startup = time.perf_counter() - t0
        t1 = time.perf_counter()
        result = run_study(study, out, client=client, cache_dir=cache, plots=False)
        wall = time.perf_counter() - t1
    variant_times = [r["wall_time_s"] for r in result.rows if r["computed"]]
    assert result.computed == len(study.variants) and result.failed == 0, result.rows
    return {"workers": workers, "variants": result.computed, "cluster_startup_s": startup, "study_wall_s": wall,
            "variant_times_s": variant_times, "sum_variant_s": sum(variant_times),
            "mean_variant_s": sum(variant_times) / len(variant_times)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", type=int, default=6, help="number of variants N (default 6)")
    parser.add_argument("--step", type=float, default=2.0, help="crank-angle step, degrees (default 2)")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each (alternating); the best counts")
    parser.add_argument("--json", type=Path, help="also write the figures to this JSON file")
    args = parser.parse_args(argv)

    from rvfem.case.definition import load_case
    from rvfem.mesh import mesh_case

    load_before = os.getloadavg()
    tmp = Path(tempfile.mkdtemp(prefix="bench-study-"))
    try:
        study_path = _study_file(tmp, args.variants, args.step)
        cache = tmp / "meshes"
        mesh_case(load_case(ROOT / "cases" / "rv40e_fanholes.toml"), cache)  # the one mesh, before timing
        runs = {1: [], 2: []}
        for r in range(args.repeat):  # alternate, so that a change of the machine's load hits both
            for workers in (1, 2):
                runs[workers].append(_run(study_path, workers, tmp / f"w{workers}-{r}", cache))
        one = min(runs[1], key=lambda run: run["study_wall_s"])  # best of the repeats
        two = min(runs[2], key=lambda run: run["study_wall_s"])
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    load_after = os.getloadavg()

    n = one["variants"]
    overhead_per_variant = (one["study_wall_s"] - one["sum_variant_s"]) / n
    per_variant_cost = one["study_wall_s"] / n  # one core, overhead included
    figures = {
        "variants": n, "angle_step_deg": args.step, "cores": os.cpu_count(),
        "load_average_before": load_before, "load_average_after": load_after,
        "repeats": args.repeat, "one_worker": one, "two_workers": two,
        "all_walls_s": {str(k): [run["study_wall_s"] for run in v] for k, v in runs.items()},
        "speed_up": one["study_wall_s"] / two["study_wall_s"],
        "overhead_per_variant_s": overhead_per_variant,
        "overhead_fraction": overhead_per_variant / one["mean_variant_s"],
        "per_variant_core_s": per_variant_cost,
        "projection_1000_on_64_cores_s": 1000 / 64 * per_variant_cost + one["cluster_startup_s"],
    }
    print(f"{n} variants (RV-40E fan holes, {args.step:g}° steps), load average before "
          f"{load_before[0]:.2f} / after {load_after[0]:.2f} on {os.cpu_count()} cores")
    for run in (one, two):
        print(f"  {run['workers']} worker(s): study {run['study_wall_s']:6.1f} s (cluster start-up "
              f"{run['cluster_startup_s']:.1f} s), variants {run['mean_variant_s']:.2f} s each on average")
    print(f"  speed-up 1 → 2 workers: {figures['speed_up']:.2f}x")
    print(f"  scheduling overhead: {overhead_per_variant * 1000:.0f} ms per variant = "
          f"{100 * figures['overhead_fraction']:.1f} % of a variant's run time")
    print(f"  projection, 1000 variants on 64 cores: {figures['projection_1000_on_64_cores_s'] / 60:.1f} min "
          f"(1000/64 × {per_variant_cost:.1f} s + start-up)")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(figures, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
