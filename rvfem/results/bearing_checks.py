"""What a bearing analyst checks next to L10h: static safety S0, the minimum load and the support
bearings (:mod:`rvfem.evaluate.bearing_checks`)."""

from __future__ import annotations

import math
from typing import Any

from rvfem.evaluate import bearing_checks as checks_eval
from rvfem.evaluate.bearing_checks import MINIMUM_LOAD_FRACTION, STATIC_SAFETY_NORMAL, STATIC_SAFETY_SHOCK
from rvfem.results.format import angle

from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'bearing_check_lines', 'bearing_checks_dict', 'compute', 'summary']

def bearing_checks_dict(checks: Any) -> dict[str, Any] | None:
    """The ``bearing_checks`` object of summary.json and ``rvfem rigid --json``
    (:class:`rvfem.evaluate.bearing_checks.BearingChecks`)."""
    if checks is None:
        return None
    static = {m: {"C0_N": v.static_rating_N, "P0_N": v.p0_N, "S0": v.s0, "verdict": v.verdict}
              for m, v in checks.static.items()}
    minimum = {m: {"min_load_N": v.min_load_N, "fraction_of_C": v.fraction_of_C, "below": v.below}
               for m, v in checks.minimum.items()}
    out = {
        "static_safety": {**static, "limits": {"normal": STATIC_SAFETY_NORMAL, "shock_or_accuracy": STATIC_SAFETY_SHOCK},
                          "source": "S0 = C0/P0, P0 = F_r,max (ISO 76); limits: bearing makers' rule (SKF catalogue)"},
        "minimum_load": {**minimum, "required_fraction_of_C": MINIMUM_LOAD_FRACTION,
                         "source": "P_min = 0.02·C for cylindrical roller bearings: bearing makers' rule "
                                   "(SKF catalogue), not ISO"},
        "support_bearings": None if checks.support is None else [
            {"support": b.support, "crank": b.crank + 1, "max_load_N": b.max_N, "max_at_deg": angle(b.max_at_deg),
             "min_load_N": b.min_N, "equivalent_load_N": b.equivalent_N, "L10h_h": b.L10h} for b in checks.support],
        "support_note": checks.support_note,
    }
    if "rigid" in checks.minimum and "flexible" in checks.minimum and checks.minimum["rigid"].min_load_N > 0:
        out["minimum_load"]["flexible_vs_rigid_percent"] = 100.0 * (
            checks.minimum["flexible"].min_load_N / checks.minimum["rigid"].min_load_N - 1.0)
    return out


def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    return {"bearing_checks": bearing_checks_dict(getattr(a, "bearing_checks", None))}


def _fmt(value: Any, fmt: str) -> str:
    """A number for a line, a dash for None, ``inf`` for infinity."""
    if value is None:
        return "–"
    return format(float(value), fmt) if math.isfinite(float(value)) else "inf"


def bearing_check_lines(checks: dict[str, Any] | None) -> list[str]:
    """The crank bearing's static safety S0 and minimum load (rigid and flexible, where there) and the
    support bearings' loads and lives (the ``bearing_checks`` object of summary.json or ``rvfem rigid
    --json``)."""
    if not checks:
        return []
    models = [m for m in ("rigid", "flexible") if m in checks["static_safety"]]
    st, mn = checks["static_safety"], checks["minimum_load"]
    lines = ["  static safety S0 = C0/P0 (ISO 76, C0 = " + f"{st[models[0]]['C0_N']:.0f} N): " + ", ".join(
        f"{m} {_fmt(st[m]['S0'], '.2f')}" for m in models) + "; makers ask ≥ 1, ≥ 2 with shock or high accuracy"]
    change = mn.get("flexible_vs_rigid_percent")
    lines.append("  minimum load (skidding): smallest bearing load " + ", ".join(
        f"{m} {mn[m]['min_load_N']:.0f} N = {100 * mn[m]['fraction_of_C']:.2f} % of C" for m in models)
        + (f" (flexible {change:+.0f} %)" if change is not None else "")
        + f"; makers' rule ≥ {100 * mn['required_fraction_of_C']:g} % of C")
    sup = checks.get("support_bearings")
    if sup:
        lines.append("  support bearings (crankshaft beam): " + "; ".join(
            f"{b['support']} max {b['max_load_N']:.0f} N, F_m {b['equivalent_load_N']:.0f} N"
            + (f", L10h {_fmt(b['L10h_h'], '.0f')} h" if b["L10h_h"] is not None else "") for b in sup)
            + (f" ({checks['support_note']})" if checks.get("support_note") else ""))
    elif checks.get("support_note"):
        lines.append(f"  support bearings: {checks['support_note']}")
    return lines


