"""Benchmark: what the reducer stage does to the flexibility effect, step by step.

For the cases given (default: the RV-40E pair, solid and fan holes), prints per bearing 1 the
attribution chain handbook → equal share of the FE pin resultant → one disc with T/2 → two discs
sharing the carrier → crankshafts as beams (when the case has ``[crank_support]``): maximum,
minimum and equivalent load, their deltas against the handbook and the life ratio; the torque
share of one disc over the cycle; and, with ``--half-pitch``, the difference between modelling
disc B as disc A at θ + 180° and the exact disc B whose teeth sit half a tooth pitch from disc A's
against the bores and holes (a second mesh and compliance; see :mod:`rvfem.solve.cycle`).

Run: ``python benchmarks/bench_reducer.py [CASE ...] [--step 1] [--half-pitch] [--set KEY=VALUE ...]``.
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

from rvfem.evaluate import attribution  # noqa: E402
from rvfem.fem import crankshaft  # noqa: E402
from rvfem.solve import cycle  # noqa: E402
from rvfem.case.definition import load_case  # noqa: E402
from rvfem.mesh import mesh_case  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases", nargs="*", default=[str(ROOT / "cases" / "rv40e_solid.toml"),
                                                 str(ROOT / "cases" / "rv40e_fanholes.toml")])
    ap.add_argument("--step", type=float, default=1.0, help="crank-angle step, deg")
    ap.add_argument("--half-pitch", action="store_true", help="also solve the exact disc B")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="case override")
    ap.add_argument("--mesh-dir", default="meshes")
    args = ap.parse_args(argv)

    for path in args.cases:
        case = load_case(path, [f"analysis.angle_step_deg={args.step}", *args.set])
        system = cycle.build_system(case, mesh_case(case, args.mesh_dir))
        thetas = cycle.cycle_angles(case)
        t0 = time.perf_counter()
        attr = attribution.attribution(system, thetas)
        dt = time.perf_counter() - t0
        print(f"\n{case.name}: {len(thetas)} angles, attribution in {dt:.1f} s "
              f"(case model: {attr.final}); bearing 1, deltas against the handbook")
        print(f"  {'step':12s} {'max N':>8s} {'Δmax':>7s} {'min N':>7s} {'Δmin':>7s} {'F_m N':>8s} {'ΔF_m':>6s} {'life':>6s}")
        for r in attr.table(case.analysis.equivalent_load_exponent):
            if r["bearing"] == 1:
                print(f"  {r['step']:12s} {r['max_N']:8.1f} {r['delta_max_percent']:+6.1f}% {r['min_N']:7.1f} "
                      f"{r['delta_min_percent']:+6.1f}% {r['equivalent_N']:8.1f} {r['delta_equivalent_percent']:+5.1f}% "
                      f"{r['life_ratio']:6.3f}")
        if case.loads.discs == 2:
            stage = cycle.build_stage(system, discs=2, influence=crankshaft.crankshaft_influence(case))
            pair = cycle.load_cycle(system, thetas, saved_angles_deg=(), stage=stage)
            share = pair.disc_torque_Nmm[:, 0] / (case.loads.torque_Nm * 500.0)
            print(f"  torque of disc A / (T/2): {share.min():.4f} … {share.max():.4f} ({stage.describe()})")
            if args.half_pitch:
                case_b = cycle.half_pitch_case(case)
                system_b = cycle.build_system(case_b, mesh_case(case_b, args.mesh_dir))
                exact = cycle.build_stage(system, discs=2, influence=crankshaft.crankshaft_influence(case),
                                          second=system_b, second_disc="half_pitch")
                t0 = time.perf_counter()
                res = cycle.load_cycle(system, thetas, saved_angles_deg=(), stage=exact)
                dt = time.perf_counter() - t0
                fa, fb = pair.bearing_loads, np.linalg.norm(res.disc_bearing_forces, axis=-1)
                share_b = res.disc_torque_Nmm[:, 0] / (case.loads.torque_Nm * 500.0)
                print(f"  exact disc B (teeth turned by {math.degrees(exact.second_phase):.3f}°), {dt:.1f} s: "
                      f"max disc A {fb[:, 0].max():.1f} N, disc B {fb[:, 1].max():.1f} N against "
                      f"{fa.max():.1f} N with disc B = disc A at θ + 180° "
                      f"({100 * (fb.max() / fa.max() - 1):+.2f} %); torque share {share_b.min():.4f} … {share_b.max():.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
