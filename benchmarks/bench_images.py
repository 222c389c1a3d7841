"""Benchmark: wall time of the image set of ``rvfem run`` (:func:`rvfem.outputs.summary.write_images`).

Analyses the case once (``cases/rv40e_fanholes.toml`` at its default mesh, or the case given)
with :func:`rvfem.app.analysis.analyse`, checks off-screen rendering once (as ``rvfem run`` does in its
"check" stage, before the clock), then writes the image set into a fresh folder ``--repeat`` times
and reports

- the wall time of the whole image set, best of the repeats (and every repeat), with the CPU
  time of the process in all its threads (less sensitive to other load on the machine than the
  wall time);
- the time of each image, from the writer's progress callback (the time between one finished
  image and the next; the last image is timed to the writer's return), from the best repeat
  (where images are drawn concurrently, e.g. the mesh picture beside the stress images, this is
  when each is handed over, not its own cost);
- the own time of each image's drawing call and of its PNG writing (where a background thread
  writes it), and the size of every PNG.

The first repeat pays the imports (PyVista, VTK, matplotlib) and the first OpenGL context, as a
real run does; ``--warm`` renders the set once untimed beforehand to see the steady state.

``--worker`` times the set as ``rvfem run`` draws it: by a :class:`rvfem.outputs.render.RenderWorker`
(a child process, started, checked and warmed up before the clock, as during a run's analysis),
the stress images, the mesh picture and the plots; the CPU time then includes the child's whole
life (its start and warm-up too), and the own times of the calls (made in the child) are not
recorded. One difference: ``rvfem run`` has the mesh picture drawn during its load cycle
(:func:`rvfem.outputs.summary.start_mesh_picture`), here it is submitted with the images.

Run from the repository root::

    python benchmarks/bench_images.py
    python benchmarks/bench_images.py --repeat 5 --json results/bench_images.json
    python benchmarks/bench_images.py --keep images_bench   # keep the PNGs of the best repeat
    python benchmarks/bench_images.py --worker              # as rvfem run: in a child process

The machine should be otherwise idle: the load average before and after is printed.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _cpu_s() -> float:
    """CPU time of this process and its ended child processes so far, all threads (user +
    system), s."""
    return sum(u.ru_utime + u.ru_stime for u in (resource.getrusage(resource.RUSAGE_SELF),
                                                  resource.getrusage(resource.RUSAGE_CHILDREN)))


@contextlib.contextmanager
def _timed_calls():
    """Time the calls that draw or write one image, by file name: ``{"draw": {...}, "png": {...}}``.

    "draw" is the stress image's own call (:meth:`rvfem.outputs.render.StressRenderer.write`, which
    hands its PNG to a background writer, or :func:`rvfem.outputs.render.stress_image` of earlier
    versions, which writes it) and the mesh picture (:func:`rvfem.outputs.plots.mesh_plot`, in its own
    thread); "png" is the background PNG writer.
    """
    from rvfem.outputs import plots
    from rvfem.outputs import render

    times: dict[str, dict[str, float]] = {"draw": {}, "png": {}}
    targets = [(plots, "mesh_plot", 0, "draw"), (render, "_write_png", 0, "png")]
    if hasattr(render, "StressRenderer"):
        targets.append((render.StressRenderer, "write", 1, "draw"))
    else:
        targets.append((render, "stress_image", 0, "draw"))
    saved = []
    for owner, name, path_arg, kind in targets:
        original = getattr(owner, name, None)
        if original is None:
            continue

        def timed(*args, _original=original, _i=path_arg, _kind=kind, **kwargs):
            t = time.perf_counter()
            try:
                return _original(*args, **kwargs)
            finally:
                times[_kind][Path(args[_i]).name] = time.perf_counter() - t

        saved.append((owner, name, original))
        setattr(owner, name, timed)
    try:
        yield times
    finally:
        for owner, name, original in saved:
            setattr(owner, name, original)


def _one_set(analysis, folder: Path, worker: bool = False, lead_s: float = 3.0) -> dict:
    from rvfem.outputs import summary as outputs
    from rvfem.outputs import render

    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    marks: list[float] = []
    if worker:   # started, checked and warmed up before the clock, as during a run's analysis
        started = render.RenderWorker(outputs.IMAGE_SIZE)
        started.check()
        time.sleep(lead_s)
    # the calls made in the child are pickled by name: not timed (wrapped) in worker mode
    with (contextlib.nullcontext({"draw": {}, "png": {}}) if worker else _timed_calls()) as own:
        c0, t0 = _cpu_s(), time.perf_counter()
        if worker:
            pending = outputs.submit_images(analysis, folder, started, calls=outputs.plot_calls(analysis, folder))
            plotted = pending.calls_result()
            written = pending.result(tick=lambda done, total: marks.append(time.perf_counter()))
            t_end = time.perf_counter()
            started.close()   # the child's CPU time counts once it has ended (its whole life)
            written += plotted
        else:
            written = outputs.write_images(analysis, folder,
                                           tick=lambda done, total: marks.append(time.perf_counter()))
            t_end = time.perf_counter()
        c_end = _cpu_s()
    ends = marks + [t_end]
    starts = [t0] + marks
    names = [p.name for p in written]
    per_image = {}
    if len(ends) == len(names):
        per_image = {n: e - s for n, s, e in zip(names, starts, ends)}
    return {"wall_s": t_end - t0, "cpu_s": c_end - c0, "per_image_s": per_image, "draw_s": own["draw"],
            "png_s": own["png"], "bytes": {p.name: p.stat().st_size for p in written}}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "rv40e_fanholes.toml"),
                        help="case file (default cases/rv40e_fanholes.toml)")
    parser.add_argument("--repeat", type=int, default=3, help="image sets to time; the best counts (default 3)")
    parser.add_argument("--warm", action="store_true", help="write one untimed image set first")
    parser.add_argument("--keep", type=Path, help="copy the images of the best repeat into this folder")
    parser.add_argument("--json", type=Path, help="also write the figures to this JSON file")
    parser.add_argument("--worker", action="store_true",
                        help="draw the images (and the plots) in a render worker, as rvfem run does")
    parser.add_argument("--lead", type=float, default=3.0,
                        help="with --worker: seconds between starting the worker and the images (default 3)")
    args = parser.parse_args(argv)

    from rvfem.app.analysis import analyse
    from rvfem.outputs.render import check_rendering

    load_before = os.getloadavg()
    t = time.perf_counter()
    analysis = analyse(args.case)
    t_analyse = time.perf_counter() - t
    window = check_rendering()
    print(f"case {analysis.case.name}: {len(analysis.stress.snapshots)} kept fields, "
          f"{analysis.mesh.n_nodes} vertices, {analysis.mesh.n_elements} triangles "
          f"(analysis {t_analyse:.1f} s, not timed); render window {window}; {os.cpu_count()} cores")

    runs = []
    with tempfile.TemporaryDirectory(prefix="bench_images_") as tmp:
        if args.warm:
            _one_set(analysis, Path(tmp) / "warm", args.worker, args.lead)
        for i in range(args.repeat):
            run = _one_set(analysis, Path(tmp) / f"run{i}", args.worker, args.lead)
            runs.append(run)
            first = " (first in the process: imports, OpenGL context)" if i == 0 and not args.warm else ""
            print(f"  repeat {i + 1}: {run['wall_s']:.2f} s wall, {run['cpu_s']:.2f} s CPU{first}")
        best_i = min(range(len(runs)), key=lambda i: runs[i]["wall_s"])
        best = runs[best_i]
        if args.keep:
            if args.keep.exists():
                shutil.rmtree(args.keep)
            shutil.copytree(Path(tmp) / f"run{best_i}" / "images", args.keep)

    print(f"\nimage set, best of {len(runs)}: {best['wall_s']:.2f} s wall ({best['cpu_s']:.2f} s CPU)")
    width = max(len(n) for n in best["bytes"])

    def sec(table: str, name: str) -> str:
        value = best[table].get(name)
        return f"{'–' if value is None else f'{value:.2f}':>7}"

    print(f"  {'':<{width}}  {'handed over':>11}  {'draw':>7}  {'PNG':>7}  {'size':>8}")
    for name, size in best["bytes"].items():
        print(f"  {name:<{width}}  {sec('per_image_s', name):>11}  {sec('draw_s', name)}  {sec('png_s', name)}  "
              f"{size / 1024:4.0f} KiB")
    print("  (handed over: from the previous image to this one in the writer's progress; draw: the image's own\n"
          "   call; PNG: encoding and writing in the background writer, where there is one)")
    load_after = os.getloadavg()
    print(f"\nload average before {load_before[0]:.2f}, after {load_after[0]:.2f}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"case": analysis.case.name, "cores": os.cpu_count(),
                                         "render_window": window, "runs": runs, "best": best},
                                        indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
