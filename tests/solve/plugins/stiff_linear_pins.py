"""A pin law written outside rvfem, in one module: linear pin springs of a fixed, very high
stiffness (:data:`STIFFNESS`), to be compared with the built-in rigid pins. A test registers it with
one line (``register_pin_model(StiffLinearPins)``)."""

from __future__ import annotations

from rvfem.solve import contact

STIFFNESS = 1.0e9
"""N/mm: about 10⁴ times a Hertz pin–flank contact's secant stiffness."""


class StiffLinearPins:
    name = "test_stiff_linear_pins"
    rigid = False

    def __init__(self, case, stiffness_N_per_mm=None):
        self.case = case

    def describe(self) -> str:
        return f"linear pin springs of {STIFFNESS:g} N/mm (a test plug-in)"

    def law(self, contacts=None, curvature=None):
        return contact.linear_law(STIFFNESS)
