"""Valid cases that stress the contact solve: they run through the command line, or fail with one
line that names the crank angle and the contacts (exit code 2)."""

from __future__ import annotations

import pytest

from rvfem import cli

from conftest import CASES_DIR

COARSE = ["mesh.size_flank=0.6", "mesh.size_bore=0.6", "mesh.size_interior=4.0", "analysis.angle_step_deg=30",
          'loads.torque_split="equal"']
STIFF_BEARING = ['pins.model="hertz"', 'crank_bearing.model="rigid_bore"',
                 "crank_bearing.rigid_bore_stiffness_N_per_mm=7e8"]


def _run(tmp_path, sets, capsys):
    argv = ["run", str(CASES_DIR / "rv40e.toml"), "-o", str(tmp_path / "out"), "--no-images",
            "--cache-dir", str(tmp_path / "meshes")]
    for s in sets:
        argv += ["--set", s]
    code = cli.main(argv)
    return code, capsys.readouterr()


@pytest.mark.slow
@pytest.mark.parametrize("modification", [
    ["cycloid.modification.equidistant=0.005"],
    ["cycloid.modification.shift=-0.003"],
    ["cycloid.modification.equidistant=0.005", "cycloid.modification.shift=-0.003"],
])
def test_compliant_pins_with_a_modified_profile_and_a_stiff_bearing_settle(tmp_path, capsys, modification):
    """The cold start gives every spring group its own secant stiffness (a compliant pin is ~10³×
    softer than a 7·10⁸ N/mm bearing), so the first Newton steps do not oscillate."""
    code, out = _run(tmp_path, COARSE + STIFF_BEARING + modification, capsys)
    assert code == 0, out.err
    assert (tmp_path / "out" / "summary.json").is_file()


def test_an_active_set_that_does_not_settle_names_the_angle_and_the_contacts(tmp_path, capsys):
    code, out = _run(tmp_path, COARSE + ["analysis.max_active_set_iterations=1"], capsys)
    assert code == 2
    errors = [line for line in out.err.splitlines() if "error:" in line]   # the other lines are progress
    assert len(errors) == 1, out.err
    assert "did not settle at crank angle" in errors[0] and "within 1 iterations" in errors[0]
    assert "roller" in errors[0]                       # the springs that do not settle are named
    assert not (tmp_path / "out").exists()
