"""Command line: exit codes, one-line errors without tracebacks, JSON output."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from conftest import CASES_DIR, documented_keys, written_keys

import rvfem
from rvfem import __version__
from rvfem.app import cli

CRV80E = str(CASES_DIR / "crv80e.toml")


def test_check_valid_case(capsys):
    assert cli.main(["check", CRV80E]) == 0
    out, err = capsys.readouterr()
    assert out.count("\n") == 1 and out.startswith("OK") and "'crv80e'" in out
    assert err == ""


def test_check_invalid_case_gives_one_line_and_exit_2(case_text, tmp_path, capsys):
    path = case_text.set("cycloid", "eccentricity", "-1.3").write(tmp_path, "bad.toml")
    assert cli.main(["check", str(path)]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1
    assert str(path) in err and "'cycloid.eccentricity'" in err and "must be positive" in err
    assert "Traceback" not in err


def test_check_missing_file(tmp_path, capsys):
    assert cli.main(["check", str(tmp_path / "nope.toml")]) == 2
    assert "cannot read the case file" in capsys.readouterr().err


def test_rigid_table(capsys):
    assert cli.main(["rigid", CRV80E]) == 0
    out = capsys.readouterr().out
    assert "bearing speed 600 rpm" in out
    assert "C = 21948.7 N" in out
    assert out.count("5576.9") == 3 and out.count("4374.1") == 3


def test_rigid_json(capsys):
    assert cli.main(["rigid", CRV80E, "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["case"] == "crv80e"
    assert report["bearing_speed_rpm"] == pytest.approx(600.0)
    assert report["dynamic_load_rating_N"] == pytest.approx(21948.7, abs=0.05)
    assert len(report["bearings"]) == 3
    for b in report["bearings"]:
        assert b["max_load_N"] == pytest.approx(5576.2, rel=5e-4)
        assert b["equivalent_load_N"] == pytest.approx(4374.1, abs=0.05)
        assert b["L10h_h"] == pytest.approx(6008.0, abs=1.0)
        assert b["hertz_inner"]["peak_pressure_MPa"] > b["hertz_outer"]["peak_pressure_MPa"] > 0
    assert "duty_cycle" not in report


def test_rigid_reports_the_duty_cycle(case_text, tmp_path, capsys):
    case_text.append("[[loads.duty_cycle]]\ntime_share = 1.0\nspeed_rpm = 15.0\ntorque_Nm = 412.0")
    path = case_text.write(tmp_path)
    assert cli.main(["rigid", str(path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    duty = report["duty_cycle"]
    # one row at the rated point: the service life is the rated life
    assert duty["service_life_h"] == pytest.approx(report["bearings"][0]["L10h_h"], rel=1e-12)


def test_rigid_says_the_handbook_is_not_defined_for_two_teeth(case_text, tmp_path, capsys):
    """Zp − Zc = 2: exit 0, the handbook keys null with the reason, the references named."""
    path = case_text.set("cycloid", "teeth", "38").append(
        "[[loads.duty_cycle]]\ntime_share = 1.0\nspeed_rpm = 15.0\ntorque_Nm = 412.0").write(tmp_path)
    assert cli.main(["rigid", str(path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    refs = report["references"]
    assert refs["bearing_loads"] == "equal_share"
    assert not refs["handbook"]["defined"] and refs["handbook"]["why"].startswith("not defined for Zp − Zc ≠ 1")
    assert not refs["classical_pin_forces"]["defined"] and not refs["equal_share"]["defined"]
    assert report["k_y"] is None and report["sum_px_N"] is None and report["duty_cycle"] is None
    assert [b["crank_angle_deg"] for b in report["bearings"]] == [90.0, 210.0, 330.0]
    assert all(b["max_load_N"] is None and b["hertz_inner"] is None for b in report["bearings"])
    assert report["bearing_speed_rpm"] == pytest.approx(300.0)
    assert cli.main(["rigid", str(path)]) == 0
    out = capsys.readouterr().out
    assert out.count("not defined for Zp − Zc ≠ 1") >= 3 + 2 and "rvfem run" in out
    assert "the equal share of the FE pin resultant" in out


def test_rigid_rejects_a_case_outside_the_handbook_model(case_text, tmp_path, capsys):
    path = case_text.set("cranks", "angles_deg", "[90, 200, 330]").write(tmp_path)
    assert cli.main(["rigid", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "equally spaced" in err and "Traceback" not in err


def test_usage_errors_exit_2(capsys):
    assert cli.main([]) == 2
    assert cli.main(["frobnicate"]) == 2
    assert cli.main(["rigid"]) == 2
    capsys.readouterr()


def test_version(capsys):
    assert cli.main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"rvfem {__version__}"


def test_keyboard_interrupt_exits_130(monkeypatch, capsys):
    def interrupted(path, overrides=()):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "load_case", interrupted)
    assert cli.main(["check", CRV80E]) == 130
    assert "Traceback" not in capsys.readouterr().err


def test_every_subcommand_is_registered_once():
    names = [c.name for c in cli.SUBCOMMANDS]
    assert len(names) == len(set(names)) and {"check", "rigid"} <= set(names)


def test_entry_point_in_a_subprocess(case_text, tmp_path):
    """The installed module run as a program: verbose logging, a bad case, no traceback."""
    ok = subprocess.run([sys.executable, "-m", "rvfem.app.cli", "-vv", "rigid", CRV80E],
                        capture_output=True, text=True, timeout=60)
    assert ok.returncode == 0 and "5576.9" in ok.stdout
    assert "DEBUG rvfem.evaluate.rigid" in ok.stderr
    path = case_text.set("pins", "count", "39").write(tmp_path)
    bad = subprocess.run([sys.executable, "-m", "rvfem.app.cli", "rigid", str(path)],
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2
    assert bad.stdout == "" and bad.stderr.count("\n") == 1 and "Traceback" not in bad.stderr


def test_rigid_is_computed_by_the_library(capsys):
    """``rvfem rigid --json`` prints what rvfem.app.analysis.analyse_rigid computes, nothing else."""
    from rvfem.app.analysis import analyse_rigid
    from rvfem.case.definition import load_case

    result = analyse_rigid(load_case(CRV80E))
    assert cli.main(["rigid", CRV80E, "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["dynamic_load_rating_N"] == result.rating_N
    for entry, b in zip(report["bearings"], result.bearings):
        assert entry["max_load_N"] == b.loads.max_N and entry["L10h_h"] == b.loads.L10h
        assert entry["hertz_inner"]["peak_pressure_MPa"] == b.hertz_inner.peak_pressure_MPa


def test_set_overrides_a_case_key(capsys):
    assert cli.main(["rigid", CRV80E, "--json", "--set", "loads.torque_Nm=392.0"]) == 0
    half = json.loads(capsys.readouterr().out)
    assert half["overrides"] == ["loads.torque_Nm=392.0"]
    # the handbook loads are linear in the torque
    assert half["bearings"][0]["max_load_N"] == pytest.approx(5576.9 / 2, abs=0.05)
    assert cli.main(["check", CRV80E, "--set", "loads.torque_Nm=392.0", "--set", "analysis.angle_step_deg=5"]) == 0
    assert "loads.torque_Nm=392.0, analysis.angle_step_deg=5" in capsys.readouterr().out


@pytest.mark.parametrize("command", ["check", "rigid", "mesh", "run"])
def test_bad_set_is_one_line_naming_the_key(command, tmp_path, capsys):
    args = [command, CRV80E, "--set", "loads.torque_Nmm=392.0"]
    if command == "run":
        args += ["-o", str(tmp_path / "out")]
    if command == "mesh":
        args += ["--cache-dir", str(tmp_path / "cache")]
    assert cli.main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "loads.torque_Nmm" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
    assert cli.main([command, CRV80E, "--set", "no_equals_sign"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "KEY=VALUE" in err


def test_bearing_model_choices_come_from_the_registry():
    from rvfem.case.registry import bearing_model_names

    parser = cli.build_parser()
    run = next(a for a in parser._subparsers._group_actions[0].choices["run"]._actions
               if a.dest == "bearing_model")
    assert tuple(run.choices) == bearing_model_names()


def test_internal_error_is_one_line_with_a_log_file(monkeypatch, capsys):
    import rvfem.app.cli

    def broken(case, theta=None):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(rvfem.app.cli, "analyse_rigid", broken)
    assert cli.main(["rigid", CRV80E]) == 1
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "Traceback" not in err
    assert "internal error (ZeroDivisionError: float division by zero)" in err and "please report" in err
    log_path = err.rstrip().rsplit(" ", 1)[1]
    with open(log_path, encoding="utf-8") as fh:
        logged = fh.read()
    assert "Traceback" in logged and "ZeroDivisionError" in logged and "broken" in logged
    import os

    os.remove(log_path)
    # -vv shows the traceback as well
    assert cli.main(["-vv", "rigid", CRV80E]) == 1
    err = capsys.readouterr().err
    assert "Traceback" in err and err.strip().splitlines()[-1].startswith("rvfem rigid: internal error")
    os.remove(err.rstrip().rsplit(" ", 1)[1])


def test_json_output_is_strict_json_with_null_for_non_finite(monkeypatch, capsys):
    """A zero torque gives zero bearing loads and an infinite life: null, never Infinity."""
    import dataclasses

    import rvfem.app.analysis

    real = rvfem.app.analysis.analyse_rigid

    def infinite_life(case, theta=None):
        result = real(case, theta)
        b = result.bearings[0]
        bearings = (dataclasses.replace(b, loads=dataclasses.replace(b.loads, L10h=float("inf"))),
                    *result.bearings[1:])
        return dataclasses.replace(result, bearings=bearings)

    monkeypatch.setattr(rvfem.app.cli, "analyse_rigid", infinite_life)
    assert cli.main(["rigid", CRV80E, "--json"]) == 0
    text = capsys.readouterr().out
    assert "Infinity" not in text and "NaN" not in text
    report = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-JSON constant {c}"))
    assert report["bearings"][0]["L10h_h"] is None and report["bearings"][1]["L10h_h"] > 0
    assert cli.main(["rigid", CRV80E]) == 0
    assert "      –" in capsys.readouterr().out


@pytest.mark.parametrize("tty", [True, False])
def test_run_progress_draws_stages_and_the_cycle(tty):
    """The progress display of ``rvfem run`` (a tqdm bar on a terminal, plain lines otherwise)."""
    import io

    from rvfem.app.run import STAGES

    stream = io.StringIO()
    progress = cli._RunProgress(stream, tty)
    for stage in STAGES:
        total = 36 if stage in ("cycle", "images") else 1
        progress(stage, 0, total)
        for done in range(1, total):
            progress(stage, done, total)
        progress(stage, total, total)
    progress.close()
    text = stream.getvalue()
    assert text.count("done in") == len(STAGES)
    assert f"[{len(STAGES)}/{len(STAGES)}] writing the report: done in" in text
    if tty:
        assert "flexible load cycle:   0%" in text and "/36" in text          # the tqdm bar of the cycle
    else:
        assert "rvfem run: cycle 36/36" not in text and "cycle 18/36 angles (50 %)" in text


def test_rigid_json_has_versions_digest_and_documented_keys(tmp_path, capsys):
    from rvfem.case.definition import file_sha256, load_case
    from rvfem.outputs.summary import RIGID_SCHEMA_VERSION

    duty = str(CASES_DIR / "crv80e_duty.toml")
    written = set()
    for path in (CRV80E, duty, str(CASES_DIR / "rv40e_two_teeth.toml")):
        assert cli.main(["rigid", path, "--json"]) == 0
        report = json.loads(capsys.readouterr().out)
        assert report["schema_version"] == RIGID_SCHEMA_VERSION
        assert report["rvfem_version"] == rvfem.__version__
        assert report["case_sha256"] == file_sha256(path)
        assert report["case_digest"] == load_case(path).digest()
        assert report["environment"]["versions"]["numpy"]
        written |= written_keys(report, {"environment"})
    assert cli.main(["rigid", CRV80E, "--json", "--set", "loads.torque_Nm=40000.0"]) == 0   # with warnings
    written |= written_keys(json.loads(capsys.readouterr().out), {"environment"})
    documented = documented_keys("## `rvfem rigid --json`")
    assert written - documented == set(), "keys written but not documented"
    assert documented - written == set(), "keys documented but not written"


# --------------------------------------------------------------------------------------------
# Presentation: stage order, progress, notes, -v anywhere, numbers for the screen
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("images, duty", [(True, False), (False, False), (True, True)])
def test_run_stages_are_numbered_in_the_order_they_start(images, duty):
    """The stages of a run with images start in another order than STAGES lists them (the
    attribution after the VTK files) and some do not occur (no duty cycle): numbered as they start,
    out of the run's own count, nothing skipped."""
    import io
    import re

    from rvfem.app.run import STAGES, run_stages
    from rvfem.case.definition import load_case

    case = load_case(CASES_DIR / ("crv80e_duty.toml" if duty else "rv40e_fanholes.toml"))
    stages = run_stages(case, images=images)
    assert set(stages) <= set(STAGES) and len(set(stages)) == len(stages)
    assert ("duty_cycle" in stages) == duty and ("images" in stages) == images
    assert stages.index("attribution") > stages.index("vtk") if images else stages.index("attribution") < stages.index("tables")
    stream = io.StringIO()
    progress = cli._RunProgress(stream, False, stages)
    for stage in stages:
        progress(stage, 0, 1)
        progress(stage, 1, 1)
    progress.close()
    numbers = [(int(a), int(b)) for a, b in re.findall(r"\[(\d+)/(\d+)\] .*: done in", stream.getvalue())]
    assert [a for a, _ in numbers] == list(range(1, len(stages) + 1))
    assert {b for _, b in numbers} == {len(stages)}


