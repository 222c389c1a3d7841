"""The load-sharing factor of the crank bearing's L10r against the roller law: the roller springs'
compliance scaled by 0.5, 1 and 2 (the FE bore unchanged), the flexible/rigid L10r ratio and its
factors (the result section ``roller_life_steps``) on a shipped case.

Run: ``python benchmarks/bench_roller_law_sensitivity.py [case] [--step DEG]`` (default
cases/rv40e_fanholes.toml at its own step). The rigid reference keeps Palmgren's law (rigid rings),
so the bearing-force and friction factors move only through the flexible cycle.
"""

from __future__ import annotations

import argparse

import numpy as np

from rvfem.app.analysis import analyse
from rvfem.solve import models


def scaled(factor: float):
    """RollerBearing whose law has ``factor`` × its compliance: δ = factor·δ_law(Q)."""

    class Scaled(models.RollerBearing):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            law = self._law

            def soft(delta):
                q, dq = law(np.asarray(delta, dtype=float) / factor)
                return q, dq / factor

            self._law = soft

    return Scaled


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", nargs="?", default="cases/rv40e_fanholes.toml")
    parser.add_argument("--step", type=float, default=None)
    args = parser.parse_args()
    original = models.RollerBearing
    print("compliance  L10r ratio  pin friction  bearing forces  load sharing  tilt")
    for factor in (0.5, 1.0, 2.0):
        cls = scaled(factor) if factor != 1.0 else original
        # the bearing model is looked up by name in the registry: replace the class there
        from rvfem.case import registry
        registry.registered_models("bearing")["rollers"] = cls
        try:
            a = analyse(args.case, angle_step_deg=args.step, recover_stress=False, duty_fe=False, attribute=False)
        finally:
            registry.registered_models("bearing")["rollers"] = original
        s = a.roller_life_steps[0]
        f = s.factors
        print(f"× {factor:<8g}  {s.ratio:10.3f}  {f['pin_friction']:12.3f}  {f['bearing_forces']:14.3f}  "
              f"{f['load_sharing']:12.3f}  {f['tilt']:5.3f}")


if __name__ == "__main__":
    main()
