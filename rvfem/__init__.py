"""rvfem: crank-bearing loads of RV reducers with a flexible cycloid disc.

The package is a set of plain functions over plain data (see docs/theory.md): a validated
:class:`~rvfem.case.Case` goes in, tables of bearing loads, lives and stresses come out. Units are
mm, N, MPa, rpm and hours throughout; angles are radians inside the code and degrees in case files.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version
from types import MappingProxyType

try:
    __version__ = version("rvfem")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0+unknown"

NOTICE = MappingProxyType({"notice": True})
"""``extra`` of an INFO log record meant for the user even without ``-v``: something rvfem chose
for them that changes the run, e.g. a crank-angle step adjusted to divide 360° or a whole-disc mesh
where a sector was possible, and why (``log.info("...", extra=NOTICE)``). Library code logs, it
never prints; the command line shows these records as one "note" line each."""

__all__ = ["__version__", "NOTICE"]
