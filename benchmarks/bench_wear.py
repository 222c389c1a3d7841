"""Benchmark: the cost of ``rvfem wear`` and how it grows with the hours and with the update step.

For the case given (default: the fan-hole RV-40E), times ``rvfem wear --hours 2000`` as the
command runs it (it stops at the lost-motion limit), then the loop over life with the limit lifted
for ``--hours`` and twice that at the case's update step and at twice the step, on one factorised
disc: the set-up (mesh, assembly, factorisation), the geometry updates and the time per update.
The cost is the set-up plus one load cycle per duty row and 3·6 + 6 solves (lost motion and
rigidity at 3 angles, TE at 6) per update, so it grows with the number of updates ≈ hours × wear
rate / step.

Run: ``python benchmarks/bench_wear.py [CASE] [--hours 100] [--set KEY=VALUE ...]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rvfem.app.analysis import default_cache_dir
from rvfem.app.wear import life_loop, wear_life
from rvfem.case.definition import load_case
from rvfem.geometry import disc_geometry
from rvfem.mesh import mesh_case
from rvfem.solve.cycle import build_system, case_stage


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default=str(ROOT / "cases" / "rv40e_fanholes.toml"))
    ap.add_argument("--hours", type=float, default=100.0, help="hours of the lifted-limit runs (and twice that)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="case override")
    args = ap.parse_args(argv)
    case = load_case(args.case, overrides=tuple(args.set))

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        s = wear_life(case, Path(tmp) / "w", hours=2000.0)
        wall = time.perf_counter() - t0
    life = s["transmission_accuracy_life_h"]
    print(f"rvfem wear {Path(args.case).name} --hours 2000: {wall:.1f} s, {s['updates']} updates, "
          f"{s['hours_run']:.0f} h run, life {'—' if life is None else f'{life:.0f} h'}")

    t0 = time.perf_counter()
    geometry = disc_geometry(case)
    system = build_system(case, mesh_case(case, default_cache_dir(), geometry=geometry), geometry=geometry)
    setup = time.perf_counter() - t0
    print(f"set-up (mesh from cache, assembly, factorisation): {setup:.1f} s")
    print("| hours | step, µm | updates | wall, s | s per update |")
    print("|---|---|---|---|---|")
    for step in (case.wear.update_step_um, 2 * case.wear.update_step_um):
        for hours in (args.hours, 2 * args.hours):
            lifted = case.replace(wear=dataclasses.replace(case.wear, update_step_um=step,
                                                           lost_motion_limit_arcsec=3600.0))
            t0 = time.perf_counter()
            records, _, _ = life_loop(lifted, case_stage(system), system, hours, 3)
            dt = time.perf_counter() - t0
            n = len(records) - 1
            print(f"| {hours:g} | {step:g} | {n} | {dt:.1f} | {dt / max(n, 1):.2f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