def compute(inputs: Any) -> checks_eval.BearingChecks:
    """Static safety, minimum load and support bearings of a run
    (:func:`rvfem.evaluate.bearing_checks.case_bearing_checks`)."""
    rigid, bearings = inputs["rigid"], inputs["comparison"].bearings
    models = {"flexible": [b.flexible for b in bearings]}
    if rigid.defined and all(b.rigid is not None for b in bearings):
        models["rigid"] = [b.rigid for b in bearings if b.rigid is not None]
    return checks_eval.case_bearing_checks(
        inputs["case"], inputs["theta"], rigid.rating_N, rigid.bearing_speed_rpm,
        {m: max(s.max_N for s in v) for m, v in models.items()},
        {m: min(s.min_N for s in v) for m, v in models.items()}, inputs["cycle"].disc_bearing_forces)


KEYS = (
    KeyRow('`bearing_checks`',
           'object',
           'what a bearing analyst checks next to L10h (docs/theory.md, "Static safety, minimum load and the support bearings")'),
    KeyRow('`bearing_checks.static_safety`',
           'object',
           "the crank bearing's static safety; `source` names the standard and where the limits come from"),
    KeyRow('`bearing_checks.static_safety.rigid`, `bearing_checks.static_safety.flexible`',
           'object (`rigid` absent for Zp − Zc ≠ 1)',
           'one per load model'),
    KeyRow('&nbsp;&nbsp;`.C0_N`, `.P0_N`, `.S0`, `.verdict`',
           'float, float, float, str',
           'C0 (ISO 76, or `crank_bearing.static_load_rating_N`), P0 = the largest radial bearing load, S0 = C0/P0, and `below 1`, `1 to 2` or `at least 2`'),
    KeyRow('`bearing_checks.static_safety.limits`, `bearing_checks.static_safety.limits.normal`, `bearing_checks.static_safety.limits.shock_or_accuracy`, `bearing_checks.static_safety.source`',
           'object, float, float, str',
           "S0 ≥ 1 in normal operation, ≥ 2 with shock loads or high running accuracy (bearing makers' rule, SKF catalogue)"),
    KeyRow('`bearing_checks.minimum_load`',
           'object',
           "the smallest crank-bearing load against the minimum load of cylindrical roller bearings, 0.02·C (bearing makers' rule, SKF catalogue, not ISO; below it the rollers may skid)"),
    KeyRow('`bearing_checks.minimum_load.rigid`, `bearing_checks.minimum_load.flexible`',
           'object (`rigid` absent for Zp − Zc ≠ 1)',
           'one per load model'),
    KeyRow('&nbsp;&nbsp;`.min_load_N`, `.fraction_of_C`, `.below`',
           'float, float, bool',
           'smallest bearing load of the cycle, over C, and whether it is under the rule'),
    KeyRow('`bearing_checks.minimum_load.required_fraction_of_C`, `bearing_checks.minimum_load.source`, `bearing_checks.minimum_load.flexible_vs_rigid_percent`',
           'float, str, float',
           "0.02; the rule's source; flexible against rigid minimum, % (absent without the rigid one)"),
    KeyRow('`bearing_checks.support_bearings[]`',
           'array or null',
           "the crankshaft's two support bearings (null without `[crank_support]` beam keys, or in `rvfem rigid --json`: `support_note` says why)"),
    KeyRow('`bearing_checks.support_bearings[].support`, `bearing_checks.support_bearings[].crank`',
           'int',
           'support 1 (at z = 0) or 2, and the crank (from 1) of the largest equivalent load'),
    KeyRow('`bearing_checks.support_bearings[].max_load_N`, `bearing_checks.support_bearings[].max_at_deg`, `bearing_checks.support_bearings[].min_load_N`, `bearing_checks.support_bearings[].equivalent_load_N`, `bearing_checks.support_bearings[].L10h_h`',
           'float or null',
           "radial load from the beam's reactions to both discs' eccentric loads over the cycle: largest (and its crank angle), smallest, F_m = (mean F^p)^(1/p) with p = `crank_support.support_bearing_life_exponent`, and ISO 281 L10h at the crank speed (null without `crank_support.support_bearing_C_N`)"),
    KeyRow('`bearing_checks.support_note`',
           'str',
           'why there are no support loads or no support life ("" when both are there)'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("bearing_checks", summary, KEYS, requires=("case", "theta", "rigid", "comparison", "cycle"),
                  compute=compute, screen=lambda s: bearing_check_lines(s.get("bearing_checks")),
                  screen_rank=60)
