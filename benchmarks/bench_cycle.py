"""Benchmark: cost of a full 360° load cycle against one assembly + factorisation.

On ``cases/rv40e_fanholes.toml`` at its default mesh (or the case given), measures

1. the mesh (cached after the first run) and the system set-up: assembly of K, factorisation on
   the 3-DOF support, footprint interface;
2. the 360-angle load cycle at 1° with the condensed solver (:func:`rvfem.cycle.load_cycle`):
   interface compliance columns computed once (in one parallel sweep over the columns the cycle
   will need) and reused by every angle, small dense active-set systems per angle;
3. a handful of angles solved *naively*: each angle factorises K afresh and back-substitutes the
   load columns of its own contacts (no reuse between angles) — the cost of solving every angle
   as an independent FE contact problem (a code that re-factorises at every active-set
   iteration would be slower still);

4. the reducer stage's cycle: two discs sharing the carrier (with the case's crankshafts), 180° of
   pair solves, from an empty compliance cache like the single disc;

and prints the ratios the design asks for: cycle / (assembly + factorisation), naive / condensed
per angle and two-disc / single-disc cycle, plus the peak memory of the process.

Run: ``python benchmarks/bench_cycle.py [CASE] [--naive-angles 5] [--step 1]``.
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rvfem import contact, cycle, fem, reducer  # noqa: E402
from rvfem.case import load_case  # noqa: E402
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
        self.version += 1

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
        self.version += 1
        self.solve_seconds += time.perf_counter() - t0
        self.columns_solved += need.size


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default=str(Path(__file__).resolve().parents[1] / "cases" / "rv40e_fanholes.toml"))
    ap.add_argument("--naive-angles", type=int, default=5)
    ap.add_argument("--step", type=float, default=1.0, help="crank-angle step of the cycle, deg")
    ap.add_argument("--mesh-dir", default="meshes")
    args = ap.parse_args(argv)

    case = load_case(args.case)
    t0 = time.perf_counter()
    mesh = mesh_case(case, args.mesh_dir)
    t_mesh = time.perf_counter() - t0
    t0 = time.perf_counter()
    system = cycle.build_system(case, mesh)
    t_setup = time.perf_counter() - t0
    setup = system.setup_seconds
    af = setup["assembly"] + setup["factorization"]
    print(f"case {case.name}: {mesh.n_nodes} nodes, {system.model.n_dofs} DOFs, "
          f"{system.interface.n_columns} interface columns")
    print(f"mesh {t_mesh:.2f} s ({'cached' if mesh.from_cache else 'generated'}); "
          f"assembly {setup['assembly']:.3f} s, factorisation {setup['factorization']:.3f} s "
          f"({fem.available_solvers()[0]}), interface {setup['interface']:.3f} s, set-up total {t_setup:.2f} s")

    thetas = np.radians(np.arange(0.0, 360.0, args.step))
    t0 = time.perf_counter()
    result = cycle.load_cycle(system, thetas, stage=None)
    t_cycle = time.perf_counter() - t0
    tm = result.timings
    print(f"cycle of {len(thetas)} angles: {t_cycle:.2f} s = {t_cycle / len(thetas) * 1e3:.1f} ms/angle "
          f"(columns {tm['columns_solved']} in {tm['column_solve']:.2f} s, prefetch {tm['prefetch']:.2f} s, "
          f"Newton iterations per angle: mean {result.iterations.mean():.1f}, max {result.iterations.max()})")
    print(f"  ratio cycle / (assembly + factorisation) = {t_cycle / af:.1f}")

    # the reducer stage: two discs sharing the carrier (and the case's crankshafts), each from an
    # empty compliance cache like the single disc above
    if case.loads.discs == 2:
        pair_system = cycle.build_system(case, mesh)
        stage = reducer.build_stage(pair_system, discs=2)
        t0 = time.perf_counter()
        pair = cycle.load_cycle(pair_system, thetas, stage=stage)
        t_pair = time.perf_counter() - t0
        print(f"two-disc cycle ({stage.describe()}): {t_pair:.2f} s, {pair.timings['pair_solves']} pair solves, "
              f"columns {pair.timings['columns_solved']}")
        print(f"  ratio two-disc cycle / single-disc cycle = {t_pair / t_cycle:.2f}")

    # naive: a handful of angles, no reuse
    picks = thetas[:: max(1, len(thetas) // args.naive_angles)][: args.naive_angles]
    naive = NaiveCompliance(system.model, system.interface.B)
    naive_system = cycle.DiscSystem(**{**system.__dict__, "compliance": naive})
    t0 = time.perf_counter()
    for th in picks:
        naive.new_angle()
        cycle.solve_angle(naive_system, float(th))
    t_naive = (time.perf_counter() - t0) / len(picks)
    # condensed, per angle, amortised over the cycle
    t_cond = t_cycle / len(thetas)
    print(f"naive: {t_naive:.2f} s/angle ({naive.factorizations / len(picks):.1f} factorisations per angle) "
          f"vs condensed {t_cond * 1e3:.1f} ms/angle: ratio {t_naive / t_cond:.0f}x")
    # same answers?
    ref = cycle.solve_angle(system, float(picks[-1]))
    naive.new_angle()
    nv = cycle.solve_angle(naive_system, float(picks[-1]))
    print(f"  max difference of bearing loads naive vs condensed: "
          f"{np.abs(ref.bearing_loads - nv.bearing_loads).max():.2e} N")
    print(f"peak memory (max RSS) {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