def test_cycle_progress_gives_the_true_percentage():
    import io
    import re

    stream = io.StringIO()
    progress = cli._RunProgress(stream, False)
    progress("cycle", 0, 72)
    for done in range(1, 73):
        progress("cycle", done, 72)
    lines = re.findall(r"cycle (\d+)/72 angles \((\d+) %\)", stream.getvalue())
    assert len(lines) == 9
    for done, percent in lines:
        assert int(percent) == 100 * int(done) // 72


@pytest.mark.parametrize("argv", [["-v", "rigid", CRV80E], ["rigid", CRV80E, "-v"], ["rigid", "-v", CRV80E]])
def test_verbose_before_or_after_the_subcommand(argv, capsys):
    assert cli.main(argv) == 0
    assert "INFO rvfem.evaluate.rigid" in capsys.readouterr().err


def test_verbose_counts_on_both_sides(monkeypatch):
    seen = []
    monkeypatch.setattr(cli, "_setup_logging", lambda verbosity, command="": seen.append(verbosity) or (lambda: None))
    monkeypatch.setattr(cli, "_run_check", lambda args: 0)
    parser = cli.build_parser()
    monkeypatch.setattr(cli, "build_parser", lambda subcommands=None: parser)
    for p in parser._subparsers._group_actions[0].choices.values():
        p.set_defaults(run=lambda args: 0)
    assert cli.main(["-v", "check", CRV80E, "-v"]) == 0 and cli.main(["check", CRV80E, "-vv"]) == 0
    assert cli.main(["check", CRV80E]) == 0
    assert seen == [2, 2, 0]


