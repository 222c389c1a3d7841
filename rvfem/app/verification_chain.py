"""The verification manual's checks of the FE chain on the coarse RV-40E pair: rigid limits,
equilibrium and symmetry (sections 4-6), mesh convergence (7), the reducer stage (8), the crank-bearing
clearance (9), transmission accuracy (10), the crank bearing in depth (11), disc mass and strength (12).

The discs and their models are built once per generator run (:class:`_Discs`); the beam integrated
numerically that the stage is checked against is written here, independently of the code it checks.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from rvfem.app.verification_check import (
    CASES,
    COARSE_MESH,
    STEP_DEG,
    Check,
    Section,
    _case,
    _thetas,
)
from rvfem.case.definition import RollerProfile, load_case
from rvfem.evaluate import compare, lubrication, rigid, roller_life, roller_slices, strength
from rvfem.evaluate.accuracy import ARCMIN_PER_RAD, accuracy_figures
from rvfem.evaluate.hertz import composite_modulus, hertz_peak_pressure, reduced_radius
from rvfem.evaluate.iso281 import crank_bearing_rating
from rvfem.evaluate.rigid import handbook_bearing_loads
from rvfem.fem import crankshaft
from rvfem.geometry import Circle, FanHole, disc_geometry, mass
from rvfem.mesh import mesh_case
from rvfem.solve import accuracy, contact, cycle, models
from rvfem.solve.cycle import build_system
from rvfem.units import nmm_from_nm


# ------------------------------------------------------------------------------------------------
# 4-6. Rigid limits, equilibrium, symmetry (the FE chain on the RV-40E pair)
# ------------------------------------------------------------------------------------------------


@dataclass
class _Discs:
    """The coarse RV-40E discs and their models, built once per generator run."""

    cache: Path
    systems: dict

    def system(self, name: str, **options):
        key = (name, tuple(sorted(options.items())))
        if key not in self.systems:
            case = _case(name)
            self.systems[key] = build_system(case, mesh_case(case, self.cache), **options)
        return self.systems[key]


def rigid_limit_section(discs: _Discs) -> Section:
    theta = _thetas()
    stiff = dict(stiffness_scale=1e6, bearing_model="rigid_bore", bearing_stiffness_scale=1e3,
                 pin_model="linear", pin_stiffness_N_per_mm=3e5)
    # the handbook and the classical distribution have no friction
    case = _case("rv40e_solid", "analysis.friction=0")
    system = dataclasses.replace(discs.system("rv40e_solid", **stiff), case=case)
    one = cycle.load_cycle(system, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(system))
    # the carrier torque is about the reducer axis: the handbook's torque about the disc centre is T·Zc/Zp
    hb_case = case.replace(loads=dataclasses.replace(case.loads, torque_Nm=case.loads.torque_Nm
                                                     * case.cycloid.teeth / case.pins.count))
    hb = rigid.handbook_bearing_loads(hb_case, theta)
    f_max = hb.magnitude.max()
    hb_vec = np.stack([hb.fx, hb.fy], axis=-1).transpose(1, 0, 2)
    e_vec = np.abs(one.bearing_forces - hb_vec).max() / f_max
    pins = rigid.classical_pin_forces(hb_case, theta, exact_moment=True).magnitude.T
    e_pin = np.abs(one.pin_forces - pins).max() / pins.max()
    loaded = set(int(n) for n in one.pins_in_contact)
    pair_stage = cycle.build_stage(system, discs=2, influence=None)
    pair = cycle.load_cycle(system, theta, saved_angles_deg=(), stage=pair_stage)
    T = nmm_from_nm(case.loads.torque_Nm)
    share = np.abs(pair.disc_torque_Nmm / (T / 2) - 1.0).max()
    e_pair = np.abs(pair.bearing_loads.T - hb.magnitude).max() / f_max
    linear = discs.system("rv40e_solid", stiffness_scale=1e3)
    lin_case = _case("rv40e_solid", 'crank_bearing.stiffness_law="linear"',
                     "crank_bearing.linear_stiffness_N_per_mm=2e5", "analysis.friction=0")
    lin_system = dataclasses.replace(linear, case=lin_case,
                                     bearings=models.bearing_model("rollers")(lin_case, 1.0))
    lin = cycle.load_cycle(lin_system, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(lin_system))
    e_share = (np.abs(lin.bearing_forces - compare.equal_share_forces(lin_case, lin)).max()
               / lin.bearing_loads.max())
    hand = ("handbook model, Gao et al. eqs. 4-10 (rigid disc, T/2 per disc about its centre) at T·Zc/Zp: the "
            "output torque about the reducer axis")
    classical = "classical rigid pin-force distribution F_i = F_max·sin φ_i/√(1 + K1² − 2K1 cos φ_i)"
    checks = (
        Check("one disc 10⁶× stiffer, rigid bores: bearing force vectors vs handbook", hand, "handbook",
              f"{f_max:.1f} N peak", e_vec, 0.03, "relative to F_max"),
        Check("same: pin forces vs the classical distribution", classical, "classical",
              f"{pins.max():.1f} N peak", e_pin, 0.01, "relative to F_max"),
        Check("same: pins in contact at every angle", "classical: half the pins (0 < φ < π)",
              case.pins.count // 2, "/".join(str(n) for n in sorted(loaded)),
              max(abs(n - case.pins.count // 2) for n in loaded), 0.0, "absolute"),
        Check("stiff disc 1000×, linear rollers: bearing forces vs equal share of the FE pin resultant",
              "handbook load sharing (each bearing 1/N of the pin resultant plus the torque share)",
              "equal share", f"{lin.bearing_loads.max():.1f} N peak", e_share, 0.005, "relative to F_max"),
        Check("two stiff discs on one carrier: torque share T_disc/(T/2) − 1", "rigid limit of the pair: "
              "equal stiffness gives equal shares", 0.0, share, share, 0.005, "absolute"),
        Check("two stiff discs: bearing loads vs handbook", hand, "handbook", f"{pair.bearing_loads.max():.1f} N peak",
              e_pair, 0.03, "relative to F_max"),
    )
    return Section("4. Rigid limits and the torque split of stiff discs",
                   f"Coarse RV-40E solid disc, {STEP_DEG:g}° steps; 'stiff' is the disc 10⁶× stiffer, "
                   "rigid-bore bearings 1000× stiffer and linear pin springs of 3e5 N/mm, no pin friction (the "
                   "handbook's assumptions).", checks)


def invariants_section(discs: _Discs) -> tuple[Section, Section]:
    theta = _thetas()
    solid = discs.system("rv40e_solid")
    case = solid.case
    one = cycle.load_cycle(solid, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(solid))
    # the bores about the reducer axis, which sits at −e·u(θ) in the disc frame
    e = case.cycloid.eccentricity
    c = cycle.crank_centres(case)[None] + e * np.stack([np.cos(theta), np.sin(theta)], axis=-1)[:, None]
    f = one.bearing_forces
    moment = (c[..., 0] * f[..., 1] - c[..., 1] * f[..., 0]).sum(axis=1)
    e_moment = np.abs(moment / case.loads.disc_torque_Nmm - 1.0).max()
    fan = discs.system("rv40e_fanholes")
    stage = cycle.case_stage(fan)
    pair = cycle.load_cycle(fan, theta, saved_angles_deg=(), stage=stage)
    assert pair.disc_torque_Nmm is not None   # a stage's cycle has the disc torques
    T = nmm_from_nm(fan.case.loads.torque_Nm)
    e_carrier = np.abs(pair.disc_torque_Nmm.sum(axis=1) / T - 1.0).max()
    eq = Section("5. Equilibrium", "Every solve: pins and bearings balance on each disc; the carrier "
                 "takes the output torque.", (
                     Check("one disc: ‖ΣF‖ / Σλ over the cycle (solid)", "Newton's third law", 0.0,
                           float(one.equilibrium_residual.max()), float(one.equilibrium_residual.max()), 1e-9,
                           "relative"),
                     Check("one disc: bearings' moment about the reducer axis / disc torque − 1 (solid)",
                           "moment balance", 0.0, e_moment, e_moment, 1e-9, "relative"),
                     Check("two discs on crankshafts: (T_A + T_B)/T_out − 1 (fan holes)", "carrier moment balance",
                           0.0, e_carrier, e_carrier, 1e-12, "relative"),
                     Check("two discs on crankshafts: ‖ΣF‖ / Σλ (fan holes)", "Newton's third law", 0.0,
                           float(pair.equilibrium_residual.max()), float(pair.equilibrium_residual.max()), 1e-9,
                           "relative"),
                 ))

    shift = int(round(360.0 / case.cranks.count / STEP_DEG))
    full_case = _case("rv40e_solid", "mesh.symmetric=false")
    full = build_system(full_case, mesh_case(full_case, discs.cache))
    every = cycle.load_cycle(full, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(full))
    F = every.bearing_loads
    e = max(np.abs(F[:, i] - np.roll(F[:, 0], i * shift)).max() for i in range(1, case.cranks.count)) / F.max()
    rows = [Check("one solid disc, full-disc mesh, every angle solved: bearing i at θ + 120°·i vs bearing 1 "
                  "at θ", "N-fold symmetry (Zc = 39 divisible by N = 3)", 0.0, float(e), float(e), 0.005,
                  "relative to F_max")]
    worst = 0.0
    for j in (7, 20, 33):               # pairs obtained by 120° turns and 180° swaps
        direct = cycle.solve_pair(stage, float(theta[j]))
        worst = max(worst, float(np.abs(direct.bearing_forces[0] - pair.bearing_forces[j]).max()))
    worst /= float(pair.bearing_loads.max())
    rows.append(Check("fan-hole pair on crankshafts, symmetric mesh: pairs turned and swapped from "
                      f"{pair.timings['pair_solves']} solved ones vs the same pairs solved directly",
                      "exact N-fold and mirror symmetry of the mesh and the load cycle", 0.0, worst, worst, 1e-8,
                      "relative to F_max"))
    sym = Section("6. Symmetry", "A full-disc (unstructured) mesh is not exactly symmetric: its bearing curves "
                  "agree to discretisation accuracy. The default mesh of an N-fold symmetric disc is one "
                  "360°/N sector copied by rotation: exactly symmetric, so the crank angles of one sector "
                  "give the others by turning, to round-off.", tuple(rows))
    return eq, sym


# ------------------------------------------------------------------------------------------------
# 7. Mesh convergence and P1 vs P2
# ------------------------------------------------------------------------------------------------


def convergence_section(discs: _Discs) -> Section:
    theta = _thetas()
    levels = (("coarse", ("mesh.size_flank=0.8", "mesh.size_bore=0.8", "mesh.size_interior=5",
                          "mesh.size_hole=1.0")),
              ("medium", COARSE_MESH),
              ("case file", ("mesh.size_flank=0.35", "mesh.size_bore=0.4", "mesh.size_interior=2.5",
                             "mesh.size_hole=0.5")))

    peaks, nodes = [], []
    for _, sizes in levels:
        case = load_case(CASES / "rv40e_fanholes.toml", sizes)
        mesh = mesh_case(case, discs.cache)
        system = cycle.build_system(case, mesh)
        one_disc = cycle.single_disc_stage(system)
        peaks.append(float(cycle.load_cycle(system, theta, saved_angles_deg=(), stage=one_disc).bearing_loads.max()))
        nodes.append(mesh.n_nodes)
    change = peaks[2] / peaks[1] - 1.0
    p2 = discs.system("rv40e_fanholes", order=2)
    p1 = discs.system("rv40e_fanholes")
    f2 = float(cycle.load_cycle(p2, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(p2)).bearing_loads.max())
    f1 = float(cycle.load_cycle(p1, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(p1)).bearing_loads.max())
    checks = (
        Check(f"fan-hole disc, one disc: peak bearing load, {nodes[1]} → {nodes[2]} nodes, N",
              "validation ladder (docs/theory.md § 10): < 1 % between the two finest meshes", peaks[1], peaks[2], change, 0.01),
        Check(f"same, {nodes[0]} → {nodes[1]} nodes (for the trend), N", "monotone approach", peaks[0], peaks[1],
              peaks[1] / peaks[0] - 1.0, 0.02),
        Check("fan-hole disc, medium mesh: peak bearing load P2 vs P1, N", "P2 is the reference", f2, f1,
              f1 / f2 - 1.0, 0.01),
    )
    return Section("7. Mesh convergence and P1 vs P2",
                   "Fan-hole disc, one disc with T/2, discrete rollers, peak of the three bearings' loads "
                   f"over a turn in {STEP_DEG:g}° steps.", checks)


# ------------------------------------------------------------------------------------------------
# 8. The reducer stage: beams, support springs, crankshaft limits
# ------------------------------------------------------------------------------------------------


def beam_by_integration(span: float, load_at: float, x: np.ndarray, EI: float) -> np.ndarray:
    """Deflection of a simply supported beam under a unit load, integrating M/EI twice (trapezoids,
    2e5 steps) with y(0) = y(L) = 0: independent of the closed forms."""
    s = np.linspace(0.0, span, 200001)
    M = np.where(s <= load_at, (span - load_at) / span * s, load_at / span * (span - s))
    k = M / EI
    slope = np.concatenate([[0.0], np.cumsum(0.5 * (k[1:] + k[:-1]) * np.diff(s))])
    y0 = np.concatenate([[0.0], np.cumsum(0.5 * (slope[1:] + slope[:-1]) * np.diff(s))])
    return np.interp(x, s, -(y0 - y0[-1] * s / span))


def reducer_section(discs: _Discs) -> Section:
    L, EI, kGA = 40.0, 2.0e9, 3.0e7
    roark = "Roark's *Formulas for Stress and Strain*, simply supported beam, central load: L³/(48EI)"
    f_mid = crankshaft.beam_influence(L, [L / 2], EI)[0, 0]
    z = np.array([13.0, 24.5])
    f_two = crankshaft.beam_influence(L, z, EI)
    ref_two = np.column_stack([beam_by_integration(L, z[j], z, EI) for j in range(2)])
    e_two = np.abs(f_two / ref_two - 1.0).max()
    f_shear = crankshaft.beam_influence(L, [L / 2], np.inf, kGA)[0, 0]
    c1, c2 = 2e-6, 5e-6
    f_spring = crankshaft.beam_influence(L, [L / 2], np.inf, None, (c1, c2))[0, 0]
    f_end = crankshaft.beam_influence(L, [1e-6 * L], np.inf, None, (c1, c2))[0, 0]
    checks = [
        Check("beam influence, central load, mm/N", roark, L**3 / (48 * EI), f_mid, f_mid / (L**3 / (48 * EI)) - 1,
              1e-14),
        Check("beam influence matrix, loads at 13 and 24.5 mm of 40 mm, mm/N (all four entries)",
              "M/EI integrated twice numerically (2e5 trapezoids)", float(ref_two[0, 1]), float(f_two[0, 1]),
              e_two, 1e-6),
        Check("Maxwell–Betti: f12 − f21, mm/N", "reciprocity", 0.0, float(f_two[0, 1] - f_two[1, 0]),
              float(f_two[0, 1] - f_two[1, 0]), 0.0, "absolute"),
        Check("shear only, central load, mm/N", "Timoshenko beam: L/(4κGA)", L / (4 * kGA), f_shear,
              f_shear / (L / (4 * kGA)) - 1, 1e-14),
        Check("support springs only, central load, mm/N", "springs and a lever: (c1 + c2)/4", (c1 + c2) / 4,
              f_spring, f_spring / ((c1 + c2) / 4) - 1, 1e-14),
        Check("support springs only, load at the support, mm/N", "the load goes into support 1: c1", c1, f_end,
              f_end / c1 - 1, 1e-5),
    ]
    theta = _thetas()[:6]
    fan = discs.system("rv40e_fanholes")
    rigid = cycle.load_cycle(fan, theta, saved_angles_deg=(), stage=cycle.build_stage(fan, discs=2, influence=None))
    stiff = cycle.load_cycle(fan, theta, saved_angles_deg=(), stage=cycle.build_stage(
        fan, discs=2, influence=1e-14 * np.array([[2.0, 1.0], [1.0, 2.0]])))
    e_stiff = np.abs(stiff.bearing_forces - rigid.bearing_forces).max() / np.abs(rigid.bearing_forces).max()
    checks.append(Check("crankshafts of 10¹⁴ N/mm vs rigid crank support: bearing forces",
                        "limit of a rigid crank support", "rigid support",
                        f"{np.abs(stiff.bearing_forces).max():.1f} N peak", e_stiff, 1e-6, "relative to F_max"))
    f = crankshaft.beam_influence(40.0, [15.0, 25.0], 2e9, 3e7, (2e-6, 2e-6))
    pair = cycle.solve_pair(cycle.build_stage(fan, discs=2, influence=f), 0.3)
    w = -np.einsum("kl,lnj->knj", f, pair.bearing_forces)
    e_w = np.abs(pair.eccentric_displacement - w).max() / np.abs(w).max()
    checks.append(Check("eccentric displacements vs −f·F of both discs' bearing forces",
                        "the crankshaft influence matrix", "−f·F", f"{np.abs(w).max() * 1000:.3f} µm peak",
                        e_w, 1e-12, "relative"))
    # reverse torque: with the cranks at 0°, 120°, 240° the configuration is mirror-symmetric about
    # the x axis, so −T at −θ is the mirror image (x, −y) of +T at θ, bearing at α ↔ bearing at −α



    base = load_case(CASES / "rv40e.toml")
    fwd = base.replace(cranks=dataclasses.replace(base.cranks, angles_deg=(0.0, 120.0, 240.0)))
    rev = fwd.replace(loads=dataclasses.replace(fwd.loads, torque_Nm=-fwd.loads.torque_Nm))
    th = np.radians(np.arange(0.0, 360.0, 7.0))
    a, b = handbook_bearing_loads(fwd, th), handbook_bearing_loads(rev, -th)
    mirror = [0, 2, 1]
    e_rev = max(np.abs(b.fx[mirror] - a.fx).max(), np.abs(b.fy[mirror] + a.fy).max()) / a.magnitude.max()
    checks.append(Check("handbook, reversed torque at −θ vs the mirror image of forward torque at θ",
                        "mirror symmetry of the configuration (cranks at 0°, 120°, 240°)", "mirror image",
                        f"{a.magnitude.max():.1f} N peak", e_rev, 1e-12, "relative to F_max"))
    return Section("8. The reducer stage: crankshaft beams, support springs, limits, reverse torque",
                   "Beam closed forms on a 40 mm span, EI = 2e9 N·mm², κGA = 3e7 N; the crankshaft "
                   f"limits on the coarse fan-hole pair (first six {STEP_DEG:g}° steps); the reverse-torque "
                   "mirror of the handbook model (the FE mirror, on a mirrored mesh, is tests/solve/test_contact.py).",
                   tuple(checks))


# ------------------------------------------------------------------------------------------------
# 9-12. Clearance, accuracy, the crank bearing in depth, mass and strength
# ------------------------------------------------------------------------------------------------


def _roller_pair_with_play(clearance: float, torque: float) -> tuple[float, float, float]:
    """A rigid body held by a stiff ground spring, turned by the carrier through two opposite
    Palmgren rollers with the radial clearance g each, started with both rollers open: (the loaded
    roller's force, the carrier travel φ, the closed form a + g + δ_Palmgren(T) of φ)."""
    length, k_ground = 9.0, 1e9
    law = contact.palmgren_law(length, contacts=2)
    iface = type("Interface", (), {"resultants": np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])})()
    compliance = type("Compliance", (), {"C": np.zeros((2, 2), order="F"), "ensure": lambda self, cols: None})()
    W = sp.csc_matrix(np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.0]]))
    cset = contact.ContactSet(W, np.zeros(3, dtype=bool), np.zeros(3), np.array([-clearance, -clearance, 0.0]),
                              np.array([1.0, -1.0, 0.0]),
                              [(np.arange(2), law), (np.array([2]), contact.linear_law(k_ground, bilateral=True))])
    start = [contact.AngleSolution(np.zeros(3), np.zeros((3, 2)), np.zeros(3), np.zeros(3), 0.0, 0)]
    sol = contact.solve_bodies([contact.Body(cset, iface, compliance)], torque, start=start, rigid_dofs=(0,))[0]
    palmgren = 2 * contact.PALMGREN_COEFFICIENT * torque**0.9 / length**0.8
    return float(sol.force[0]), float(sol.carrier_rotation), float(sol.rigid[0]) + clearance + palmgren


