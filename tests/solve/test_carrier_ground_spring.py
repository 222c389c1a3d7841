"""A stage component written outside the package (tests/solve/plugins/carrier_ground_spring.py, one
module plus the one registration line of :func:`_register`): a torsional spring k_t between the
carrier and the ground, with its own case table.

* the case reader takes its table like a built-in one (defaults, bounds, ``--set``), refuses an
  unknown key in it, and forgets the table once the registry is restored;
* ``rvfem hysteresis``'s library part (:func:`rvfem.app.hysteresis.accuracy_study`) on the case with
  the table against the same case without it: the spring is in series with the stage in the
  output's load path, so each side's rigidity follows 1/K_new = 1/K_old + 1/k_t and the lost
  motion grows by 2·T_lm/k_t (T_lm = 3 % of the torque). The spring changes no contact solve (the
  whole output torque passes through it), so these hold to round-off: checked at 1e-9 relative, not
  at the solver's tolerance;
* the compliance shares gain the spring's share, (1 − 1/STIFFEN)·Δφ_k/a_new with Δφ_k = 0.97·T/k_t,
  every other share is scaled by a_old/a_new (the same rotation goes when that part is stiffened),
  so the shares still sum as the linear case requires: 1 − Σ = (1 − Σ_old)·a_old/a_new +
  Δφ_k/(STIFFEN·a_new) (a series compliance adds no interaction).
"""

from __future__ import annotations

import csv

import pytest
from conftest import CaseText, coarse_case, saved_registries
from plugins.carrier_ground_spring import CarrierGroundSpring, CarrierGroundSpringTable

from rvfem.app.hysteresis import accuracy_study
from rvfem.case.definition import case_from_dict, case_to_dict, load_case
from rvfem.errors import CaseError
from rvfem.evaluate.accuracy import ARCMIN_PER_RAD
from rvfem.solve.stage_parts import BUILTIN_COMPONENTS, STIFFEN, component_names, register_stage_component

T_R = 412.0
K_T = 1.0e9
"""k_t, N·mm/rad: 0.29 of the coarse linear stage's own torsional stiffness (about 3.4e9 N·mm/rad), so
the spring takes about a fifth of the rotation."""

LINEAR = dict(pins={"model": "linear", "linear_stiffness_N_per_mm": 2e5},
              crank_bearing={"stiffness_law": "linear", "linear_stiffness_N_per_mm": 3e5})
NAME = CarrierGroundSpring.name


def _register():
    return register_stage_component(CarrierGroundSpring())


@pytest.fixture
def spring(registries):
    """The carrier–ground spring registered for one test (the registries restored after it)."""
    return _register()


def _rotation_arcmin(torque_Nm: float) -> float:
    """The spring's rotation under ``torque_Nm`` (N·m), arcmin."""
    return torque_Nm * 1e3 / K_T * ARCMIN_PER_RAD


# ------------------------------------------------------------------------------------------------
# Its case table
# ------------------------------------------------------------------------------------------------


def test_the_case_reader_takes_the_components_table(spring, tmp_path):
    path = CaseText.shipped("rv40e").append(f"[carrier_ground_spring]\nstiffness_Nmm_per_rad = {K_T:g}").write(tmp_path)
    case = load_case(path)
    assert case.component_table("carrier_ground_spring") == CarrierGroundSpringTable(K_T)
    assert case_from_dict(case_to_dict(case)) == case                      # it round-trips as a table
    assert load_case(path, ["carrier_ground_spring.stiffness_Nmm_per_rad=2e9"]).component_table(
        "carrier_ground_spring").stiffness_Nmm_per_rad == 2e9
    assert load_case(CaseText.shipped("rv40e").write(tmp_path, "plain.toml")).component_table("carrier_ground_spring") is None
    plain = load_case(CaseText.shipped("rv40e").write(tmp_path, "plain.toml"))
    assert plain.replace(carrier_ground_spring=CarrierGroundSpringTable(K_T)) == case.replace(name=plain.name)


@pytest.mark.parametrize("line, message", [
    ("stifness_Nmm_per_rad = 1e9", r"'carrier_ground_spring.stifness_Nmm_per_rad' is not a known key \(did you mean "
                                   r"'carrier_ground_spring.stiffness_Nmm_per_rad'\?\)"),
    ("", r"'carrier_ground_spring.stiffness_Nmm_per_rad' is missing \(required\)"),
    ("stiffness_Nmm_per_rad = 0.0", r"'carrier_ground_spring.stiffness_Nmm_per_rad' must be positive"),
])
def test_the_components_table_is_checked_like_any_other(spring, tmp_path, line, message):
    path = CaseText.shipped("rv40e").append(f"[carrier_ground_spring]\n{line}").write(tmp_path)
    with pytest.raises(CaseError, match=message):
        load_case(path)


def test_without_the_component_its_table_is_an_unknown_key(tmp_path):
    with saved_registries():
        _register()
    # the registries restored: the table is no longer part of the case format
    path = CaseText.shipped("rv40e").append(f"[carrier_ground_spring]\nstiffness_Nmm_per_rad = {K_T:g}").write(tmp_path)
    with pytest.raises(CaseError, match="'carrier_ground_spring' is not a known key"):
        load_case(path)
    assert NAME not in component_names()


