"""rvfem compare: ratios B / A of two results, against known scalings and the ISO 281 life law."""

from __future__ import annotations

import csv
import html
import json
import shutil

import pytest
from conftest import ROOT

from rvfem.app import cli
from rvfem.app.cli_study import COMPARE, STUDY
from rvfem.app.result_compare import compare_results, read_result
from rvfem.app.run import run_case
from rvfem.errors import OutputError

COARSE = ["mesh.size_flank=1.2", "mesh.size_bore=1.5", "mesh.size_interior=6.0", "mesh.size_hole=2.0",
          "analysis.angle_step_deg=30"]


def _main(argv, monkeypatch) -> int:
    names = {s.name for s in cli.SUBCOMMANDS}
    subs = cli.SUBCOMMANDS + tuple(c for c in (COMPARE, STUDY) if c.name not in names)
    build = cli.build_parser
    monkeypatch.setattr(cli, "build_parser", lambda subcommands=None: build(subs))
    return cli.main([str(a) for a in argv])


@pytest.fixture(scope="module")
def solid_result(tmp_path_factory):
    from rvfem.case.definition import load_case

    tmp = tmp_path_factory.mktemp("compare")
    case = load_case(ROOT / "cases" / "rv40e_solid.toml", COARSE)
    run_case(case, tmp / "solid", images=False, cache_dir=tmp / "meshes")
    return tmp / "solid"


