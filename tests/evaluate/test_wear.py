"""Archard wear (rvfem.evaluate.wear) and the life loop of ``rvfem wear`` (rvfem.app.wear), against
closed forms and Liu et al.'s published kinematics (*Degradation law analysis and life estimation of
transmission accuracy of RV reducer based on tooth surface and bearing wear*, § 3.1 and § 4.1)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import CASES_DIR, coarse_case

from rvfem.app import cli
from rvfem.app.wear import duty_rows, flank_grid, life_figures, life_loop, wear_rates, worn_stage
from rvfem.errors import CaseError
from rvfem.evaluate import wear as archard
from rvfem.evaluate.accuracy import quick_figures
from rvfem.geometry import FlankDeviation, disc_geometry, pin_centres, pin_phases
from rvfem.mesh import mesh_case
from rvfem.solve.cycle import OperatingPoint, build_system, case_stage, contact_set, load_cycle

RV40E = dict(Rp=64.0, r_rp=3.0, e=1.3, zp=40, zc=39)   # Liu et al. Table 1
PSI = np.linspace(0.0, math.pi, 3603)[1:-1]


def _kin(psi=PSI, **kw):
    g = {**RV40E, **kw}
    return archard.mesh_kinematics(g["Rp"], g["r_rp"], g["e"], g["zp"], g["zc"], psi)


def test_pin_on_flat_depth_is_archard_and_linear_in_time():
    """A pin pressed on a flat that slides under it at constant load: the pin's point under the
    contact centre wears k·p_h·s (p_h = 2F/(πbL), the Hertz peak) and the worn area is k·F·s/L,
    both linear in the sliding distance s = v·t."""
    k, F, L, b, v, dt = 3e-11, 500.0, 9.0, 0.05, 20.0, 1e-3
    nodes = np.linspace(-0.2, 0.2, 4001)
    for steps in (100, 200):
        depth = archard.footprint_wear(nodes, np.zeros(steps), np.full(steps, k * F * v * dt / L), np.full(steps, b))
        s = v * dt * steps
        p_h = 2 * F / (math.pi * b * L)
        assert depth[2000] == pytest.approx(archard.archard_depth(k, p_h, s), rel=2e-3)
        assert np.trapezoid(depth, nodes) * L == pytest.approx(k * F * s, rel=1e-12)
        if steps == 100:
            first = depth[2000]
    assert depth[2000] == pytest.approx(2 * first, rel=1e-12)


def test_sliding_speed_is_liu_closed_form_and_coefficients_match_their_figure_9():
    """|v_s| = (Zp − Zc)/Zp·(Rp·τ − r_rp) per unit crank angle (Liu et al.'s V_pc^r with
    ω_p = Zc/Zp); their RV-40E: the flank's largest sliding coefficient 2.7258, the pin's contact
    arc α = 0–54.3692° and its sliding coefficient infinite near ψ = 36° (contact standing still on
    the pin)."""
    kin = _kin()
    K1 = 1.3 * 40 / 64
    tau = np.sqrt(1 + K1**2 - 2 * K1 * np.cos(PSI))
    assert np.allclose(kin.sliding, (64 * tau - 3) / 40, rtol=1e-12, atol=1e-12)
    assert kin.eps_disc.max() == pytest.approx(2.7258, abs=1e-4)
    # the contact arc on the pin ends where sin γ = K1 (the largest lever, docs/theory.md § 9b): 54.341°,
    # Liu et al. print 54.3692° (their modified profile)
    assert math.degrees(np.abs(kin.pin_angle).max()) == pytest.approx(math.degrees(math.asin(K1)), abs=1e-3)
    assert math.degrees(np.abs(kin.pin_angle).max()) == pytest.approx(54.3692, abs=0.05)
    assert math.degrees(PSI[np.argmin(kin.rolling_pin)]) == pytest.approx(36.0, abs=1.0)
    # another tooth difference: the pitch point at e·Zp/(Zp − Zc), |v_s| = (Zp − Zc)/Zp·|P − C|
    two = _kin(zp=40, zc=38)
    C = np.array([1.3 * 40 / 2, 0.0])
    assert np.allclose(two.sliding, 2 / 40 * np.linalg.norm(two.point - C, axis=-1), rtol=1e-12)


def test_sliding_vanishes_at_the_pitch_point():
    """With r_rp = Rp·(1 − K1) the pin at ψ = 0 touches the disc at the pitch point: the two bodies
    move alike there (the rolling/sliding decomposition: sliding 0, equal rolling speeds over
    both surfaces), so both sliding coefficients vanish; away from it they do not."""
    K1 = 1.3 * 40 / 64
    kin = _kin(np.array([0.0, 0.3]), r_rp=64 * (1 - K1))
    assert kin.sliding[0] == pytest.approx(0.0, abs=1e-12)
    assert kin.rolling_disc[0] == pytest.approx(kin.rolling_pin[0], rel=1e-9)
    assert kin.eps_disc[0] == pytest.approx(0.0, abs=1e-12) and kin.eps_pin[0] == pytest.approx(0.0, abs=1e-12)
    assert kin.eps_disc[1] > 0.01


def test_engagement_conserves_the_worn_area():
    """Worn area of the flank (and of a fixed pin) in one engagement = k·Σ F·ds / L, ds the sliding
    distance of each step; a freely turning pin spreads the same area over its circumference."""
    kin = _kin(np.linspace(0.0, math.pi, 723)[1:-1])
    K1 = 1.3 * 40 / 64
    F = 406.0 * np.sin(kin.psi) / np.sqrt(1 + K1**2 - 2 * K1 * np.cos(kin.psi))
    k, L = 2.8e-11, 9.0
    expect = k * np.sum(F * kin.sliding * 40 / 39 * np.abs(np.gradient(kin.psi))) / L
    for mode in ("none", "free"):
        disc, pin = archard.flank_pin_engagement(kin, F, k_mm2_per_N=k, length_mm=L, modulus_MPa=1.16e5, zp=40,
                                                 zc=39, pin_radius=3.0, pin_rolling=mode)
        assert np.trapezoid(disc, kin.disc_arc) == pytest.approx(expect, rel=1e-3)
        nodes = np.linspace(-0.5 * math.pi, 0.5 * math.pi, len(pin)) * 3.0
        area = np.trapezoid(pin, nodes) if mode == "none" else pin[0] * 2 * math.pi * 3.0
        assert area == pytest.approx(expect, rel=1e-3)


@pytest.fixture(scope="module")
def coarse(tmp_path_factory):
    """The coarse solid RV-40E at 10° crank-angle steps and its factorised disc."""
    case = coarse_case("rv40e_solid", analysis={"angle_step_deg": 10.0})
    geometry = disc_geometry(case)
    system = build_system(case, mesh_case(case, tmp_path_factory.mktemp("mesh"), geometry=geometry),
                          geometry=geometry)
    return case, system


def test_pin_phases_are_the_angle_of_each_pin_from_the_eccentric():
    """ψ_j: the pin centre's angle about the pin-circle centre (at −e·u(θ) in the disc frame) minus
    the eccentric's angle θ (rvfem.geometry.pin_centres)."""
    case = coarse_case("rv40e_solid")
    for theta in (0.0, 0.37, 2.9):
        c = pin_centres(case, theta) + 1.3 * np.array([math.cos(theta), math.sin(theta)])
        expect = np.angle(np.exp(1j * (np.arctan2(c[:, 1], c[:, 0]) - theta)))
        assert np.allclose(pin_phases(case, theta), expect, atol=1e-12)


