"""Files of ``rvfem hysteresis``: the loop's table and picture, the compliance shares' bar chart,
the transmission error's table and picture, and the short markdown report.

Matplotlib is imported only inside the figure factory (:func:`rvfem.outputs.figures.new_figure`).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from rvfem.evaluate.accuracy import ARCMIN_PER_RAD, LOST_MOTION_FRACTION
from rvfem.outputs.csvfile import write_csv
from rvfem.outputs.figures import new_figure, save_figure
from rvfem.units import ARCSEC_PER_RAD

__all__ = ["accuracy_report", "hysteresis_plot", "shares_plot", "te_plot", "write_loop_csv", "write_te_csv"]

BRANCH_NAMES = ("loading +", "unloading +", "loading -", "unloading -")


def write_loop_csv(path: str | os.PathLike, torque_Nm: np.ndarray, branch: np.ndarray, rotation_rad: np.ndarray,
                   angles_deg: np.ndarray, per_angle_rad: np.ndarray) -> Path:
    """``hysteresis.csv``: one row per load step: step, branch, torque (N·m), the rotation of the
    averaged loop (arcmin) and the rotation at each crank angle (arcmin)."""
    header = (["step", "branch", "torque_Nm", "rotation_arcmin"]
              + [f"rotation_arcmin_at_{a:g}deg" for a in angles_deg])
    rows = ([i, BRANCH_NAMES[int(b)], t, r * ARCMIN_PER_RAD] + [x * ARCMIN_PER_RAD for x in per_angle_rad[:, i]]
            for i, (t, b, r) in enumerate(zip(torque_Nm, branch, rotation_rad)))
    return write_csv(path, header, rows)


def hysteresis_plot(path: str | os.PathLike, torque_Nm: np.ndarray, branch: np.ndarray, rotation_rad: np.ndarray,
                    figures, rated_torque_Nm: float, *, title: str = "") -> Path:
    """The loop (rotation in arcmin across, torque up) with the catalogue's constructions: the
    rigidity's b/a secant on the loading branch between 3 % and 100 % of the torque, the
    centreline points at ±3 % whose distance is the lost motion, and the width at zero torque."""
    fig = new_figure((7.0, 5.0))
    ax = fig.add_subplot(111)
    phi = np.asarray(rotation_rad) * ARCMIN_PER_RAD
    for k, style in enumerate(("-", "--", "-", "--")):
        sel = branch == k
        ax.plot(phi[sel], torque_Nm[sel], style, color="tab:blue" if k < 2 else "tab:orange", marker=".",
                label=BRANCH_NAMES[k])
    (t0, p0), (t1, p1) = figures.rigidity_points
    ax.plot([p0, p1], [t0, t1], ":", color="k", lw=1.5,
            label=f"rigidity b/a = {figures.torsional_rigidity_Nm_per_arcmin:.1f} N·m/arcmin")
    ax.annotate("", xy=(p1, t0), xytext=(p0, t0), arrowprops={"arrowstyle": "<->", "color": "k"})
    ax.text(0.5 * (p0 + p1), t0, " a", va="bottom", ha="center")
    ax.annotate("", xy=(p1, t1), xytext=(p1, t0), arrowprops={"arrowstyle": "<->", "color": "k"})
    ax.text(p1, 0.5 * (t0 + t1), " b", va="center", ha="left")
    (tp, mp), (tm, mm) = figures.lost_motion_points
    ax.plot([mm, mp], [tm, tp], "o-", color="tab:red", ms=5,
            label=f"lost motion (±{LOST_MOTION_FRACTION:.0%} T) = {figures.lost_motion_arcmin:.3f} arcmin")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axvline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel("output rotation, arcmin")
    ax.set_ylabel("output torque, N·m")
    ax.set_title(title or f"hysteresis loop, input locked, ±{rated_torque_Nm:g} N·m")
    ax.text(0.02, 0.98, f"hysteresis loss {figures.hysteresis_loss_arcmin:.4f} arcmin\n"
            f"backlash {figures.backlash_arcmin:.4f} arcmin", transform=ax.transAxes, va="top", fontsize=8)
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    return save_figure(fig, path)


def shares_plot(path: str | os.PathLike, shares: dict, *, title: str = "") -> Path:
    """Bar chart of the compliance shares (fractions of the loop's elastic rotation)."""
    fig = new_figure((7.0, 3.6))
    ax = fig.add_subplot(111)
    names = list(shares)
    values = [100.0 * shares[n] for n in names]
    ax.barh(names[::-1], values[::-1], color="tab:blue")
    for y, v in enumerate(values[::-1]):
        ax.text(v, y, f" {v:.1f} %", va="center", fontsize=8)
    ax.set_xlabel("share of the output rotation between 3 % and 100 % of the torque, %")
    ax.set_title(title or "where the compliance sits (each component stiffened ×1000 in turn)")
    ax.set_xlim(0, max(values + [1.0]) * 1.2)
    fig.tight_layout()
    return save_figure(fig, path)


def write_te_csv(path: str | os.PathLike, theta_deg: np.ndarray, no_load_rad: np.ndarray, loaded_rad: np.ndarray
                 ) -> Path:
    """``te.csv``: crank angle (deg), the no-load (kinematic) and the loaded TE (arcsec)."""
    arcsec = ARCSEC_PER_RAD
    rows = ([t, a * arcsec, b * arcsec] for t, a, b in zip(theta_deg, no_load_rad, loaded_rad))
    return write_csv(path, ["crank_angle_deg", "te_no_load_arcsec", "te_loaded_arcsec"], rows)


def te_plot(path: str | os.PathLike, theta_deg: np.ndarray, no_load_rad: np.ndarray, loaded_rad: np.ndarray,
            torque_Nm: float, *, title: str = "") -> Path:
    """TE over one crank revolution (one output pin pitch), each about its mean, arcsec."""
    fig = new_figure((7.0, 4.0))
    ax = fig.add_subplot(111)
    arcsec = ARCSEC_PER_RAD
    for te, label in ((no_load_rad, "no load (kinematic)"), (loaded_rad, f"at {torque_Nm:g} N·m")):
        te = np.asarray(te) * arcsec
        ax.plot(theta_deg, te - te.mean(), label=f"{label}: p-p {np.ptp(te):.3f} arcsec, mean {te.mean():.2f} arcsec "
                                                 "(subtracted)")
    ax.set_xlabel("crank angle, ° (one revolution = one output pin pitch)")
    ax.set_ylabel("TE − its mean, arcsec")
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 60))
    ax.set_title(title or "transmission error θ_out − θ_in/i")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)  # below: not over the curves
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    return save_figure(fig, path)


