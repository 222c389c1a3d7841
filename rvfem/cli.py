"""Command line: ``rvfem <subcommand> ...``.

Only this module prints. Library code raises :class:`~rvfem.errors.RvfemError` subclasses for
anything a user can cause; :func:`main` turns them into one line on stderr and exit code 2.
Anything else is a bug and keeps its traceback. Ctrl-C exits with 130.

Adding a subcommand: write ``_add_<name>_arguments(parser)`` and ``_run_<name>(args) -> int`` and
append one :class:`Subcommand` to :data:`SUBCOMMANDS`.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import sys
from dataclasses import asdict, dataclass
from typing import Callable, TextIO

from . import __version__
from .case import Case, load_case
from .errors import RvfemError
from .evaluation import (
    STRIBECK_FACTOR,
    bearing_speed_rpm,
    crank_bearing_hertz,
    crank_bearing_rating,
    duty_cycle_life,
    rating_life_hours,
    stribeck_max_roller_load,
)
from .rigid import handbook_bearing_loads, summarize_bearing_loads

__all__ = ["main", "build_parser", "Subcommand", "SUBCOMMANDS", "EXIT_OK", "EXIT_USER_ERROR", "EXIT_INTERRUPTED"]

EXIT_OK = 0
EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130
EXIT_BROKEN_PIPE = 141

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Subcommand:
    """One ``rvfem`` subcommand: its name, one-line help, argument setup and action."""

    name: str
    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


# --------------------------------------------------------------------------------------------
# rvfem check CASE
# --------------------------------------------------------------------------------------------


def _add_check_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML)")


def _run_check(args: argparse.Namespace) -> int:
    case = load_case(args.case)
    print(f"OK: case '{case.name}' ({args.case}) is valid")
    return EXIT_OK


# --------------------------------------------------------------------------------------------
# rvfem rigid CASE [--json]
# --------------------------------------------------------------------------------------------


def _add_rigid_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML)")
    parser.add_argument("--json", action="store_true", help="write the results as JSON to stdout")


def rigid_report(case: Case) -> dict:
    """Results of the rigid handbook evaluation of a case as a JSON-ready dict.

    Loads in N, angles in degrees, speeds in rpm, lives in hours, pressures in MPa, lengths in mm.
    """
    loads = handbook_bearing_loads(case)
    exponent = case.analysis.equivalent_load_exponent
    summaries = summarize_bearing_loads(loads, exponent)
    n_b = bearing_speed_rpm(case.loads.speed_rpm, case.pins.count, case.cycloid.teeth)
    rating = crank_bearing_rating(case.crank_bearing)
    mat = case.material
    bearings = []
    for s in summaries:
        inner, outer = crank_bearing_hertz(
            case.crank_bearing, s.max_N, youngs_modulus_MPa=mat.youngs_modulus, poissons_ratio=mat.poissons_ratio
        )
        life = rating_life_hours(rating, s.equivalent_N, n_b)
        entry = {
            "bearing": s.bearing + 1,
            "crank_angle_deg": case.cranks.angles_deg[s.bearing],
            "max_load_N": s.max_N,
            "max_at_deg": s.max_at_deg,
            "min_load_N": s.min_N,
            "min_at_deg": s.min_at_deg,
            "equivalent_load_N": s.equivalent_N,
            "L10h_h": life,
            "max_roller_load_N": stribeck_max_roller_load(s.max_N, case.crank_bearing.rollers),
            "hertz_inner": asdict(inner),
            "hertz_outer": asdict(outer),
        }
        bearings.append(entry)
    comp = loads.components
    report = {
        "case": case.name,
        "source": case.source,
        "model": "rigid handbook (equal load sharing, zero clearance)",
        "output_torque_Nm": case.loads.torque_Nm,
        "disc_torque_Nmm": comp.disc_torque_Nmm,
        "output_speed_rpm": case.loads.speed_rpm,
        "bearing_speed_rpm": n_b,
        "k": comp.k,
        "k_y": comp.k_y,
        "sum_px_N": comp.sum_px,
        "sum_py_N": comp.sum_py,
        "equivalent_load_exponent": exponent,
        "angle_step_deg": 360.0 / loads.theta.size,
        "dynamic_load_rating_N": rating,
        "stribeck_factor": STRIBECK_FACTOR,
        "bearings": bearings,
    }
    if case.loads.duty_cycle:
        rated_life = min(b["L10h_h"] for b in bearings)
        duty = duty_cycle_life(case.loads.duty_cycle, rated_life, case.loads.speed_rpm, case.loads.torque_Nm)
        report["duty_cycle"] = {"rated_life_h": rated_life, **asdict(duty)}
    return report


def _format_rigid(report: dict, out: TextIO) -> None:
    p = report["equivalent_load_exponent"]
    p_text = "10/3" if math.isclose(p, 10.0 / 3.0) else f"{p:g}"
    w = out.write
    w(f"Case {report['case']} ({report['source']}): {report['model']}\n")
    w(
        f"  output torque {report['output_torque_Nm']:g} N·m, disc torque {report['disc_torque_Nmm'] / 1000:g} N·m, "
        f"output speed {report['output_speed_rpm']:g} rpm, bearing speed {report['bearing_speed_rpm']:g} rpm\n"
    )
    w(
        f"  k = {report['k']:.4f}, k_y = {report['k_y']:.4f}, ΣPx = {report['sum_px_N']:.1f} N, "
        f"ΣPy = {report['sum_py_N']:.1f} N, crank-angle step {report['angle_step_deg']:g}°\n"
    )
    w(f"  dynamic load rating C = {report['dynamic_load_rating_N']:.1f} N; equivalent load exponent p = {p_text}\n\n")
    header = (
        f"{'bearing':>7} {'max N':>9} {'at °':>6} {'min N':>9} {'at °':>6} {'F_m N':>9} "
        f"{'L10h h':>9} {'Q_max N':>8} {'p_in MPa':>9} {'p_out MPa':>9}\n"
    )
    w(header)
    w("-" * (len(header) - 1) + "\n")
    for b in report["bearings"]:
        w(
            f"{b['bearing']:>7d} {b['max_load_N']:9.1f} {b['max_at_deg']:6.1f} {b['min_load_N']:9.1f} "
            f"{b['min_at_deg']:6.1f} {b['equivalent_load_N']:9.1f} {b['L10h_h']:9.0f} "
            f"{b['max_roller_load_N']:8.1f} {b['hertz_inner']['peak_pressure_MPa']:9.1f} "
            f"{b['hertz_outer']['peak_pressure_MPa']:9.1f}\n"
        )
    w(
        "\n  at °: crank angle θ of the eccentric relative to the carrier; F_m = (mean F^p)^(1/p) over a turn\n"
        f"  L10h = 1e6/(60·n_b)·(C/F_m)^(10/3); Hertz at Q_max = {report['stribeck_factor']:g}·F_max/Z "
        "(p_in: eccentric, p_out: disc bore)\n"
    )
    duty = report.get("duty_cycle")
    if duty:
        w(
            f"  duty cycle: equivalent torque {duty['equivalent_torque_Nm']:.1f} N·m, equivalent speed "
            f"{duty['equivalent_speed_rpm']:.2f} rpm, service life {duty['service_life_h']:.0f} h "
            f"(from the shortest rated life {duty['rated_life_h']:.0f} h)\n"
        )


def _run_rigid(args: argparse.Namespace) -> int:
    case = load_case(args.case)
    report = rigid_report(case)
    if args.json:
        json.dump(report, sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    else:
        _format_rigid(report, sys.stdout)
    return EXIT_OK


# --------------------------------------------------------------------------------------------
# rvfem mesh CASE [--cache-dir DIR] [--force]
# --------------------------------------------------------------------------------------------


def _add_mesh_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML)")
    parser.add_argument("--cache-dir", default="meshes",
                        help="directory of cached meshes and previews (default: meshes)")
    parser.add_argument("--force", action="store_true", help="re-mesh even if a cached mesh exists")


def _run_mesh(args: argparse.Namespace) -> int:
    import time

    from .geometry import disc_geometry
    from .mesh import mesh_case, mesh_preview_png

    case = load_case(args.case)
    start = time.perf_counter()
    geom = disc_geometry(case)
    mesh = mesh_case(case, args.cache_dir, use_cache=not args.force, geometry=geom)
    elapsed = time.perf_counter() - start
    png = mesh_preview_png(mesh, mesh.path.with_suffix(".png"), title=f"{case.name}: disc mesh")
    thinnest = geom.walls[0]
    print(f"mesh of case '{case.name}' ({args.case}): {mesh.path}"
          f" ({'cached' if mesh.from_cache else 'generated'} in {elapsed:.2f} s)")
    print(f"  {mesh.n_nodes} nodes, {mesh.n_elements} linear triangles, "
          f"min element quality ({mesh.quality_measure}) {mesh.min_quality:.3f}")
    print(f"  boundaries: {', '.join(f'{n} ({len(e)} edges)' for n, e in mesh.boundaries.items())}")
    print(f"  thinnest wall {thinnest.thickness:.2f} mm between {thinnest.first} and {thinnest.second}")
    print(f"  preview: {png}")
    return EXIT_OK


# --------------------------------------------------------------------------------------------
# rvfem run CASE -o DIR [--step DEG] [--bearing-model M] [--order N] [--overwrite] ...
# --------------------------------------------------------------------------------------------


def _add_run_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML)")
    parser.add_argument("-o", "--output", metavar="DIR",
                        help="result folder (default: results/<case name>); must not exist or be empty "
                             "unless --overwrite")
    parser.add_argument("--step", type=float, metavar="DEG", help="crank-angle step in degrees (overrides "
                        "analysis.angle_step_deg)")
    parser.add_argument("--bearing-model", choices=("rollers", "rigid_bore"),
                        help="crank-bearing model (overrides crank_bearing.model)")
    parser.add_argument("--order", type=int, choices=(1, 2), help="element order (overrides analysis.element_order)")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace an existing result folder (only once the new results are complete)")
    parser.add_argument("--field-step", type=float, metavar="DEG",
                        help="also keep stress fields (VTU frames) every DEG degrees; default: the case's "
                             "saved angles and the angle of the largest bearing load")
    parser.add_argument("--no-images", action="store_true", help="skip the PyVista stress and mesh images")
    parser.add_argument("--cache-dir", default="meshes", help="directory of cached meshes (default: meshes)")


class _RunProgress:
    """Progress of ``rvfem run`` on stderr: a redrawn status line with a bar for the load cycle on a
    terminal, plain log lines otherwise."""

    BAR = 30

    def __init__(self, stream: TextIO, tty: bool):
        from .run import STAGES

        self.stream, self.tty, self.stages = stream, tty, list(STAGES)
        self.descriptions = STAGES
        self.started: dict[str, float] = {}
        self.first_tick: dict[str, tuple[float, int]] = {}  # (time, angles done) of the first tick
        self.last_draw = 0.0
        self.last_tenth = -1
        self.width = 0

    def _line(self, text: str, final: bool = False) -> None:
        if self.tty:
            pad = max(0, self.width - len(text))
            self.stream.write("\r" + text + " " * pad + ("\n" if final else ""))
            self.width = 0 if final else len(text)
        elif final:
            self.stream.write(text + "\n")
        self.stream.flush()

    def __call__(self, stage: str, done: int, total: int) -> None:
        import time

        now = time.perf_counter()
        index = self.stages.index(stage) + 1 if stage in self.stages else 0
        head = f"rvfem run [{index}/{len(self.stages)}] {self.descriptions.get(stage, stage)}"
        if done == 0:
            self.started[stage] = now
            self.first_tick.pop(stage, None)
            self.last_tenth = -1
            if self.tty:
                self._line(head + " …")
            elif stage == "cycle":
                self._line(f"{head}: {total} crank angles", final=True)
            return
        elapsed = now - self.started.get(stage, now)
        if done >= total:
            self._line(f"{head}: done in {elapsed:.1f} s", final=True)
            return
        if stage != "cycle":
            return
        if self.tty:
            self.first_tick.setdefault(stage, (now, done))
            if now - self.last_draw < 0.1:
                return
            self.last_draw = now
            filled = int(self.BAR * done / total)
            # the first angle also computes the interface compliance the whole cycle reuses:
            # estimate the rate from the angles after it
            t_first, d_first = self.first_tick.setdefault(stage, (now, done))
            rate = (now - t_first) / (done - d_first) if done > d_first else None
            left = "" if rate is None else f", about {rate * (total - done):.0f} s left"
            self._line(f"{head} [{'#' * filled}{'.' * (self.BAR - filled)}] {done}/{total}, "
                       f"{elapsed:.1f} s{left}")
        else:
            tenth = 10 * done // total
            if tenth > self.last_tenth:
                self.last_tenth = tenth
                if tenth > 0:
                    self._line(f"rvfem run: cycle {done}/{total} angles ({10 * tenth} %), {elapsed:.1f} s",
                               final=True)

    def abort(self) -> None:
        """End a half-drawn status line (before an error message)."""
        if self.tty and self.width:
            self.stream.write("\n")
            self.stream.flush()
            self.width = 0


def _run_run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .run import run_case, summary_text

    case = load_case(args.case)
    out_dir = Path(args.output) if args.output else Path("results") / case.name
    progress = _RunProgress(sys.stderr, sys.stderr.isatty())
    try:
        result = run_case(case, out_dir, angle_step_deg=args.step, bearing_model=args.bearing_model,
                          order=args.order, overwrite=args.overwrite, progress=progress,
                          cache_dir=args.cache_dir, images=not args.no_images, field_step_deg=args.field_step)
    except BaseException:
        progress.abort()
        raise
    print(summary_text(result.summary))
    print(f"  results: {result.out_dir}/ (summary.json, report.html; schema in docs/outputs.md)")
    return EXIT_OK


# --------------------------------------------------------------------------------------------
# Registry and entry point
# --------------------------------------------------------------------------------------------

#: All subcommands, in the order ``rvfem --help`` lists them.
SUBCOMMANDS: tuple[Subcommand, ...] = (
    Subcommand("check", "validate a case file", _add_check_arguments, _run_check),
    Subcommand("rigid", "rigid handbook crank-bearing loads, rating, life and Hertz pressures",
               _add_rigid_arguments, _run_rigid),
    Subcommand("mesh", "mesh the disc (Gmsh, cached) and write a PNG preview", _add_mesh_arguments, _run_mesh),
    Subcommand("run", "the main job: rigid and flexible load cycle, lives, stresses; tables, VTK, images "
               "and a report in a result folder", _add_run_arguments, _run_run),
)


def build_parser(subcommands: tuple[Subcommand, ...] = SUBCOMMANDS) -> argparse.ArgumentParser:
    """The argument parser with one sub-parser per entry of ``subcommands``."""
    parser = argparse.ArgumentParser(
        prog="rvfem",
        description="Crank-bearing loads of RV reducers with a flexible cycloid disc.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="more log output on stderr (-v info, -vv debug)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for command in subcommands:
        p = sub.add_parser(command.name, help=command.help, description=command.help)
        command.add_arguments(p)
        p.set_defaults(run=command.run)
    return parser


def _setup_logging(verbosity: int) -> None:
    level = logging.WARNING if verbosity <= 0 else logging.INFO if verbosity == 1 else logging.DEBUG
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s", stream=sys.stderr, force=True)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (0 ok, 2 user error, 130 interrupted,
    141 output pipe closed early)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, usage errors (argparse exits with 2)
        return exc.code if isinstance(exc.code, int) else (EXIT_OK if exc.code is None else EXIT_USER_ERROR)
    _setup_logging(args.verbose)
    try:
        return args.run(args)
    except RvfemError as exc:
        print(f"rvfem {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("rvfem: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # e.g. `rvfem rigid case.toml | head -3`: stop quietly
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_BROKEN_PIPE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
