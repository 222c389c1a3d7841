"""`rvfem run` (or another command writing a result folder) of two source trees side by side:
whole-process wall time, alternating A and B, the median of each and B/A.

Each run is a fresh ``python -m rvfem run CASE`` process with ``PYTHONPATH`` set to the tree, so the
two versions run under the same load; the mesh cache is shared (both read the same meshes). Prints
every run, the medians and the ratio, and each stage's median from ``summary.json``'s
``timings_s``::

    python benchmarks/bench_side_by_side.py OLD_TREE NEW_TREE [--case cases/rv40e_fanholes.toml]
        [--repeat 5] [--no-images] [--command hysteresis --extra "--te"]

A tree is a checkout of rvfem (e.g. ``git worktree add /path/old COMMIT``).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _run(tree: Path, case: Path, out: Path, cache: Path, images: bool, command: str = "run",
         extra: tuple[str, ...] = ()) -> tuple[float, dict]:
    env = {**os.environ, "PYTHONPATH": str(tree)}
    argv = [sys.executable, "-m", "rvfem", command, str(case), "-o", str(out), "--overwrite", "--cache-dir", str(cache),
            *extra]
    if not images:
        argv.append("--no-images")
    t0 = time.perf_counter()
    subprocess.run(argv, env=env, cwd=tree, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    return wall, summary.get("timings_s") or summary.get("timings") or {}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--case", type=Path, default=Path("cases/rv40e_fanholes.toml"))
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--no-images", action="store_true", help="rvfem run only")
    parser.add_argument("--command", default="run", help="the rvfem command (default run)")
    parser.add_argument("--extra", default="", help="further arguments of the command, in one string")
    args = parser.parse_args(argv)
    extra = tuple(args.extra.split())
    case = args.case.resolve()
    walls: dict[str, list[float]] = {"old": [], "new": []}
    stages: dict[str, dict[str, list[float]]] = {"old": {}, "new": {}}
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp) / "meshes"
        for name, tree in (("old", args.old), ("new", args.new)):      # warm the mesh cache, not timed
            _run(tree.resolve(), case, Path(tmp) / name, cache, not args.no_images, args.command, extra)
        for i in range(args.repeat):
            for name, tree in (("old", args.old), ("new", args.new)):
                wall, timings = _run(tree.resolve(), case, Path(tmp) / name, cache, not args.no_images, args.command,
                                     extra)
                walls[name].append(wall)
                for k, v in timings.items():
                    stages[name].setdefault(k, []).append(float(v))
                print(f"run {i + 1} {name}: {wall:.2f} s", flush=True)
    old, new = statistics.median(walls["old"]), statistics.median(walls["new"])
    print(f"median wall time: old {old:.2f} s, new {new:.2f} s, new/old {new / old:.3f}")
    for k in sorted(set(stages["old"]) | set(stages["new"])):
        a = statistics.median(stages["old"].get(k, [float("nan")]))
        b = statistics.median(stages["new"].get(k, [float("nan")]))
        print(f"  {k:<24} old {a:7.2f} s  new {b:7.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
