"""The loads and their deltas: every crank bearing's load statistics (rigid, flexible, equal share),
flexible against the reference, and the largest FE bearing load of the cycle."""

from __future__ import annotations

import math
from typing import Any

from rvfem.results.format import angle, stats_dict

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'summary']

def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    bearings = [{
        "bearing": bc.bearing + 1,
        "crank_angle_deg": a.case.cranks.angles_deg[bc.bearing],
        "rigid": None if bc.rigid is None else stats_dict(bc.rigid),
        "flexible": stats_dict(bc.flexible),
        "equal_share": stats_dict(bc.equal_share),
        "delta_max_percent": bc.delta_max_percent,
        "delta_min_percent": bc.delta_min_percent,
        "delta_equivalent_percent": bc.delta_equivalent_percent,
        "life_ratio": bc.life_ratio,
    } for bc in a.comparison.bearings]
    k, i = a.max_load_index
    return {
        "bearings": bearings,
        "max_bearing_load": {
            "bearing": i + 1,
            "theta_deg": angle(math.degrees(float(a.theta[k]))),
            "flexible_N": float(a.cycle.bearing_loads[k, i]),
        },
    }


KEYS = (
    KeyRow('`bearings[]`',
           'array',
           'one entry per crank bearing, in case order'),
    KeyRow('`bearings[].bearing`, `bearings[].crank_angle_deg`',
           'int, float',
           'number (from 1) and crank position'),
    KeyRow('`bearings[].rigid`, `bearings[].flexible`, `bearings[].equal_share`',
           'object (`rigid` may be null)',
           'load statistics of the handbook model (null where it is not defined, Zp − Zc ≠ 1), the FE model, and the FE pin resultant shared equally (see `rvfem.evaluate.compare`)'),
    KeyRow('&nbsp;&nbsp;`.max_load_N`, `.max_at_deg`',
           'float',
           'largest load over the cycle and its crank angle'),
    KeyRow('&nbsp;&nbsp;`.min_load_N`, `.min_at_deg`',
           'float',
           'smallest load and its crank angle'),
    KeyRow('&nbsp;&nbsp;`.equivalent_load_N`',
           'float',
           'F_m'),
    KeyRow('&nbsp;&nbsp;`.L10h_h`',
           'float',
           'ISO 281 life L10h = 10⁶/(60·n_b)·(C/F_m)^(10/3), hours'),
    KeyRow('`bearings[].delta_max_percent`, `bearings[].delta_min_percent`, `bearings[].delta_equivalent_percent`',
           'float',
           'flexible vs the reference `references.bearing_loads` (rigid, or equal share for Zp − Zc ≠ 1), % of the reference'),
    KeyRow('`bearings[].life_ratio`',
           'float',
           'L10h flexible / L10h of the reference = (F_m,ref/F_m,flex)^(10/3)'),
    KeyRow('`max_bearing_load`',
           'object',
           'the largest FE bearing load of the cycle'),
    KeyRow('`max_bearing_load.bearing`, `max_bearing_load.theta_deg`, `max_bearing_load.flexible_N`',
           'int, float, float',
           'which bearing, at which crank angle, how large'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("bearings", summary, KEYS,
                  screen=lambda s: screen_lines.bearing_lines(s, screen_lines.handbook_reference(s)), screen_rank=5)
