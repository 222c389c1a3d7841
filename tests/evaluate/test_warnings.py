"""Warnings for results outside their model's range (:mod:`rvfem.evaluate.validity`): the limits on
synthetic numbers, the rigid evaluation of every shipped case (none warns) and at overload, and one
overloaded ``rvfem run`` through the command line (slow)."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import CASES_DIR, CaseText, coarse_case

from rvfem.app import cli
from rvfem.app.analysis import analyse_rigid
from rvfem.case.definition import load_case
from rvfem.evaluate import validity
from rvfem.evaluate.validity import (
    DISPLACEMENT_FRACTION_LIMIT,
    HERTZ_PRESSURE_LIMIT_MPA,
    LOAD_RATIO_LIMIT,
    MIN_LIFE_H,
    PLACEHOLDER_YIELD_STRENGTH_MPA,
    ResultWarning,
    check_limits,
)

CRV80E = str(CASES_DIR / "crv80e.toml")
SHIPPED = sorted(p.stem for p in CASES_DIR.glob("*.toml"))


def _codes(warnings) -> list[str]:
    return [w.code for w in warnings]


# --------------------------------------------------------------------------------------------
# The limits, on synthetic numbers
# --------------------------------------------------------------------------------------------


def test_nothing_to_check_gives_no_warning():
    assert check_limits() == ()


@pytest.mark.parametrize("factor, warns", [(0.999, False), (1.0, False), (1.001, True)])
def test_load_ratio_limit(factor, warns):
    w = check_limits(load_ratios=[("bearing 1, rigid", 0.1), ("bearing 2, flexible", factor * LOAD_RATIO_LIMIT)])
    assert _codes(w) == (["load_ratio"] if warns else [])
    if warns:
        assert w[0].value == pytest.approx(factor * LOAD_RATIO_LIMIT) and w[0].limit == LOAD_RATIO_LIMIT
        assert "bearing 2, flexible" in w[0].message and "ISO 281" in w[0].message and w[0].unit == ""


@pytest.mark.parametrize("life, warns", [(0.999, True), (0.4, True), (1.0, False), (1e24, False)])
def test_life_limit(life, warns):
    w = check_limits(lives_h=[("bearing 1, flexible L10h", life), ("bearing 2, flexible L10h", 5000.0)])
    assert _codes(w) == (["life_under_1h"] if warns else [])
    if warns:
        assert w[0].value == life and w[0].limit == MIN_LIFE_H and w[0].unit == "h"
        assert "bearing 1, flexible L10h" in w[0].message and "< 1 h" in w[0].message


def test_life_of_zero_load_is_infinite_and_not_a_warning():
    assert check_limits(lives_h=[("bearing 1", math.inf), ("bearing 2", None), ("bearing 3", math.nan)]) == ()


@pytest.mark.parametrize("pressure, warns", [(3999.0, False), (4000.0, False), (4001.0, True)])
def test_hertz_limit_is_iso_76(pressure, warns):
    w = check_limits(hertz_MPa=[("FE, on the eccentric", pressure), ("FE, in the disc bore", 0.8 * pressure)])
    assert _codes(w) == (["hertz_pressure"] if warns else [])
    if warns:
        assert w[0].limit == HERTZ_PRESSURE_LIMIT_MPA == 4000.0 and "ISO 76" in w[0].message
        assert "on the eccentric" in w[0].message and w[0].unit == "MPa"


@pytest.mark.parametrize("stress, warns", [(1599.0, False), (1600.0, False), (1601.0, True)])
def test_disc_stress_against_the_placeholder_yield_strength(stress, warns):
    w = check_limits(disc_stress_MPa=stress)
    assert _codes(w) == (["disc_stress_yield"] if warns else [])
    if warns:
        assert w[0].limit == PLACEHOLDER_YIELD_STRENGTH_MPA and "placeholder" in w[0].message


def test_disc_stress_against_a_given_yield_strength():
    (w,) = check_limits(disc_stress_MPa=900.0, yield_strength_MPa=800.0)
    assert w.limit == 800.0 and "placeholder" not in w.message


@pytest.mark.parametrize("fraction, warns", [(0.099, False), (0.1, False), (0.101, True), (2.0, True)])
def test_deformation_against_the_element_size(fraction, warns):
    w = check_limits(deformation_mm=fraction * 0.35, element_size_mm=0.35)
    assert _codes(w) == (["large_displacement"] if warns else [])
    if warns:
        assert w[0].limit == pytest.approx(DISPLACEMENT_FRACTION_LIMIT * 0.35) and w[0].unit == "mm"
        assert f"{100 * fraction:.0f} %" in w[0].message


def test_worst_value_named_and_order_fixed():
    w = check_limits(load_ratios=[("a", 0.7), ("b", 3.0), ("c", 0.9)], lives_h=[("x", 0.2), ("y", 0.01)],
                     hertz_MPa=[("p", 5000.0), ("q", 9000.0)], disc_stress_MPa=2000.0, deformation_mm=1.0,
                     element_size_mm=0.4)
    assert _codes(w) == ["load_ratio", "life_under_1h", "hertz_pressure", "disc_stress_yield", "large_displacement"]
    assert [x.value for x in w[:3]] == [3.0, 0.01, 9000.0]
    assert "(b)" in w[0].message and "(y)" in w[1].message and "(q)" in w[2].message
    for x in w:
        assert "\n" not in x.message
        assert json.loads(json.dumps(x.as_dict())) == {"code": x.code, "message": x.message, "value": x.value,
                                                       "limit": x.limit, "unit": x.unit}


def _fake_analysis(scale: float):
    """The parts of an Analysis that :func:`validity.analysis_warnings` reads, its loads scaled."""
    stats = SimpleNamespace(equivalent_N=4000.0 * scale, L10h=30000.0 / scale ** (10 / 3))
    contact = SimpleNamespace(peak_pressure_MPa=1500.0 * math.sqrt(scale))
    return SimpleNamespace(
        comparison=SimpleNamespace(rating_N=21948.7, bearings=[
            SimpleNamespace(bearing=0, rigid=stats, flexible=stats), SimpleNamespace(bearing=1, rigid=None,
                                                                                     flexible=stats)]),
        duty_cycle=None,
        hertz={"fe_rollers": SimpleNamespace(inner=contact, outer=contact)},
        stress=SimpleNamespace(structural=SimpleNamespace(von_mises_MPa=107.0 * scale),
                               snapshots=[SimpleNamespace(deformation=np.array([[0.0, 0.008 * scale], [0.0, 0.0]]))]),
        case=SimpleNamespace(mesh=SimpleNamespace(size_flank=0.35, size_bore=0.4),
                             material=SimpleNamespace(youngs_modulus=206000.0, poissons_ratio=0.3,
                                                               yield_strength=1600.0)),
    )


def test_analysis_warnings_read_the_analysis():
    assert validity.analysis_warnings(_fake_analysis(1.0)) == ()
    w = validity.analysis_warnings(_fake_analysis(48.0))
    assert _codes(w) == ["load_ratio", "life_under_1h", "hertz_pressure", "disc_stress_yield", "large_displacement"]
    assert "bearing 1, rigid" in w[0].message          # the first of the equal ones
    assert w[4].value == pytest.approx(0.008 * 48) and "0.35 mm" in w[4].message


# --------------------------------------------------------------------------------------------
# The rigid evaluation: the shipped cases do not warn, an overload does
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_cases_do_not_warn_in_the_rigid_evaluation(name):
    assert analyse_rigid(load_case(CASES_DIR / f"{name}.toml")).warnings == ()


@pytest.mark.parametrize("torque", [48 * 784.0, 1e6])
def test_rigid_overload_warns_on_screen_and_in_json(torque, capsys):
    assert cli.main(["rigid", CRV80E, "--set", f"loads.torque_Nm={torque}"]) == 0
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if line.startswith("  warning: ")]
    # 48× the rated torque also crushes the raceways statically: the pressure along the roller of
    # the slice model is over ISO 76's 4000 MPa (as it is in rvfem run), and S0 = C0/P0 < 1 (ISO 76)
    assert [line.split(":")[1].split()[0] for line in lines] == ["P/C", "life", "Hertz", "pressure", "static"]
    assert cli.main(["rigid", CRV80E, "--json", "--set", f"loads.torque_Nm={torque}"]) == 0
    out, err = capsys.readouterr()
    report = json.loads(out)
    assert [w["code"] for w in report["warnings"]] == ["load_ratio", "life_under_1h", "hertz_pressure",
                                                       "roller_pressure", "static_safety"]
    assert report["warnings"][3]["value"] > report["warnings"][3]["limit"] == 4000.0
    s0 = report["bearing_checks"]["static_safety"]["rigid"]
    assert report["warnings"][4]["value"] == pytest.approx(s0["C0_N"] / max(b["max_load_N"] for b in report["bearings"]))
    assert report["warnings"][0]["value"] == pytest.approx(
        report["bearings"][0]["equivalent_load_N"] / report["dynamic_load_rating_N"])
    assert err.count("rvfem rigid: warning: ") == 5


def test_rigid_duty_cycle_life_under_an_hour_warns(tmp_path):
    path = (CaseText.shipped("crv80e_duty").write(tmp_path))
    case = load_case(path, ("loads.torque_Nm=40000.0",))
    w = analyse_rigid(case).warnings
    assert "life_under_1h" in _codes(w)
    assert analyse_rigid(load_case(path)).warnings == ()


def test_rigid_json_without_warnings_has_an_empty_list(capsys):
    assert cli.main(["rigid", CRV80E, "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["warnings"] == [] and err == ""


# --------------------------------------------------------------------------------------------
# rvfem run at 48 × the rated torque (slow)
# --------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_run_at_48_times_the_rated_torque_warns_everywhere(tmp_path, capsys):
    """The default case, coarse, at 48 × its rated torque (412 N·m): every limit is crossed; the
    warnings are in summary.json, on the screen and in the report."""
    text = (CaseText.shipped("rv40e_fanholes")
            .set("mesh", "size_flank", "0.7").set("mesh", "size_bore", "0.8").set("mesh", "size_interior", "5.0")
            .set("analysis", "angle_step_deg", "30.0").set("analysis", "saved_angles_deg", "[0.0]"))
    path = text.write(tmp_path, "coarse.toml")
    out = tmp_path / "out"
    assert cli.main(["run", str(path), "-o", str(out), "--no-images", "--cache-dir", str(tmp_path / "meshes"),
                     "--set", f"loads.torque_Nm={48 * 412.0}"]) == 0
    screen = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    codes = [w["code"] for w in summary["warnings"]]
    assert codes == ["load_ratio", "life_under_1h", "hertz_pressure", "disc_stress_yield", "large_displacement",
                     "fatigue_safety", "roller_pressure", "roller_pressure",     # rigid and flexible slices
                     "static_safety"]
    slices = [w["message"] for w in summary["warnings"] if w["code"] == "roller_pressure"]
    assert ["rigid" in m for m in slices] == [True, False] and all("> 4000 MPa" in m for m in slices)
    for w in summary["warnings"]:
        assert set(w) == {"code", "message", "value", "limit", "unit"}
        assert f"  warning: {w['message']}" in screen.splitlines()
    pc = max(b["flexible"]["equivalent_load_N"] for b in summary["bearings"]) / summary["model"]["dynamic_load_rating_N"]
    assert summary["warnings"][0]["value"] == pytest.approx(pc)
    assert summary["warnings"][3]["value"] == pytest.approx(summary["peak_von_mises_MPa"])
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "class='warnings'" in html and html.count("<li><code>") >= 6
    assert ResultWarning(**summary["warnings"][0]).code == "load_ratio"


@pytest.mark.slow
@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_cases_do_not_warn(name, tmp_path):
    """Every shipped case, coarse and at 30° steps, is inside every model's range — but for the
    minimum-load rule (0.02·C, a maker's rule), which warns exactly when the smallest bearing load
    of the cycle is under it (the FE lowers it below the rule on most shipped cases)."""
    from rvfem.app.analysis import analyse

    a = analyse(coarse_case(name), angle_step_deg=30.0, cache_dir=tmp_path / "meshes")
    below = any(m.fraction_of_C < 0.02 for m in a.bearing_checks.minimum.values())
    assert _codes(a.warnings) == (["minimum_load"] if below else []), [w.message for w in a.warnings]


@pytest.mark.slow
@pytest.mark.parametrize("changes, slices", [({"loads": {"torque_Nm": 1e6}}, ["roller_pressure"] * 2),
                                             ({"cycloid": {"pitch_error": {"amplitude": 1.0, "values": []}}},
                                              ["roller_pressure"])])
def test_overload_cases_warn(changes, slices, tmp_path):
    """1e6 N·m and a 1 mm pitch error (the issue's examples): every limit is crossed. The slice
    pressure warns for the rigid and the flexible loads at 1e6 N·m, for the flexible ones alone
    with the pitch error (the rigid handbook has none)."""
    from rvfem.app.analysis import analyse

    a = analyse(coarse_case("rv40e_fanholes", **changes), angle_step_deg=30.0, cache_dir=tmp_path / "meshes")
    assert _codes(a.warnings) == ["load_ratio", "life_under_1h", "hertz_pressure", "disc_stress_yield",
                                  "large_displacement", "fatigue_safety", *slices, "static_safety"]


def test_hertz_limit_scales_with_a_material_that_is_not_steel():
    """ISO 76's 4000 MPa is on bearing steel; a material of 6 × steel's modulus (the rigid-disc limit
    of rv40e_classical) presses sqrt(6) times harder for the same roller load, and so may its limit."""
    from rvfem.evaluate.validity import hertz_pressure_limit_MPa

    assert hertz_pressure_limit_MPa() == HERTZ_PRESSURE_LIMIT_MPA
    assert hertz_pressure_limit_MPa(206000.0, 0.3) == pytest.approx(4000.0, rel=1e-15)
    limit = hertz_pressure_limit_MPa(1.2e6, 0.3)
    assert limit == pytest.approx(4000.0 * math.sqrt(1.2e6 / 206000.0))
    assert check_limits(hertz_MPa=[("x", 4041.0)], hertz_limit_MPa=limit) == ()
    (w,) = check_limits(hertz_MPa=[("x", 1.01 * limit)], hertz_limit_MPa=limit)
    assert w.limit == limit and "scaled to the case's modulus" in w.message
