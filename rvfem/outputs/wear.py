"""The files of ``rvfem wear`` (:mod:`rvfem.app.wear`): wear.csv, the worn flank and pins as tables,
the lost motion and TE over the hours and the wear along the flank and around the pin as plots, and
a short report (report.md)."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from rvfem.outputs.csvfile import write_csv
from rvfem.outputs.figures import new_figure, save_figure

__all__ = ["WEAR_COLUMNS", "write_wear_files", "write_wear_report"]

WEAR_COLUMNS = (
    ("hours", "hours"), ("lost_motion_arcsec", "lost_motion_arcsec"),
    ("te_peak_to_peak_arcsec", "te_peak_to_peak_arcsec"),
    ("torsional_rigidity_Nm_per_arcmin", "torsional_rigidity_Nm_per_arcmin"),
    ("flank_wear_max_um", "flank_wear_max_um"), ("pin_wear_max_um", "pin_wear_max_um"),
    ("wear_gap_max_um", "wear_gap_max_um"),
    ("crank_bearing_clearance_um", "crank_bearing_clearance_um"),
    ("support_bearing_clearance_um", "support_bearing_clearance_um"),
)
"""wear.csv's columns: (header, record key)."""


def _draw_here(function: Callable, *args) -> None:
    function(*args)


def write_wear_files(out: Path, records: list[dict], state, kin, case, profile, pin_gap,
                     draw: Callable = _draw_here) -> list[Path]:
    """Write wear.csv (one row per geometry update), worn_flank.csv (one tooth space of the profile
    at each pin phase ψ: the profile parameter, the nominal and worn points, the flank's depth, the
    pin's depth at the same contact and their sum, the FE gap added there, and the sliding
    coefficients), worn_pin.csv (around a pin), plots/lost_motion.png (lost motion and TE over the
    hours) and plots/wear_profile.png into ``out``.

    ``profile`` is the :class:`rvfem.evaluate.wear.WornProfile` of the final state, ``pin_gap``
    (2, n) the pin's depth at the contact of each grid phase (rows: +ψ, −ψ), mm. ``draw(function,
    *args)`` draws a plot (here by default; :meth:`rvfem.outputs.plot_worker.PlotWorker.submit` in a
    child process)."""
    paths = [write_csv(out / "wear.csv", [h for h, _ in WEAR_COLUMNS],
                       ([r[k] for _, k in WEAR_COLUMNS] for r in records), nan_as_empty=True)]
    n = len(kin.psi)
    rev = slice(None, None, -1)
    side = np.concatenate([np.full(n, "-"), np.full(n, "+")])
    both = lambda a, b: np.concatenate([np.asarray(b)[rev], np.asarray(a)])   # noqa: E731  (−ψ then +ψ)
    pin_depth = both(pin_gap[0], pin_gap[1])
    rows = zip(np.degrees(profile.psi), side, profile.segment, profile.param, profile.point[:, 0],
               profile.point[:, 1], profile.worn[:, 0], profile.worn[:, 1], 1e3 * profile.depth, 1e3 * pin_depth,
               1e3 * (profile.depth + pin_depth), both(kin.disc_radius, kin.disc_radius),
               both(kin.disc_arc, kin.disc_arc), both(kin.eps_disc, kin.eps_disc),
               np.minimum(both(kin.eps_pin, kin.eps_pin), 1e9))
    paths.append(write_csv(out / "worn_flank.csv",
                           ["pin_phase_deg", "flank_of_torque", "profile_segment", "profile_parameter", "x_mm",
                            "y_mm", "x_worn_mm", "y_worn_mm", "flank_wear_um", "pin_wear_at_contact_um",
                            "gap_added_um", "disc_radius_mm", "flank_arc_mm", "sliding_coefficient_flank",
                            "sliding_coefficient_pin"], rows))
    pin_deg = np.linspace(-90.0, 90.0, state.pin.shape[1])
    paths.append(write_csv(out / "worn_pin.csv", ["pin_angle_deg", "wear_um_positive_torque_side",
                                                  "wear_um_negative_torque_side"],
                           zip(pin_deg, 1e3 * state.pin[0], 1e3 * state.pin[1])))
    draw(_history_plot, out / "plots" / "lost_motion.png", records, case)
    draw(_profile_plot, out / "plots" / "wear_profile.png", kin, state, pin_gap, pin_deg, case)
    return paths + [out / "plots" / "lost_motion.png", out / "plots" / "wear_profile.png"]


def _history_plot(path: Path, records: list[dict], case) -> Path:
    fig = new_figure((7.0, 6.5))
    a, b = fig.subplots(2, 1, sharex=True)
    h = [r["hours"] for r in records]
    a.plot(h, [r["lost_motion_arcsec"] for r in records], "o-", label="lost motion (±3 % T)")
    a.axhline(case.wear.lost_motion_limit_arcsec, color="r", ls="--", label="limit")
    a.set_ylabel("lost motion, arcsec")
    a.set_title(f"{case.name}: accuracy over the hours of service")
    a.grid(True, alpha=0.3)
    a.legend()
    b.plot(h, [r["te_peak_to_peak_arcsec"] for r in records], "s-", color="C1",
           label=f"TE peak to peak over a mesh period at {abs(case.loads.torque_Nm):g} N·m")
    b.set_xlabel("hours of service")
    b.set_ylabel("TE, arcsec")
    b.set_ylim(bottom=0.0)
    b.grid(True, alpha=0.3)
    b.legend()
    return save_figure(fig, path)


