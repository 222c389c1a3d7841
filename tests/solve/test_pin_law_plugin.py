"""A pin law from outside rvfem (tests/solve/plugins/stiff_linear_pins.py, one module and one
registration line): the case accepts its name, the load cycle solves with it, and in its stiff
limit it gives the rigid pins' bearing loads."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import coarse_case

from rvfem.app.analysis import analyse
from rvfem.case import registry


@pytest.mark.slow
def test_a_pin_law_from_outside_tends_to_the_rigid_pins(registries, tmp_path):
    from plugins.stiff_linear_pins import StiffLinearPins

    registry.register_pin_model(StiffLinearPins)           # the one registration line
    assert StiffLinearPins.name in registry.pin_model_names()
    loads = {}
    for model in (StiffLinearPins.name, "rigid"):
        case = coarse_case("rv40e_solid", pins={"model": model})
        a = analyse(case, angle_step_deg=30, cache_dir=tmp_path, recover_stress=False, duty_fe=False, attribute=False)
        assert a.system.pin_model == model
        loads[model] = a.cycle.bearing_loads
    # 10⁹ N/mm against a disc of ~10⁵–10⁶ N/mm at a footprint: the springs add ~1e-4 of the compliance
    np.testing.assert_allclose(loads[StiffLinearPins.name], loads["rigid"], rtol=2e-3)
