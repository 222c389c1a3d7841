"""Command line: ``rvfem <subcommand> ...``.

This module parses arguments and prints; the computing is in :mod:`rvfem.app.analysis` and the
formatting in :mod:`rvfem.outputs.summary`. Library code raises :class:`~rvfem.errors.RvfemError`
subclasses for anything a user can cause; :func:`main` turns them into one line on stderr and exit
code 2. Anything else is a bug: one line on stderr asking to report it, with the path of a log file
holding the traceback (shown on stderr too with ``-vv``), and exit code 1. Ctrl-C exits with 130.

Adding a subcommand: write ``_add_<name>_arguments(parser)`` and ``_run_<name>(args) -> int`` and
append one :class:`Subcommand` to :data:`SUBCOMMANDS`; from outside the package, one
:func:`register_subcommand` line.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
import tempfile
import time
import traceback
from pathlib import Path
from typing import Callable, TextIO

from rvfem import __version__
from rvfem.app.analysis import analyse_rigid, default_cache_dir, resolve_case
from rvfem.app.cli_hysteresis import HYSTERESIS
from rvfem.app.cli_wear import WEAR
from rvfem.app.cli_study import COMPARE, OPTIMISE, STUDY
from rvfem.app.commands import (
    EXIT_BROKEN_PIPE,
    EXIT_INTERNAL_ERROR,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_USER_ERROR,
    Subcommand,
)
from rvfem.app.run import STAGES, run_case, run_stages, summary_text
from rvfem.app.screen import rigid_text
from rvfem.case.definition import Case, load_case
from rvfem.case.registry import bearing_model_names
from rvfem.errors import FolderNotEmptyError, RvfemError
from rvfem.evaluate.postprocess import feature_label
from rvfem.geometry import disc_geometry
from rvfem.geometry.features import feature_text
from rvfem.mesh import mesh_case
from rvfem.outputs.plots import mesh_preview
from rvfem.outputs.summary import check_output_folder, rigid_summary

__all__ = ["main", "build_parser", "register_subcommand", "all_subcommands", "unregister_subcommand", "Subcommand",
           "SUBCOMMANDS", "EXIT_OK", "EXIT_INTERNAL_ERROR",
           "EXIT_USER_ERROR", "EXIT_INTERRUPTED"]

logger = logging.getLogger(__name__)


# --------------------------------------------------------------------------------------------
# rvfem check CASE
# --------------------------------------------------------------------------------------------


def _add_case_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a case key, e.g. --set fan_holes.ligament=4.0 (repeatable; the value "
                             "is a TOML literal, checked like the file)")


def _load(args: argparse.Namespace) -> Case:
    return load_case(args.case, overrides=tuple(args.set))


def _add_check_arguments(parser: argparse.ArgumentParser) -> None:
    _add_case_argument(parser)


def _log_check(case: Case, args: argparse.Namespace, walls) -> None:
    """What ``rvfem -v check`` adds (INFO): where the case comes from, the reducer it describes and
    how many keys take their default; with ``-vv`` (DEBUG) every default used and every wall."""
    if not logger.isEnabledFor(logging.INFO):
        return
    _, provenance = resolve_case(args.case, overrides=tuple(args.set))
    c, p, k = case.cycloid, case.pins, case.cranks
    logger.info("case file %s, sha256 %s%s", provenance.file, provenance.sha256,
                f", overrides {', '.join(case.overrides)}" if case.overrides else "")
    logger.info("disc of %d teeth on %d pins (pin circle radius %g mm, eccentricity %g mm, %d discs of %g mm), "
                "%d crank bearings at %s° (circle radius %g mm); crank-bearing model '%s'",
                c.teeth, p.count, p.circle_radius, c.eccentricity, case.loads.discs, c.thickness, k.count,
                ", ".join(f"{a:g}" for a in k.angles_deg), k.circle_radius, case.crank_bearing.model)
    logger.info("%d keys take their default (-vv lists them); %d walls between features measured",
                len(provenance.defaults_used), len(walls))
    for key, value in provenance.defaults_used:
        logger.debug("default used: %s = %s", key, value)
    for w in walls:
        logger.debug("wall %.3f mm between %s and %s at (%.2f, %.2f) mm", w.thickness, feature_text(w.first),
                     feature_text(w.second), *w.location)


def _run_check(args: argparse.Namespace) -> int:
    case = _load(args)
    walls = disc_geometry(case).walls   # the geometry checks meshing does first (cheap, no Gmsh)
    _log_check(case, args, walls)
    wall = walls[0]
    given = f" with {', '.join(case.overrides)}" if case.overrides else ""
    print(f"OK: case '{case.name}' ({args.case}){given} is valid; thinnest wall {wall.thickness:.3f} mm "
          f"between {feature_text(wall.first)} and {feature_text(wall.second)}")
    return EXIT_OK


# --------------------------------------------------------------------------------------------
# rvfem rigid CASE [--json]
# --------------------------------------------------------------------------------------------


def _add_rigid_arguments(parser: argparse.ArgumentParser) -> None:
    _add_case_argument(parser)
    parser.add_argument("--json", action="store_true", help="write the results as JSON to stdout "
                        "(non-finite numbers as null)")


def _run_rigid(args: argparse.Namespace) -> int:
    report = rigid_summary(analyse_rigid(_load(args)))
    if args.json:
        print(json.dumps(report, indent=2, allow_nan=False))
        for w in report["warnings"]:     # stdout is the JSON: the warnings for the eye on stderr
            print(f"rvfem rigid: warning: {w['message']}", file=sys.stderr)
    else:
        print(rigid_text(report))
    return EXIT_OK


# --------------------------------------------------------------------------------------------
# rvfem mesh CASE [--cache-dir DIR] [--force]
# --------------------------------------------------------------------------------------------


def _add_mesh_arguments(parser: argparse.ArgumentParser) -> None:
    _add_case_argument(parser)
    parser.add_argument("--cache-dir", default=None,
                        help="directory of cached meshes and previews (default: the repository's meshes/ in a "
                             "source checkout, else the per-user cache, e.g. ~/.cache/rvfem/meshes)")
    parser.add_argument("--force", action="store_true", help="re-mesh even if a cached mesh exists")


def _run_mesh(args: argparse.Namespace) -> int:
    case = _load(args)
    start = time.perf_counter()
    geom = disc_geometry(case)
    cache = default_cache_dir() if args.cache_dir is None else args.cache_dir
    mesh = mesh_case(case, cache, use_cache=not args.force, geometry=geom)
    elapsed = time.perf_counter() - start
    png = mesh_preview(mesh, mesh.path.with_suffix(".png"), title=f"{case.name}: disc mesh")
    thinnest = geom.walls[0]
    print(f"mesh of case '{case.name}' ({args.case}): {mesh.path}"
          f" ({'cached' if mesh.from_cache else 'generated'} in {elapsed:.2f} s)")
    print(f"  {mesh.n_nodes} nodes, {mesh.n_elements} linear triangles, "
          f"min element quality ({mesh.quality_measure}) {mesh.min_quality:.3f}")
    print(f"  mesh cache: {Path(cache).resolve()}" + (" (default)" if args.cache_dir is None else ""))
    print(f"  boundaries: {', '.join(f'{feature_label(n)} ({len(e)} edges)' for n, e in mesh.boundaries.items())}")
    print(f"  thinnest wall {thinnest.thickness:.2f} mm between {feature_text(thinnest.first)} and "
          f"{feature_text(thinnest.second)}")
    print(f"  preview: {png}")
    return EXIT_OK


# --------------------------------------------------------------------------------------------
# rvfem run CASE -o DIR [--step DEG] [--bearing-model M] [--order N] [--overwrite] ...
# --------------------------------------------------------------------------------------------


def _add_run_arguments(parser: argparse.ArgumentParser) -> None:
    _add_case_argument(parser)
    parser.add_argument("-o", "--output", metavar="DIR",
                        help="result folder (default: results/<case name>); must not exist or be empty "
                             "unless --overwrite")
    parser.add_argument("--step", type=float, metavar="DEG", help="crank-angle step in degrees (overrides "
                        "analysis.angle_step_deg)")
    parser.add_argument("--bearing-model", choices=bearing_model_names(),
                        help="crank-bearing model (overrides crank_bearing.model)")
    parser.add_argument("--order", type=int, choices=(1, 2), help="element order (overrides analysis.element_order)")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace an existing result folder (only once the new results are complete)")
    parser.add_argument("--field-step", type=float, metavar="DEG",
                        help="also keep stress fields (VTU frames, images) every DEG degrees; always kept: the "
                             "case's saved angles, the angle of the largest bearing load and the angles of the "
                             "structural and the contact-zone stress peaks")
    parser.add_argument("--no-images", action="store_true", help="skip the PyVista stress images")
    parser.add_argument("--cache-dir", default=None,
                        help="directory of cached meshes (default: the repository's meshes/ in a source checkout, "
                             "else the per-user cache, e.g. ~/.cache/rvfem/meshes)")


class _RunProgress:
    """Progress of ``rvfem run`` on stderr: a tqdm bar for the rigid model (its roller slices), the
    load cycle, the roller slices, the VTK files and the images on a terminal (a status line for the other stages), plain lines
    otherwise (one per stage, and every tenth of a stage that reports its steps).

    Stages are numbered in the order they start, out of the stages the run reports
    (``stages``, :func:`rvfem.app.run.run_stages`; default every stage of :data:`rvfem.app.run.STAGES`)."""

    BAR_STAGES = ("rigid", "cycle", "roller_slices", "vtk", "images")
    UNITS = {"cycle": "angle", "rigid": "step", "roller_slices": "step"}   # else "file"
    QUIET_SECONDS = 1.0   # without a terminal, steps of a stage other than the cycle are told after this

    def __init__(self, stream: TextIO, tty: bool, stages: tuple[str, ...] | None = None):
        self.stream, self.tty = stream, tty
        self.descriptions = STAGES
        self.expected = len(stages if stages is not None else STAGES)
        self.numbers: dict[str, int] = {}   # stage → its number, in the order the stages started
        self.started: dict[str, float] = {}
        self.bar = None
        self.pending = ""  # a status line drawn on a terminal, not yet ended
        self.last_tenth = -1

    def _head(self, stage: str) -> str:
        index = self.numbers.setdefault(stage, len(self.numbers) + 1)
        return f"rvfem run [{index}/{max(self.expected, len(self.numbers))}] {self.descriptions.get(stage, stage)}"

    def __call__(self, stage: str, done: int, total: int) -> None:
        now = time.perf_counter()
        if done == 0:
            self.close()
            self.started[stage] = now
            self.last_tenth = -1
            if self.tty and stage in self.BAR_STAGES and total > 1:
                self._open_bar(stage, total)
            elif self.tty:  # a status line, replaced when the stage ends
                self.pending = f"{self._head(stage)} …"
                self.stream.write(self.pending)
                self.stream.flush()
            elif stage == "cycle":
                self.stream.write(f"{self._head(stage)}: {total} crank angles\n")
            return
        elapsed = now - self.started.get(stage, now)
        if done >= total:
            line = f"{self._head(stage)}: done in {elapsed:.1f} s"
            if self.pending:
                line = "\r" + line.ljust(len(self.pending))
                self.pending = ""
            self.close()
            self.stream.write(line + "\n")
            self.stream.flush()
            return
        if self.bar is None and self.tty and stage in self.BAR_STAGES and total > 1:
            # a stage that knows its number of steps only once it runs: its status line becomes a bar
            if self.pending:
                self.stream.write("\r" + " " * len(self.pending) + "\r")
                self.pending = ""
            self._open_bar(stage, total)
        if self.bar is not None:
            self.bar.update(done - self.bar.n)
        elif not self.tty and (stage == "cycle" or elapsed >= self.QUIET_SECONDS):
            tenth = 10 * done // total
            if tenth > self.last_tenth:
                self.last_tenth = tenth
                if tenth > 0:
                    self.stream.write(f"rvfem run: {stage} {done}/{total} {self.UNITS.get(stage, 'file')}s "
                                      f"({100 * done // total} %), {elapsed:.1f} s\n")
                    self.stream.flush()

    def _open_bar(self, stage: str, total: int) -> None:
        from tqdm import tqdm  # progress bars of the command line only

        self.bar = tqdm(total=total, desc=self._head(stage), file=self.stream, leave=False,
                        unit=self.UNITS.get(stage, "file"), dynamic_ncols=True)

    def close(self) -> None:
        """Remove a bar still drawn and end a status line (at the end of a stage, or before an
        error message)."""
        if self.bar is not None:
            self.bar.close()
            self.bar = None
        if self.pending:
            self.stream.write("\n")
            self.stream.flush()
            self.pending = ""


def _run_run(args: argparse.Namespace) -> int:
    case = _load(args)
    out_dir = Path(args.output) if args.output else Path("results") / case.name
    check_output_folder(out_dir, args.overwrite)   # before the progress display: a refusal is one line

    progress = _RunProgress(sys.stderr, sys.stderr.isatty(), run_stages(case, images=not args.no_images))
    if _notices is not None:
        _notices.before = progress.close    # a note ends a status line or a bar first
    try:
        result = run_case(case, out_dir, angle_step_deg=args.step, bearing_model=args.bearing_model,
                          order=args.order, overwrite=args.overwrite, progress=progress,
                          cache_dir=args.cache_dir, images=not args.no_images, field_step_deg=args.field_step)
    finally:
        progress.close()
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


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line on stderr, like every other error of
    rvfem: ``rvfem: error: MESSAGE (see rvfem COMMAND --help)``, exit code 2. (Sub-parsers are of
    the same class: argparse makes them of the main parser's.)"""

    #: The parser of each subcommand, by name (set on the main parser by :func:`build_parser`).
    subcommand_parsers: dict[str, argparse.ArgumentParser]

    def error(self, message: str):  # noqa: D102 - argparse's hook
        self.exit(EXIT_USER_ERROR, f"rvfem: error: {message} (see {self.prog} --help)\n")

    def parse_args(self, args=None, namespace=None):  # noqa: D102
        # argparse gives arguments a sub-parser does not know back to the main parser: blame the
        # subcommand's, whose --help lists the arguments it takes
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            parser = getattr(self, "subcommand_parsers", {}).get(getattr(parsed, "command", None), self)
            parser.error(f"unrecognized arguments: {' '.join(extras)}")
        return parsed


