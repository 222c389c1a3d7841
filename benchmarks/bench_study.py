"""Design studies on Dask: the same N variants on 1 and on 2 workers.

Measures, on a local cluster of single-threaded worker processes:

- the wall time of the study on 1 worker and on 2 workers, and the speed-up;
- the scheduling overhead per variant: (study wall time on 1 worker − Σ the variants' own run
  times measured inside the workers) / N, as a fraction of a variant's mean run time — the cost of
  submitting, scheduling, shipping the small summary back and bookkeeping;
- the cluster start-up (once per study) separately;
- the scheduler's own cost per task: the round trip of ``--noop-tasks`` empty tasks (submit,
  schedule, run nothing, gather) on the same cluster, per task;
- the memory of a worker: the peak resident set (RSS) of each worker process over the study and
  the largest of its child processes (the P2 model of the stress stage is built in one), from
  ``getrusage`` in the workers; and the peak RSS of the client process;
- the cost model ``T(N, W) = start-up + ⌈N / W⌉ · t_variant(W) + N · t_task`` (t_variant(W): a
  variant's run time when W workers share the machine; t_task: the scheduler's cost per task,
  paid by the client and scheduler while the workers compute) and its projection for 1000
  variants on 2, 16 and 64 workers (one core each, t_variant measured on 1 worker: a cluster
  node with a core per worker; the 2-worker figure of this machine where cores are shared).

The variants differ in torque only (one mesh, built and cached before timing), so both runs do the
same work; the workers import rvfem before the clock starts (a long study pays that once per
worker). Run from the repository root::

    python benchmarks/bench_study.py                  # 6 variants, the case's mesh, 2° steps
    python benchmarks/bench_study.py --variants 8 --step 5 --repeat 2   # best of 2, alternating
    python benchmarks/bench_study.py --json results/bench_study.json
    python benchmarks/bench_study.py --variants 8 --noop-tasks 2000 --json results/bench_study.json

The machine should be otherwise idle: the load average before and after is printed.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import statistics
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


def _peak_rss_mb() -> dict:
    """Peak resident set of this process and of its largest waited-for child, MB (in a worker)."""
    import resource as r

    return {"self": r.getrusage(r.RUSAGE_SELF).ru_maxrss / 1024, "children": r.getrusage(r.RUSAGE_CHILDREN).ru_maxrss / 1024}


def _noop() -> None:
    return None


def _task_round_trip(client, n: int) -> float:
    """Seconds per task of ``n`` empty tasks submitted at once and gathered (best of 3)."""
    best = math.inf
    for _ in range(3):
        t = time.perf_counter()
        futures = [client.submit(_noop, pure=False) for _ in range(n)]
        client.gather(futures)
        best = min(best, (time.perf_counter() - t) / n)
        del futures
    return best


def _run(study_path: Path, workers: int, out: Path, cache: Path, noop_tasks: int) -> dict:
    from distributed import Client

    from rvfem.app.study import load_study, local_cluster, run_study

    study = load_study(study_path)
    t0 = time.perf_counter()
    with local_cluster(workers) as cluster, Client(cluster) as client:
        client.run(__import__, "rvfem.app.run")  # warm the workers: imports are paid once per worker
        client.run(__import__, "rvfem.app.study")
        startup = time.perf_counter() - t0
        idle = client.run(_peak_rss_mb)          # the workers with rvfem imported, before any variant
        t1 = time.perf_counter()
        result = run_study(study, out, client=client, cache_dir=cache, plots=False)
        wall = time.perf_counter() - t1
        peak = client.run(_peak_rss_mb)
        per_task = _task_round_trip(client, noop_tasks) if noop_tasks else None
    variant_times = [r["wall_time_s"] for r in result.rows if r["computed"]]
    assert result.computed == len(study.variants) and result.failed == 0, result.rows
    return {"workers": workers, "variants": result.computed, "cluster_startup_s": startup, "study_wall_s": wall,
            "variant_times_s": variant_times, "sum_variant_s": sum(variant_times),
            "mean_variant_s": sum(variant_times) / len(variant_times),
            "median_variant_s": statistics.median(variant_times),
            "worker_rss_idle_mb": max(v["self"] for v in idle.values()),
            "worker_rss_peak_mb": max(v["self"] for v in peak.values()),
            "worker_child_rss_peak_mb": max(v["children"] for v in peak.values()),
            "noop_task_s": per_task}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", type=int, default=6, help="number of variants N (default 6)")
    parser.add_argument("--step", type=float, default=2.0, help="crank-angle step, degrees (default 2)")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each (alternating); the best counts")
    parser.add_argument("--noop-tasks", type=int, default=1000,
                        help="empty tasks timed for the scheduler's cost per task (default 1000; 0: none)")
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
                runs[workers].append(_run(study_path, workers, tmp / f"w{workers}-{r}", cache, args.noop_tasks))
        one = sorted(runs[1], key=lambda run: run["study_wall_s"])[(len(runs[1]) - 1) // 2]  # median of the repeats
        two = sorted(runs[2], key=lambda run: run["study_wall_s"])[(len(runs[2]) - 1) // 2]
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    load_after = os.getloadavg()

    n = one["variants"]
    overhead_per_variant = (one["study_wall_s"] - one["sum_variant_s"]) / n
    per_variant_cost = one["study_wall_s"] / n  # one core, overhead included
    t_task = one["noop_task_s"] or 0.0
    startup = max(one["cluster_startup_s"], two["cluster_startup_s"])

    def model(variants: int, workers: int, t_variant: float) -> float:
        """T(N, W) = start-up + ⌈N / W⌉ · t_variant + N · t_task (module docstring)."""
        return startup + math.ceil(variants / workers) * t_variant + variants * t_task

    projection = {f"{w}_workers_s": model(1000, w, one["median_variant_s"]) for w in (2, 16, 64)}
    projection["2_workers_this_machine_s"] = model(1000, 2, two["median_variant_s"])
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
        "cost_model": {"startup_s": startup, "t_variant_1_worker_s": one["median_variant_s"],
                       "t_variant_2_workers_s": two["median_variant_s"], "t_task_s": t_task,
                       "model_vs_measured_2_workers": model(n, 2, two["median_variant_s"]) - startup,
                       "measured_2_workers_s": two["study_wall_s"],
                       "worker_rss_peak_mb": max(one["worker_rss_peak_mb"], two["worker_rss_peak_mb"]),
                       "worker_child_rss_peak_mb": max(one["worker_child_rss_peak_mb"], two["worker_child_rss_peak_mb"]),
                       "worker_rss_idle_mb": one["worker_rss_idle_mb"],
                       "client_rss_peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024},
        "projection_1000_variants": projection,
    }
    print(f"{n} variants (RV-40E fan holes, {args.step:g}° steps), load average before "
          f"{load_before[0]:.2f} / after {load_after[0]:.2f} on {os.cpu_count()} cores")
    for run in (one, two):
        print(f"  {run['workers']} worker(s): study {run['study_wall_s']:6.1f} s (cluster start-up "
              f"{run['cluster_startup_s']:.1f} s), variants {run['mean_variant_s']:.2f} s each on average")
    print(f"  speed-up 1 → 2 workers: {figures['speed_up']:.2f}x")
    print(f"  scheduling overhead: {overhead_per_variant * 1000:.0f} ms per variant = "
          f"{100 * figures['overhead_fraction']:.1f} % of a variant's run time")
    cm = figures["cost_model"]
    print(f"  scheduler cost per task (empty tasks): {t_task * 1000:.2f} ms")
    print(f"  memory: worker peak RSS {cm['worker_rss_peak_mb']:.0f} MB (idle with rvfem imported "
          f"{cm['worker_rss_idle_mb']:.0f} MB), its P2 child {cm['worker_child_rss_peak_mb']:.0f} MB; "
          f"client {cm['client_rss_peak_mb']:.0f} MB")
    print(f"  cost model T = {startup:.1f} s + ⌈N/W⌉·t_variant + N·{t_task * 1000:.2f} ms: on 2 workers it gives "
          f"{cm['model_vs_measured_2_workers']:.1f} s against {two['study_wall_s']:.1f} s measured")
    print("  1000 variants: " + ", ".join(f"{k.replace('_s', '').replace('_', ' ')} {v / 60:.1f} min"
                                          for k, v in projection.items()))
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(figures, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
