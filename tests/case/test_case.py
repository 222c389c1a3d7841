"""Case-file reading and validation: every error names the file and the dotted key."""

from __future__ import annotations

import math

import pytest
from conftest import CASES_DIR

from rvfem.case.definition import Case, case_from_dict, case_to_dict, load_case
from rvfem.errors import CaseError, RvfemError


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


def test_a_default_name_from_an_unportable_file_name_is_made_one_component(case_text, tmp_path):
    """The file "-my reducer (v2).toml" gives the name "_my_reducer__v2_": each character outside
    letters, digits and ._+- and a leading '-' become '_', so the default never fails the check."""
    case_text.drop("", "name")
    assert load_case(case_text.write(tmp_path, "-my reducer (v2).toml")).name == "_my_reducer__v2_"


@pytest.mark.parametrize("name, fragment", [
    ("", "got an empty name"),
    (".", "it starts with '.'"),
    ("..", "it starts with '.'"),
    (".hidden", "it starts with '.'"),
    ("-rf", "it starts with '-'"),
    ("a/b", "it holds '/'"),
    ("a\\\\b", "it holds '\\\\'"),
    ("my disc / v2", "it holds ' ', '/'"),
    ("disc:v2", "it holds ':'"),
    ("x" * 101, "at most 100 characters"),
])
def test_a_name_that_is_not_one_portable_file_name_component_is_refused(case_text, tmp_path, name, fragment):
    """The name is the result folder results/<name>: "" would be results/ itself, ".." its parent,
    "a/b" a nested folder."""
    case_text.set("", "name", '"' + name + '"')
    message = expect_error(tmp_path, case_text, "name", fragment)
    if "at most" not in fragment:
        assert "letters A–Z a–z, digits and . _ + -, not starting with '.' or '-'" in message


@pytest.mark.parametrize("name", ["rv40e", "RV-40E_v2.1", "a+b", "_x", "9", "x" * 100])
def test_portable_names_are_taken(case_text, tmp_path, name):
    case_text.set("", "name", '"' + name + '"')
    assert load_case(case_text.write(tmp_path)).name == name


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
        ("crank_bearing", "radial_clearance", "-0.05", "must be at least -0.02 mm"),
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


# --------------------------------------------------------------------------------------------
# one schema: order of the checks, generated docs, bounds on every number
# --------------------------------------------------------------------------------------------

import copy  # noqa: E402
import dataclasses  # noqa: E402
import re  # noqa: E402

from conftest import ROOT  # noqa: E402

from rvfem.case import definition as case_module  # noqa: E402
from rvfem.case import registry  # noqa: E402
from rvfem.case.definition import CrankSupport, estimated_mesh_nodes, table_class  # noqa: E402
from rvfem.case.format_doc import render_case_format  # noqa: E402
from rvfem.case.schema import file_fields  # noqa: E402


def test_misspelled_required_key_is_unknown_not_missing(case_text, tmp_path):
    case_text.drop("cycloid", "eccentricity").set("cycloid", "eccentricty", "1.3")
    message = expect_error(tmp_path, case_text, "cycloid.eccentricty", "is not a known key",
                           "did you mean 'cycloid.eccentricity'")
    assert "missing" not in message


def test_docs_tables_are_generated_from_the_schema():
    path = ROOT / "docs" / "case-format.md"
    text = path.read_text(encoding="utf-8")
    assert render_case_format(text) == text, (
        "docs/case-format.md is stale; regenerate it with: python -m rvfem.case.format_doc docs/case-format.md")


def _all_tables(cls=Case, prefix=""):
    yield prefix, cls
    for spec in file_fields(cls):
        if spec.item is not None:
            yield from _all_tables(spec.item, f"{prefix}.{spec.name}".lstrip("."))


def test_every_table_has_a_generated_section_in_the_docs():
    text = (ROOT / "docs" / "case-format.md").read_text(encoding="utf-8")
    for dotted, cls in _all_tables():
        if any(spec.item is None for spec in file_fields(cls)):
            assert f"<!-- schema: {dotted} -->" in text, dotted
        assert table_class(dotted) is cls


