"""The main bearings: ``[main_bearings]``, a stage component (:mod:`rvfem.solve.stage_parts`).

The carrier runs in the housing on a preloaded pair of angular-contact ball bearings (back to back,
the RV-E construction). The pair carries the external loads of the output — a radial force and a
tilting moment — straight from the carrier into the housing; the model gives its radial and tilt
stiffness from the bearing geometry (:func:`pair_stiffness`), linearised about the preload.

**How it enters the torsional accuracy: not at all.** A ball's contact normal lies in the plane
through the reducer axis (contact angle α in that plane), so a rotation of the carrier about the
axis changes no ball's approach: the pair's stiffness matrix has no torsional term and it passes no
part of the output torque. Under pure torque the discs' net forces on the carrier (each disc's pin
resultant less its crank-bearing forces is zero; the two discs' crank forces on the carrier cancel
in sum and leave a small couple) load the pair only with that couple, which tilts the carrier about
a radial axis and moves disc A's and disc B's eccentrics by equal and opposite amounts: to first
order no output rotation. So the component adds a series output compliance of exactly zero (its
compliance share is zero) and states the pair's radial and moment rigidity for the external loads.

Ball–raceway contact: Hertz point contact, exact (the contact ellipse's eccentricity solved from
the curvature ratio; Harris & Kotzalas, *Rolling Bearing Analysis*, ch. 6, in the notation of
Hamrock & Brewe, "Simplified solution for stresses and deformations", J. Lubr. Technol. 105, 1983);
each ball a spring along its contact line, of stiffness dQ/dδ = 3Q₀/(2δ₀) at its preload
Q₀ = F_a0/(Z·sin α) (Harris & Kotzalas, ch. 7-8, the bearing's stiffness as the sum of its balls').
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from rvfem.case.definition import Case, register_component_table
from rvfem.case.schema import param
from rvfem.solve.cycle_stage import ReducerStage
from rvfem.solve.stage_component import StageComponent

__all__ = ["MainBearings", "MainBearingsTable", "ball_approach", "ball_stiffness", "pair_stiffness"]

NAME = "main_bearings"


@dataclass(frozen=True)
class MainBearingsTable:
    """The keys of ``[main_bearings]``. Defaults: the RV-40E class, estimated (the catalogue gives the
    outline and the moment rigidity, not the bearings): a back-to-back pair of full-complement rows
    on a 150 mm pitch circle between the case's ends."""

    enabled: bool = param(True, doc="state the main bearings (their torsional compliance is zero)")
    ball_diameter: float = param(7.938, unit="mm", low=0.1, high=500.0, doc="ball diameter D (estimated, 5/16 in)")
    pitch_diameter: float = param(150.0, unit="mm", low=1.0, high=10000.0, doc="ball pitch diameter d_m (estimated)")
    balls: int = param(50, low=3, high=2000, doc="balls per row Z (estimated)")
    contact_angle_deg: float = param(45.0, unit="deg", low=1.0, high=89.0, doc="contact angle α (estimated)")
    row_spacing: float = param(70.0, unit="mm", low=0.0, high=10000.0, doc="axial distance between the rows' ball centres (estimated)")
    inner_conformity: float = param(0.52, low=0.5, low_open=True, high=1.0, doc="inner groove radius / D, f_i (Harris' usual value)")
    outer_conformity: float = param(0.53, low=0.5, low_open=True, high=1.0, doc="outer groove radius / D, f_o (Harris' usual value)")
    preload: float = param(2000.0, unit="N", low=0.0, low_open=True, high=1.0e8, doc="axial preload of the pair F_a0 (estimated)")
    youngs_modulus: float = param(206000.0, unit="MPa", low=1.0e3, high=1.2e6, doc="E of balls and rings (steel)")
    poissons_ratio: float = param(0.3, low=0.0, high=0.5, high_open=True, doc="ν of balls and rings")


