"""The verification manual's wear section (:mod:`rvfem.app.verification`): Archard's law in closed
form, the sliding identity at the pitch point, the conservation of the worn area over an FE load
cycle, the uniform wear gap against the equidistant modification and the update step's independence
of the transmission-accuracy life (docs/theory.md, "Transmission-accuracy life")."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from rvfem.app.verification_check import Check, Section, _case
from rvfem.app.wear import duty_rows, flank_grid, life_figures, life_loop, wear_rates, worn_stage
from rvfem.evaluate import wear as archard
from rvfem.evaluate.accuracy import quick_figures
from rvfem.geometry import FlankDeviation, pin_phases
from rvfem.mesh import mesh_case
from rvfem.solve.cycle import OperatingPoint, build_system, case_stage, load_cycle

__all__ = ["wear_section"]

LIU = ("Liu et al., Degradation law analysis and life estimation of transmission accuracy of RV reducer based on "
       "tooth surface and bearing wear")


def _archard_checks() -> tuple[Check, ...]:
    """A pin on a flat sliding under it at constant load (Archard's law, Johnson's Hertz footprint)."""
    k, F, L, b, v, dt, steps = 3e-11, 500.0, 9.0, 0.05, 20.0, 1e-3, 200
    nodes = np.linspace(-0.2, 0.2, 4001)
    depth = archard.footprint_wear(nodes, np.zeros(steps), np.full(steps, k * F * v * dt / L), np.full(steps, b))
    s = v * dt * steps
    p_h = 2 * F / (math.pi * b * L)
    ref_depth = archard.archard_depth(k, p_h, s)
    area = float(np.trapezoid(depth, nodes) * L)
    return (
        Check("pin on a flat, depth under the contact centre after s = 4 mm, mm",
              "Archard: k·p_h·s, p_h = 2F/(πbL) the Hertz peak pressure (Archard 1953; Johnson § 4.3)",
              ref_depth, float(depth[2000]), float(depth[2000]) / ref_depth - 1.0, 2e-3),
        Check("pin on a flat, worn volume, mm³", "Archard's global form k·F·s", k * F * s, area,
              area / (k * F * s) - 1.0, 1e-12),
    )


def _sliding_checks() -> tuple[Check, ...]:
    """The cycloid–pin pair's sliding speed and coefficients (RV-40E of Liu et al., Table 1)."""
    K1 = 1.3 * 40 / 64
    psi = np.linspace(0.0, math.pi, 3603)[1:-1]
    kin = archard.mesh_kinematics(64.0, 3.0, 1.3, 40, 39, psi)
    tau = np.sqrt(1 + K1**2 - 2 * K1 * np.cos(psi))
    closed = (64 * tau - 3) / 40
    e_slide = float(np.abs(kin.sliding / closed - 1.0).max())
    pitch = archard.mesh_kinematics(64.0, 64 * (1 - K1), 1.3, 40, 39, np.array([0.0, 0.3]))
    return (
        Check("sliding speed over ψ, mm per rad of crank angle (largest relative error)",
              "(Zp − Zc)/Zp·(Rp·τ − r_rp), τ = √(1 + K1² − 2K1·cos ψ) (" + LIU + ", V_pc^r)",
              float(closed.max()), float(kin.sliding.max()), e_slide, 1e-12),
        Check("sliding at the pitch point (r_rp = Rp(1 − K1), ψ = 0), mm/rad",
              "rolling/sliding decomposition: both bodies move alike at the pitch point", 0.0,
              float(pitch.sliding[0]), float(pitch.sliding[0]), 1e-12, "absolute"),
        Check("sliding coefficients at the pitch point: flank ε, pin ε", "0 where the sliding vanishes", 0.0,
              float(max(pitch.eps_disc[0], pitch.eps_pin[0])), float(max(pitch.eps_disc[0], pitch.eps_pin[0])),
              1e-12, "absolute"),
        Check("largest sliding coefficient of the flank, RV-40E", LIU + ", Figure 9", 2.7258,
              float(kin.eps_disc.max()), float(kin.eps_disc.max()) - 2.7258, 1e-4, "absolute"),
    )