def test_every_number_and_string_is_bounded():
    for dotted, cls in _all_tables():
        for spec in file_fields(cls):
            p = spec.param
            if spec.kind in ("int", "float", "floats", "matrix", "float_or_floats"):
                assert p.allowed() is not None or (p.low is not None and p.high is not None), f"{dotted}.{spec.name}"
            if spec.kind in ("str", "floats", "matrix", "tables") and p.allowed() is None:
                assert p.max_length is not None, f"{dotted}.{spec.name}"
            assert p.doc or spec.kind in ("table", "tables"), f"{dotted}.{spec.name} has no meaning in the docs"


def _numeric_keys(data, prefix=""):
    for key, value in data.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, dict):
            yield from _numeric_keys(value, dotted + ".")
        elif isinstance(value, float):
            yield dotted


FAN_DATA = case_to_dict(load_case(CASES_DIR / "rv40e_fanholes.toml"))


def _with(data, dotted, value):
    out = copy.deepcopy(data)
    *tables, key = dotted.split(".")
    table = out
    for part in tables:
        table = table[part]
    table[key] = value
    return out


@pytest.mark.parametrize("dotted", sorted(_numeric_keys(FAN_DATA)))
@pytest.mark.parametrize("value, pattern", [(math.nan, "must be finite, got nan"),
                                            (math.inf, "must be finite, got inf"),
                                            (-math.inf, "must be finite, got -inf"),
                                            (1e300, "must (be at most|lie in) "),
                                            (-1e300, "must be (positive|non-negative|at least)")])
def test_every_number_rejects_non_finite_and_huge_values(dotted, value, pattern):
    with pytest.raises(CaseError) as info:
        case_from_dict(_with(FAN_DATA, dotted, value), source="x.toml")
    message = str(info.value)
    assert re.match(rf"x\.toml: '{re.escape(dotted)}' {pattern}", message), message


@pytest.mark.parametrize("table, key, value, fragment", [
    ("cranks", "count", "13", "must be at most 12"),
    ("pins", "count", "500", "must be at most 200"),
    ("analysis", "equivalent_load_exponent", "25.0", "must be at most 20"),
    ("analysis", "equivalent_load_exponent", "0.5", "must be at least 1"),
    ("analysis", "angle_step_deg", "1e-9", "must be at least 0.05°"),
    ("loads", "torque_Nm", "1e9", "must be at most 1e+06 N·m"),
    ("cycloid", "eccentricity", "5e-324", "must be at least 0.01 mm"),
    ("", "name", '"' + "x" * 101 + '"', "at most 100 characters"),
    ("crank_bearing", "b_m", "0.0", "must be positive"),
    ("crank_bearing", "b_m", "0.9", "must be at least 1"),
    ("crank_bearing", "b_m", "2.0", "must be at most 1.3"),
    ("crank_bearing", "lambda_nu", "1e-100", "must be at least 0.4"),
    ("crank_bearing", "lambda_nu", "5e-324", "must be at least 0.4"),
    ("crank_bearing", "lambda_nu", "1.2", "must be at most 1"),
    ("analysis", "friction", "1.0", "must be at most 0.3"),
    ("analysis", "friction", "0.31", "must be at most 0.3"),
])
def test_ranges(case_text, tmp_path, table, key, value, fragment):
    case_text.set(table, key, value)
    expect_error(tmp_path, case_text, f"{table}.{key}".lstrip("."), fragment)


def test_control_characters_in_keys_stay_on_one_line(case_text, tmp_path):
    case_text.set("pins", '"col\\nour"', "1")
    message = expect_error(tmp_path, case_text, "pins.col\\nour", "is not a known key")
    assert "\n" not in message


def test_bore_smaller_than_the_outer_raceway(case_text, tmp_path):
    case_text.set("crank_bearing", "bore_radius", "17.0")    # (31 + 5)/2 = 18
    expect_error(tmp_path, case_text, "crank_bearing.bore_radius", "outer raceway radius (D_m + D_we)/2 = 18 mm")


def test_crank_angles_must_be_distinct(case_text, tmp_path):
    case_text.set("cranks", "angles_deg", "[90, -270, 330]")
    expect_error(tmp_path, case_text, "cranks.angles_deg", "must be distinct")


