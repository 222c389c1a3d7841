"""Benchmark: the cost of the hysteresis loop against one assembly + factorisation of the disc.

For the case given (default: the fan-hole RV-40E), builds the disc model (assembly and
factorisation timed), then solves the loop of 40 load steps (plus the ±3 % points) at crank angle
0 three ways: on the fresh stage (its compliance columns computed as the loop needs them), again on
the same stage (the columns cached: the loop's own solves) and averaged over the 9 crank angles of
one mesh period as ``rvfem hysteresis`` does; with ``--te``, then the transmission error over one
crank revolution at the case's angle step (``rvfem hysteresis --te``). Prints the times, wall and
CPU (the process's, all threads: on a shared machine the wall time also counts the waits for a
core), and each as a multiple of one assembly + factorisation.

Run: ``python benchmarks/bench_hysteresis.py [CASE] [--steps 40] [--angles 9] [--te] [--set KEY=VALUE ...]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rvfem import fem
from rvfem.app.analysis import default_cache_dir
from rvfem.app.hysteresis import mesh_period_angles
from rvfem.case.definition import load_case
from rvfem.mesh import mesh_case
from rvfem.solve import accuracy, cycle


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default=str(ROOT / "cases" / "rv40e_fanholes.toml"))
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--angles", type=int, default=9)
    ap.add_argument("--te", action="store_true", help="also the transmission error over one revolution")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="case override")
    args = ap.parse_args(argv)
    case = load_case(args.case, overrides=tuple(args.set))
    mesh = mesh_case(case, default_cache_dir())
    system = cycle.build_system(case, mesh)
    t0 = time.perf_counter()
    model = fem.build_model(mesh.points, mesh.triangles, youngs_modulus=case.material.youngs_modulus,
                            poissons_ratio=case.material.poissons_ratio, thickness=case.cycloid.thickness,
                            order=case.analysis.element_order)
    fem.factorize(model)
    unit = time.perf_counter() - t0
    stage = cycle.case_stage(system)
    T, mu = float(case.loads.torque_Nm), float(case.analysis.friction)
    times, cpu = {}, {}
    for label in ("first loop (columns computed)", "loop again (columns cached)"):
        t0, c0 = time.perf_counter(), time.process_time()
        loop = accuracy.hysteresis_loop(stage, 0.0, T, friction=mu, steps=args.steps)
        times[label], cpu[label] = time.perf_counter() - t0, time.process_time() - c0
    thetas = mesh_period_angles(case, args.angles)
    label = f"{args.angles} crank angles"
    t0, c0 = time.perf_counter(), time.process_time()
    for th in thetas:
        accuracy.hysteresis_loop(stage, float(th), T, friction=mu, steps=args.steps)
    times[label], cpu[label] = time.perf_counter() - t0, time.process_time() - c0
    if args.te:
        te_angles = np.radians(np.arange(0.0, 360.0, case.analysis.angle_step_deg))
        t0, c0 = time.perf_counter(), time.process_time()
        accuracy.transmission_error(stage, te_angles, T, mu)
        times[f"TE at {te_angles.size} crank angles"] = time.perf_counter() - t0
        cpu[f"TE at {te_angles.size} crank angles"] = time.process_time() - c0
    print(f"{case.name}: {mesh.n_nodes} nodes; assembly + factorisation {unit:.2f} s")
    print(f"loop of {len(loop.torque_Nm)} solves ({args.steps} steps + the ±3 % points and both sides of the "
          f"zeros), {int(loop.iterations.sum())} Newton iterations at crank angle 0")
    for label, t in times.items():
        print(f"  {label:32s} {t:7.2f} s  = {t / unit:5.1f} × assembly + factorisation   (CPU {cpu[label]:6.2f} s)")
    print(f"  per crank angle of the average  {times[f'{args.angles} crank angles'] / len(thetas):7.2f} s "
          f"(mesh period {math.degrees(thetas[1] - thetas[0]) * len(thetas):.2f}°)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
