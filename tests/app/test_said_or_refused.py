"""What a user gives is used, said or refused; never silently dropped; and the error blames the
right thing: the case name as a folder, the mesh cache as a file, the hysteresis options, the
range warnings of the loop's torque, the rigid slice model's pressure and tilt, and the output
folders of compare and hysteresis that rvfem did not write."""

from __future__ import annotations

import json
from types import SimpleNamespace

import pytest
from conftest import CASES_DIR, CaseText

from rvfem.app import cli
from rvfem.app.analysis import analyse_rigid
from rvfem.app.hysteresis import loop_option_problem, loop_warnings
from rvfem.case.definition import load_case
from rvfem.evaluate import validity
from rvfem.outputs import report
from rvfem.outputs.summary import RESULT_MARKER, mark_folder

COARSE = ("--set", "mesh.size_flank=0.6", "--set", "mesh.size_bore=0.6", "--set", "mesh.size_interior=4.0")


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0] and "internal error" not in err[0], err
    return err[0]


# --------------------------------------------------------------------------------------------
# The case name is one file-name component (rvfem check names the key)
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["", "..", "a/b", "my disc / v2"])
def test_check_refuses_a_name_that_is_not_one_component(tmp_path, capsys, name):
    path = CaseText.shipped("rv40e").set("", "name", json.dumps(name)).write(tmp_path)
    assert cli.main(["check", str(path)]) == 2
    err = _one_line_error(capsys)
    assert "'name' must be one file-name component" in err and "letters A–Z a–z, digits and . _ + -" in err


