"""Transmission accuracy: the hysteresis loop with the input locked against independent references.

* the linear limit (no clearance, linear pins and rollers): the loop is the existing solve scaled,
  T/φ at every step equal to T_R/φ(T_R) of one :func:`rvfem.solve.cycle.solve_pair`;
* the profile modifications (Liu et al.'s equidistant ΔR_rp and pin-circle shift ΔR_p, each alone
  and together), stiff limit: lost motion and backlash against the rigid kinematics of the carrier
  and discs turning about the reducer axis, 2·(ΔR_rp − ΔR_p·√(1 − K1²))/(e·Zp) (or
  2·√(ΔR_rp² − ΔR_p²)/Rp when the first contact is between tip and pitch point), docs/theory.md;
* a crank-bearing clearance and a support-bearing clearance, each alone, stiff limit: lost motion
  against 2·g·Zc/(r0·Zp) (g the radial play, half the clearance; r0 the crank circle);
* friction: the unloading branch lies outside the loading branch by the friction's work, and
  without a clearance the loop closes at zero torque (Coulomb friction vanishes with the load).
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from conftest import CASES_DIR, coarse_case

from rvfem.evaluate.accuracy import ARCMIN_PER_RAD, accuracy_figures
from rvfem.mesh import mesh_case
from rvfem.solve import cycle
from rvfem.solve.accuracy import (
    ZERO_FRACTION,
    component_names,
    compliance_shares,
    hysteresis_loop,
    rigid_kinematic_te,
    stiffened_stage,
    te_plan,
    transmission_error,
)

T_R = 412.0


@pytest.fixture(scope="module")
def mesh_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


def _stiff_stage(mesh_dir, **tables):
    """Disc ×1e3, linear pins 2e8 N/mm and rollers 3e7 N/mm (about 1e3 and 1e2 times the Hertz and
    Palmgren secants at the rated load), rigid eccentrics: the stiff limit."""
    tables.setdefault("pins", {}).update(model="linear", linear_stiffness_N_per_mm=2e8)
    tables.setdefault("crank_bearing", {}).update(stiffness_law="linear", linear_stiffness_N_per_mm=3e7)
    case = coarse_case("rv40e", **tables)
    system = cycle.build_system(case, mesh_case(case, mesh_dir), stiffness_scale=1e3)
    return cycle.build_stage(system, discs=2, influence=None)


def test_linear_limit_is_the_existing_solve_scaled(mesh_dir):
    case = coarse_case("rv40e", pins={"model": "linear", "linear_stiffness_N_per_mm": 2e5},
                       crank_bearing={"stiffness_law": "linear", "linear_stiffness_N_per_mm": 3e5})
    stage = cycle.case_stage(cycle.build_system(case, mesh_case(case, mesh_dir)))
    theta = 0.3
    loop = hysteresis_loop(stage, theta, T_R, steps=8)
    for sign in (1.0, -1.0):
        phi = cycle.solve_pair(stage, theta, op=cycle.OperatingPoint(sign * T_R)).output_rotation
        side = np.sign(loop.torque_Nm) == sign
        np.testing.assert_allclose(loop.torque_Nm[side] / loop.rotation_rad[side], sign * T_R / phi, rtol=1e-7)
    fig = accuracy_figures(loop.torque_Nm, loop.rotation_rad, loop.branch, T_R)
    # compression-only linear springs without a gap: φ ∝ T on each side, so b/a is T/φ and the
    # lost motion is the 3 % torque's elastic rotation, 0.03·(φ(+T) − φ(−T))
    k = [T_R / (cycle.solve_pair(stage, theta, op=cycle.OperatingPoint(s * T_R)).output_rotation * s)
         / ARCMIN_PER_RAD for s in (1.0, -1.0)]
    assert fig.torsional_rigidity_Nm_per_arcmin == pytest.approx(0.5 * sum(k), rel=1e-7)
    assert fig.lost_motion_arcmin == pytest.approx(0.03 * T_R * (1 / k[0] + 1 / k[1]), rel=1e-6)
    # no play: the zero crossing's jump is the elastic rotation of the ±ZERO_FRACTION·T_R it is solved at
    eps = ZERO_FRACTION * T_R
    assert fig.backlash_arcmin == pytest.approx(eps * (1 / k[0] + 1 / k[1]), rel=1e-6)


def _play_closed_form(case, equidistant: float = 0.0, shift: float = 0.0) -> float:
    """Lost motion = backlash of the rigid stage, rad, for an equidistant modification ΔR_rp and a
    pin-circle shift ΔR_p (Liu et al.'s signs: ΔR_rp > 0 and ΔR_p < 0 open the flanks), the carrier
    and the stiff discs turning about the reducer axis (docs/theory.md § 9b): the flank gap of the
    pin whose normal meets the radius to it at γ is ΔR_rp − ΔR_p·cos γ, its lever about the axis
    Rp·sin γ ≤ Rp·K1 = e·Zp; the first pin to close, both ways, gives
    2·(ΔR_rp − ΔR_p·√(1 − K1²))/(e·Zp) if ΔR_p ≤ ΔR_rp·√(1 − K1²), else 2·√(ΔR_rp² − ΔR_p²)/Rp."""
    e, zp, rp = case.cycloid.eccentricity, case.pins.count, case.pins.circle_radius
    root = math.sqrt(1.0 - (e * zp / rp) ** 2)
    if shift <= equidistant * root:
        return 2.0 * (equidistant - shift * root) / (e * zp)
    return 2.0 * math.sqrt(equidistant ** 2 - shift ** 2) / rp


@pytest.mark.parametrize("modification", [{"equidistant": 0.01}, {"shift": -0.01},
                                          {"equidistant": 0.004, "shift": -0.017},
                                          {"equidistant": 0.01, "shift": 0.008}],
                         ids=["equidistant", "shift", "both_open", "both_interior"])
def test_profile_modification_lost_motion_against_closed_form(mesh_dir, modification):
    """Each modification alone and both together, stiff limit, θ = 0 (a pin sits where the lever
    about the axis is largest): lost motion and backlash within 0.5 % of the rigid kinematics."""
    stage = _stiff_stage(mesh_dir, cycloid={"modification": modification})
    case = stage.first.case
    closed = _play_closed_form(case, **modification) * ARCMIN_PER_RAD
    loop = hysteresis_loop(stage, 0.0, T_R, steps=8)
    fig = accuracy_figures(loop.torque_Nm, loop.rotation_rad, loop.branch, T_R)
    assert fig.lost_motion_arcmin == pytest.approx(closed, rel=0.005)
    assert fig.backlash_arcmin == pytest.approx(closed, rel=0.005)
    if modification == {"equidistant": 0.01}:
        # about the disc centre (rvfem ≤ 0.3's convention) the lever was e·Zc, 40/39 larger a play
        zc = case.cycloid.teeth
        assert fig.backlash_arcmin < 2.0 * 0.01 / (case.cycloid.eccentricity * zc) * ARCMIN_PER_RAD * 0.985


def test_shift_lost_motion_goes_with_the_root_not_the_shift(mesh_dir):
    """A pin-circle shift opens the flanks by |ΔR_p|·cos γ, not |ΔR_p|: at the pin of the largest
    lever about the axis cos γ = √(1 − K1²) (0.583 for the RV-40E), so the lost motion is well
    below the 2|ΔR_p|/(e·Zp) of an equidistant modification of the same size."""
    stage = _stiff_stage(mesh_dir, cycloid={"modification": {"shift": -0.01}})
    case = stage.first.case
    k1 = case.cycloid.eccentricity * case.pins.count / case.pins.circle_radius
    loop = hysteresis_loop(stage, 0.0, T_R, steps=8)
    fig = accuracy_figures(loop.torque_Nm, loop.rotation_rad, loop.branch, T_R)
    equidistant = 2.0 * 0.01 / (case.cycloid.eccentricity * case.pins.count) * ARCMIN_PER_RAD
    assert fig.lost_motion_arcmin / equidistant == pytest.approx(math.sqrt(1.0 - k1 ** 2), rel=0.005)


def test_crank_bearing_clearance_lost_motion_against_closed_form(mesh_dir):
    """A crank-bearing radial play g (clearance 2g) alone, stiff limit: the pins let the disc turn
    about the pitch point only; turning it by −φ/Zc while the carrier turns φ about the axis leaves
    the eccentrics a rotation φ·Zp/Zc about the disc centre relative to it, which moves every bore by
    the same φ·r0·Zp/Zc (the smallest largest one, docs/theory.md § 9b): lost motion
    2g·Zc/(r0·Zp)."""
    clearance = 0.01                                              # diametral, mm: play g = 5 µm
    stage = _stiff_stage(mesh_dir, crank_bearing={"radial_clearance": clearance})
    case = stage.first.case
    closed = clearance * case.cycloid.teeth / (case.cranks.circle_radius * case.pins.count) * ARCMIN_PER_RAD
    loop = hysteresis_loop(stage, 0.0, T_R, steps=8)
    fig = accuracy_figures(loop.torque_Nm, loop.rotation_rad, loop.branch, T_R)
    assert fig.lost_motion_arcmin == pytest.approx(closed, rel=0.005)
    assert fig.backlash_arcmin == pytest.approx(closed, rel=0.005)


def test_support_bearing_clearance_lost_motion_against_closed_form(mesh_dir):
    """The support bearings' radial clearance alone (crank_support.radial_clearance, stiff
    crankshaft and supports): each crankshaft's play in its supports moves the eccentrics like the
    crank bearing's play, lost motion 2g_s·Zc/(r0·Zp); with both clearances the plays add."""
    clearance = 0.01
    tables = dict(crank_support={"span": 33.0, "eccentric_positions": [11.5, 21.5],
                                 "journal_diameter": 500.0,
                                 "support_stiffness_N_per_mm": 1e10, "radial_clearance": clearance},
                  # the stiff limit: the housing ring's and the carrier's series compliances off too
                  pin_housing={"enabled": False}, carrier={"enabled": False})
    stage = _stiff_stage(mesh_dir, **tables)
    from rvfem.solve.stage_parts import build_components
    stage = build_components(stage)
    assert stage.eccentric_play_mm == pytest.approx(0.5 * clearance) and stage.influence is not None
    case = stage.first.case
    closed = clearance * case.cycloid.teeth / (case.cranks.circle_radius * case.pins.count) * ARCMIN_PER_RAD
    loop = hysteresis_loop(stage, 0.0, T_R, steps=8)
    fig = accuracy_figures(loop.torque_Nm, loop.rotation_rad, loop.branch, T_R)
    assert fig.lost_motion_arcmin == pytest.approx(closed, rel=0.005)
    assert fig.backlash_arcmin == pytest.approx(closed, rel=0.005)


