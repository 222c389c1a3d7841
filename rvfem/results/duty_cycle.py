"""The duty-cycle service life (Palmgren–Miner) from the rigid and the flexible lives, and the
flexible FE at every duty-cycle torque."""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from typing import Any

import numpy as np

from rvfem.errors import ContactError
from rvfem.evaluate import iso281
from rvfem.evaluate.rigid import equivalent_load
from rvfem.results.analysis import DutyCycleFE, DutyCycleResult
from rvfem.solve import cycle as cycle_module

log = logging.getLogger(__name__)

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'compute', 'duty_cycle_fe', 'summary']

def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    if a.duty_cycle is None:
        return {}
    fe = a.duty_cycle.flexible_fe
    return {"duty_cycle": {
        "rigid": None if a.duty_cycle.rigid is None else dataclasses.asdict(a.duty_cycle.rigid),
        "flexible": dataclasses.asdict(a.duty_cycle.flexible),
        "flexible_fe": None if fe is None else {
            "torques_Nm": list(fe.torques_Nm),
            "equivalent_load_N": [list(row) for row in fe.equivalent_load_N],
            "linear_scaling_error_percent": list(fe.linear_scaling_error_percent),
            "service_life_h": fe.service_life_h,
            "life_difference_percent": fe.life_difference_percent,
            "seconds": fe.seconds,
        },
    }}


def duty_cycle_fe(system: Any, thetas: np.ndarray, cycle: Any, comparison: Any, linear_life_h: float) -> DutyCycleFE:
    """Solve the flexible load cycle at every distinct positive duty-cycle torque of the case and
    the service life from those loads (:class:`DutyCycleFE`; sources: ISO 281 life, Gao et al.
    eqs. 16-18 with the FE loads in place of the linear scaling).

    Parameters
    ----------
    system : rvfem.solve.cycle.DiscSystem
        The case's disc model (its compliance is reused).
    thetas : ndarray
        Crank angles, rad (those of ``cycle``).
    cycle : rvfem.solve.cycle.CycleResult
        The cycle at the case's own torque (reused for a duty row at that torque).
    comparison : rvfem.evaluate.compare.Comparison
        Its comparison (F_m at the case's torque).
    linear_life_h : float
        The linear-scaling service life, hours.
    """

    t0 = time.perf_counter()
    case = system.case
    rows = case.loads.duty_cycle
    rated_T = case.loads.torque_Nm
    torques = sorted({float(r.torque_Nm) for r in rows if r.torque_Nm > 0})
    rated_fm = [b.flexible.equivalent_N for b in comparison.bearings]
    fm: dict[float, list[float]] = {}
    for torque in torques:
        if math.isclose(torque, rated_T, rel_tol=1e-12):
            fm[torque] = rated_fm
            continue
        # the same system at another operating point: no new factorisation, the compliance
        # columns and contact sets of the case's cycle reused
        op = cycle_module.OperatingPoint(torque, case.analysis.friction)
        cyc = cycle_module.load_cycle(system, thetas, op=op, saved_angles_deg=())
        fm[torque] = [float(equivalent_load(f, case.analysis.equivalent_load_exponent))
                      for f in cyc.bearing_loads.T]
    errors = tuple(100.0 * max((f / (f0 * t / rated_T) - 1.0 for f, f0 in zip(fm[t], rated_fm)), key=abs)
                   for t in torques)
    rating = iso281.crank_bearing_rating(case.crank_bearing)
    total = sum(r.time_share for r in rows)
    lives = []
    for i in range(len(rated_fm)):
        damage = 0.0  # Σ s_i / L_i, 1/h
        for r in rows:
            if r.torque_Nm <= 0:
                continue
            n_b = iso281.bearing_speed_rpm(r.speed_rpm, case.pins.count, case.cycloid.teeth)
            life = iso281.rating_life_hours(rating, fm[float(r.torque_Nm)][i], n_b)
            # a life that underflows to 0 h is infinite damage, not a division by zero
            damage += (r.time_share / total) / life if life > 0 else math.inf
        lives.append(math.inf if damage == 0 else 1.0 / damage)
    return DutyCycleFE(torques_Nm=tuple(torques), equivalent_load_N=tuple(tuple(fm[t]) for t in torques),
                       linear_scaling_error_percent=errors, service_life_h=min(lives),
                       linear_scaling_life_h=linear_life_h, seconds=time.perf_counter() - t0)


