"""The one CSV writer of rvfem: a header row and rows of cells, every cell formatted by one policy.

Every CSV file rvfem writes (the run's tables, ``roller_pressure.csv``, ``hysteresis.csv``,
``te.csv``, a study's ``study.csv`` and an optimisation's ``trials.csv``) goes through
:func:`write_csv`, :func:`write_csv_columns` or :func:`csv_text`, so they all read back the same way.
:func:`write_csv_columns` writes a table given by its columns (the long tables of a run: one row per
crank angle and roller or pin) with the same text as :func:`write_csv`, formatting a NumPy column
in one pass (:func:`format_column`) instead of cell by cell.

The policy (documented for users in ``docs/outputs.md``, section "CSV tables"):

- a float is written as its shortest decimal that reads back as the same double (Python's
  ``repr``): no digit of a result is lost, and a number read back with ``float`` is bit-identical
  to the one computed;
- an integer (Python or NumPy) is written in decimal;
- a bool is ``yes`` or ``no``;
- ``None`` (a value not there) is an empty cell; NaN (a value that is not defined, such as the
  handbook's bearing loads of a two-tooth disc) is ``nan``, or an empty cell where the caller asks
  for ``nan_as_empty`` (the study and optimisation tables, which read empty cells back as missing);
- anything else (a string) is written as ``str`` gives it.

Comma-separated, ``\\n`` line ends, UTF-8, quoted by :mod:`csv` only where a cell needs it.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["csv_text", "format_cell", "format_column", "write_csv", "write_csv_columns"]


def format_cell(value: Any, *, nan_as_empty: bool = False) -> str:
    """One cell of a CSV file rvfem writes, by the policy of :mod:`rvfem.outputs.csvfile`.

    Parameters
    ----------
    value : float, int, bool, str, None or a NumPy scalar
        The cell's value (numbers in the units the column's name states).
    nan_as_empty : bool
        Write NaN as an empty cell (as ``None``) instead of ``nan``.

    Returns
    -------
    str
        The cell's text: floats as their shortest round-trip decimal (``repr``).
    """
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        x = float(value)
        if math.isnan(x):
            return "" if nan_as_empty else "nan"
        return repr(x)
    return str(value)


def format_column(values: np.ndarray | Sequence[Any], *, nan_as_empty: bool = False) -> list[str]:
    """The cells of one column of a CSV file, each exactly as :func:`format_cell` writes it.

    A one-dimensional NumPy array of floats, integers or bools is formatted in one pass (its
    values as Python numbers, ``repr`` or ``str`` mapped over them: a tenth of the time of a call
    of :func:`format_cell` per cell); anything else cell by cell.

    Parameters
    ----------
    values : ndarray (n,) or sequence
        The column's values.
    nan_as_empty : bool
        Write NaN as an empty cell instead of ``nan``.

    Returns
    -------
    list of str
    """
    if isinstance(values, np.ndarray) and values.ndim == 1:
        kind = values.dtype.kind
        if kind == "f":
            cells = list(map(repr, values.astype(float, copy=False).tolist()))   # NaN gives "nan"
            if nan_as_empty and bool(np.isnan(values).any()):
                cells = ["" if cell == "nan" else cell for cell in cells]
            return cells
        if kind in "iu":
            return list(map(str, values.tolist()))
        if kind == "b":
            return ["yes" if v else "no" for v in values.tolist()]
    return [format_cell(v, nan_as_empty=nan_as_empty) for v in values]


def _write_rows(fh, header: Sequence[str], rows: Iterable[Sequence[Any]], nan_as_empty: bool) -> None:
    writer = csv.writer(fh, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow([format_cell(v, nan_as_empty=nan_as_empty) for v in row])


def csv_text(header: Sequence[str], rows: Iterable[Sequence[Any]], *, nan_as_empty: bool = False) -> str:
    """The text of a CSV file: ``header``, then one line per row, cells by :func:`format_cell`.

    Parameters
    ----------
    header : sequence of str
        Column names (with their units, e.g. ``theta_deg``).
    rows : iterable of sequences
        One sequence of values per row, in the header's order.
    nan_as_empty : bool
        Write NaN as an empty cell instead of ``nan``.

    Returns
    -------
    str
        The file's text (for an atomic write by the caller).
    """
    out = io.StringIO()
    _write_rows(out, header, rows, nan_as_empty)
    return out.getvalue()


def write_csv(path: str | os.PathLike, header: Sequence[str], rows: Iterable[Sequence[Any]], *,
              nan_as_empty: bool = False) -> Path:
    """Write a CSV file: ``header``, then one line per row, cells by :func:`format_cell`.

    Parameters
    ----------
    path : path-like
        The file to write (replaced if it exists).
    header : sequence of str
        Column names (with their units).
    rows : iterable of sequences
        One sequence of values per row, in the header's order (may be a generator).
    nan_as_empty : bool
        Write NaN as an empty cell instead of ``nan``.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    with path.open("w", newline="", encoding="utf-8") as fh:
        _write_rows(fh, header, rows, nan_as_empty)
    return path


def write_csv_columns(path: str | os.PathLike, header: Sequence[str],
                      columns: Sequence[np.ndarray | Sequence[Any]], *, nan_as_empty: bool = False) -> Path:
    """Write a CSV file given by its columns: the same file as :func:`write_csv` with the rows
    ``zip(*columns)``, each column formatted in one pass (:func:`format_column`).

    Parameters
    ----------
    path : path-like
        The file to write (replaced if it exists).
    header : sequence of str
        Column names (with their units).
    columns : sequence of ndarray (n,) or sequences
        One per name of ``header``, all of the same length (the rows).
    nan_as_empty : bool
        Write NaN as an empty cell instead of ``nan``.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ValueError
        The columns are not one per name, or not all of the same length.
    """
    if len(columns) != len(header):
        raise ValueError(f"{len(columns)} columns for {len(header)} names in the header of {Path(path).name}")
    cells = [format_column(c, nan_as_empty=nan_as_empty) for c in columns]
    if len({len(c) for c in cells}) > 1:
        raise ValueError(f"the columns of {Path(path).name} differ in length: {sorted({len(c) for c in cells})}")
    path = Path(path)
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(header)
        writer.writerows(zip(*cells))
    return path