# ------------------------------------------------------------------------------------------------
# Its part of the stage: rigidity, lost motion and compliance shares
# ------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def studies(tmp_path_factory):
    """``rvfem hysteresis``'s summary of the coarse linear RV-40E stage at crank angle 0 without and
    with the spring (friction 0, 8 load steps, with the compliance shares)."""
    cache = tmp_path_factory.mktemp("meshes")
    plain = coarse_case("rv40e", **LINEAR)
    out = {}
    with saved_registries():
        _register()
        for key, case in (("plain", plain), ("spring", plain.replace(carrier_ground_spring=CarrierGroundSpringTable(K_T)))):
            folder = tmp_path_factory.mktemp(key) / "accuracy"
            out[key] = accuracy_study(case, folder, angles_deg=(0.0,), steps=8, friction=0.0, cache_dir=cache)
            out[f"{key} folder"] = folder
    return out


def _side_rigidities(folder) -> tuple[float, float]:
    """The + and − sides' b/a (N·m/arcmin) of the loop in ``folder``/hysteresis.csv: the loading
    branches' rotation between 3 % and 100 % of the torque."""
    with open(folder / "hysteresis.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    phi = {(r["branch"], float(r["torque_Nm"])): float(r["rotation_arcmin"]) for r in rows}
    lm = 0.03 * T_R
    plus = (T_R - lm) / (phi["loading +", T_R] - phi["loading +", lm])
    minus = (T_R - lm) / (phi["loading -", -lm] - phi["loading -", -T_R])
    return plus, minus


def test_the_spring_changes_the_rigidity_and_lost_motion_as_springs_in_series_do(studies):
    plain, spring = studies["plain"], studies["spring"]
    k_t = T_R / _rotation_arcmin(T_R)                          # k_t in N·m/arcmin
    # each side of the loop, and the reported rigidity (their mean)
    sides = []
    for old, new in zip(_side_rigidities(studies["plain folder"]), _side_rigidities(studies["spring folder"])):
        assert 1.0 / new == pytest.approx(1.0 / old + 1.0 / k_t, rel=1e-9)
        sides.append(1.0 / (1.0 / old + 1.0 / k_t))
    assert plain["torsional_rigidity_Nm_per_arcmin"] == pytest.approx(
        0.5 * sum(_side_rigidities(studies["plain folder"])), rel=1e-12)
    assert spring["torsional_rigidity_Nm_per_arcmin"] == pytest.approx(0.5 * sum(sides), rel=1e-9)
    # the mean of the sides' series combinations is the series combination of their mean to second
    # order in the sides' difference (δ = (K+ − K−)/(K+ + K−) ≈ 1e-4 here, at one crank angle)
    plus, minus = _side_rigidities(studies["plain folder"])
    delta = (plus - minus) / (plus + minus)
    assert abs(delta) < 1e-3
    expected = 1.0 / (1.0 / plain["torsional_rigidity_Nm_per_arcmin"] + 1.0 / k_t)
    assert spring["torsional_rigidity_Nm_per_arcmin"] == pytest.approx(expected, rel=2 * delta ** 2 + 1e-9)
    assert spring["torsional_rigidity_Nm_per_arcmin"] < 0.9 * plain["torsional_rigidity_Nm_per_arcmin"]
    lm = 0.03 * T_R
    assert spring["lost_motion_arcmin"] == pytest.approx(plain["lost_motion_arcmin"] + 2.0 * _rotation_arcmin(lm),
                                                         rel=1e-9)


def test_the_stage_and_the_report_name_the_spring(studies):
    assert NAME in studies["spring"]["stage"] and NAME not in studies["plain"]["stage"]
    assert "and a torsional spring between the carrier and the ground. It leaves out" in studies["spring"]["left_out"]


def test_the_compliance_shares_gain_the_springs_share_and_still_sum_as_in_series(studies):
    old, new = studies["plain"]["compliance_shares"], studies["spring"]["compliance_shares"]
    builtin = [c.name for c in BUILTIN_COMPONENTS]
    assert list(old["shares"]) == builtin                      # the spring is left out where the case has none
    assert list(new["shares"]) == builtin + [NAME]             # after the built-in parts, in registration order
    a_old, a_new = old["rotation_arcmin"], new["rotation_arcmin"]
    d = _rotation_arcmin(0.97 * T_R)                            # the spring's rotation between 3 % and 100 %
    assert a_new == pytest.approx(a_old + d, rel=1e-9)
    assert new["shares"][NAME] == pytest.approx((1.0 - 1.0 / STIFFEN) * d / a_new, rel=1e-9)
    for c in builtin:   # stiffening a part of the stage removes the same rotation with the spring there
        assert new["shares"][c] * a_new == pytest.approx(old["shares"][c] * a_old, rel=1e-9), c
    assert 1.0 - new["total"] == pytest.approx((1.0 - old["total"]) * a_old / a_new + d / (STIFFEN * a_new),
                                               rel=1e-6, abs=1e-12)
    assert new["total"] == pytest.approx(1.0, abs=0.05)        # the linear case: the shares of series parts
