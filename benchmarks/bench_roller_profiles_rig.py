"""The roller profiles at the durability rig's load: L10r and where the lamina damage peaks, beside
the rig's outcome.

Zhang et al., *Contact load and elastohydrodynamic lubrication analysis of eccentric bearings in RV
reducer considering the effects of roller profile modification* (Lubricants 2025), ran RV reducers
300 h at their ultimate 1250 N·m with three roller profiles, three reducers each: the arc roller
(R = 500 mm) spalled the crankshaft (the eccentric raceway) at the centre of the contact, the
straight roller near its edge, and the combined roller (a = 1.23 mm, b = 6 µm) showed small pitting
spread over the contact and the best life. This script runs the load cycle of the RV-40E fan-hole
case once at that torque (the roller loads do not depend on the profile: the slice model is
one-way) and evaluates the crank bearing in depth for each profile
(:func:`rvfem.evaluate.roller_life.crank_bearing_depth`, the same function ``rvfem run`` calls; its
numbers are the run's with ``--set crank_bearing.profile.kind=…``), then the same with what the
model leaves out of the straight and combined rollers — a sharp end, a mounting misalignment — to
show what the ranking rests on.

    python benchmarks/bench_roller_profiles_rig.py [CASE] [--torque 1250] [--step 5] [--combined-grid]

``--combined-grid`` adds the combined roller's modification length a and drop b at the rated torque
and at ``--torque`` (the grid of studies/rv40e_fanholes_combined_roller.toml, whose variants are
full runs; here one load cycle per torque): flexible L10r and largest roller pressure per (a, b),
and the best of each.

About a minute on the default case (one load cycle per torque, then about a second per profile).
"""

from __future__ import annotations

import argparse
import dataclasses

from rvfem.app.analysis import analyse
from rvfem.evaluate import roller_life

PROFILES = (
    ("straight", {}, "spalled near the edge of the contact"),
    ("arc", {"crown_radius": 500.0}, "spalled at the centre of the contact"),
    ("combined", {"modification_length": 1.23, "modification_drop": 0.006},
     "small pitting spread over the contact; best life"),
    ("logarithmic", {}, "(not tested)"),
)
"""(kind, profile keys, the rig's outcome) of the table; the keys are Zhang et al.'s rollers."""

WHAT_IF = (
    ("straight", {"corner_radius": 0.0}, "sharp end (r = 0)"),
    ("straight", {"misalignment_mrad": 0.5}, "misalignment 0.5 mrad"),
    ("straight", {"misalignment_mrad": 1.0}, "misalignment 1 mrad"),
    ("combined", {"misalignment_mrad": 0.5}, "misalignment 0.5 mrad"),
    ("combined", {"misalignment_mrad": 1.0}, "misalignment 1 mrad"),
    ("arc", {"misalignment_mrad": 1.0}, "misalignment 1 mrad"),
    ("logarithmic", {"misalignment_mrad": 1.0}, "misalignment 1 mrad"),
)
"""What the model leaves out: (kind, profile keys, label)."""


def with_profile(case, kind: str, **keys):
    """The case with another roller profile (``kind`` and its keys)."""
    b = case.crank_bearing
    return dataclasses.replace(case, crank_bearing=dataclasses.replace(
        b, profile=dataclasses.replace(b.profile, kind=kind, **keys)))


def where(d, length_mm: float) -> str:
    """Where a bearing's damage peaks, in the rig's words: centre (|x| ≤ L/4), edge (within 0.5 mm of
    an end of L) or between."""
    g = d.damage
    if g is None:
        return "-"
    x = abs(g.x_mm)
    zone = "centre" if x <= 0.25 * length_mm else "edge" if x >= 0.5 * length_mm - 0.5 else "between"
    return f"{g.raceway} {zone} |x| {x:.2f}"


def evaluate(a, case):
    """Bearing 1 of the crank bearing in depth of ``case`` on the load cycle of ``a``: (flexible, rigid)."""
    depth = roller_life.crank_bearing_depth(case, a.theta, a.cycle, a.rigid_forces, a.comparison, a.rigid.rating_N,
                                            a.rigid.bearing_speed_rpm)
    return depth.flexible[0], depth.rigid[0]


