"""A stage component written outside the package: a torsional spring between the carrier and the
ground, in series with the stage in the output's load path.

It owns the case table ``[carrier_ground_spring]`` with one key, its stiffness k_t (N·mm/rad); a
case without the table has no such spring. Its part of the stage is a series output compliance of
1/k_t (rad/(N·mm)): under the output torque T it turns by T/k_t on top of the stage's carrier
rotation, so that the stage's torsional rigidity K becomes K·k_t/(K + k_t) (springs in series,
1/K_new = 1/K + 1/k_t), and it changes no contact force (the whole output torque passes through it),
so it has no attribution step. Stiffened, its compliance is divided by STIFFEN.

The whole plug-in is this module and one registration line,
``register_stage_component(CarrierGroundSpring())``.
"""

from __future__ import annotations

from dataclasses import dataclass

from rvfem.case.schema import param
from rvfem.solve.cycle import ReducerStage
from rvfem.solve.stage_parts import STIFFEN, StageComponent


@dataclass(frozen=True)
class CarrierGroundSpringTable:
    """The keys of ``[carrier_ground_spring]``."""

    stiffness_Nmm_per_rad: float = param(unit="N·mm/rad", low=0.0, low_open=True,
                                         doc="torsional stiffness k_t of the spring between the carrier and the ground")


class CarrierGroundSpring(StageComponent):
    """A torsional spring of stiffness k_t between the carrier and the ground."""

    name = "carrier–ground spring"
    table, schema = "carrier_ground_spring", CarrierGroundSpringTable
    held = "a torsional spring between the carrier and the ground"
    step = None

    def build(self, stage: ReducerStage) -> ReducerStage:
        """The stage with the series output compliance 1/k_t, rad/(N·mm)."""
        k = self.parameters(stage.first.case).stiffness_Nmm_per_rad
        return stage.with_output_compliance(self.name, 1.0 / k)

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        """The spring STIFFEN times stiffer: its compliance / STIFFEN."""
        c = stage.output_compliance(self.name)
        if c is None:
            raise ValueError("the stage has no carrier–ground spring")
        return stage.with_output_compliance(self.name, c / STIFFEN)
