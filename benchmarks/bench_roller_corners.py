"""Convergence of the crank bearing in depth under slice refinement, per roller profile.

For every profile kind the case is run with ``[crank_bearing.profile] slices`` = n and 2n (n the
case's own, default 30) and the table prints, for bearing 1, the largest roller pressure (flexible
and rigid) and L10r (flexible and rigid) with their change from n to 2n. The slices are refined at
the roller ends and the profile's junctions (:func:`rvfem.evaluate.roller_slices.slice_layout`);
the corners are the case's (default 0.2 mm radius).

    python benchmarks/bench_roller_corners.py [CASE] [--slices 30] [--step 1]

Each run is a full ``rvfem run --no-images`` (about 10 s on the default case).
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

KINDS = ("straight", "arc", "combined", "logarithmic")


def _run(case: Path, kind: str, slices: int, step: float, work: Path) -> dict:
    text = case.read_text(encoding="utf-8")
    text = re.sub(r"^\[crank_bearing\.profile\][^\[]*", "", text, flags=re.M)
    table = f'[crank_bearing.profile]\nkind = "{kind}"\nslices = {slices}\n\n'
    text = text.replace("[material]", table + "[material]", 1)
    text = re.sub(r"^angle_step_deg\s*=.*$", f"angle_step_deg = {step}", text, flags=re.M)
    path = work / f"{kind}_{slices}.toml"
    path.write_text(text, encoding="utf-8")
    out = work / f"out_{kind}_{slices}"
    subprocess.run([sys.executable, "-m", "rvfem", "run", str(path), "-o", str(out), "--no-images"],
                   check=True, capture_output=True)
    return json.loads((out / "summary.json").read_text())["crank_bearing_depth"]["bearings"][0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("case", nargs="?", default="cases/rv40e_fanholes.toml")
    parser.add_argument("--slices", type=int, default=30)
    parser.add_argument("--step", type=float, default=1.0, help="crank angle step, degrees")
    args = parser.parse_args()
    print(f"{'profile':12s} {'n':>4s}  {'p_max flex':>10s} {'rigid':>8s}  {'L10r flex h':>11s} {'rigid h':>9s}  "
          f"{'ratio':>6s}")
    with tempfile.TemporaryDirectory() as tmp:
        for kind in KINDS:
            rows = [_run(Path(args.case), kind, n, args.step, Path(tmp)) for n in (args.slices, 2 * args.slices)]
            for n, r in zip((args.slices, 2 * args.slices), rows):
                f, g = r["flexible"], r["rigid"]
                print(f"{kind:12s} {n:4d}  {f['roller_peak_pressure_MPa']:10.1f} {g['roller_peak_pressure_MPa']:8.1f}  "
                      f"{f['L10r_h']:11.0f} {g['L10r_h']:9.0f}  {r['L10r_ratio']:6.4f}")
            a, b = rows
            change = {key: 100.0 * (b[m][key] / a[m][key] - 1.0) for m in ("flexible", "rigid")
                      for key in ("roller_peak_pressure_MPa", "L10r_h")}
            print(f"{'':12s} {'Δ %':>4s}  {change['roller_peak_pressure_MPa']:+10.2f}   (rigid p_max and L10r "
                  f"{100.0 * (b['rigid']['roller_peak_pressure_MPa'] / a['rigid']['roller_peak_pressure_MPa'] - 1):+.2f} "
                  f"/ {100.0 * (b['rigid']['L10r_h'] / a['rigid']['L10r_h'] - 1):+.2f}; flexible L10r "
                  f"{100.0 * (b['flexible']['L10r_h'] / a['flexible']['L10r_h'] - 1):+.2f})")


if __name__ == "__main__":
    main()
