"""The ``references`` section: which rigid references a run is compared with, and why
(:func:`rvfem.evaluate.rigid.references`)."""

from __future__ import annotations

from typing import Any

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'references_dict', 'summary']

def references_dict(refs: Any) -> dict[str, Any]:
    """The ``references`` object of ``summary.json`` and ``rvfem rigid --json``."""
    return {
        "bearing_loads": refs.bearing_loads,
        **{key: {"defined": ref.defined, "why": ref.why} for key, ref in refs.items()},
    }


def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    return {"references": references_dict(a.references)}


KEYS = (
    KeyRow('`references`',
           'object',
           'which rigid references the run is compared with, and why (`rvfem.evaluate.rigid.references`; docs/theory.md, "Any tooth difference")'),
    KeyRow('`references.bearing_loads`',
           'str',
           'the reference of the bearing-load deltas, life ratios and the first attribution step: `handbook`, or `equal_share` where the handbook is not defined (Zp − Zc ≠ 1)'),
    KeyRow('`references.handbook`, `references.classical_pin_forces`, `references.equal_share`',
           'object',
           'the handbook crank-bearing loads, the classical rigid pin-force distribution (`pin_forces.csv`, pin-force plot) and the equal share of the FE pin resultant'),
    KeyRow('&nbsp;&nbsp;`.defined`',
           'bool',
           'true if the reference is computed and compared with; the handbook and the classical distribution are defined for Zp − Zc = 1 only'),
    KeyRow('&nbsp;&nbsp;`.why`',
           'str',
           'one line: what the reference assumes and why it holds, or why it is not defined ("not defined for Zp − Zc ≠ 1: …")'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("references", summary, KEYS,
                  screen=lambda s: ["", *screen_lines.reference_lines(s["references"])], screen_rank=10)