def test_duty_cycle_needs_a_non_zero_torque(case_text, tmp_path):
    case_text.append("[[loads.duty_cycle]]\ntime_share = 1.0\nspeed_rpm = 15.0\ntorque_Nm = 0.0")
    expect_error(tmp_path, case_text, "loads.duty_cycle", "at least one row with a non-zero torque")


def test_zero_torque_is_refused_and_a_negative_one_reverses(case_text, tmp_path):
    case_text.set("loads", "torque_Nm", "0.0")
    expect_error(tmp_path, case_text, "loads.torque_Nm", "at least 0.001 N·m in magnitude")
    case_text.set("loads", "torque_Nm", "-412.0")
    case_text.append("[[loads.duty_cycle]]\ntime_share = 1.0\nspeed_rpm = 15.0\ntorque_Nm = -300.0")
    case = load_case(case_text.write(tmp_path))
    assert case.loads.torque_Nm == -412.0 and case.loads.disc_torque_Nmm < 0
    assert case.loads.duty_cycle[0].torque_Nm == -300.0


def test_pin_models_of_the_case_format(case_text, tmp_path):
    for name in ("hertz", "rigid", "palmgren"):
        case_text.set("pins", "model", f'"{name}"')
        assert load_case(case_text.write(tmp_path)).pins.model == name
    case_text.set("pins", "model", '"linear"')
    expect_error(tmp_path, case_text, "pins.linear_stiffness_N_per_mm", "required when pins.model = 'linear'")
    case_text.set("pins", "linear_stiffness_N_per_mm", "1e4")
    assert load_case(case_text.write(tmp_path)).pins.linear_stiffness_N_per_mm == 1e4
    case_text.set("pins", "model", '"hertz_palmgren"')
    expect_error(tmp_path, case_text, "pins.model", "palmgren")


def test_duty_cycle_torque_below_a_milli_newton_metre(case_text, tmp_path):
    case_text.append("[[loads.duty_cycle]]\ntime_share = 1.0\nspeed_rpm = 15.0\ntorque_Nm = 1e-300")
    expect_error(tmp_path, case_text, "loads.duty_cycle[0].torque_Nm", "must be 0 or at least 0.001 N·m")


def test_bad_element_order_lists_the_orders(case_text, tmp_path):
    case_text.set("analysis", "element_order", "0")
    expect_error(tmp_path, case_text, "analysis.element_order", "must be 1 (P1) or 2 (P2), got 0")


# --------------------------------------------------------------------------------------------
# model names come from the registry at validation time
# --------------------------------------------------------------------------------------------


def test_a_model_registered_at_run_time_is_accepted(case_text, tmp_path, registries):
    class SoftBearing:
        name = "soft_test_bearing"

    registry.register_bearing_model(SoftBearing)
    case_text.set("crank_bearing", "model", '"soft_test_bearing"')
    assert load_case(case_text.write(tmp_path)).crank_bearing.model == "soft_test_bearing"


# --------------------------------------------------------------------------------------------
# mesh size: node estimate before meshing
# --------------------------------------------------------------------------------------------


def test_mesh_estimate_uses_the_mesher_size_field_constants():
    from rvfem import mesh

    assert case_module._MESH_SIZE_GROWTH == mesh.SIZE_GROWTH
    assert case_module._MESH_BAND_FACTOR == mesh.BAND_FACTOR
    assert case_module._MESH_HOLE_SIZE_FACTOR == mesh.HOLE_SIZE_FACTOR


def test_mesh_estimate_scales_with_the_sizes():
    case = load_case(CASES_DIR / "rv40e_fanholes.toml")
    half = case.replace(mesh=dataclasses.replace(case.mesh, **{k: getattr(case.mesh, k) / 2 for k in (
        "size_flank", "size_bore", "size_interior", "size_hole")}))
    a, b = estimated_mesh_nodes(case), estimated_mesh_nodes(half)
    assert b["mesh.size_interior"] == pytest.approx(4 * a["mesh.size_interior"], rel=1e-12)  # area/h²
    for key in ("mesh.size_flank", "mesh.size_bore", "mesh.size_hole"):                    # length/h
        assert b[key] == pytest.approx(2 * a[key], rel=1e-12)
    # nodes per area of an equilateral triangulation: 2/(√3 h²); the interior term is exactly that
    area = (math.pi * (64.0 - 3.0) ** 2 - math.pi * 12.0 ** 2 - 3 * math.pi * 18.0 ** 2)
    assert a["mesh.size_interior"] == pytest.approx(2 / math.sqrt(3) * area / 2.5 ** 2, rel=1e-12)