def clearance_section(discs: _Discs) -> Section:
    theta = _thetas()
    force, phi, phi_ref = _roller_pair_with_play(0.01, 500.0)
    # a 5 µm preload on a (1000×) rigid disc at a vanishing torque: every roller at Palmgren's load
    # of its 2.5 µm approach
    stiff = discs.system("rv40e_solid", stiffness_scale=1e3)
    pre_case = _case("rv40e_solid", "crank_bearing.radial_clearance=-0.005", "loads.torque_Nm=0.001")
    pre = dataclasses.replace(stiff, case=pre_case, bearings=models.bearing_model("rollers")(
        pre_case, 1.0, disc_stiffness_scale=stiff.stiffness_scale))
    rollers = cycle.solve_angle(pre, 0.3).roller_loads
    assert rollers is not None   # the 'rollers' bearing model
    b = pre_case.crank_bearing
    q = (0.0025 * b.roller_length**0.8 / (2 * contact.PALMGREN_COEFFICIENT)) ** (1 / 0.9)
    # a 20 µm clearance on the flexible disc: every angle carries the torque (rvfem 0.3 lost it)
    gap_case = _case("rv40e_solid", "crank_bearing.radial_clearance=0.02")
    base = discs.system("rv40e_solid")
    gap = dataclasses.replace(base, case=gap_case, bearings=models.bearing_model("rollers")(gap_case, 1.0))
    run = cycle.load_cycle(gap, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(gap))
    T = gap_case.loads.disc_torque_Nmm
    e_torque = max(abs(r.solution.residual["torque_Nmm"] / T - 1.0) for r in run.solutions)
    palmgren = "Palmgren's line contact δ = 2·3.84e-5·Q^0.9/L^0.8 (Harris & Kotzalas), both raceways"
    checks = (
        Check("roller pair with 10 µm play, started with both rollers open: loaded roller force, N",
              "equilibrium: the carrier torque T on a unit lever", 500.0, force, force / 500.0 - 1.0, 1e-9),
        Check("same: carrier travel φ, mm", "a + g + δ_Palmgren(T) (" + palmgren + ")", phi_ref, phi,
              phi / phi_ref - 1.0, 1e-7),
        Check("5 µm preload, disc 1000× stiffer, 1e-3 N·m: every roller's load, N",
              palmgren + " at the 2.5 µm approach", q, f"{rollers.min():.1f}–{rollers.max():.1f}",
              float(np.abs(rollers / q - 1.0).max()), 0.01),
        Check("20 µm clearance, flexible disc: torque carried at every angle, T_disc",
              "the carrier equation Σ m·λ = T_disc", 1.0, 1.0 + e_torque, e_torque, 1e-9),
    )
    return Section("9. Crank-bearing clearance and preload",
                   f"Coarse RV-40E solid disc, {STEP_DEG:g}° steps, one disc with T/2. A clearance opens every "
                   "roller by half of it at zero load, a preload (negative clearance) compresses every roller "
                   "by half of it; the solve carries the disc through a clearance onto its rollers.", checks)