def _scaled_copy(folder, out, factor: float):
    """A copy of a result folder with every flexible load scaled by ``factor`` (F_m too, so
    L10h scales by factor^(-10/3))."""
    shutil.copytree(folder, out)
    summary = json.loads((out / "summary.json").read_text())
    for b in summary["bearings"]:
        f = b["flexible"]
        for key in ("max_load_N", "min_load_N", "equivalent_load_N"):
            f[key] *= factor
        f["L10h_h"] *= factor ** (-10.0 / 3.0)
    (out / "summary.json").write_text(json.dumps(summary))
    with open(out / "bearing_loads.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    for row in rows:
        for key in row:
            if "_flexible_" in key:
                row[key] = repr(float(row[key]) * factor)
    with open(out / "bearing_loads.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return out


def test_ratios_against_a_known_scaling(solid_result, tmp_path):
    a = read_result(solid_result)
    b = read_result(_scaled_copy(solid_result, tmp_path / "scaled", 1.1))
    c = compare_results(a, b)
    assert len(c["bearings"]) == 3
    for row in c["bearings"]:
        assert row["ratio"]["max_load_N"] == pytest.approx(1.1, rel=1e-12)
        assert row["ratio"]["min_load_N"] == pytest.approx(1.1, rel=1e-12)
        assert row["ratio"]["equivalent_load_N"] == pytest.approx(1.1, rel=1e-12)
        assert row["ratio"]["L10h_h"] == pytest.approx(1.1 ** (-10 / 3), rel=1e-12)
    assert c["overall"]["ratio"]["handbook_max_load_N"] == 1.0
    assert c["life_ratio_from_load"] == pytest.approx(c["overall"]["ratio"]["L10h_h"], rel=1e-12)
    assert c["warnings"] == []
    same = compare_results(a, a)
    assert all(v == 1.0 for row in same["bearings"] for v in row["ratio"].values())
    assert b.flexible_N == pytest.approx(1.1 * a.flexible_N, rel=1e-9)


def test_compare_folders_json_plot_and_page(solid_result, tmp_path, monkeypatch, capsys):
    b = _scaled_copy(solid_result, tmp_path / "scaled", 0.9)
    code = _main(["compare", solid_result, b, "--json", "-o", tmp_path / "cmp"], monkeypatch)
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["ratio_is"] == "B / A"
    assert out["overall"]["ratio"]["max_load_N"] == pytest.approx(0.9, rel=1e-12)
    assert (tmp_path / "cmp" / "compare.png").stat().st_size > 10_000
    page = (tmp_path / "cmp" / "compare.html").read_text()
    assert "data:image/png;base64," in page and "B/A" in page
    code = _main(["compare", solid_result, b], monkeypatch)
    text = capsys.readouterr().out
    assert code == 0 and "largest load -10.0 %" in text and "L10h × 1.42" in text
    # both stress peaks are structural peaks away from the contacts: the headline P2 re-solve and
    # the P1 cycle's envelope, each labelled with its element order (screen and page)
    for label in ("structural peak (P2, away from contacts), MPa",
                  "structural peak, P1 cycle (away from contacts), MPa"):
        assert label in text and html.escape(label) in page
    assert "peak von Mises" not in text and "peak away from contacts" not in text


def test_comparison_figure_leaves_the_backend_alone(solid_result, tmp_path):
    """The figure is drawn without pyplot: a notebook's inline backend stays on."""
    import matplotlib
    from matplotlib.figure import Figure

    from rvfem.app.result_compare import comparison_figure, comparison_plot

    before = matplotlib.get_backend()
    matplotlib.use("svg")   # stands for a notebook's inline backend
    try:
        a = read_result(solid_result)
        fig = comparison_figure(a, a)
        assert isinstance(fig, Figure) and len(fig.axes[0].lines) == 2 * a.flexible_N.shape[1] + 1
        path = comparison_plot(a, a, tmp_path / "sub" / "c.png")
        assert path.stat().st_size > 10_000
        assert matplotlib.get_backend() == "svg"
    finally:
        matplotlib.use(before)


def test_missing_result_is_one_line(tmp_path, monkeypatch, capsys):
    (tmp_path / "empty").mkdir()
    with pytest.raises(OutputError, match="summary.json: cannot read it"):
        read_result(tmp_path / "empty")
    code = _main(["compare", tmp_path / "empty", tmp_path / "nowhere"], monkeypatch)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "summary.json" in err


def test_holes_against_solid_from_case_files(tmp_path, monkeypatch, capsys):
    """The pair as case files (run on a coarse mesh): holes raise the loads and cost life; the
    handbook is the same for both; the life ratio follows F_m by the ISO 281 exponent."""
    argv = ["compare", ROOT / "cases" / "rv40e_solid.toml", ROOT / "cases" / "rv40e_fanholes.toml", "--json",
            "--cache-dir", tmp_path / "meshes"]
    for item in COARSE:
        argv += ["--set", item]
    assert _main(argv, monkeypatch) == 0
    c = json.loads(capsys.readouterr().out)
    assert c["a"]["label"] == "rv40e_solid" and c["b"]["label"] == "rv40e_fanholes"
    assert c["overall"]["ratio"]["handbook_max_load_N"] == 1.0
    # the holes raise the largest load; by how much depends on the reducer stage (two discs on
    # crankshafts with Hertz pins: about 2 points, one disc with T/2: about 10; docs/theory.md § 9)
    assert c["overall"]["ratio"]["max_load_N"] > 1.0
    assert c["overall"]["ratio"]["peak_away_from_contacts_MPa"] > 1.5  # the hole fillets
    for row in c["bearings"]:
        r = row["ratio"]
        assert r["equivalent_load_N"] > 1.0 and r["L10h_h"] < 1.0
        assert r["L10h_h"] == pytest.approx(r["equivalent_load_N"] ** (-10 / 3), rel=1e-9)
    bad = _main(["compare", ROOT / "cases" / "rv40e_solid.toml", ROOT / "cases" / "rv40e_fanholes.toml",
                 "--set", "crank_bearing.rolers=14"], monkeypatch)
    err = capsys.readouterr().err.strip()
    assert bad == 2 and "crank_bearing.rolers" in err and "did you mean" in err and len(err.splitlines()) == 1


def test_headline_leads_with_mass_and_inertia_and_ends_with_the_lamina_life():
    """The comparison's first line: mass and inertia first, then loads and lives, B against A; the
    L10r ratio only where both results have the crank bearing in depth."""
    from rvfem.app.result_compare import headline

    ratio = {"disc_mass_kg": 0.713, "disc_polar_inertia_kg_mm2": 0.818, "max_load_N": 1.023,
             "equivalent_load_N": 1.034, "L10h_h": 0.895, "L10r_h": 0.591}
    assert headline({"overall": {"ratio": ratio}}) == ("B against A: mass −28.7 %, inertia −18.2 %, largest load "
                                                      "+2.3 %, equivalent load +3.4 %, L10h × 0.90, L10r × 0.59")
    assert "L10r" not in headline({"overall": {"ratio": dict(ratio, L10r_h=None)}})
