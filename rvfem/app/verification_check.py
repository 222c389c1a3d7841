"""A row and a section of the verification manual, how their numbers are printed, and the fixed
inputs of its checks (the shipped case files with coarse mesh overrides, the crank-angle step).

The rows are computed by :mod:`rvfem.app.verification_closed_form` and
:mod:`rvfem.app.verification_chain` and written by :mod:`rvfem.app.verification`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rvfem.case.definition import load_case
from rvfem.evaluate.rigid import load_cycle_angles

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"
COARSE_MESH = ("mesh.size_flank=0.6", "mesh.size_bore=0.6", "mesh.size_interior=4", "mesh.size_hole=0.8")
STEP_DEG = 10.0
ROUND_OFF = 1e-12
"""Relative errors below this (or below the check's tolerance, if smaller) are round-off and printed
as the bound ``< 1e-12`` (:func:`noise_bound`)."""

NOISE_FLOOR = 1e-6
"""Relative errors below this (or below the check's tolerance, if smaller) and above
:data:`ROUND_OFF` are printed as the bound ``< 1e-06`` (:func:`noise_bound`).

The relative errors of the checks fall in three groups, decades apart (measured on the shipped
manual): round-off of an identity evaluated directly, 0 to 8e-16 (one 5.6e-14); round-off
amplified by a solve (iterative pair solves, a stiff limit of 1e14 N/mm, a sum of 2e5 trapezoids),
2.9e-11 to 3.3e-9, whose digits differ between machines (one printed 3.2e-09 where another printed
3.3e-09); and the accuracy of a discretisation or a model against a closed form, 2e-6 and above,
the same on every machine to the digits printed. The bounds lie between the groups, more than a
decade from every noise-level error (5.6e-14 and 2.9e-11 around 1e-12; 3.3e-9 below 1e-6, 1.8e-10
below a tolerance of 1e-8), so that no error flips between a figure and a bound from one machine to
the next; the accuracy error nearest a bound (2e-6) is a model's and does not move."""


@dataclass(frozen=True)
class Check:
    """One row of the manual.

    Attributes
    ----------
    quantity : str
        What is compared, with its unit.
    source : str
        Where the reference value comes from (a paper, a textbook, a closed form, a limit).
    reference, value : float or str
        The reference value and rvfem's value (a string for a statement such as "0 (exact)").
    error : float
        The measured error, in the sense of ``error_kind``.
    tolerance : float
        The largest error accepted (the test suite's tolerance for the same check).
    error_kind : str
        ``"relative"``, ``"absolute"`` (in the quantity's unit), ``"rate"`` (difference of a
        convergence order) or ``"relative to F_max"``.
    """

    quantity: str
    source: str
    reference: float | str
    value: float | str
    error: float
    tolerance: float
    error_kind: str = "relative"

    @property
    def passed(self) -> bool:
        return bool(abs(self.error) <= self.tolerance)


@dataclass(frozen=True)
class Section:
    """A rung of the validation ladder: a title, what it checks, its rows and what is pending."""

    title: str
    text: str
    checks: tuple[Check, ...]
    pending: tuple[str, ...] = ()


def _number(x, digits: int = 6) -> str:
    if isinstance(x, str):
        return x
    x = float(x)
    if x == 0.0:
        return "0"
    if not math.isfinite(x):
        return str(x)
    return f"{x:.{digits}g}"


def noise_bound(check: Check, error: float | None = None) -> float | None:
    """The bound a noise-level ``error`` (default the check's) is printed as, None if it is printed
    as a figure: for the relative error kinds (``relative``, ``relative to F_max``) below
    min(:data:`ROUND_OFF`, tolerance) that bound, else below min(:data:`NOISE_FLOOR`, tolerance)
    that one. Never above the tolerance: a bound is a pass. An absolute error (in the quantity's
    unit) and a rate are always printed as figures."""
    if not check.error_kind.startswith("relative") or check.tolerance <= 0:
        return None
    e = abs(check.error if error is None else float(error))
    for floor in (ROUND_OFF, NOISE_FLOOR):
        if e < min(floor, check.tolerance):
            return min(floor, check.tolerance)
    return None


def _error(check: Check) -> str:
    bound = noise_bound(check)
    return f"{abs(check.error):.2g}" if bound is None else f"< {bound:.0e}"


def _case(name: str, *overrides: str):
    return load_case(CASES / f"{name}.toml", COARSE_MESH + overrides if "fanholes" in name else
                     tuple(o for o in COARSE_MESH if "size_hole" not in o) + overrides)


def _thetas() -> np.ndarray:
    return load_cycle_angles(STEP_DEG)