def test_friction_opens_the_loop_and_closes_it_at_zero_torque(mesh_dir):
    case = coarse_case("rv40e")
    stage = cycle.case_stage(cycle.build_system(case, mesh_case(case, mesh_dir)))
    free = hysteresis_loop(stage, 0.0, T_R, steps=8, friction=0.0)
    rough = hysteresis_loop(stage, 0.0, T_R, steps=8, friction=0.05)
    load, unload = rough.branch_curve(0), rough.branch_curve(1)
    mid = free.branch_curve(0)
    # at the same torque: loading (friction against the rotation) below frictionless below unloading
    assert np.all(load[1][1:] < mid[1][1:]) and np.all(unload[1][::-1][1:] > mid[1][1:])
    fig = accuracy_figures(rough.torque_Nm, rough.rotation_rad, rough.branch, T_R)
    # Coulomb friction ∝ the load: no width at zero torque without a clearance
    assert abs(fig.hysteresis_loss_arcmin) < 1e-3 * math.degrees(np.ptp(rough.rotation_rad)) * 60


def test_kinematic_te_with_pitch_error_against_rigid_kinematics(mesh_dir):
    # pitch error (Li et al.'s sin pattern, 3 µm) inside a 4 µm equidistant modification: every
    # flank has a gap, so the rigid stage's no-load rotation is the first gap to close
    case = coarse_case("rv40e", mesh={"size_flank": 0.3},
                       pins={"model": "linear", "linear_stiffness_N_per_mm": 2e8},
                       crank_bearing={"stiffness_law": "linear", "linear_stiffness_N_per_mm": 3e7},
                       cycloid={"modification": {"equidistant": 0.004}, "pitch_error": {"amplitude": 0.003}})
    system = cycle.build_system(case, mesh_case(case, mesh_dir), stiffness_scale=1e3)
    stage = cycle.build_stage(system, discs=1, influence=None)
    theta = np.radians(np.arange(0.0, 360.0, 30.0))
    no_load, loaded = transmission_error(stage, theta, T_R)
    rigid = rigid_kinematic_te(system.geometry, theta)
    arcsec = 180.0 * 3600.0 / math.pi
    assert np.ptp(rigid) * arcsec > 0.5                         # the pitch error shows
    # the footprint spreads a pin's load over ±3 flank elements, whose mean lever differs from the
    # contact point's by O(h²): 7e-4 arcsec at 0.6 mm, 1.4e-4 at 0.3 mm
    np.testing.assert_allclose(no_load * arcsec, rigid * arcsec, atol=1e-3)
    assert np.all(loaded > no_load)


