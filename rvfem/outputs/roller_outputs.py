"""Outputs of the crank bearing in depth: ``roller_pressure.csv`` (p(x) of the worst roller of every
bearing, rigid and flexible) and ``plots/roller_pressure.png``; ``roller_damage.csv`` (the lamina
damage along each raceway of every bearing, rigid and flexible: where spalling starts) and
``plots/roller_damage.png``.

The numbers come from :mod:`rvfem.evaluate.roller_life` (``Analysis.roller_depth``); docs/outputs.md
describes the files.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from rvfem.evaluate.roller_life import BearingDepth
from rvfem.outputs.csvfile import write_csv
from rvfem.outputs.figures import new_figure, save_figure
from rvfem.outputs.plots import COLOURS
from rvfem.outputs.registry import register_writer

__all__ = ["write_roller_pressure_csv", "roller_pressure_calls", "roller_pressure_curves", "roller_pressure_plot",
           "write_roller_damage_csv", "roller_damage_rows", "roller_damage_curves", "roller_damage_plot",
           "roller_damage_calls", "DAMAGE_COLUMNS"]

_COLUMNS = ("bearing", "model", "raceway", "theta_deg", "roller", "roller_load_N", "tilt_mrad", "x_mm",
            "pressure_MPa")


DAMAGE_COLUMNS = ("bearing", "model", "x_mm", "width_mm", "eccentric_damage_per_h", "bore_damage_per_h",
                  "eccentric_damage_per_h_mm", "bore_damage_per_h_mm")
"""Columns of ``roller_damage.csv`` (docs/outputs.md)."""


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
    rows = ([d.bearing + 1, d.model, d.raceway, d.theta_deg, d.roller + 1, d.roller_load_N, d.tilt_mrad, x, p]
            for d in sorted(depths, key=lambda d: (d.bearing, d.model)) for x, p in zip(d.x_mm, d.pressure_MPa))
    write_csv(path, _COLUMNS, rows)
    return [path]


def _same_curve(a, b) -> bool:
    """Whether two pressure curves draw as one: the same raceway, slices and pressures to 1e-6 of
    the peak (bearings that carry the same loads 360°/N apart, N-fold symmetry)."""
    if a.raceway != b.raceway or len(a.x_mm) != len(b.x_mm):
        return False
    scale = 1e-6 * max(float(np.max(np.abs(a.pressure_MPa))), 1e-300)
    return bool(np.allclose(a.x_mm, b.x_mm, rtol=0, atol=1e-9) and
                np.allclose(a.pressure_MPa, b.pressure_MPa, rtol=0, atol=scale) and
                abs(a.roller_load_N - b.roller_load_N) <= 1e-6 * max(abs(a.roller_load_N), 1e-300))


def roller_pressure_curves(depths: Iterable[BearingDepth]) -> list[tuple[str, BearingDepth]]:
    """The curves of ``roller_pressure.png``: (legend label, depth drawn) per model and run of
    bearings whose curves are the same (:func:`_same_curve`), which would be drawn over each
    other: one curve labelled ``bearings 1–3 (identical) …`` with the crank angle of each."""
    curves: list[tuple[list[BearingDepth], BearingDepth]] = []
    for d in sorted(depths, key=lambda d: (d.model, d.bearing)):
        if curves and curves[-1][1].model == d.model and _same_curve(curves[-1][1], d):
            curves[-1][0].append(d)
        else:
            curves.append(([d], d))
    out = []
    for group, d in sorted(curves, key=lambda c: (c[1].bearing, c[1].model)):
        if len(group) > 1:
            who = f"bearings {group[0].bearing + 1}–{group[-1].bearing + 1} (identical)"
            when = "θ = " + ", ".join(f"{g.theta_deg:.0f}" for g in group) + "°"
        else:
            who, when = f"bearing {d.bearing + 1}", f"θ = {d.theta_deg:.0f}°"
        out.append((f"{who} {d.model}: {d.raceway}, {when}, Q = {d.roller_load_N:.0f} N", d))
    return out


def roller_pressure_plot(path: str | os.PathLike, depths: Iterable[BearingDepth], profile: str) -> Path:
    """Draw p(x) of the worst roller of every bearing and model (rigid dashed, flexible solid);
    bearings with the same curve share one, labelled so (:func:`roller_pressure_curves`)."""
    curves = roller_pressure_curves(depths)
    fig = new_figure((7.0, 4.6 + 0.22 * len(curves)))
    ax = fig.add_subplot(1, 1, 1)
    for label, d in curves:
        ax.plot(d.x_mm, d.pressure_MPa, ls="--" if d.model == "rigid" else "-", color=COLOURS[d.bearing % len(COLOURS)],
                label=label)
    ax.set_xlabel("x along the roller (mm)")
    ax.set_ylabel("contact pressure (MPa)")
    ax.set_title(f"Pressure along the roller of the highest pressure\n({profile} profile, slice model)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=1,   # below: the curves fill the axes
              title="dashed: rigid loads, solid: flexible (FE) loads", title_fontsize=7)
    fig.tight_layout()
    return save_figure(fig, path)


def roller_pressure_calls(analysis, plots_folder: str | os.PathLike) -> list[tuple]:
    """The drawing of ``plots/roller_pressure.png`` as a call (:func:`roller_pressure_plot`, keyword
    arguments) for :func:`rvfem.outputs.summary.plot_calls`, so that a render worker's child process
    draws it beside the other plots; none without FE rollers."""
    depths = _depths(analysis)
    if not depths:
        return []
    return [(roller_pressure_plot, dict(path=Path(plots_folder) / "roller_pressure.png", depths=depths,
                                        profile=analysis.case.crank_bearing.profile.kind))]


def roller_damage_rows(depths: Iterable[BearingDepth]) -> list[list]:
    """The rows of ``roller_damage.csv``: per bearing and load model (rigid first) one row per
    lamina: its centre and width (mm), its damage per hour on the eccentric and on the bore
    (Palmgren–Miner over the cycle; the rows of a bearing and model sum to 1/L10r_h) and the same
    per mm of roller (the damage's density along the roller, independent of the laminae's widths)."""
    rows = []
    for d in sorted(depths, key=lambda d: (d.bearing, d.model)):
        if d.damage_per_h is None or d.slice_width_mm is None:
            continue
        ecc, bore = d.damage_per_h
        for x, w, de, db in zip(d.x_mm, d.slice_width_mm, ecc, bore):
            rows.append([d.bearing + 1, d.model, x, w, de, db, de / w, db / w])
    return rows


@register_writer("roller_damage_csv", order=16, stage="tables", files=("roller_damage.csv",))
def write_roller_damage_csv(analysis, folder: str | os.PathLike) -> list[Path]:
    """Write ``roller_damage.csv``: the lamina damage along each raceway of every bearing and load
    model (:func:`roller_damage_rows`); nothing without FE rollers."""
    rows = roller_damage_rows(_depths(analysis))
    if not rows:
        return []
    path = Path(folder) / "roller_damage.csv"
    write_csv(path, DAMAGE_COLUMNS, rows)
    return [path]


def _same_damage(a: BearingDepth, b: BearingDepth) -> bool:
    """Whether two bearings' damage curves draw as one (to 1e-6 of the largest; N-fold symmetry)."""
    if a.damage_per_h is None or b.damage_per_h is None or a.damage_per_h.shape != b.damage_per_h.shape:
        return False
    scale = 1e-6 * max(float(np.max(a.damage_per_h)), 1e-300)
    return bool(np.allclose(a.damage_per_h, b.damage_per_h, rtol=0, atol=scale))