def _fmt(v, digits: int = 4) -> str:
    return "—" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.{digits}g}"


def accuracy_report(summary: dict) -> str:
    """The markdown report of ``rvfem hysteresis`` from its summary."""
    s = summary
    lines = [f"# Transmission accuracy: {s['case']}", "",
             f"Hysteresis loop with the input locked, output torque 0 → +{s['torque_Nm']:g} → 0 → "
             f"−{s['torque_Nm']:g} → 0 N·m in {s['steps']} load steps, pin friction μ = {s['friction']:g}, "
             f"averaged over {len(s['angles_deg'])} crank angles ({', '.join(f'{a:.2f}' for a in s['angles_deg'])}°).",
             "", "| figure | value | definition |", "|---|---|---|",
             f"| torsional rigidity | {_fmt(s['torsional_rigidity_Nm_per_arcmin'])} N·m/arcmin | b/a of the loading "
             "branches between 3 % and 100 % of the torque |",
             f"| lost motion | {_fmt(s['lost_motion_arcmin'])} arcmin | width of the loop's centreline between ±3 % |",
             f"| hysteresis loss | {_fmt(s['hysteresis_loss_arcmin'])} arcmin | width of the loop at zero torque |",
             f"| backlash | {_fmt(s['backlash_arcmin'])} arcmin | jump of the rotation at a zero crossing |", "",
             "Per crank angle:", "", "| crank angle ° | rigidity N·m/arcmin | lost motion arcmin | "
             "hysteresis loss arcmin |", "|---|---|---|---|"]
    for a in s["per_angle"]:
        lines.append(f"| {a['crank_angle_deg']:.2f} | {_fmt(a['torsional_rigidity_Nm_per_arcmin'])} | "
                     f"{_fmt(a['lost_motion_arcmin'])} | {_fmt(a['hysteresis_loss_arcmin'])} |")
    shares = s.get("compliance_shares")
    if shares:
        lines += ["", f"## Where the compliance sits (crank angle {shares['crank_angle_deg']:.2f}°)", "",
                  f"Output rotation between 3 % and 100 % of the torque: {shares['rotation_arcmin']:.4f} arcmin. "
                  "Each component stiffened ×1000 in turn; its share is the part of that rotation that goes.", "",
                  "| component | share |", "|---|---|"]
        lines += [f"| {k} | {100 * v:.1f} % |" for k, v in shares["shares"].items()]
        lines += [f"| sum | {100 * shares['total']:.1f} % (100 % for compliances in series; the rest, "
                  f"{100 * (shares['total'] - 1):+.1f} %, is the interaction of the parts: stiffening one moves load "
                  "between parallel paths and changes which contacts carry) |", "", "![shares](plots/compliance_shares.png)"]
    te = s.get("transmission_error")
    if te:
        lines += ["", "## Transmission error over one crank revolution", "",
                  f"No load (kinematic): peak-to-peak {te['no_load_peak_to_peak_arcsec']:.4f} arcsec; at "
                  f"{s['torque_Nm']:g} N·m: {te['loaded_peak_to_peak_arcsec']:.4f} arcsec.", "",
                  "Largest orders (per crank revolution) of the loaded TE: "
                  + ", ".join(f"{o['order']} ({o['amplitude_arcsec']:.4f} arcsec)" for o in te["loaded_orders"]),
                  "", "![TE](plots/transmission_error.png)"]
    if s.get("warnings"):   # the range warnings of rvfem run at the loop's torque
        lines += ["", "## Warnings at the loop's torque", ""] + [f"- {w['message']}" for w in s["warnings"]]
    lines += ["", "![loop](plots/hysteresis.png)", "", "## What the model leaves out", "", s["left_out"], ""]
    return "\n".join(lines)