def test_an_empty_name_no_longer_takes_the_results_folder(tmp_path, capsys, monkeypatch):
    """The 0.3 behaviour: name = "" and run --overwrite without -o replaced results/ itself."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results" / "other").mkdir(parents=True)
    (tmp_path / "results" / "keep.txt").write_text("x")
    path = CaseText.shipped("rv40e").set("", "name", '""').write(tmp_path)
    assert cli.main(["run", str(path), "--overwrite", "--no-images"]) == 2
    assert "'name'" in _one_line_error(capsys)
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == ["keep.txt", "other"]


# --------------------------------------------------------------------------------------------
# The mesh cache: a file where the folder should be is one line blaming the cache
# --------------------------------------------------------------------------------------------


def test_a_mesh_cache_that_is_a_file_is_one_line(tmp_path, capsys):
    cache = tmp_path / "cache"
    cache.write_text("an ordinary file")
    case = str(CASES_DIR / "rv40e.toml")
    assert cli.main(["mesh", case, "--cache-dir", str(cache), "--force", *COARSE]) == 2
    err = _one_line_error(capsys)
    assert f"the mesh cache folder {cache} cannot be used" in err and "is a file" in err
    out = tmp_path / "out"
    assert cli.main(["run", case, "--cache-dir", str(cache), "-o", str(out), "--no-images", *COARSE]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "mesh cache folder" in err and "cannot write the results" not in err
    assert not out.exists() and cache.read_text() == "an ordinary file"


# --------------------------------------------------------------------------------------------
# rvfem hysteresis: options, output folder, the range warnings of the loop's torque
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("options, cause", [
    (["--angle", "400"], "--angle must lie in [0, 360)° (one crank revolution), got 400"),
    (["--angle", "-5"], "--angle must lie in [0, 360)°"),
    (["--angle", "360"], "--angle must lie in [0, 360)°"),
    (["--angle", "10", "--angles", "3"], "--angle and --angles exclude each other"),
    (["--angles", "0"], "--angles needs at least 1 crank angle"),
])
def test_hysteresis_angles_are_used_as_given_or_refused(tmp_path, capsys, options, cause):
    out = tmp_path / "out"
    assert cli.main(["hysteresis", str(CASES_DIR / "rv40e.toml"), "-o", str(out), *options]) == 2
    assert cause in _one_line_error(capsys)
    assert not out.exists()


def test_the_library_says_its_own_parameter_names():
    assert loop_option_problem(angles_deg=(400.0,)) == ("angles_deg", "must lie in [0, 360)° (one crank revolution), "
                                                                      "got 400")
    assert loop_option_problem(angles_deg=(10.0,), angle_count=3)[0] == "angles_deg"
    assert loop_option_problem(torque_Nm=-1.0)[0] == "torque_Nm"
    assert loop_option_problem(angles_deg=(0.0, 359.9), steps=8, friction=0.1) is None


def test_hysteresis_into_a_non_empty_folder_says_the_option(tmp_path, capsys):
    out = tmp_path / "acc"
    out.mkdir()
    mark_folder(out, "hysteresis")                 # an earlier result of rvfem hysteresis
    (out / "summary.json").write_text("{}")
    assert cli.main(["hysteresis", str(CASES_DIR / "rv40e.toml"), "-o", str(out)]) == 2
    err = _one_line_error(capsys)
    assert "exists and is not empty" in err and "--overwrite" in err and "(overwrite)" not in err
    assert "overwrite=True" not in err


def test_hysteresis_overwrite_leaves_a_folder_rvfem_did_not_write(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert cli.main(["hysteresis", str(CASES_DIR / "rv40e.toml"), "-o", str(out), "--overwrite"]) == 2
    assert "rvfem did not write it" in _one_line_error(capsys)
    assert [p.name for p in out.iterdir()] == ["notes.txt"]


def test_loop_warnings_are_those_of_rigid_and_run_at_that_torque():
    """hysteresis --torque 5000 on the RV-40E: P/C and the Hertz pressure out of range, the same
    messages rvfem rigid gives at 5000 N·m (the warnings of the handbook evaluation)."""
    case = load_case(CASES_DIR / "rv40e.toml")
    warnings = loop_warnings(case, 5000.0)
    assert [w.code for w in warnings][:1] == ["load_ratio"] and "hertz_pressure" in {w.code for w in warnings}
    reference = analyse_rigid(load_case(CASES_DIR / "rv40e.toml", overrides=("loads.torque_Nm=5000",)))
    assert [w.message for w in warnings] == [w.message for w in reference.warnings]
    assert loop_warnings(case, case.loads.torque_Nm) == ()        # the rated torque is in range


def test_hysteresis_at_5000_Nm_warns_on_screen_and_in_its_files(tmp_path, capsys):
    out = tmp_path / "acc"
    assert cli.main(["hysteresis", str(CASES_DIR / "rv40e.toml"), "-o", str(out), "--torque", "5000",
                     "--angles", "1", "--steps", "8", "--no-shares", "--cache-dir", str(tmp_path / "m"), *COARSE]) == 0
    screen = capsys.readouterr().out
    s = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert s["warnings"] and s["warnings"][0]["code"] == "load_ratio"
    for w in s["warnings"]:
        assert f"  warning: {w['message']}" in screen.splitlines()
        assert w["message"] in (out / "accuracy.md").read_text(encoding="utf-8")
    assert (out / RESULT_MARKER).read_text(encoding="utf-8").startswith("rvfem ")


# --------------------------------------------------------------------------------------------
# compare -o into a folder rvfem did not write
# --------------------------------------------------------------------------------------------


def test_compare_output_into_a_folder_rvfem_did_not_write_is_refused_first(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "compare.html").write_text("my own page")
    case = str(CASES_DIR / "rv40e.toml")
    assert cli.main(["compare", case, case, "-o", str(out)]) == 2      # before running either case
    assert "rvfem did not write it" in _one_line_error(capsys)
    assert (out / "compare.html").read_text() == "my own page"


# --------------------------------------------------------------------------------------------
# The slice model: the rigid pressure warns like the flexible one; the rigid tilt is said
# --------------------------------------------------------------------------------------------


def _depth(model: str, peak: float, bearing: int = 0) -> SimpleNamespace:
    return SimpleNamespace(roller_peak_pressure_MPa=peak, bearing=bearing, model=model, raceway="eccentric", kappa=0.7)


def test_a_rigid_slice_pressure_above_the_iso76_limit_warns_beside_the_flexible_one():
    """The issue's numbers: rigid 4377 MPa under a flexible 5010 MPa gave one warning (the
    flexible); rigid 4377 over a flexible 3900 is warned as well."""
    depth = SimpleNamespace(rigid=(_depth("rigid", 4377.0),), flexible=(_depth("flexible", 5010.0),))
    warnings = validity.roller_depth_warnings(depth)
    assert [(w.code, w.value) for w in warnings] == [("roller_pressure", 4377.0), ("roller_pressure", 5010.0)]
    assert "rigid" in warnings[0].message and "flexible" in warnings[1].message
    depth = SimpleNamespace(rigid=(_depth("rigid", 4377.0), _depth("rigid", 4100.0, 1)),
                            flexible=(_depth("flexible", 3900.0),))
    (only,) = validity.roller_depth_warnings(depth)
    assert only.value == 4377.0 and "(bearing 1, rigid, eccentric) > 4000 MPa" in only.message


def _summary_depth(rigid_tilt: float | None) -> dict:
    return {"bearings": [{"rigid": None if rigid_tilt is None else {"peak_tilt_mrad": rigid_tilt}}]}


def test_the_report_says_the_rigid_slice_models_tilt():
    assert report._rigid_tilt_words(_summary_depth(0.0)) == "untilted"
    assert report._rigid_tilt_words(_summary_depth(None)) == "untilted"
    words = report._rigid_tilt_words(_summary_depth(-4.99))     # misalignment_mrad = 5 on the case
    assert "untilted" not in words and "misalignment" in words and "4.99 mrad" in words


# --------------------------------------------------------------------------------------------
# optimise: only into a folder that is new, empty or its own
# --------------------------------------------------------------------------------------------


def test_an_optimisation_into_a_folder_rvfem_did_not_write_is_refused(tmp_path):
    pytest.importorskip("optuna")
    from rvfem.app.optimise import run_optimisation
    from rvfem.errors import OutputError

    problem = tmp_path / "p.toml"
    problem.write_text('name = "p"\nproblem = "analytic"\ntrials = 2\n\n[[parameter]]\nkey = "x"\nlow = -1.0\n'
                       'high = 1.0\n\n[[parameter]]\nkey = "y"\nlow = -1.0\nhigh = 1.0\n', encoding="utf-8")
    out = tmp_path / "mine"
    out.mkdir()
    (out / "trials.csv").write_text("my own table")
    with pytest.raises(OutputError, match="rvfem did not write it"):
        run_optimisation(problem, out, scheduler="tcp://127.0.0.1:1")   # refused before any cluster
    assert [p.name for p in out.iterdir()] == ["trials.csv"] and (out / "trials.csv").read_text() == "my own table"
