"""Benchmark: cost of a full 360° load cycle against one assembly + factorisation.

On ``cases/rv40e_fanholes.toml`` at its default mesh (or the case given), measures

1. the mesh (cached after the first run) and the system set-up: assembly of K, factorisation on
   the 3-DOF support, footprint interface;
2. the 360-angle load cycle at 1° with the condensed solver (:func:`rvfem.solve.cycle.load_cycle`):
   interface compliance columns computed once (in one parallel sweep over the columns the cycle
   will need) and reused by every angle, small dense active-set systems per angle;
3. a handful of angles solved *naively*: each angle factorises K afresh and back-substitutes the
   load columns of its own contacts (no reuse between angles) — the cost of solving every angle
   as an independent FE contact problem (a code that re-factorises at every active-set
   iteration would be slower still);

4. the reducer stage's cycle: two discs sharing the carrier (with the case's crankshafts), from an
   empty compliance cache like the single disc;
5. all of the above side by side for the case's exactly symmetric mesh (one 360°/N sector copied
   by rotation: compliance columns of one sector, crank angles of one sector, the rest turned)
   and for the full-disc mesh (``mesh.symmetric = false``), with the bearing loads of both;
6. ``rvfem run`` of the case, wall time by stage (a subprocess, as a user runs it; the mesh is
   cached by the runs before).

and prints the ratios the design asks for: cycle / (assembly + factorisation), naive / condensed
per angle, two-disc / single-disc cycle and symmetric / full, plus the peak memory of the
process and of the ``rvfem run`` subprocess and each of its child processes.

Run: ``python benchmarks/bench_cycle.py [CASE] [--naive-angles 5] [--step 1] [--no-run] [--repeat 5]``
(``--repeat`` reports the medians of several measurements: the column time varies by about 15 %
from run to run on a shared machine).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rvfem import fem  # noqa: E402
from rvfem.solve import contact  # noqa: E402
from rvfem.fem import crankshaft  # noqa: E402
from rvfem.solve import cycle  # noqa: E402
from rvfem.case.definition import load_case  # noqa: E402
from rvfem.mesh import mesh_case  # noqa: E402


class NaiveCompliance(contact.Compliance):
    """The straightforward alternative: every crank angle factorises K afresh and back-substitutes
    the load columns of its own contacts, with no reuse between angles (within an angle, columns
    are kept across its active-set iterations). :meth:`new_angle` starts an angle."""

    def __init__(self, model, B):
        super().__init__(None, B, workers=1)
        self.model = model
        self.factorizations = 0
        self._factor = None

    def new_angle(self):
        self._factor = None
        self.known[:] = False

    def ensure(self, columns):
        columns = np.asarray(columns, dtype=int)
        need = np.unique(columns[~self.known[columns]])
        if need.size == 0:
            return
        t0 = time.perf_counter()
        if self._factor is None:
            self._factor = fem.factorize(self.model)
            self.factorizations += 1
        X = self._factor.solve(self.B[:, need].toarray())
        self.C[:, need] = np.asarray(self.B.T @ X)
        self.known[need] = True
        self.solve_seconds += time.perf_counter() - t0
        self.columns_solved += need.size


def measure(case, mesh_dir: str, thetas: np.ndarray) -> dict:
    """Set-up, single-disc cycle and reducer-stage cycle of one case, from empty caches."""
    out = {}
    t0 = time.perf_counter()
    mesh = mesh_case(case, mesh_dir)
    out["mesh_s"] = time.perf_counter() - t0
    out["mesh_cached"] = mesh.from_cache
    system = cycle.build_system(case, mesh)
    setup = system.setup_seconds
    out.update(nodes=mesh.n_nodes, dofs=system.model.n_dofs, columns=system.interface.n_columns,
               symmetry=system.symmetry, assembly_s=setup["assembly"], factorization_s=setup["factorization"],
               interface_s=setup["interface"])
    t0 = time.perf_counter()
    result = cycle.load_cycle(system, thetas, stage=cycle.single_disc_stage(system))
    out["cycle_s"] = time.perf_counter() - t0
    tm = result.timings
    out.update(columns_solved=tm["columns_solved"], columns_mapped=system.compliance.columns_mapped,
               column_s=tm["column_solve"], solves=tm["pair_solves"],
               iterations=float(result.iterations.mean()), max_load=float(result.bearing_loads.max()))
    # each cycle with only its own system alive, as in a run: with the single disc's system (its
    # factor and its 100 MB of compliance) kept, the stage's back-substitutions were measured
    # 30 % slower on the benchmark machine (0.90 against 0.69 s), in the same process
    del system, result
    if case.loads.discs == 2:
        pair_system = cycle.build_system(case, mesh)
        stage = cycle.build_stage(pair_system, discs=2, influence=crankshaft.crankshaft_influence(case))
        t0 = time.perf_counter()
        pair = cycle.load_cycle(pair_system, thetas, stage=stage)
        out["pair_s"] = time.perf_counter() - t0
        out.update(pair_solves=pair.timings["pair_solves"], pair_columns=pair.timings["columns_solved"],
                   pair_max_load=float(pair.bearing_loads.max()), stage=stage.describe())
    return out


def measure_repeated(case, mesh_dir: str, thetas: np.ndarray, repeat: int) -> dict:
    """:func:`measure` ``repeat`` times; every time is the median over the repeats, the rest is
    from the last one (the counts and loads do not change)."""
    times: dict[str, list[float]] = {}
    for _ in range(max(1, repeat)):
        out = measure(case, mesh_dir, thetas)      # the run before is dropped (its system with it)
        for key, value in out.items():
            if key.endswith("_s") and isinstance(value, float):
                times.setdefault(key, []).append(value)
    out.update({key: float(np.median(values)) for key, values in times.items()})
    return out


def _high_water_mib(pid: int) -> float:
    """VmHWM of a live process (Linux), MiB; 0 when it cannot be read (gone, not Linux)."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return 0.0


