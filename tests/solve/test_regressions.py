"""Valid cases an earlier rvfem refused, and the causes fixed for them.

* Every case file in tests/regressions/ passes ``rvfem check`` and ``rvfem run`` (exit 0).
* The cause of the three refused in 0.4-dev: rigid pins with a backlash all round (an equidistant
  modification with a negative shift: at zero load no pin touches) gave the cold start of a
  contact solve no active pin, and its first Newton matrix was singular (the disc and the carrier
  turn freely through the backlash). Checked on a model small enough to state its answer: a
  uniform gap g at pins of radius r_p is closed by a rigid rotation g/r_p of the disc and the
  carrier, so the forces are those without a gap and both rotations grow by exactly g/r_p.
* A secondary analysis may not refuse a case whose load cycle solved: an attribution step that
  does not solve is left out with a warning that says why.
"""

from __future__ import annotations

import types

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import CASES_DIR, REGRESSIONS_DIR

from rvfem.app import cli
from rvfem.case.definition import load_case
from rvfem.errors import ContactError
from rvfem.evaluate import attribution as attribution_module
from rvfem.evaluate.rigid import handbook_bearing_loads, load_cycle_angles
from rvfem.solve import contact

REGRESSIONS = REGRESSIONS_DIR
CASE_FILES = sorted(REGRESSIONS.glob("*.toml"))


# ------------------------------------------------------------------------------------------------
# the cause: a cold start with every rigid pin open
# ------------------------------------------------------------------------------------------------


class _ColumnCompliance:
    """A disc whose interface columns are independent springs: C = diag(c), mm/N."""

    def __init__(self, c):
        self.C = np.asfortranarray(np.diag(c))

    def ensure(self, cols):
        pass


def _rigid_pin_disc(gaps, torque=2.0e5, r_pin=64.0, r_crank=36.0, c_pin=2e-6, c_bore=1e-7, k_bearing=2e5):
    """Solve a disc held by ``len(gaps)`` rigid pins on radius ``r_pin`` (mm), each pushing against
    the disc's rotation with the initial gap ``gaps[i]`` (mm), and three cranks on ``r_crank`` with
    x and y springs of ``k_bearing`` (N/mm) to the carrier, which carries ``torque`` (N·mm). One
    interface column per contact, of compliance ``c_pin`` or ``c_bore`` (mm/N)."""
    n = len(gaps)
    a = 2 * np.pi * np.arange(n) / n
    pin_points, pin_dirs = r_pin * np.c_[np.cos(a), np.sin(a)], np.c_[np.sin(a), -np.cos(a)]
    c = np.radians([90.0, 210.0, 330.0])
    bore_points, bore_dirs = np.repeat(r_crank * np.c_[np.cos(c), np.sin(c)], 2, axis=0), np.tile(np.eye(2), (3, 1))
    points, dirs = np.r_[pin_points, bore_points], np.r_[pin_dirs, bore_dirs]
    resultants = np.c_[dirs, points[:, 0] * dirs[:, 1] - points[:, 1] * dirs[:, 0]]   # Fx, Fy, Mz
    m = len(points)
    cset = contact.ContactSet(
        sp.identity(m, format="csc"), np.r_[np.ones(n, bool), np.zeros(6, bool)], np.r_[gaps, np.zeros(6)],
        np.zeros(m), np.r_[np.zeros(n), resultants[n:, 2]],
        [(np.arange(n, m), contact.linear_law(k_bearing, bilateral=True))])
    body = contact.Body(cset, contact.Interface(None, points, dirs, resultants, {}, {}),
                        _ColumnCompliance(np.r_[np.full(n, c_pin), np.full(6, c_bore)]))
    return contact.solve_bodies([body], torque, label="at crank angle 0.00° ")[0]


def test_backlash_all_round_is_closed_by_a_rigid_rotation():
    """A uniform gap at every pin (exact symmetry: 0.4-dev stopped here as "a mechanism")."""
    r_pin, g, n = 64.0, 0.015, 12
    closed = _rigid_pin_disc(np.zeros(n), r_pin=r_pin)
    open_ = _rigid_pin_disc(np.full(n, g), r_pin=r_pin)
    scale = closed.force.max()
    np.testing.assert_allclose(open_.force, closed.force, rtol=0, atol=1e-9 * scale)
    assert open_.rigid[2] - closed.rigid[2] == pytest.approx(g / r_pin, rel=1e-9)
    assert open_.carrier_rotation - closed.carrier_rotation == pytest.approx(g / r_pin, rel=1e-9)
    # and the zero-gap answer itself: the torque is shared equally by the n pins
    assert closed.force[:n] == pytest.approx(np.full(n, 2.0e5 / (n * r_pin)), rel=1e-9)


