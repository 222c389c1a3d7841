"""The flexible/rigid L10r ratio of the crank bearing taken apart in steps — handbook → pin friction
→ flexible bearing forces → load sharing → tilt — each a factor, their product the ratio
(:func:`rvfem.evaluate.roller_life.l10r_steps`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from rvfem.evaluate import roller_life
from rvfem.results.analysis import rigid_bearing_forces
from rvfem.results.screen_lines import sig
from rvfem.results.section import KeyRow, Section, SummaryContext
from rvfem.solve.cycle import OperatingPoint, load_cycle

__all__ = ["SECTION", "FACTORS", "FRICTIONLESS_ANGLES", "compute", "frictionless_bearing_forces", "summary", "screen", "report"]

FACTORS = ("pin_friction", "bearing_forces", "load_sharing", "tilt")
"""The factors of the ratio, in the order of the steps."""

_WORDS = {"pin_friction": "pin friction", "bearing_forces": "bearing forces", "load_sharing": "load sharing",
          "tilt": "tilt"}


FRICTIONLESS_ANGLES = 90
"""Most crank angles the cycle without pin friction is solved at (every k-th angle of the case's
cycle, k the smallest divisor of its angle count that leaves at most this many); the bearing forces
in between are interpolated along the cycle (periodic, linear). Measured on the default case at 1°
steps (k = 4): the pin-friction factor within 0.1 % of the one from all 360 angles (docs/theory.md
§ 12); it costs a quarter of a load cycle instead of a whole one."""


def frictionless_bearing_forces(system: Any, theta: np.ndarray, torque_Nm: float,
                                most_angles: int = FRICTIONLESS_ANGLES) -> np.ndarray:
    """The bearing forces of the cycle solved again without pin friction, at every angle of
    ``theta`` (rad), N, (n, N, 2): solved at every k-th angle (:data:`FRICTIONLESS_ANGLES`) and
    interpolated periodically in between."""
    n = len(theta)
    k = next(k for k in range(max(1, -(-n // most_angles)), n + 1) if n % k == 0)
    op = OperatingPoint(torque_Nm, 0.0)
    solved = load_cycle(system, theta[::k], op=op, saved_angles_deg=()).bearing_forces
    if k == 1:
        return np.asarray(solved)
    flat = np.asarray(solved).reshape(len(theta[::k]), -1)
    full = np.stack([np.interp(theta, theta[::k], flat[:, j], period=2.0 * np.pi) for j in range(flat.shape[1])],
                    axis=1)
    return full.reshape((n, *np.asarray(solved).shape[1:]))


def compute(inputs: Any) -> tuple[roller_life.L10rSteps, ...] | None:
    """The steps of every bearing: the handbook forces and the flexible cycle's forces and rollers,
    and the flexible cycle solved again without pin friction (on the background thread, beside the
    other stages; not solved when the case has no friction)."""
    case, cycle, rigid = inputs["case"], inputs["cycle"], inputs["rigid"]
    if not rigid.defined or not any(b.depth is not None for b in rigid.bearings):
        return None
    theta = inputs["theta"]
    forces = cycle.bearing_forces
    if case.analysis.friction > 0.0:
        forces = frictionless_bearing_forces(inputs["system"], theta, float(case.loads.torque_Nm))
    handbook = rigid_bearing_forces(rigid, theta)
    assert isinstance(handbook, np.ndarray)           # the handbook is defined (checked above)
    return roller_life.l10r_steps(case, theta, cycle, handbook, forces,
                                  rigid.bearing_speed_rpm,
                                  bearings=[b.loads.bearing for b in rigid.bearings if b.depth is not None])


def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    steps = getattr(a, "roller_life_steps", None)
    if steps is None:
        return {"crank_bearing_l10r_steps": None}
    return {"crank_bearing_l10r_steps": {
        "pin_friction": a.case.analysis.friction,
        "bearings": [{"bearing": s.bearing + 1, "L10r_h": dict(s.L10r_h), "factors": dict(s.factors),
                      "L10r_ratio": s.ratio} for s in steps],
    }}


def _line(b: dict[str, Any]) -> str:
    f = b["factors"]
    return (f"L10r flexible/rigid {sig(b['L10r_ratio'], '.3f')} = "
            + " × ".join(f"{_WORDS[k]} {sig(f[k], '.3f')}" for k in FACTORS))


def screen(s: dict[str, Any]) -> list[str]:
    """One line per group of bearings whose factors read the same."""
    steps = s.get("crank_bearing_l10r_steps")
    if not steps:
        return []
    groups: list[tuple[list[int], str]] = []
    for b in steps["bearings"]:
        line = _line(b)
        if groups and groups[-1][1] == line:
            groups[-1][0].append(b["bearing"])
        else:
            groups.append(([b["bearing"]], line))
    out = []
    for numbers, line in groups:
        name = f"bearings {numbers[0]}–{numbers[-1]}" if len(numbers) > 1 else f"bearing {numbers[0]}"
        out.append(f"    {name} {line}")
    return out


def report(s: dict[str, Any]) -> list[list[str]]:
    """The report's rows: one per bearing."""
    steps = s.get("crank_bearing_l10r_steps")
    if not steps:
        return []
    return [[f"L10r flexible/rigid in steps, bearing {b['bearing']}", _line(b).split(" = ", 1)[1] + f" = {sig(b['L10r_ratio'], '.3f')}"]
            for b in steps["bearings"]]


