"""The unit conversions defined once (:mod:`rvfem.units`): their values against the definitions of
the units, and no second spelling of the N·m → N·mm or rad → arcmin conversion in the package."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from conftest import ROOT

from rvfem.units import ARCMIN_PER_RAD, ARCSEC_PER_RAD, arcmin_from_rad, nm_from_nmm, nmm_from_nm


def test_the_conversions_against_the_definitions_of_the_units():
    assert nmm_from_nm(412.0) == 412000.0                     # 1 m = 1000 mm
    assert nm_from_nmm(nmm_from_nm(0.123)) == pytest.approx(0.123, rel=1e-15)
    assert arcmin_from_rad(2.0 * math.pi) == pytest.approx(360.0 * 60.0, rel=1e-15)      # a full turn
    assert arcmin_from_rad(math.radians(1.0 / 60.0)) == pytest.approx(1.0, rel=1e-14)
    assert ARCSEC_PER_RAD == pytest.approx(648000.0 / math.pi, rel=1e-15)
    np.testing.assert_allclose(arcmin_from_rad(np.array([math.pi, -math.pi / 2])), [10800.0, -5400.0], rtol=1e-15)
    assert ARCMIN_PER_RAD == pytest.approx(10800.0 / math.pi, rel=1e-15)


SECOND_SPELLINGS = {
    "torque N·m → N·mm": re.compile(r"torque_Nm\)? \* 1000|torque_Nmm[\]'\"]*\)* / 1000|\* 1e3 \* torque"),
    "rad → arcmin": re.compile(r"180(\.0)? \* 60|degrees\([^()]*(\([^()]*\))?[^()]*\) \* 60|\* 60(\.0)? / (math|np)\.pi"),
}


@pytest.mark.parametrize("what", SECOND_SPELLINGS)
def test_no_module_converts_a_torque_or_an_angle_by_hand(what):
    found = []
    for path in sorted((ROOT / "rvfem").rglob("*.py")):
        if path.name == "units.py":
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            code = line.split("#")[0]
            if SECOND_SPELLINGS[what].search(code) and not code.lstrip().startswith(('"', "'")):
                found.append(f"{path.relative_to(ROOT)}:{n}")
    assert not found, f"use rvfem.units for the {what} conversion: " + ", ".join(found)