def _children(pid: int) -> list[int]:
    try:
        return [int(c) for t in Path(f"/proc/{pid}/task").iterdir()
                for c in (t / "children").read_text().split()]
    except OSError:
        return []


def _role(pid: int) -> str:
    """What a child process of ``rvfem run`` is, from its command line."""
    try:
        cmd = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return "other"
    if "rvfem._child import _serve" in cmd:   # the process's name is its program's argument
        return "render worker" if cmd.rstrip().endswith(" render") else "P2 model process"
    return "other"


def run_stages(case_path: str) -> tuple[float, dict, dict]:
    """``rvfem run`` in a subprocess: wall time, its stage timings and the peak memory (MiB) of
    the run's process and of each of its child processes (render worker, P2 model process), read
    from /proc every 20 ms (the high-water mark of a process only grows; ``RUSAGE_CHILDREN`` would
    count the benchmark's own memory, which a forked child shows until it executes the
    interpreter), and their sum (an upper bound of what the run holds at once)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "rvfem.app.cli", "run", case_path, "-o", str(Path(tmp) / "out")]
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        peak, roles = {}, {}
        while proc.poll() is None:
            for pid in [proc.pid] + _children(proc.pid):
                peak[pid] = max(peak.get(pid, 0.0), _high_water_mib(pid))
                if pid != proc.pid and roles.get(pid, "other") == "other":
                    # again until known: a forked child shows its parent's command line (and peak
                    # memory) until it executes, so its peak restarts once its role is known
                    roles[pid] = _role(pid)
                    if roles[pid] != "other":
                        peak[pid] = _high_water_mib(pid)
            time.sleep(0.02)
        wall = time.perf_counter() - t0
        if proc.returncode:
            raise subprocess.CalledProcessError(proc.returncode, cmd)
        timings = json.loads((Path(tmp) / "out" / "summary.json").read_text())["timings_s"]
    memory = {"main process": peak.pop(proc.pid, 0.0)}
    counted = {pid: mib for pid, mib in peak.items()
               if mib >= 1 or roles.get(pid, "other") != "other"}    # short-lived helpers left out
    for pid, mib in counted.items():
        role = roles.get(pid, "other")
        memory[role] = max(memory.get(role, 0.0), mib)
    memory["sum"] = sum(counted.values()) + memory["main process"]
    return wall, timings, memory


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default=str(Path(__file__).resolve().parents[1] / "cases" / "rv40e_fanholes.toml"))
    ap.add_argument("--naive-angles", type=int, default=5)
    ap.add_argument("--step", type=float, default=1.0, help="crank-angle step of the cycle, deg")
    ap.add_argument("--mesh-dir", default="meshes")
    ap.add_argument("--no-run", action="store_true", help="skip the rvfem run subprocess")
    ap.add_argument("--repeat", type=int, default=1,
                    help="measure set-up and cycles this many times and report the medians (the column "
                         "time varies by about 15 %% from run to run on a shared machine)")
    args = ap.parse_args(argv)

    case = load_case(args.case)
    full_case = dataclasses.replace(case, mesh=dataclasses.replace(case.mesh, symmetric=False))
    thetas = np.radians(np.arange(0.0, 360.0, args.step))
    rows = {"symmetric": measure_repeated(case, args.mesh_dir, thetas, args.repeat),
            "full": measure_repeated(full_case, args.mesh_dir, thetas, args.repeat)}
    if args.repeat > 1:
        print(f"times are medians of {args.repeat} repeats (each from empty caches)")
    print(f"case {case.name}, {len(thetas)} crank angles at {args.step}°, solver {fem.available_solvers()[0]}")
    print(f"{'':34s}{'symmetric mesh':>16s}{'full mesh':>16s}")

    def line(label, key, fmt="{:.3f}"):
        print(f"{label:34s}" + "".join(f"{fmt.format(rows[k][key]) if key in rows[k] else '-':>16s}" for k in rows))

    line("mesh symmetry (N)", "symmetry", "{:d}")
    line("nodes", "nodes", "{:d}")
    line("interface columns", "columns", "{:d}")
    line("assembly, s", "assembly_s")
    line("factorisation, s", "factorization_s")
    for r in rows.values():
        r["af"] = r["assembly_s"] + r["factorization_s"]
        r["ratio"] = r["cycle_s"] / r["af"]
        r["per_angle_ms"] = 1e3 * r["cycle_s"] / len(thetas)
        if "pair_s" in r:
            r["pair_ratio"] = r["pair_s"] / r["af"]
    line("single-disc cycle, s", "cycle_s", "{:.2f}")
    line("  crank angles solved", "solves", "{:d}")
    line("  columns back-substituted", "columns_solved", "{:d}")
    line("  columns by rotation", "columns_mapped", "{:d}")
    line("  column time, s", "column_s", "{:.2f}")
    line("  cost per angle, ms", "per_angle_ms", "{:.1f}")
    line("  Newton iterations per angle", "iterations", "{:.1f}")
    line("  cycle / (assembly + fact.)", "ratio", "{:.1f}")
    line("  max bearing load, N", "max_load", "{:.1f}")
    line("reducer-stage cycle, s", "pair_s", "{:.2f}")
    line("  pair solves", "pair_solves", "{:d}")
    line("  columns back-substituted", "pair_columns", "{:d}")
    line("  cycle / (assembly + fact.)", "pair_ratio", "{:.1f}")
    line("  max bearing load, N", "pair_max_load", "{:.1f}")
    sym, full = rows["symmetric"], rows["full"]
    print(f"symmetric / full: single-disc cycle {sym['cycle_s'] / full['cycle_s']:.2f}"
          + (f", stage cycle {sym['pair_s'] / full['pair_s']:.2f}" if "pair_s" in sym else "")
          + f"; max bearing load differs by {100 * (sym['max_load'] / full['max_load'] - 1):+.3f} % (one disc)"
          + (f", {100 * (sym['pair_max_load'] / full['pair_max_load'] - 1):+.3f} % (stage)" if "pair_s" in sym else ""))
    if "stage" in sym:
        print(f"stage model: {sym['stage']}")

    # naive: a handful of angles, no reuse (full mesh, so that every angle is a real solve)
    if args.naive_angles > 0:
        system = cycle.build_system(full_case, mesh_case(full_case, args.mesh_dir))
        picks = thetas[:: max(1, len(thetas) // args.naive_angles)][: args.naive_angles]
        naive = NaiveCompliance(system.model, system.interface.B)
        naive_system = dataclasses.replace(system, compliance=naive, contact_sets={})
        t0 = time.perf_counter()
        for th in picks:
            naive.new_angle()
            cycle.solve_angle(naive_system, float(th))
        t_naive = (time.perf_counter() - t0) / len(picks)
        t_cond = full["cycle_s"] / len(thetas)
        print(f"naive: {t_naive:.2f} s/angle ({naive.factorizations / len(picks):.1f} factorisations per angle) "
              f"vs condensed {t_cond * 1e3:.1f} ms/angle (full mesh): ratio {t_naive / t_cond:.0f}x")
        ref = cycle.solve_angle(system, float(picks[-1]))
        naive.new_angle()
        nv = cycle.solve_angle(naive_system, float(picks[-1]))
        print(f"  max difference of bearing loads naive vs condensed: "
              f"{np.abs(ref.bearing_loads - nv.bearing_loads).max():.2e} N")
    print(f"peak memory of this process (max RSS) {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")

    if not args.no_run:
        runs = [run_stages(args.case) for _ in range(3)]
        wall, timings, _ = min(runs, key=lambda r: r[0])
        print(f"rvfem run {Path(args.case).name}: {wall:.1f} s wall (best of 3, subprocess incl. start-up; "
              f"all: {', '.join(f'{r[0]:.2f}' for r in runs)})")
        print("  peak memory, MiB (largest of the 3 runs): " + ", ".join(
            f"{k} {max(r[2].get(k, 0.0) for r in runs):.0f}" for k in runs[0][2]))
        print("  stages, s: " + ", ".join(f"{k} {v:.2f}" for k, v in timings.items()
                                         if k not in ("total", "cycle_per_angle") and v >= 0.005))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