def test_a_uniform_wear_gap_is_an_equidistant_modification(coarse):
    """Every flank worn by the same depth g is the profile of the generating pin radius r_rp + g (an
    offset curve at g: every pin's gap grows by g at every crank angle), so the flank deviation
    and the equidistant modification give the same pin gaps to round-off and the same lost motion
    and rigidity; a zero deviation changes nothing."""
    case, system = coarse
    g = 4e-3
    mod = case.cycloid.modification
    offset_case = case.replace(cycloid=dataclasses.replace(
        case.cycloid, modification=dataclasses.replace(mod, equidistant=mod.equidistant + g)))
    worn = worn_stage(system, case, FlankDeviation.of([0.0, math.pi], [g, g], [g, g]))
    offset = worn_stage(system, offset_case, None)
    zp = case.pins.count
    op = OperatingPoint(412.0, 0.05)
    for theta in (0.0, 0.1, 1.0, 2.5):
        a, b = contact_set(worn.first, theta, op)[0], contact_set(offset.first, theta, op)[0]
        assert np.allclose(a.offset[:zp], b.offset[:zp], rtol=0.0, atol=1e-10)
    fa, fb = quick_figures(worn, 412.0, 0.05, 0.0), quick_figures(offset, 412.0, 0.05, 0.0)
    assert fa["lost_motion_arcmin"] == pytest.approx(fb["lost_motion_arcmin"], rel=1e-3)
    assert fa["torsional_rigidity_Nm_per_arcmin"] == pytest.approx(fb["torsional_rigidity_Nm_per_arcmin"], rel=1e-3)
    nominal = quick_figures(case_stage(system), 412.0, 0.05, 0.0)
    zero = quick_figures(worn_stage(system, case, FlankDeviation.of([0.0, math.pi], [0.0, 0.0], [0.0, 0.0])),
                         412.0, 0.05, 0.0)
    assert zero == nominal