def ball_approach(Q: float, rx: float, ry: float, youngs_modulus: float, poissons_ratio: float) -> float:
    """Approach (mm) of a Hertz point contact of principal relative radii ``rx`` ≤ ``ry`` (mm; 1/R_x
    the sum of the two bodies' curvatures in x) under the force Q (N), both bodies of E, ν.

    Exact Hertz: the ellipse's eccentricity m = 1 − 1/k² from
    R_y/R_x = (𝓔(m)/(1 − m) − 𝓚(m))/(𝓚(m) − 𝓔(m)), then
    δ = 𝓚·[9/(2𝓔R)·(Q/(πkE'))²]^(1/3), 1/R = 1/R_x + 1/R_y, E' = E/(1 − ν²), 𝓚 and 𝓔 the complete
    elliptic integrals (Harris & Kotzalas, ch. 6; Hamrock & Brewe's notation, whose fits of k, 𝓚, 𝓔
    this solves exactly instead)."""
    ratio = ry / rx
    R = 1.0 / (1.0 / rx + 1.0 / ry)
    e_prime = youngs_modulus / (1.0 - poissons_ratio ** 2)
    if ratio <= 1.0 + 1e-9:
        m = 0.0
    else:
        def f(m: float) -> float:
            return float((ellipe(m) / (1.0 - m) - ellipk(m)) / (ellipk(m) - ellipe(m)) - ratio)

        m = float(brentq(f, 1e-12, 1.0 - 1e-15, xtol=1e-15))
    k = 1.0 / math.sqrt(1.0 - m)
    return float(ellipk(m) * (9.0 / (2.0 * ellipe(m) * R) * (Q / (math.pi * k * e_prime)) ** 2) ** (1.0 / 3.0))


def ball_stiffness(t: MainBearingsTable) -> float:
    """k_n, N/mm: a ball's stiffness along its contact line (inner and outer contact in series) at
    its share of the preload, 3Q₀/(2δ₀) (δ ∝ Q^(2/3))."""
    D, dm, a = t.ball_diameter, t.pitch_diameter, math.radians(t.contact_angle_deg)
    q0 = t.preload / (t.balls * math.sin(a))
    gamma = D * math.cos(a) / dm
    inner = (0.5 * D * (1.0 - gamma), t.inner_conformity * D / (2.0 * t.inner_conformity - 1.0))
    outer = (0.5 * D * (1.0 + gamma), t.outer_conformity * D / (2.0 * t.outer_conformity - 1.0))
    delta = sum(ball_approach(q0, min(r), max(r), t.youngs_modulus, t.poissons_ratio) for r in (inner, outer))
    return 1.5 * q0 / delta


def pair_stiffness(t: MainBearingsTable) -> np.ndarray:
    """The pair's stiffness matrix (6 × 6) for the carrier's rigid motion (u_x, u_y, u_z in mm;
    rotations γ_x, γ_y, γ_z in rad; N/mm, N, N·mm/rad) about the pair's centre: Σ k_n·g·gᵀ over
    the balls, g the ball's contact normal as a generalised force direction (back to back: the rows
    at z = ±s/2 with their contact lines leaning outward). Its γ_z row and column are zero: the pair
    passes no torque."""
    k = ball_stiffness(t)
    a = math.radians(t.contact_angle_deg)
    rm = 0.5 * t.pitch_diameter
    K = np.zeros((6, 6))
    for row, z in ((-1.0, 0.5 * t.row_spacing), (1.0, -0.5 * t.row_spacing)):   # O: the lines diverge
        for psi in 2.0 * math.pi * np.arange(t.balls) / t.balls:
            er = np.array([math.cos(psi), math.sin(psi), 0.0])
            n = math.cos(a) * er + row * math.sin(a) * np.array([0.0, 0.0, 1.0])     # contact normal
            p = rm * er + np.array([0.0, 0.0, z])                                     # ball centre
            g = np.concatenate([n, np.cross(p, n)])
            K += k * np.outer(g, g)
    return K


class MainBearings(StageComponent):
    """The main bearings (module docstring): zero torsional compliance."""

    name = NAME
    table, schema = NAME, MainBearingsTable
    table_by_default = True
    held = "the main bearings (which pass no torque)"
    step = None
    models = ("main bearings",)

    def present(self, case: Case) -> bool:
        t = self.parameters(case)
        return t is not None and bool(t.enabled)

    def build(self, stage: ReducerStage) -> ReducerStage:
        """The stage with the pair's torsional compliance: zero (module docstring)."""
        K = pair_stiffness(self.parameters(stage.first.case))
        if abs(K[5, 5]) > 1e-9 * abs(K[3, 3]):
            raise ValueError("the main bearings' stiffness has a torsional term")
        return stage.with_output_compliance(self.name, 0.0)

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        if stage.output_compliance(self.name) is None:
            raise ValueError("the stage has no main bearings")
        return stage


register_component_table(NAME, MainBearingsTable, by_default=True, owner=NAME)
