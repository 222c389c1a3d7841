"""``rvfem run``: the result folder against the Python API, file formats, and nothing lost.

Runs a coarse version of the default case (mesh sizes doubled, 20° crank-angle step, fields at 0°
and at the largest bearing load) once through the command line and checks every output; a second
run adds a duty cycle, ``--field-step`` and ``--set``.
"""

from __future__ import annotations

import csv
import importlib.machinery
import json
import math
import sys
import types
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest
from conftest import ROOT, CaseText, documented_keys, written_keys

from rvfem import __version__
from rvfem.app import cli, screen
from rvfem.app.analysis import analyse
from rvfem.app.run import IMAGE_SIZE, run_case
from rvfem.case.definition import file_sha256, load_case
from rvfem.errors import FolderNotEmptyError, OutputError, RenderError
from rvfem.evaluate.compare import rigid_vs_flexible
from rvfem.mesh import mesh_case
from rvfem.outputs import render, render_check
from rvfem.outputs import summary as outputs
from rvfem.outputs.vtkio import CELL_FIELDS, POINT_FIELDS
from rvfem.solve.cycle import build_system, load_cycle

STEP_DEG = 20.0

#: Documented keys of summary.json (docs/outputs.md).
TOP_KEYS = {
    "schema_version", "rvfem_version", "environment", "case", "model", "bearings", "max_bearing_load", "pins_in_contact",
    "peak_von_mises_MPa", "peak_von_mises_at", "stress", "torsional_stiffness_Nm_per_arcmin",
    "carrier_rotation_arcmin", "equilibrium_residual", "active_set_iterations", "hertz", "fields", "images",
    "plots", "timings_s", "files",
}
CASE_KEYS = {"name", "description", "file", "sha256", "matches_file", "digest", "overrides", "defaults_used"}
MODEL_KEYS = {
    "bearing_model", "element_order", "pin_model", "pin_friction", "nodes", "vertices", "dofs", "elements", "mesh_file",
    "mesh_min_quality", "angle_step_deg", "angles", "output_torque_Nm", "discs", "disc_torque_Nmm",
    "torque_convention", "radial_clearance_mm", "equivalent_load_exponent", "dynamic_load_rating_N",
    "bearing_speed_rpm", "handbook_k_y", "fe_pin_resultant_ratio",
}
BEARING_KEYS = {"bearing", "crank_angle_deg", "rigid", "flexible", "equal_share", "delta_max_percent",
                "delta_min_percent", "delta_equivalent_percent", "life_ratio"}
STATS_KEYS = {"max_load_N", "max_at_deg", "min_load_N", "min_at_deg", "equivalent_load_N", "L10h_h"}
HERTZ_KEYS = {"roller_load_N", "bearing", "roller", "theta_deg", "inner", "outer"}
LOCATION_KEYS = {"x_mm", "y_mm", "radius_mm", "theta_deg", "feature", "feature_label", "distance_to_feature_mm"}