def roller_depth_section() -> Section:
    """11. The crank bearing in depth: Hertz check of Zhang et al., the logarithmic profile's design
    property, the lamina life at the rating, the film against a second formula, the crankshaft slope."""
    zhang = ("Zhang et al., *Contact load and elastohydrodynamic lubrication analysis of eccentric bearings in RV "
             "reducer considering the effects of roller profile modification*")
    p_zhang = hertz_peak_pressure(1978.0, 8.5, 0.095)
    e_star, r_in = composite_modulus(206000.0, 0.3), reduced_radius(2.5, 13.0, concave=False)
    log = roller_slices.roller_contact(1978.0, 9.0, r_in, e_star, RollerProfile(kind="logarithmic", design_load_N=1978.0),
                                       slices=60)
    # over the inner 80 % of the effective length: the end-refined slices resolve a rise of the load
    # per length within a few µm of the ends, 1.4 % over ±b there (docs/theory.md § 12)
    core = log.pressure_MPa[np.abs(log.x_mm) < 0.4 * 9.0]
    log_spread = float(core.max() / core.min())
    case = _case("rv40e_fanholes")
    c = crank_bearing_rating(case.crank_bearing)
    qci, qce = roller_life.lamina_ratings(case, 30)
    z = case.crank_bearing.rollers
    damage = []
    for phase in np.linspace(0.0, 2.0 * math.pi / z, 8, endpoint=False):
        # ISO/TS 16281 rates the laminae from C/λν (λν: ISO 281's allowance for edge stresses)
        q = roller_slices.rigid_ring_roller_loads(np.array([c / case.crank_bearing.lambda_nu, 0.0]),
                                                  phase + 2.0 * np.pi * np.arange(z) / z)
        lam = np.repeat(q[:, None] / 30.0, 30, axis=1)
        damage.append(1.0 / float(roller_life.lamina_life_mrev(lam, lam, qci, qce, inner_rotates=True)))
    life = 1.0 / float(np.mean(damage))
    film = lubrication.pan_hamrock_film(143.0, r_in, e_star, 0.025, 0.474, 20.0).minimum_um
    film_dh = lubrication.dowson_higginson_min_film(143.0, r_in, e_star, 0.025, 0.474, 20.0)
    span, ei = 33.0, 206000.0 * math.pi * 20.0**4 / 64.0
    slope = float(roller_life.beam_slope_influence(span, [1e-9, span / 2.0], ei)[0, 1])
    checks = (
        Check("Hertz peak of Zhang et al.'s roller, Q = 1978 N, L = 8.5 mm, b = 95 µm, MPa", zhang + ", p_h = 1.56 GPa",
              1560.0, p_zhang, p_zhang / 1560.0 - 1.0, 0.005),
        Check("logarithmic (Johns–Gohar) roller at its design load 1978 N: largest / smallest pressure along "
              "the inner 80 % of the roller",
              "Lundberg's profile: uniform pressure along the roller", 1.0, log_spread, log_spread - 1.0, 0.01),
        Check("lamina life (ISO/TS 16281) at P = C/λν, rigid rings, straight rollers, 10⁶ rev",
              "definition of the basic dynamic load rating C (ISO 281), the laminae rated from C/λν (ISO/TS 16281)",
              1.0, life, life - 1.0, 0.01),
        Check("minimum film, 143 N/mm, 25 mPa·s, 0.47 m/s, α = 20/GPa (Pan & Hamrock), µm",
              "Dowson & Higginson's line-contact h_min", film_dh, film, film / film_dh - 1.0, 0.10),
        Check("crankshaft slope at a support under a central load, rad/N",
              "Roark: P·L²/(16·EI)", span**2 / (16.0 * ei), slope, slope / (span**2 / (16.0 * ei)) - 1.0, 1e-6),
    )
    return Section("11. The crank bearing in depth",
                   "The slice model of a roller on an elastic half-space, the ISO/TS 16281 lamina life, the EHL film "
                   "and the crankshaft's slope at the eccentrics (docs/theory.md § 12). The slice model against a "
                   "two-dimensional half-space solve is in tests/evaluate/test_roller_slices.py.", checks)


