"""``rvfem hysteresis``: the transmission-accuracy figures of a case (hysteresis loop, torsional
rigidity, lost motion, hysteresis loss, backlash, where the compliance sits and, on request, the
transmission error over a revolution), written to a directory.

The library part (:func:`accuracy_study`) computes and writes; the command line prints.
"""

from __future__ import annotations

import json
import logging
import math
import os
import time
from pathlib import Path

import numpy as np

from rvfem.app.analysis import default_cache_dir
from rvfem.case.definition import MAX_FRICTION, Case
from rvfem.errors import CaseError
from rvfem.evaluate.accuracy import ARCMIN_PER_RAD, accuracy_figures, mean_loop
from rvfem.geometry import disc_geometry
from rvfem.mesh import mesh_case
from rvfem.outputs import accuracy as files
from rvfem.solve import accuracy
from rvfem.solve.cycle import build_system, case_stage

log = logging.getLogger(__name__)

__all__ = ["LEFT_OUT", "accuracy_study", "mesh_period_angles"]

LEFT_OUT = ("The stage model holds both discs, the pins (Hertz contact at the gaps of the modified profile), "
            "the crank-bearing rollers with their clearance, the crankshafts as beams and their support "
            "bearings. It leaves out the main (output) bearings, the carrier's end plates and pins (the carrier is "
            "rigid), the pin housing (the pins' seats are rigid), the input spur stage (with the input locked the "
            "crankshafts do not turn relative to the carrier) and the rotation of the pins in their grooves. The "
            "output rotation is the carrier rotation of the stage model's torque convention (each disc's torque about "
            "its own centre, the eccentrics turning about the disc centre). Pin friction is Coulomb with full "
            "sliding at every step: it vanishes with the load, so without a clearance the loop has no width at zero "
            "torque. Catalogue rigidity and lost motion are measured on the whole reducer: this model's rigidity is "
            "an upper bound and its lost motion a lower bound.")
"""What the stage model leaves out, for the report and the screen."""


def mesh_period_angles(case: Case, count: int = 9) -> np.ndarray:
    """``count`` crank angles spread over one tooth-mesh period 2π/Zc (rad): the disc's contact
    pattern at θ + 2π/Zc is the one at θ turned by a tooth (docs/theory.md)."""
    if count < 1:
        raise CaseError(f"--angles needs at least 1 crank angle, got {count}")
    return np.arange(count) * 2.0 * math.pi / (count * case.cycloid.teeth)


def _loops(stage, thetas, torque, friction, steps):
    loops = [accuracy.hysteresis_loop(stage, float(t), torque, friction=friction, steps=steps) for t in thetas]
    per_angle = []
    for loop in loops:
        f = accuracy_figures(loop.torque_Nm, loop.rotation_rad, loop.branch, torque)
        per_angle.append({"crank_angle_deg": math.degrees(loop.theta), **f.as_dict()})
    return loops, per_angle


