"""``rvfem wear``'s library part: the transmission-accuracy life of a case, Archard wear of the
flanks, pins and bearings over the hours of service and the lost motion it leaves
(docs/theory.md, "Transmission-accuracy life").

The loop (Liu et al., *Degradation law analysis and life estimation of transmission accuracy of
RV reducer based on tooth surface and bearing wear*, § 2.4 and its Figure 5): the load cycle of
every duty row on the current (worn) stage gives the pin forces along each flank and the bearing
loads; :mod:`rvfem.evaluate.wear` turns them into wear rates per hour of the flank (along the
profile), of the pins (around them) and of the bearings' clearances; the wear runs on until the
largest increment of any part reaches ``wear.update_step_um``; the worn geometry is then applied
and the lost motion solved again, until the hours asked or the lost-motion limit.

**The worn geometry.** Every tooth wears alike, so the wear of the flanks is a function of the
pin phase ψ (:func:`rvfem.geometry.pin_phases`); with the pin's wear at the same contact it is the
disc model's :class:`rvfem.geometry.FlankDeviation`, added to the FE gap of each pin at each crank
angle (element by element, Liu et al.'s tooth-surface update). The bearing wear is added to
``crank_bearing.radial_clearance`` (the mean over the cranks) and ``crank_support.radial_clearance``.
The worn stage shares the disc's factorisation and column compliance: only the gaps and the bearing
laws change (:func:`worn_stage`).
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import os
import time
from dataclasses import dataclass

import numpy as np

from rvfem.app.analysis import default_cache_dir
from rvfem.case.definition import Case
from rvfem.errors import CaseError
from rvfem.evaluate import wear as archard
from rvfem.evaluate.accuracy import quick_figures
from rvfem.evaluate.hertz import composite_modulus
from rvfem.geometry import FlankDeviation, disc_geometry, pin_phases
from rvfem.mesh import mesh_case
from rvfem.outputs import wear as files
from rvfem.outputs.plot_worker import PlotWorker
from rvfem.outputs.summary import result_folder
from rvfem.solve import models
from rvfem.solve.accuracy import loop_at_torques
from rvfem.solve.cycle import OperatingPoint, build_system, case_stage, load_cycle
from rvfem.units import ARCSEC_PER_RAD

log = logging.getLogger(__name__)

__all__ = ["GRID_POINTS", "WearState", "duty_rows", "flank_deviation", "flank_grid", "life_figures", "life_loop",
           "te_peak_to_peak", "wear_life", "wear_option_problem", "wear_rates", "wear_warnings", "worn_stage"]

GRID_POINTS = 361
"""Pin phases ψ per flank (0 < ψ < π) the wear is accumulated on."""

MAX_UPDATES = 2000
"""Bound of the geometry updates of one run."""

WORN_RANGE_MM = 0.05
"""Wear depth beyond which the warning says the model leaves its range (the contact shape, taken
as the unworn one, has changed by a visible part of the pin radius' curvature)."""


@dataclass
class WearState:
    """The accumulated wear (mm): flank and pin depth per flank side (rows 0: ψ > 0, the flanks a
    positive torque loads; 1: the mirror flanks) on the ψ grid, clearance added per crank bearing
    and per crankshaft's support bearings."""

    hours: float
    flank: np.ndarray
    pin: np.ndarray
    crank: np.ndarray
    support: np.ndarray


def wear_option_problem(hours: float, angle_count: int) -> tuple[str, str] | None:
    """The first option of :func:`wear_life` that cannot be used, as ``(parameter, why)``, or None."""
    if not (math.isfinite(hours) and hours > 0):
        return "hours", f"must be a positive number of hours of service, got {hours:g}"
    if angle_count < 1:
        return "angle_count", f"needs at least 1 crank angle for the lost motion, got {angle_count}"
    return None


def duty_rows(case: Case) -> list[tuple[float, float, float]]:
    """(time share normalised, speed rpm, torque N·m) of each duty row (the case's operating point
    without a duty cycle); rows of zero torque wear nothing and are left out."""
    rows = case.loads.duty_cycle
    raw = ([(r.time_share, r.speed_rpm, r.torque_Nm) for r in rows] if rows
           else [(1.0, case.loads.speed_rpm, case.loads.torque_Nm)])
    total = sum(r[0] for r in raw)
    return [(s / total, n, t) for s, n, t in raw if abs(t) > 0]


def flank_deviation(case: Case, state: WearState, kin) -> FlankDeviation:
    """The worn flanks as the disc model's gap deviation (module docstring): at each pin phase of
    the grid, the flank's depth plus the pin's depth at the point of the pin that contact touches
    (mm), for the flanks of either torque."""
    pin_at = kin.pin_angle * case.pins.radius
    nodes = pin_nodes(case)
    g = [state.flank[s] + np.interp(pin_at, nodes, state.pin[s]) for s in range(2)]
    # the flanks of either torque meet at the root (ψ = 0) and the tip (ψ = π): one value there, so
    # that the gap of a pin is continuous in ψ (a pin at ψ = ±0 by round-off gets the same gap)
    root, tip = 0.5 * (g[0][0] + g[1][0]), 0.5 * (g[0][-1] + g[1][-1])
    psi = np.concatenate([[0.0], kin.psi, [math.pi]])
    return FlankDeviation.of(psi, np.concatenate([[root], g[0], [tip]]), np.concatenate([[root], g[1], [tip]]))


def pin_nodes(case: Case) -> np.ndarray:
    """Where the pin's wear is kept: arc length around the pin from its pole facing the pin-circle
    centre, −π/2·r_rp … π/2·r_rp, mm (GRID_POINTS)."""
    return np.linspace(-0.5 * math.pi, 0.5 * math.pi, GRID_POINTS) * case.pins.radius


def _worn_case(case: Case, state: WearState) -> Case:
    """The case with the bearings' worn clearances (the flanks' wear is the disc model's deviation)."""
    bearing = dataclasses.replace(case.crank_bearing,
                                  radial_clearance=case.crank_bearing.radial_clearance + float(state.crank.mean()))
    changes: dict[str, object] = {"crank_bearing": bearing}
    if case.crank_support is not None:
        changes["crank_support"] = dataclasses.replace(
            case.crank_support, radial_clearance=case.crank_support.radial_clearance + float(state.support.mean()))
    return case.replace(**changes)


def worn_stage(system, worn: Case, deviation: FlankDeviation | None):
    """The stage of ``worn`` on the factorised disc of ``system`` (same mesh, model and column
    compliance): the gaps of its profile plus ``deviation``
    (:attr:`rvfem.solve.cycle.DiscSystem.flank_deviation`), the bearing laws of its clearances."""
    bearings = models.bearing_laws(system.bearing_model, worn, system.bearing_stiffness_scale, system.stiffness_scale)
    geometry = system.geometry if worn is system.case else disc_geometry(worn)
    worn_system = dataclasses.replace(system, case=worn, geometry=geometry, bearings=bearings,
                                      contact_sets={}, flank_deviation=deviation)
    return case_stage(worn_system)


def _figures(stage, case: Case, angle_count: int) -> tuple[float, float, float]:
    """Lost motion (arcsec) and torsional rigidity (N·m/arcmin) of the stage at the rated torque,
    the mean over ``angle_count`` crank angles of one tooth-mesh period, and the peak-to-peak
    transmission error (arcsec) at the rated torque over one mesh period (:func:`te_peak_to_peak`)."""
    T = abs(case.loads.torque_Nm)
    thetas = np.arange(angle_count) * 2.0 * math.pi / (angle_count * case.cycloid.teeth)
    figs = [quick_figures(stage, T, case.analysis.friction, float(t)) for t in thetas]
    return (60.0 * float(np.mean([f["lost_motion_arcmin"] for f in figs])),
            float(np.mean([f["torsional_rigidity_Nm_per_arcmin"] for f in figs])),
            te_peak_to_peak(stage, case))


TE_ANGLES = 6
"""Crank angles of one tooth-mesh period at which the loaded transmission error is solved."""


def te_peak_to_peak(stage, case: Case, count: int = TE_ANGLES) -> float:
    """Peak-to-peak transmission error at the rated torque over one tooth-mesh period (2π/Zc of
    crank angle), arcsec: the output rotation of the running stage (pins sliding as the crank
    turns) at +|``loads.torque_Nm``| at ``count`` equally spaced crank angles, one solve each
    (:func:`rvfem.solve.accuracy.loop_at_torques`; Liu et al. § 4: TE = θ_out − θ_in/i, here the
    deviation from the ideal ratio within a mesh period, the part the flank wear can change)."""
    T = abs(case.loads.torque_Nm)
    thetas = np.arange(count) * 2.0 * math.pi / (count * case.cycloid.teeth)
    rot = [float(loop_at_torques(stage, float(t), [T], case.analysis.friction, [0])[0][0]) for t in thetas]
    return float(np.ptp(rot)) * ARCSEC_PER_RAD


def _cycle_samples(cycle, case: Case):
    """Pin phases (wrapped to (−π, π]) and forces (N) of every pin at every crank angle of a cycle."""
    psi = np.concatenate([pin_phases(case, float(t)) for t in cycle.theta])
    return psi, np.asarray(cycle.pin_forces).ravel()


def _support_loads(cycle, case: Case) -> np.ndarray | None:
    """Mean radial load of each crankshaft's support bearings over the cycle, N (half the crank's
    load from both discs), or None without ``[crank_support]``."""
    if case.crank_support is None:
        return None
    if cycle.disc_bearing_forces is not None:
        f = np.asarray(cycle.disc_bearing_forces).sum(axis=1)
    else:
        f = np.asarray(cycle.bearing_forces) * case.loads.discs
    return 0.5 * np.linalg.norm(f, axis=-1).mean(axis=0)


def wear_rates(system_stage, case: Case, kin, duty) -> dict:
    """Wear rates per hour of every part on ``system_stage`` (mm/h) under the ``duty`` rows
    (:func:`duty_rows`): ``flank`` and ``pin`` (2, GRID_POINTS) on the grid ``kin``
    (:func:`flank_grid`; rows +ψ, −ψ), ``crank`` and ``support`` per crankshaft."""
    zp, zc, d = case.pins.count, case.cycloid.teeth, case.pins.count - case.cycloid.teeth
    estar = composite_modulus(case.material.youngs_modulus, case.material.poissons_ratio)
    w = case.wear
    flank, pin = np.zeros((2, GRID_POINTS)), np.zeros((2, GRID_POINTS))
    n_cranks = case.cranks.count
    crank, support = np.zeros(n_cranks), np.zeros(n_cranks)
    for share, speed, torque in duty:
        cycle = load_cycle(system_stage.first, op=OperatingPoint(torque, case.analysis.friction), stage=system_stage)
        psi, force = _cycle_samples(cycle, case)
        crank_revs_h = speed * 60.0 * zp / d                     # crank relative to the carrier
        for s, sel in enumerate((psi >= 0, psi < 0)):
            f = archard.side_force(np.abs(psi[sel]), force[sel], kin.psi)
            dd, pp = archard.flank_pin_engagement(kin, f, k_mm2_per_N=w.k_flank_pin, length_mm=case.cycloid.thickness,
                                                  modulus_MPa=estar, zp=zp, zc=zc, pin_radius=case.pins.radius,
                                                  pin_rolling=w.pin_rolling)
            flank[s] += share * dd * crank_revs_h * d            # one engagement per tooth per pin pitch passed
            pin[s] += share * pp * speed * 60.0 * zc / d          # Zc/d engagements of a pin per output revolution
        radial = np.linalg.norm(np.asarray(cycle.bearing_forces), axis=-1).mean(axis=0)
        crank += share * np.array([archard.bearing_clearance_rate(r, crank_revs_h, w.crank_bearing_rate_um_per_N_Mrev)
                                   for r in radial])
        sup = _support_loads(cycle, case)
        if sup is not None:
            support += share * np.array([archard.bearing_clearance_rate(r, crank_revs_h,
                                                                        w.support_bearing_rate_um_per_N_Mrev)
                                         for r in sup])
    return {"flank": flank, "pin": pin, "crank": crank, "support": support}


def _record(state: WearState, figures: tuple[float, float, float], worn: Case, deviation: FlankDeviation | None
            ) -> dict:
    """One row of wear.csv."""
    lm, rigidity, te = figures
    gap = 0.0 if deviation is None else max(max(deviation.positive), max(deviation.negative))
    return {"hours": state.hours, "lost_motion_arcsec": lm, "te_peak_to_peak_arcsec": te,
            "torsional_rigidity_Nm_per_arcmin": rigidity,
            "flank_wear_max_um": 1e3 * float(state.flank.max()), "pin_wear_max_um": 1e3 * float(state.pin.max()),
            "wear_gap_max_um": 1e3 * gap,
            "crank_bearing_clearance_um": 1e3 * worn.crank_bearing.radial_clearance,
            "support_bearing_clearance_um": (1e3 * worn.crank_support.radial_clearance
                                             if worn.crank_support is not None else None)}


def _advance(state: WearState, rates: dict, step_mm: float, hours_left: float) -> float:
    """Run the wear on by the hours at which the largest increment of any part reaches the step
    (at most ``hours_left``); returns the hours run."""
    fastest = max(float(np.max(rates[k])) for k in ("flank", "pin", "crank", "support"))
    dt = hours_left if fastest <= 0 else min(hours_left, step_mm / fastest)
    state.flank += rates["flank"] * dt
    state.pin += rates["pin"] * dt
    state.crank += rates["crank"] * dt
    state.support += rates["support"] * dt
    state.hours += dt
    return dt


def flank_grid(case: Case) -> archard.MeshKinematics:
    """The kinematics (:func:`rvfem.evaluate.wear.mesh_kinematics`) of the pin phases the wear is
    kept on: GRID_POINTS in (0, π), ends left out."""
    return archard.mesh_kinematics(case.pins.circle_radius, case.pins.radius, case.cycloid.eccentricity,
                                   case.pins.count, case.cycloid.teeth,
                                   np.linspace(0.0, math.pi, GRID_POINTS + 2)[1:-1])


def life_loop(case: Case, stage, system, hours: float, angle_count: int
              ) -> tuple[list[dict], WearState, archard.MeshKinematics]:
    """The loop over life (module docstring): the records of every update, the final state and the
    kinematics of the flank grid."""
    kin = flank_grid(case)
    duty = duty_rows(case)
    if not duty:
        raise CaseError("rvfem wear needs a torque: loads.torque_Nm (or every duty_cycle row's torque) is 0; "
                        "give the torque of the service")
    n = case.cranks.count
    state = WearState(0.0, np.zeros((2, GRID_POINTS)), np.zeros((2, GRID_POINTS)), np.zeros(n), np.zeros(n))
    records = [_record(state, _figures(stage, case, angle_count), case, None)]
    step = 1e-3 * case.wear.update_step_um
    current = stage
    for _ in range(MAX_UPDATES):
        if state.hours >= hours * (1 - 1e-12) or records[-1]["lost_motion_arcsec"] >= case.wear.lost_motion_limit_arcsec:
            break
        rates = wear_rates(current, case, kin, duty)
        _advance(state, rates, step, hours - state.hours)
        worn = _worn_case(case, state)
        deviation = flank_deviation(case, state, kin)
        current = worn_stage(system, worn, deviation)
        records.append(_record(state, _figures(current, case, angle_count), worn, deviation))
        log.info("wear: %.1f h, lost motion %.2f arcsec", state.hours, records[-1]["lost_motion_arcsec"])
    return records, state, kin


def life_figures(records: list[dict], limit: float) -> dict:
    """``transmission_accuracy_life_h`` (the hours at which the lost motion reaches ``limit``,
    linear between updates; None when not reached), the hours run and
    ``lost_motion_growth_arcsec_per_h`` (the least-squares slope over the second half of the hours
    run, or the secant of the last two records)."""
    h = np.array([r["hours"] for r in records])
    lm = np.array([r["lost_motion_arcsec"] for r in records])
    life = None
    above = np.flatnonzero(lm >= limit)
    if above.size:
        i = int(above[0])
        life = 0.0 if i == 0 else float(np.interp(limit, lm[i - 1:i + 1], h[i - 1:i + 1]))
    late = h >= 0.5 * h[-1]
    if late.sum() >= 3:
        slope = float(np.polyfit(h[late], lm[late], 1)[0])
    elif len(h) >= 2 and h[-1] > h[-2]:
        slope = float((lm[-1] - lm[-2]) / (h[-1] - h[-2]))
    else:
        slope = None
    return {"transmission_accuracy_life_h": life, "hours_run": float(h[-1]),
            "lost_motion_growth_arcsec_per_h": slope}


def wear_warnings(state: WearState, case: Case, records: list[dict], hours: float) -> list[str]:
    """Where the wear leaves the model's range, or the run did not resolve what it was asked."""
    out = []
    deepest = max(float(state.flank.max()), float(state.pin.max()))
    if deepest > WORN_RANGE_MM:
        out.append(f"the deepest wear, {1e3 * deepest:.0f} µm, is beyond {1e3 * WORN_RANGE_MM:.0f} µm: the worn depth "
                   "enters the gaps, but the Hertz law and the load footprints keep the unworn flank's curvature and "
                   "position; the results past it are indicative")
    limit = case.wear.lost_motion_limit_arcsec
    lm = [r["lost_motion_arcsec"] for r in records]
    if lm[0] >= limit:
        out.append(f"the lost motion before any wear, {lm[0]:.2f} arcsec, is already at the limit of {limit:g} arcsec "
                   "(wear.lost_motion_limit_arcsec): the life is 0 h")
    elif lm[-1] >= limit and len(records) <= 3:
        out.append(f"the limit is reached within {len(records) - 1} geometry update(s): the life is interpolated "
                   "over few points; a smaller wear.update_step_um resolves it")
    if len(records) - 1 >= MAX_UPDATES and state.hours < hours * (1 - 1e-12) and lm[-1] < limit:
        out.append(f"stopped after {MAX_UPDATES} geometry updates at {state.hours:.0f} h of the {hours:g} h asked; "
                   "a larger wear.update_step_um runs further")
    if case.crank_support is None:
        out.append("no [crank_support]: the support bearings' wear is not modelled")
    return out


RUNNING_IN = ("not modelled: a constant wear coefficient from the first hour (no cited running-in law for the "
              "cycloid–pin pair; docs/theory.md, \"Transmission-accuracy life\")")
"""What the run says about running-in (report.md)."""


def wear_life(case: Case, out_dir: str | os.PathLike, *, hours: float, angle_count: int = 3,
              cache_dir: str | os.PathLike | None = None, overwrite: bool = False) -> dict:
    """Run the wear of ``case`` over ``hours`` of service (or to the lost-motion limit) and write
    wear.csv, worn_flank.csv, worn_pin.csv, plots/lost_motion.png, plots/wear_profile.png, report.md
    and summary.json to ``out_dir`` (an atomic result folder, :func:`rvfem.outputs.summary.result_folder`).
    Returns the summary.

    The lost motion is read at ±3 % of ``loads.torque_Nm`` (its magnitude) with
    :func:`rvfem.evaluate.accuracy.quick_figures`, the mean over ``angle_count`` crank angles of one
    tooth-mesh period; the TE over a mesh period at the rated torque with :func:`te_peak_to_peak`.

    Raises
    ------
    CaseError
        An option cannot be used (:func:`wear_option_problem`), or the duty has no torque.
    OutputError
        ``out_dir`` cannot take the results.
    """
    t0 = time.perf_counter()
    problem = wear_option_problem(hours, angle_count)
    if problem is not None:
        raise CaseError(" ".join(problem))
    if not case.loads.torque_Nm:
        raise CaseError("rvfem wear reads the lost motion at ±3 % of loads.torque_Nm, which is 0; give the rated torque")
    with result_folder(out_dir, overwrite=overwrite, what="wear") as out, \
            PlotWorker("wear plots") as plots:          # Matplotlib imported while the life is solved
        geometry = disc_geometry(case)
        mesh = mesh_case(case, default_cache_dir() if cache_dir is None else cache_dir, geometry=geometry)
        system = build_system(case, mesh, geometry=geometry)
        records, state, kin = life_loop(case, case_stage(system), system, hours, angle_count)
        summary = {"case": case.name, "hours_asked": float(hours),
                   **life_figures(records, case.wear.lost_motion_limit_arcsec),
                   "lost_motion_limit_arcsec": case.wear.lost_motion_limit_arcsec,
                   "initial_lost_motion_arcsec": records[0]["lost_motion_arcsec"],
                   "final_lost_motion_arcsec": records[-1]["lost_motion_arcsec"], "updates": len(records) - 1,
                   "wear": dataclasses.asdict(case.wear), "duty": [list(r) for r in duty_rows(case)],
                   "te_peak_to_peak_initial_arcsec": records[0]["te_peak_to_peak_arcsec"],
                   "te_peak_to_peak_final_arcsec": records[-1]["te_peak_to_peak_arcsec"],
                   "running_in": RUNNING_IN, "warnings": wear_warnings(state, case, records, hours)}
        pin_at = kin.pin_angle * case.pins.radius
        pin_gap = np.array([np.interp(pin_at, pin_nodes(case), state.pin[s]) for s in range(2)])
        profile = archard.worn_profile(geometry, kin.psi, state.flank[0], state.flank[1])
        files.write_wear_files(out, records, state, kin, case, profile, pin_gap, draw=plots.submit)
        plots.wait()
        summary["timings"] = {"total_s": time.perf_counter() - t0}
        files.write_wear_report(out, summary, records)
        (out / "summary.json").write_text(json.dumps(summary, indent=2, allow_nan=False), encoding="utf-8")
    return summary

