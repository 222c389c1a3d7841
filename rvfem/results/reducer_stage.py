"""The reducer-stage model of the flexible cycle: two discs on one carrier, crankshafts."""

from __future__ import annotations

from typing import Any

import numpy as np

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'summary']

def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    cy, case = a.cycle, a.case
    share = None
    disc_b = None
    if cy.disc_torque_Nmm is not None and cy.disc_torque_Nmm.shape[1] == 2:
        s = cy.disc_torque_Nmm[:, 0] / case.loads.disc_torque_Nmm
        share = {"min": float(s.min()), "max": float(s.max())}
        disc_b = float(np.linalg.norm(cy.disc_bearing_forces[:, 1], axis=-1).max())
    f = cy.crankshaft_influence if a.attribution.final == "crankshafts" else None
    w = cy.eccentric_displacement
    return {"reducer_stage": {
        "model": cy.stage,
        "step": a.attribution.final,
        "crank_support_rigid": f is None,
        "torque_share": share,
        "disc_b_max_load_N": disc_b,
        "crankshaft_influence_mm_per_N": None if f is None else f.tolist(),
        "eccentric_displacement_max_mm": None if (w is None or f is None) else float(np.linalg.norm(w, axis=-1).max()),
    }}


KEYS = (
    KeyRow('`reducer_stage`',
           'object',
           'the reducer-stage model of the flexible cycle (two discs on one carrier, crankshafts)'),
    KeyRow('`reducer_stage.model`',
           'str',
           'the model in words, e.g. "two discs sharing one carrier …; crankshafts as beams on elastic support bearings" or "… crank support rigid: upper bound of the flexibility effect"'),
    KeyRow('`reducer_stage.step`',
           'str',
           "which attribution step this run's cycle is: `one_disc`, `two_discs` or `crankshafts`"),
    KeyRow('`reducer_stage.crank_support_rigid`',
           'bool',
           'true when the eccentrics are rigid (no `[crank_support]`, or the equal torque split): the flexibility effect is then an upper bound'),
    KeyRow('`reducer_stage.torque_share`',
           'object or null',
           "disc A's torque over the cycle in units of T/2 (two discs sharing the carrier), else null"),
    KeyRow('`reducer_stage.torque_share.min`, `reducer_stage.torque_share.max`',
           'float',
           'smallest and largest share'),
    KeyRow('`reducer_stage.disc_b_max_load_N`',
           'float or null',
           'largest bearing load on disc B (at θ + 180°)'),
    KeyRow('`reducer_stage.crankshaft_influence_mm_per_N`',
           'array or null',
           'the 2×2 crankshaft influence matrix f (eccentric displacement per unit force), mm/N'),
    KeyRow('`reducer_stage.eccentric_displacement_max_mm`',
           'float or null',
           'largest eccentric displacement relative to the carrier, mm'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("reducer_stage", summary, KEYS,
                  screen=lambda s: screen_lines.stage_lines(s, screen_lines.handbook_reference(s)), screen_rank=20)