def test_compliance_shares_add_up_and_vanish_when_stiffened(mesh_dir):
    case = coarse_case("rv40e", pins={"model": "linear", "linear_stiffness_N_per_mm": 2e5},
                       crank_bearing={"stiffness_law": "linear", "linear_stiffness_N_per_mm": 3e5})
    stage = cycle.case_stage(cycle.build_system(case, mesh_case(case, mesh_dir)))
    shares = compliance_shares(stage, 0.0, T_R)
    assert set(shares.shares) == set(component_names())
    assert all(s > 0 for name, s in shares.shares.items() if name != "main_bearings")
    assert shares.shares["main_bearings"] == 0.0           # the main bearings pass no torque
    # series compliances: the shares add up to one but for the load redistribution between parallel
    # paths (pins, rollers, the two discs) that stiffening one component causes
    assert shares.total == pytest.approx(1.0, abs=0.05)
    first = component_names()[0]
    stiff = stiffened_stage(stage, first)
    again = compliance_shares(stiff, 0.0, T_R, components=(first,))
    assert again.shares[first] < 2e-3


def _mirrored_mesh(mesh, cranks: int):
    """The mesh mirrored about the x axis: y → −y, triangles and boundary loops reversed (the disc
    stays on their left), bore i (at angle α_i) renamed to the bore at −α_i."""
    pts = mesh.points * np.array([1.0, -1.0])
    boundaries = {}
    for name, edges in mesh.boundaries.items():
        if name.startswith("bore_"):
            name = f"bore_{(-int(name.split('_')[1])) % cranks}"
        boundaries[name] = np.ascontiguousarray(edges[::-1, ::-1])
    return dataclasses.replace(mesh, points=np.ascontiguousarray(pts),
                               triangles=np.ascontiguousarray(mesh.triangles[:, ::-1]),
                               boundaries=boundaries, symmetry=1)


