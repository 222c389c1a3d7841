"""The front door of ``rvfem``: the few names a notebook needs, imported lazily from their modules."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest
from conftest import ROOT

import rvfem

#: The front door and the module each name lives in.
HOMES = {
    "load_case": "rvfem.case.definition",
    "mesh_case": "rvfem.mesh",
    "analyse_rigid": "rvfem.app.analysis",
    "analyse": "rvfem.app.analysis",
    "run_case": "rvfem.app.run",
    "build_system": "rvfem.solve.cycle",
    "OperatingPoint": "rvfem.solve.cycle",
    "solve_angle": "rvfem.solve.cycle",
    "load_cycle": "rvfem.solve.cycle",
    "load_study": "rvfem.app.study",
    "run_study": "rvfem.app.study",
}


def _python(code: str) -> str:
    """Run ``code`` in a fresh interpreter (nothing of this test process imported); its stdout."""
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


@pytest.mark.parametrize("name, home", HOMES.items())
def test_each_name_is_the_object_of_its_home_module(name, home):
    assert getattr(rvfem, name) is getattr(importlib.import_module(home), name)


def test_all_and_dir_show_the_front_door():
    assert set(rvfem.__all__) == {"__version__", "NOTICE", *HOMES}
    assert set(HOMES) <= set(dir(rvfem))
    assert {"__version__", "NOTICE"} <= set(dir(rvfem))
    assert rvfem.NOTICE["notice"] is True and isinstance(rvfem.__version__, str)


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="module 'rvfem' has no attribute 'no_such_name'"):
        rvfem.no_such_name  # noqa: B018
    assert not hasattr(rvfem, "analyze")


def test_import_rvfem_is_light():
    """``import rvfem`` imports none of the package's modules, nor NumPy or SciPy."""
    loaded = _python("import rvfem, sys; print(sorted(m for m in sys.modules "
                     "if m.startswith('rvfem.') or m.split('.')[0] in ('numpy', 'scipy', 'gmsh', 'matplotlib')))")
    assert loaded == "[]"
    assert _python("import rvfem, sys; print('rvfem.solve.cycle' in sys.modules)") == "False"


def test_first_use_imports_the_home_module_only():
    assert _python("import rvfem, sys; rvfem.load_case; "
                   "print('rvfem.case.definition' in sys.modules, 'rvfem.solve.cycle' in sys.modules, 'rvfem.app.study' in sys.modules)"
                   ) == "True False False"


def test_submodules_still_import_from_the_package():
    """``from rvfem.solve import cycle`` finds the submodule (the lazy ``__getattr__`` does not hide it),
    and ``from rvfem import *`` gives the front door."""
    assert _python("from rvfem.solve import cycle; from rvfem.app import study; print(cycle.__name__, study.__name__)") == \
        "rvfem.solve.cycle rvfem.app.study"
    assert _python("from rvfem import *; print(load_study.__module__, OperatingPoint.__module__)") \
        == "rvfem.app.study_definition rvfem.solve.cycle"
