"""The files of ``rvfem wear`` (:mod:`rvfem.app.wear`): wear.csv, the worn flank and pins as tables,
the lost motion over the hours and the wear along the flank and around the pin as plots."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rvfem.outputs.csvfile import write_csv
from rvfem.outputs.figures import new_figure, save_figure

__all__ = ["WEAR_COLUMNS", "write_wear_files"]

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


def write_wear_files(out: Path, records: list[dict], state, kin, case) -> list[Path]:
    """Write wear.csv (one row per geometry update), worn_flank.csv (the wear depth along the flank
    at each pin phase ψ, both flanks), worn_pin.csv (around a pin), plots/lost_motion.png and
    plots/wear_profile.png into ``out``."""
    paths = [write_csv(out / "wear.csv", [h for h, _ in WEAR_COLUMNS],
                       ([r[k] for _, k in WEAR_COLUMNS] for r in records), nan_as_empty=True)]
    psi = np.degrees(kin.psi)
    paths.append(write_csv(out / "worn_flank.csv",
                           ["pin_phase_deg", "disc_radius_mm", "flank_arc_mm", "sliding_coefficient_flank",
                            "sliding_coefficient_pin", "wear_um_positive_torque_flank",
                            "wear_um_negative_torque_flank"],
                           zip(psi, kin.disc_radius, kin.disc_arc, kin.eps_disc, np.minimum(kin.eps_pin, 1e9),
                               1e3 * state.flank[0], 1e3 * state.flank[1])))
    pin_deg = np.linspace(-90.0, 90.0, state.pin.shape[1])
    paths.append(write_csv(out / "worn_pin.csv", ["pin_angle_deg", "wear_um_positive_torque_side",
                                                  "wear_um_negative_torque_side"],
                           zip(pin_deg, 1e3 * state.pin[0], 1e3 * state.pin[1])))
    paths.append(_lost_motion_plot(out / "plots" / "lost_motion.png", records, case))
    paths.append(_profile_plot(out / "plots" / "wear_profile.png", kin, state, pin_deg, case))
    return paths


def _lost_motion_plot(path: Path, records: list[dict], case) -> Path:
    fig = new_figure((7.0, 4.5))
    ax = fig.add_subplot(1, 1, 1)
    h = [r["hours"] for r in records]
    ax.plot(h, [r["lost_motion_arcsec"] for r in records], "o-", label="lost motion (±3 % T)")
    ax.axhline(case.wear.lost_motion_limit_arcsec, color="r", ls="--", label="limit")
    ax.set_xlabel("hours of service")
    ax.set_ylabel("lost motion, arcsec")
    ax.set_title(f"{case.name}: lost motion over the hours of service")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return save_figure(fig, path)


def _profile_plot(path: Path, kin, state, pin_deg, case) -> Path:
    fig = new_figure((10.0, 4.5))
    a, b = fig.subplots(1, 2)
    a.plot(kin.disc_radius, 1e3 * state.flank[0], label="flank of + torque")
    a.plot(kin.disc_radius, 1e3 * state.flank[1], label="flank of − torque")
    a.set_xlabel("radius of the flank point, mm")
    a.set_ylabel("wear depth, µm")
    a.set_title("cycloid flank")
    a.legend()
    b.plot(pin_deg, 1e3 * state.pin[0], label="+ torque side")
    b.plot(pin_deg, 1e3 * state.pin[1], label="− torque side")
    b.set_xlabel("angle on the pin from its inner pole, °")
    b.set_title(f"pin ({case.wear.pin_rolling} rolling)")
    b.legend()
    fig.suptitle(f"{case.name}: wear after {state.hours:.0f} h")
    return save_figure(fig, path)
