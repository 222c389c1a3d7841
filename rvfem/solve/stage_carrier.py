"""The carrier: ``[carrier]``, a stage component (:mod:`rvfem.solve.stage_parts`).

The carrier is two end plates joined by pillars that pass through the discs' holes. Each
crankshaft sits in a support bearing in each end plate; the output is taken from one plate (plate
1, at support 1 of ``[crank_support]``), so the torque the crankshafts deliver to the other plate
(plate 2) reaches the output through the pillars. Under that torque T₂ the pillars shear and bend
between the plates and plate 2 turns against plate 1 by Δψ = T₂/k_p.

**Model: a frame of pillars between rigid end plates.** Each pillar is a Timoshenko beam clamped in
both plates; a tangential force F at radius r_p moves one end against the other by
F·(L³/(12EI) + L/(κGA)) (a clamped–guided beam: Roark, *Formulas for Stress and Strain*, Table 8.1,
case 1e with both ends fixed against rotation; shear after Timoshenko), so n pillars give
k_p = n·r_p²/(L³/(12EI) + L/(κGA)) (:func:`pillar_torsional_stiffness`). Why a frame and not a 2D
FE of an end plate: the RV pillars are short and thick (L/t ≈ 1 for the RV-40E class), so they
deform mostly in shear and bending between plates that are several times thicker than they are
long; the plates' in-plane twist between the bearing seats and the pillar roots is a second-order
part that the frame leaves out (the frame is therefore a lower bound on the carrier's compliance;
the pillars' roots turning in the plates would add to it).

**How it enters.** Crank i's eccentric under disc k lies at x_k along the support span s; the
tangential (torque-carrying) force of disc k goes to plate 2 in the share x_k/s (the beam's
reaction), so T₂ = Σ_k T_k·x_k/s, and disc k's eccentric turns with the plates' twist by
(x_k/s)·Δψ (the crankshaft tilts: its two support bearings turn apart by Δψ·r₀). With the discs'
torques T_k = T/discs the output turns by the carrier's share

    Δφ = Σ_k (T_k/T)·(x_k/s)·Δψ = f²·T/k_p,   f = (1/discs)·Σ_k x_k/s,

a series output compliance f²/k_p (:func:`carrier_output_compliance`). That is the torsional part of
the twist. The tilt of each crankshaft also turns disc B against disc A by (x_B − x_A)/s·Δψ, which
shifts the torque between the discs; to first order that changes no output rotation (it is
antisymmetric between the discs) and it is not modelled here (it would need the eccentrics'
tangential displacement in the contact problem). Without ``[crank_support]`` the eccentrics are
taken at mid-span (f = ½).
"""

from __future__ import annotations

from dataclasses import dataclass

from rvfem.case.definition import Case, register_component_table
from rvfem.case.schema import param
from rvfem.solve.cycle_stage import ReducerStage
from rvfem.solve.stage_component import STIFFEN, StageComponent

__all__ = ["Carrier", "CarrierTable", "carrier_output_compliance", "pillar_torsional_stiffness", "plate_two_share"]

NAME = "carrier"


@dataclass(frozen=True)
class CarrierTable:
    """The keys of ``[carrier]``. Defaults: the RV-40E class, estimated from the fan-hole disc of the
    shipped cases (the catalogue gives no carrier dimensions): three pillars through the three
    fan-shaped holes (r 17–49 mm), each the hole less the orbit 2e and a clearance, between plates
    that hold the two 9 mm discs and their axial clearances."""

    enabled: bool = param(True, doc="model the carrier's pillars (false: a rigid carrier, as before)")
    pillars: int = param(3, low=1, high=64, doc="number of pillars between the end plates (estimated: one per fan hole)")
    pillar_radius: float = param(33.0, unit="mm", low=0.1, high=5000.0,
                                 doc="radius of the pillars' centroids (estimated: middle of the fan hole, r 17–49)")
    pillar_radial_size: float = param(26.0, unit="mm", low=0.1, high=5000.0,
                                      doc="pillar section's radial size (estimated: hole height 32 less 2e and clearance)")
    pillar_tangential_size: float = param(18.0, unit="mm", low=0.1, high=5000.0,
                                          doc="pillar section's tangential size, the direction it bends in (estimated)")
    pillar_length: float = param(21.0, unit="mm", low=0.1, high=5000.0,
                                 doc="free length of a pillar between the plates (estimated: two 9 mm discs, 1 mm "
                                     "between them and 1 mm each side)")
    youngs_modulus: float = param(206000.0, unit="MPa", low=1.0e3, high=1.2e6, doc="carrier E (steel, estimated)")
    poissons_ratio: float = param(0.3, low=0.0, high=0.5, high_open=True, doc="carrier ν")


def pillar_torsional_stiffness(t: CarrierTable) -> float:
    """k_p, N·mm/rad: the torque that turns one end plate against the other by one radian through
    the pillars (module docstring): rectangular sections, bending about the radial axis
    (I = b_r·t³/12), shear factor κ = 10(1 + ν)/(12 + 11ν) (Cowper, rectangle)."""
    E, nu = t.youngs_modulus, t.poissons_ratio
    G = E / (2.0 * (1.0 + nu))
    area = t.pillar_radial_size * t.pillar_tangential_size
    second_moment = t.pillar_radial_size * t.pillar_tangential_size ** 3 / 12.0
    kappa = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu)
    L = t.pillar_length
    per_force = L ** 3 / (12.0 * E * second_moment) + L / (kappa * G * area)
    return t.pillars * t.pillar_radius ** 2 / per_force


def plate_two_share(case: Case) -> float:
    """f = (1/discs)·Σ_k x_k/s: the share of the output torque that reaches plate 2 through the
    crankshafts (and the share of the plates' twist the discs turn with); ½ without the beam keys
    of ``[crank_support]``."""
    cs = case.crank_support
    if cs is None or cs.span is None or cs.eccentric_positions is None:
        return 0.5
    x = cs.eccentric_positions[:case.loads.discs]
    return float(sum(x) / (len(x) * cs.span))


def carrier_output_compliance(case: Case, t: CarrierTable) -> float:
    """The carrier's series output compliance f²/k_p, rad/(N·mm) (module docstring)."""
    return plate_two_share(case) ** 2 / pillar_torsional_stiffness(t)


class Carrier(StageComponent):
    """The carrier's end plates and pillars (module docstring)."""

    name = NAME
    table, schema = NAME, CarrierTable
    table_by_default = True
    held = "the carrier's pillars between its end plates"
    step = None
    models = ("carrier end plates",)

    def present(self, case: Case) -> bool:
        t = self.parameters(case)
        return t is not None and bool(t.enabled)

    def build(self, stage: ReducerStage) -> ReducerStage:
        """The stage with the carrier's series output compliance."""
        case = stage.first.case
        return stage.with_output_compliance(self.name, carrier_output_compliance(case, self.parameters(case)))

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        c = stage.output_compliance(self.name)
        if c is None:
            raise ValueError("the stage has no carrier compliance")
        return stage.with_output_compliance(self.name, c / STIFFEN)


register_component_table(NAME, CarrierTable, by_default=True, owner=NAME)
