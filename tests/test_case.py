"""Case-file reading and validation: every error names the file and the dotted key."""

from __future__ import annotations

import math

import pytest

from rvfem.case import Case, case_from_dict, case_to_dict, load_case
from rvfem.errors import CaseError, RvfemError

from conftest import CASES_DIR


def expect_error(tmp_path, text, key, *fragments):
    """Load the edited text from a file and check the CaseError names file, key and fragments."""
    path = text.write(tmp_path)
    with pytest.raises(CaseError) as info:
        load_case(path)
    message = str(info.value)
    assert str(path) in message, message
    assert f"'{key}'" in message, message
    for fragment in fragments:
        assert fragment in message, message
    assert "\n" not in message, "errors are one line"
    return message


# --------------------------------------------------------------------------------------------
# shipped cases
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("path", sorted(CASES_DIR.glob("*.toml")), ids=lambda p: p.stem)
def test_every_shipped_case_loads_and_round_trips(path):
    case = load_case(path)
    assert isinstance(case, Case)
    assert case.name == path.stem
    again = case_from_dict(case_to_dict(case), source=str(path))
    assert again == case
    assert again.digest() == case.digest()


def test_shipped_cases_carry_the_published_data():
    crv = load_case(CASES_DIR / "crv80e.toml")
    assert (crv.cycloid.eccentricity, crv.pins.circle_radius, crv.pins.count, crv.cycloid.teeth) == (1.45, 76.5, 40, 39)
    assert (crv.cranks.circle_radius, crv.cranks.count, crv.loads.torque_Nm, crv.loads.speed_rpm) == (42.0, 3, 784.0, 15.0)
    b = crv.crank_bearing
    assert (b.roller_diameter, b.roller_length, b.rollers, b.pitch_diameter, b.b_m, b.lambda_nu) == (5, 9, 14, 31, 1.1, 0.83)
    assert crv.analysis.equivalent_load_exponent == 4.0
    rv110 = load_case(CASES_DIR / "rv110e.toml")
    b = rv110.crank_bearing
    assert (b.roller_diameter, b.rollers, b.roller_length, b.b_m) == (6.0, 13, 11.8, 1.0)
    assert b.inner_raceway_radius == 15.0 and b.bore_radius == 21.0   # Table 2: d = 30, D = 42
    assert math.isclose(rv110.analysis.equivalent_load_exponent, 10 / 3)


def test_defaults_fill_optional_tables(case_text, tmp_path):
    case_text.drop_table("analysis").drop_table("material")
    case = load_case(case_text.write(tmp_path))
    assert math.isclose(case.analysis.equivalent_load_exponent, 10 / 3)
    assert case.material.youngs_modulus == 206000.0
    assert case.cranks.angles_deg == (90.0, 210.0, 330.0)


def test_name_defaults_to_the_file_stem(case_text, tmp_path):
    case_text.drop("", "name")
    assert load_case(case_text.write(tmp_path, "my_reducer.toml")).name == "my_reducer"


def test_case_error_is_an_rvfem_error():
    assert issubclass(CaseError, RvfemError)


# --------------------------------------------------------------------------------------------
# file-level problems
# --------------------------------------------------------------------------------------------


def test_missing_file(tmp_path):
    path = tmp_path / "absent.toml"
    with pytest.raises(CaseError, match="cannot read the case file") as info:
        load_case(path)
    assert str(path) in str(info.value)


