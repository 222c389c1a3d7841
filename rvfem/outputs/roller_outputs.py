"""Outputs of the crank bearing in depth: ``roller_pressure.csv`` (p(x) of the worst roller of every
bearing, rigid and flexible) and ``plots/roller_pressure.png``.

The numbers come from :mod:`rvfem.evaluate.roller_life` (``Analysis.roller_depth``); docs/outputs.md
describes the files.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

from rvfem.outputs.plots import COLOURS, _figure, _save
from rvfem.outputs.registry import register_writer

__all__ = ["write_roller_pressure_csv", "roller_pressure_calls", "roller_pressure_plot"]

_COLUMNS = ("bearing", "model", "raceway", "theta_deg", "roller", "roller_load_N", "tilt_mrad", "x_mm",
            "pressure_MPa")


def _depths(analysis):
    depth = getattr(analysis, "roller_depth", None)
    return [] if depth is None else list(depth.rigid) + list(depth.flexible)


@register_writer("roller_pressure_csv", order=15, stage="tables", files=("roller_pressure.csv",))
def write_roller_pressure_csv(analysis, folder: str | os.PathLike) -> list[Path]:
    """Write ``roller_pressure.csv``: the pressure along the roller with the largest slice pressure
    of every bearing and load model (one row per slice); nothing without FE rollers."""
    depths = _depths(analysis)
    if not depths:
        return []
    path = Path(folder) / "roller_pressure.csv"
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(_COLUMNS)
        for d in sorted(depths, key=lambda d: (d.bearing, d.model)):
            for x, p in zip(d.x_mm, d.pressure_MPa):
                writer.writerow([d.bearing + 1, d.model, d.raceway, f"{d.theta_deg:.6g}", d.roller + 1,
                                 f"{d.roller_load_N:.6g}", f"{d.tilt_mrad:.6g}", f"{x:.6g}", f"{p:.6g}"])
    return [path]


def roller_pressure_plot(path: str | os.PathLike, depths, profile: str) -> Path:
    """Draw p(x) of the worst roller of every bearing and model (rigid dashed, flexible solid)."""
    fig = _figure((7.0, 5.0))
    ax = fig.add_subplot(1, 1, 1)
    for d in sorted(depths, key=lambda d: (d.bearing, d.model)):
        ax.plot(d.x_mm, d.pressure_MPa, ls="--" if d.model == "rigid" else "-", color=COLOURS[d.bearing % len(COLOURS)],
                label=f"bearing {d.bearing + 1} {d.model}: {d.raceway}, θ = {d.theta_deg:.0f}°, "
                      f"Q = {d.roller_load_N:.0f} N")
    ax.set_xlabel("x along the roller (mm)")
    ax.set_ylabel("contact pressure (MPa)")
    ax.set_title(f"Pressure along the most loaded roller ({profile} profile, slice model)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)  # below: the curves fill the axes
    fig.tight_layout()
    return _save(fig, path)


def roller_pressure_calls(analysis, plots_folder: str | os.PathLike) -> list[tuple]:
    """The drawing of ``plots/roller_pressure.png`` as a call (:func:`roller_pressure_plot`, keyword
    arguments) for :func:`rvfem.outputs.summary.plot_calls`, so that a render worker's child process
    draws it beside the other plots; none without FE rollers."""
    depths = _depths(analysis)
    if not depths:
        return []
    return [(roller_pressure_plot, dict(path=Path(plots_folder) / "roller_pressure.png", depths=depths,
                                        profile=analysis.case.crank_bearing.profile.kind))]
