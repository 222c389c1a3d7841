"""The result sections: declared once, documented from their declarations, open to a section from
outside rvfem (a trial plug-in, tests/results/plugins/torque_balance.py, one module and one
registration line)."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest
from conftest import CASES_DIR, ROOT, documented_keys

from rvfem.app import cli
from rvfem.app.analysis import STAGES
from rvfem.outputs.registry import writers
from rvfem.results import registry
from rvfem.results.registry import register_section


def test_the_key_table_of_the_outputs_doc_is_generated_from_the_sections():
    doc = ROOT / "docs" / "outputs.md"
    text = doc.read_text(encoding="utf-8")
    assert registry.render_outputs_doc(text) == text, (
        "docs/outputs.md's key table is stale; regenerate it with: python -m rvfem.results.registry docs/outputs.md")
    assert registry.main(["--check", str(doc)]) == 0


def test_sections_are_named_once_and_computed_in_a_known_stage():
    names = [s.name for s in registry.sections()]
    assert len(names) == len(set(names)) and names[-1] == "files"
    for s in registry.sections():
        assert s.keys, f"section {s.name} documents no key"
        assert s.stage is None or s.stage in STAGES, s.name
        assert s.compute is not None or not s.requires, s.name


def test_a_second_section_of_a_taken_name_is_refused(registries):
    with pytest.raises(ValueError, match="already registered"):
        register_section(registry.section("accuracy"))
    with pytest.raises(KeyError, match="no result section 'nothing'"):
        registry.section("nothing")


@pytest.mark.slow
def test_a_section_from_outside_adds_a_key_a_screen_line_a_report_row_and_a_file(registries, tmp_path):
    from plugins import torque_balance

    register_section(torque_balance.SECTION)                 # the one registration line
    assert any(w.name == "torque_balance_csv" for w in writers(images=False))
    out = tmp_path / "out"
    argv = ["run", str(CASES_DIR / "rv40e_fanholes.toml"), "-o", str(out), "--no-images", "--step", "30",
            "--cache-dir", str(tmp_path / "meshes")]
    for s in ("mesh.size_flank=0.6", "mesh.size_bore=0.6", "mesh.size_interior=4.0"):
        argv += ["--set", s]
    screen = io.StringIO()
    with contextlib.redirect_stdout(screen):
        assert cli.main(argv) == 0
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    balance = summary["torque_balance"]
    # two conservation laws: the discs carry the output torque, the bearing forces the disc torque
    assert balance["output_torque_error"] < 1e-9
    assert balance["bearing_moment_error"] < 1e-9
    assert "torque_balance.csv" in summary["files"]
    lines = (out / "torque_balance.csv").read_text(encoding="utf-8").splitlines()
    assert lines[0].startswith("theta_deg,disc_1_torque_Nmm,disc_2_torque_Nmm") and len(lines) == 1 + 12
    assert any(line.startswith("  torque balance: Σ T_disc vs T_out") for line in screen.getvalue().splitlines())
    assert "torque balance (Σ T_disc − T_out" in (out / "report.html").read_text(encoding="utf-8")
    # its documented keys are the keys it writes, and the built-in table does not list them
    assert {"torque_balance", "torque_balance.output_torque_error"} <= set(
        k for row in torque_balance.SECTION.keys for k in _names(row.keys))
    assert "torque_balance" not in documented_keys()


def _names(cell: str) -> list[str]:
    import re

    return re.findall(r"`([^`]+)`", cell)


def test_the_registries_fixture_removes_the_section_again():
    assert "torque_balance" not in [s.name for s in registry.sections()]
    assert Path(__file__).with_name("plugins").is_dir()