def build_parser(subcommands: tuple[Subcommand, ...] | None = None) -> argparse.ArgumentParser:
    """The argument parser with one sub-parser per entry of ``subcommands`` (default
    :func:`all_subcommands`: rvfem's own and those registered)."""
    if subcommands is None:
        subcommands = all_subcommands()
    parser = _Parser(
        prog="rvfem",
        description="Crank-bearing loads of RV reducers with a flexible cycloid disc.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="more log output on stderr (-v info, -vv debug); also after the subcommand")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    parser.subcommand_parsers = {}
    for command in subcommands:
        p = sub.add_parser(command.name, help=command.help, description=command.help)
        parser.subcommand_parsers[command.name] = p
        command.add_arguments(p)
        # -v after the subcommand too (its own dest: a subparser's value would replace the main one's)
        p.add_argument("-v", "--verbose", action="count", default=0, dest="verbose_after",
                       help="more log output on stderr (-v info, -vv debug)")
        p.set_defaults(run=command.run)
    return parser


class _Notices(logging.Handler):
    """Shows the library's notices (INFO records logged with ``extra=rvfem.NOTICE``) without
    ``-v``: one line ``rvfem COMMAND: note: …`` on stderr each, a message once.

    Attributes
    ----------
    before : callable or None
        Called before a note is written (``rvfem run`` ends its progress status line or bar).
    """

    def __init__(self, command: str, stream: TextIO):
        super().__init__(logging.INFO)
        self.command, self.stream = command, stream
        self.seen: set[str] = set()
        self.before: Callable[[], None] | None = None
        self.addFilter(lambda record: getattr(record, "notice", False))

    def emit(self, record: logging.LogRecord) -> None:
        try:
            message = record.getMessage()
            if message in self.seen:
                return
            self.seen.add(message)
            if self.before is not None:
                self.before()
            self.stream.write(f"rvfem {self.command}: note: {message}\n")
            self.stream.flush()
        except Exception:  # pragma: no cover - logging must not raise
            self.handleError(record)


#: The notice handler of the running command (None with -v: the log lines show the notices).
_notices: _Notices | None = None


def _setup_logging(verbosity: int, command: str = "") -> Callable[[], None]:
    """Log to stderr at WARNING (INFO with -v, DEBUG with -vv); without -v the notices of rvfem
    (:class:`_Notices`) are shown as well. Returns the function that removes the notice handler."""
    global _notices
    level = logging.WARNING if verbosity <= 0 else logging.INFO if verbosity == 1 else logging.DEBUG
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s", stream=sys.stderr, force=True)
    for handler in logging.getLogger().handlers:
        handler.setLevel(level)     # rvfem's logger may pass INFO records (the notices) below
    if verbosity > 0:
        return lambda: None
    package = logging.getLogger("rvfem")          # the whole package's loggers
    previous = package.level
    _notices = _Notices(command, sys.stderr)
    package.addHandler(_notices)
    package.setLevel(logging.INFO)

    def remove(handler: _Notices = _notices) -> None:
        global _notices
        package.removeHandler(handler)
        package.setLevel(previous)
        _notices = None

    return remove


def _write_crash_log(command: str, argv: list[str] | None) -> str:
    """Write the current exception's traceback to a log file in the temporary folder; its path."""
    text = (f"rvfem {__version__} {command}\nargv: {argv if argv is not None else sys.argv[1:]}\n"
            f"python {sys.version.split()[0]} on {sys.platform}\n\n{traceback.format_exc()}")
    try:
        fd, path = tempfile.mkstemp(prefix="rvfem-error-", suffix=".log")
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        return path
    except OSError:
        return "(no log file: the temporary folder is not writable)"


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (0 ok, 1 internal error, 2 user error,
    130 interrupted, 141 output pipe closed early)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, usage errors (argparse exits with 2)
        return exc.code if isinstance(exc.code, int) else (EXIT_OK if exc.code is None else EXIT_USER_ERROR)
    args.verbose += getattr(args, "verbose_after", 0)
    remove_notices = _setup_logging(args.verbose, args.command)
    try:
        return args.run(args)
    except FolderNotEmptyError as exc:  # the command line's words: the option, not the keyword argument
        print(f"rvfem {args.command}: error: {exc.folder} exists and is not empty; choose another output folder "
              "(-o DIR) or pass --overwrite to replace it", file=sys.stderr)
        return EXIT_USER_ERROR
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
    except Exception as exc:  # a bug: one line, the traceback in a log file
        log_path = _write_crash_log(args.command, argv)
        if args.verbose >= 2:
            traceback.print_exc(file=sys.stderr)
        reason = " ".join(str(exc).split())
        print(f"rvfem {args.command}: internal error ({type(exc).__name__}{': ' + reason if reason else ''}); "
              f"this is a bug in rvfem, please report it with the log file {log_path}", file=sys.stderr)
        return EXIT_INTERNAL_ERROR
    finally:
        remove_notices()


SUBCOMMANDS = (*SUBCOMMANDS, COMPARE, STUDY, OPTIMISE, HYSTERESIS, WEAR)

_ADDED: dict[str, Subcommand] = {}
"""Subcommands added with :func:`register_subcommand` (a test fixture saves and restores it)."""


def register_subcommand(command: Subcommand) -> Subcommand:
    """Add a subcommand from outside the package (after rvfem's own, in ``rvfem --help``); returns
    it. A name taken raises ValueError."""
    if any(s.name == command.name for s in all_subcommands()):
        raise ValueError(f"an rvfem subcommand named {command.name!r} exists already")
    _ADDED[command.name] = command
    return command


def unregister_subcommand(name: str) -> None:
    """Remove a subcommand added with :func:`register_subcommand` (rvfem's own stay)."""
    _ADDED.pop(name, None)


def all_subcommands() -> tuple[Subcommand, ...]:
    """Every subcommand: rvfem's own (:data:`SUBCOMMANDS`), then those registered."""
    return (*SUBCOMMANDS, *_ADDED.values())


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
