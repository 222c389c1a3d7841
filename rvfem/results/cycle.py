"""The load cycle's own figures: pins in contact, the disc's torsional stiffness, carrier rotation,
equilibrium residual and active-set iterations."""

from __future__ import annotations

from typing import Any

import numpy as np

from rvfem.units import arcmin_from_rad

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'summary']

def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    cy = a.cycle
    arcmin = arcmin_from_rad(np.asarray(cy.carrier_rotation))
    return {
        "pins_in_contact": {
            "min": int(cy.pins_in_contact.min()),
            "max": int(cy.pins_in_contact.max()),
            "mean": float(cy.pins_in_contact.mean()),
            "of": a.case.pins.count,
        },
        "torsional_stiffness_Nm_per_arcmin": a.torsional_stiffness_Nm_per_arcmin,
        "carrier_rotation_arcmin": {"min": float(arcmin.min()), "max": float(arcmin.max()),
                                    "mean": float(arcmin.mean())},
        "equilibrium_residual": float(cy.equilibrium_residual.max()),
        "active_set_iterations": {"max": int(cy.iterations.max()), "mean": float(cy.iterations.mean())},
    }


KEYS = (
    KeyRow('`pins_in_contact`',
           'object',
           'pins in contact over the cycle'),
    KeyRow('`pins_in_contact.min`, `pins_in_contact.max`, `pins_in_contact.mean`, `pins_in_contact.of`',
           'int, int, float, int',
           'over the cycle; `of` = Zp'),
    KeyRow('`torsional_stiffness_Nm_per_arcmin`',
           'float',
           'disc torque / mean carrier rotation'),
    KeyRow('`carrier_rotation_arcmin`',
           'object',
           'carrier rotation over the cycle'),
    KeyRow('`carrier_rotation_arcmin.min`, `carrier_rotation_arcmin.max`, `carrier_rotation_arcmin.mean`',
           'float',
           'arcmin'),
    KeyRow('`equilibrium_residual`',
           'float',
           'largest \\|ΣF\\|/Σ\\|λ\\| of the disc over the cycle (should be round-off)'),
    KeyRow('`active_set_iterations`',
           'object',
           'iterations per angle'),
    KeyRow('`active_set_iterations.max`, `active_set_iterations.mean`',
           'int, float',
           'over the cycle'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("cycle", summary, KEYS,
                  screen=screen_lines.cycle_lines, screen_rank=31)