def roller_damage_curves(depths: Iterable[BearingDepth]) -> list[tuple[str, BearingDepth]]:
    """The curves of ``roller_damage.png``: (legend label, depth drawn) per model and run of
    bearings with the same damage (one curve labelled ``bearings 1–3 (identical)``)."""
    groups: list[list[BearingDepth]] = []
    for d in sorted((d for d in depths if d.damage_per_h is not None), key=lambda d: (d.model, d.bearing)):
        if groups and groups[-1][0].model == d.model and _same_damage(groups[-1][0], d):
            groups[-1].append(d)
        else:
            groups.append([d])
    out = []
    for group in sorted(groups, key=lambda g: (g[0].bearing, g[0].model)):
        d = group[0]
        who = (f"bearings {group[0].bearing + 1}–{group[-1].bearing + 1} (identical)" if len(group) > 1
               else f"bearing {d.bearing + 1}")
        life = "∞" if not np.isfinite(d.L10r_h) else f"{d.L10r_h:.0f}"
        out.append((f"{who} {d.model}: L10r {life} h", d))
    return out


def roller_damage_plot(path: str | os.PathLike, depths: Iterable[BearingDepth], profile: str,
                       length_mm: float) -> Path:
    """Draw the lamina damage per length along the roller on the eccentric (top) and the bore
    (bottom) of every bearing and model (rigid dashed, flexible solid; piecewise constant over the
    laminae), the ends of the effective length dotted."""
    curves = roller_damage_curves(depths)
    fig = new_figure((7.0, 6.2 + 0.22 * len(curves)))
    axes = fig.subplots(2, 1, sharex=True)
    for r, (ax, name) in enumerate(zip(axes, ("eccentric (inner raceway)", "bore (outer raceway)"))):
        for label, d in curves:
            assert d.damage_per_h is not None and d.slice_width_mm is not None
            edges = np.concatenate([d.x_mm - 0.5 * d.slice_width_mm, d.x_mm[-1:] + 0.5 * d.slice_width_mm[-1:]])
            ax.stairs(1e6 * d.damage_per_h[r] / d.slice_width_mm, edges, ls="--" if d.model == "rigid" else "-",
                      color=COLOURS[d.bearing % len(COLOURS)], label=label if r == 0 else None)
        for end in (-0.5 * length_mm, 0.5 * length_mm):
            ax.axvline(end, color="0.6", ls=":", lw=0.8)
        ax.set_ylabel("damage per mm\nper 10⁶ h of operation")
        ax.set_title(name, fontsize=9)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("x along the roller (mm; dotted: ends of the effective length)")
    fig.suptitle(f"Lamina damage along the roller: where spalling starts\n({profile} profile, ISO/TS 16281 "
                 f"laminae, Palmgren–Miner over the cycle)", fontsize=10)
    fig.legend(fontsize=7, loc="lower center", ncol=1, title="dashed: rigid loads, solid: flexible (FE) loads",
               title_fontsize=7)
    fig.tight_layout(rect=(0.0, 0.03 + 0.03 * len(curves), 1.0, 1.0))
    return save_figure(fig, path)


def roller_damage_calls(analysis, plots_folder: str | os.PathLike) -> list[tuple]:
    """The drawing of ``plots/roller_damage.png`` as a call (:func:`roller_damage_plot`, keyword
    arguments) for :func:`rvfem.outputs.summary.plot_calls`; none without FE rollers."""
    depths = [d for d in _depths(analysis) if d.damage_per_h is not None]
    if not depths:
        return []
    return [(roller_damage_plot, dict(path=Path(plots_folder) / "roller_damage.png", depths=depths,
                                      profile=analysis.case.crank_bearing.profile.kind,
                                      length_mm=analysis.case.crank_bearing.roller_length))]