def _profile_plot(path: Path, kin, state, pin_gap, pin_deg, case) -> Path:
    fig = new_figure((10.0, 4.5))
    a, b = fig.subplots(1, 2)
    psi = np.degrees(kin.psi)
    a.plot(psi, 1e3 * state.flank[0], label="flank (+ torque)")
    a.plot(psi, 1e3 * state.flank[1], label="flank (− torque)")
    a.plot(psi, 1e3 * (state.flank[0] + pin_gap[0]), "--", label="flank + pin at the contact (+)")
    a.plot(psi, 1e3 * (state.flank[1] + pin_gap[1]), "--", label="flank + pin at the contact (−)")
    a.set_xlabel("pin phase |ψ| of the contact, ° (0: root, 180: tip)")
    a.set_ylabel("wear depth, µm")
    a.set_title("along the flank (every tooth alike)")
    a.legend(fontsize="small")
    b.plot(pin_deg, 1e3 * state.pin[0], label="+ torque side")
    b.plot(pin_deg, 1e3 * state.pin[1], label="− torque side")
    b.set_xlabel("angle on the pin from its inner pole, °")
    b.set_title(f"around a pin ({case.wear.pin_rolling} rolling; every pin alike)")
    b.legend(fontsize="small")
    fig.suptitle(f"{case.name}: wear after {state.hours:.0f} h")
    return save_figure(fig, path)


def _num(x, fmt: str, none: str = "—") -> str:
    return none if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def write_wear_report(out: Path, summary: dict, records: list[dict]) -> Path:
    """report.md of a wear run: the inputs, the life, the accuracy over the hours (a few rows of
    wear.csv), the wear and clearances at the end, the warnings and the files."""
    s = summary
    w = s["wear"]
    life = s["transmission_accuracy_life_h"]
    lines = [f"# Transmission-accuracy life: {s['case']}", "",
             "Archard wear of the cycloid flanks, the pins and the crank and support bearings over the hours "
             "of service; the worn flanks and pins enter the FE gaps of every pin at every crank angle "
             "(docs/theory.md, \"Transmission-accuracy life\").", "",
             "## Inputs", "",
             "| | |", "|---|---|",
             f"| wear coefficient k (flank–pin) | {w['k_flank_pin']:g} mm²/N |",
             f"| pins in their grooves | {w['pin_rolling']} |",
             f"| geometry update step | {w['update_step_um']:g} µm |",
             f"| lost-motion limit | {s['lost_motion_limit_arcsec']:g} arcsec |",
             f"| running-in | {s['running_in']} |",
             "| duty (share, rpm, N·m) | " + "; ".join(f"{a:.3g}, {b:g}, {c:g}" for a, b, c in s["duty"]) + " |",
             "", "## Result", "",
             "| | |", "|---|---|",
             "| transmission-accuracy life | "
             + (f"{life:.0f} h" if life is not None else f"not reached in {s['hours_run']:.0f} h") + " |",
             f"| hours run | {s['hours_run']:.1f} h of {s['hours_asked']:g} h asked, {s['updates']} geometry updates |",
             f"| lost motion | {s['initial_lost_motion_arcsec']:.2f} → {s['final_lost_motion_arcsec']:.2f} arcsec |",
             f"| late growth of lost motion | {_num(s['lost_motion_growth_arcsec_per_h'], '.4f')} arcsec/h |",
             f"| TE peak to peak (a mesh period) | {s['te_peak_to_peak_initial_arcsec']:.2f} → "
             f"{s['te_peak_to_peak_final_arcsec']:.2f} arcsec |",
             "", "## Over the hours", "",
             "| hours | lost motion, arcsec | TE p-p, arcsec | rigidity, N·m/arcmin | flank, µm | pin, µm "
             "| crank brg clearance, µm |", "|---|---|---|---|---|---|---|"]
    pick = sorted(set(np.linspace(0, len(records) - 1, min(len(records), 12)).round().astype(int)))
    for i in pick:
        r = records[i]
        lines.append(f"| {r['hours']:.1f} | {r['lost_motion_arcsec']:.2f} | {r['te_peak_to_peak_arcsec']:.2f} | "
                     f"{r['torsional_rigidity_Nm_per_arcmin']:.1f} | {r['flank_wear_max_um']:.2f} | "
                     f"{r['pin_wear_max_um']:.2f} | {r['crank_bearing_clearance_um']:.4f} |")
    lines += ["", "## Warnings", ""] + ([f"- {x}" for x in s["warnings"]] or ["none"])
    lines += ["", "## Files", "",
              "- `wear.csv`: one row per geometry update", "- `worn_flank.csv`: the worn tooth space (profile "
              "parameter, nominal and worn points, depths, sliding coefficients)",
              "- `worn_pin.csv`: the wear around a pin", "- `plots/lost_motion.png`, `plots/wear_profile.png`",
              "- `summary.json`", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines), encoding="utf-8")
    return path
