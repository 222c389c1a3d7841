"""What the flexibility effect is made of: the attribution of the flexible bearing loads to the
modelling steps handbook → equal share of the FE pin resultant → one flexible disc with T/discs →
two discs sharing the carrier → crankshaft compliance (→ the step of each stage component that
brings its own, :mod:`rvfem.solve.stage_parts`), on the same crank angles and the same compliance.

The attribution is a secondary analysis: a step whose cycle cannot be solved (a contact problem the
step's model does not settle, though the case's own model does) is left out of the chain and named
with its reason (:attr:`Attribution.skipped`, :func:`skipped_warnings`); the other steps and the
run's results stand."""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from rvfem.errors import ContactError
from rvfem.evaluate.compare import equal_share_forces
from rvfem.evaluate.iso281 import life_ratio
from rvfem.evaluate.rigid import (
    equivalent_load,
    handbook_applicable,
    handbook_bearing_loads,
)
from rvfem.evaluate.validity import ResultWarning
from rvfem.solve.cycle import build_stage, load_cycle
from rvfem.solve.stage_parts import build_components, stage_components

__all__ = ["Attribution", "AttributionStep", "STEP_LABELS", "attribution", "case_step", "chain", "skipped_warnings",
           "step_label"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class AttributionStep:
    """One modelling step of the attribution: the bearing-load curves it gives.

    Attributes
    ----------
    key : str
        ``handbook``, ``equal_share``, ``one_disc``, ``two_discs`` or ``crankshafts``.
    label : str
        What the step adds, in words.
    loads : ndarray (N, n)
        Load magnitude of each bearing over the crank angles, N.
    """

    key: str
    label: str
    loads: np.ndarray


@dataclass(frozen=True)
class Attribution:
    """The chain handbook → equal share of the FE pin resultant → one flexible disc with T/discs
    → two discs sharing the carrier → crankshaft compliance, on the same crank angles.

    ``final`` names the step that is the case's own model (the full FE answer). ``skipped`` holds
    ``(key, why)`` for every step that could not be made (its cycle did not solve, or the cycle it is
    built from did not); those steps are left out of ``steps``.
    """

    theta: np.ndarray
    steps: tuple[AttributionStep, ...]
    final: str
    skipped: tuple[tuple[str, str], ...] = ()

    def step(self, key: str) -> AttributionStep:
        return next(s for s in self.steps if s.key == key)

    def table(self, exponent: float) -> list[dict]:
        """Per step and bearing: max, min and equivalent load (N) and their deltas against the
        first step (%), and the life ratio (F_ref,m/F_m)^(10/3). The first step is the handbook, or
        the equal share where the handbook is not defined (Zp − Zc ≠ 1)."""
        ref = self.steps[0].loads
        rows = []
        for s in self.steps:
            for i in range(s.loads.shape[0]):
                mx, mn = float(s.loads[i].max()), float(s.loads[i].min())
                fm = float(equivalent_load(s.loads[i], exponent))
                rmx, rmn = float(ref[i].max()), float(ref[i].min())
                rfm = float(equivalent_load(ref[i], exponent))
                rows.append({
                    "step": s.key, "label": s.label, "bearing": i + 1,
                    "max_N": mx, "min_N": mn, "equivalent_N": fm,
                    "delta_max_percent": 100.0 * (mx / rmx - 1.0),
                    "delta_min_percent": 100.0 * (mn / rmn - 1.0),
                    "delta_equivalent_percent": 100.0 * (fm / rfm - 1.0),
                    "life_ratio": life_ratio(rfm, fm),
                })
        return rows


STEP_LABELS = {
    "handbook": "handbook (rigid disc, classical pin forces, T/2 per disc)",
    "equal_share": "equal share of the FE pin resultant (pin-force distribution of the flexible disc)",
    "equal_share_reference": "equal share of this run's FE pin resultant (the reference: handbook not defined "
                             "for Zp − Zc ≠ 1)",
    "one_disc": "one flexible disc with T/2 on rigid eccentrics (bearing load sharing)",
    "two_discs": "two discs sharing the carrier, rigid crank support",
    "crankshafts": "two discs sharing the carrier, crankshafts as beams",
}


def step_label(key: str) -> str:
    """What the step ``key`` adds, in words: :data:`STEP_LABELS`, or the ``step_label`` of the stage
    component that brings its own step (:mod:`rvfem.solve.stage_parts`)."""
    if key in STEP_LABELS:
        return STEP_LABELS[key]
    for c in stage_components():
        if c.step == key and c.step_label:
            return c.step_label
    raise KeyError(f"no attribution step {key!r}")


def chain(case) -> list[str]:
    """The model steps of the case's attribution after the handbook and the equal share, in order:
    one flexible disc, two discs sharing the carrier (two discs), then the step of each stage
    component the case has (:func:`rvfem.solve.stage_parts.stage_components`, in their order; the
    crankshafts only with ``[crank_support]``), each step once."""
    need = ["one_disc"]
    if case.loads.discs == 2:
        need.append("two_discs")
    for c in stage_components():
        if c.step is not None and c.step not in need and c.present(case):
            need.append(c.step)
    return need


def attribution(system, thetas: np.ndarray, cycles: dict | None = None) -> Attribution:
    """Solve the modelling steps the case does not already have and collect their load curves, at
    the case's operating point.

    Parameters
    ----------
    system : rvfem.solve.cycle.DiscSystem
    thetas : ndarray
        Crank angles, rad (a uniformly sampled turn).
    cycles : dict, optional
        Already solved cycles by step key (``one_disc``, ``two_discs``, ``crankshafts``), e.g. the
        run's own cycle, so that it is not solved twice. All steps share the disc's compliance.

    Raises
    ------
    rvfem.errors.ContactError
        Only if the case's own step (:func:`case_step`) is not in ``cycles`` and its cycle does not
        solve. Any other step that does not solve is left out and named in
        :attr:`Attribution.skipped` (and given as a warning by :func:`skipped_warnings`).

    Notes
    -----
    The equal share is built from the one-disc cycle's pin resultant (the handbook's load sharing
    applied to the flexible disc's pin forces): F_i = −P/N + T_disc/(N·r0)·t_i. Where the handbook
    is not defined (Zp − Zc ≠ 1, :func:`rvfem.evaluate.rigid.handbook_applicable`) the chain starts at the
    reference the run's bearing loads are compared with instead, the equal share of the case's own
    cycle's pin resultant (:func:`rvfem.evaluate.compare.rigid_vs_flexible`), so that the last row's deltas
    are the run's.
    """
    case = system.case
    cycles = dict(cycles or {})
    need = chain(case)
    discs = 2 if case.loads.discs == 2 else 1
    skipped: dict[str, str] = {}
    for k, key in enumerate(need):
        if key in cycles:
            continue
        # the step's stage: one disc or both, with every component first modelled up to this step
        stage = build_components(build_stage(system, discs=1 if key == "one_disc" else discs, influence=None),
                                 steps=tuple(need[:k + 1]))
        try:
            cycles[key] = load_cycle(system, thetas, saved_angles_deg=(), stage=stage)
        except ContactError as exc:
            if key == case_step(case):      # the case's own model: no chain to end in
                raise
            skipped[key] = f"its load cycle does not solve: {str(exc).rstrip('.')}"
    if handbook_applicable(case)[0]:
        steps = [AttributionStep("handbook", STEP_LABELS["handbook"], handbook_bearing_loads(case, thetas).magnitude)]
        base, label = cycles.get("one_disc"), STEP_LABELS["equal_share"]
    else:   # Zp − Zc ≠ 1: start at the run's own reference
        steps, base, label = [], cycles[case_step(case)], STEP_LABELS["equal_share_reference"]
    if base is not None:
        share = np.linalg.norm(equal_share_forces(case, base), axis=2).T
        steps.append(AttributionStep("equal_share", label, share))
    else:
        skipped["equal_share"] = "it is built from the pin forces of the one-disc step, which was not made"
    for key in need:
        if key in cycles:
            steps.append(AttributionStep(key, step_label(key), cycles[key].bearing_loads.T))
    for key, why in skipped.items():
        log.info("attribution step %s (%s) not made: %s", key, step_label(key), why)
    return Attribution(np.asarray(thetas), tuple(steps), case_step(case), tuple(skipped.items()))


def skipped_warnings(result: Attribution | None) -> tuple[ResultWarning, ...]:
    """One warning (code ``not_computed``) per attribution step that could not be made, naming the
    step and why; ``value`` is 1 (one step left out), ``limit`` 0. Empty without an attribution or
    with every step made."""
    if result is None:
        return ()
    return tuple(ResultWarning("not_computed", f"attribution step {key} ({step_label(key)}) not made: {why}; "
                               "the other steps and the run's results stand", 1.0, 0.0, "")
                 for key, why in result.skipped)


def case_step(case) -> str:
    """The attribution step that is the case's own model: ``one_disc`` (one disc with T/discs on
    rigid eccentrics: ``torque_split = "equal"``, or one disc without ``[crank_support]``),
    ``two_discs`` (two discs on rigid eccentrics), ``crankshafts``, or the step of its own of the
    last stage component the case has that brings one."""
    if case.loads.discs > 1 and case.loads.torque_split == "equal":
        return "one_disc"
    own = [key for key in chain(case) if key not in STEP_LABELS]
    if own:     # a stage component's own step, the last of the chain
        return own[-1]
    if case.crank_support is not None:
        return "crankshafts"
    return "two_discs" if case.loads.discs == 2 else "one_disc"
