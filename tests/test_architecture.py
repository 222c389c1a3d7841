"""The package's structure: layers that follow the data flow without import circles (the
import-linter contracts of pyproject.toml), imports at module level (function-level imports only of
heavy optional libraries, each with its reason), short functions, and no string sentinels."""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

PACKAGE = ROOT / "rvfem"
MODULES = sorted(PACKAGE.rglob("*.py"))

LAZY_LIBRARIES = {"matplotlib", "pyvista", "vtkmodules", "PIL", "dask", "distributed", "tqdm", "sksparse",
                  "pypardiso", "cholespy", "optuna"}
"""The only libraries a function may import itself: heavy (drawing, rendering, Dask), optional
(alternative sparse solvers) or needed by one command only (progress bars)."""

MAX_FUNCTION_LINES = 80


def _functions(tree):
    return [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]


def _lint_imports() -> str:
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or shutil.which("lint-imports")
    if exe is None:
        pytest.fail("lint-imports (import-linter, a dev dependency) is not installed")
    run = subprocess.run([exe, "--config", str(ROOT / "pyproject.toml"), "--no-cache"], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]
    return run.stdout


def test_the_layers_hold_and_there_is_no_import_circle():
    out = _lint_imports()
    assert "broken" not in out.split("Contracts:")[-1].split("\n")[0].replace("0 broken", "")


def test_the_layer_contract_names_every_module_of_the_package():
    """Every module sits in a layer of the main contract (a new module cannot escape the check)."""
    import tomllib

    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["importlinter"]
    layers = config["contracts"][0]["layers"]
    named = {name.strip() for layer in layers for name in layer.split("|")}
    for path in MODULES:
        rel = path.relative_to(ROOT).with_suffix("")
        parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
        if len(parts) == 1 or (len(parts) == 2 and parts[1] in ("__main__",)):
            continue                          # the package's face and ``python -m rvfem``
        assert ".".join(parts[:2]) in named, f"{path.relative_to(ROOT)} is in no layer of pyproject.toml"


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_imports_are_at_module_level_except_heavy_optional_libraries_with_a_reason(path):
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    for fn in _functions(ast.parse(text)):
        for node in ast.walk(fn):
            if not isinstance(node, (ast.Import, ast.ImportFrom)):
                continue
            module = node.names[0].name if isinstance(node, ast.Import) else (node.module or "")
            assert getattr(node, "level", 0) == 0 and module.split(".")[0] in LAZY_LIBRARIES, (
                f"{path.name}:{node.lineno}: {fn.name} imports {module} inside the function; import it at "
                "module level (only heavy optional libraries are imported where used)")
            reason = lines[node.end_lineno - 1].partition("#")[2].strip() or lines[node.lineno - 2].strip().lstrip("#")
            assert reason, f"{path.name}:{node.lineno}: say in a comment why {module} is imported here"


def test_no_function_is_longer_than_80_lines():
    long = []
    for path in MODULES:
        for fn in _functions(ast.parse(path.read_text(encoding="utf-8"))):
            n = fn.end_lineno - fn.lineno + 1
            if n > MAX_FUNCTION_LINES:
                long.append(f"{path.relative_to(ROOT)}:{fn.lineno} {fn.name} ({n} lines)")
    assert not long, "split these functions: " + "; ".join(long)


def test_no_string_sentinel_stands_for_the_case():
    """What varies between solves is an argument (an OperatingPoint, a stage), never a string
    default such as ``"case"`` that a function resolves from the case behind the caller's back."""
    for path in MODULES:
        for fn in _functions(ast.parse(path.read_text(encoding="utf-8"))):
            defaults = fn.args.defaults + [d for d in fn.args.kw_defaults if d is not None]
            for d in defaults:
                assert not (isinstance(d, ast.Constant) and d.value == "case"), (
                    f"{path.relative_to(ROOT)}:{fn.lineno} {fn.name} has the default 'case'")


def test_the_atomic_text_writer_replaces_a_file_whole(tmp_path):
    from rvfem._files import write_text_atomic

    path = tmp_path / "study.csv"
    path.write_text("old", encoding="utf-8")
    assert write_text_atomic(path, "new\n") == path
    assert path.read_text(encoding="utf-8") == "new\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.csv"]      # no temporary file left
    with pytest.raises(TypeError):
        write_text_atomic(path, b"bytes are not text")
    assert path.read_text(encoding="utf-8") == "new\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.csv"]
