"""rvfem: crank-bearing loads of RV reducers with a flexible cycloid disc.

The package is a set of plain functions over plain data (see docs/theory.md): a validated
:class:`~rvfem.case.definition.Case` goes in, tables of bearing loads, lives and stresses come out. Units are
mm, N, MPa, rpm and hours throughout; angles are radians inside the code and degrees in case files.

The front door: the few functions a notebook needs, importable from the package itself::

    import rvfem

    case = rvfem.load_case("cases/rv40e_fanholes.toml")
    rigid = rvfem.analyse_rigid(case)                     # handbook loads, rating, life, Hertz
    result = rvfem.analyse(case)                          # rigid + flexible load cycle, stresses
    rvfem.run_case(case, "results/x", overwrite=True)     # the main job: analysis and result folder

    system = rvfem.build_system(case, rvfem.mesh_case(case))   # one disc model, factorised once
    cycle = rvfem.load_cycle(system, op=rvfem.OperatingPoint(torque_Nm=300.0))

    study = rvfem.load_study("studies/rv40e_ligament_torque_grid.toml")
    rvfem.run_study(study, "results/grid")

They are imported on first use (:pep:`562`), so ``import rvfem`` stays light (no NumPy, SciPy or
Gmsh) and the package's modules can import it without a circle. Everything else lives in its own
module (:mod:`rvfem.case.definition`, :mod:`rvfem.solve.cycle`, :mod:`rvfem.outputs.summary`, ...).
"""

from __future__ import annotations

import importlib
from importlib.metadata import PackageNotFoundError, version
from types import MappingProxyType
from typing import Any

try:
    __version__ = version("rvfem")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0+unknown"

NOTICE = MappingProxyType({"notice": True})
"""``extra`` of an INFO log record meant for the user even without ``-v``: something rvfem chose
for them that changes the run, e.g. a crank-angle step adjusted to divide 360° or a whole-disc mesh
where a sector was possible, and why (``log.info("...", extra=NOTICE)``). Library code logs, it
never prints; the command line shows these records as one "note" line each."""

_FRONT_DOOR = MappingProxyType({
    "load_case": "case.definition",           # read and validate a case file (with KEY=VALUE overrides)
    "mesh_case": "mesh",                      # mesh the disc of a case (cached)
    "analyse_rigid": "app.analysis",          # rigid handbook loads, rating, life, Hertz pressures
    "analyse": "app.analysis",                # the whole analysis: rigid and flexible, lives, stresses
    "run_case": "app.run",                    # the main job: analysis and result folder (rvfem run)
    "build_system": "solve.cycle",            # one disc model: stiffness factorised, contact columns
    "OperatingPoint": "solve.cycle",          # what varies between solves of one model: torque, friction
    "solve_angle": "solve.cycle",             # one crank angle
    "load_cycle": "solve.cycle",              # a crank revolution
    "load_study": "app.study",                # read and validate a design study
    "run_study": "app.study",                 # run its variants on Dask (rvfem study)
})
"""The names importable from ``rvfem`` itself and the module each comes from (imported on first
use)."""

__all__ = ["__version__", "NOTICE", *_FRONT_DOOR]


def __getattr__(name: str) -> Any:
    """The front door's names, imported from their module on first use (:pep:`562`)."""
    module = _FRONT_DOOR.get(name)
    if module is None:  # also how ``from rvfem import cycle`` finds a submodule not yet imported
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # the next access is a plain attribute
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_FRONT_DOOR})