def _life(case, system, step_um: float) -> float:
    worn = case.replace(wear=dataclasses.replace(case.wear, k_flank_pin=4e-10, update_step_um=step_um,
                                                 lost_motion_limit_arcsec=40.0))
    records, _, _ = life_loop(worn, case_stage(system), system, 1e4, 1)
    life = life_figures(records, 40.0)["transmission_accuracy_life_h"]
    return float("nan") if life is None else float(life)


def wear_section(cache) -> Section:
    """The wear rung (coarse solid RV-40E, meshes cached in ``cache``)."""
    case = _case("rv40e_solid")
    case10 = case.replace(analysis=dataclasses.replace(case.analysis, angle_step_deg=10.0))
    system = build_system(case10, mesh_case(case10, cache))
    stage = case_stage(system)
    # conservation over the FE load cycle: k/L·∫ Σ_j F_j·|v_s(ψ_j)| dθ worn per crank revolution
    kin = flank_grid(case10)
    rates = wear_rates(stage, case10, kin, duty_rows(case10))
    cyc = load_cycle(system, op=OperatingPoint(412.0, case10.analysis.friction), stage=stage)
    psi = np.array([pin_phases(case10, t) for t in cyc.theta])
    K1 = 1.3 * 40 / 64
    v = (64 * np.sqrt(1 + K1**2 - 2 * K1 * np.cos(psi)) - 3) / 40
    k, L = case10.wear.k_flank_pin, case10.cycloid.thickness
    area = k / L * float(np.sum((np.asarray(cyc.pin_forces) * v)[psi >= 0])) * 2 * math.pi / len(cyc.theta) * 15 * 60 * 40
    flank = float(np.trapezoid(rates["flank"][0], kin.disc_arc)) * 39
    nodes = np.linspace(-0.5 * math.pi, 0.5 * math.pi, rates["pin"].shape[1]) * 3.0
    pin = float(np.trapezoid(rates["pin"][0], nodes)) * 40
    # a uniform wear gap g against the equidistant modification ΔR_rp = g
    g = 4e-3
    mod = case10.cycloid.modification
    offset_case = case10.replace(cycloid=dataclasses.replace(
        case10.cycloid, modification=dataclasses.replace(mod, equidistant=mod.equidistant + g)))
    lm_dev = quick_figures(worn_stage(system, case10, FlankDeviation.of([0.0, math.pi], [g, g], [g, g])),
                           412.0, case10.analysis.friction)["lost_motion_arcmin"]
    lm_mod = quick_figures(worn_stage(system, offset_case, None), 412.0,
                           case10.analysis.friction)["lost_motion_arcmin"]
    # the update step
    case30 = case.replace(analysis=dataclasses.replace(case.analysis, angle_step_deg=30.0))
    system30 = dataclasses.replace(system, case=case30, contact_sets={})
    life5, life25 = _life(case30, system30, 5.0), _life(case30, system30, 2.5)
    checks = _archard_checks() + _sliding_checks() + (
        Check("flank wear of a load cycle at 412 N·m, all teeth, mm²/h",
              "Archard's global form k/L·∫ Σ_j F_j·|v_s(ψ_j)| dθ over the FE cycle's pin forces", area, flank,
              flank / area - 1.0, 0.02),
        Check("pin wear of the same cycle, all pins, mm²/h", "the same integral (the pin wears the same area)",
              area, pin, pin / area - 1.0, 0.02),
        Check("lost motion, every flank worn by 4 µm, arcmin",
              "the equidistant modification ΔR_rp = 4 µm (an offset profile: every pin gap + 4 µm)", lm_mod, lm_dev,
              lm_dev / lm_mod - 1.0, 1e-3),
        Check("transmission-accuracy life, update step 5 µm against 2.5 µm, h",
              "independent of the step (the issue's acceptance: within 5 %)", life25, life5, life5 / life25 - 1.0,
              0.05),
    )
    return Section("14. Wear and the transmission-accuracy life",
                   "Archard's law on a flat, the cycloid–pin kinematics of Liu et al.'s RV-40E, and the loop over "
                   "life on the coarse RV-40E solid disc (both discs on one carrier, 412 N·m at 15 rpm, μ = 0.05; "
                   "the worn flanks in the FE gaps by pin phase). The life check raises k to 4·10⁻¹⁰ mm²/N and "
                   "ends at 40 arcsec, at 30° crank-angle steps (the life scales as 1/k).", checks)