def test_too_fine_a_mesh_is_refused_before_meshing(case_text, tmp_path):
    case_text.append("[mesh]\nsize_interior = 0.05")   # 2/√3·7200 mm²/(0.05 mm)² ≈ 3.3 million
    message = expect_error(tmp_path, case_text, "mesh.size_interior", "too fine a mesh", "nodes estimated")
    assert "2e+06" in message


# --------------------------------------------------------------------------------------------
# loads.torque_split
# --------------------------------------------------------------------------------------------


def test_torque_split_defaults_to_stiffness(case_text, tmp_path):
    assert load_case(case_text.write(tmp_path)).loads.torque_split == "stiffness"


def test_stiffness_split_needs_one_or_two_discs(case_text, tmp_path):
    case_text.set("loads", "discs", "3")
    expect_error(tmp_path, case_text, "loads.torque_split", "1 or 2 discs", "use 'equal'")
    case_text.set("loads", "torque_split", '"equal"')
    case_text.drop_table("crank_support")      # its eccentric positions are those of two discs
    assert load_case(case_text.write(tmp_path)).loads.discs == 3


def test_torque_split_choices(case_text, tmp_path):
    case_text.set("loads", "torque_split", '"equl"')
    expect_error(tmp_path, case_text, "loads.torque_split", "must be one of", "did you mean 'equal'")


# --------------------------------------------------------------------------------------------
# [crank_support]
# --------------------------------------------------------------------------------------------

BEAM = "[crank_support]\nspan = 60.0\neccentric_positions = [20.0, 40.0]\njournal_diameter = 25.0\n"


def test_crank_support_beam_loads(case_text, tmp_path):
    case_text.drop_table("crank_support")    # the shipped case has one
    case_text.append(BEAM + "support_stiffness_N_per_mm = [3e5, 4e5]\ncarrier_stiffness_N_per_mm = 1e6")
    s = load_case(case_text.write(tmp_path)).crank_support
    assert (s.span, s.eccentric_positions, s.journal_diameter, s.youngs_modulus, s.shear) == (
        60.0, (20.0, 40.0), 25.0, 206000.0, True)
    assert s.support_stiffness_pair == (3e5, 4e5)
    assert s.carrier_stiffness_pair == (1e6, 1e6)


def test_crank_support_is_optional_and_pairs_default_to_none(case_text, tmp_path):
    case_text.drop_table("crank_support")    # the shipped case has one
    assert load_case(case_text.write(tmp_path)).crank_support is None
    s = CrankSupport(span=60.0, eccentric_positions=(20.0, 40.0), journal_diameter=25.0)
    assert s.support_stiffness_pair == (None, None) and s.carrier_stiffness_pair == (None, None)


def test_crank_support_influence_matrix_loads(case_text, tmp_path):
    case_text.drop_table("crank_support")    # the shipped case has one
    case_text.append("[crank_support]\ninfluence_mm_per_N = [[2e-6, 1e-6], [1e-6, 2e-6]]")
    s = load_case(case_text.write(tmp_path)).crank_support
    assert s.influence_mm_per_N == ((2e-6, 1e-6), (1e-6, 2e-6)) and s.span is None


