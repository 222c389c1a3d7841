"""A result section written outside rvfem, in one module: the torque balance of the load cycle.

Two conservation laws the solver does not impose in this form: the discs sharing the carrier
carry the output torque between them (Σ T_disc = T_out at every crank angle), and the crank
bearings' forces on disc A balance its torque about the reducer axis, about which the carrier turns
(Σ r_i × F_i = T_A, the rollers push through the bore centres r_i = c_i + e·u(θ) from the axis). It adds a key to summary.json, a line to the screen, a row to
the report and a CSV file; a test registers it with one line (``register_section(SECTION)``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rvfem.geometry import crank_centres
from rvfem.outputs.csvfile import write_csv
from rvfem.results.section import KeyRow, Section, SectionWriter, SummaryContext


@dataclass(frozen=True)
class TorqueBalance:
    """The torque balance over the cycle.

    Attributes
    ----------
    theta_deg : ndarray (n,)
        Crank angles, degrees.
    disc_torque_Nmm : ndarray (n, discs)
        Each disc's torque, N·mm.
    bearing_moment_Nmm : ndarray (n,)
        Moment of disc A's bearing forces about the reducer axis, N·mm.
    output_torque_error : float
        max |Σ T_disc − T_out| / T_out.
    bearing_moment_error : float
        max |Σ r_i × F_i − T_A| / T_out.
    """

    theta_deg: np.ndarray
    disc_torque_Nmm: np.ndarray
    bearing_moment_Nmm: np.ndarray
    output_torque_error: float
    bearing_moment_error: float


def compute(inputs: Any) -> TorqueBalance:
    case, cycle = inputs["case"], inputs["cycle"]
    t_out = case.loads.disc_torque_Nmm * case.loads.discs
    discs = (np.full((len(cycle.theta), 1), case.loads.disc_torque_Nmm) if cycle.disc_torque_Nmm is None
             else np.asarray(cycle.disc_torque_Nmm))
    if discs.shape[1] < case.loads.discs:          # one disc modelled: it carries its share
        discs = np.repeat(discs, case.loads.discs, axis=1)
    u = np.stack([np.cos(cycle.theta), np.sin(cycle.theta)], axis=1)
    r = crank_centres(case)[None, :, :] + case.cycloid.eccentricity * u[:, None, :]
    f = np.asarray(cycle.bearing_forces)
    moment = np.sum(r[..., 0] * f[..., 1] - r[..., 1] * f[..., 0], axis=1)
    return TorqueBalance(theta_deg=np.degrees(cycle.theta), disc_torque_Nmm=discs, bearing_moment_Nmm=moment,
                         output_torque_error=float(np.max(np.abs(discs.sum(axis=1) - t_out)) / t_out),
                         bearing_moment_error=float(np.max(np.abs(moment - discs[:, 0])) / t_out))


def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    b = a.extra["torque_balance"]
    return {"torque_balance": {"output_torque_error": b.output_torque_error,
                               "bearing_moment_error": b.bearing_moment_error}}


def screen(s: dict[str, Any]) -> list[str]:
    b = s["torque_balance"]
    return [f"  torque balance: Σ T_disc vs T_out {b['output_torque_error']:.1e}, "
            f"bearing moment vs disc torque {b['bearing_moment_error']:.1e}"]


def report(s: dict[str, Any]) -> list[list[str]]:
    b = s["torque_balance"]
    return [["torque balance (Σ T_disc − T_out, bearing moment − T_A)",
             f"{b['output_torque_error']:.1e}, {b['bearing_moment_error']:.1e} of T_out"]]


def write(a: Any, folder: Path) -> list[Path]:
    b = a.extra["torque_balance"]
    rows = ([t, *d, m] for t, d, m in zip(b.theta_deg, b.disc_torque_Nmm, b.bearing_moment_Nmm))
    header = ["theta_deg", *(f"disc_{k + 1}_torque_Nmm" for k in range(b.disc_torque_Nmm.shape[1])),
              "bearing_moment_Nmm"]
    return [write_csv(Path(folder) / "torque_balance.csv", header, rows)]


SECTION = Section(
    "torque_balance", summary,
    keys=(KeyRow("`torque_balance`", "object", "the load cycle's torque balance (a section from outside rvfem)"),
          KeyRow("`torque_balance.output_torque_error`, `torque_balance.bearing_moment_error`", "float",
                 "max \\|Σ T_disc − T_out\\|/T_out and max \\|Σ r×F − T_A\\|/T_out")),
    requires=("case", "cycle"), compute=compute, screen=screen, screen_rank=32, report=report,
    writers=(SectionWriter("torque_balance_csv", ("torque_balance.csv",), write),))