def _stiff_accuracy_stage(discs: _Discs, *overrides: str):
    """The coarse solid RV-40E in the stiff limit of the accuracy checks: disc ×10³, linear pins of
    2·10⁸ N/mm and rollers of 3·10⁷ N/mm, rigid eccentrics, both discs; ``overrides`` add the play."""
    case = _case("rv40e_solid", "pins.model='linear'", "pins.linear_stiffness_N_per_mm=2e8",
                 "crank_bearing.stiffness_law='linear'", "crank_bearing.linear_stiffness_N_per_mm=3e7", *overrides)
    system = build_system(case, mesh_case(case, discs.cache), stiffness_scale=1e3)
    return cycle.build_stage(system, discs=2, influence=None)


def accuracy_section(discs: _Discs) -> Section:
    T = 412.0
    linear = _case("rv40e_solid", "pins.model='linear'", "pins.linear_stiffness_N_per_mm=2e5",
                   "crank_bearing.stiffness_law='linear'", "crank_bearing.linear_stiffness_N_per_mm=3e5")
    stage = cycle.case_stage(build_system(linear, mesh_case(linear, discs.cache)))
    loop = accuracy.hysteresis_loop(stage, 0.3, T, steps=8)
    phi = cycle.solve_pair(stage, 0.3, op=cycle.OperatingPoint(T)).output_rotation   # with the series parts
    plus = loop.torque_Nm > 0
    e_lin = float(np.abs(loop.torque_Nm[plus] / loop.rotation_rad[plus] / (T / phi) - 1.0).max())
    dr, g2 = 0.01, 0.01
    eq = _stiff_accuracy_stage(discs, f"cycloid.modification.equidistant={dr}")
    fig_eq = accuracy_figures(*_loop_arrays(accuracy.hysteresis_loop(eq, 0.0, T, steps=8)), T)
    c = eq.first.case
    e, zc, zp = c.cycloid.eccentricity, c.cycloid.teeth, c.pins.count
    ref_eq = 2.0 * dr / (e * zp) * ARCMIN_PER_RAD
    sh = _stiff_accuracy_stage(discs, f"cycloid.modification.shift={-dr}")
    fig_sh = accuracy_figures(*_loop_arrays(accuracy.hysteresis_loop(sh, 0.0, T, steps=8)), T)
    k1 = e * zp / c.pins.circle_radius
    ref_sh = 2.0 * dr * np.sqrt(1.0 - k1 ** 2) / (e * zp) * ARCMIN_PER_RAD
    cl = _stiff_accuracy_stage(discs, f"crank_bearing.radial_clearance={g2}")
    fig_cl = accuracy_figures(*_loop_arrays(accuracy.hysteresis_loop(cl, 0.0, T, steps=8)), T)
    ref_cl = g2 * zc / (c.cranks.circle_radius * zp) * ARCMIN_PER_RAD
    liu = ("Liu et al., Degradation law analysis and life estimation of transmission accuracy of RV reducer "
           "based on tooth surface and bearing wear, § 4.4")
    checks = (
        Check("linear pins and rollers, no play: T/φ at every step of the + branches / T_R/φ(T_R)",
              "one stage solve at T_R (φ ∝ T without gaps)", 1.0, 1.0 + e_lin, e_lin, 1e-7),
        Check("lost motion, equidistant ΔR_rp = 10 µm only, stiff limit, θ = 0, arcmin",
              "rigid kinematics about the reducer axis: 2ΔR_rp/(e·Zp) (Liu et al.'s ΔB_c with the lever e·Zp "
              "for e·Zc; " + liu + ")", ref_eq, fig_eq.lost_motion_arcmin,
              fig_eq.lost_motion_arcmin / ref_eq - 1.0, 0.005),
        Check("lost motion, pin-circle shift ΔR_p = −10 µm only, stiff limit, θ = 0, arcmin",
              "rigid kinematics about the reducer axis: 2|ΔR_p|·√(1 − K1²)/(e·Zp) (docs/theory.md § 9b)",
              ref_sh, fig_sh.lost_motion_arcmin, fig_sh.lost_motion_arcmin / ref_sh - 1.0, 0.005),
        Check("lost motion, crank-bearing clearance 10 µm only, stiff limit, θ = 0, arcmin",
              "rigid kinematics about the reducer axis: Δu·Zc/(r0·Zp), Δu the clearance (Liu et al.'s ΔB_tb, "
              "a_sp = r0, × Zc/Zp; " + liu + ")", ref_cl, fig_cl.lost_motion_arcmin,
              fig_cl.lost_motion_arcmin / ref_cl - 1.0, 0.005),
    )
    return Section("10. Transmission accuracy: the hysteresis loop",
                   "Coarse RV-40E solid disc, both discs on one carrier, input locked (crank angle held), the "
                   "loop 0 → +412 → 0 → −412 → 0 N·m in 8 steps. Stiff limit: disc ×10³, linear pins 2·10⁸ N/mm, "
                   "rollers 3·10⁷ N/mm, rigid eccentrics. The closed forms are the rigid kinematics of the carrier and "
                   "the stiff discs turning about the reducer axis (docs/theory.md § 9b).", checks)


