"""The ``warnings`` section: results outside the range where their model holds
(:mod:`rvfem.evaluate.validity`), one entry per limit crossed."""

from __future__ import annotations

from typing import Any

from rvfem.evaluate import attribution as attribution_eval
from rvfem.evaluate import validity

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'compute', 'summary']

def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    return {"warnings": [w.as_dict() for w in a.warnings]}


def compute(inputs: Any) -> tuple[validity.ResultWarning, ...]:
    """Every result outside its model's range (:mod:`rvfem.evaluate.validity`), then what could not
    be computed: the attribution's steps and the flexible FE at every duty-cycle torque."""
    a = inputs["analysis"]
    found = (validity.analysis_warnings(a) + validity.roller_depth_warnings(a.roller_depth)
             + validity.bearing_check_warnings(a.bearing_checks) + attribution_eval.skipped_warnings(a.attribution))
    if a.duty_cycle is not None and a.duty_cycle.fe_not_computed is not None:
        found += (validity.ResultWarning(
            "not_computed", f"the flexible FE at every duty-cycle torque not computed: {a.duty_cycle.fe_not_computed}; "
            "the service life is the linear scaling of the case's own cycle", 1.0, 0.0, ""),)
    return found


KEYS = (
    KeyRow('`warnings`, `warnings[]`',
           'array',
           'results outside the range where their model holds, one entry per limit crossed (the worst value of its kind); empty when every result is inside. Also on screen and at the top of `report.html`; see [Warnings](#warnings-results-outside-their-models-range)'),
    KeyRow('`warnings[].code`, `warnings[].message`',
           'str',
           'what is checked (`load_ratio`, `life_under_1h`, `hertz_pressure`, `roller_pressure`, `kappa_range`, `disc_stress_yield`, `large_displacement`; stable keys) and one line for the user: the value, where it occurs, the limit and what it means'),
    KeyRow('`warnings[].value`, `warnings[].limit`, `warnings[].unit`',
           'float, float, str',
           'the offending value, the limit it crosses, and their unit (`""` for P/C, `h`, `MPa`, `mm`)'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("warnings", summary, KEYS, requires=("analysis",), compute=compute,
                  screen=lambda s: screen_lines.warning_lines(s.get("warnings", [])), screen_rank=90)
