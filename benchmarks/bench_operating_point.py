"""A torque sweep on one disc model: the cost of 20 operating points at one crank angle against one
angle's Newton solve, and of a load cycle at a new operating point against the case's own cycle.

Usage::

    python benchmarks/bench_operating_point.py [--case cases/rv40e_fanholes.toml] [--points 20]

Prints:

* ``one solve``: one crank angle solved from a cold start at the case's torque once its compliance
  columns exist (the median of 5);
* ``sweep``: the same angle at ``--points`` torques from 5 % to 100 % of the case's, each from a
  cold start, on the same system: no factorisation, and columns computed only where a higher
  torque brings new pins into contact (counted);
* the ratio sweep / (points × one solve) (the architecture issue's target: ≤ 1);
* ``cycle`` and ``cycle at 50 %``: the case's load cycle and the same system's cycle at half the
  torque (its contact sets and most columns reused).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rvfem.case.definition import load_case  # noqa: E402
from rvfem.mesh import mesh_case  # noqa: E402
from rvfem.solve import cycle  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", default=str(ROOT / "cases" / "rv40e_fanholes.toml"))
    parser.add_argument("--points", type=int, default=20)
    parser.add_argument("--theta-deg", type=float, default=17.0)
    parser.add_argument("--mesh-dir", default=str(ROOT / "meshes"))
    args = parser.parse_args()
    case = load_case(args.case)
    mesh = mesh_case(case, args.mesh_dir)
    t0 = time.perf_counter()
    system = cycle.build_system(case, mesh)
    setup = time.perf_counter() - t0
    theta = np.radians(args.theta_deg)
    stage = cycle.case_stage(system)
    cycle.solve_pair(stage, theta)                      # columns of the case's torque
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        cycle.solve_pair(stage, theta)
        times.append(time.perf_counter() - t0)
    one = statistics.median(times)
    before = system.compliance.columns_solved
    torques = np.linspace(0.05, 1.0, args.points) * case.loads.torque_Nm
    t0 = time.perf_counter()
    for t in torques:
        cycle.solve_pair(stage, theta, op=cycle.OperatingPoint(float(t), case.analysis.friction))
    sweep = time.perf_counter() - t0
    new_columns = system.compliance.columns_solved - before
    print(f"{case.name}: assembly + factorisation {setup:.2f} s; crank angle {args.theta_deg:g}°")
    print(f"  one solve (cold start, columns known) {one * 1e3:.1f} ms (median of 5)")
    print(f"  sweep of {args.points} torques {sweep * 1e3:.1f} ms = {sweep / (args.points * one):.2f} × "
          f"{args.points} solves; {new_columns} new columns, no factorisation")
    t0 = time.perf_counter()
    cycle.load_cycle(system, saved_angles_deg=())
    full = time.perf_counter() - t0
    t0 = time.perf_counter()
    cycle.load_cycle(system, op=cycle.OperatingPoint(0.5 * case.loads.torque_Nm, case.analysis.friction),
                     saved_angles_deg=())
    half = time.perf_counter() - t0
    print(f"  cycle {full:.2f} s; cycle at 50 % torque on the same system {half:.2f} s")


if __name__ == "__main__":
    main()
