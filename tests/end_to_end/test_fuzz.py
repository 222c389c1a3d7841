"""Fuzzing of ``rvfem check`` and ``rvfem rigid --json`` with mutated shipped cases (hypothesis).

Every input must end in exit code 0 (and strict JSON from ``rigid --json``) or exit code 2 with
one line on stderr naming a key or the cause; never a traceback. The inputs come from the
generator of ``benchmarks/fuzz_cases.py`` (driven here by hypothesis's random source, so a
failure is reported with a reproducible example); that script runs the same check on thousands
of inputs.
"""

from __future__ import annotations

import math
import sys

import pytest
from conftest import ROOT
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(ROOT / "benchmarks"))

import fuzz_cases  # noqa: E402

OK = ("exit 0", "exit 2")


EXAMPLES = 2000
"""Mutated inputs in all, drawn in :data:`SHARDS` parts of equal size: hypothesis gives every
parametrized instance its own derandomized seed (from its test id), so the parts draw different
inputs, and parallel workers (``make test``) share them."""
SHARDS = 4


@pytest.mark.parametrize("shard", range(SHARDS))
@settings(max_examples=EXAMPLES // SHARDS, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(rng=st.randoms(use_true_random=False))
def test_mutated_cases_exit_cleanly(shard, rng, tmp_path):
    description, content = fuzz_cases.fuzz_input(rng)
    path = tmp_path / "case.toml"
    path.write_bytes(content)
    for command, outcome, detail in fuzz_cases.check_file(path):
        assert outcome in OK, f"{command}: {outcome}: {detail}\ninput: {description}\n{content[:2000]!r}"


@pytest.mark.parametrize("name", sorted(fuzz_cases.SHIPPED))
def test_shipped_cases_pass_both_commands(name, tmp_path):
    path = tmp_path / f"{name}.toml"
    path.write_text(fuzz_cases.SHIPPED[name], encoding="utf-8")
    assert [o for _, o, _ in fuzz_cases.check_file(path)] == ["exit 0", "exit 0"]


def test_the_toml_writer_round_trips():
    import tomllib

    data = {"a": 1, "b": [1.0, math.inf], "t": {"x": "y\n", "weird key": True, "u": {"v": []}},
            "rows": [{"p": 1}, {"p": 2}]}
    back = tomllib.loads(fuzz_cases.toml_dumps(data))
    assert back["b"][1] == math.inf and back["t"] == data["t"] and back["rows"] == data["rows"]


@pytest.mark.parametrize("stdout, ok", [('{"a": 1.5}', True), ('{"a": NaN}', False), ('{"a": Infinity}', False),
                                        ("{", False)])
def test_strict_json_rejects_non_finite_numbers(stdout, ok):
    outcome, _ = fuzz_cases.classify("rigid", 0, stdout, "", None)
    assert (outcome == "exit 0") == ok


@pytest.mark.parametrize("stderr, ok", [
    ("rvfem check: error: x.toml: 'pins.radius' must be positive, got -3.0\n", True),
    ("rvfem check: error: x.toml: not a valid TOML file (Expected '=' (at line 1, column 3))\n", True),
    ("rvfem check: error: something went wrong\n", False),
    ("rvfem check: error: x.toml: 'a'\nsecond line\n", False),
])
def test_messages_must_be_one_line_naming_a_key_or_cause(stderr, ok):
    outcome, _ = fuzz_cases.classify("check", 2, "", stderr, None)
    assert (outcome == "exit 2") == ok
