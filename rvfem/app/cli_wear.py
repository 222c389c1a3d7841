"""``rvfem wear CASE -o DIR --hours H``: the transmission-accuracy life of a case (the library part
is :func:`rvfem.app.wear.wear_life`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from rvfem.app.commands import EXIT_OK, Subcommand
from rvfem.app.wear import wear_life, wear_option_problem
from rvfem.case.definition import load_case
from rvfem.errors import CaseError
from rvfem.outputs.summary import check_output_folder

__all__ = ["WEAR"]


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML)")
    parser.add_argument("--hours", type=float, required=True, metavar="H",
                        help="hours of service to run (stops earlier at wear.lost_motion_limit_arcsec)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a case key (repeatable), as for rvfem run")
    parser.add_argument("-o", "--output", metavar="DIR", help="result folder (default: results/<case name>-wear); "
                        "must not exist or be empty unless --overwrite")
    parser.add_argument("--angles", type=int, default=3, metavar="N",
                        help="crank angles of one mesh period the lost motion is averaged over (default 3)")
    parser.add_argument("--overwrite", action="store_true", help="replace a non-empty result folder rvfem wrote")
    parser.add_argument("--cache-dir", default=None, help="directory of cached meshes (as for rvfem run)")


_OPTIONS = {"hours": "--hours", "angle_count": "--angles"}


def _run(args: argparse.Namespace) -> int:
    problem = wear_option_problem(args.hours, args.angles)
    if problem is not None:   # the library's check, in the command line's words
        raise CaseError(f"{_OPTIONS[problem[0]]} {problem[1]}")
    case = load_case(args.case, overrides=tuple(args.set))
    out = Path(args.output or Path("results") / f"{case.name}-wear")
    check_output_folder(out, args.overwrite)
    s = wear_life(case, out, hours=args.hours, angle_count=args.angles, cache_dir=args.cache_dir,
                  overwrite=args.overwrite)
    life = s["transmission_accuracy_life_h"]
    slope = s["lost_motion_growth_arcsec_per_h"]
    print(f"transmission-accuracy life of '{case.name}': k = {case.wear.k_flank_pin:g} mm²/N, step "
          f"{case.wear.update_step_um:g} µm, pins {case.wear.pin_rolling}, {s['updates']} geometry updates")
    print(f"  lost motion {s['initial_lost_motion_arcsec']:.2f} → {s['final_lost_motion_arcsec']:.2f} arcsec over "
          f"{s['hours_run']:.0f} h" + (f"; late growth {slope:.4f} arcsec/h" if slope is not None else ""))
    print(f"  TE peak to peak over a mesh period {s['te_peak_to_peak_initial_arcsec']:.2f} → "
          f"{s['te_peak_to_peak_final_arcsec']:.2f} arcsec")
    print(f"  life to {s['lost_motion_limit_arcsec']:g} arcsec: "
          + (f"{life:.0f} h" if life is not None else f"not reached in {s['hours_run']:.0f} h"))
    for w in s["warnings"]:
        print(f"  warning: {w}")
    print(f"  wall time {s['timings']['total_s']:.1f} s; results: {out}/ (report.md, summary.json, wear.csv, worn_flank.csv)")
    return EXIT_OK


WEAR = Subcommand("wear", "transmission-accuracy life: Archard wear of flanks, pins and bearings, lost motion "
                  "over the hours of service", _add_arguments, _run)
