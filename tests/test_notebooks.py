"""The notebooks run: their code cells are executed in order (coarser angle step to stay fast)."""

from __future__ import annotations

import json

import matplotlib
import pytest

from conftest import ROOT

matplotlib.use("Agg")


# design_study.ipynb runs a Dask study; tests/test_study.py executes it with nbclient from its folder
@pytest.mark.parametrize("path", [p for p in sorted((ROOT / "notebooks").glob("*.ipynb")) if p.stem != "design_study"],
                         ids=lambda p: p.stem)
def test_notebook_code_cells_run(path, monkeypatch, tmp_path):
    monkeypatch.chdir(ROOT)
    nb = json.loads(path.read_text(encoding="utf-8"))
    namespace: dict = {}
    for cell in nb["cells"]:
        if cell["cell_type"] != "code":
            continue
        source = "".join(cell["source"]).replace("STEP_DEG = 1.0", "STEP_DEG = 20.0")
        source = source.replace('MESH_CACHE = "meshes"', f"MESH_CACHE = {str(tmp_path)!r}")
        exec(compile(source, f"{path.name}", "exec"), namespace)
    assert namespace["comparison"].bearings[0].flexible.max_N > 0
    if "analysis" in namespace:  # the one-call analysis gives the stage-by-stage numbers
        for staged, one_call in zip(namespace["comparison"].bearings, namespace["analysis"].comparison.bearings):
            assert one_call.flexible.max_N == pytest.approx(staged.flexible.max_N, rel=1e-9)
            assert one_call.rigid.equivalent_N == pytest.approx(staged.rigid.equivalent_N, rel=1e-9)