@pytest.mark.parametrize("extra, key, fragment", [
    ("", "crank_support.span", "is missing"),
    ("span = 60.0\njournal_diameter = 25.0", "crank_support.eccentric_positions", "is missing"),
    ("span = 60.0\neccentric_positions = [20.0]\njournal_diameter = 25.0", "crank_support.eccentric_positions",
     "must list 2 positions"),
    ("span = 60.0\neccentric_positions = [20.0, 60.0]\njournal_diameter = 25.0",
     "crank_support.eccentric_positions[1]", "strictly between the supports"),
    ("span = 60.0\neccentric_positions = [20.0, 20.0]\njournal_diameter = 25.0",
     "crank_support.eccentric_positions", "must be distinct"),
    ("span = 60.0\neccentric_positions = [20.0, 40.0]", "crank_support.journal_diameter", "exactly one"),
    ("span = 60.0\neccentric_positions = [20.0, 40.0]\njournal_diameter = 25.0\nbending_stiffness_Nmm2 = 4e9",
     "crank_support.journal_diameter", "exactly one"),
    ("span = 60.0\neccentric_positions = [20.0, 40.0]\nbending_stiffness_Nmm2 = 4e9",
     "crank_support.shear", "needs 'journal_diameter'"),
    ("span = 60.0\neccentric_positions = [20.0, 40.0]\njournal_diameter = 25.0\n"
     "support_stiffness_N_per_mm = [1e5, 1e5, 1e5]", "crank_support.support_stiffness_N_per_mm", "at most 2 values"),
    ("span = 60.0\neccentric_positions = [20.0, 40.0]\njournal_diameter = 25.0\n"
     "carrier_stiffness_N_per_mm = [1e5]", "crank_support.carrier_stiffness_N_per_mm", "list of 2"),
    ("span = 60.0\neccentric_positions = [20.0, 40.0]\njournal_diameter = 25.0\n"
     "support_stiffness_N_per_mm = 0.0", "crank_support.support_stiffness_N_per_mm", "must be positive"),
    ("span = 60.0\neccentric_positions = [20.0, 40.0]\njournal_diameter = 25.0\nshear = 1",
     "crank_support.shear", "must be true or false"),
    ("influence_mm_per_N = [[2e-6, 1e-6], [0.0, 2e-6]]", "crank_support.influence_mm_per_N", "must be symmetric"),
    ("influence_mm_per_N = [[1e-6, 2e-6], [2e-6, 1e-6]]", "crank_support.influence_mm_per_N",
     "must be positive definite"),
    ("influence_mm_per_N = [[1e-6]]", "crank_support.influence_mm_per_N", "must be a 2×2 matrix"),
    ("influence_mm_per_N = [1e-6, 1e-6]", "crank_support.influence_mm_per_N", "list of lists"),
    ("influence_mm_per_N = [[2e-6, 1e-6], [1e-6, 2e-6]]\nspan = 60.0", "crank_support.span", "exclude each other"),
    ("influence_mm_per_N = [[2e-6, 1e-6], [1e-6, 2e-6]]\nshear = false", "crank_support.shear",
     "only applies to the beam model"),
    ("spn = 60.0", "crank_support.spn", "did you mean 'crank_support.span'"),
])
def test_crank_support_errors(case_text, tmp_path, extra, key, fragment):
    case_text.drop_table("crank_support")    # the shipped case has one
    case_text.append("[crank_support]\n" + extra)
    expect_error(tmp_path, case_text, key, fragment)


# --------------------------------------------------------------------------------------------
# cases built in code are validated like files
# --------------------------------------------------------------------------------------------


def test_case_built_in_code_is_validated_and_normalized():
    case = load_case(CASES_DIR / "rv40e.toml")
    fields = {f.name: getattr(case, f.name) for f in dataclasses.fields(case) if f.name not in ("source",)}
    with pytest.raises(CaseError, match=r"^<code>: 'pins.radius' must be finite"):
        Case(**{**fields, "pins": dataclasses.replace(case.pins, radius=math.nan)})
    with pytest.raises(CaseError, match=r"^<code>: 'cycloid.teeth' must be an integer"):
        Case(**{**fields, "cycloid": dataclasses.replace(case.cycloid, teeth=39.0)})
    with pytest.raises(CaseError, match=r"'loads.torque_split'"):
        dataclasses.replace(case, loads=dataclasses.replace(case.loads, discs=4))
    same = Case(**{**fields, "cycloid": dataclasses.replace(case.cycloid, thickness=9, central_hole_radius=12)})
    assert same == case and isinstance(same.cycloid.thickness, float)
    assert same.digest() == case.digest()


