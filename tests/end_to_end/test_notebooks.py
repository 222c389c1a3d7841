"""The notebooks run as Jupyter runs them: executed with nbclient, in a fresh ``python3`` kernel
started in the notebook's own folder (``notebooks/``), as ``jupyter nbconvert --execute``, VS Code
and JupyterLab do. Only the parameters are changed (a coarser crank-angle step, a private mesh
cache) to stay fast; what the notebooks compute is then checked against physics.

``notebooks/design_study.ipynb`` and ``notebooks/what_drives_the_flexibility_effect.ipynb`` have
their own test files (tests/end_to_end/test_study.py, tests/app/test_verification.py). Every notebook's figures
must be in its executed outputs (``conftest.assert_figures_shown``): rvfem draws its own figures
without pyplot, so a notebook's inline backend stays on.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from conftest import ROOT, assert_figures_shown

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NOTEBOOKS = sorted(p for p in (ROOT / "notebooks").glob("*.ipynb")
                   if p.stem not in ("design_study", "what_drives_the_flexibility_effect"))
STEP_DEG = 20.0
"""Crank-angle step the tests run the notebooks with (a whole divisor of 120°: the three bearings'
curves are then exact shifts of each other on the sampled angles)."""

REPORT_CELL = """
import json as _json, math as _math
_out = {}
for _name in ("case", "one", "result", "comparison", "analysis", "profile_results"):
    _v = globals().get(_name)
    if _v is None:
        continue
    if _name == "one":
        _out["one"] = {"residual": float(_v.solution.residual["relative"]), "pins": int(_v.pins_in_contact),
                       "loads": [float(x) for x in _v.bearing_loads]}
    elif _name == "comparison":
        _out["comparison"] = [{"rigid_max": b.rigid.max_N, "flex_max": b.flexible.max_N,
                               "rigid_Fm": b.rigid.equivalent_N, "flex_Fm": b.flexible.equivalent_N,
                               "life_ratio": b.life_ratio, "rigid_L": b.rigid.L10h, "flex_L": b.flexible.L10h}
                              for b in _v.bearings]
    elif _name == "result":
        _out["result"] = {"pins_min": int(_v.pins_in_contact.min()), "pins_max": int(_v.pins_in_contact.max()),
                          "residual": float(_v.equilibrium_residual.max())}
    elif _name == "analysis":
        _r = _v.stress.recovered
        _out["analysis"] = {"flex_max": [b.flexible.max_N for b in _v.comparison.bearings],
                            "structural": None if _r is None else _r.peak.von_mises_MPa,
                            "p1": None if _r is None else _r.p1_MPa,
                            "feature": None if _r is None else _r.peak.feature,
                            "contact_zone": _v.stress.peak.von_mises_MPa}
    elif _name == "profile_results":
        _out["profile_results"] = _v
    elif _name == "case":
        _out["case"] = {"pins": _v.pins.count, "cranks": _v.cranks.count, "torque": _v.loads.disc_torque_Nmm,
                        "exponent": _v.analysis.equivalent_load_exponent}
print("RVFEM-NOTEBOOK-CHECK " + _json.dumps(_out))
"""


def _execute(path: Path, cache: Path) -> tuple[dict, str]:
    """Execute a notebook like Jupyter (kernel started in its folder); its check values and its
    printed text."""
    nb = nbformat.read(path, as_version=4)
    for cell in nb.cells:
        if cell.cell_type == "code":
            cell.source = (cell.source.replace("STEP_DEG = 1.0", f"STEP_DEG = {STEP_DEG}")
                           .replace("MESH_CACHE = None", f"MESH_CACHE = {str(cache)!r}"))
    nb.cells.append(nbformat.v4.new_code_cell(REPORT_CELL))
    client = nbclient.NotebookClient(nb, kernel_name="python3", timeout=900,
                                     resources={"metadata": {"path": str(path.parent)}})
    client.execute()
    assert_figures_shown(nb)
    text = []
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            if out.get("output_type") == "stream":
                text.append(out["text"])
            elif "data" in out and "text/plain" in out["data"]:
                text.append(out["data"]["text/plain"])
    printed = "".join(text)
    line = next(s for s in printed.splitlines() if s.startswith("RVFEM-NOTEBOOK-CHECK "))
    return json.loads(line.split(" ", 1)[1]), printed


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs_from_its_own_folder(path, tmp_path):
    checks, printed = _execute(path, tmp_path / "meshes")
    assert "bearing 0" not in printed            # numbered from 1, like every output
    if path.stem == "flexible_vs_rigid":
        _check_flexible_vs_rigid(checks, printed)
    if path.stem == "roller_profiles":
        _check_roller_profiles(checks["profile_results"], printed)


def _check_roller_profiles(r: dict, printed: str) -> None:
    straight, arc = r["straight"], r["arc R = 500 mm"]
    log, comb = r["logarithmic"], r["combined a = 1.23 mm, b = 6 µm"]
    # the straight roller peaks at its ends, the arc at its centre (Zhang et al.); the
    # logarithmic profile designed for the largest roller load is nearly flat there
    assert straight["x_peak"] > 4.0 and arc["x_peak"] < 0.5
    assert log["edge"] < 1.1 < straight["edge"]
    # the profile changes neither the basic life nor the film (same loads, same nominal line load)
    for v in r.values():
        assert v["L10h"] == pytest.approx(straight["L10h"], rel=1e-12)
        assert v["h_min"] == pytest.approx(straight["h_min"], rel=1e-12)
    # the pressure peak orders the lamina lives: the highest peak (arc) has the shortest L10r
    assert arc["L10r"] == min(v["L10r"] for v in r.values())
    assert "lowest peak with" in printed


def _check_flexible_vs_rigid(c: dict, printed: str) -> None:
    zp, n = c["case"]["pins"], c["case"]["cranks"]
    # one crank angle: disc and carrier in equilibrium to round-off; part of the pins carry load
    # (about half in the rigid classical distribution; fewer with the modified profile)
    assert c["one"]["residual"] < 1e-9
    assert zp / 5 <= c["one"]["pins"] <= zp / 2 + 1
    assert c["result"]["residual"] < 1e-9
    bearings = c["comparison"]
    assert len(bearings) == n
    # 360°/N symmetry: the N bearings see the same extremes
    for b in bearings[1:]:
        assert b["flex_max"] == pytest.approx(bearings[0]["flex_max"], rel=1e-3)
        assert b["rigid_max"] == pytest.approx(bearings[0]["rigid_max"], rel=1e-9)
    for b in bearings:
        # fan-hole disc: the flexible disc loads the most loaded bearing more than the handbook
        assert b["flex_max"] > b["rigid_max"]
        # the life ratio is ISO 281's (F_rigid/F_flex)^(10/3) and the lives' ratio
        assert b["life_ratio"] == pytest.approx((b["rigid_Fm"] / b["flex_Fm"]) ** (10.0 / 3.0), rel=1e-9)
        assert b["life_ratio"] == pytest.approx(b["flex_L"] / b["rigid_L"], rel=1e-9)
    # the one-call analysis gives the stage-by-stage numbers
    for staged, one_call in zip(bearings, c["analysis"]["flex_max"]):
        assert one_call == pytest.approx(staged["flex_max"], rel=1e-9)
    # the structural peak: at a lightening hole, the P2 re-solve above the P1 envelope (P1 vertex
    # stresses lie low at a free edge)
    a = c["analysis"]
    assert a["feature"].startswith("hole_")
    assert a["structural"] > a["p1"]
    assert math.isfinite(a["contact_zone"])
    assert "bearing 1:" in printed and f"bearing {n}:" in printed
