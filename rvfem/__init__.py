"""rvfem: crank-bearing loads of RV reducers with a flexible cycloid disc.

The package is a set of plain functions over plain data (see docs/theory.md): a validated
:class:`~rvfem.case.Case` goes in, tables of bearing loads, lives and stresses come out. Units are
mm, N, MPa, rpm and hours throughout; angles are radians inside the code and degrees in case files.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("rvfem")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0+unknown"

__all__ = ["__version__"]
