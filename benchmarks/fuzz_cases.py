"""Fuzzing of the case reader and the subcommands: mutated shipped cases through ``rvfem check``
and ``rvfem rigid --json`` and, with ``--run N``, valid-looking ones through ``rvfem mesh`` and
``rvfem run`` too.

Each input is a shipped case file mutated at random: keys deleted, misspelled or added; values
replaced by wrong types, zero, negative, nan, ±inf, huge, tiny or denormal numbers; lists made too
short or too long; optional tables (holes, duty cycle, crank support) added with random values;
or the text itself damaged (duplicate tables, truncation, garbage or invalid UTF-8 bytes, lines
deleted). Both commands run in-process (:func:`rvfem.app.cli.main`) and every run is classified:

``exit 0``
    valid input; ``rigid --json`` printed strict JSON (no NaN/Infinity);
``exit 2``
    refused with one line on stderr that names a key (``'...'``) or the cause;
``traceback``
    an exception escaped :func:`rvfem.app.cli.main` (a bug);
``bad exit``
    any other exit code;
``bad message``
    exit 2 with a message on several lines or naming neither a key nor a cause;
``invalid JSON``
    exit 0 but stdout is not strict JSON;
``hang``
    an input took longer than the time limit (``--timeout``).

``refused after check``
    (``--run``) ``check`` accepted the case but ``mesh`` or ``run`` refused it: a valid case refused
    later, a bug unless the message names a physical cause ``check`` cannot know.

The mutations include the 0.4 tables and keys (roller profile, lubricant, strength, preload,
profile modifications, rigid or linear pins and rollers).

Run: ``python benchmarks/fuzz_cases.py --count 5000 --seed 1`` (prints the counts per outcome and
the first failing inputs); ``python benchmarks/fuzz_cases.py --run 30 --seed 1`` runs 30 valid
inputs through ``mesh`` and ``run`` as well (about 15 s each). ``tests/end_to_end/test_fuzz.py`` draws its inputs from the same generator.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import io
import json
import math
import random
import re
import signal
import sys
import time
import tomllib
import traceback
from collections import Counter
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from rvfem.case.definition import table_class  # noqa: E402
from rvfem.app.cli import main as rvfem_main  # noqa: E402
from rvfem.case.schema import file_fields, toml_literal  # noqa: E402

CASES_DIR = ROOT / "cases"
SHIPPED = {p.stem: p.read_text(encoding="utf-8") for p in sorted(CASES_DIR.glob("*.toml"))}

# --------------------------------------------------------------------------------------------
# A small TOML writer (the standard library only reads TOML)
# --------------------------------------------------------------------------------------------

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(key: str) -> str:
    return key if _BARE_KEY.match(key) else json.dumps(key)


def _value(value: Any) -> str:
    return toml_literal(value, bare_keys=True)


def _is_table_array(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def toml_dumps(data: dict) -> str:
    """TOML text of ``data`` (tables as sections, lists of tables as ``[[...]]``)."""
    lines: list[str] = []

    def table(body: dict, path: list[str]) -> None:
        for k, v in body.items():
            if not isinstance(v, dict) and not _is_table_array(v):
                lines.append(f"{_key(k)} = {_value(v)}")
        for k, v in body.items():
            if isinstance(v, dict):
                lines.append(f"\n[{'.'.join(_key(p) for p in path + [k])}]")
                table(v, path + [k])
            elif _is_table_array(v):
                for item in v:
                    lines.append(f"\n[[{'.'.join(_key(p) for p in path + [k])}]]")
                    table(item, path + [k])

    table(data, [])
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------------------------
# The generator
# --------------------------------------------------------------------------------------------

EXTREMES = (0, 0.0, -0.0, -1.0, -1, 1, 2, 3, math.nan, math.inf, -math.inf, 1e308, -1e308, 1e-308, 5e-324,
            2.2250738585072014e-308, 1e300, 1e-300, 2**63 - 1, -(2**63), 1e9, 1e-9, 0.5, 0.999999, 360.0, 1e6)
WRONG_TYPES = ("", "1.3", "rigid", True, False, [], [1.0], [[1.0]], {}, {"a": 1}, "x" * 300)
OPTIONAL_TABLES = {
    "fan_holes": lambda r: {"inner_radius": _num(r, 17.0), "outer_radius": _num(r, 49.0),
                            r.choice(["ligament", "span_deg"]): _num(r, 4.5), "fillet_radius": _num(r, 2.0),
                            **({"count": r.choice([1, 2, 3, 4, 0, 13])} if r.random() < 0.3 else {})},
    "round_holes": lambda r: {"radius": _num(r, 4.0), "circle_radius": _num(r, 50.0),
                              **({"count": r.choice([1, 3, 6, 0, 100])} if r.random() < 0.3 else {})},
    "crank_support": lambda r: r.choice([
        {"span": _num(r, 60.0), "eccentric_positions": [_num(r, 20.0), _num(r, 40.0)][: r.choice([1, 2, 2, 2])],
         r.choice(["journal_diameter", "bending_stiffness_Nmm2"]): _num(r, 25.0),
         "support_stiffness_N_per_mm": r.choice([_num(r, 3e5), [_num(r, 3e5), _num(r, 4e5)], [1e5] * 3]),
         "shear": r.choice([True, False, 1])},
        {"influence_mm_per_N": r.choice([[[2e-6, 1e-6], [1e-6, 2e-6]], [[1e-6, 2e-6], [2e-6, 1e-6]],
                                         [[_num(r, 2e-6), 1e-6], [1e-6, _num(r, 2e-6)]], [[1e-6]], [1e-6]])},
    ]),
}
# Tables inside tables, and keys of existing tables, that the 0.4 capabilities added (the roller
# profile, the lubricant, the strength of the material, preload, profile modifications): added to the
# mutated bases so the fuzzer reaches them.
NESTED_OPTIONAL = {
    ("crank_bearing", "profile"): lambda r: {
        "kind": r.choice(["straight", "arc", "logarithmic", "combined", "crowned", "straight"]),
        **({"crown_radius": _num(r, 500.0)} if r.random() < 0.4 else {}),
        **({"design_load_N": _num(r, 2000.0)} if r.random() < 0.3 else {}),
        **({"modification_length": _num(r, 1.23), "modification_drop": _num(r, 0.006)} if r.random() < 0.3 else {}),
        **({"misalignment_mrad": _num(r, 1.0)} if r.random() < 0.3 else {}),
        **({"slices": r.choice([8, 12, 30, 7, 401, 30.5])} if r.random() < 0.3 else {})},
    ("lubricant",): lambda r: {
        **({"iso_vg": r.choice([22, 68, 100, 460, 67, "68"])} if r.random() < 0.5 else {}),
        **({"nu40": _num(r, 68.0), "nu100": _num(r, 8.7)} if r.random() < 0.4 else {}),
        **({"temperature_C": _num(r, 60.0)} if r.random() < 0.4 else {}),
        **({"contamination_factor": _num(r, 0.5)} if r.random() < 0.2 else {}),
        **({"cleanliness": r.choice(["normal", "high", "severe", "dirty"])} if r.random() < 0.3 else {}),
        **({"roughness_Ra_um": _num(r, 0.1)} if r.random() < 0.3 else {})},
    ("cycloid", "modification"): lambda r: {
        "equidistant": r.choice([0.01, 0.005, -0.01, _num(r, 0.01)]),
        "shift": r.choice([-0.01, 0.0, 0.005, _num(r, -0.01)]),
        **({"rotation_deg": _num(r, 0.01)} if r.random() < 0.3 else {})},
}
NESTED_KEYS = {
    ("material", "yield_strength"): lambda r: _num(r, 1800.0),
    ("material", "ultimate_strength"): lambda r: _num(r, 2400.0),
    ("material", "fatigue_limit"): lambda r: _num(r, 960.0),
    ("material", "density_kg_m3"): lambda r: _num(r, 7810.0),
    ("crank_bearing", "radial_clearance"): lambda r: r.choice([-0.005, -0.01, 0.005, 0.02, _num(r, -0.005)]),
    ("pins", "model"): lambda r: r.choice(["rigid", "linear", "hertz", "palmgren"]),
    ("crank_bearing", "stiffness_law"): lambda r: r.choice(["linear", "palmgren"]),
}


def _add_nested(r: random.Random, data: dict) -> str:
    """Add one of the 0.4 tables or keys (with its companions where a choice needs them)."""
    if r.random() < 0.5:
        path = r.choice(list(NESTED_OPTIONAL))
        make = NESTED_OPTIONAL[path]
    else:
        path = r.choice(list(NESTED_KEYS))
        make = NESTED_KEYS[path]
    parent = data
    for key in path[:-1]:
        parent = parent.setdefault(key, {})
        if not isinstance(parent, dict):
            return "no-op"
    parent[path[-1]] = make(r)
    if path == ("pins", "model") and parent[path[-1]] == "linear":
        parent["linear_stiffness_N_per_mm"] = _num(r, 5e5)
    if path == ("crank_bearing", "stiffness_law") and parent[path[-1]] == "linear":
        parent["linear_stiffness_N_per_mm"] = _num(r, 5e5)
    return f"add {'.'.join(path)} = {parent[path[-1]]!r}"


def _wrong_type(r: random.Random) -> Any:
    """A value of a wrong type (a fresh copy: mutations must not change the module's constants)."""
    return copy.deepcopy(r.choice(WRONG_TYPES))


def _num(r: random.Random, typical: float) -> Any:
    """Mostly a plausible value near ``typical``, sometimes an extreme."""
    roll = r.random()
    if roll < 0.6:
        return typical * r.choice([1.0, 0.5, 0.9, 1.1, 2.0])
    if roll < 0.9:
        return r.choice(EXTREMES)
    return _wrong_type(r)


def _declared_range(path: tuple) -> tuple[float, float] | None:
    """(low, high) declared for the number at ``path`` of a case (list indices skipped)."""
    names = [p for p in path if isinstance(p, str)]
    try:
        cls = table_class(".".join(names[:-1]))
    except KeyError:
        return None
    spec = {s.name: s for s in file_fields(cls)}.get(names[-1])
    if spec is None or spec.param.low is None or spec.param.high is None:
        return None
    return spec.param.low, spec.param.high


def _in_range(r: random.Random, low: float, high: float, integer: bool) -> float | int:
    """A bound itself, or a value log-uniform (linear across zero) between the bounds."""
    roll = r.random()
    if roll < 0.25:
        value = low
    elif roll < 0.5:
        value = high
    elif low > 0:
        value = math.exp(r.uniform(math.log(low), math.log(high)))
    else:
        value = r.uniform(low, high)
    return int(round(value)) if integer else float(value)


def _paths(data: Any, prefix: tuple = ()) -> list[tuple]:
    out = []
    if isinstance(data, dict):
        for k, v in data.items():
            out.append(prefix + (k,))
            out.extend(_paths(v, prefix + (k,)))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            if isinstance(v, dict):
                out.extend(_paths(v, prefix + (i,)))
    return out


def _parent(data: Any, path: tuple) -> Any:
    for part in path[:-1]:
        data = data[part]
    return data


def _misspell(r: random.Random, word: str) -> str:
    if not word:
        return "x"
    i = r.randrange(len(word))
    op = r.choice(["drop", "swap", "insert", "case", "weird"])
    if op == "drop":
        return word[:i] + word[i + 1:] or "x"
    if op == "swap" and len(word) > 1:
        i = min(i, len(word) - 2)
        return word[:i] + word[i + 1] + word[i] + word[i + 2:]
    if op == "case":
        return word.upper()
    if op == "weird":
        return word[:i] + r.choice(["\n", "\t", " ", "é", "'", '"', "\\", ".", "\x00"]) + word[i:]
    return word[:i] + r.choice("abcdefghijklmnopqrstuvwxyz_") + word[i:]


def _mutate_data(r: random.Random, data: dict, op: str | None = None) -> str:
    """Apply one mutation (of the kind ``op``, default drawn at random) to the parsed case in place;
    return its description."""
    op = op or r.choice(["delete", "misspell", "type", "extreme", "extreme", "extreme", "scale", "list", "add_table",
                   "add_duty", "discs", "choice", "in_range", "in_range", "in_range", "in_range", "all_in_range",
                   "add_nested", "add_nested", "add_nested"])
    if op == "add_nested":
        return _add_nested(r, data)
    paths = _paths(data)
    path = r.choice(paths)
    parent, key = _parent(data, path), path[-1]
    dotted = ".".join(str(p) for p in path)
    if op == "delete":
        del parent[key]
        return f"delete {dotted}"
    if op == "misspell" and isinstance(parent, dict):
        new = _misspell(r, str(key))
        parent[new] = parent.pop(key)
        return f"misspell {dotted} -> {new!r}"
    if op == "type":
        parent[key] = _wrong_type(r)
        return f"type {dotted} = {parent[key]!r}"
    if op == "all_in_range":
        changed = 0
        for path in paths:
            parent = _parent(data, path)
            value = parent[path[-1]]
            bounds = _declared_range(path)
            if bounds and isinstance(value, (int, float)) and not isinstance(value, bool) and r.random() < 0.5:
                parent[path[-1]] = _in_range(r, *bounds, isinstance(value, int))
                changed += 1
        return f"{changed} numbers in range"
    numbers = [p for p in paths if isinstance(_parent(data, p)[p[-1]], (int, float))
               and not isinstance(_parent(data, p)[p[-1]], bool)]
    if op == "in_range":
        ranged = [(p, b) for p, b in ((p, _declared_range(p)) for p in numbers) if b is not None]
        if not ranged:
            return "no-op"
        path, (low, high) = r.choice(ranged)
        parent = _parent(data, path)
        parent[path[-1]] = _in_range(r, low, high, isinstance(parent[path[-1]], int))
        return f"in range {'.'.join(map(str, path))} = {parent[path[-1]]!r}"
    if op in ("nudge", "extreme", "scale"):
        if not numbers:
            return "no-op"
        path = r.choice(numbers)
        parent, key = _parent(data, path), path[-1]
    if op == "nudge":
        factor = r.choice([0.8, 0.9, 0.95, 1.05, 1.1, 1.25])
        parent[key] = round(parent[key] * factor) if isinstance(parent[key], int) else parent[key] * factor
        return f"nudge {'.'.join(map(str, path))} = {parent[key]!r}"
    if op in ("extreme", "scale"):
        if op == "extreme":
            parent[key] = r.choice(EXTREMES)
        else:
            parent[key] = parent[key] * r.choice([1e-3, 0.1, 0.5, 2.0, 10.0, 1e3, -1.0])
        return f"{op} {'.'.join(map(str, path))} = {parent[key]!r}"
    if op == "list":
        lists = [p for p in paths if isinstance(_parent(data, p)[p[-1]], list)]
        table = r.choice(["cranks", "analysis", "cycloid"])
        if not lists or r.random() < 0.5:
            key = {"cranks": "angles_deg", "analysis": "saved_angles_deg", "cycloid": "teeth"}[table]
            data.setdefault(table, {})
            if not isinstance(data[table], dict):
                return "no-op"
            data[table][key] = [r.choice([0.0, 90.0, 210.0, 330.0, math.nan, 1e9]) for _ in range(r.randrange(0, 6))]
            return f"list {table}.{key} = {data[table][key]!r}"
        path = r.choice(lists)
        values = _parent(data, path)[path[-1]]
        if values and r.random() < 0.5:
            values.pop(r.randrange(len(values)))
        else:
            values.append(r.choice(EXTREMES))
        return f"list {'.'.join(map(str, path))} = {values!r}"
    if op == "add_table":
        name = r.choice(list(OPTIONAL_TABLES))
        data[name] = OPTIONAL_TABLES[name](r)
        return f"add [{name}] = {data[name]!r}"
    if op == "add_duty":
        loads = data.get("loads")
        if not isinstance(loads, dict):
            return "no-op"
        rows = [{"time_share": _num(r, 0.5), "speed_rpm": _num(r, 15.0), "torque_Nm": _num(r, 400.0)}
                for _ in range(r.randrange(1, 4))]
        loads["duty_cycle"] = rows
        return f"duty cycle {rows!r}"
    if op == "discs":
        loads = data.get("loads")
        if not isinstance(loads, dict):
            return "no-op"
        loads["discs"] = r.choice([1, 2, 3, 4, 5, 0])
        if r.random() < 0.5:
            loads["torque_split"] = r.choice(["equal", "stiffness", "equl", ""])
        return f"loads.discs = {loads['discs']}, torque_split = {loads.get('torque_split')!r}"
    # choice
    table, key, values = r.choice([("pins", "model", ["rigid", "hertz", "linear", "rigd"]),
                                   ("crank_bearing", "model", ["rollers", "rigid_bore", "roller"]),
                                   ("crank_bearing", "stiffness_law", ["palmgren", "linear", "palmgrem"]),
                                   ("analysis", "element_order", [1, 2, 3, 0])])
    if not isinstance(data.get(table), dict):
        return "no-op"
    data[table][key] = r.choice(values)
    return f"choice {table}.{key} = {data[table][key]!r}"


def _mutate_text(r: random.Random, text: str) -> tuple[str, bytes]:
    raw = text.encode("utf-8")
    op = r.choice(["duplicate", "truncate", "garbage", "bytes", "utf8", "line", "empty"])
    if op == "duplicate":
        headers = re.findall(r"^\[[^\]\n]+\]$", text, flags=re.M) or ["[cycloid]"]
        return "duplicate table", (text + "\n" + r.choice(headers) + "\nteeth = 39\n").encode()
    if op == "truncate":
        return "truncate", raw[: r.randrange(len(raw) + 1)]
    if op == "garbage":
        i = r.randrange(len(raw) + 1)
        return "garbage", raw[:i] + bytes(r.randrange(256) for _ in range(r.randrange(1, 20))) + raw[i:]
    if op == "bytes":
        data = bytearray(raw)
        for _ in range(r.randrange(1, 6)):
            data[r.randrange(len(data))] = r.randrange(256)
        return "flipped bytes", bytes(data)
    if op == "utf8":
        return "invalid UTF-8", raw + b"\n# \xff\xfe\xc3\x28\n"
    if op == "line":
        lines = text.splitlines()
        del lines[r.randrange(len(lines))]
        return "delete line", ("\n".join(lines) + "\n").encode()
    return "empty", b""


def fuzz_input(r: random.Random) -> tuple[str, bytes]:
    """One mutated case file: (description, content)."""
    name = r.choice(sorted(SHIPPED))
    text = SHIPPED[name]
    if r.random() < 0.2:
        description, content = _mutate_text(r, text)
        return f"{name}: {description}", content
    data = tomllib.loads(text)
    steps = [_mutate_data(r, data) for _ in range(r.choice([1, 1, 1, 2, 3]))]
    return f"{name}: " + "; ".join(steps), toml_dumps(data).encode("utf-8")


VALID_OPS = ("nudge", "nudge", "nudge", "in_range", "add_nested", "add_nested", "add_nested")


def fuzz_valid_input(r: random.Random) -> tuple[str, bytes]:
    """A mutated case meant to stay valid (for the expensive commands): numbers moved inside their
    declared ranges or nudged by a few per cent, the 0.4 tables and keys added. Some still fail
    ``check`` (a combination out of range); ``--run`` skips those."""
    name = r.choice(sorted(SHIPPED))
    data = tomllib.loads(SHIPPED[name])
    steps = []
    for _ in range(r.choice([1, 2, 2, 3])):
        op = r.choice(VALID_OPS)
        steps.append(_mutate_data(r, data, op))
    return f"{name}: " + "; ".join(steps), toml_dumps(data).encode("utf-8")


# --------------------------------------------------------------------------------------------
# Running one input
# --------------------------------------------------------------------------------------------

_CAUSE = re.compile(r"'[^']+'|not a valid TOML file|cannot read the case file")


def _strict_json(text: str) -> Any:
    def reject(constant: str) -> Any:
        raise ValueError(f"non-finite number {constant} in JSON")

    return json.loads(text, parse_constant=reject)


def run_cli(argv: list[str]) -> tuple[int | None, str, str, str | None]:
    """``rvfem.app.cli.main(argv)`` in-process: (exit code, stdout, stderr, traceback or None)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = rvfem_main(argv)
        except Exception:  # noqa: BLE001 - a bug: classified as "traceback"
            return None, out.getvalue(), err.getvalue(), traceback.format_exc()
    return code, out.getvalue(), err.getvalue(), None


def classify(command: str, code: int | None, stdout: str, stderr: str, tb: str | None) -> tuple[str, str]:
    """(outcome, detail) of one run; outcomes as in the module docstring."""
    if tb is not None:
        return "traceback", tb.strip().splitlines()[-1]
    if code == 2:
        message = stderr.strip()
        if "\n" in message or not message.startswith(f"rvfem {command}: error: ") or not _CAUSE.search(message):
            return "bad message", message
        return "exit 2", message
    if code != 0:
        return "bad exit", f"exit code {code}: {stderr.strip()}"
    if command == "rigid":
        try:
            _strict_json(stdout)
        except ValueError as exc:
            return "invalid JSON", str(exc)
    return "exit 0", ""


def check_file(path: Path) -> list[tuple[str, str, str]]:
    """Run ``check`` and ``rigid --json`` on ``path``: [(command, outcome, detail)]."""
    results = []
    for command, argv in (("check", ["check", str(path)]), ("rigid", ["rigid", "--json", str(path)])):
        outcome, detail = classify(command, *run_cli(argv))
        results.append((command, outcome, detail))
    return results


def run_file(path: Path, workdir: Path) -> list[tuple[str, str, str]]:
    """Run ``mesh`` and ``run --step 30 --no-images`` on a case that passed ``check``:
    [(command, outcome, detail)]. A refusal (exit 2) here is a *valid case refused later*: the
    outcome is then ``refused after check``."""
    results = []
    cache = workdir / "meshes"
    for command, argv in (("mesh", ["mesh", str(path), "--cache-dir", str(cache)]),
                          ("run", ["run", str(path), "-o", str(workdir / "out"), "--overwrite", "--step", "30",
                                   "--no-images", "--cache-dir", str(cache)])):
        code, stdout, stderr, tb = run_cli(argv)
        outcome, detail = classify(command, code, stdout, stderr, tb)
        if outcome == "exit 2":
            outcome = "refused after check"
        results.append((command, outcome, detail))
        if outcome != "exit 0":
            break
    return results


class _Timeout(Exception):
    pass


def _alarm(signum: int, frame: Any) -> None:
    raise _Timeout


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=5000, help="number of inputs (default 5000)")
    parser.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    parser.add_argument("--timeout", type=float, default=10.0, help="time limit per input, s (default 10)")
    parser.add_argument("--workdir", default=None, help="folder for the input files (default: a temporary one)")
    parser.add_argument("--show", type=int, default=10, help="failing inputs to print (default 10)")
    parser.add_argument("--run", type=int, default=0, metavar="N",
                        help="also draw inputs meant to stay valid until N of them pass check, and run "
                             "`mesh` and `run --step 30 --no-images` on those (default 0)")
    args = parser.parse_args(argv)
    if args.run:
        return _main_run(args)

    import tempfile

    rng = random.Random(args.seed)
    counts: Counter = Counter()
    failures: list[tuple[int, str, str, str, str]] = []
    signal.signal(signal.SIGALRM, _alarm)
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(dir=args.workdir) as tmp:
        path = Path(tmp) / "case.toml"
        for i in range(args.count):
            description, content = fuzz_input(rng)
            path.write_bytes(content)
            signal.setitimer(signal.ITIMER_REAL, args.timeout)
            try:
                results = check_file(path)
            except _Timeout:
                results = [("check/rigid", "hang", f"> {args.timeout:g} s")]
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
            for command, outcome, detail in results:
                counts[(command, outcome)] += 1
                if outcome not in ("exit 0", "exit 2"):
                    failures.append((i, command, outcome, description, detail))
    elapsed = time.perf_counter() - start
    print(f"fuzz_cases: {args.count} inputs, seed {args.seed}, {elapsed:.1f} s "
          f"({1000 * elapsed / max(args.count, 1):.1f} ms per input, both commands)")
    for command in ("check", "rigid"):
        row = {o: n for (c, o), n in sorted(counts.items()) if c == command}
        print(f"  {command:6s} " + ", ".join(f"{o}: {n}" for o, n in row.items()))
    hangs = sum(n for (c, o), n in counts.items() if o == "hang")
    if hangs:
        print(f"  hang: {hangs}")
    kinds = Counter((c, o, d.split(":")[0][:80]) for _, c, o, _, d in failures)
    for (command, outcome, detail), n in kinds.most_common():
        print(f"  FAIL {n:5d} × {command} {outcome}: {detail}")
    for i, command, outcome, description, detail in failures[: args.show]:
        print(f"  input {i}: {command} {outcome}: {description!r} -> {detail}")
    return 1 if failures else 0


def _main_run(args: argparse.Namespace) -> int:
    """``--run N``: valid-looking inputs through check, mesh and run; counts and failures."""
    import tempfile

    rng = random.Random(args.seed)
    counts: Counter = Counter()
    failures: list[tuple[int, str, str, str, str]] = []
    start = time.perf_counter()
    drawn = ran = 0
    with tempfile.TemporaryDirectory(dir=args.workdir) as tmp:
        work = Path(tmp)
        path = work / "case.toml"
        while ran < args.run:
            description, content = fuzz_valid_input(rng)
            drawn += 1
            path.write_bytes(content)
            (command, outcome, detail), = [check_file(path)[0]]
            counts[("check", outcome)] += 1
            if outcome not in ("exit 0", "exit 2"):
                failures.append((drawn, command, outcome, description, detail))
            if outcome != "exit 0":
                continue
            ran += 1
            for command, outcome, detail in run_file(path, work):
                counts[(command, outcome)] += 1
                if outcome != "exit 0":
                    failures.append((drawn, command, outcome, description, detail))
                    (work / f"failed-{drawn}.toml").write_bytes(content)
            print(f"  {ran}/{args.run} ({time.perf_counter() - start:.0f} s): {description[:100]}", flush=True)
    elapsed = time.perf_counter() - start
    print(f"fuzz_cases --run: {drawn} inputs drawn, {ran} passed check and ran, seed {args.seed}, "
          f"{elapsed:.0f} s")
    for command in ("check", "mesh", "run"):
        row = {o: n for (c, o), n in sorted(counts.items()) if c == command}
        print(f"  {command:6s} " + ", ".join(f"{o}: {n}" for o, n in row.items()))
    for i, command, outcome, description, detail in failures[: args.show]:
        print(f"  input {i}: {command} {outcome}: {description!r} -> {detail}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
