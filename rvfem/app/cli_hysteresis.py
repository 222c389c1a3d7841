"""``rvfem hysteresis CASE -o DIR``: the transmission-accuracy figures of a case (the library part
is :func:`rvfem.app.hysteresis.accuracy_study`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from rvfem.app.commands import EXIT_OK, Subcommand
from rvfem.app.hysteresis import accuracy_study, loop_option_problem
from rvfem.app.screen import warning_lines
from rvfem.case.definition import load_case
from rvfem.errors import CaseError
from rvfem.outputs.summary import check_output_folder
from rvfem.solve.stage_parts import not_modelled

__all__ = ["HYSTERESIS"]


def _add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a case key (repeatable), as for rvfem run")
    parser.add_argument("-o", "--output", metavar="DIR", help="result folder (default: results/<case name>-accuracy); "
                        "must not exist or be empty unless --overwrite")
    parser.add_argument("--torque", type=float, metavar="NM", help="the loop's torque T (default: loads.torque_Nm, "
                        "the rated torque)")
    parser.add_argument("--angle", type=float, action="append", metavar="DEG",
                        help="crank angle to hold, in [0, 360) (repeatable; not with --angles; default: --angles "
                        "angles over one mesh period 360°/Zc)")
    parser.add_argument("--angles", type=int, metavar="N", help="crank angles of one mesh period the "
                        "loop is averaged over (default 9; not with --angle)")
    parser.add_argument("--steps", type=int, default=40, metavar="N", help="load steps of the loop, a multiple of 4 "
                        "(default 40; the ±3 %% points are added)")
    parser.add_argument("--friction", type=float, metavar="MU", help="pin friction (default: analysis.friction)")
    parser.add_argument("--te", action="store_true", help="also the transmission error over one crank revolution "
                        "at no load and at the torque (te.csv; a few solves per crank angle of the case's step)")
    parser.add_argument("--no-shares", action="store_true", help="skip the compliance shares")
    parser.add_argument("--overwrite", action="store_true", help="replace a non-empty result folder rvfem wrote "
                        "(a folder it did not write is never replaced)")
    parser.add_argument("--cache-dir", default=None, help="directory of cached meshes (as for rvfem run)")


_OPTIONS = {"torque_Nm": "--torque", "angles_deg": "--angle", "angle_count": "--angles", "steps": "--steps",
            "friction": "--friction"}
"""The option of each parameter of :func:`rvfem.app.hysteresis.accuracy_study`."""


def _run(args: argparse.Namespace) -> int:
    case = load_case(args.case, overrides=tuple(args.set))
    out = Path(args.output or Path("results") / f"{case.name}-accuracy")
    problem = loop_option_problem(torque_Nm=args.torque, angles_deg=tuple(args.angle or ()), angle_count=args.angles,
                                  steps=args.steps, friction=args.friction)
    if problem is not None:   # the library's check, in the command line's words
        key, why = problem
        raise CaseError(f"{_OPTIONS[key]} {why.replace('angle_count', '--angles')}")
    check_output_folder(out, args.overwrite)
    s = accuracy_study(case, out, torque_Nm=args.torque, angles_deg=tuple(args.angle or ()), angle_count=args.angles,
                       steps=args.steps, friction=args.friction, te=args.te, shares=not args.no_shares,
                       cache_dir=args.cache_dir, overwrite=args.overwrite)
    print(f"transmission accuracy of '{case.name}': loop ±{s['torque_Nm']:g} N·m, input locked, {s['steps']} steps, "
          f"μ = {s['friction']:g}, mean of {len(s['angles_deg'])} crank angles")
    print(f"  torsional rigidity {s['torsional_rigidity_Nm_per_arcmin']:.1f} N·m/arcmin (b/a, 3–100 % T)")
    print(f"  lost motion {s['lost_motion_arcmin']:.4f} arcmin (±3 % T); hysteresis loss "
          f"{s['hysteresis_loss_arcmin']:.4f} arcmin; backlash {s['backlash_arcmin']:.4f} arcmin")
    if "compliance_shares" in s:
        cs = s["compliance_shares"]
        print("  where the compliance sits: " + ", ".join(f"{k} {100 * v:.0f} %" for k, v in cs["shares"].items()))
        print(f"    each: the part of the rotation that goes when that part alone is made 1000× stiffer; sum "
              f"{100 * cs['total']:.0f} %, {100 * (cs['total'] - 1):+.0f} % from 100 % because the parts interact (stiffening "
              "one shifts load between parallel paths and changes which contacts carry)")
    if "transmission_error" in s:
        te = s["transmission_error"]
        print(f"  transmission error p-p: no load {te['no_load_peak_to_peak_arcsec']:.3f} arcsec, loaded "
              f"{te['loaded_peak_to_peak_arcsec']:.3f} arcsec")
    print(f"  not modelled: {', '.join(short for short, _ in not_modelled())} (see accuracy.md)")
    for line in warning_lines(s["warnings"]):   # the range warnings rvfem run gives at this torque
        print(line)
    print(f"  wall time {s['timings']['total_s']:.1f} s; results: {out}/ (summary.json, accuracy.md, hysteresis.csv)")
    return EXIT_OK


HYSTERESIS = Subcommand("hysteresis", "transmission accuracy: hysteresis loop with the input locked, torsional "
                        "rigidity, lost motion, hysteresis loss, compliance shares, transmission error",
                        _add_arguments, _run)