def test_overrides_are_validated_like_the_file(tmp_path):
    path = CASES_DIR / "rv40e_fanholes.toml"
    case = load_case(path, overrides=("fan_holes.ligament=4.0", "loads.torque_split=equal"))
    assert case.fan_holes.ligament == 4.0 and case.loads.torque_split == "equal"
    assert case.overrides == ("fan_holes.ligament=4.0", "loads.torque_split=equal")
    with pytest.raises(CaseError, match="did you mean 'fan_holes.ligament'"):
        load_case(path, overrides=("fan_holes.ligamnt=4.0",))
    with pytest.raises(CaseError, match="'fan_holes.ligament' must be finite"):
        load_case(path, overrides=("fan_holes.ligament=nan",))


def test_p2_mesh_estimate_counts_edge_nodes(case_text, tmp_path):
    p1 = load_case(case_text.write(tmp_path))
    p2 = load_case(case_text.set("analysis", "element_order", "2").write(tmp_path))
    assert estimated_mesh_nodes(p2)["total"] == pytest.approx(4 * estimated_mesh_nodes(p1)["total"], rel=1e-12)


def test_two_tooth_difference_case_is_valid_and_outside_the_handbook(case_text, tmp_path):
    from rvfem.evaluate.rigid import handbook_applicable

    case_text.set("cycloid", "teeth", "38")
    case = load_case(case_text.write(tmp_path))
    assert case.pins.count - case.cycloid.teeth == 2
    ok, reason = handbook_applicable(case)
    assert not ok and "not defined for Zp − Zc ≠ 1" in reason


def test_iso281_factors_and_friction_accept_their_documented_ranges(case_text, tmp_path):
    """b_m 1.0–1.3 (ISO 281:2007), λ·ν 0.4–1, friction up to 0.3: the ends are valid."""
    for b_m, lambda_nu, friction in ((1.0, 0.4, 0.0), (1.3, 1.0, 0.3)):
        case_text.set("crank_bearing", "b_m", repr(b_m)).set("crank_bearing", "lambda_nu", repr(lambda_nu))
        case = load_case(case_text.set("analysis", "friction", repr(friction)).write(tmp_path))
        assert (case.crank_bearing.b_m, case.crank_bearing.lambda_nu, case.analysis.friction) == (b_m, lambda_nu,
                                                                                                  friction)
    assert case_module.MAX_FRICTION == 0.3 and case_module.LAMBDA_NU_RANGE == (0.4, 1.0)


@pytest.mark.parametrize("key, value, limit", [("size_bore", "45", "9.42 mm"), ("size_bore", "9.5", "9.42 mm"),
                                               ("size_flank", "5", "1.6 mm"), ("size_flank", "1.7", "1.6 mm")])
def test_boundary_sizes_too_coarse_for_the_contact_footprints(tmp_path, key, value, limit):
    """mesh.size_bore = 45 used to end in an internal error of the contact interface ("footprint
    half-width must be less than half the loop length"); now the case is refused, naming the key
    and the largest size whose footprint stays local (a quarter of the bore, one flank)."""
    from conftest import CaseText

    text = CaseText.shipped("rv40e_fanholes").set("mesh", key, value)
    message = expect_error(tmp_path, text, f"mesh.{key}", "too coarse", f"use at most {limit}")
    assert "±1.5 element sizes" in message


def test_largest_allowed_boundary_sizes_follow_the_geometry(tmp_path):
    from conftest import CaseText

    case_text = CaseText.shipped("rv40e_fanholes")

    case = load_case(case_text.write(tmp_path))
    limits = case_module.max_element_sizes(case)
    root = 64.0 - 1.3 - 3.0                                              # Rp − e − r_rp, RV-40E
    assert limits["mesh.size_bore"] == pytest.approx(math.pi * 18.0 / 6.0, rel=1e-12)
    assert limits["mesh.size_flank"] == pytest.approx(math.pi * root / (3.0 * 39), rel=1e-12)
    # the limits themselves are accepted
    case_text.set("mesh", "size_bore", "9.42").set("mesh", "size_flank", "1.6")
    assert load_case(case_text.write(tmp_path)).mesh.size_bore == 9.42


