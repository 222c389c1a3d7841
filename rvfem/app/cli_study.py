"""Command line of the comparative work: ``rvfem compare`` and ``rvfem study``.

Two :class:`rvfem.app.cli.Subcommand` objects, :data:`COMPARE` and :data:`STUDY`, for
:data:`rvfem.app.cli.SUBCOMMANDS`. Like the rest of the command line, only these functions print;
errors are :class:`~rvfem.errors.RvfemError` raised by the library and turned into one line and
exit code 2 by :func:`rvfem.app.cli.main`.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import sys
import tempfile
from pathlib import Path

from rvfem.app.commands import EXIT_OK, Subcommand
from rvfem.app.optimise import load_problem, run_optimisation
from rvfem.app.result_compare import (
    STATISTICS,
    ResultFolder,
    compare_results,
    comparison_html,
    comparison_plot,
    headline,
    overall_titles,
    read_result,
    result_from_case,
)
from rvfem.app.study import MAX_ID_LENGTH, load_study, run_study, short_id
from rvfem.case.definition import Case, load_case
from rvfem.errors import CaseError
from rvfem.outputs.summary import check_output_folder, prepare_output_folder

__all__ = ["COMPARE", "STUDY"]


# --------------------------------------------------------------------------------------------
# rvfem compare A B [-o DIR] [--json] [--set KEY=VALUE ...]
# --------------------------------------------------------------------------------------------


def _add_set_argument(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help=f"override a case key {what} (dotted key of the case format, TOML value), "
                             "e.g. --set analysis.angle_step_deg=2; repeatable")


def _add_compare_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("a", metavar="A", help="result folder of rvfem run, or a case file (run into a "
                        "temporary folder)")
    parser.add_argument("b", metavar="B", help="the other result folder or case file; ratios are B / A")
    parser.add_argument("-o", "--output", metavar="DIR", help="write the overlaid load curves (compare.png) and "
                        "a self-contained page (compare.html) into DIR (new, empty, or a folder rvfem wrote)")
    parser.add_argument("--json", action="store_true", help="write the comparison as JSON to stdout")
    _add_set_argument(parser, "of A and B where they are case files")
    parser.add_argument("--cache-dir", default="meshes", help="directory of cached meshes (default: meshes)")


def _is_case_file(path: str) -> bool:
    p = Path(path)
    return p.is_file() or p.suffix == ".toml"


_SMALL_KEYS = ("disc_mass_kg", "static_safety_factor", "fatigue_safety_factor")
"""Whole-disc quantities shown with four significant figures (not one decimal)."""


def _format_compare(c: dict, out) -> None:
    w = out.write
    w(f"A: {c['a']['label']} ({c['a']['path']})\n")
    w(f"B: {c['b']['label']} ({c['b']['path']})\n")
    w(f"models: bearings {c['a']['bearing_model']} / {c['b']['bearing_model']}, pins {c['a']['pin_model']} / "
      f"{c['b']['pin_model']}, P{c['a']['element_order']} / P{c['b']['element_order']}, step "
      f"{c['a']['angle_step_deg']:g}° / {c['b']['angle_step_deg']:g}°\n\n")
    title = headline(c)
    if title:
        w(title + "\n\n")
    head = f"{'bearing':>7} " + " ".join(f"{t + ' A':>10} {t + ' B':>10} {'B/A':>7}" for _, t in STATISTICS)
    w(head + "\n" + "-" * len(head) + "\n")
    for row in c["bearings"]:
        cells = []
        for key, _ in STATISTICS:
            r = row["ratio"][key]
            cells.append(f"{row['a'][key]:10.1f} {row['b'][key]:10.1f} {'–' if r is None else format(r, '7.4f'):>7}")
        w(f"{row['bearing']:>7d} " + " ".join(cells) + "\n")
    o = c["overall"]
    titles = overall_titles(c)
    width = max(len(t) for t in titles.values())
    w(f"\n{'whole disc':<{width}} {'A':>10} {'B':>10} {'B/A':>8}\n")
    for key, title in titles.items():
        a, b, r = o["a"].get(key), o["b"].get(key), o["ratio"].get(key)
        fmt = (lambda v, k=key: "–" if v is None else f"{v:10.4g}" if k in _SMALL_KEYS else f"{v:10.1f}")
        w(f"{title:<{width}} {fmt(a):>10} {fmt(b):>10} {'–' if r is None else format(r, '8.4f'):>8}\n")
    # the ratios in words are the headline above the tables, said once
    for warning in c["warnings"]:
        w(f"note: {warning}\n")


def _run_compare(args: argparse.Namespace) -> int:
    if args.overrides and not (_is_case_file(args.a) or _is_case_file(args.b)):
        raise CaseError("--set applies to case files; A and B are result folders")

    if args.output:   # before running anything: rvfem writes only into a folder that is new, empty or its own
        check_output_folder(args.output, overwrite=True)
    inputs: list[tuple[str, Case | ResultFolder]] = []  # validate both before running either
    for given in (args.a, args.b):
        if _is_case_file(given) and not Path(given).is_dir():
            inputs.append((given, load_case(given, args.overrides)))
        else:
            inputs.append((given, read_result(given)))
    with tempfile.TemporaryDirectory(prefix="rvfem-compare-") as tmp:
        results: list[ResultFolder] = []
        for tag, (given, item) in zip("AB", inputs):
            if isinstance(item, ResultFolder):
                results.append(item)
            else:
                print(f"rvfem compare: running {given} ({tag}) …", file=sys.stderr)
                results.append(result_from_case(item, Path(tmp) / tag, cache_dir=args.cache_dir))
        a, b = results
        comparison = compare_results(a, b)
        if args.output:
            out = prepare_output_folder(args.output, "compare")
            plot = comparison_plot(a, b, out / "compare.png")
            page = comparison_html(comparison, plot, out / "compare.html")
            comparison["files"] = {"plot": str(plot), "html": str(page)}
    if args.json:
        json.dump(comparison, sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    else:
        _format_compare(comparison, sys.stdout)
        if args.output:
            print(f"  plot: {comparison['files']['plot']}; page: {comparison['files']['html']}")
    return EXIT_OK


# --------------------------------------------------------------------------------------------
# rvfem study STUDY.toml [-o DIR] [--scheduler tcp://HOST:PORT] [--workers N] [--set KEY=VALUE ...]
# --------------------------------------------------------------------------------------------


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected at least 1, got {value}")
    return value


def _add_cluster_arguments(parser: argparse.ArgumentParser) -> None:
    """``--scheduler`` and ``--workers``: where a study's or an optimisation's designs run."""
    parser.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                        help="address of a running Dask scheduler (default: a local cluster)")
    parser.add_argument("--workers", type=_positive_int, metavar="N",
                        help="workers of the local cluster (default: one per core)")


def _add_study_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("study", help="study file (TOML; see docs/studies.md)")
    parser.add_argument("-o", "--output", metavar="DIR", help="study folder (default: results/<study name>); "
                        "a rerun into the same folder skips the variants already done")
    _add_cluster_arguments(parser)
    _add_set_argument(parser, "of the base case and every variant")
    parser.add_argument("--cache-dir", default="meshes", help="mesh cache shared by the workers (default: meshes)")
    parser.add_argument("--check", action="store_true", help="validate the study and list its variants; run nothing")
    parser.add_argument("--no-plots", action="store_true", help="no plots (study.csv and the report only)")


def _id_width(ids) -> int:
    """Width of the id column: the longest id, up to :data:`rvfem.app.study.MAX_ID_LENGTH`."""

    return max(7, min(MAX_ID_LENGTH, max((len(i) for i in ids), default=0)))


def _print_variants(study) -> None:
    print(f"study '{study.name}' ({study.kind}) on {study.base_case}: {len(study.variants)} variants")
    width = _id_width(v.id for v in study.variants)
    for v in study.variants:
        own = ", ".join(f"{k} = {val!r}" for k, val in v.settings) or "(the base case)"
        print(f"  {short_id(v.id, width):<{width}}  {own}")


def _format_rows(rows) -> None:
    def f(v, spec):
        return "–" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)

    width = _id_width(r["id"] for r in rows)
    head = (f"{'variant':<{width}} {'status':<8} {'max N':>8} {'vs hb':>7} {'vs base':>8} {'F_m N':>8} "
            f"{'life/hb':>7} {'life/base':>9} {'s_vm MPa':>8} {'time s':>7}")
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{short_id(r['id'], width):<{width}} {r['status']:<8} {f(r['max_load_N'], '8.1f')} "
              f"{f(r['max_vs_handbook_percent'], '+6.1f')}% {f(r['max_vs_base_percent'], '+7.1f')}% "
              f"{f(r['equivalent_load_N'], '8.1f')} {f(r['life_ratio'], '7.3f')} {f(r['life_ratio_vs_base'], '9.3f')} "
              f"{f(r['peak_von_mises_MPa'], '8.1f')} {f(r['wall_time_s'], '7.1f')}"
              + ("" if r["computed"] or r["status"] != "ok" else "  (earlier run)"))
        if r["error"]:
            print(f"{'':<{width}} {r['error']}")
    print("s_vm: structural stress peak away from contacts, von Mises (the value rvfem run reports: P2 re-solve "
          "by default); time: the variant's run time")


class _StudyProgress:
    """A tqdm bar over the variants on a terminal, one line per variant otherwise."""

    def __init__(self, stream):
        self.stream, self.bar = stream, None
        self.tty = stream.isatty()

    def __call__(self, done: int, total: int, record: dict) -> None:
        if self.tty:
            if self.bar is None:
                from tqdm import tqdm  # progress bars of the command line only

                self.bar = tqdm(total=total, initial=done - 1, unit="variant", file=self.stream, desc="rvfem study")
            self.bar.set_postfix_str(f"{short_id(record['id'], 40)}: {record['status']}")
            self.bar.update(1)
        else:
            wall = record.get("wall_time_s")
            wall_text = "" if wall is None or math.isnan(wall) else f" in {wall:.1f} s"
            self.stream.write(f"rvfem study: {done}/{total} {record['id']}: {record['status']}{wall_text}"
                              + (f" ({record['error']})" if record["error"] else "") + "\n")
            self.stream.flush()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _run_study(args: argparse.Namespace) -> int:
    study = load_study(args.study, extra_overrides=args.overrides)
    # Dask configures its loggers at INFO; follow rvfem's verbosity (-v, -vv) instead. The errors
    # tornado (Dask's event loop) logs are Dask's internals, e.g. a callback cut short by Ctrl-C; a
    # failing variant is recorded by the study itself: shown with -vv only
    logging.getLogger("distributed").setLevel(max(logging.getLogger().getEffectiveLevel(), logging.DEBUG))
    if args.verbose < 2:
        logging.getLogger("tornado").setLevel(logging.CRITICAL)
    if args.check:
        _print_variants(study)
        return EXIT_OK
    out_dir = Path(args.output) if args.output else Path("results") / study.name
    where = f"scheduler {args.scheduler}" if args.scheduler else \
        f"a local cluster of {args.workers or 'one worker per core'}{' workers' if args.workers else ''}"
    print(f"rvfem study: {len(study.variants)} variants of '{study.name}' on {where} into {out_dir}/",
          file=sys.stderr)
    progress = _StudyProgress(sys.stderr)
    try:
        result = run_study(study, out_dir, scheduler=args.scheduler, workers=args.workers, cache_dir=args.cache_dir,
                           progress=progress, plots=not args.no_plots)
    finally:
        progress.close()
    _format_rows(result.rows)
    print(f"\n{len(result.rows)} variants: {result.computed} computed, {result.reused} from an earlier run, "
          f"{result.failed} failed; compute time of the variants {result.compute_time_s:.1f} s (earlier runs "
          f"included), wall time {result.wall_time_s:.1f} s")
    print(f"  results: {result.out_dir}/ (study.csv, report.html, variants/<id>/; see docs/studies.md)")
    return EXIT_OK


COMPARE = Subcommand("compare", "compare two results (folders or case files): loads, lives, stresses and "
                     "their ratios B / A, overlaid load curves", _add_compare_arguments, _run_compare)
STUDY = Subcommand("study", "run a design study (grid, sensitivity or list of variants) on Dask distributed",
                   _add_study_arguments, _run_study)


# --------------------------------------------------------------------------------------------
# rvfem optimise FILE.toml [-o DIR] [--scheduler tcp://HOST:PORT] [--workers N] [--trials N]
# --------------------------------------------------------------------------------------------


def _add_optimise_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("problem", help="optimisation file (TOML; see docs/studies.md, \"Optimisation\")")
    parser.add_argument("-o", "--output", metavar="DIR", help="folder (default: results/<name>); a rerun into "
                        "the same folder takes the designs already in its trials.csv from there")
    _add_cluster_arguments(parser)
    parser.add_argument("--trials", type=_positive_int, metavar="N", help="designs to evaluate (default: the file's)")
    _add_set_argument(parser, "of the base case and every design")
    parser.add_argument("--cache-dir", default="meshes", help="mesh cache shared by the workers (default: meshes)")
    parser.add_argument("--no-plots", action="store_true", help="no Pareto plot")


def _optimise_progress(done: int, total: int, row: dict) -> None:
    wall = row.get("wall_time_s")
    obj = row.get("objective")
    sys.stderr.write(f"rvfem optimise: {done}/{total} {row['id']}: {row['status']}"
                     f"{'' if obj is None else f', objective {obj:.6g}'}{', feasible' if row['feasible'] else ''}"
                     f"{'' if not row['computed'] else '' if wall is None or math.isnan(wall) else f' in {wall:.1f} s'}"
                     f"{'' if row['computed'] else ' (earlier run)'}" + (f" ({row['error']})" if row["error"] else "") + "\n")
    sys.stderr.flush()


def _run_optimise(args: argparse.Namespace) -> int:
    problem = load_problem(args.problem, extra_overrides=args.overrides, trials=args.trials)
    logging.getLogger("distributed").setLevel(max(logging.getLogger().getEffectiveLevel(), logging.DEBUG))
    if args.verbose < 2:
        logging.getLogger("tornado").setLevel(logging.CRITICAL)
    out_dir = Path(args.output) if args.output else Path("results") / problem.name
    print(f"rvfem optimise: {problem.trials} designs of '{problem.name}' (minimise {problem.objective}) into "
          f"{out_dir}/", file=sys.stderr)
    r = run_optimisation(problem, out_dir, scheduler=args.scheduler, workers=args.workers, cache_dir=args.cache_dir,
                         progress=_optimise_progress, plots=not args.no_plots)
    feasible = sum(1 for row in r.rows if row["feasible"])
    print(f"{len(r.rows)} designs: {r.computed} computed, {feasible} feasible; wall time {r.wall_time_s:.1f} s")
    keys = [p.key for p in problem.parameters]
    for title, row in (("base", r.base), ("best", r.best)):
        if row is not None:
            print(f"  {title}: {problem.objective} = {row['objective']:.6g}; " + ", ".join(
                f"{k} = {row[k]:g}" for k in keys if row.get(k) is not None) + ("; " if keys and row.get(keys[0]) is not None else "")
                + ", ".join(f"{n} {row.get(n):.4g}" for n in ("max_load_delta_percent", "life_ratio",
                                                               "fatigue_safety_factor") if row.get(n) is not None))
    if r.best is None:
        print("  no design met every budget")
    print(f"  results: {r.out_dir}/ (trials.csv, best.toml, pareto.png, report.html)")
    return EXIT_OK


OPTIMISE = Subcommand("optimise", "minimise the disc mass (or inertia) over the hole parameters within budgets "
                      "of load, life and safety, on Dask distributed", _add_optimise_arguments, _run_optimise)
