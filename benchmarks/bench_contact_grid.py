"""Benchmark: the load cycle's cost and answers against the mesh size, with the contact grid at the
boundary vertices (the default) and fixed (``mesh.contact_grid_flank`` / ``contact_grid_bore``).

For each mesh factor (every element size of the case's ``[mesh]`` × factor) and each grid:

* the DOFs, one assembly + factorisation (A+F), the compliance columns back-substituted;
* the 360° load cycle of the reducer stage from an empty column cache: wall and CPU time, and the
  ratio cycle / (A+F);
* the largest and smallest crank-bearing load and the largest pin force, relative to the case's
  own mesh with the vertex grid (today's answer);

then the growth exponent of the cycle time and of A+F with the DOFs (least-squares slope of the
logarithms over the factors). The fixed grid is the case's own element sizes times ``--grid``
(1: the same footprints as the default mesh; 1.5 or 2: coarser footprints, fewer columns).

Run: ``python benchmarks/bench_contact_grid.py [CASE] [--factors 1 0.8 0.6 0.45] [--grid 1]``.
The machine should be otherwise idle; the CPU time is the steadier figure on a shared one (the
columns' back-substitution holds the GIL with cholespy, so the cycle runs on one core).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench_convergence import scaled  # noqa: E402  (the scripts' own folder is on the path)
from rvfem.case.definition import load_case  # noqa: E402
from rvfem.geometry import disc_geometry  # noqa: E402
from rvfem.mesh import mesh_case  # noqa: E402
from rvfem.solve import cycle  # noqa: E402


def measure(case, mesh_dir: str) -> dict:
    geometry = disc_geometry(case)
    mesh = mesh_case(case, mesh_dir, geometry=geometry)
    system = cycle.build_system(case, mesh, geometry=geometry)
    af = system.setup_seconds["assembly"] + system.setup_seconds["factorization"]
    stage = cycle.case_stage(system)
    wall, cpu = time.perf_counter(), time.process_time()
    result = cycle.load_cycle(stage.first, stage=stage)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    loads = np.linalg.norm(np.asarray(result.bearing_forces), axis=-1)
    return {"dofs": int(system.model.n_dofs), "columns": int(system.interface.n_columns),
            "solved": int(system.compliance.columns_solved), "af_s": af, "cycle_s": wall, "cycle_cpu_s": cpu,
            "ratio": wall / af, "bearing_max": float(loads.max()), "bearing_min": float(loads.min()),
            "pin_max": float(np.max(result.pin_forces))}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("case", nargs="?", default="cases/rv40e_fanholes.toml")
    parser.add_argument("--factors", type=float, nargs="+", default=[1.0, 0.8, 0.6, 0.45])
    parser.add_argument("--grid", type=float, default=1.0, help="fixed grid spacing in the case's own element sizes")
    parser.add_argument("--mesh-dir", default="meshes")
    parser.add_argument("--json", help="write the rows to this file too")
    args = parser.parse_args(argv)
    base = load_case(args.case)
    rows = []
    for label, grid in (("vertex", None), (f"fixed × {args.grid:g}", args.grid)):
        for factor in args.factors:
            row = {"grid": label, "factor": factor, **measure(scaled(base, factor, grid), args.mesh_dir)}
            rows.append(row)
            print(json.dumps(row), flush=True)
    ref = next(r for r in rows if r["grid"] == "vertex" and r["factor"] == 1.0) if 1.0 in args.factors else rows[0]
    print(f"\n{'grid':<12}{'factor':>7}{'DOFs':>8}{'cols':>6}{'A+F s':>7}{'cycle s':>8}{'CPU s':>7}{'/A+F':>6}"
          f"{'ΔFmax %':>9}{'ΔFmin %':>9}{'Δpin %':>8}")
    for r in rows:
        print(f"{r['grid']:<12}{r['factor']:>7.2f}{r['dofs']:>8}{r['solved']:>6}{r['af_s']:>7.2f}{r['cycle_s']:>8.2f}"
              f"{r['cycle_cpu_s']:>7.2f}{r['ratio']:>6.1f}"
              f"{100 * (r['bearing_max'] / ref['bearing_max'] - 1):>9.3f}"
              f"{100 * (r['bearing_min'] / ref['bearing_min'] - 1):>9.3f}{100 * (r['pin_max'] / ref['pin_max'] - 1):>8.3f}")
    for label in dict.fromkeys(r["grid"] for r in rows):
        part = [r for r in rows if r["grid"] == label]
        if len(part) >= 2:
            n = np.log([r["dofs"] for r in part])
            grow = {k: float(np.polyfit(n, np.log([r[k] for r in part]), 1)[0]) for k in ("cycle_s", "cycle_cpu_s", "af_s")}
            print(f"{label}: cycle ∝ N^{grow['cycle_s']:.2f} (CPU N^{grow['cycle_cpu_s']:.2f}), "
                  f"A+F ∝ N^{grow['af_s']:.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
