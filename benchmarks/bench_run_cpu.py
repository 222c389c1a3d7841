"""Where a command's processor time goes, process by process, and how busy the cores are.

Runs one rvfem command (default ``rvfem run`` of the default case into a temporary folder) and
samples, every ``--interval`` seconds, the processor time (user + system, from ``/proc``) of the
command's process and of every process it starts (the P2 model's child, the render worker, a TE
child). Prints

* the wall time and the processor time of each process and of all together,
* the mean number of busy cores (processor time / wall time) against the cores this machine has,
* how the wall time divides by the number of busy cores (idle, under one, under two, ...),

and with ``--timeline`` the samples themselves (per cent of one core per process). A command whose
processes keep every core busy cannot get faster by overlapping its stages any better, only by
doing less work: its wall time is at least its processor time divided by the cores.

Linux only (``/proc``). Run from the repository root:
``python benchmarks/bench_run_cpu.py [--repeat 3] [--timeline] [-- ARGS OF rvfem]``, e.g.
``python benchmarks/bench_run_cpu.py -- hysteresis cases/rv40e_fanholes.toml -o /tmp/h --overwrite --te``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")


def _stat_fields(pid: int) -> list[str] | None:
    """The fields of /proc/PID/stat after the command name (None if the process is gone)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as f:
            return f.read().rpartition(")")[2].split()
    except OSError:
        return None


def process_tree(root: int) -> list[int]:
    """``root`` and every process descended from it."""
    children: dict[int, list[int]] = {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            fields = _stat_fields(int(name))
            if fields is not None:
                children.setdefault(int(fields[1]), []).append(int(name))
    found, todo = [], [root]
    while todo:
        pid = todo.pop()
        found.append(pid)
        todo += children.get(pid, [])
    return found


def cpu_seconds(pid: int) -> float | None:
    """User + system processor time of a process so far, s (None if it is gone)."""
    fields = _stat_fields(pid)
    return None if fields is None else (int(fields[11]) + int(fields[12])) / CLOCK_TICKS


def _label(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            words = f.read().split(b"\0")
    except OSError:
        return "?"
    words = [w.decode(errors="replace") for w in words if w]
    if len(words) >= 3 and words[1] == "-c":     # a child of rvfem._child: python -c PROGRAM NAME
        return f"child process '{' '.join(words[3:])}'"
    text = " ".join(words)
    return text if len(text) <= 70 else text[:67] + "..."


def measure(argv: list[str], interval: float) -> dict:
    """Run ``argv`` and sample the processor time of its process tree every ``interval`` s."""
    start = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    last: dict[int, float] = {}
    labels: dict[int, str] = {}
    samples: list[tuple[float, dict[int, float]]] = []
    while proc.poll() is None:
        now = time.perf_counter() - start
        used = {}
        for pid in process_tree(proc.pid):
            c = cpu_seconds(pid)
            if c is None:
                continue
            labels.setdefault(pid, _label(pid))
            used[pid] = c - last.get(pid, 0.0)
            last[pid] = c
        samples.append((now, used))
        time.sleep(interval)
    wall = time.perf_counter() - start
    _, stderr = proc.communicate()
    if proc.returncode != 0:
        raise SystemExit(f"the command failed (exit {proc.returncode}): {stderr.decode(errors='replace')[-2000:]}")
    return {"wall": wall, "cpu": dict(last), "labels": labels, "samples": samples}


def busy_histogram(samples: list[tuple[float, dict[int, float]]], cores: int) -> list[float]:
    """Wall time (s) with about 0, 1, ..., ``cores`` cores busy (the sample's total rounded)."""
    spent = [0.0] * (cores + 1)
    previous = 0.0
    for t, used in samples[1:]:
        step = t - previous
        previous = t
        busy = sum(used.values()) / step if step > 0 else 0.0
        spent[min(cores, int(round(busy)))] += step
    return spent


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=1, help="runs (default 1)")
    parser.add_argument("--interval", type=float, default=0.1, help="sampling interval, s (default 0.1)")
    parser.add_argument("--timeline", action="store_true", help="print the samples of the last run")
    parser.add_argument("rvfem_args", nargs="*", help="arguments of rvfem (after --; default: run the default case)")
    args = parser.parse_args(argv)
    cores = len(os.sched_getaffinity(0))
    with tempfile.TemporaryDirectory() as tmp:
        rvfem_args = args.rvfem_args or ["run", str(ROOT / "cases" / "rv40e_fanholes.toml"), "-o",
                                         str(Path(tmp) / "out"), "--overwrite"]
        command = [sys.executable, "-m", "rvfem", *rvfem_args]
        print("command: rvfem " + " ".join(rvfem_args))
        print(f"cores: {cores}")
        for k in range(args.repeat):
            m = measure(command, args.interval)
            total = sum(m["cpu"].values())
            print(f"\nrun {k + 1}: wall {m['wall']:.2f} s, processor time {total:.2f} s "
                  f"(mean busy cores {total / m['wall']:.2f} of {cores}; floor at {cores} busy cores "
                  f"{total / cores:.2f} s)")
            for pid, seconds in sorted(m["cpu"].items(), key=lambda kv: -kv[1]):
                print(f"  {seconds:7.2f} s  {m['labels'][pid]}")
            spent = busy_histogram(m["samples"], cores)
            print("  wall time by busy cores: " + ", ".join(f"{n}: {s:.2f} s" for n, s in enumerate(spent)))
        if args.timeline:
            pids = sorted(m["labels"])
            print("\n     t  " + " ".join(f"{p:>7}" for p in pids) + "   (per cent of one core)")
            previous = 0.0
            for t, used in m["samples"][1:]:
                step = max(t - previous, 1e-9)
                previous = t
                print(f"{t:6.2f}  " + " ".join(f"{100 * used.get(p, 0.0) / step:7.0f}" for p in pids))
    return 0


if __name__ == "__main__":
    sys.exit(main())