def test_invalid_toml(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[cycloid\nteeth = 39\n")
    with pytest.raises(CaseError, match="not a valid TOML file") as info:
        load_case(path)
    assert str(path) in str(info.value)


# --------------------------------------------------------------------------------------------
# unknown, missing and mistyped keys
# --------------------------------------------------------------------------------------------


def test_misspelled_key_suggests_the_right_one(case_text, tmp_path):
    case_text.drop("crank_bearing", "radial_clearance").set("crank_bearing", "radial_clerance", "0.01")
    expect_error(tmp_path, case_text, "crank_bearing.radial_clerance", "is not a known key",
                 "did you mean 'crank_bearing.radial_clearance'")


def test_unknown_key_without_close_match(case_text, tmp_path):
    case_text.set("pins", "colour", '"red"')
    message = expect_error(tmp_path, case_text, "pins.colour", "is not a known key")
    assert "did you mean" not in message


def test_misspelled_table_suggests_the_right_one(case_text, tmp_path):
    case_text.append("[fanholes]\ninner_radius = 20.0\nouter_radius = 30.0\nspan_deg = 40.0")
    expect_error(tmp_path, case_text, "fanholes", "is not a known key", "did you mean 'fan_holes'")


def test_missing_required_key(case_text, tmp_path):
    case_text.drop("cycloid", "teeth")
    expect_error(tmp_path, case_text, "cycloid.teeth", "is missing (required)")


def test_missing_required_table(case_text, tmp_path):
    case_text.drop_table("pins")
    expect_error(tmp_path, case_text, "pins", "is missing (required table)")


def test_key_that_must_be_a_table(case_text, tmp_path):
    case_text.drop_table("loads").prepend("loads = 412.0")
    expect_error(tmp_path, case_text, "loads", "must be a table")


@pytest.mark.parametrize(
    "table, key, value, fragment",
    [
        ("cycloid", "teeth", "39.0", "must be an integer"),
        ("crank_bearing", "rollers", "true", "must be an integer"),
        ("cycloid", "eccentricity", '"1.3"', "must be a number"),
        ("cycloid", "eccentricity", "nan", "must be finite"),
        ("pins", "circle_radius", "inf", "must be finite"),
        ("material", "name", "42", "must be a string"),
        ("cranks", "angles_deg", '"90"', "must be a list of numbers"),
        ("cranks", "angles_deg", '[90, "210", 330]', "must be a list of numbers"),
    ],
)
def test_wrong_types(case_text, tmp_path, table, key, value, fragment):
    case_text.set(table, key, value)
    expect_error(tmp_path, case_text, f"{table}.{key}", fragment)


@pytest.mark.parametrize(
    "table, key, value, suggestion",
    [
        ("pins", "model", '"rigd"', "rigid"),
        ("crank_bearing", "model", '"roller"', "rollers"),
        ("crank_bearing", "stiffness_law", '"palmgrem"', "palmgren"),
    ],
)
def test_bad_choices_list_the_options_and_suggest(case_text, tmp_path, table, key, value, suggestion):
    case_text.set(table, key, value)
    expect_error(tmp_path, case_text, f"{table}.{key}", "must be one of", f"did you mean '{suggestion}'")


# --------------------------------------------------------------------------------------------
# non-physical values
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "table, key, value, fragment",
    [
        ("pins", "radius", "-3.0", "must be positive"),
        ("pins", "circle_radius", "-64.0", "must be positive"),
        ("cranks", "circle_radius", "0.0", "must be positive"),
        ("cycloid", "thickness", "0", "must be positive"),
        ("cycloid", "central_hole_radius", "-1.0", "must be positive"),
        ("crank_bearing", "bore_radius", "-18.0", "must be positive"),
        ("crank_bearing", "radial_clearance", "-0.005", "must be non-negative"),
        ("loads", "torque_Nm", "-412.0", "must be positive"),
        ("loads", "discs", "0", "must be positive"),
        ("material", "youngs_modulus", "-1.0", "must be positive"),
        ("analysis", "equivalent_load_exponent", "0.0", "must be positive"),
        ("analysis", "friction", "-0.05", "must be non-negative"),
    ],
)
def test_negative_or_zero_values(case_text, tmp_path, table, key, value, fragment):
    case_text.set(table, key, value)
    expect_error(tmp_path, case_text, f"{table}.{key}", fragment)


def test_more_lobes_than_pins(case_text, tmp_path):
    case_text.set("pins", "count", "39")
    expect_error(tmp_path, case_text, "pins.count", "must exceed cycloid.teeth", "Zp = 39")


def test_short_amplitude_coefficient_at_least_one(case_text, tmp_path):
    case_text.set("cycloid", "eccentricity", "1.6")   # k = 1.6·40/64 = 1.0
    expect_error(tmp_path, case_text, "cycloid.eccentricity", "k = e·Zp/Rp = 1.000", "must be < 1")


def test_overlapping_pins(case_text, tmp_path):
    case_text.set("pins", "radius", "5.1")   # pitch half-chord 64·sin(π/40) = 5.02 mm
    expect_error(tmp_path, case_text, "pins.radius", "neighbouring pins overlap")


def test_rollers_that_do_not_fit(case_text, tmp_path):
    case_text.set("crank_bearing", "rollers", "20")   # 20·5 mm > π·31 mm
    expect_error(tmp_path, case_text, "crank_bearing.rollers", "do not fit the pitch circle")


def test_roller_larger_than_pitch_diameter(case_text, tmp_path):
    case_text.set("crank_bearing", "roller_diameter", "31.0").set("crank_bearing", "rollers", "2")
    expect_error(tmp_path, case_text, "crank_bearing.roller_diameter", "must be smaller than pitch_diameter")


def test_bore_inside_the_pitch_circle(case_text, tmp_path):
    case_text.set("crank_bearing", "bore_radius", "15.0")
    expect_error(tmp_path, case_text, "crank_bearing.bore_radius", "must exceed half the pitch diameter")


def test_linear_law_needs_a_stiffness(case_text, tmp_path):
    case_text.set("crank_bearing", "stiffness_law", '"linear"')
    expect_error(tmp_path, case_text, "crank_bearing.linear_stiffness_N_per_mm", "required when stiffness_law = 'linear'")


def test_one_crank_is_not_enough(case_text, tmp_path):
    case_text.set("cranks", "count", "1")
    expect_error(tmp_path, case_text, "cranks.count", "must be at least 2")


def test_crank_angles_must_match_the_count(case_text, tmp_path):
    case_text.set("cranks", "angles_deg", "[0, 120]")
    expect_error(tmp_path, case_text, "cranks.angles_deg", "must list 3 angles")


def test_poissons_ratio_range(case_text, tmp_path):
    case_text.set("material", "poissons_ratio", "0.5")
    expect_error(tmp_path, case_text, "material.poissons_ratio", "must lie in [0, 0.5)")


def test_element_order(case_text, tmp_path):
    case_text.set("analysis", "element_order", "3")
    expect_error(tmp_path, case_text, "analysis.element_order", "must be 1 (P1) or 2 (P2)")


def test_angle_step_too_coarse(case_text, tmp_path):
    case_text.set("analysis", "angle_step_deg", "45.0")
    expect_error(tmp_path, case_text, "analysis.angle_step_deg", "must be at most 30°")


# --------------------------------------------------------------------------------------------
# optional tables: pitch error, holes, duty cycle
# --------------------------------------------------------------------------------------------


def test_pitch_error_values_one_per_tooth(case_text, tmp_path):
    case_text.append("[cycloid.pitch_error]\nvalues = [0.01, -0.01]")
    expect_error(tmp_path, case_text, "cycloid.pitch_error.values", "one value per tooth (39)")


def test_pitch_error_amplitude_and_values_exclude_each_other(case_text, tmp_path):
    values = ", ".join(["0.0"] * 39)
    case_text.append(f"[cycloid.pitch_error]\namplitude = 0.01\nvalues = [{values}]")
    expect_error(tmp_path, case_text, "cycloid.pitch_error.amplitude", "exclude each other")


def test_profile_modification_unknown_key(case_text, tmp_path):
    case_text.append("[cycloid.modification]\nequidistant = 0.01\nshfit = 0.01")
    expect_error(tmp_path, case_text, "cycloid.modification.shfit", "did you mean 'cycloid.modification.shift'")


FAN = "[fan_holes]\ninner_radius = 20.0\nouter_radius = 30.0\n"


def test_fan_holes_load(case_text, tmp_path):
    case_text.append(FAN + "span_deg = 40.0")
    fan = load_case(case_text.write(tmp_path)).fan_holes
    assert (fan.inner_radius, fan.outer_radius, fan.span_deg, fan.count) == (20.0, 30.0, 40.0, 3)


def test_fan_holes_outer_radius_must_exceed_inner(case_text, tmp_path):
    case_text.append("[fan_holes]\ninner_radius = 30.0\nouter_radius = 20.0\nspan_deg = 40.0")
    expect_error(tmp_path, case_text, "fan_holes.outer_radius", "must exceed inner_radius")


@pytest.mark.parametrize("extra", ["", "span_deg = 40.0\nligament = 3.0"])
def test_fan_holes_need_exactly_one_of_span_and_ligament(case_text, tmp_path, extra):
    case_text.append(FAN + extra)
    expect_error(tmp_path, case_text, "fan_holes.span_deg", "give exactly one of them")


def test_fan_holes_span_times_count_below_full_turn(case_text, tmp_path):
    case_text.append(FAN + "span_deg = 130.0")
    expect_error(tmp_path, case_text, "fan_holes.span_deg", "must stay below 360°")


def test_round_holes_negative_radius(case_text, tmp_path):
    case_text.append("[round_holes]\nradius = -4.0\ncircle_radius = 25.0")
    expect_error(tmp_path, case_text, "round_holes.radius", "must be positive")


def test_duty_cycle_loads(case_text, tmp_path):
    case_text.append(
        "[[loads.duty_cycle]]\ntime_share = 0.7\nspeed_rpm = 15.0\ntorque_Nm = 412.0\n"
        "[[loads.duty_cycle]]\ntime_share = 0.3\nspeed_rpm = 5.0\ntorque_Nm = 800.0"
    )
    rows = load_case(case_text.write(tmp_path)).loads.duty_cycle
    assert [(r.time_share, r.speed_rpm, r.torque_Nm) for r in rows] == [(0.7, 15.0, 412.0), (0.3, 5.0, 800.0)]


def test_duty_cycle_must_be_an_array_of_tables(case_text, tmp_path):
    case_text.set("loads", "duty_cycle", "3")
    expect_error(tmp_path, case_text, "loads.duty_cycle", "must be an array of tables")


def test_duty_cycle_row_missing_key(case_text, tmp_path):
    case_text.append("[[loads.duty_cycle]]\ntime_share = 1.0\nspeed_rpm = 15.0")
    expect_error(tmp_path, case_text, "loads.duty_cycle[0].torque_Nm", "is missing (required)")


def test_duty_cycle_row_negative_speed(case_text, tmp_path):
    case_text.append("[[loads.duty_cycle]]\ntime_share = 1.0\nspeed_rpm = -15.0\ntorque_Nm = 100.0")
    expect_error(tmp_path, case_text, "loads.duty_cycle[0].speed_rpm", "must be positive")


def test_duty_cycle_row_misspelled_key(case_text, tmp_path):
    case_text.append("[[loads.duty_cycle]]\ntime_share = 1.0\nspeed_rpm = 15.0\ntorque_Nm = 1.0\ntorque_nm = 2.0")
    expect_error(tmp_path, case_text, "loads.duty_cycle[0].torque_nm", "did you mean 'loads.duty_cycle[0].torque_Nm'")


# --------------------------------------------------------------------------------------------
# cases built in code
# --------------------------------------------------------------------------------------------


def test_replace_validates_again():
    case = load_case(CASES_DIR / "rv40e.toml")
    with pytest.raises(CaseError, match="'cycloid.eccentricity'"):
        case.replace(cycloid=type(case.cycloid)(39, 2.0, 9.0, 12.0))
    heavier = case.replace(loads=type(case.loads)(824.0, 15.0))
    assert heavier.loads.torque_Nm == 824.0 and heavier.digest() != case.digest()


def test_case_from_dict_names_the_source():
    data = case_to_dict(load_case(CASES_DIR / "rv40e.toml"))
    data["pins"]["count"] = 30
    with pytest.raises(CaseError) as info:
        case_from_dict(data, source="study/variant_7.toml")
    assert str(info.value).startswith("study/variant_7.toml: 'pins.count'")