KEYS = (
    KeyRow('`crank_bearing_l10r_steps`',
           'object or null',
           "the flexible/rigid L10r ratio of the crank bearing in depth taken apart (bearing model `rollers` with the handbook defined, else null; docs/theory.md, \"The crank bearing in depth\"): handbook → pin friction → flexible bearing forces → load sharing → tilt, every step the same slices and lamina life with the case's clearance or preload"),
    KeyRow('`crank_bearing_l10r_steps.pin_friction`',
           'float',
           'the case\'s pin friction μ (0: the `pin_friction` factor is 1, no cycle solved again)'),
    KeyRow('`crank_bearing_l10r_steps.bearings[]`, `crank_bearing_l10r_steps.bearings[].bearing`',
           'array, int',
           'one entry per bearing; bearing number (from 1)'),
    KeyRow('`crank_bearing_l10r_steps.bearings[].L10r_h`',
           'object',
           'L10r (h) of each load model, in the order of the steps'),
    KeyRow('&nbsp;&nbsp;`.handbook`, `.flexible_forces_frictionless`, `.flexible_forces`, `.flexible_rollers_untilted`, `.flexible`',
           'float',
           'the handbook forces on rigid rings (`crank_bearing_depth.bearings[].rigid.L10r_h`); the FE bearing forces of the cycle solved again with μ = 0, on the same rigid rings; the FE bearing forces, rigid rings; the FE roller loads, no crankshaft tilt; the FE roller loads with the tilt (`crank_bearing_depth.bearings[].flexible.L10r_h`)'),
    KeyRow('`crank_bearing_l10r_steps.bearings[].factors`',
           'object',
           'the factors of the steps; their product is `L10r_ratio`'),
    KeyRow('&nbsp;&nbsp;`.pin_friction`, `.bearing_forces`, `.load_sharing`, `.tilt`',
           'float',
           'flexible_forces / flexible_forces_frictionless (the handbook has no friction: measured on the flexible disc); flexible_forces_frictionless / handbook; flexible_rollers_untilted / flexible_forces (the flexible disc against rigid rings under the same forces); flexible / flexible_rollers_untilted'),
    KeyRow('`crank_bearing_l10r_steps.bearings[].L10r_ratio`',
           'float',
           'flexible / handbook, the product of the factors (= `crank_bearing_depth.bearings[].L10r_ratio`)'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("roller_life_steps", summary, KEYS, requires=("case", "theta", "cycle", "rigid", "system"),
                  compute=compute, applies=lambda inputs: inputs["cycle"].roller_loads is not None,
                  stage="roller_slices", executor="thread", screen=screen, screen_rank=50.5, report=report)