@pytest.fixture(scope="module")
def workspace(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("run")


@pytest.fixture(scope="module")
def coarse_case_file(workspace) -> Path:
    """The default case with the mesh sizes doubled and a 20° step."""
    text = (CaseText.shipped("rv40e_fanholes")
            .set("mesh", "size_flank", "0.7").set("mesh", "size_bore", "0.8").set("mesh", "size_interior", "5.0")
            .set("analysis", "angle_step_deg", str(STEP_DEG)).set("analysis", "saved_angles_deg", "[0.0]"))
    return text.write(workspace, "coarse.toml")


@pytest.fixture(scope="module")
def cache_dir(workspace) -> Path:
    return workspace / "meshes"


@pytest.fixture(scope="module")
def cli_run(workspace, coarse_case_file, cache_dir) -> Path:
    """``rvfem run`` into a fresh folder (below a parent that does not exist yet)."""
    out = workspace / "results" / "coarse"
    code = cli.main(["run", str(coarse_case_file), "-o", str(out), "--cache-dir", str(cache_dir)])
    assert code == 0
    return out


@pytest.fixture(scope="module")
def summary(cli_run) -> dict:
    return json.loads((cli_run / "summary.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def api(coarse_case_file, cache_dir):
    """The same analysis through the library functions, independently of rvfem.app.run."""
    case = load_case(coarse_case_file)
    system = build_system(case, mesh_case(case, cache_dir))
    cycle = load_cycle(system)
    return case, system, cycle, rigid_vs_flexible(case, cycle)


# --------------------------------------------------------------------------------------------
# summary.json
# --------------------------------------------------------------------------------------------


def test_summary_has_the_documented_keys(summary, coarse_case_file):
    assert TOP_KEYS <= set(summary)
    assert CASE_KEYS <= set(summary["case"])
    assert MODEL_KEYS <= set(summary["model"])
    assert summary["schema_version"] == 2
    assert summary["case"]["sha256"] == file_sha256(coarse_case_file)
    assert summary["case"]["matches_file"] is True and summary["case"]["overrides"] == {}
    assert summary["model"]["angle_step_deg"] == pytest.approx(STEP_DEG)
    assert summary["model"]["angles"] == 18
    assert len(summary["bearings"]) == 3
    for b in summary["bearings"]:
        assert BEARING_KEYS <= set(b)
        for model in ("rigid", "flexible", "equal_share"):
            assert STATS_KEYS <= set(b[model])
    assert {"min", "max", "mean", "of"} <= set(summary["pins_in_contact"])
    assert LOCATION_KEYS <= set(summary["peak_von_mises_at"])
    assert LOCATION_KEYS <= set(summary["stress"]["away_from_contacts"]["at"])
    for key in ("fe_rollers", "stribeck_rigid", "stribeck_flexible"):
        assert HERTZ_KEYS <= set(summary["hertz"][key])
        assert summary["hertz"][key]["inner"]["peak_pressure_MPa"] > summary["hertz"][key]["outer"]["peak_pressure_MPa"]
    assert summary["timings_s"]["total"] > summary["timings_s"]["cycle"] > 0
    # case file defaults are listed (the coarse file does not set e.g. the element order)
    assert summary["case"]["defaults_used"]["analysis.element_order"] == 1
    # the default case is inside every model's range but the minimum-load rule (0.02·C, a maker's rule),
    # which its flexible minimum bearing load misses (docs/theory.md, "Static safety, minimum load ...")
    below = summary["bearing_checks"]["minimum_load"]["flexible"]["below"]
    assert [w["code"] for w in summary["warnings"]] == (["minimum_load"] if below else [])


def test_summary_numbers_equal_the_python_api(summary, api):
    case, system, cycle, comparison = api
    m = summary["model"]
    assert (m["nodes"], m["dofs"], m["elements"]) == (system.model.n_nodes, system.model.n_dofs,
                                                      system.model.n_elements)
    assert m["dynamic_load_rating_N"] == pytest.approx(comparison.rating_N, rel=1e-12)
    for entry, bc in zip(summary["bearings"], comparison.bearings):
        assert entry["bearing"] == bc.bearing + 1
        for model in ("rigid", "flexible", "equal_share"):
            s, ref = entry[model], getattr(bc, model)
            assert s["max_load_N"] == pytest.approx(ref.max_N, rel=1e-9)
            assert s["max_at_deg"] == pytest.approx(ref.max_at_deg, abs=1e-9)
            assert s["min_load_N"] == pytest.approx(ref.min_N, rel=1e-9)
            assert s["equivalent_load_N"] == pytest.approx(ref.equivalent_N, rel=1e-9)
            assert s["L10h_h"] == pytest.approx(ref.L10h, rel=1e-9)
        assert entry["delta_max_percent"] == pytest.approx(bc.delta_max_percent, rel=1e-7, abs=1e-9)
        assert entry["delta_min_percent"] == pytest.approx(bc.delta_min_percent, rel=1e-7, abs=1e-9)
        assert entry["life_ratio"] == pytest.approx(bc.life_ratio, rel=1e-9)
    assert summary["pins_in_contact"]["min"] == int(cycle.pins_in_contact.min())
    assert summary["pins_in_contact"]["max"] == int(cycle.pins_in_contact.max())
    assert summary["torsional_stiffness_Nm_per_arcmin"] == pytest.approx(
        cycle.torsional_stiffness_Nm_per_arcmin(case.loads.disc_torque_Nmm), rel=1e-9)
    assert summary["equilibrium_residual"] < 1e-8
    assert summary["hertz"]["fe_rollers"]["roller_load_N"] == pytest.approx(float(cycle.roller_loads.max()), rel=1e-9)
    # the largest bearing load: on a symmetric disc it has equal copies (bearing i + 1 at θ + 360°/N),
    # the summary names the first (lowest angle, then lowest bearing)
    loads = cycle.bearing_loads
    tied = np.argwhere(loads >= loads.max() * (1 - 1e-9))
    k, i = tied[0]
    assert summary["max_bearing_load"]["theta_deg"] == pytest.approx(math.degrees(cycle.theta[k]))
    assert summary["max_bearing_load"]["bearing"] == i + 1


# --------------------------------------------------------------------------------------------
# VTK
# --------------------------------------------------------------------------------------------


def _pvd_files(out: Path) -> list[tuple[float, Path]]:
    root = ET.parse(out / "vtk" / "disc.pvd").getroot()
    return [(float(d.get("timestep")), out / "vtk" / d.get("file")) for d in root.iter("DataSet")]


def _von_mises(sxx, syy, sxy):
    return np.sqrt(sxx**2 - sxx * syy + syy**2 + 3.0 * sxy**2)


def test_vtu_files_read_back_with_the_named_fields(cli_run, summary):
    entries = _pvd_files(cli_run)
    cz = summary["stress"]["contact_zone"]
    angles = [f["theta_deg"] for f in summary["fields"]]
    assert [t for t, _ in entries] == pytest.approx(sorted(angles))
    assert 0.0 in angles and summary["max_bearing_load"]["theta_deg"] in angles
    for _, path in entries:
        mesh = meshio.read(path)
        assert mesh.points.shape == (summary["model"]["vertices"], 3)
        assert mesh.cells[0].type == "triangle" and len(mesh.cells[0].data) == summary["model"]["elements"]
        for name, comps in POINT_FIELDS.items():
            a = mesh.point_data[name]
            assert a.shape[0] == len(mesh.points) and (a.ndim == 1 if comps == 1 else a.shape[1] == comps)
            assert np.all(np.isfinite(a))
        for name in CELL_FIELDS:
            assert mesh.cell_data[name][0].shape == (summary["model"]["elements"],)
        pd, cd = mesh.point_data, {k: v[0] for k, v in mesh.cell_data.items()}
        for data in (pd, cd):
            vm = _von_mises(data["sxx_MPa"], data["syy_MPa"], data["sxy_MPa"])
            np.testing.assert_allclose(data["von_mises_MPa"], vm, rtol=1e-10, atol=1e-9)
            np.testing.assert_allclose(data["s1_MPa"] + data["s2_MPa"], data["sxx_MPa"] + data["syy_MPa"],
                                       rtol=1e-10, atol=1e-9)
        assert float(pd["von_mises_MPa"].max()) <= cz["peak_von_mises_MPa"] * (1 + 1e-12)
    # the contact-zone peak is the envelope's overall maximum: its field holds it at its place
    peak_file = next(p for t, p in entries if t == pytest.approx(cz["at"]["theta_deg"]))
    mesh = meshio.read(peak_file)
    i = int(np.argmax(mesh.point_data["von_mises_MPa"]))
    assert mesh.point_data["von_mises_MPa"][i] == pytest.approx(cz["peak_von_mises_MPa"], rel=1e-12)
    assert mesh.points[i, :2] == pytest.approx([cz["at"]["x_mm"], cz["at"]["y_mm"]])


# --------------------------------------------------------------------------------------------
# Images, plots, report
# --------------------------------------------------------------------------------------------


def _check_png(path: Path, size: tuple[int, int] | None = None) -> None:
    from PIL import Image

    with Image.open(path) as im:
        assert im.format == "PNG"
        if size is not None:
            assert im.size == size
        rgb = np.asarray(im.convert("RGB"))
    assert rgb.std() > 10.0
    packed = (rgb[..., 0].astype(np.int64) << 16) | (rgb[..., 1].astype(np.int64) << 8) | rgb[..., 2]
    colours = np.unique(packed)
    assert len(colours) > 64, f"{path.name}: only {len(colours)} colours"


def test_images_are_real_renders(cli_run, summary):
    images = summary["images"]
    stress = [f["image"] for f in summary["fields"]]
    assert len(stress) == len(summary["fields"]) >= 2
    assert {"mesh", "stress_peak_closeup", "stress_away_from_contacts_closeup"} <= set(images)
    for rel in stress + [images["stress_peak_closeup"], images["stress_away_from_contacts_closeup"]]:
        _check_png(cli_run / rel, IMAGE_SIZE)
    _check_png(cli_run / images["mesh"])
    # the stress image is mostly coloured by the colour map, not background
    from PIL import Image

    rgb = np.asarray(Image.open(cli_run / stress[0]).convert("RGB")).astype(int)
    coloured = (rgb.max(axis=2) - rgb.min(axis=2) > 20).mean()
    assert coloured > 0.12


def test_plots_exist(cli_run, summary):
    assert set(summary["plots"]) == {"bearing_loads", "roller_loads", "pin_forces", "pins_in_contact", "roller_pressure",
                                     "roller_damage"}
    for rel in summary["plots"].values():
        _check_png(cli_run / rel)


def test_report_embeds_the_images(cli_run, summary):
    html = (cli_run / "report.html").read_text(encoding="utf-8")
    n_png = len(summary["images"]) + len(summary["plots"])
    assert html.count('<img src="data:image/png;base64,') == n_png
    assert "src=\"images/" not in html and "src=\"plots/" not in html
    assert summary["case"]["name"] in html and "disc centre" in html
    assert f"{summary['bearings'][0]['flexible']['max_load_N']:.0f}" in html


def test_report_writes_case_values_as_in_a_case_file(cli_run, summary):
    """The defaults table (and the overrides) read like TOML: true, {key = value}, not Python."""
    import html as html_module

    text = html_module.unescape((cli_run / "report.html").read_text(encoding="utf-8"))
    table = text[text.index("defaults used"):]
    table = table[: table.index("</table>")]
    assert summary["case"]["defaults_used"]["mesh.symmetric"] is True
    assert "<code>true</code>" in table and "True" not in table
    assert "{equidistant = 0.0, shift = 0.0, rotation_deg = 0.0}" in table and "{'" not in table
    # The default case warns only where its smallest bearing load is under the makers' minimum-load
    # rule 0.02·C (the FE lowers it below the rule), and then of nothing else.
    codes = [w["code"] for w in summary["warnings"]]
    minimum = summary["bearing_checks"]["minimum_load"]
    below = any(minimum[m]["fraction_of_C"] < minimum["required_fraction_of_C"] for m in ("rigid", "flexible")
                if minimum.get(m))
    assert codes == (["minimum_load"] if below else [])
    assert ("class='warnings'" in text) == below


def test_report_states_the_reducer_stage_and_what_the_delta_depends_on(cli_run, summary):
    import html as html_module

    text = html_module.unescape((cli_run / "report.html").read_text(encoding="utf-8"))
    assert "What the flexibility delta is made of" in text and "What this delta depends on" in text
    assert summary["reducer_stage"]["model"] in text
    steps = {r["step"] for r in summary["attribution"]}
    assert {"handbook", "equal_share", "one_disc", "two_discs"} <= steps
    # the run's own model is the last step of the chain and equals the run's bearing loads
    final = [r for r in summary["attribution"] if r["final"]]
    assert {r["step"] for r in final} == {summary["reducer_stage"]["step"]}
    for r, b in zip(final, summary["bearings"]):
        assert r["max_N"] == pytest.approx(b["flexible"]["max_load_N"], rel=1e-12)


def test_files_listed_exist(cli_run, summary):
    listed = set(summary["files"])
    on_disk = {p.relative_to(cli_run).as_posix() for p in cli_run.rglob("*") if p.is_file()}
    assert listed == on_disk - {outputs.RESULT_MARKER}     # the marker says who wrote the folder
    assert (cli_run / outputs.RESULT_MARKER).read_text(encoding="utf-8").startswith(f"rvfem {__version__} run ")
    assert not any(p.name.startswith(".") for p in cli_run.parent.iterdir())  # no temporary folders left


# --------------------------------------------------------------------------------------------
# CSV
# --------------------------------------------------------------------------------------------


def _read_csv(path: Path) -> list[dict]:
    with path.open(newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_csv_tables_agree_with_summary(cli_run, summary):
    rows = _read_csv(cli_run / "bearing_loads.csv")
    assert len(rows) == summary["model"]["angles"]
    theta = [float(r["theta_deg"]) for r in rows]
    assert theta == pytest.approx(np.arange(0.0, 360.0, STEP_DEG))
    for b in summary["bearings"]:
        i = b["bearing"]
        for model in ("flexible", "rigid", "equal_share"):
            f = np.array([float(r[f"bearing{i}_{model}_F_N"]) for r in rows])
            fx = np.array([float(r[f"bearing{i}_{model}_Fx_N"]) for r in rows])
            fy = np.array([float(r[f"bearing{i}_{model}_Fy_N"]) for r in rows])
            np.testing.assert_allclose(np.hypot(fx, fy), f, rtol=1e-8)
            assert f.max() == pytest.approx(b[model]["max_load_N"], rel=1e-9)
            assert theta[int(np.argmax(f))] == pytest.approx(b[model]["max_at_deg"])
            assert f.min() == pytest.approx(b[model]["min_load_N"], rel=1e-9)

    rollers = _read_csv(cli_run / "roller_loads.csv")
    assert len(rollers) == 18 * 3 * 14
    q = max(float(r["load_N"]) for r in rollers)
    assert q == pytest.approx(summary["hertz"]["fe_rollers"]["roller_load_N"], rel=1e-9)

    pins = _read_csv(cli_run / "pin_forces.csv")
    assert len(pins) == 18 * 40
    first = [r for r in pins if float(r["theta_deg"]) == 0.0]
    assert math.hypot(float(first[0]["x_mm"]), float(first[0]["y_mm"]) + 0.0) == pytest.approx(64.0 - 1.3)
    classical = np.array([float(r["classical_N"]) for r in first])
    assert 18 <= np.count_nonzero(classical) <= 22

    cycle = _read_csv(cli_run / "cycle.csv")
    counts = [int(r["pins_in_contact"]) for r in cycle]
    assert (min(counts), max(counts)) == (summary["pins_in_contact"]["min"], summary["pins_in_contact"]["max"])


# --------------------------------------------------------------------------------------------
# Nothing lost
# --------------------------------------------------------------------------------------------


def test_second_run_without_overwrite_fails_and_keeps_the_results(cli_run, coarse_case_file, cache_dir, capsys):
    before = {p: p.read_bytes() for p in cli_run.rglob("*") if p.is_file()}
    code = cli.main(["run", str(coarse_case_file), "-o", str(cli_run), "--cache-dir", str(cache_dir)])
    err = capsys.readouterr().err
    assert code == 2
    assert "exists and is not empty" in err and "--overwrite" in err and "Traceback" not in err
    assert "overwrite=True" not in err                     # the command line's wording, not the API's
    assert {p: p.read_bytes() for p in cli_run.rglob("*") if p.is_file()} == before
    with pytest.raises(FolderNotEmptyError, match=r"allow replacing it \(overwrite\)") as info:  # the library's
        outputs.check_output_folder(cli_run, overwrite=False)
    assert "--overwrite" not in str(info.value) and info.value.folder == cli_run


def test_overwrite_replaces_and_options_override_the_case(cli_run, coarse_case_file, cache_dir, workspace, capsys):
    """A second run with --overwrite replaces a result folder rvfem wrote (it holds the marker)."""
    import shutil

    out = workspace / "overwritten"
    shutil.copytree(cli_run, out)
    assert outputs.is_rvfem_folder(out)
    code = cli.main(["run", str(coarse_case_file), "-o", str(out), "--cache-dir", str(cache_dir), "--overwrite",
                     "--no-images", "--step", "30", "--bearing-model", "rigid_bore"])
    stdout = capsys.readouterr().out
    assert code == 0
    s = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert s["model"]["angles"] == 12 and s["model"]["bearing_model"] == "rigid_bore"
    assert s["case"]["overrides"] == {"analysis.angle_step_deg": 30.0, "crank_bearing.model": "rigid_bore"}
    assert s["case"]["matches_file"] is False
    assert s["hertz"]["fe_rollers"] is None and s["images"] == {}
    assert not (out / "images").exists() and not (out / "roller_loads.csv").exists()
    assert len(_read_csv(out / "bearing_loads.csv")) == 12
    assert "rigid_bore" in stdout and "life ratio" in stdout
    assert not any(p.name.startswith(".") for p in workspace.iterdir())


class Interrupt:
    """A progress callback that raises after a few crank angles."""

    def __init__(self, exc: BaseException, after: int = 3):
        self.exc, self.after, self.seen = exc, after, []

    def __call__(self, stage, done, total):
        self.seen.append((stage, done, total))
        if stage == "cycle" and done >= self.after:
            raise self.exc


@pytest.mark.parametrize("exc", [KeyboardInterrupt(), RuntimeError("boom")])
def test_interrupted_run_leaves_no_folder(coarse_case_file, cache_dir, tmp_path, exc):
    out = tmp_path / "a" / "b" / "out"
    cb = Interrupt(exc)
    with pytest.raises(type(exc)):
        run_case(coarse_case_file, out, progress=cb, cache_dir=cache_dir, images=False)
    # interrupted within the cycle of 18 angles (the N-fold symmetric pair: six per pair solve)
    assert any(stage == "cycle" and 0 < done < 18 and total == 18 for stage, done, total in cb.seen)
    assert list(tmp_path.iterdir()) == []          # no DIR, no temporary folder, no created parents


def test_interrupted_overwrite_keeps_the_previous_results(coarse_case_file, cache_dir, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    outputs.mark_folder(out, "run")                # results rvfem wrote earlier
    (out / "old.txt").write_text("previous results")
    with pytest.raises(KeyboardInterrupt):
        run_case(coarse_case_file, out, overwrite=True, progress=Interrupt(KeyboardInterrupt()),
                 cache_dir=cache_dir, images=False)
    assert [p.name for p in tmp_path.iterdir()] == ["out"]
    assert sorted(p.name for p in out.iterdir()) == [outputs.RESULT_MARKER, "old.txt"]


def test_cli_interrupt_exits_130(coarse_case_file, cache_dir, tmp_path, monkeypatch, capsys):
    import rvfem.solve.cycle

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(rvfem.solve.cycle, "load_cycle", interrupted)
    out = tmp_path / "out"
    assert cli.main(["run", str(coarse_case_file), "-o", str(out), "--cache-dir", str(cache_dir),
                     "--no-images"]) == 130
    assert "interrupted" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def _foreign_folder(path: Path) -> dict:
    """A non-empty folder rvfem did not write (a sibling result, a file, a sub-folder); its contents."""
    (path / "sub").mkdir(parents=True)
    (path / "notes.txt").write_text("mine")
    (path / "sub" / "data.csv").write_text("1,2\n")
    return {p.relative_to(path): p.read_bytes() for p in path.rglob("*") if p.is_file()}


def test_overwrite_never_replaces_a_folder_rvfem_did_not_write(tmp_path):
    out = tmp_path / "out"
    before = _foreign_folder(out)
    for overwrite in (False, True):
        with pytest.raises(OutputError, match=r"rvfem did not write it \(no \.rvfem-results file in it\)"):
            with outputs.result_folder(out, overwrite=overwrite):
                pytest.fail("entered")
    assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    assert [p.name for p in tmp_path.iterdir()] == ["out"]     # no temporary folder left
    outputs.check_output_folder(tmp_path / "absent", overwrite=False)   # a new or empty folder is taken
    (tmp_path / "empty").mkdir()
    outputs.check_output_folder(tmp_path / "empty", overwrite=False)


def test_a_result_folder_of_an_earlier_rvfem_is_refused_and_named(tmp_path):
    """A folder from before the marker (a summary.json with rvfem_version, no marker) is still
    refused, since files may have been added to it since, and the message says what it probably is."""
    out = tmp_path / "old"
    _foreign_folder(out)
    (out / "summary.json").write_text('{"schema_version": 1, "rvfem_version": "0.3.0"}')
    with pytest.raises(OutputError, match="suggests an earlier rvfem wrote it"):
        outputs.check_output_folder(out, overwrite=True)
    assert (out / "notes.txt").read_text() == "mine"


def test_cli_overwrite_of_a_folder_rvfem_did_not_write_is_refused(coarse_case_file, tmp_path, capsys):
    """rvfem run --overwrite on a non-empty folder without the marker: one line, exit 2, the
    folder's contents untouched (the 0.3 behaviour deleted them: a case named "" took results/)."""
    out = tmp_path / "results"
    before = _foreign_folder(out)
    assert cli.main(["run", str(coarse_case_file), "-o", str(out), "--overwrite", "--no-images"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "rvfem did not write it" in err and "Traceback" not in err
    assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    assert [p.name for p in tmp_path.iterdir()] == ["results"]


def test_existing_file_as_output_is_an_error(coarse_case_file, tmp_path):
    target = tmp_path / "file"
    target.write_text("x")
    with pytest.raises(OutputError, match="not a folder"):
        run_case(coarse_case_file, target, images=False)


def test_impossible_rendering_is_a_clear_error(coarse_case_file, cache_dir, tmp_path, monkeypatch, capsys):
    # a renderer that crashes its process, as VTK does without any usable OpenGL context
    monkeypatch.setattr(render_check, "_PROBE", "import os; os.abort()")
    monkeypatch.setattr(render_check, "_probe_result", None)
    with pytest.raises(RenderError, match="off-screen rendering is not available.*--no-images"):
        render.check_rendering()
    out = tmp_path / "out"
    assert cli.main(["run", str(coarse_case_file), "-o", str(out), "--cache-dir", str(cache_dir)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "crashed" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_bad_step_is_a_case_error(coarse_case_file, tmp_path, capsys):
    assert cli.main(["run", str(coarse_case_file), "-o", str(tmp_path / "o"), "--step", "-5"]) == 2
    assert "angle step" in capsys.readouterr().err


@pytest.mark.parametrize("value", ["0", "-10", "400"])
def test_bad_field_step_is_one_line_and_leaves_nothing(coarse_case_file, tmp_path, capsys, value):
    assert cli.main(["run", str(coarse_case_file), "-o", str(tmp_path / "o"), "--no-images",
                     "--field-step", value]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "field step" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_p2_fields_are_written_on_the_linear_mesh(coarse_case_file, cache_dir, tmp_path):
    result = run_case(coarse_case_file, tmp_path / "p2", order=2, angle_step_deg=30.0, cache_dir=cache_dir,
                      images=False)
    s = result.summary
    assert s["model"]["element_order"] == 2 and s["case"]["overrides"]["analysis.element_order"] == 2
    assert s["model"]["nodes"] > s["model"]["vertices"]
    mesh = meshio.read(tmp_path / "p2" / s["fields"][0]["vtu"])
    assert mesh.points.shape == (s["model"]["vertices"], 3)
    vertex_u = result.cycle.fields[min(result.cycle.fields)][result.system.model.node_dofs[: s["model"]["vertices"]]]
    np.testing.assert_allclose(mesh.point_data["displacement_mm"][:, :2], vertex_u, rtol=1e-12, atol=1e-15)
    pd = mesh.point_data
    np.testing.assert_allclose(pd["von_mises_MPa"], _von_mises(pd["sxx_MPa"], pd["syy_MPa"], pd["sxy_MPa"]),
                               rtol=1e-10, atol=1e-9)


# --------------------------------------------------------------------------------------------
# Duty cycle, --field-step and --set (a second run)
# --------------------------------------------------------------------------------------------

#: A start-run-stop cycle after the accelerated test of Gao et al. (CRV-80E, section 3): 0.3 s
#: accelerating (mean speed half the rated one, 2.5 times the rated torque), 1.7 s at the rated
#: speed and torque, 0.3 s braking; scaled to the RV-40E's 412 N·m.
DUTY_ROWS = [(0.3, 7.5, 1030.0), (1.7, 15.0, 412.0), (0.3, 7.5, 1030.0)]
FIELD_STEP_DEG = 60.0
SPEED_OVERRIDE_RPM = 20.0


@pytest.fixture(scope="module")
def duty_run(workspace, cache_dir) -> tuple[Path, dict, str]:
    """``rvfem run`` of the coarse case with a duty cycle, ``--field-step`` and ``--set``."""
    text = (CaseText.shipped("rv40e_fanholes")
            .set("mesh", "size_flank", "0.7").set("mesh", "size_bore", "0.8").set("mesh", "size_interior", "5.0")
            .set("analysis", "angle_step_deg", str(STEP_DEG)).set("analysis", "saved_angles_deg", "[0.0]"))
    for t, n, torque in DUTY_ROWS:
        text.append(f"[[loads.duty_cycle]]\ntime_share = {t}\nspeed_rpm = {n}\ntorque_Nm = {torque}")
    path = text.write(workspace, "duty.toml")
    out = workspace / "duty"
    import contextlib
    import io

    screen = io.StringIO()
    with contextlib.redirect_stdout(screen):
        code = cli.main(["run", str(path), "-o", str(out), "--cache-dir", str(cache_dir), "--no-images",
                         "--field-step", str(FIELD_STEP_DEG), "--set", f"loads.speed_rpm={SPEED_OVERRIDE_RPM}"])
    assert code == 0
    return out, json.loads((out / "summary.json").read_text(encoding="utf-8")), screen.getvalue()


def test_duty_cycle_service_life_is_palmgren_miner_of_the_rated_lives(duty_run):
    out, s, screen = duty_run
    n0, t0 = SPEED_OVERRIDE_RPM, 412.0
    # Gao et al., eqs. 17-18 written out: damage rate Σ t_i n_i T_i^(10/3) / Σ t_i
    rate = sum(t * n * torque ** (10 / 3) for t, n, torque in DUTY_ROWS) / sum(t for t, _, _ in DUTY_ROWS)
    t_m = (sum(t * n * torque ** (10 / 3) for t, n, torque in DUTY_ROWS)
           / sum(t * n for t, n, _ in DUTY_ROWS)) ** 0.3
    for model in ("rigid", "flexible"):
        d = s["duty_cycle"][model]
        rated = min(b[model]["L10h_h"] for b in s["bearings"])
        assert d["rated_life_h"] == pytest.approx(rated, rel=1e-12)
        assert d["service_life_h"] == pytest.approx(rated * n0 * t0 ** (10 / 3) / rate, rel=1e-12)
        assert d["equivalent_torque_Nm"] == pytest.approx(t_m, rel=1e-12)
        assert d["equivalent_speed_rpm"] == pytest.approx((0.3 * 7.5 * 2 + 1.7 * 15.0) / 2.3, rel=1e-12)
    # the flexible model changes the rated life only: the service lives scale alike
    d = s["duty_cycle"]
    assert d["flexible"]["service_life_h"] / d["rigid"]["service_life_h"] == pytest.approx(
        d["flexible"]["rated_life_h"] / d["rigid"]["rated_life_h"], rel=1e-12)
    # the rated speed is the overridden one: n_b = 20·40/(40 − 39) = 800 rpm
    assert s["model"]["bearing_speed_rpm"] == pytest.approx(800.0)
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "Duty cycle (Palmgren–Miner)" in html and f"{d['flexible']['service_life_h']:.0f}" in html
    assert "duty cycle: service life" in screen and f"flexible {d['flexible']['service_life_h']:.0f} h" in screen


def test_set_overrides_are_recorded_and_stated(duty_run):
    out, s, screen = duty_run
    assert s["case"]["overrides"] == {"loads.speed_rpm": SPEED_OVERRIDE_RPM}
    assert s["case"]["matches_file"] is False
    assert s["case"]["sha256"] == file_sha256(Path(s["case"]["file"]))
    assert "loads.speed_rpm" not in s["case"]["defaults_used"] and "analysis.element_order" in s["case"]["defaults_used"]
    assert json.loads((out / "case.json").read_text(encoding="utf-8"))["loads"]["speed_rpm"] == SPEED_OVERRIDE_RPM
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "overrides: <code>loads.speed_rpm = 20.0</code>" in html
    assert "overrides: loads.speed_rpm = 20.0" in screen.splitlines()[0]


def test_field_step_keeps_a_field_every_step(duty_run):
    out, s, _ = duty_run
    angles = [f["theta_deg"] for f in s["fields"]]
    every = np.arange(0.0, 360.0, FIELD_STEP_DEG)              # all solved angles (20° step)
    for theta in every:
        assert any(math.isclose(theta, a, abs_tol=1e-9) for a in angles), theta
    # besides: the largest bearing load and the stress peaks, nothing else
    extra = {round(a, 6) for a in angles} - {round(t, 6) for t in every}
    assert extra <= {round(s["max_bearing_load"]["theta_deg"], 6), round(s["peak_von_mises_at"]["theta_deg"], 6),
                     round(s["stress"]["away_from_contacts"]["at"]["theta_deg"], 6),
                     round(s["stress"]["contact_zone"]["at"]["theta_deg"], 6)}
    assert s["stress"]["field_angles_deg"] == pytest.approx(angles)
    assert [t for t, _ in _pvd_files(out)] == pytest.approx(sorted(angles))
    for f in s["fields"]:
        assert (out / f["vtu"]).is_file() and "image" not in f


# --------------------------------------------------------------------------------------------
# The analysis without outputs; the documented keys
# --------------------------------------------------------------------------------------------


def test_analyse_writes_nothing_and_gives_the_summary_numbers(coarse_case_file, cache_dir, summary, tmp_path,
                                                              monkeypatch):
    monkeypatch.chdir(tmp_path)
    cached = sorted(p.name for p in cache_dir.iterdir())
    analysis = analyse(coarse_case_file, cache_dir=cache_dir)
    assert list(tmp_path.iterdir()) == [] and sorted(p.name for p in cache_dir.iterdir()) == cached
    built = outputs.build_summary(analysis)
    skipped = {"timings_s", "files", "fields", "images", "plots", "environment"}   # wall times, dates

    def numbers(s):
        out = {k: v for k, v in s.items() if k not in skipped}
        out["stress"] = dict(out["stress"], structural_peak={k: v for k, v in out["stress"]["structural_peak"].items()
                                                             if k != "seconds"})
        return out

    assert numbers(built) == numbers(summary)
    assert built["files"] == [] and built["images"] == {}
    assert [f["theta_deg"] for f in built["fields"]] == [f["theta_deg"] for f in summary["fields"]]
    assert json.loads(json.dumps(built, allow_nan=False)) == built


OPAQUE_KEYS = {"case.overrides", "case.defaults_used", "images", "plots", "timings_s", "environment.versions"}
"""Objects whose keys are names (case keys, files, stages), documented as a whole."""


def test_summary_keys_are_the_documented_ones(summary, duty_run, two_teeth_run):
    from rvfem.evaluate.validity import check_limits

    # no shipped case warns: the keys of a warning come from one made here
    warning = check_limits(load_ratios=[("bearing 1, flexible", 0.6)])[0].as_dict()
    written = (written_keys(summary, OPAQUE_KEYS) | written_keys(duty_run[1], OPAQUE_KEYS)
               | written_keys(two_teeth_run[1], OPAQUE_KEYS) | written_keys({"warnings": [warning]}))
    documented = documented_keys()
    assert written - documented == set(), "keys written but not in docs/outputs.md"
    assert documented - written == set(), "keys in docs/outputs.md that no run writes"


# --------------------------------------------------------------------------------------------
# The atomic result folder
# --------------------------------------------------------------------------------------------


def test_result_folder_moves_into_place_only_when_complete(tmp_path):
    out = tmp_path / "a" / "out"
    with outputs.result_folder(out) as folder:
        (folder / "x.txt").write_text("new")
        assert not out.exists() and folder.parent == out.parent
    assert sorted(p.name for p in out.iterdir()) == [outputs.RESULT_MARKER, "x.txt"]
    assert [p.name for p in out.parent.iterdir()] == ["out"]
    # an existing folder is refused before anything is written, and kept
    with pytest.raises(OutputError, match="exists and is not empty"):
        with outputs.result_folder(out):
            pytest.fail("entered")
    # a failure inside leaves the previous results as they were, and no temporary folder
    with pytest.raises(ZeroDivisionError):
        with outputs.result_folder(out, overwrite=True) as folder:
            (folder / "y.txt").write_text("half")
            1 / 0
    assert sorted(p.name for p in out.iterdir()) == [outputs.RESULT_MARKER, "x.txt"]
    assert (out / "x.txt").read_text() == "new"
    assert [p.name for p in out.parent.iterdir()] == ["out"]
    with outputs.result_folder(out, overwrite=True) as folder:
        (folder / "y.txt").write_text("complete")
    assert sorted(p.name for p in out.iterdir()) == [outputs.RESULT_MARKER, "y.txt"]
    assert [p.name for p in out.parent.iterdir()] == ["out"]


# --------------------------------------------------------------------------------------------
# The structural stress peak, numbering, angles, provenance
# --------------------------------------------------------------------------------------------


def test_structural_peak_leads_and_is_recovered_on_p2(summary, cli_run):
    st = summary["stress"]
    sp, away, cz = st["structural_peak"], st["away_from_contacts"], st["contact_zone"]
    # the headline number is the P2-recovered structural peak, at a lightening hole, away from contacts
    assert summary["peak_von_mises_MPa"] == sp["von_mises_MPa"]
    assert summary["peak_von_mises_at"] == sp["at"]
    assert sp["at"]["feature"].startswith("hole_")
    # P1 vertex stresses (averages of constant element stresses) lie low at a free edge
    assert sp["p1_MPa"] == away["peak_von_mises_MPa"] and sp["von_mises_MPa"] > sp["p1_MPa"]
    assert sp["p1_error_percent"] == pytest.approx(100 * (sp["p1_MPa"] / sp["von_mises_MPa"] - 1))
    assert 0 < sp["estimated_error_MPa"] < 0.2 * sp["von_mises_MPa"]
    assert sp["at"]["theta_deg"] in sp["angles_deg"] and sp["seconds"] > 0
    assert cz["mesh_dependent"] is True and cz["peak_von_mises_MPa"] >= away["peak_von_mises_MPa"]
    screen_lines = screen.stress_lines(st)
    assert screen_lines[0].lstrip().startswith("structural stress peak (away from contacts)")
    assert "contact-zone" in screen_lines[-1] and "mesh-dependent" in screen_lines[-1]
    html = (cli_run / "report.html").read_text(encoding="utf-8")
    assert html.index("structural stress peak") < html.index("contact-zone peak")


@pytest.mark.slow
def test_p2_recovery_matches_a_full_p2_cycle(coarse_case_file, cache_dir):
    """The P2 re-solve with the P1 cycle's forces against a P2 load cycle solved throughout
    (its own contact and roller forces): the same structural peak within 1 %."""
    p1 = analyse(coarse_case_file, cache_dir=cache_dir)
    p2 = analyse(coarse_case_file, cache_dir=cache_dir, order=2, recover_stress=False)
    rec, full = p1.stress.recovered, p2.stress.away_from_contacts
    assert rec.peak.von_mises_MPa == pytest.approx(full.von_mises_MPa, rel=0.01)
    # on the exactly 3-fold symmetric mesh the peak is reached at three places 120° apart: the
    # same place is one of them
    n = p1.system.symmetry
    turns = [np.exp(2j * np.pi * k / n) * complex(rec.peak.x_mm, rec.peak.y_mm) for k in range(n)]
    assert min(abs(z - complex(full.x_mm, full.y_mm)) for z in turns) <= 1.0
    assert p2.stress.recovered is None and p1.stress.recovered.p1_MPa == p1.stress.away_from_contacts.von_mises_MPa


@pytest.mark.slow
def test_p2_model_in_its_child_process_gives_what_it_gives_here(coarse_case_file, cache_dir):
    """The P2 re-solve of a run is made in a child process from the angles' column loads
    (rvfem.solve.cycle.AngleLoads); the same re-solve with the P2 model built in this process, from the
    cycle's results themselves, gives the same peak (to round-off: the two factorisations may
    round differently) and the same P1 value."""
    from rvfem.app.p2_model import recover_structural_peak as _recover_structural_peak

    a = analyse(coarse_case_file, cache_dir=cache_dir, attribute=False)
    here = _recover_structural_peak(a.system, a.cycle, a.mesh, a.stress.band_mm, a.stress.away_from_contacts)
    there = a.stress.recovered
    assert there.peak.von_mises_MPa == pytest.approx(here.peak.von_mises_MPa, rel=1e-12)   # measured 0
    assert (there.peak.x_mm, there.peak.y_mm, there.peak.theta_deg) == (here.peak.x_mm, here.peak.y_mm,
                                                                        here.peak.theta_deg)
    assert there.p1_at_peak_MPa == here.p1_at_peak_MPa and there.angles_deg == here.angles_deg
    assert there.estimated_error_MPa == pytest.approx(here.estimated_error_MPa, rel=1e-9, abs=1e-12)


def test_features_are_numbered_from_one(summary):
    for at in (summary["stress"]["structural_peak"]["at"], summary["stress"]["contact_zone"]["at"]):
        stem, _, number = at["feature"].rpartition("_")
        if stem in ("bore", "hole"):
            assert at["feature_label"] == f"{stem} {number}"
        assert at["feature"] not in ("bore_0", "hole_0")
    from rvfem.evaluate.postprocess import feature_label, user_feature_name

    for name in ("bore_0", "bore_2", "hole_0", "hole_5"):
        number = user_feature_name(name).rpartition("_")[2]
        assert feature_label(name).endswith(f" {number}")
    assert user_feature_name("profile") == "profile" and user_feature_name("central_hole") == "central_hole"


def _angles(obj, key=""):
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _angles(v, k)
    elif isinstance(obj, list):
        for v in obj:
            yield from _angles(v, key)
    elif isinstance(obj, float) and (key.endswith("_deg") or key == "angles_deg"):
        yield obj


def test_angles_carry_no_float_noise(summary, duty_run):
    angles = list(_angles(summary)) + list(_angles(duty_run[1]))
    assert angles
    for a in angles:
        assert a == round(a, outputs.ANGLE_DECIMALS)


def test_summary_records_date_versions_and_command(summary, monkeypatch):
    import datetime

    env = summary["environment"]
    when = datetime.datetime.strptime(env["date_utc"], "%Y-%m-%dT%H:%M:%SZ")
    assert abs((datetime.datetime.now(datetime.timezone.utc).replace(tzinfo=None) - when).total_seconds()) < 3600
    for name in ("numpy", "scipy", "scikit-fem", "gmsh", "vtk"):
        assert env["versions"][name]
    import numpy

    assert env["versions"]["numpy"] == numpy.__version__
    assert env["command_line"] is None                 # run from Python (pytest), not the command
    script = types.ModuleType("__main__")              # the console script: a plain script, no module spec
    script.__spec__ = None
    monkeypatch.setitem(sys.modules, "__main__", script)
    monkeypatch.setattr("sys.argv", ["/somewhere/bin/rvfem", "run", "a b.toml", "-o", "x"])
    assert outputs.command_line() == "rvfem run 'a b.toml' -o x"


def _main_module(spec_name):
    """A ``__main__`` module as ``python -m spec_name`` leaves it (``None``: a plain script)."""
    module = types.ModuleType("__main__")
    module.__spec__ = None if spec_name is None else importlib.machinery.ModuleSpec(spec_name, None)
    return module


@pytest.mark.parametrize("spec_name, argv0, expected", [
    # python -m pytest in a clone named rvfem: the path holds "rvfem" and ends in __main__.py
    ("pytest.__main__", "/tmp/x/rvfem/.venv/lib/python3.11/site-packages/pytest/__main__.py", None),
    ("pytest.__main__", "/tmp/x/rvfem/rvfem/__main__.py", None),
    (None, "/tmp/x/rvfem/.venv/bin/pytest", None),                # the pytest console script
    (None, "/tmp/x/rvfem/rvfem/cli.py", None),                    # a file of the package, not the command
    ("ipykernel_launcher", "/tmp/x/rvfem/ipykernel_launcher.py", None),
    (None, "/tmp/x/rvfem/.venv/bin/rvfem", "rvfem rigid c.toml"),  # the console script
    ("rvfem.__main__", "/tmp/x/site-packages/rvfem/__main__.py", "rvfem rigid c.toml"),   # python -m rvfem
    ("rvfem.app.cli", "/tmp/x/site-packages/rvfem/cli.py", "rvfem rigid c.toml"),             # python -m rvfem.app.cli
])
def test_command_line_is_decided_by_the_entry_point(spec_name, argv0, expected, monkeypatch):
    monkeypatch.setitem(sys.modules, "__main__", _main_module(spec_name))
    monkeypatch.setattr("sys.argv", [argv0, "rigid", "c.toml"])
    assert outputs.command_line() == expected


def test_duty_cycle_at_every_torque_is_palmgren_miner_of_the_fe_loads(duty_run):
    from rvfem.evaluate.iso281 import rating_life_hours

    out, s, screen = duty_run
    fe = s["duty_cycle"]["flexible_fe"]
    assert fe["torques_Nm"] == sorted({t for _, _, t in DUTY_ROWS})
    # at the case's own torque the FE loads are the run's own
    i0 = fe["torques_Nm"].index(412.0)
    assert fe["equivalent_load_N"][i0] == pytest.approx([b["flexible"]["equivalent_load_N"] for b in s["bearings"]],
                                                         rel=1e-12)
    assert fe["linear_scaling_error_percent"][i0] == pytest.approx(0.0, abs=1e-9)
    # Palmgren-Miner written out: 1/L = sum s_i/L_i per bearing, L_i the L10h at the row's F_m and speed
    c, total = s["model"]["dynamic_load_rating_N"], sum(t for t, _, _ in DUTY_ROWS)
    lives = []
    for i in range(len(s["bearings"])):
        damage = sum((t / total) / rating_life_hours(c, fe["equivalent_load_N"][fe["torques_Nm"].index(torque)][i],
                                                     n * 40 / (40 - 39))
                     for t, n, torque in DUTY_ROWS)
        lives.append(1 / damage)
    assert fe["service_life_h"] == pytest.approx(min(lives), rel=1e-12)
    assert fe["life_difference_percent"] == pytest.approx(
        100 * (fe["service_life_h"] / s["duty_cycle"]["flexible"]["service_life_h"] - 1), rel=1e-9)
    assert "flexible FE at every duty torque" in screen


def test_repository_files_are_found_from_any_folder(tmp_path, monkeypatch):
    from rvfem.app.analysis import default_cache_dir, repository_path
    from rvfem.errors import CaseError

    root = ROOT
    monkeypatch.chdir(root / "notebooks")
    assert repository_path("cases/rv40e_fanholes.toml") == root / "cases" / "rv40e_fanholes.toml"
    assert repository_path("cases/rv40e_fanholes.toml", start=root / "rvfem" / "fem") == \
        root / "cases" / "rv40e_fanholes.toml"
    with pytest.raises(CaseError, match="not found"):
        repository_path("cases/no_such_case.toml", start=tmp_path)
    # the default mesh cache does not follow the current folder
    monkeypatch.chdir(tmp_path)
    assert default_cache_dir() == root / "meshes"
    assert not (tmp_path / "meshes").exists()


def test_report_links_further_field_images_instead_of_embedding_them(cli_run, summary, coarse_case_file, tmp_path):
    """A --field-step run's extra images are linked, the key ones (saved angles, largest load,
    stress peaks) embedded: the report stays light."""
    import shutil

    from rvfem.outputs.report import key_field_angles, write_report

    folder = tmp_path / "copy"
    shutil.copytree(cli_run, folder)
    key = key_field_angles(summary, load_case(coarse_case_file))
    extra = dict(summary["fields"][0], theta_deg=333.0)          # an angle that is none of the key ones
    assert all(not math.isclose(333.0, a) for a in key)
    s = dict(summary, fields=summary["fields"] + [extra])
    html = write_report(folder / "report.html", s, load_case(coarse_case_file), folder).read_text(encoding="utf-8")
    embedded = html.count('<img src="data:image/png;base64,')
    assert embedded == len(summary["images"]) + len(summary["plots"])   # the extra one is not embedded
    assert f"<a href='{extra['image']}'>333°</a>" in html
    for f in summary["fields"]:                                          # the key angles are embedded
        assert any(math.isclose(f["theta_deg"], a, abs_tol=1e-6) for a in key)


def test_screen_gives_the_stribeck_pressure_without_roller_loads_and_stiffness_per_disc(summary):
    rigid_bore = json.loads(json.dumps(summary))
    rigid_bore["hertz"]["fe_rollers"] = None           # what the 'rigid_bore' bearing model gives
    text = screen.summary_text(rigid_bore)
    sf = summary["hertz"]["stribeck_flexible"]
    assert f"rigid rings under the FE bearing loads Q = {sf['roller_load_N']:.0f} N" in text
    assert "N·m/arcmin per disc" in text


# --------------------------------------------------------------------------------------------
# Zp − Zc = 2: no handbook, the FE against the equal share of its pin resultant
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def two_teeth_run(workspace, cache_dir) -> tuple[Path, dict, str]:
    """``rvfem run`` of the shipped two-tooth-difference case, coarse (images on: the stress
    images have no handbook forces to draw)."""
    text = (CaseText.shipped("rv40e_two_teeth")
            .set("mesh", "size_flank", "0.7").set("mesh", "size_bore", "0.8").set("mesh", "size_interior", "5.0")
            .set("analysis", "angle_step_deg", str(STEP_DEG)).set("analysis", "saved_angles_deg", "[0.0]"))
    path = text.write(workspace, "two_teeth.toml")
    out = workspace / "two_teeth"
    import contextlib
    import io

    screen = io.StringIO()
    with contextlib.redirect_stdout(screen):
        code = cli.main(["run", str(path), "-o", str(out), "--cache-dir", str(cache_dir)])
    assert code == 0
    return out, json.loads((out / "summary.json").read_text(encoding="utf-8")), screen.getvalue()


def test_two_teeth_run_says_which_references_it_compares_with(two_teeth_run):
    out, s, screen = two_teeth_run
    refs = s["references"]
    assert refs["bearing_loads"] == "equal_share"
    assert refs["equal_share"]["defined"] and "any tooth difference" in refs["equal_share"]["why"]
    for key in ("handbook", "classical_pin_forces"):
        assert not refs[key]["defined"] and refs[key]["why"].startswith("not defined for Zp − Zc ≠ 1")
    assert s["model"]["handbook_k_y"] is None and s["hertz"]["stribeck_rigid"] is None
    assert s["model"]["bearing_speed_rpm"] == pytest.approx(15.0 * 40 / 2)
    assert "bearing loads compared with the equal share of the FE pin resultant" in screen
    assert screen.count("not defined for Zp − Zc ≠ 1") >= 3 + 2
    import html as html_module

    report = html_module.unescape((out / "report.html").read_text(encoding="utf-8"))
    assert "equal share of the FE pin resultant vs flexible disc" in report
    assert refs["handbook"]["why"] in report and refs["classical_pin_forces"]["why"] in report
    assert "rigid handbook (dashed)" not in report


def test_two_teeth_deltas_are_against_the_equal_share_and_the_attribution_starts_there(two_teeth_run):
    out, s, _ = two_teeth_run
    for b in s["bearings"]:
        f, e = b["flexible"], b["equal_share"]
        assert b["rigid"] is None
        assert b["delta_max_percent"] == pytest.approx(100 * (f["max_load_N"] / e["max_load_N"] - 1), rel=1e-12)
        assert b["delta_equivalent_percent"] == pytest.approx(
            100 * (f["equivalent_load_N"] / e["equivalent_load_N"] - 1), rel=1e-12)
        assert b["life_ratio"] == pytest.approx((e["equivalent_load_N"] / f["equivalent_load_N"]) ** (10 / 3), rel=1e-12)
    steps = [r["step"] for r in s["attribution"] if r["bearing"] == 1]
    assert steps[0] == "equal_share" and "handbook" not in steps
    for r, b in zip([r for r in s["attribution"] if r["step"] == "equal_share"], s["bearings"]):
        assert r["max_N"] == pytest.approx(b["equal_share"]["max_load_N"], rel=1e-12)
        assert r["delta_max_percent"] == 0.0
    for r, b in zip([r for r in s["attribution"] if r["final"]], s["bearings"]):
        assert r["delta_max_percent"] == pytest.approx(b["delta_max_percent"], rel=1e-9)


def test_two_teeth_tables_leave_the_undefined_references_empty(two_teeth_run):
    out, s, _ = two_teeth_run
    rows = _read_csv(out / "bearing_loads.csv")
    for b in s["bearings"]:
        i = b["bearing"]
        assert all(math.isnan(float(r[f"bearing{i}_rigid_F_N"])) for r in rows)
        share = np.array([float(r[f"bearing{i}_equal_share_F_N"]) for r in rows])
        assert share.max() == pytest.approx(b["equal_share"]["max_load_N"], rel=1e-9)
    pins = _read_csv(out / "pin_forces.csv")
    assert all(math.isnan(float(r["classical_N"])) for r in pins)
    assert {"bearing_loads", "pin_forces", "pins_in_contact"} <= set(s["plots"])
    assert any(k.startswith("stress_theta_") for k in s["images"])
