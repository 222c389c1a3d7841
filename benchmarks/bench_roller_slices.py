"""Speed of the crank bearing in depth: the slice model of every roller at every crank angle.

Runs the load cycle of a case once (default ``cases/rv40e_fanholes.toml``, 360 angles, no stress
re-solve, no attribution), then times :func:`rvfem.evaluate.roller_life.crank_bearing_depth` (both
raceways of every bearing, rigid and flexible, plus the worst roller's re-solve, film and lives:
the whole cycle) and the flexible slices alone (:func:`rvfem.evaluate.roller_life.cycle_slices` on
both raceways of every bearing), the median of ``--repeat`` (the machine is shared), for each
roller profile (``--kinds``, default the case's) at each number of slices (``--slices``, default
30 100 400), with the ratio of the whole cycle's time to that at the first count. Prints the
number of roller contacts solved and the time per contact.

Run: ``python benchmarks/bench_roller_slices.py [CASE] [--repeat 3] [--slices 30 100 400] [--kinds logarithmic]``
(a few minutes). Measurements with one solve per distinct active set: benchmarks/README.md,
"Roller slices".

Earlier, Measured on two shared cores (rv40e_fanholes, logarithmic profile, 400 slices, rigid + flexible
with film and lives): with one dense solve of n + 1 unknowns per contact and active-set iteration,
48–89 s for every fourth angle (90 angles; the 360 angles of a run took 365 s), and far longer
with two BLAS threads contending for the cores; with the block inverse through C⁻¹
(k = min(|S|, |I|) unknowns) and single-threaded BLAS 7 s for the 90 angles and 17–19 s for all
360. The slice loads agree to 1e-12 (relative); 30 slices take 0.3 s either way.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from rvfem.app.analysis import analyse
from rvfem.evaluate import roller_life


def _median(function, repeat: int) -> float:
    """Median wall time of ``repeat`` calls, s (the machine is shared: the median, not the best)."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        function()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", nargs="?", default="cases/rv40e_fanholes.toml")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--slices", type=int, nargs="+", default=[30, 100, 400],
                        help="slices per roller (default: 30 100 400)")
    parser.add_argument("--kinds", nargs="+", default=None,
                        help="roller profiles to time (default: the case's)")
    args = parser.parse_args()
    a = analyse(args.case, recover_stress=False, attribute=False)
    cyc = a.cycle
    contacts = int(np.count_nonzero(cyc.roller_loads > 0)) * 2
    print(f"{a.case.name}: {len(a.theta)} crank angles, {cyc.roller_loads.shape[1]} bearings × "
          f"{cyc.roller_loads.shape[2]} rollers; {contacts} loaded roller–raceway contacts (flexible); "
          f"median of {args.repeat}")
    kinds = args.kinds or [a.case.crank_bearing.profile.kind]
    for kind in kinds:
        first = None
        for slices in args.slices:
            profile = dataclasses.replace(a.case.crank_bearing.profile, kind=kind, slices=slices)
            case = a.case.replace(crank_bearing=dataclasses.replace(a.case.crank_bearing, profile=profile))
            geoms = roller_life.raceways(case)
            slopes = roller_life.eccentric_slopes(case, cyc)
            tilts = roller_life.roller_tilts(slopes, cyc.roller_angles, cyc.bearing_forces,
                                             1e-3 * profile.misalignment_mrad)

            def flexible_slices():
                cache: dict = {}
                for i in range(cyc.roller_loads.shape[1]):
                    for g in geoms:
                        roller_life.cycle_slices(cyc.roller_loads[:, i], tilts[:, i],
                                                 case.crank_bearing.roller_length, g, profile, cache=cache)

            def everything():
                roller_life.crank_bearing_depth(case, a.theta, cyc, a.rigid_forces, a.comparison, a.rigid.rating_N,
                                                a.rigid.bearing_speed_rpm)

            t_flex = _median(flexible_slices, args.repeat)
            t_all = _median(everything, args.repeat)
            first = first or t_all
            print(f"  {kind:<12} {slices:4d} slices: whole cycle (rigid + flexible with film and lives) "
                  f"{t_all:.3f} s ({t_all / first:.2f}× the first count); flexible slices {t_flex:.3f} s "
                  f"({1e6 * t_flex / contacts:.1f} µs per contact)")


if __name__ == "__main__":
    main()