def test_an_adjusted_angle_step_is_one_note_and_logging_is_left_as_found(capsys):
    import logging

    package = logging.getLogger("rvfem")
    level, handlers = package.level, list(package.handlers)
    assert cli.main(["rigid", CRV80E, "--set", "analysis.angle_step_deg=7"]) == 0
    out, err = capsys.readouterr()
    assert err == ("rvfem rigid: note: the crank-angle step 7° does not divide 360°: it is adjusted to 7.05882° "
                   "(51 angles)\n")
    assert "crank-angle step 7.05882°" in out
    assert package.level == level and package.handlers == handlers and cli._notices is None
    assert cli.main(["rigid", CRV80E]) == 0 and capsys.readouterr().err == ""


def test_notes_are_shown_once_and_end_a_status_line_first():
    import io
    import logging

    from rvfem import NOTICE

    stream = io.StringIO()
    handler = cli._Notices("run", stream)
    ended = []
    handler.before = lambda: ended.append(True)
    log = logging.getLogger("rvfem.test_notes")
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    try:
        log.info("meshing the whole disc: why", extra=NOTICE)
        log.info("meshing the whole disc: why", extra=NOTICE)
        log.info("an ordinary info line")
    finally:
        log.removeHandler(handler)
    assert stream.getvalue() == "rvfem run: note: meshing the whole disc: why\n" and ended == [True]