# --------------------------------------------------------------------------------------------
# Said, or refused: a key the case gives but does not use, values that contradict each other
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("kind, key, value, uses", [
    ("straight", "crown_radius", "300.0", "arc"),          # a forgotten kind = "arc"
    ("logarithmic", "crown_radius", "300.0", "arc"),
    ("arc", "design_load_N", "5000.0", "logarithmic"),
    ("straight", "modification_length", "2.0", "combined"),
    ("arc", "modification_drop", "0.01", "combined"),
])
def test_a_profile_key_of_another_kind_is_refused(case_text, tmp_path, kind, key, value, uses):
    case_text.set("crank_bearing", "profile.kind", f'"{kind}"').set("crank_bearing", f"profile.{key}", value)
    expect_error(tmp_path, case_text, f"crank_bearing.profile.{key}",
                 f"kind = '{kind}' does not use it", f"set crank_bearing.profile.kind = '{uses}'")


@pytest.mark.parametrize("kind", ["straight", "arc", "logarithmic", "combined"])
@pytest.mark.parametrize("keys, bad, words", [
    ({"corner_radius": "-0.1"}, "corner_radius", "must be non-negative"),
    ({"corner_radius": "0.2", "chamfer_length": "0.3"}, "chamfer_length", "must not exceed"),
    ({"corner_radius": "4.5"}, "corner_radius", "shorter than half the roller length (4.5 mm)"),
    ({"corner_radius": "6.0", "chamfer_length": "5.0"}, "chamfer_length", "shorter than half the roller length"),
    ({"chamfer_length": "0.0"}, "chamfer_length", "crank_bearing.profile.chamfer_length"),
])
def test_a_corner_that_does_not_fit_the_roller_is_refused(case_text, tmp_path, kind, keys, bad, words):
    # every kind has the corner: a negative radius, a chamfer longer than the arc can reach, or a
    # corner of half the roller (the effective length L_we = 9 mm of the RV-40E roller)
    case_text.set("crank_bearing", "profile.kind", f'"{kind}"')
    for key, value in keys.items():
        case_text.set("crank_bearing", f"profile.{key}", value)
    expect_error(tmp_path, case_text, f"crank_bearing.profile.{bad}", words)


def test_profile_keys_at_their_defaults_are_what_a_whole_case_holds(case_text, tmp_path):
    """case.json and best.toml hold every key: the shape keys of the other kinds at their defaults
    are taken, and the case round-trips."""
    for key, value in (("kind", '"combined"'), ("crown_radius", "500.0"), ("design_load_N", "2000.0"),
                       ("modification_length", "1.0"), ("modification_drop", "0.004")):
        case_text.set("crank_bearing", f"profile.{key}", value)
    case = load_case(case_text.write(tmp_path))
    assert case.crank_bearing.profile.kind == "combined" and case.crank_bearing.profile.modification_length == 1.0
    assert case_from_dict(case_to_dict(case), source="x.toml") == case


def test_a_fatigue_limit_above_the_yield_strength_is_refused(case_text, tmp_path):
    """yield_strength = 500 MPa against the default fatigue limit 960 MPa (the issue's case)."""
    case_text.set("material", "yield_strength", "500.0")
    expect_error(tmp_path, case_text, "material.yield_strength", "500 MPa is below the fatigue limit",
                 "'material.fatigue_limit' = 960 MPa", "not physical")
    case_text.set("material", "fatigue_limit", "400.0")          # both given, consistent: taken
    assert load_case(case_text.write(tmp_path)).material.fatigue_limit == 400.0


def test_iso_vg_with_nu40_and_nu100_is_refused(case_text, tmp_path):
    case_text.lines += ["", "[lubricant]", "iso_vg = 68", "nu40 = 100.0", "nu100 = 11.0"]
    expect_error(tmp_path, case_text, "lubricant.iso_vg", "are both given", "not both")


def test_the_viscosity_is_the_grade_or_the_two_points(case_text, tmp_path):
    """Without a viscosity the grade is ISO VG 68; with nu40/nu100 the case has no grade, and
    writes none (case.json reads back)."""
    assert load_case(case_text.write(tmp_path)).lubricant.iso_vg == 68
    case_text.lines += ["", "[lubricant]", "nu40 = 100.0", "nu100 = 11.0"]
    case = load_case(case_text.write(tmp_path))
    assert (case.lubricant.iso_vg, case.lubricant.nu40, case.lubricant.nu100) == (None, 100.0, 11.0)
    assert "iso_vg" not in case_to_dict(case)["lubricant"]
    assert case_from_dict(case_to_dict(case), source="x.toml") == case
