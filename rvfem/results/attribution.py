"""The attribution: the flexibility effect step by step (:mod:`rvfem.evaluate.attribution`)."""

from __future__ import annotations

from typing import Any

from rvfem.evaluate import attribution as attribution_eval

from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'compute', 'summary']

def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    rows = a.attribution.table(a.case.analysis.equivalent_load_exponent)
    for r in rows:
        r["final"] = r["step"] == a.attribution.final
    return {"attribution": rows}


def compute(inputs: Any) -> attribution_eval.Attribution:
    """The attribution of the case's flexible load cycle (:func:`rvfem.evaluate.attribution.attribution`):
    the modelling steps the case's own model does not already give, on the same angles and the
    same compliance (mostly small dense solves, computed beside the stress stage)."""
    system = inputs["system"]
    return attribution_eval.attribution(system, inputs["theta"],
                                        cycles={attribution_eval.case_step(system.case): inputs["cycle"]})


KEYS = (
    KeyRow('`attribution[]`',
           'array',
           "the flexibility effect step by step, one entry per step and bearing: `handbook` → `equal_share` (the FE pin resultant shared equally) → `one_disc` (one flexible disc with T/2 on rigid eccentrics) → `two_discs` (two discs sharing the carrier) → `crankshafts` (crankshafts as beams), those that apply; for Zp − Zc ≠ 1 no `handbook` step, and `equal_share` is the equal share of this run's own pin resultant (the reference of `bearings[]`)"),
    KeyRow('`attribution[].step`, `attribution[].label`, `attribution[].bearing`, `attribution[].final`',
           'str, str, int, bool',
           "step key, what it adds in words, bearing number (from 1), true for this run's own model"),
    KeyRow('`attribution[].max_N`, `attribution[].min_N`, `attribution[].equivalent_N`',
           'float',
           'load statistics over the cycle'),
    KeyRow('`attribution[].delta_max_percent`, `attribution[].delta_min_percent`, `attribution[].delta_equivalent_percent`',
           'float',
           'against the first step (the handbook, or the equal share for Zp − Zc ≠ 1), %'),
    KeyRow('`attribution[].life_ratio`',
           'float',
           '(F_m,first step/F_m)^(10/3)'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("attribution", summary, KEYS, requires=("system", "theta", "cycle"), compute=compute,
                  applies=lambda inputs: bool(inputs["options"].attribute), stage="attribution", executor="thread")