@pytest.mark.slow
def test_whole_disc_mesh_says_why_without_verbose(tmp_path, capsys):
    """The fan-hole disc with its ligament at min_wall is 3-fold symmetric, but no sector cut clears
    the holes: the note says so, when meshing and when the mesh comes from the cache."""
    from conftest import CaseText

    path = (CaseText.shipped("rv40e_fanholes").set("mesh", "size_flank", "0.8").set("mesh", "size_bore", "0.8")
            .set("mesh", "size_interior", "5.0").set("fan_holes", "ligament", "2.0").write(tmp_path))
    for _ in range(2):
        assert cli.main(["mesh", str(path), "--cache-dir", str(tmp_path / "meshes")]) == 0
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        assert err.startswith("rvfem mesh: note: meshing the whole disc: it is 3-fold symmetric, but the best "
                              "sector cut")


def test_rigid_json_angles_carry_no_float_noise(capsys):
    assert cli.main(["rigid", CRV80E, "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["bearings"][0]["min_at_deg"] == 250.0          # not 250.00000000000003
    for b in report["bearings"]:
        for key in ("max_at_deg", "min_at_deg", "crank_angle_deg"):
            assert b[key] == round(b[key], 6)


def test_a_tiny_torque_shows_significant_figures(capsys):
    """1e-3 N·m: loads in mN, not "0"; a life of 10^23 hours in exponent form, not 24 digits."""
    assert cli.main(["rigid", CRV80E, "--set", "loads.torque_Nm=0.001"]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.strip().startswith("1 "))
    cells = row.split()
    assert cells[1] == "0.007113" and cells[5] == "0.005579"
    assert "e+23" in cells[6] and len(cells[6]) <= 9
    assert " 0.0 " not in row