def _loop_arrays(loop) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return loop.torque_Nm, loop.rotation_rad, loop.branch


def _sector_disc_checks() -> tuple[Check, ...]:
    """A disc of a 3600-gon (circumradius 60 mm), a central hole (12), three bores (9 at 36 mm) and
    three sharp annular-sector holes (17…49 mm, 0.6 rad) against the closed forms."""
    n, R, beta = 3600, 60.0, 2 * math.pi / 3600
    a_out = 0.5 * n * R * R * math.sin(beta)
    j_out = a_out * R * R * (2 + math.cos(beta)) / 6
    a_ref = a_out - math.pi * 12**2 - 3 * math.pi * 9**2 - 3 * 0.3 * (49**2 - 17**2)
    j_ref = (j_out - math.pi * 12**4 / 2 - 3 * (math.pi * 9**4 / 2 + math.pi * 9**2 * 36**2)
             - 3 * 0.3 * (49**4 - 17**4) / 2)
    ang = 2 * np.pi * np.arange(n) / n
    outline = np.stack([R * np.cos(ang), R * np.sin(ang)], axis=1)
    area, polar = mass.polygon_area_polar(outline)
    for f in [Circle("central_hole", (0.0, 0.0), 12.0)] + [
            Circle(f"bore_{i}", (36 * math.cos(a), 36 * math.sin(a)), 9.0) for i, a in enumerate(np.radians([90, 210, 330]))] + [
            FanHole(f"hole_{i}", 17.0, 49.0, math.radians(30 + 120 * i), 0.3, 0.0) for i in range(3)]:
        a, j = mass.outline_area_polar(f)
        area, polar = area - a, polar - j
    source = "closed forms: n-gon, circles by parallel axes, annular sectors α(r_o² − r_i²), α(r_o⁴ − r_i⁴)/2"
    return (Check("disc with three annular-sector holes: area, mm²", source, a_ref, area, area / a_ref - 1, 1e-9),
            Check("same: polar moment ∬ r² dA, mm⁴", source, j_ref, polar, polar / j_ref - 1, 1e-9))


