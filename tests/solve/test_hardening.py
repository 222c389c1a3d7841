"""Valid cases that stress the contact solve: they run through the command line, or fail with one
line that names the crank angle and the contacts (exit code 2)."""

from __future__ import annotations

import re

import pytest
from conftest import CASES_DIR

from rvfem.app import cli

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
    # the advice is one that can work: more iterations do not settle a cycling set (friction 0.85
    # on the fan-hole case fails at 50 and at 1000 iterations alike)
    assert "analysis.friction" in errors[0] and "raises the bound" not in errors[0]
    assert not (tmp_path / "out").exists()


# --------------------------------------------------------------------------------------------
# Valid-looking cases that used to pass `check` and then fail in `mesh`/`run`
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("sets, fragment, key", [
    (["fan_holes.inner_radius=10"], "hole 1 overlaps the central hole by 2.000 mm", "'fan_holes.inner_radius'"),
    (["cranks.circle_radius=44"], "cuts into the teeth", "'cranks.circle_radius'"),
    (["crank_bearing.bore_radius=24"], "bore 1 cuts into the teeth", "'crank_bearing.bore_radius'"),
    (["fan_holes.ligament=0.5"], "is only 0.500 mm thick", "'fan_holes.ligament'"),
    (["fan_holes.inner_radius=100", "fan_holes.outer_radius=120"], "cut the teeth", "'fan_holes.outer_radius'"),
    (["mesh.size_bore=45"], "too coarse for the bores", "'mesh.size_bore'"),
])
def test_check_rejects_what_meshing_would_reject(capsys, sets, fragment, key):
    """`rvfem check` runs the geometry checks that meshing runs before Gmsh: one line, exit 2, the
    features numbered from 1 and the key to change."""
    argv = ["check", str(CASES_DIR / "rv40e_fanholes.toml")]
    for s in sets:
        argv += ["--set", s]
    assert cli.main(argv) == 2
    out = capsys.readouterr()
    assert out.out == "" and out.err.count("\n") == 1, out.err
    assert fragment in out.err and key in out.err, out.err
    assert not re.search(r"\b(bore|hole)_\d", out.err)          # no 0-based feature names


def test_check_of_a_shipped_case_reports_the_thinnest_wall(capsys):
    assert cli.main(["check", str(CASES_DIR / "rv40e_fanholes.toml")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("OK: case 'rv40e_fanholes'") and out.count("\n") == 1
    assert "thinnest wall 4.500 mm between bore 1 and hole 1" in out


def test_duty_cycle_life_of_a_zero_life_is_zero_not_a_division_by_zero(monkeypatch):
    """A rating life that underflows to 0 h (λ·ν = 1e-100 used to get there) is infinite damage: the
    FE duty-cycle life is 0 h, not a ZeroDivisionError."""
    import dataclasses
    from types import SimpleNamespace

    from rvfem.app import analysis
    from rvfem.case.definition import load_case
    from rvfem.evaluate import iso281

    case = load_case(CASES_DIR / "crv80e_duty.toml")
    monkeypatch.setattr(iso281, "crank_bearing_rating", lambda bearing: 1e-300)
    rated = case.loads.torque_Nm
    rows = tuple(r for r in case.loads.duty_cycle if r.torque_Nm in (0.0, rated))
    assert len(rows) == 2               # the rated row and the row at rest: no other torque to solve
    case = case.replace(loads=dataclasses.replace(case.loads, duty_cycle=rows))
    bearings = [SimpleNamespace(flexible=SimpleNamespace(equivalent_N=4000.0)) for _ in range(3)]
    result = analysis.duty_cycle_fe(SimpleNamespace(case=case), None, None,
                                    SimpleNamespace(bearings=bearings), linear_life_h=0.0)
    assert result.service_life_h == 0.0


def test_the_coarsest_boundary_sizes_allowed_still_build_the_contact_model(tmp_path):
    """At the largest `size_bore` and `size_flank` the case accepts, the load footprints are built
    (`size_bore = 45` used to fail there with an internal error)."""
    from rvfem.case.definition import load_case, max_element_sizes
    from rvfem.mesh import mesh_case
    from rvfem.solve import cycle

    case = load_case(CASES_DIR / "rv40e_solid.toml", ["mesh.size_interior=6.0"])
    limits = max_element_sizes(case)
    case = load_case(CASES_DIR / "rv40e_solid.toml", ["mesh.size_interior=6.0",
                                                       f"mesh.size_bore={limits['mesh.size_bore']}",
                                                       f"mesh.size_flank={limits['mesh.size_flank']}"])
    system = cycle.build_system(case, mesh_case(case, tmp_path / "meshes"))
    assert system.interface.n_columns > 0
