"""What the screen, the README, the report's case table and the plots say: one-line usage errors,
the words for a solid disc, identical bearings named in a legend, the case tables the report shows,
and the README's lists of the shipped cases and of the files a run writes."""

from __future__ import annotations

import fnmatch
import logging
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import ROOT

from rvfem.app.cli import main
from rvfem.case.definition import load_case

CASE = str(ROOT / "cases" / "rv40e.toml")


@pytest.mark.parametrize("argv, command", [
    (["run", CASE, "--bogus"], "rvfem run"),
    (["run", CASE, "--step", "abc"], "rvfem run"),
    (["check"], "rvfem check"),
    (["frobnicate"], "rvfem"),
    ([], "rvfem"),
])
def test_usage_errors_are_one_line_naming_the_help_to_read(argv, command, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "usage:" not in err
    assert err.startswith("rvfem: error: ") and err.rstrip().endswith(f"(see {command} --help)")


def test_help_still_prints_the_usage(capsys):
    assert main(["run", "--help"]) == 0
    assert capsys.readouterr().out.startswith("usage: rvfem run")


def test_verbose_check_logs_the_case_and_very_verbose_every_default(capsys):
    from rvfem.app.analysis import resolve_case

    try:
        assert main(["check", CASE]) == 0
        quiet = capsys.readouterr().err
        assert main(["-v", "check", CASE]) == 0
        info = capsys.readouterr().err
        assert main(["check", "-vv", CASE]) == 0
        debug = capsys.readouterr().err
    finally:
        logging.getLogger().setLevel(logging.WARNING)
    assert "INFO" not in quiet
    assert "sha256" in info and "39 teeth on 40 pins" in info and "default used" not in info
    _, provenance = resolve_case(CASE)
    assert debug.count("default used:") == len(provenance.defaults_used) > 0
    assert "DEBUG" in debug and "wall " in debug


def test_a_folder_that_cannot_be_created_is_named(tmp_path):
    from rvfem.errors import OutputError
    from rvfem.outputs.summary import result_folder

    if not Path("/proc/self").is_dir():
        pytest.skip("needs /proc (Linux)")
    with pytest.raises(OutputError, match=r"^cannot create the folder /proc/x: "):
        with result_folder("/proc/x"):
            pass


def _mass_summary(area: float, solid_area: float) -> dict:
    """The keys :func:`mass_strength_lines` reads, for a disc of ``area`` and its solid twin."""
    rho_b = 7.85e-6 * 9.0
    saving = 100.0 * (1.0 - area / solid_area)
    return {"disc_mass_kg": rho_b * area, "disc_polar_inertia_kg_mm2": 1000.0, "static_safety_factor": 10.0,
            "mass_strength": {"mass_saving_percent": saving, "inertia_saving_percent": saving,
                              "solid_disc_mass_kg": rho_b * solid_area, "solid_disc_polar_inertia_kg_mm2": 1000.0,
                              "yield_strength_MPa": 1800.0}}


def test_a_solid_disc_says_it_has_no_lightening_holes():
    from rvfem.results.mass_strength import mass_strength_lines

    solid = mass_strength_lines(_mass_summary(7000.0, 7000.0))[0]
    assert "no lightening holes" in solid and "save" not in solid
    holed = mass_strength_lines(_mass_summary(5000.0, 7000.0))[0]
    assert "the lightening holes save 28.6 % of the mass" in holed


def _depth(bearing: int, model: str, theta: float, scale: float = 1.0):
    x = np.linspace(-4.5, 4.5, 30)
    return SimpleNamespace(bearing=bearing, model=model, raceway="eccentric", theta_deg=theta, roller=0,
                           roller_load_N=1000.0 * scale, x_mm=x, pressure_MPa=scale * (1500.0 + 10.0 * x ** 2))


def test_identical_bearings_share_one_curve_named_so_in_the_legend():
    from rvfem.outputs.roller_outputs import roller_pressure_curves

    # N-fold symmetry: the same curve 120° apart, to round-off
    depths = [_depth(i, m, 86.0 + 120.0 * i, 1.0 + 1e-12 * i) for i in range(3) for m in ("rigid", "flexible")]
    labels = [label for label, _ in roller_pressure_curves(depths)]
    assert len(labels) == 2
    assert all(label.startswith("bearings 1–3 (identical)") for label in labels)
    assert "θ = 86, 206, 326°" in labels[0]
    # a bearing that differs keeps its own curve
    depths[2] = _depth(1, "rigid", 206.0, 1.2)
    labels = [label for label, _ in roller_pressure_curves(depths)]
    assert len(labels) == 4 and sum(label.startswith("bearing ") for label in labels) == 3


def test_the_report_case_table_has_every_table_that_changes_the_result():
    from rvfem.outputs.report import _case_rows

    case = load_case(CASE)
    rows = dict(_case_rows(case))
    assert f"span = {case.crank_support.span:g} mm" in rows["crank support (crankshaft as a beam)"]
    assert f"iso_vg = {case.lubricant.iso_vg:g}" in rows["lubricant"]
    assert f'kind = "{case.crank_bearing.profile.kind}"' in rows["crank-bearing roller profile"]
    assert f"μ = {case.analysis.friction:g}" in rows["analysis"]
    arc = load_case(CASE, overrides=('crank_bearing.profile.kind="arc"',))
    assert "crown_radius = 500 mm" in dict(_case_rows(arc))["crank-bearing roller profile"]
    assert "crown_radius" not in rows["crank-bearing roller profile"]   # straight: not used


def test_the_readme_lists_every_shipped_case_and_every_file_a_run_writes():
    import rvfem.outputs.summary  # noqa: F401  (registers the writers)
    from rvfem.outputs.registry import writers

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    table = {m for m in re.findall(r"^\| `(cases/[^`]+\.toml)` \|", readme, flags=re.M)}
    assert table == {f"cases/{p.name}" for p in (ROOT / "cases").glob("*.toml")}
    outputs_md = (ROOT / "docs" / "outputs.md").read_text(encoding="utf-8")
    for w in writers(images=True):
        for pattern in w.files:
            folder, _, name = pattern.rpartition("/")
            if "*" in name:   # a family of files: its folder is described
                assert f"`{folder}/" in readme, pattern
            else:
                assert f"`{name}`" in readme or f"`{pattern}`" in readme, pattern
            assert any(fnmatch.fnmatch(f, pattern) for f in re.findall(r"DIR/(\S+)", outputs_md)) or \
                f"DIR/{pattern}" in outputs_md, pattern


def test_the_wall_time_line_says_the_drawing_ran_beside_the_writing():
    from rvfem.results.screen_lines import drawing_text as _drawing_text

    files = ["summary.json"] + [f"images/stress_{k}.png" for k in range(10)]
    text = _drawing_text({"plots": 0.2, "images": 0.1, "drawing_background": 11.4}, files)
    assert text == "10 images and the plots drawn in a background process within 11.4 s, 0.3 s of it waited for"
    assert _drawing_text({"images": 0.0}, ["summary.json"]) == "no images"


@pytest.mark.parametrize("pitch_radius", [64.0, 80.0])
def test_the_mesh_close_up_holds_the_bore_and_the_teeth_however_thick_the_rim(pitch_radius):
    from rvfem.outputs.plots import rim_closeup

    def circle(centre, radius, start, n=720):
        a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
        pts = np.column_stack([centre[0] + radius * np.cos(a), centre[1] + radius * np.sin(a)])
        edges = np.column_stack([np.arange(n), np.roll(np.arange(n), -1)]) + start
        return pts, edges

    bore, bore_edges = circle((0.0, 36.0), 18.0, 0)
    profile, profile_edges = circle((0.0, 0.0), pitch_radius, len(bore))
    (cx, cy), half = rim_closeup(np.vstack([bore, profile]), {"bore_0": bore_edges, "profile": profile_edges})
    # the rim runs from the bore's top (0, 54) to the profile above it (0, R): both in the window
    assert abs(cx) < 1e-9 and cy - half < 54.0 - 1.0 and cy + half > pitch_radius + 1.0
    assert half >= 8.0
