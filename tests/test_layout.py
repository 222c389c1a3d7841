"""The tests mirror the package: a test module lies in the folder of the package layer it mainly
tests (``tests/solve/`` for ``rvfem/solve``, ``tests/mesh/`` for ``rvfem/mesh``), the whole-job
tests in ``tests/end_to_end/``, and only the checks of the package as a whole or of one of its
top-level modules directly in ``tests/``."""

from __future__ import annotations

from collections import Counter

from conftest import ROOT, TESTS_DIR

PACKAGE = ROOT / "rvfem"

WHOLE_JOB = "end_to_end"
"""The folder of the tests that run the whole job (every test in it counts as ``slow``)."""

DATA_FOLDERS = ("regressions",)
"""Folders of input files read by tests (no test modules)."""

PACKAGE_WIDE = ("test_architecture.py", "test_types.py", "test_front_door.py", "test_layout.py")
"""Test modules of the package as a whole (its layers, its types, its front door, this layout)."""


def _layers() -> set[str]:
    """The names a test folder may take: the package's subpackages and top-level modules."""
    subpackages = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()}
    modules = {p.stem for p in PACKAGE.glob("*.py") if not p.name.startswith("__")}
    return subpackages | modules


def _test_modules() -> list:
    return sorted(p for p in TESTS_DIR.rglob("test_*.py") if "__pycache__" not in p.parts)


def test_every_test_folder_is_a_layer_of_the_package_or_the_whole_job():
    folders = {p.name for p in TESTS_DIR.iterdir() if p.is_dir() and not p.name.startswith((".", "__"))}
    stray = sorted(folders - _layers() - {WHOLE_JOB, *DATA_FOLDERS})
    assert not stray, f"test folders that mirror no part of rvfem: {stray}"
    for folder in folders - set(DATA_FOLDERS):
        assert list((TESTS_DIR / folder).glob("test_*.py")), f"tests/{folder}/ holds no test module"
    for folder in DATA_FOLDERS:
        assert not list((TESTS_DIR / folder).rglob("*.py")), f"tests/{folder}/ holds input files only"


def test_only_package_wide_checks_lie_directly_in_tests():
    """A module directly in tests/ checks the package as a whole or a top-level module of it
    (``tests/test_units.py`` for ``rvfem/units.py``, ``tests/test_child.py`` for ``rvfem/_child.py``)."""
    top_modules = {p.stem.lstrip("_") for p in PACKAGE.glob("*.py") if not p.name.startswith("__")}
    flat = [p.name for p in TESTS_DIR.glob("test_*.py")]
    stray = sorted(n for n in flat if n not in PACKAGE_WIDE and n[len("test_"):-len(".py")] not in top_modules)
    assert not stray, f"move these into the folder of the layer they test (tests/<layer>/): {stray}"


def test_test_module_names_are_unique_and_the_folders_are_not_packages():
    """pytest's default import mode imports a test module by its file name from its folder, so two
    modules of the same name in two folders would clash; the folders stay plain folders."""
    names = Counter(p.name for p in _test_modules())
    assert not [n for n, k in names.items() if k > 1], f"test module names used twice: {names.most_common(3)}"
    assert not list(TESTS_DIR.rglob("__init__.py")), "tests/ folders are not packages (no __init__.py)"