def accuracy_study(case: Case, out_dir: str | os.PathLike, *, torque_Nm: float | None = None,
                   angles_deg: tuple[float, ...] | None = None, angle_count: int = 9, steps: int = 40,
                   friction: float | None = None, te: bool = False, shares: bool = True,
                   cache_dir: str | os.PathLike | None = None) -> dict:
    """Solve the hysteresis loop (and the shares and TE) of ``case`` and write the files to
    ``out_dir``: hysteresis.csv, plots/hysteresis.png, plots/compliance_shares.png, te.csv and
    plots/transmission_error.png (``te``), summary.json and accuracy.md. Returns the summary.

    ``torque_Nm`` defaults to ``loads.torque_Nm`` (the rated torque), ``friction`` to
    ``analysis.friction``; the loop is averaged over ``angles_deg`` or ``angle_count`` crank angles
    of one mesh period (:func:`mesh_period_angles`).
    """
    t_start = time.perf_counter()
    T = float(case.loads.torque_Nm if torque_Nm is None else torque_Nm)
    if not T > 0:
        raise CaseError(f"--torque must be positive (the loop goes to +T and −T), got {T:g}")
    if steps < 8 or steps % 4:
        raise CaseError(f"--steps must be a multiple of 4 and at least 8 (0 → +T → 0 → −T → 0 in equal "
                        f"steps), got {steps}")
    mu = float(case.analysis.friction if friction is None else friction)
    if not 0.0 <= mu <= MAX_FRICTION:
        raise CaseError(f"--friction must be in [0, {MAX_FRICTION:g}] (the range of analysis.friction), got {mu:g}")
    out = Path(out_dir)
    (out / "plots").mkdir(parents=True, exist_ok=True)
    thetas = (np.radians(angles_deg) if angles_deg else mesh_period_angles(case, angle_count))
    timings = {}
    t0 = time.perf_counter()
    geometry = disc_geometry(case)
    mesh = mesh_case(case, default_cache_dir() if cache_dir is None else cache_dir, geometry=geometry)
    stage = case_stage(build_system(case, mesh, geometry=geometry))
    timings["model_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    loops, per_angle = _loops(stage, thetas, T, mu, steps)
    timings["loops_s"] = time.perf_counter() - t0
    torque, branch = loops[0].torque_Nm, loops[0].branch
    rotations = np.array([lp.rotation_rad for lp in loops])
    mean = mean_loop(rotations)
    fig = accuracy_figures(torque, mean, branch, T)
    summary = {"case": case.name, "torque_Nm": T, "friction": mu, "steps": steps,
               "angles_deg": [math.degrees(t) for t in thetas], **fig.as_dict(),
               "per_angle": per_angle, "stage": stage.describe(), "left_out": LEFT_OUT}
    files.write_loop_csv(out / "hysteresis.csv", torque, branch, mean, np.degrees(thetas), rotations)
    files.hysteresis_plot(out / "plots" / "hysteresis.png", torque, branch, mean, fig, T,
                          title=f"{case.name}: hysteresis loop, input locked (mean of {len(thetas)} crank angles)")
    if shares:
        t0 = time.perf_counter()
        cs = accuracy.compliance_shares(stage, float(thetas[0]), T, mu)
        timings["shares_s"] = time.perf_counter() - t0
        summary["compliance_shares"] = {"crank_angle_deg": math.degrees(thetas[0]), "rotation_arcmin": cs.rotation_arcmin,
                                        "shares": cs.shares, "total": cs.total}
        files.shares_plot(out / "plots" / "compliance_shares.png", cs.shares, title=f"{case.name}: where the compliance sits")
    if te:
        t0 = time.perf_counter()
        summary["transmission_error"] = _te(case, stage, T, mu, out)
        timings["te_s"] = time.perf_counter() - t0
    timings["total_s"] = time.perf_counter() - t_start
    summary["timings"] = timings
    (out / "summary.json").write_text(json.dumps(summary, indent=2, allow_nan=False), encoding="utf-8")
    (out / "accuracy.md").write_text(files.accuracy_report(summary), encoding="utf-8")
    return summary


def _te(case: Case, stage, torque: float, friction: float, out: Path) -> dict:
    """The TE over one crank revolution at the case's angle step: te.csv, the plot, the summary part."""
    thetas = np.radians(np.arange(0.0, 360.0, case.analysis.angle_step_deg))
    no_load, loaded = accuracy.transmission_error(stage, thetas, torque, friction)
    files.write_te_csv(out / "te.csv", np.degrees(thetas), no_load, loaded)
    files.te_plot(out / "plots" / "transmission_error.png", np.degrees(thetas), no_load, loaded, torque,
                  title=f"{case.name}: transmission error over one crank revolution")
    arcsec = ARCMIN_PER_RAD * 60.0

    def orders(te):
        return [{"order": k, "amplitude_arcsec": a} for k, a in accuracy.te_orders(te * arcsec, thetas, 6)]

    return {"no_load_peak_to_peak_arcsec": float(np.ptp(no_load) * arcsec),
            "loaded_peak_to_peak_arcsec": float(np.ptp(loaded) * arcsec),
            "loaded_mean_arcsec": float(np.mean(loaded) * arcsec),
            "no_load_orders": orders(no_load), "loaded_orders": orders(loaded)}
