"""A subcommand from outside rvfem (tests/app/plugins/disc_mass_command.py, one module and one
registration line): ``rvfem --help`` lists it, it runs, bad input gets rvfem's one-line errors."""

from __future__ import annotations

import contextlib
import io
import math

import pytest
from conftest import CASES_DIR

from rvfem.app import cli
from rvfem.app.cli import register_subcommand


def _main(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main(argv)
    return code, out.getvalue(), err.getvalue()


def test_a_subcommand_from_outside_is_listed_and_runs(registries):
    from plugins.disc_mass_command import DISC_MASS

    register_subcommand(DISC_MASS)                         # the one registration line
    code, out, _ = _main(["--help"])
    assert code == 0 and "disc-mass" in out
    code, out, _ = _main(["disc-mass", str(CASES_DIR / "rv40e_solid.toml")])
    assert code == 0
    mass = float(out.split("disc mass ")[1].split(" kg")[0])
    # a solid RV-40E disc: between an annulus of the root and of the tip circle (ρ = 7850 kg/m³)
    from rvfem.case.definition import load_case
    case = load_case(CASES_DIR / "rv40e_solid.toml")
    assert 0.1 < mass < case.material.density_kg_m3 * 1e-9 * case.cycloid.thickness * math.pi * (
        case.pins.circle_radius ** 2)
    code, _, err = _main(["disc-mass", "no-such-case.toml"])
    assert code == 2 and err.startswith("rvfem disc-mass: error:") and len(err.strip().splitlines()) == 1


def test_a_taken_name_is_refused_and_the_command_is_gone_after_the_test(registries):
    from plugins.disc_mass_command import DISC_MASS

    with pytest.raises(ValueError, match="exists already"):
        register_subcommand(type(DISC_MASS)("run", "another run", DISC_MASS.add_arguments, DISC_MASS.run))


def test_the_registered_subcommand_did_not_stay():
    assert all(s.name != "disc-mass" for s in cli.all_subcommands())
