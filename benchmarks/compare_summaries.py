"""Compare two ``summary.json`` files number by number (a refactoring must not change results).

Usage::

    python benchmarks/compare_summaries.py BEFORE/summary.json AFTER/summary.json [--rtol 1e-9]

Every number present in both files is compared with a relative tolerance (absolute 1e-12 for
values near zero); keys that are timings, the rvfem version or file paths are skipped. Keys present
in only one file are listed. Exit code 0 when everything agrees, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import math
import sys

SKIPPED = {"timings_s", "rvfem_version", "file", "files", "images", "plots", "vtu", "image"}


def compare(before, after, path: str, rtol: float, out: list[str]) -> int:
    """Number of values compared; differences are appended to ``out``."""
    if isinstance(before, dict) and isinstance(after, dict):
        n = 0
        for key in sorted(set(before) | set(after)):
            if key in SKIPPED:
                continue
            sub = f"{path}.{key}" if path else key
            if key not in after:
                out.append(f"{sub}: only in the first file")
            elif key not in before:
                out.append(f"{sub}: only in the second file")
            else:
                n += compare(before[key], after[key], sub, rtol, out)
        return n
    if isinstance(before, list) and isinstance(after, list):
        if len(before) != len(after):
            out.append(f"{path}: {len(before)} vs {len(after)} entries")
            return 0
        return sum(compare(b, a, f"{path}[{i}]", rtol, out) for i, (b, a) in enumerate(zip(before, after)))
    numbers = (int, float)
    if isinstance(before, numbers) and isinstance(after, numbers) and not isinstance(before, bool):
        if not math.isclose(before, after, rel_tol=rtol, abs_tol=1e-12):
            rel = abs(after - before) / max(abs(before), 1e-300)
            out.append(f"{path}: {before!r} vs {after!r} (relative {rel:.2e})")
        return 1
    if before != after:
        out.append(f"{path}: {before!r} vs {after!r}")
    return 1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--rtol", type=float, default=1e-9)
    args = parser.parse_args(argv)
    with open(args.before, encoding="utf-8") as fh:
        before = json.load(fh)
    with open(args.after, encoding="utf-8") as fh:
        after = json.load(fh)
    differences: list[str] = []
    n = compare(before, after, "", args.rtol, differences)
    for line in differences:
        print(line)
    print(f"{n} values compared, {len(differences)} differences (rtol {args.rtol:g})")
    return 1 if differences else 0


if __name__ == "__main__":
    sys.exit(main())