def test_wear_rates_conserve_archard_over_the_load_cycle(coarse):
    """Archard's law in its global form over a load cycle of the FE stage: the worn area of all the
    teeth's flanks per crank revolution is k/L·∫ Σ_j F_j·|v_s(ψ_j)| dθ, and the same area is worn off
    the pins (|v_s| the closed form (Zp − Zc)/Zp·(Rp·τ − r_rp)); the rates spread it over one tooth
    (÷ Zc) and one pin (÷ Zp) at the crank revolutions of an hour."""
    case, system = coarse
    stage = case_stage(system)
    kin = flank_grid(case)
    rates = wear_rates(stage, case, kin, duty_rows(case))
    cycle = load_cycle(system, op=OperatingPoint(412.0, 0.05), stage=stage)
    psi = np.array([pin_phases(case, t) for t in cycle.theta])
    F = np.asarray(cycle.pin_forces)
    K1 = 1.3 * 40 / 64
    v = (64 * np.sqrt(1 + K1**2 - 2 * K1 * np.cos(psi)) - 3) / 40
    dtheta = 2 * math.pi / len(cycle.theta)
    revs_h = 15.0 * 60.0 * 40
    k, L = case.wear.k_flank_pin, case.cycloid.thickness
    nodes = np.linspace(-0.5 * math.pi, 0.5 * math.pi, rates["pin"].shape[1]) * 3.0
    loaded = k / L * np.sum((F * v)[psi >= 0]) * dtheta * revs_h
    assert loaded > 0
    for side, sel in enumerate((psi >= 0, psi < 0)):     # the flanks of the torque, then the nearly idle ones
        area = k / L * np.sum((F * v)[sel]) * dtheta * revs_h
        assert np.trapezoid(rates["flank"][side], kin.disc_arc) * 39 == pytest.approx(area, abs=0.01 * loaded)
        assert np.trapezoid(rates["pin"][side], nodes) * 40 == pytest.approx(area, abs=0.01 * loaded)


@pytest.mark.parametrize("key, value, words", [("wear.pin_rolling", '"rolling"', "must be one of"),
                                               ("wear.k_flank_pin", "-1e-11", "wear.k_flank_pin"),
                                               ("wear.update_step_um", "0", "wear.update_step_um")])
def test_bad_wear_keys_are_refused_in_one_line(key, value, words, tmp_path, capsys):
    assert cli.main(["wear", str(CASES_DIR / "rv40e.toml"), "--hours", "10", "-o", str(tmp_path / "o"),
                     "--set", f"{key}={value}"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and key in err and "Traceback" not in err
    assert words in err or "must be" in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("hours", ["0", "-5", "nan"])
def test_bad_hours_are_refused(hours, tmp_path, capsys):
    assert cli.main(["wear", str(CASES_DIR / "rv40e.toml"), "--hours", hours, "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--hours" in err
    assert not (tmp_path / "o").exists()


def test_a_duty_without_torque_is_refused():
    from rvfem.app.wear import wear_life
    case = coarse_case("rv40e_solid")
    with pytest.raises(CaseError, match="torque"):
        wear_life(case.replace(loads=case.loads.__class__(torque_Nm=0.0, speed_rpm=15.0)), "/nonexistent/x", hours=1)


def test_the_wear_command_writes_its_folder(tmp_path):
    """``wear_life`` end to end on the coarse solid disc: every file of the folder, the tables'
    hours rising with the lost motion (wear only removes material), the worn flank at least the
    nominal one's depth, the plots drawn (by the plot worker's child process) and the summary's
    life figures consistent with wear.csv."""
    import csv
    import json

    from rvfem.app.wear import wear_life

    case = coarse_case("rv40e_solid", analysis={"angle_step_deg": 10.0}, wear={"update_step_um": 10.0})
    out = tmp_path / "wear"
    summary = wear_life(case, out, hours=30.0, cache_dir=tmp_path / "mesh")
    names = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()} - {".rvfem-results"}   # the folder mark
    assert names == {"wear.csv", "worn_flank.csv", "worn_pin.csv", "plots/lost_motion.png", "plots/wear_profile.png",
                     "report.md", "summary.json"}
    assert all((out / "plots" / n).stat().st_size > 5000 for n in ("lost_motion.png", "wear_profile.png"))
    rows = list(csv.DictReader((out / "wear.csv").open(encoding="utf-8")))
    hours = [float(r["hours"]) for r in rows]
    lost = [float(r["lost_motion_arcsec"]) for r in rows]
    assert hours[0] == 0.0 and all(b > a for a, b in zip(hours, hours[1:])) and len(rows) == summary["updates"] + 1
    assert all(b >= a - 1e-9 for a, b in zip(lost, lost[1:])) and lost[-1] > lost[0]
    assert json.loads((out / "summary.json").read_text(encoding="utf-8"))["final_lost_motion_arcsec"] == pytest.approx(lost[-1])
    flank = list(csv.DictReader((out / "worn_flank.csv").open(encoding="utf-8")))
    assert all(float(r["flank_wear_um"]) >= 0.0 for r in flank) and max(float(r["flank_wear_um"]) for r in flank) > 0.0
