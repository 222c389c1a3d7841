"""Hertz pressures of the most loaded roller: of the FE, of the rigid rings under the handbook loads
and under the FE bearing loads."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from rvfem.evaluate import hertz, roller_slices
from rvfem.evaluate.hertz import RIGID_ROLLER_MODEL
from rvfem.results.format import angle

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'compute', 'summary']

def _hertz_dict(h: Any) -> dict[str, Any]:
    return {
        "roller_load_N": h.roller_load_N,
        "bearing": None if h.bearing is None else h.bearing + 1,
        "roller": None if h.roller is None else h.roller + 1,
        "theta_deg": angle(h.theta_deg),
        "factor": h.factor,
        "inner": dataclasses.asdict(h.inner),
        "outer": dataclasses.asdict(h.outer),
    }


def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    h = a.hertz
    return {"hertz": {
        "rigid_roller_model": RIGID_ROLLER_MODEL,
        "stribeck_factor": h["stribeck_rigid"].factor if "stribeck_rigid" in h else h["stribeck_flexible"].factor,
        "fe_rollers": _hertz_dict(h["fe_rollers"]) if "fe_rollers" in h else None,
        "stribeck_rigid": _hertz_dict(h["stribeck_rigid"]) if "stribeck_rigid" in h else None,
        "stribeck_flexible": _hertz_dict(h["stribeck_flexible"]),
    }}


def compute(inputs: Any) -> dict[str, hertz.RollerHertz]:
    """The most loaded roller's Hertz pressures (:func:`rvfem.evaluate.hertz.most_loaded_roller_hertz`):
    of the FE roller loads, and of the rigid rings under the handbook and under the FE bearing loads."""
    case, cycle, rigid_analysis = inputs["case"], inputs["cycle"], inputs["rigid"]
    rigid_forces = None
    if rigid_analysis.defined:
        hb = rigid_analysis.loads
        rigid_forces = np.stack([hb.fx.T, hb.fy.T], axis=2)
    return hertz.most_loaded_roller_hertz(
        case, cycle.theta, cycle.bearing_forces, cycle.roller_loads, rigid_forces,
        None if rigid_forces is None else roller_slices.case_rigid_roller_loads(case, cycle.theta, rigid_forces),
        roller_slices.case_rigid_roller_loads(case, cycle.theta, cycle.bearing_forces))


KEYS = (
    KeyRow('`hertz`',
           'object',
           'Hertz pressures of the most loaded roller'),
    KeyRow('`hertz.rigid_roller_model`',
           'str',
           "what the rigid most loaded roller is: rigid rings (Stribeck's method) with the rollers at their cage positions, Palmgren line contact and the case's radial clearance — the one definition of `hertz.stribeck_rigid`, `crank_bearing_depth.bearings[].rigid.max_roller_load_N` and `bearings[].max_roller_load_N` of `rvfem rigid --json`"),
    KeyRow('`hertz.stribeck_factor`',
           'float',
           "k of the rigid most loaded roller Q_max = k·F/Z (F that bearing's load at that angle; 4.08 for zero clearance, many rollers; Gao et al.'s 4.6 allows for a clearance)"),
    KeyRow('`hertz.fe_rollers`, `hertz.stribeck_rigid`, `hertz.stribeck_flexible`',
           'object (`fe_rollers`, `stribeck_rigid` may be null)',
           'the most loaded roller, the largest roller load over the cycle, bearings and rollers: of the FE (`rollers` model only, else null); of the rigid rings under the handbook loads (null for Zp − Zc ≠ 1); of the rigid rings under the FE bearing loads'),
    KeyRow('&nbsp;&nbsp;`.roller_load_N`, `.bearing`, `.roller`, `.theta_deg`, `.factor`',
           'float, int, int, float, float',
           "the roller load Q, where, and Z·Q/F with F that bearing's load there (null where not applicable)"),
    KeyRow('&nbsp;&nbsp;`.inner`, `.outer`',
           'object',
           'Hertz line contact on the eccentric (convex) and in the bore (concave)'),
    KeyRow('`hertz.fe_rollers.inner`, `hertz.fe_rollers.outer`, `hertz.stribeck_rigid.inner`, `hertz.stribeck_rigid.outer`, `hertz.stribeck_flexible.inner`, `hertz.stribeck_flexible.outer`',
           'object',
           'one contact'),
    KeyRow('&nbsp;&nbsp;`.half_width_mm`, `.peak_pressure_MPa`, `.approach_mm`',
           'float',
           'half-width b, peak pressure p_h = 2Q/(π·L·b), Palmgren approach'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("hertz", summary, KEYS, requires=("case", "cycle", "rigid"), compute=compute, stage="evaluation",
                  screen=lambda s: [screen_lines.hertz_line(s["hertz"])], screen_rank=45)
