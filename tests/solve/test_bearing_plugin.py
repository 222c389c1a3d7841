"""A crank-bearing model written outside the package runs end to end through the registry: the case
reader accepts its name, the command line solves with it, and the report states its assumption.

The model here is a linear isotropic bore spring: each bore is loaded through its x and y
footprint columns with a uniform (not cosine) weighting, behind one spring of fixed stiffness per
direction. It differs from the built-in ``rigid_bore`` only in how the force is spread over the
bore, so the bearing loads must agree closely, and equilibrium must close to round-off.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import CASES_DIR

from rvfem.app import cli
from rvfem.case import registry
from rvfem.solve import contact
from rvfem.solve.models import ContactGroup

STIFFNESS = 7.0e5


class LinearBoreSpring:
    name = "test_bore_spring"

    def __init__(self, case, stiffness_scale: float = 1.0):
        self.case = case
        self.stiffness = STIFFNESS * stiffness_scale

    def describe(self) -> str:
        return f"a linear isotropic bore spring of {self.stiffness:.3g} N/mm loading the bore uniformly"

    def contacts(self, interface, centres, theta):
        rows, cols, vals, names, bearing = [], [], [], [], []
        for i, c in enumerate(centres):
            grid = interface.grids[f"bore_{i}"]
            d = interface.points[grid.offset:grid.offset + grid.count] - c
            d /= np.linalg.norm(d, axis=1)[:, None]
            for k in range(2):
                # uniform radial pushes on the half of the bore facing +axis k, uniform pulls on the
                # other half, scaled so that the resultant is a unit force along axis k
                pos, neg = d[:, k] > 0, d[:, k] < 0
                w = 0.5 * (pos / d[pos, k].sum() - neg / -d[neg, k].sum())
                rows.append(grid.offset + np.arange(grid.count))
                cols.append(np.full(grid.count, len(names)))
                vals.append(w)
                names.append(f"bearing {i + 1} {'xy'[k]}")
                bearing.append(i)
        n = len(names)
        W = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(interface.n_columns, n))
        return ContactGroup(W=W, signorini=np.zeros(n, dtype=bool), gap0=np.zeros(n), offset=np.zeros(n),
                            laws=[(np.arange(n), contact.linear_law(self.stiffness, bilateral=True))],
                            names=names, bearing=np.asarray(bearing))

    def bearing_forces(self, vectors, forces, theta):
        return vectors.reshape(self.case.cranks.count, 2, 2).sum(axis=1), None, None


@pytest.fixture
def plugin(registries):
    """The bore spring registered as a crank-bearing model for one test (the registries fixture
    removes it afterwards)."""
    return registry.register_bearing_model(LinearBoreSpring)


def _run(tmp_path, model: str) -> dict:
    out = tmp_path / model
    argv = ["run", str(CASES_DIR / "rv40e.toml"), "-o", str(out), "--no-images", "--cache-dir",
            str(tmp_path / "meshes"), "--set", f'crank_bearing.model="{model}"',
            "--set", f"crank_bearing.rigid_bore_stiffness_N_per_mm={STIFFNESS}"]
    for s in ("mesh.size_flank=0.6", "mesh.size_bore=0.6", "mesh.size_interior=4.0", "analysis.angle_step_deg=10"):
        argv += ["--set", s]
    assert cli.main(argv) == 0
    return json.loads((out / "summary.json").read_text(encoding="utf-8")), (out / "report.html").read_text("utf-8")


@pytest.mark.slow
def test_a_bearing_model_registered_outside_the_package_runs_end_to_end(plugin, tmp_path):
    assert plugin.name in registry.bearing_model_names()
    summary, report = _run(tmp_path, plugin.name)
    assert summary["model"]["bearing_model"] == plugin.name
    assert "loading the bore uniformly" in report
    assert summary["equilibrium_residual"] < 1e-12
    builtin, _ = _run(tmp_path, "rigid_bore")
    for ours, ref in zip(summary["bearings"], builtin["bearings"]):
        # same spring, another spreading of the force over the bore: loads within a few per cent
        assert ours["flexible"]["max_load_N"] == pytest.approx(ref["flexible"]["max_load_N"], rel=0.03)
        assert ours["rigid"]["max_load_N"] == ref["rigid"]["max_load_N"]


def test_an_unregistered_model_name_is_a_case_error_naming_the_key(tmp_path, capsys):
    code = cli.main(["check", str(CASES_DIR / "rv40e.toml"), "--set", 'crank_bearing.model="test_bore_spring"'])
    assert code == 2
    err = capsys.readouterr().err
    assert "crank_bearing.model" in err and len(err.strip().splitlines()) == 1