def test_mirror_image_of_the_stage_gives_the_mirrored_loop(mesh_dir):
    # with cranks at 0°, 120°, 240° and at θ = 0 the pins, the profile and the cranks are symmetric
    # about the x axis (disc B at θ + 180° too);
    # the mesh is not, so the mirror image of the stage is the stage on the mirrored mesh. Its loop
    # is the first's turned about the origin: φ'(−T) = −φ(T) (frictionless; rigid_bore bearings,
    # whose springs are isotropic, where the rollers' cage positions are not symmetric)
    case = coarse_case("rv40e", crank_bearing={"model": "rigid_bore"}, analysis={"friction": 0.0},
                       cranks={"angles_deg": (0.0, 120.0, 240.0)})
    mesh = mesh_case(case, mesh_dir)
    stage = cycle.case_stage(cycle.build_system(case, mesh))
    mirror = cycle.case_stage(cycle.build_system(case, _mirrored_mesh(mesh, case.cranks.count)))
    loop = hysteresis_loop(stage, 0.0, T_R, steps=8)
    image = hysteresis_loop(mirror, 0.0, T_R, steps=8)
    n = len(loop.torque_Nm) // 2                       # the − half of the loop is the + half negated
    np.testing.assert_array_equal(loop.torque_Nm[n:], -loop.torque_Nm[:n])
    scale = np.abs(loop.rotation_rad).max()
    np.testing.assert_allclose(image.rotation_rad[n:], -loop.rotation_rad[:n], rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(image.rotation_rad[:n], -loop.rotation_rad[n:], rtol=0, atol=1e-9 * scale)
    # the loop itself is symmetric about the origin to the mesh's asymmetry
    asym = np.abs(loop.rotation_rad[n:] + loop.rotation_rad[:n]).max() / scale
    assert asym < 1e-4                                   # 8e-6 on this mesh


def test_te_by_symmetry_equals_every_angle_solved(mesh_dir):
    case = coarse_case("rv40e")
    stage = cycle.case_stage(cycle.build_system(case, mesh_case(case, mesh_dir)))
    theta = np.radians(np.arange(0.0, 360.0, 20.0))
    _, loaded = transmission_error(stage, theta, T_R, 0.05)
    direct = [cycle.solve_pair(stage, float(t), op=cycle.OperatingPoint(T_R, 0.05)).output_rotation for t in theta]
    np.testing.assert_allclose(loaded, direct, rtol=1e-7)
    assert np.ptp(loaded) > 1e-3 * np.mean(loaded)           # the loaded TE ripples


def test_hysteresis_command_writes_the_folder(tmp_path, capsys):
    from rvfem.app.cli import main

    out = tmp_path / "acc"
    code = main(["hysteresis", str(CASES_DIR / "rv40e.toml"), "-o", str(out), "--angles", "2", "--steps", "8", "--te",
                 "--cache-dir", str(tmp_path / "meshes"), "--set", "mesh.size_flank=0.6", "--set", "mesh.size_bore=0.6",
                 "--set", "mesh.size_interior=4.0", "--set", "analysis.angle_step_deg=30"])
    assert code == 0
    s = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    for key in ("torsional_rigidity_Nm_per_arcmin", "lost_motion_arcmin", "hysteresis_loss_arcmin", "backlash_arcmin"):
        assert math.isfinite(s[key]) and key in s["per_angle"][0]
    assert s["torsional_rigidity_Nm_per_arcmin"] > 0 and s["lost_motion_arcmin"] > 0
    assert abs(s["compliance_shares"]["total"] - 1.0) < 0.2
    assert len(s["per_angle"]) == 2 and s["angles_deg"][1] == pytest.approx(360.0 / 39 / 2)
    rows = (out / "hysteresis.csv").read_text(encoding="utf-8").splitlines()
    assert len(rows) == 1 + 8 + 8 and rows[0].startswith("step,branch,torque_Nm,rotation_arcmin")
    assert len((out / "te.csv").read_text(encoding="utf-8").splitlines()) == 1 + 12
    for png in ("hysteresis", "compliance_shares", "transmission_error"):
        assert (out / "plots" / f"{png}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "What the model leaves out" in (out / "accuracy.md").read_text(encoding="utf-8")
    assert "torsional rigidity" in capsys.readouterr().out


def test_the_te_shared_with_the_child_process_is_the_te_solved_here(mesh_dir):
    """``rvfem hysteresis --te`` shares the TE's crank angles with a child process: the child
    solves shares from the first angle on, on the same stage built there on its own
    factorisation, this process the rest from the last angle back. Together they give the TE of
    this process alone to round-off; the shares of a child that has ended are solved here; no TE
    asked, no child."""
    from rvfem._child import usable_cores
    from rvfem.app.hysteresis import TE_SHARE_ANGLES, _TransmissionErrorChild, te_angles
    from rvfem.geometry import disc_geometry

    if usable_cores() < 2:
        pytest.skip("one core: the TE is solved in this process (no child)")

    case = coarse_case("rv40e", analysis={"angle_step_deg": 3.0})
    geometry = disc_geometry(case)
    mesh = mesh_case(case, mesh_dir, geometry=geometry)
    stage = cycle.case_stage(cycle.build_system(case, mesh, geometry=geometry))
    thetas = te_angles(case)
    here = transmission_error(stage, thetas, T_R, 0.05)
    assert len(te_plan(stage, thetas)[0]) > 2 * TE_SHARE_ANGLES     # shares for both processes

    def shared(kill: bool = False, te_case=case):
        with _TransmissionErrorChild(te_case) as child:
            if kill:
                child._child._proc.kill()
            child.start(mesh, geometry)
            child.begin(stage, thetas, T_R, 0.05)
            result = transmission_error(stage, thetas, T_R, 0.05, solve=child.solve(stage, T_R, 0.05))
            return result, child.shares_to_child

    for kill in (False, True):
        there, given = shared(kill)
        assert given >= 1
        for a, b in zip(there, here):
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12 * np.max(np.abs(here[1])))
    there, given = shared(te_case=None)                     # no TE asked: no child, solved here
    assert given == 0
    for a, b in zip(there, here):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=0)


@pytest.mark.parametrize("options, cause", [
    (["--steps", "2"], "--steps must be a multiple of 4"), (["--steps", "42"], "--steps must be a multiple of 4"),
    (["--friction", "0.9"], "--friction must be in"), (["--torque", "-5"], "--torque must be positive"),
])
def test_hysteresis_options_out_of_range_give_one_line_errors(options, cause, tmp_path, capsys):
    """Options the loop cannot use end with exit 2 and one line naming the option, before any
    folder is written."""
    from rvfem.app import cli

    out = tmp_path / "out"
    assert cli.main(["hysteresis", str(CASES_DIR / "rv40e_fanholes.toml"), "-o", str(out), *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and cause in err[0]
    assert not out.exists()
