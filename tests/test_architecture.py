"""The package's structure: layers that follow the data flow without import circles (the
import-linter contracts of pyproject.toml), imports at module level (function-level imports only of
heavy optional libraries, each with its reason), short functions, and no string sentinels."""

from __future__ import annotations

import ast
import os
import re
import shutil
import subprocess
import sys
import tomllib
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

SUBLAYERED = {"rvfem.solve", "rvfem.case", "rvfem.app", "rvfem.results"}
"""The subpackages whose modules are layered among themselves by a contract of their own."""


def _functions(tree):
    return [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]


def contract_counts(config: Path, path: Path = ROOT) -> tuple[int, int]:
    """(kept, broken) import-linter contracts of ``config`` (a pyproject.toml), run on the package found
    on ``path``: the command's exit status and its count line ``Contracts: K kept, B broken.`` must
    agree, and K + B must be every contract of ``config`` (a contract that could not be checked, e.g. a
    layer naming a module that does not exist, fails)."""
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or shutil.which("lint-imports")
    if exe is None:
        pytest.fail("lint-imports (import-linter, a dev dependency) is not installed")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(path), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run([exe, str(config), "--no-cache"], cwd=path, capture_output=True, text=True, timeout=300,
                         env=env)
    out = run.stdout + run.stderr
    count = re.search(r"Contracts: (\d+) kept, (\d+) broken\.", out)
    assert count is not None, f"import-linter did not check the contracts: {out[-3000:]}"
    kept, broken = int(count[1]), int(count[2])
    assert (run.returncode == 0) == (broken == 0), out[-3000:]
    total = len(tomllib.loads(config.read_text(encoding="utf-8"))["tool"]["importlinter"]["contracts"])
    assert kept + broken == total, out[-3000:]
    return kept, broken


def _layer_names(contract: dict) -> set[str]:
    return {name.strip().removesuffix("(optional)").strip("() ") for layer in contract["layers"]
            for name in layer.split("|")}


def unlayered_modules(package: Path, config: dict) -> list[str]:
    """What of ``package`` (a directory) the layer contracts of ``config`` (the ``tool.importlinter``
    table) leave unchecked: a subpackage or top-level module in no layer of the first contract, a
    package of :data:`SUBLAYERED` without its own contract, or a module of a package that has its own
    contract (all of its layers inside that package) missing from that contract's layers."""
    root = package.name
    contracts = [c for c in config["contracts"] if c["type"] == "layers"]
    top = _layer_names(contracts[0])
    inner = {}
    for c in contracts[1:]:
        names = _layer_names(c)
        parents = {n.rpartition(".")[0] for n in names}
        if len(parents) == 1:
            inner[parents.pop()] = names
    problems = [f"{name} has no layer contract of its own" for name in sorted(SUBLAYERED - set(inner))]
    for path in sorted(package.rglob("*.py")):
        parts = (root,) + path.relative_to(package).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if len(parts) == 1 or parts == (root, "__main__"):
            continue                          # the package's face and ``python -m rvfem``
        name, sub = ".".join(parts), ".".join(parts[:2])
        if sub not in top:
            problems.append(f"{name} is in no layer of the first contract")
        elif len(parts) > 2 and sub in inner and ".".join(parts[:3]) not in inner[sub]:
            problems.append(f"{name} is in no layer of the contract of {sub}")
    return problems


def test_the_layers_hold_and_there_is_no_import_circle():
    kept, broken = contract_counts(ROOT / "pyproject.toml")
    assert broken == 0, f"{broken} import contracts of pyproject.toml are broken (run lint-imports to see which)"


def test_the_layer_contracts_name_every_module_of_the_package():
    """Every module sits in a layer of the main contract, and every module of solve, case and app in a
    layer of its package's contract (a new module cannot escape the check)."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["importlinter"]
    assert unlayered_modules(PACKAGE, config) == []


def _write_package(root: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")


def test_every_broken_contract_fails_the_check_even_ten_of_them(tmp_path):
    """A lower layer importing an upper one breaks the contract; ten broken contracts are ten failures
    (a summary line "Contracts: 0 kept, 10 broken." once passed a check that only looked for "0 broken")."""
    _write_package(tmp_path, {"rvfem_layer_probe/__init__.py": "", "rvfem_layer_probe/high.py": "",
                              "rvfem_layer_probe/low.py": "from rvfem_layer_probe import high\n"})
    contracts = "".join(f'''
[[tool.importlinter.contracts]]
name = "contract {i}: low under high"
type = "layers"
layers = ["rvfem_layer_probe.high", "rvfem_layer_probe.low"]
''' for i in range(10))
    config = tmp_path / "pyproject.toml"
    config.write_text('[tool.importlinter]\nroot_package = "rvfem_layer_probe"\n' + contracts, encoding="utf-8")
    assert contract_counts(config, tmp_path) == (0, 10)
    (tmp_path / "rvfem_layer_probe" / "low.py").write_text("", encoding="utf-8")    # the import removed
    assert contract_counts(config, tmp_path) == (10, 0)


def test_a_module_added_under_an_existing_subpackage_is_caught(tmp_path):
    """A copy of the package's tree with a module more in solve (whose contract must name it), one in
    evaluate (covered by the first contract, evaluate has no contract of its own) and a new subpackage."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["importlinter"]
    copy = tmp_path / "rvfem"
    _write_package(copy, {str(p.relative_to(PACKAGE)): "" for p in MODULES})
    assert unlayered_modules(copy, config) == []
    _write_package(copy, {"solve/carrier_spring.py": "", "evaluate/wear.py": "", "units2/__init__.py": ""})
    assert unlayered_modules(copy, config) == [
        "rvfem.solve.carrier_spring is in no layer of the contract of rvfem.solve",
        "rvfem.units2 is in no layer of the first contract"]
    config["contracts"] = [c for c in config["contracts"] if "rvfem.app.cli" not in _layer_names(c)]
    assert unlayered_modules(copy, config)[0] == "rvfem.app has no layer contract of its own"


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


def test_the_analysis_scheduler_takes_at_most_eight_parameters_per_function():
    """The analysis is a scheduler over the result sections: what varies between analyses is an
    AnalysisOptions, not a long list of arguments (a ``**choices`` counts as one)."""
    tree = ast.parse((ROOT / "rvfem" / "app" / "analysis.py").read_text(encoding="utf-8"))
    for f in _functions(tree):
        a = f.args
        count = (len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None)
                 + (a.kwarg is not None) - (1 if a.args and a.args[0].arg in ("self", "cls") else 0))
        assert count <= 8, f"rvfem/app/analysis.py: {f.name} takes {count} parameters"


MAX_MODULE_LINES = 800
"""Longest module of the package, lines: a module longer than this holds more than one concern."""


def test_no_module_is_longer_than_eight_hundred_lines():
    long = {str(p.relative_to(ROOT)): n for p in sorted(PACKAGE.rglob("*.py"))
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES}
    assert not long, f"modules over {MAX_MODULE_LINES} lines (split them along their concerns): {long}"
