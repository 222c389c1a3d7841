"""Transmission accuracy at the case's torque: torsional rigidity and lost motion from a few points
of the hysteresis loop at crank angle 0 (:func:`rvfem.evaluate.accuracy.quick_figures`)."""

from __future__ import annotations

import logging
from typing import Any

from rvfem.errors import ContactError
from rvfem.evaluate import accuracy as accuracy_eval
from rvfem.solve import cycle as cycle_module

log = logging.getLogger(__name__)

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'accuracy_rows', 'compute', 'run_accuracy', 'summary']

def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    """Torsional rigidity and lost motion at the case's torque (a few points of the hysteresis loop)."""
    acc = getattr(a, "accuracy", None)
    if not acc:
        return {}
    return {"accuracy": {"torsional_rigidity_Nm_per_arcmin": acc["torsional_rigidity_Nm_per_arcmin"],
                         "lost_motion_arcmin": acc["lost_motion_arcmin"],
                         "crank_angle_deg": acc["crank_angle_deg"], "torque_Nm": acc["torque_Nm"]}}


def run_accuracy(system: Any) -> dict[str, Any] | None:
    """Torsional rigidity and lost motion of the case's stage at its torque and pin friction, at
    crank angle 0, from six solves on the factorised disc (:func:`rvfem.evaluate.accuracy.quick_figures`;
    ``rvfem hysteresis`` gives the whole loop averaged over a mesh period). None if a solve fails
    (logged): the run's other results do not depend on it."""
    case = system.case
    try:
        figures = accuracy_eval.quick_figures(cycle_module.case_stage(system), abs(float(case.loads.torque_Nm)),
                                              float(case.analysis.friction))
    except (ContactError, ValueError) as exc:
        log.warning("torsional rigidity and lost motion not computed: %s", exc)
        return None
    return {**figures, "crank_angle_deg": 0.0, "torque_Nm": abs(float(case.loads.torque_Nm))}


def compute(inputs: Any) -> dict[str, Any] | None:
    """The ``accuracy`` result of an analysis (:func:`run_accuracy`)."""
    return run_accuracy(inputs["system"])


def accuracy_rows(acc: dict[str, Any] | None) -> list[list[str]]:
    """Torsional rigidity and lost motion of the stage from the run's few points of the hysteresis
    loop (docs/theory.md § 9b; ``rvfem hysteresis`` gives the whole loop)."""
    if not acc:
        return []
    where = f"input locked at θ = {acc['crank_angle_deg']:g}°, ±{acc['torque_Nm']:g} N·m, stage only"
    return [["torsional rigidity (b/a, 3–100 % T)", f"{acc['torsional_rigidity_Nm_per_arcmin']:.1f} N·m/arcmin ({where})"],
            ["lost motion (±3 % T)", f"{acc['lost_motion_arcmin']:.3f} arcmin ({where})"]]


KEYS = (
    KeyRow('`accuracy`',
           'object',
           "transmission accuracy at the case's torque and pin friction, from six solves of the hysteresis loop (input locked) at crank angle 0: the loading and unloading branches at ±3 % and ±100 % of the torque (`rvfem hysteresis` gives the whole loop averaged over a mesh period); absent if those solves fail"),
    KeyRow('`accuracy.torsional_rigidity_Nm_per_arcmin`',
           'float',
           'b/a: 0.97·T over the rotation between 3 % and 100 % of T on the loading branches (mean of + and −), N·m/arcmin'),
    KeyRow('`accuracy.lost_motion_arcmin`',
           'float',
           "width of the loop's centreline between ±3 % of T, arcmin"),
    KeyRow('`accuracy.crank_angle_deg`, `accuracy.torque_Nm`',
           'float',
           'the crank angle held and the torque T'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("accuracy", summary, KEYS, requires=("system",), compute=compute, stage="accuracy",
                  report=lambda s: accuracy_rows(s.get("accuracy")),
                  screen=lambda s: screen_lines.accuracy_lines(s.get("accuracy")), screen_rank=35)
