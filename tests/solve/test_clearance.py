"""Crank-bearing clearance and preload: the load cycle and every attribution step carry the
torque at every clearance (a wide clearance once left every roller open at the first Newton step,
and the solve returned zero loads), the attribution's own step is the case's cycle, and a preload
compresses every roller at zero load."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import CASES_DIR, coarse_case

from rvfem.evaluate import attribution
from rvfem.mesh import mesh_case
from rvfem.solve import contact, cycle

SHIPPED = sorted(p.stem for p in CASES_DIR.glob("*.toml"))
CLEARANCES_UM = (0, 2, 5, 10, 20, 50)
THETA = np.radians(np.arange(0.0, 360.0, 30.0))   # 30° steps: the coarse step that lost the load


@pytest.fixture(scope="module")
def mesh_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


def _system(name: str, clearance_mm: float, mesh_dir):
    case = coarse_case(name, crank_bearing={"radial_clearance": clearance_mm})
    return cycle.build_system(case, mesh_case(case, mesh_dir))


@pytest.mark.slow
@pytest.mark.parametrize("name", SHIPPED)
def test_every_attribution_step_carries_the_torque_at_every_clearance(name, mesh_dir):
    for um in CLEARANCES_UM:
        system = _system(name, um * 1e-3, mesh_dir)
        case = system.case
        att = attribution.attribution(system, THETA)           # every step solved here, none passed in
        for step in att.steps:
            assert np.all(step.loads.max(axis=1) > 0.0), f"{name} at {um} µm: step {step.key} lost the load"
        # the attribution's last step is the case's own model: the same as the cycle of a run
        run = cycle.load_cycle(system, THETA, saved_angles_deg=())
        own = att.step(attribution.case_step(case)).loads
        assert np.allclose(own, run.bearing_loads.T, rtol=1e-6, atol=1e-6 * run.bearing_loads.max())
        # every solve is in equilibrium with the torque on the carrier
        torque = max(abs(r.solution.residual["torque_Nmm"]) for r in run.solutions)
        for r in run.solutions:
            assert r.solution.residual["carrier_Nmm"] <= 1e-9 * torque
            assert r.solution.residual["relative"] <= 1e-9


def test_a_clearance_wider_than_the_first_approaches_does_not_lose_the_load(mesh_dir):
    """The solve of one angle with 10 µm clearance from a cold start: before the mechanism step of
    the Newton iteration it returned zero bearing loads with the whole torque unbalanced."""
    system = _system("rv40e_solid", 0.01, mesh_dir)
    r = cycle.solve_angle(system, 0.0)
    T = system.case.loads.disc_torque_Nmm
    assert r.solution.residual["carrier_Nmm"] <= 1e-9 * T
    assert r.solution.residual["torque_Nmm"] == pytest.approx(T, rel=1e-9)
    assert r.bearing_loads.sum() > 0.0
    # with the clearance, fewer rollers carry the load than without it
    tight = cycle.solve_angle(_system("rv40e_solid", 0.0, mesh_dir), 0.0)
    assert np.count_nonzero(r.roller_loads) < np.count_nonzero(tight.roller_loads)


@pytest.mark.parametrize("stiffness_scale", [1.0, 1000.0])
def test_a_preload_compresses_every_roller_at_almost_no_load(mesh_dir, stiffness_scale):
    """5 µm preload, 1e-3 N·m: every roller is loaded and the bearing forces balance (the pins carry
    next to nothing). On a (1000×) rigid disc each roller carries Palmgren's load at its 2.5 µm
    approach, Q = (δ·L^0.8 / (2·3.84e-5))^(1/0.9), and the bearings' forces vanish. On the
    flexible disc the preloaded rollers widen the bores and the disc grows against the pins of its
    unmodified profile (nearly every pin touches): the pins and bearings then carry
    self-equilibrated forces of a few hundred N, and the rollers are unequally loaded."""
    case = coarse_case("rv40e_solid", crank_bearing={"radial_clearance": -0.005},
                       loads={"torque_Nm": 1e-3})
    system = cycle.build_system(case, mesh_case(case, mesh_dir), stiffness_scale=stiffness_scale)
    r = cycle.solve_angle(system, 0.3)
    assert np.all(r.roller_loads > 0.0)
    total = r.bearing_forces.sum(axis=0) + r.pin_vectors.sum(axis=0)
    assert np.abs(total).max() <= 1e-9 * r.roller_loads.sum()
    if stiffness_scale > 1.0:
        b = case.crank_bearing
        q = (0.0025 * b.roller_length**0.8 / (2 * contact.PALMGREN_COEFFICIENT)) ** (1 / 0.9)
        assert r.roller_loads == pytest.approx(np.full_like(r.roller_loads, q), rel=0.01)
        assert r.bearing_loads.max() <= 0.01 * q


def test_a_preload_raises_the_smallest_bearing_load_of_the_fan_hole_disc(mesh_dir):
    """An independently written two-disc solver on rvfem's meshes found the fan-hole disc's minimum
    bearing load rising from −8 % (zero clearance) to +30 % over the handbook with a 5 µm preload,
    and the maximum falling from +8.7 % to +4.9 %: the trend, not the numbers (its pins were rigid
    and frictionless)."""
    loads = {}
    for c in (0.0, -0.005):
        system = _system("rv40e_fanholes", c, mesh_dir)
        loads[c] = cycle.load_cycle(system, THETA, saved_angles_deg=()).bearing_loads
    assert loads[-0.005].min() > loads[0.0].min()
    assert loads[-0.005].max() < loads[0.0].max()


def test_newton_step_of_a_mechanism_is_none_and_of_a_consistent_system_is_the_solution():
    """:func:`rvfem.solve.contact._reduced_step` on 2×2 systems: a zero row with a nonzero residual is a
    mechanism (None); a regular one gives −J⁻¹r."""
    J = np.array([[2.0, 0.0], [0.0, 0.0]])
    r = np.array([1.0, 3.0])
    assert contact._reduced_step(J, r, np.ones(2), np.zeros(2, dtype=bool)) is None
    J = np.array([[2.0, 1.0], [1.0, 3.0]])
    step = contact._reduced_step(J, r, np.ones(2), np.zeros(2, dtype=bool))
    assert np.allclose(J @ step, -r, atol=1e-14)


def _eccentric_in_a_bore(clearance: float, torque: float, start_open: bool):
    """A rigid body (x motion a, held by a stiff bilateral ground spring) on a carrier (x motion φ)
    through two opposite compression-only Palmgren springs with a clearance g each: the 1D model of
    a roller bearing with play. Exact solution for T > 0: the first spring carries T, the second is
    open, the ground spring holds −T, and φ = a + g + δ_Palmgren(T)."""
    import scipy.sparse as sp

    k_ground, length = 1e9, 9.0
    law = contact.palmgren_law(length, contacts=2)
    # interface columns: 0 a unit +x force on the body, 1 a unit −x force
    iface = type("Interface", (), {"resultants": np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])})()
    compliance = type("Compliance", (), {"C": np.zeros((2, 2), order="F"), "ensure": lambda self, cols: None})()
    W = sp.csc_matrix(np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.0]]))     # spring +x, spring −x, ground
    cset = contact.ContactSet(W, np.zeros(3, dtype=bool), np.zeros(3), np.array([-clearance, -clearance, 0.0]),
                              np.array([1.0, -1.0, 0.0]),
                              [(np.arange(2), law), (np.array([2]), contact.linear_law(k_ground, bilateral=True))])
    body = contact.Body(cset, iface, compliance)
    start = None
    if start_open:      # every roller open: the Newton matrix of this iterate is a mechanism
        start = [contact.AngleSolution(np.zeros(3), np.zeros((3, 2)), np.zeros(3), np.zeros(3), 0.0, 0)]
    return contact.solve_bodies([body], torque, start=start, rigid_dofs=(0,))[0], length


@pytest.mark.parametrize("start_open", [False, True])
@pytest.mark.parametrize("clearance", [0.0, 0.01, 1.0])
def test_a_roller_pair_with_play_closes_one_roller_under_load(clearance, start_open):
    T = 500.0
    sol, length = _eccentric_in_a_bore(clearance, T, start_open)
    assert sol.force[1] == 0.0
    assert sol.force[0] == pytest.approx(T, rel=1e-9)
    assert sol.force[2] == pytest.approx(-T, rel=1e-9)
    palmgren = 2 * contact.PALMGREN_COEFFICIENT * T**0.9 / length**0.8
    a = sol.rigid[0]
    assert a == pytest.approx(T / 1e9, rel=1e-6)
    assert sol.carrier_rotation == pytest.approx(a + clearance + palmgren, rel=1e-7)
