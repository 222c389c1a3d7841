"""Mesh-convergence study of the crank-bearing loads (validation ladder, step 6).

Runs the full load cycle of a case (default ``cases/rv40e_fanholes.toml``) on a sequence of
meshes — all element sizes of the case's ``[mesh]`` table (``size_flank``, ``size_bore``,
``size_interior`` and ``size_hole`` when set) scaled by the factors given — with P1
elements, then the default mesh with P2, and prints per mesh the maximum, minimum and equivalent
load of bearing 0 and their change from the previous (coarser) mesh. The validation ladder
(docs/theory.md) asks for a change of the maximum below 1 % between the two finest meshes.

With ``--stress`` it measures instead the convergence of the structural stress peak (the
``peak_von_mises_MPa`` of ``rvfem run``: P2 re-solve, away from the contacts) under refinement of
the holes: the whole analysis (``rvfem.app.analysis.analyse``, as ``rvfem run`` makes it) with
``mesh.size_hole`` multiplied by each of ``--hole-factors`` (default 1, 1/2, 1/4 of the case's),
the other sizes unchanged. Per mesh it prints the reported peak with its own error estimate, the
P1 cycle's peak, and the P2 peak maximised over every crank angle within ``--window`` degrees of
the reported one (the reported value re-solves only the angles where the P1 peak lies, which move by
a degree or two with the mesh). Every three successive meshes (factors halving) give a
Richardson extrapolation f∞ = f₃ + (f₃ − f₂)/(2^p − 1) with the observed order
p = log2((f₂ − f₁)/(f₃ − f₂)); each mesh's error against the finest three's f∞ is printed beside
the run's own estimate. docs/outputs.md quotes ``--hole-factors 1 0.5 0.25 0.125``.

With ``--fixed-contact-grid`` the contact grid stays that of the case's own mesh
(``mesh.contact_grid_*``): the loads' change is then the FE discretisation's alone.

Run: ``python benchmarks/bench_convergence.py [CASE] [--factors 2 1.4 1 0.7 0.5] [--step 1]
[--bearing-model rollers] [--fixed-contact-grid]``; ``python benchmarks/bench_convergence.py --stress [CASE]
[--hole-factors 1 0.5 0.25] [--step 1] [--window 10]`` (about 2 minutes on two cores, 4 with the
factor 0.125 added).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rvfem.evaluate import compare  # noqa: E402
from rvfem.solve import cycle  # noqa: E402
from rvfem.evaluate import postprocess  # noqa: E402
from rvfem.case.definition import case_from_dict, case_to_dict, load_case  # noqa: E402
from rvfem.mesh import mesh_case  # noqa: E402


def scaled(case, factor: float, grid: float | None = None):
    """The case with every element size of its ``[mesh]`` table multiplied by ``factor``
    (``size_hole`` and ``size_fillet`` too when the case sets them; otherwise their defaults follow
    ``size_bore``). With ``grid``, the contact grid is fixed at the case's own flank and bore sizes
    × ``grid`` (``mesh.contact_grid_flank`` / ``contact_grid_bore``, docs/theory.md § 5): only the
    FE mesh is refined, not the contact model."""
    data = case_to_dict(case)
    own = dict(data["mesh"])
    for key in ("size_flank", "size_bore", "size_interior", "size_hole", "size_fillet"):
        if data["mesh"].get(key) is not None:
            data["mesh"][key] *= factor
    if grid is not None:
        data["mesh"].update(contact_grid_flank=own["size_flank"] * grid, contact_grid_bore=own["size_bore"] * grid)
    return case_from_dict(data, source=case.source)


def run(case, order, step, bearing_model, mesh_dir):
    mesh = mesh_case(case, mesh_dir)
    t0 = time.perf_counter()
    system = cycle.build_system(case, mesh, order=order, bearing_model=bearing_model)
    result = cycle.load_cycle(system, np.radians(np.arange(0.0, 360.0, step)), saved_angles_deg=())
    wall = time.perf_counter() - t0
    b = compare.rigid_vs_flexible(case, result).bearings[0]
    return mesh, system, b, wall


def stress_row(path, size_hole, step, mesh_dir, window_deg):
    """The structural peak of ``rvfem run`` on the case with ``mesh.size_hole = size_hole``, and
    the P2 peak maximised over the crank angles within ``window_deg`` of it."""
    from rvfem.app.analysis import analyse

    t0 = time.perf_counter()
    analysis = analyse(path, overrides=(f"mesh.size_hole={size_hole!r}",), angle_step_deg=step,
                       cache_dir=mesh_dir, attribute=False, duty_fe=False)
    wall = time.perf_counter() - t0
    reported = analysis.stress.recovered
    theta = analysis.cycle.theta
    centre = np.radians(reported.peak.theta_deg)
    near = np.abs(np.angle(np.exp(1j * (theta - centre)))) <= np.radians(window_deg) + 1e-9
    system = analysis.system
    system_p2 = cycle.build_system(analysis.case, analysis.mesh, order=2, bearing_model=system.bearing_model,
                                   pin_model=system.pin_model, geometry=system.geometry)
    swept = postprocess.recover_peak(system_p2, analysis.cycle, theta[near], analysis.mesh.points,
                                     analysis.mesh.boundaries, exclude=analysis.stress.band_mm)
    return analysis, reported, swept, wall


def richardson(values):
    """Converged value and observed order from three values on meshes halved twice (NaN when the
    differences do not shrink monotonically)."""
    f1, f2, f3 = values
    d1, d2 = f2 - f1, f3 - f2
    if d1 == 0.0 or d2 / d1 <= 0.0 or abs(d2) >= abs(d1):
        return float("nan"), float("nan")
    p = float(np.log2(d1 / d2))
    return f3 + d2 / (2.0 ** p - 1.0), p


def main_stress(args) -> int:
    base = load_case(args.case)
    h0 = base.mesh.size_hole if base.mesh.size_hole is not None else 2.0 * base.mesh.size_bore
    factors = sorted(args.hole_factors, reverse=True)
    print(f"structural stress peak of {base.name}: P2 re-solve away from contacts, mesh.size_hole refined "
          f"(other sizes unchanged), {args.step:g}° steps")
    print(f"{'size_hole':>9} {'vertices':>8} {'P1 MPa':>7} {'run MPa':>8} {'± est':>6} {'at °':>5} "
          f"{'window MPa':>10} {'at °':>5} {'analyse s':>9} {'P2 s':>5}")
    rows = []
    for f in factors:
        h = h0 * f
        analysis, reported, swept, wall = stress_row(args.case, h, args.step, args.mesh_dir, args.window)
        rows.append((h, reported, swept))
        print(f"{h:>9.4g} {analysis.mesh.points.shape[0]:>8} {reported.p1_MPa:>7.2f} "
              f"{reported.peak.von_mises_MPa:>8.2f} {reported.estimated_error_MPa:>6.2f} "
              f"{reported.peak.theta_deg:>5.0f} {swept.peak.von_mises_MPa:>10.2f} {swept.peak.theta_deg:>5.0f} "
              f"{wall:>9.1f} {reported.seconds:>5.1f}", flush=True)
        del analysis
    if len(rows) < 3 or not np.allclose(np.diff(np.log2(factors)), -1.0):
        print("Richardson extrapolation needs three or more factors, each half the previous")
        return 0
    for label, pick in (("run (P1 peak angles)", lambda r: r[1]), ("window (P2 maximum)", lambda r: r[2])):
        values = [pick(r).peak.von_mises_MPa for r in rows]
        print(f"\n{label}:")
        for i in range(len(values) - 2):
            converged, order = richardson(values[i:i + 3])
            print(f"  size_hole {rows[i][0]:.4g} to {rows[i + 2][0]:.4g}: differences "
                  f"{values[i + 1] - values[i]:+.2f}, {values[i + 2] - values[i + 1]:+.2f} MPa; "
                  f"observed order {order:.2f}; Richardson {converged:.2f} MPa")
        # errors against the extrapolation from the finest three meshes
        for (h, reported, _), v in zip(rows, values):
            err = v - converged
            print(f"  size_hole {h:.4g}: {v:.2f} MPa, {100 * err / converged:+.2f} % "
                  f"({err:+.2f} MPa; the run's estimate ± {reported.estimated_error_MPa:.2f} MPa, "
                  f"{'covers' if abs(err) <= reported.estimated_error_MPa else 'does NOT cover'} it; "
                  f"P1 {100 * (reported.p1_MPa / converged - 1):+.1f} %)")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default=str(Path(__file__).resolve().parents[1] / "cases" / "rv40e_fanholes.toml"))
    ap.add_argument("--factors", type=float, nargs="+", default=[2.0, 1.4, 1.0, 0.7, 0.5])
    ap.add_argument("--step", type=float, default=1.0)
    ap.add_argument("--bearing-model", default=None)
    ap.add_argument("--fixed-contact-grid", action="store_true",
                    help="keep the contact grid of the case's own mesh while the mesh is refined")
    ap.add_argument("--mesh-dir", default="meshes")
    ap.add_argument("--stress", action="store_true",
                    help="convergence of the structural stress peak under refinement of mesh.size_hole")
    ap.add_argument("--hole-factors", type=float, nargs="+", default=[1.0, 0.5, 0.25],
                    help="factors of the case's mesh.size_hole (--stress)")
    ap.add_argument("--window", type=float, default=10.0,
                    help="crank angles within this many degrees of the reported peak's are re-solved on P2 (--stress)")
    args = ap.parse_args(argv)
    if args.stress:
        return main_stress(args)
    base = load_case(args.case)

    print(f"{'mesh':>14} {'order':>5} {'nodes':>7} {'DOFs':>7} {'max N':>9} {'Δmax %':>7} "
          f"{'min N':>8} {'Δmin %':>7} {'equiv N':>9} {'Δeq %':>7} {'rigid max':>9} {'wall s':>7}")
    prev = None
    rows = [(f, 1) for f in sorted(args.factors, reverse=True)] + [(1.0, 2)]
    for factor, order in rows:
        case = scaled(base, factor, 1.0 if args.fixed_contact_grid else None)
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
