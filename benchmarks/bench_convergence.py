"""Mesh-convergence study of the crank-bearing loads (validation ladder, step 6).

Runs the full load cycle of a case (default ``cases/rv40e_fanholes.toml``) on a sequence of
meshes — all element sizes of the case's ``[mesh]`` table (``size_flank``, ``size_bore``,
``size_interior`` and ``size_hole`` when set) scaled by the factors given — with P1
elements, then the default mesh with P2, and prints per mesh the maximum, minimum and equivalent
load of bearing 0 and their change from the previous (coarser) mesh. The validation ladder
(docs/theory.md) asks for a change of the maximum below 1 % between the two finest meshes.

Run: ``python benchmarks/bench_convergence.py [CASE] [--factors 2 1.4 1 0.7 0.5] [--step 1]
[--bearing-model rollers]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rvfem import compare, cycle  # noqa: E402
from rvfem.case import case_from_dict, case_to_dict, load_case  # noqa: E402
from rvfem.mesh import mesh_case  # noqa: E402


def scaled(case, factor: float):
    """The case with every element size of its ``[mesh]`` table multiplied by ``factor``
    (``size_hole`` too when the case sets it; otherwise its default follows ``size_bore``)."""
    data = case_to_dict(case)
    for key in ("size_flank", "size_bore", "size_interior", "size_hole"):
        if data["mesh"].get(key) is not None:
            data["mesh"][key] *= factor
    return case_from_dict(data, source=case.source)


def run(case, order, step, bearing_model, mesh_dir):
    mesh = mesh_case(case, mesh_dir)
    t0 = time.perf_counter()
    system = cycle.build_system(case, mesh, order=order, bearing_model=bearing_model)
    result = cycle.load_cycle(system, np.radians(np.arange(0.0, 360.0, step)), saved_angles_deg=())
    wall = time.perf_counter() - t0
    b = compare.rigid_vs_flexible(case, result).bearings[0]
    return mesh, system, b, wall


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default=str(Path(__file__).resolve().parents[1] / "cases" / "rv40e_fanholes.toml"))
    ap.add_argument("--factors", type=float, nargs="+", default=[2.0, 1.4, 1.0, 0.7, 0.5])
    ap.add_argument("--step", type=float, default=1.0)
    ap.add_argument("--bearing-model", default=None)
    ap.add_argument("--mesh-dir", default="meshes")
    args = ap.parse_args(argv)
    base = load_case(args.case)

    print(f"{'mesh':>14} {'order':>5} {'nodes':>7} {'DOFs':>7} {'max N':>9} {'Δmax %':>7} "
          f"{'min N':>8} {'Δmin %':>7} {'equiv N':>9} {'Δeq %':>7} {'rigid max':>9} {'wall s':>7}")
    prev = None
    rows = [(f, 1) for f in sorted(args.factors, reverse=True)] + [(1.0, 2)]
    for factor, order in rows:
        case = scaled(base, factor)
        mesh, system, b, wall = run(case, order, args.step, args.bearing_model, args.mesh_dir)
        f = b.flexible
        if prev is not None and order == 1:
            d = [100 * (f.max_N / prev.max_N - 1), 100 * (f.min_N / prev.min_N - 1),
                 100 * (f.equivalent_N / prev.equivalent_N - 1)]
        else:
            d = [float("nan")] * 3
        print(f"{'x' + format(factor, '.2f') + ' sizes':>14} {'P' + str(order):>5} {mesh.n_nodes:>7} "
              f"{system.model.n_dofs:>7} {f.max_N:>9.1f} {d[0]:>7.2f} {f.min_N:>8.1f} {d[1]:>7.2f} "
              f"{f.equivalent_N:>9.1f} {d[2]:>7.2f} {b.rigid.max_N:>9.1f} {wall:>7.1f}")
        if order == 1:
            prev = f
            if factor == 1.0:
                p1_default = f
        else:
            print(f"  P2 vs P1 on the default mesh: max {100 * (f.max_N / p1_default.max_N - 1):+.2f} %, "
                  f"min {100 * (f.min_N / p1_default.min_N - 1):+.2f} %, "
                  f"equivalent {100 * (f.equivalent_N / p1_default.equivalent_N - 1):+.2f} %")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