def row(label: str, f, r, length_mm: float, rig: str = "") -> str:
    g = f.damage
    return (f"| {label} | {f.L10r_h:.0f} | {r.L10r_h:.0f} | {f.roller_peak_pressure_MPa:.0f} | "
            f"{where(f, length_mm)} | {g.peak_over_mean:.2f} | {g.spread_mm:.2f} | {g.middle_share:.2f} | "
            f"{where(r, length_mm)} | {rig} |")


GRID_LENGTHS_MM = (0.6, 1.23, 2.0, 3.0)
GRID_DROPS_MM = (0.0008, 0.003, 0.006, 0.010, 0.015)
"""The combined roller's a and b of ``--combined-grid`` (those of the shipped study)."""


def combined_grid(a, lengths=GRID_LENGTHS_MM, drops=GRID_DROPS_MM) -> None:
    """Print flexible L10r (h) and p_max (MPa) of bearing 1 for every (a, b) on the load cycle of ``a``."""
    torque = a.case.loads.torque_Nm
    cells = {}
    for length in lengths:
        for drop in drops:
            f, _ = evaluate(a, with_profile(a.case, "combined", modification_length=length, modification_drop=drop))
            cells[length, drop] = f
    print(f"\ncombined roller at {torque:g} N·m: flexible L10r h / p_max MPa / damage peak |x| mm (bearing 1)")
    print("| a mm \\ b µm | " + " | ".join(f"{1e3 * b:g}" for b in drops) + " |")
    print("|---|" + "---|" * len(drops))
    for length in lengths:
        print(f"| {length:g} | " + " | ".join(
            f"{cells[length, b].L10r_h:.0f} / {cells[length, b].roller_peak_pressure_MPa:.0f} / "
            f"{abs(cells[length, b].damage.x_mm):.2f}" for b in drops) + " |")
    best_life = max(cells, key=lambda k: cells[k].L10r_h)
    best_p = min(cells, key=lambda k: cells[k].roller_peak_pressure_MPa)
    print(f"longest L10r at a = {best_life[0]:g} mm, b = {1e3 * best_life[1]:g} µm; lowest p_max at "
          f"a = {best_p[0]:g} mm, b = {1e3 * best_p[1]:g} µm")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", nargs="?", default="cases/rv40e_fanholes.toml")
    parser.add_argument("--torque", type=float, default=1250.0, help="output torque, N·m")
    parser.add_argument("--step", type=float, default=5.0, help="crank angle step, degrees")
    parser.add_argument("--combined-grid", action="store_true", help="the combined roller's a × b grid too")
    args = parser.parse_args()
    a = analyse(args.case, overrides=(f"loads.torque_Nm={args.torque}",), angle_step_deg=args.step,
                recover_stress=False, attribute=False)
    length = a.case.crank_bearing.roller_length
    q = a.cycle.roller_loads[:, 0]
    print(f"{a.case.name} at {args.torque:g} N·m, {len(a.theta)} crank angles: bearing 1, largest roller load "
          f"{q.max():.0f} N (flexible); damage per mm on the raceway of its peak")
    head = ("| profile | L10r flexible h | L10r rigid h | p_max flexible MPa | damage peak, flexible (mm) | "
            "peak/mean | half-peak length mm | middle-half share | damage peak, rigid (mm) | rig (300 h at 1250 N·m) |")
    print(head)
    print("|" + "---|" * head.count(" | ") + "---|")
    lives = {}
    for kind, keys, rig in PROFILES:
        f, r = evaluate(a, with_profile(a.case, kind, **keys))
        lives[kind] = f.L10r_h
        print(row(kind, f, r, length, rig))
    print("\nranking by flexible L10r: " + " > ".join(sorted(lives, key=lives.get, reverse=True)))
    print("\nwhat the ranking rests on (the same load cycle):")
    print(head)
    print("|" + "---|" * head.count(" | ") + "---|")
    for kind, keys, label in WHAT_IF:
        base = dict(next(k for n, k, _ in PROFILES if n == kind))
        f, r = evaluate(a, with_profile(a.case, kind, **{**base, **keys}))
        print(row(f"{kind}, {label}", f, r, length))
    if args.combined_grid:
        rated = analyse(args.case, angle_step_deg=args.step, recover_stress=False, attribute=False)
        combined_grid(rated)
        combined_grid(a)


if __name__ == "__main__":
    main()
