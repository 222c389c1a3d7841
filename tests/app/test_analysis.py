"""What rvfem.app.analysis promises: the case as analysed and where it comes from, the rigid
handbook evaluation, one analysis held in memory (a load cycle in equilibrium, its comparison,
the wall time of every stage), the duty cycle solved at every torque, and the two path helpers.

References: the CRV-80E of Gao et al. (cases/crv80e.toml: F_max = 5576.9 N, F_m = 4374.1 N with
p = 4, C = 21948.7 N, L10h ≈ 6008 h at 600 rpm bearing speed); statics of the disc and the carrier
(forces and moments balance); the definitions of the load statistics and of Palmgren–Miner.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import CASES_DIR, ROOT, coarse_case

from rvfem import fem
from rvfem.app import analysis as an
from rvfem.app.analysis import (
    STAGES,
    analyse,
    analyse_rigid,
    cycle_angles,
    duty_cycle_fe,
    kept_field_angles,
    repository_path,
    resolve_case,
)
from rvfem.case.definition import case_to_dict, file_sha256, load_case
from rvfem.errors import CaseError
from rvfem.evaluate import iso281
from rvfem.evaluate.rigid import equivalent_load, load_cycle_angles
from rvfem.solve import cycle as cycle_module

CRV80E = CASES_DIR / "crv80e.toml"
STEP_DEG = 30.0


def _dotted(data: dict, prefix: str = "") -> dict:
    """Dotted key → value of the leaves of a nested dict."""
    out = {}
    for key, value in data.items():
        if isinstance(value, dict) and value:
            out.update(_dotted(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


# --------------------------------------------------------------------------------------------
# resolve_case: overrides, options, provenance
# --------------------------------------------------------------------------------------------


def test_a_case_file_as_it_is_matches_its_file():
    case, prov = resolve_case(CRV80E)
    assert case == load_case(CRV80E)
    assert prov.file == str(CRV80E)
    assert prov.sha256 == file_sha256(CRV80E)
    assert prov.matches_file and prov.overrides == {}


def test_overrides_and_options_are_applied_and_recorded():
    case, prov = resolve_case(CRV80E, overrides=("loads.torque_Nm=500", "pins.model=\"rigid\""),
                              angle_step_deg=5, order=2, bearing_model="rigid_bore")
    assert case.loads.torque_Nm == 500.0 and case.pins.model == "rigid"
    assert case.analysis.angle_step_deg == 5.0 and case.analysis.element_order == 2
    assert case.crank_bearing.model == "rigid_bore"
    assert prov.overrides == {"loads.torque_Nm": 500, "pins.model": "rigid", "analysis.angle_step_deg": 5.0,
                              "analysis.element_order": 2, "crank_bearing.model": "rigid_bore"}
    assert not prov.matches_file
    assert prov.sha256 == file_sha256(CRV80E)          # the file the overrides were applied to
    # the options leave the KEY=VALUE overrides on the case, and nothing else changes
    assert case.overrides == ("loads.torque_Nm=500", "pins.model=\"rigid\"")
    before = _dotted(case_to_dict(load_case(CRV80E, case.overrides)))
    after = _dotted(case_to_dict(case))
    assert {k for k in after if after[k] != before[k]} == {"analysis.angle_step_deg", "analysis.element_order",
                                                           "crank_bearing.model"}


def test_defaults_used_are_exactly_the_keys_the_file_and_the_overrides_leave_out():
    raw = _dotted(tomllib.loads(CRV80E.read_text(encoding="utf-8")))
    case, prov = resolve_case(CRV80E, overrides=("analysis.saved_angles_deg=[0.0]",))
    defaults = dict(prov.defaults_used)
    full = case_to_dict(case)
    assert defaults, "the shipped CRV-80E leaves the mesh table and several keys to their defaults"
    for key, value in defaults.items():
        assert not any(k == key or k.startswith(key + ".") for k in raw), key
        node = full
        for part in key.split("."):
            node = node[part]
        assert node == value
    assert "mesh" in defaults and "analysis.element_order" in defaults
    assert "analysis.saved_angles_deg" not in defaults            # set by the override
    assert "cycloid.teeth" not in defaults                        # set by the file
    # a key the file sets is never listed, whatever its value
    assert not set(defaults) & set(raw)


def test_a_case_read_from_its_file_matches_it_and_one_changed_in_code_does_not():
    case = load_case(CRV80E)
    _, prov = resolve_case(case)
    assert prov.matches_file and prov.file == str(CRV80E) and prov.defaults_used
    changed = case.replace(loads=dataclasses.replace(case.loads, torque_Nm=500.0))
    _, prov = resolve_case(changed)
    assert not prov.matches_file and prov.overrides == {} and prov.defaults_used == ()
    assert prov.sha256 == file_sha256(CRV80E)
    with_overrides = load_case(CRV80E, ("loads.torque_Nm=500",))
    _, prov = resolve_case(with_overrides)
    assert prov.overrides == {"loads.torque_Nm": 500} and not prov.matches_file
    assert prov.file == str(CRV80E)


def test_a_case_built_in_code_has_no_file():
    case, prov = resolve_case(coarse_case("crv80e"), angle_step_deg=STEP_DEG)
    assert (prov.file, prov.sha256, prov.matches_file, prov.defaults_used) == (None, None, False, ())
    assert prov.overrides == {"analysis.angle_step_deg": STEP_DEG}
    assert case.analysis.angle_step_deg == STEP_DEG


@pytest.mark.parametrize("options, message", [
    ({"angle_step_deg": -1.0}, "the angle step must be positive, got -1.0"),
    ({"angle_step_deg": "5"}, "the angle step must be positive, got '5'"),
    ({"order": 3}, "the element order must be 1 or 2, got 3"),
    ({"bearing_model": "springs"}, "the bearing model must be one of .*, got 'springs'"),
])
def test_bad_options_are_case_errors_naming_the_option(options, message):
    with pytest.raises(CaseError, match=message):
        resolve_case(CRV80E, **options)


def test_cycle_angles_need_four_per_turn():
    case, _ = resolve_case(CRV80E, angle_step_deg=STEP_DEG)
    np.testing.assert_array_equal(cycle_angles(case), load_cycle_angles(STEP_DEG))
    # the case schema stops at 30°; the check stands for any case-like object
    coarser = lambda step: SimpleNamespace(analysis=SimpleNamespace(angle_step_deg=step))  # noqa: E731
    assert len(cycle_angles(coarser(100.0))) == an.MIN_ANGLES == 4       # 360°/100° rounds to 4 angles of 90°
    with pytest.raises(CaseError, match="the angle step 130° leaves fewer than 4 angles per turn"):
        cycle_angles(coarser(130.0))


# --------------------------------------------------------------------------------------------
# analyse_rigid: the handbook reference
# --------------------------------------------------------------------------------------------


def test_rigid_handbook_loads_of_the_crv80e_reference():
    case = load_case(CRV80E)
    r = analyse_rigid(case)
    assert r.defined and r.exponent == 4.0 and r.angle_step_deg == pytest.approx(1.0)
    assert r.rating_N == pytest.approx(21948.7, abs=0.05)          # Gao et al.: C_d = 21948.7 N
    assert r.bearing_speed_rpm == pytest.approx(15.0 * 40 / (40 - 39))   # n_b = 600 rpm
    for b in r.bearings:
        assert b.loads.max_N == pytest.approx(5576.9, abs=0.05)
        assert b.loads.equivalent_N == pytest.approx(4374.1, abs=0.05)
        assert b.loads.exponent == 4.0
        assert b.loads.L10h == pytest.approx(6008.6, abs=0.5)       # (C/F_m)^(10/3)·10⁶/(60 n_b)
    assert r.bearings[0].loads.max_at_deg == pytest.approx(70.0)
    assert r.warnings == ()


def test_rigid_handbook_curves_balance_the_disc_torque_and_are_shifts_of_each_other():
    case = load_case(CRV80E)
    loads = analyse_rigid(case).loads
    c = cycle_module.crank_centres(case)
    moment = (c[:, 0, None] * loads.fy - c[:, 1, None] * loads.fx).sum(axis=0)
    np.testing.assert_allclose(moment, case.loads.disc_torque_Nmm, rtol=1e-12)
    per_crank = len(loads.theta) // case.cranks.count                 # 120 samples of 1°
    for i in range(1, case.cranks.count):
        np.testing.assert_allclose(loads.magnitude[i], np.roll(loads.magnitude[0], i * per_crank),
                                   rtol=1e-12, atol=1e-9)
    f = loads.magnitude[0]
    s = analyse_rigid(case).bearings[0].loads
    assert (s.max_N, s.min_N) == (f.max(), f.min())
    assert s.equivalent_N == pytest.approx(float(np.mean(f ** 4) ** 0.25), rel=1e-12)


# --------------------------------------------------------------------------------------------
# analyse: one coarse analysis
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def coarse(tmp_path_factory):
    """The CRV-80E on a coarse mesh at 30° steps (two discs on one carrier, crankshafts), without
    the P2 stress re-solve; the progress reports and the results after the ``stress`` and
    ``roller_depth`` sections (``after``) recorded."""
    reports, sections = [], {}
    result = analyse(coarse_case("crv80e"), angle_step_deg=STEP_DEG, recover_stress=False,
                     cache_dir=tmp_path_factory.mktemp("meshes"), progress=lambda *r: reports.append(r),
                     after={name: lambda a, name=name: sections.setdefault(name, a)
                            for name in ("model", "stress", "roller_depth")})
    return result, reports, sections


def test_after_gives_the_model_and_the_results_so_far_after_each_named_section(coarse):
    """What a run hands its render worker early: after ``model`` the disc's system; after
    ``stress`` the stress result that the analysis ends with and none of the later sections; after
    ``roller_depth`` that one too."""
    a, _, partial = coarse
    assert list(partial) == ["model", "stress", "roller_depth"]
    assert partial["model"] is a.system
    assert a.roller_depth is not None
    early = partial["stress"]
    assert early.stress is a.stress and early.cycle is a.cycle and early.hertz is a.hertz
    assert early.roller_depth is None and early.roller_life_steps is None and early.warnings == ()
    assert partial["roller_depth"].roller_depth is a.roller_depth and partial["roller_depth"].stress is a.stress


def test_the_plot_groups_handed_over_early_make_up_the_plots(coarse, tmp_path):
    """A run hands its render worker the load cycle's plots after the ``stress`` section and the
    crank bearing's after ``roller_depth``: from those partial analyses, the two groups are the
    plots of the whole analysis, in their order."""
    from rvfem.outputs import summary as outputs

    a, _, partial = coarse

    def names(calls):
        return [(function.__name__, kwargs["path"].name) for function, kwargs in calls]

    cycle = names(outputs.plot_calls(partial["stress"], tmp_path, group="cycle"))
    roller = names(outputs.plot_calls(partial["roller_depth"], tmp_path, group="roller_depth"))
    assert roller and cycle + roller == names(outputs.plot_calls(a, tmp_path))
    with pytest.raises(ValueError, match="no plot group 'stress'"):
        outputs.plot_calls(a, tmp_path, group="stress")


def test_the_cycle_is_in_equilibrium(coarse):
    a, _, _ = coarse
    case, cyc = a.case, a.cycle
    np.testing.assert_array_equal(a.theta, load_cycle_angles(STEP_DEG))
    np.testing.assert_array_equal(cyc.theta, a.theta)
    assert cyc.equilibrium_residual.max() < 1e-12
    # the carrier: the two discs' torques add up to the output torque at every angle
    np.testing.assert_allclose(cyc.disc_torque_Nmm.sum(axis=1), case.loads.torque_Nm * 1000.0, rtol=1e-12)
    # each disc: its bearings' moment about the reducer axis is its torque (the carrier turns about the
    # axis; the bores are at c_i + e·u(θ) from it, disc B at θ + 180°)
    c, e = cycle_module.crank_centres(case), case.cycloid.eccentricity
    for k in range(case.loads.discs):
        th = a.theta + k * math.pi
        r = c[None, :, :] + e * np.stack([np.cos(th), np.sin(th)], axis=1)[:, None, :]
        f = cyc.disc_bearing_forces[:, k]
        moment = (r[..., 0] * f[..., 1] - r[..., 1] * f[..., 0]).sum(axis=1)
        np.testing.assert_allclose(moment, cyc.disc_torque_Nmm[:, k], rtol=1e-9)


def test_the_comparison_holds_the_cycle_and_the_handbook_loads(coarse):
    a, _, _ = coarse
    loads = a.cycle.bearing_loads
    p = a.case.analysis.equivalent_load_exponent
    rigid = analyse_rigid(a.case, a.theta)
    assert len(a.comparison.bearings) == a.case.cranks.count
    for i, b in enumerate(a.comparison.bearings):
        k_max, k_min = int(np.argmax(loads[:, i])), int(np.argmin(loads[:, i]))
        assert b.flexible.max_N == loads[k_max, i] and b.flexible.min_N == loads[k_min, i]
        assert b.flexible.max_at_deg == pytest.approx(math.degrees(a.theta[k_max]))
        assert b.flexible.min_at_deg == pytest.approx(math.degrees(a.theta[k_min]))
        assert b.flexible.equivalent_N == pytest.approx(float(equivalent_load(loads[:, i], p)), rel=1e-12)
        assert b.rigid.max_N == rigid.bearings[i].loads.max_N
        assert b.rigid.equivalent_N == rigid.bearings[i].loads.equivalent_N
        assert b.delta_max_percent == pytest.approx(100.0 * (b.flexible.max_N / b.rigid.max_N - 1.0), rel=1e-9)
        assert b.life_ratio == pytest.approx(b.flexible.L10h / b.rigid.L10h, rel=1e-9)
    k, i = a.max_load_index
    assert loads[k, i] == pytest.approx(loads.max(), rel=1e-9)


def test_every_stage_is_timed_and_reported_in_order(coarse):
    a, reports, _ = coarse
    ran = ["check", "mesh", "model", "rigid", "cycle", "evaluation", "stress", "attribution", "accuracy",
           "roller_slices"]
    started = [stage for stage, done, _ in reports if done == 0]
    assert started == [s for s in STAGES if s in ran] == ran     # no duty cycle; stress: histories, no P2 re-solve
    for stage in ran:
        mine = [(done, total) for s, done, total in reports if s == stage]
        assert mine[0][0] == 0 and mine[-1][0] == mine[-1][1]           # starts at 0, ends at total
        assert [d for d, _ in mine] == sorted(d for d, _ in mine)
        assert a.timings[stage] >= 0.0
    n = len(a.theta)
    assert [r for r in reports if r[0] == "cycle"][-1] == ("cycle", n, n)
    assert a.timings["cycle_per_angle"] == pytest.approx(a.timings["cycle"] / n)
    assert {"model_assembly", "model_factorization", "attribution_compute"} <= set(a.timings)
    assert a.stress.recovered is None                               # the stage only made the histories
    assert a.attribution is not None


def test_the_kept_fields_are_the_saved_angles_and_the_largest_load(coarse):
    a, _, _ = coarse
    kept = {round(s.theta_deg, 9) for s in a.stress.snapshots}
    k, _ = a.max_load_index
    assert set(a.case.analysis.saved_angles_deg) <= kept
    assert round(math.degrees(a.theta[k]), 9) in kept
    assert round(a.stress.peak.theta_deg, 9) in kept


# --------------------------------------------------------------------------------------------
# The duty cycle at every torque
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def duty(tmp_path_factory):
    """The CRV-80E with the duty cycle of Gao et al. (784 and 1960 N·m) on a coarse mesh at 30°."""
    return analyse(coarse_case("crv80e_duty"), angle_step_deg=STEP_DEG, recover_stress=False, attribute=False,
                   cache_dir=tmp_path_factory.mktemp("meshes"))


def test_the_duty_cycle_at_the_rated_torque_is_the_comparison(duty):
    fe = duty.duty_cycle.flexible_fe
    rated = duty.case.loads.torque_Nm
    assert fe.torques_Nm == tuple(sorted({r.torque_Nm for r in duty.case.loads.duty_cycle if r.torque_Nm > 0}))
    i = fe.torques_Nm.index(rated)
    assert fe.equivalent_load_N[i] == tuple(b.flexible.equivalent_N for b in duty.comparison.bearings)
    assert fe.linear_scaling_error_percent[i] == 0.0
    assert fe.linear_scaling_life_h == duty.duty_cycle.flexible.service_life_h
    assert "duty_cycle" in duty.timings


def test_the_duty_cycle_at_another_torque_is_the_cycle_at_that_operating_point(duty):
    fe = duty.duty_cycle.flexible_fe
    case = duty.case
    p = case.analysis.equivalent_load_exponent
    (torque,) = [t for t in fe.torques_Nm if t != case.loads.torque_Nm]
    op = cycle_module.OperatingPoint(torque, case.analysis.friction)
    other = cycle_module.load_cycle(duty.system, duty.theta, op=op, saved_angles_deg=())
    expected = [float(equivalent_load(f, p)) for f in other.bearing_loads.T]
    np.testing.assert_allclose(fe.equivalent_load_N[fe.torques_Nm.index(torque)], expected, rtol=1e-12)
    # the linear-scaling error of that row, by its definition
    rated = fe.equivalent_load_N[fe.torques_Nm.index(case.loads.torque_Nm)]
    ratio = [f / (f0 * torque / case.loads.torque_Nm) - 1.0 for f, f0 in zip(expected, rated)]
    assert fe.linear_scaling_error_percent[fe.torques_Nm.index(torque)] == pytest.approx(
        100.0 * max(ratio, key=abs), rel=1e-9, abs=1e-12)


def test_the_duty_cycle_life_is_palmgren_miner_over_the_fe_loads(duty):
    fe = duty.duty_cycle.flexible_fe
    case = duty.case
    rows = case.loads.duty_cycle
    rating = iso281.crank_bearing_rating(case.crank_bearing)
    total = sum(r.time_share for r in rows)
    lives = []
    for i in range(case.cranks.count):
        damage = sum(r.time_share / total / iso281.rating_life_hours(
            rating, fe.equivalent_load_N[fe.torques_Nm.index(r.torque_Nm)][i],
            r.speed_rpm * case.pins.count / (case.pins.count - case.cycloid.teeth))
            for r in rows if r.torque_Nm > 0)                   # a row at rest does no damage
        lives.append(1.0 / damage)
    assert fe.service_life_h == pytest.approx(min(lives), rel=1e-12)


def test_duty_cycle_fe_solves_on_the_same_factorisation(duty, monkeypatch):
    calls = []
    real = fem.factorize
    monkeypatch.setattr(fem, "factorize", lambda *a, **k: calls.append(1) or real(*a, **k))
    again = duty_cycle_fe(duty.system, duty.theta, duty.cycle, duty.comparison,
                          duty.duty_cycle.flexible.service_life_h)
    assert calls == []
    first = duty.duty_cycle.flexible_fe
    assert again.torques_Nm == first.torques_Nm
    np.testing.assert_allclose(again.equivalent_load_N, first.equivalent_load_N, rtol=1e-12)


# --------------------------------------------------------------------------------------------
# Kept field angles and repository paths
# --------------------------------------------------------------------------------------------


def test_kept_field_angles_are_the_saved_ones_and_every_field_step():
    case = load_case(CRV80E)
    saved = tuple(case.analysis.saved_angles_deg)
    assert kept_field_angles(case, None) == saved
    assert kept_field_angles(case, 90) == saved + (0.0, 90.0, 180.0, 270.0)
    assert kept_field_angles(case, 360.0) == saved + (0.0,)
    assert len(kept_field_angles(case, 7.5)) == len(saved) + 48


@pytest.mark.parametrize("step", [0, -10.0, 360.5, "10"])
def test_a_bad_field_step_is_a_case_error(step):
    with pytest.raises(CaseError, match=r"the field step must be in \(0°, 360°\]"):
        kept_field_angles(load_case(CRV80E), step)


def test_repository_path_looks_in_every_folder_above_the_start(tmp_path):
    assert repository_path("cases/crv80e.toml", start=ROOT / "docs") == CRV80E
    assert repository_path("cases/crv80e.toml", start=ROOT / "rvfem" / "app") == CRV80E
    assert repository_path(CRV80E) == CRV80E                         # an absolute path that exists
    with pytest.raises(CaseError, match="no such file"):
        repository_path(tmp_path / "missing.toml")
    with pytest.raises(CaseError, match="not found in .* or any folder above it"):
        repository_path("cases/crv80e.toml", start=tmp_path)