def mass_strength_section(discs: _Discs) -> Section:
    """Disc mass and polar inertia against closed forms and the mesh integral; the fatigue safety
    factor against the Goodman line by hand."""
    case = _case("rv40e_fanholes")
    props = mass.disc_mass_properties(disc_geometry(case))
    m = mesh_case(case, discs.cache)
    a_mesh, j_mesh = mass.mesh_area_polar(m.points, m.triangles)
    theta = np.radians(np.arange(0.0, 360.0, 1.0))
    steel = case.material
    sa, sm = 300.0, 200.0
    s1 = sm + sa * np.sin(theta)
    amp, mean = strength.amplitude_mean(strength.signed_von_mises(s1, np.zeros_like(s1)))
    hand = 1.0 / (sa / steel.fatigue_limit + sm / steel.ultimate_strength)
    sf = strength.goodman_safety_factor(float(amp), float(mean), steel.fatigue_limit, steel.ultimate_strength)
    sf48 = strength.goodman_safety_factor(48 * float(amp), 48 * float(mean), steel.fatigue_limit,
                                          steel.ultimate_strength)
    checks = _sector_disc_checks() + (
        Check("coarse fan-hole disc: area from the P1 mesh, mm²", "Green's theorem over the outlines (rvfem.geometry.mass)",
              props.area_mm2, a_mesh, a_mesh / props.area_mm2 - 1, 5e-4),
        Check("same: polar moment from the P1 mesh, mm⁴", "Green's theorem over the outlines",
              props.polar_mm4, j_mesh, j_mesh / props.polar_mm4 - 1, 5e-4),
        Check("plate, σ = 200 + 300 sin θ MPa uniaxial: fatigue safety factor",
              f"Goodman by hand, 1/(σ_a/σ_W + σ_m/R_m), σ_W = {steel.fatigue_limit:g}, R_m = {steel.ultimate_strength:g} MPa",
              hand, sf, sf / hand - 1, 1e-12),
        Check("same, load × 48: fatigue safety factor", "proportional scaling: S/48", hand / 48, sf48,
              sf48 / (hand / 48) - 1, 1e-12),
    )
    return Section("12. Disc mass, inertia and fatigue strength",
                   "Mass and polar inertia by Green's theorem over the outlines (docs/theory.md § 13) against closed "
                   "forms and against the coarse P1 mesh (straight-sided triangles: the chords of the curved "
                   "boundaries, an error falling as h²); the fatigue safety factor (FKM signed von Mises on the "
                   "Goodman line) of a plate under an alternating uniaxial stress against the hand calculation.",
                   checks)