def compute(inputs: Any) -> DutyCycleResult:
    """The duty-cycle service lives from the rigid and the flexible lives (linear scaling with the
    torque) and, with ``options.duty_fe``, the flexible FE at every duty-cycle torque
    (:func:`duty_cycle_fe`); where that does not solve, the reason in ``fe_not_computed``."""
    case, comparison = inputs["case"], inputs["comparison"]
    flexible = iso281.case_duty_cycle_life(case, [b.flexible.L10h for b in comparison.bearings])
    assert flexible is not None          # the case has a duty cycle (the section's ``applies``)
    duty = DutyCycleResult(
        rigid=(iso281.case_duty_cycle_life(case, [b.rigid.L10h for b in comparison.bearings])
               if inputs["rigid"].defined else None),
        flexible=flexible)
    if not inputs["options"].duty_fe:
        return duty
    try:
        return dataclasses.replace(duty, flexible_fe=duty_cycle_fe(inputs["system"], inputs["theta"], inputs["cycle"],
                                                                   comparison, duty.flexible.service_life_h))
    except ContactError as exc:
        log.info("the flexible FE at every duty-cycle torque not computed: %s", exc)
        return dataclasses.replace(duty, fe_not_computed=str(exc))


KEYS = (
    KeyRow('`duty_cycle`',
           'object',
           'only if the case has a duty cycle (`loads.duty_cycle`): the service life from the rigid and from the flexible lives'),
    KeyRow('`duty_cycle.rigid`, `duty_cycle.flexible`',
           'object (`rigid` may be null)',
           'Palmgren–Miner over the duty cycle (`rigid` null for Zp − Zc ≠ 1)'),
    KeyRow('&nbsp;&nbsp;`.rated_life_h`',
           'float',
           "L0: the shortest bearing L10h at the case's torque and speed"),
    KeyRow('&nbsp;&nbsp;`.equivalent_torque_Nm`, `.equivalent_speed_rpm`',
           'float',
           'T_m and n_m of the duty cycle'),
    KeyRow('&nbsp;&nbsp;`.service_life_h`',
           'float',
           'L = L0·n0·T0^(10/3)/(n_m·T_m^(10/3)), hours: the loads are assumed to scale linearly with the torque'),
    KeyRow('`duty_cycle.flexible_fe`',
           'object or null',
           'the check of that assumption: the flexible load cycle solved at every distinct positive duty-cycle torque (same disc model and compliance)'),
    KeyRow('`duty_cycle.flexible_fe.torques_Nm`, `duty_cycle.flexible_fe.equivalent_load_N`',
           'array',
           "the torques and, per torque, every bearing's flexible F_m, N"),
    KeyRow('`duty_cycle.flexible_fe.linear_scaling_error_percent`',
           'array',
           'per torque: F_m(T_i)/(F_m(T0)·T_i/T0) − 1, the bearing farthest off, %'),
    KeyRow('`duty_cycle.flexible_fe.service_life_h`, `duty_cycle.flexible_fe.life_difference_percent`',
           'float',
           'Palmgren–Miner 1/L = Σ s_i/L_i per bearing with the FE F_m of each row (shortest bearing), hours; its difference from `duty_cycle.flexible.service_life_h`, %'),
    KeyRow('`duty_cycle.flexible_fe.seconds`',
           'float',
           'wall time of the extra load cycles'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("duty_cycle", summary, KEYS, requires=("case", "system", "theta", "cycle", "comparison", "rigid"),
                  compute=compute, applies=lambda inputs: bool(inputs["case"].loads.duty_cycle), stage="duty_cycle",
                  screen=lambda s: screen_lines.duty_lines(s.get("duty_cycle")), screen_rank=70)