def test_uneven_backlash_meets_the_signorini_conditions():
    """Gaps of 15–19 µm (a pitch error inside the backlash): no pin touches at zero load; the
    solution closes some, and holds λ ≥ 0, g ≥ 0, λ·g = 0 and the carrier's equilibrium."""
    gaps = 0.015 + 0.004 * np.random.default_rng(7).random(12)
    sol = _rigid_pin_disc(gaps)
    lam, gap = sol.force[:12], sol.gap[:12]
    assert lam.min() >= 0 and gap.min() >= -1e-9 and np.all(np.abs(lam * gap) <= 1e-9 * lam.max())
    assert 0 < np.count_nonzero(lam) < 12
    assert sol.residual["carrier_Nmm"] <= 1e-9 * 2.0e5 and sol.residual["relative"] <= 1e-9


def test_first_to_close_picks_the_smallest_gap_per_moment_arm_on_the_torque_side():
    gaps = np.array([0.02, 0.012, 0.016, 0.001])
    moment = np.array([-64.0, -32.0, -64.0, 64.0])       # the last pin is on the other side
    problem = types.SimpleNamespace(carrier=True, torque=1.0, moment=moment, sig=np.ones(4, bool),
                                    gap0=gaps, offs=np.array([0, 4]), nc=4)
    none_active = np.zeros(4, bool)
    # gap / arm: 0.02/64, 0.012/32 = 0.000375, 0.016/64 = 0.00025: the third closes first
    assert contact.first_to_close(problem, none_active).tolist() == [False, False, True, False]
    # a body already held on the torque's side gets nothing more
    assert not contact.first_to_close(problem, np.array([True, False, False, False])).any()
    # no carrier torque: no side to close
    assert not contact.first_to_close(types.SimpleNamespace(**{**vars(problem), "torque": 0.0}), none_active).any()


# ------------------------------------------------------------------------------------------------
# a secondary analysis never refuses a case whose cycle solved
# ------------------------------------------------------------------------------------------------


def test_attribution_step_that_does_not_solve_is_left_out_with_a_warning(monkeypatch):
    case = load_case(CASES_DIR / "rv40e_fanholes.toml")
    thetas = load_cycle_angles(30.0)
    final = attribution_module.case_step(case)
    n = case.cranks.count
    own = types.SimpleNamespace(bearing_loads=np.full((len(thetas), n), 3000.0))
    two = types.SimpleNamespace(bearing_loads=np.full((len(thetas), n), 3100.0))
    assert final == "crankshafts" and attribution_module.handbook_applicable(case)[0]

    def load_cycle(system, thetas, saved_angles_deg, stage):
        if stage == "one_disc":
            raise ContactError("the contact problem at crank angle 0.00° is a mechanism")
        return two

    monkeypatch.setattr(attribution_module, "build_stage",
                        lambda system, discs, influence: "one_disc" if discs == 1 else "two_discs")
    monkeypatch.setattr(attribution_module, "build_components", lambda stage, steps: stage)
    monkeypatch.setattr(attribution_module, "load_cycle", load_cycle)
    result = attribution_module.attribution(types.SimpleNamespace(case=case), thetas, cycles={final: own})
    assert [s.key for s in result.steps] == ["handbook", "two_discs", "crankshafts"]
    assert dict(result.skipped).keys() == {"one_disc", "equal_share"}
    assert "mechanism" in dict(result.skipped)["one_disc"]
    np.testing.assert_array_equal(result.step("handbook").loads, handbook_bearing_loads(case, thetas).magnitude)
    rows = result.table(case.analysis.equivalent_load_exponent)
    assert {r["step"] for r in rows} == {"handbook", "two_discs", "crankshafts"}
    warnings = attribution_module.skipped_warnings(result)
    assert [w.code for w in warnings] == ["not_computed", "not_computed"]
    assert "one_disc" in warnings[0].message and "mechanism" in warnings[0].message
    assert attribution_module.skipped_warnings(None) == ()

    # the case's own step is the main result: if it is not given and does not solve, that is an error
    monkeypatch.setattr(attribution_module, "load_cycle",
                        lambda *a, **k: (_ for _ in ()).throw(ContactError("does not settle")))
    with pytest.raises(ContactError):
        attribution_module.attribution(types.SimpleNamespace(case=case), thetas, cycles={})


# ------------------------------------------------------------------------------------------------
# every regression case file, end to end
# ------------------------------------------------------------------------------------------------


def test_regression_folder_is_not_empty():
    assert len(CASE_FILES) >= 3


@pytest.mark.slow
@pytest.mark.parametrize("path", CASE_FILES, ids=[p.stem for p in CASE_FILES])
def test_regression_case_checks_and_runs(path, tmp_path, capsys):
    assert cli.main(["check", str(path)]) == 0
    code = cli.main(["run", str(path), "-o", str(tmp_path / "out"), "--step", "30", "--no-images",
                     "--cache-dir", str(tmp_path / "cache")])
    err = capsys.readouterr().err
    assert code == 0, err
    assert (tmp_path / "out" / "summary.json").is_file()
