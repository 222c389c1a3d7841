"""The type check: mypy, configured in pyproject.toml ([tool.mypy]), finds no error in the package.

The whole package is checked at mypy's default strictness; the modules listed in the strict
overrides of pyproject.toml are checked with every function annotated and no bare generics.
"""

from __future__ import annotations

from pathlib import Path

import pytest

api = pytest.importorskip("mypy.api", reason="mypy is in the dev extra")

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_mypy_finds_no_error(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)   # mypy reads [tool.mypy] (files = rvfem) from the project's pyproject.toml
    stdout, stderr, status = api.run(["--config-file", str(ROOT / "pyproject.toml"),
                                      "--cache-dir", str(tmp_path / "mypy-cache"), "--no-error-summary"])
    errors = [line for line in stdout.splitlines() if ": error:" in line]
    assert status == 0 and not errors, "mypy reports:\n" + (stdout + stderr)[-6000:]
