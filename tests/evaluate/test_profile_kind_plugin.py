"""A roller-profile kind from outside rvfem (tests/evaluate/plugins/parabolic_crown.py, one module and
one registration line): the case accepts it, the slice model draws it, and it presses like the
circular crown it approximates."""

from __future__ import annotations

import dataclasses

import pytest
from conftest import CASES_DIR

from rvfem.app import cli
from rvfem.case.definition import load_case
from rvfem.evaluate import hertz
from rvfem.evaluate.roller_slices import register_profile_kind, roller_contact


def test_a_profile_kind_from_outside_is_accepted_and_presses_like_the_arc_it_approximates(registries):
    from plugins.parabolic_crown import END_DROP_MM, NAME, parabolic_drop

    register_profile_kind(NAME, parabolic_drop)          # the one registration line
    assert cli.main(["check", str(CASES_DIR / "rv40e.toml"), "--set", f'crank_bearing.profile.kind="{NAME}"']) == 0
    case = load_case(CASES_DIR / "rv40e.toml", overrides=(f'crank_bearing.profile.kind="{NAME}"',))
    cb, mat = case.crank_bearing, case.material
    length = cb.roller_length
    e_star = hertz.composite_modulus(mat.youngs_modulus, mat.poissons_ratio)
    r_eff = 0.5 * cb.roller_diameter        # a roller on a flat: the comparison needs the same contact only
    ours = dataclasses.replace(cb.profile, kind=NAME, corner_radius=0.0)
    # the circle through the same end drop: R = (L/2)²/(2δ) + δ/2, within (δ/R)² of the parabola
    arc = dataclasses.replace(cb.profile, kind="arc", crown_radius=(0.5 * length) ** 2 / (2 * END_DROP_MM) + END_DROP_MM / 2,
                              corner_radius=0.0)
    for load in (300.0, 1500.0):
        a = roller_contact(load, length, r_eff, e_star, ours)
        b = roller_contact(load, length, r_eff, e_star, arc)
        assert a.peak_pressure_MPa == pytest.approx(b.peak_pressure_MPa, rel=2e-3)
        assert a.approach_mm == pytest.approx(b.approach_mm, rel=2e-3)


def test_a_kind_that_exists_or_keys_of_another_kind_are_refused(registries):
    from plugins.parabolic_crown import parabolic_drop

    with pytest.raises(ValueError, match="exists already"):
        register_profile_kind("arc", parabolic_drop)
    with pytest.raises(ValueError, match="crown_radius must be keys"):
        register_profile_kind("test_other", parabolic_drop, keys=("crown_radius",))
    with pytest.raises(ValueError, match="not_a_key must be keys"):
        register_profile_kind("test_other", parabolic_drop, keys=("not_a_key",))


def test_the_kind_is_gone_after_the_test():
    assert cli.main(["check", str(CASES_DIR / "rv40e.toml"), "--set", 'crank_bearing.profile.kind="test_parabolic"']) == 2
