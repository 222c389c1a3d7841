"""Contact solver against closed forms: Hertz line contact and the Signorini conditions.

An elastic cylinder (plane stress, thickness L) is squeezed between two rigid flat plates; every
boundary vertex near the two poles is a Signorini contact. Hertz (Johnson, *Contact Mechanics*,
§4.3, a cylinder on a rigid flat, plane stress E* = E) gives the half-width b = √(4FR/(πE*L))
and the peak pressure p0 = 2F/(πbL) from the contact force F alone.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp

from rvfem import fem
from rvfem.app.verification import squeezed_cylinder_mesh
from rvfem.errors import ContactError
from rvfem.solve import contact

R, L, E, NU = 10.0, 1.0, 2.0e5, 0.3
H_CONTACT = 0.03  # element size in the contact zones, mm


@pytest.fixture(scope="module")
def squeezed_cylinder():
    """P1 model of the cylinder, its rim interface and the Signorini contact set near the poles."""
    # uniform H_CONTACT within |x| < 1 near both poles, growing away from them
    points, triangles, rim = squeezed_cylinder_mesh(R, H_CONTACT)
    model = fem.build_model(points, triangles, E, NU, L, order=1)
    factor = fem.factorize(model)
    iface = contact.build_interface(model, {"rim": rim}, fem.rigid_body_modes(model), {},
                                    {"rim": 0.25 * H_CONTACT})
    grid = iface.grids["rim"]
    near = np.flatnonzero(np.abs(grid.polyline[:, 0]) < 0.9)      # candidate vertices
    cols, w = grid.columns_at(grid.chain.s[near], -grid.polyline[near] / R)  # push towards the centre
    n = len(near)
    W = sp.csc_matrix((w.ravel(), (cols.ravel(), np.repeat(np.arange(n), cols.shape[1]))),
                      shape=(iface.n_columns, n))
    return model, factor, iface, grid.polyline[near], W


def _squeeze(squeezed_cylinder, approach):
    model, factor, iface, xy, W = squeezed_cylinder
    # plates at y = ±(R − approach): gap of each vertex to its plate
    gap0 = (R - np.abs(xy[:, 1])) - approach
    cset = contact.ContactSet(W, np.ones(len(xy), bool), gap0, np.zeros(len(xy)), np.zeros(len(xy)), [])
    comp = contact.Compliance(factor.solve, iface.B)
    # the round body's rotation and x translation are not resisted by frictionless plates
    sol = contact.solve_contact(cset, iface, comp, None, rigid_dofs=(1,), max_iterations=60)
    return sol, xy


def test_hertz_half_width_and_peak_pressure(squeezed_cylinder):
    sol, xy = _squeeze(squeezed_cylinder, approach=0.02)
    top = xy[:, 1] > 0
    force = sol.force[top].sum()
    b_hertz = math.sqrt(4 * force * R / (math.pi * E * L))
    p_hertz = 2 * force / (math.pi * b_hertz * L)
    x_top = xy[top, 0]
    loaded = sol.force[top] > 0
    # the edge of contact lies between the last loaded and the first unloaded vertex
    b_lo = np.abs(x_top[loaded]).max()
    b_hi = np.abs(x_top[~loaded]).min()
    b_fe = 0.5 * (b_lo + b_hi)
    assert b_hertz / H_CONTACT > 8, "the contact must span many elements for this check"
    assert b_fe == pytest.approx(b_hertz, rel=0.05)
    # nodal force / tributary length is the pressure at the centre vertex
    p_fe = sol.force[top].max() / (H_CONTACT * L)
    assert p_fe == pytest.approx(p_hertz, rel=0.03)
    # the two plates' forces balance (equilibrium of the floating cylinder)
    assert abs(sol.vectors[:, 1].sum()) <= 1e-9 * force


def test_signorini_conditions_hold(squeezed_cylinder):
    sol, _ = _squeeze(squeezed_cylinder, approach=0.01)
    assert sol.force.min() >= 0.0                      # no tensile contact force
    assert sol.gap.min() >= -1e-9                      # no penetration
    scale = sol.force.max()
    assert np.all(np.abs(sol.force * sol.gap) <= 1e-9 * scale)   # complementarity


def test_force_grows_as_approach_to_the_power_of_hertz(squeezed_cylinder):
    # rigid plates on a cylinder: the load–approach law is nearly linear (log-corrected) in 2D;
    # doubling the approach must at least double the force but not more than 2.3×
    f1 = _squeeze(squeezed_cylinder, 0.01)[0].force.sum()
    f2 = _squeeze(squeezed_cylinder, 0.02)[0].force.sum()
    assert 2.0 < f2 / f1 < 2.3


def test_unsettled_active_set_names_the_label(squeezed_cylinder):
    model, factor, iface, xy, W = squeezed_cylinder
    gap0 = (R - np.abs(xy[:, 1])) - 0.02
    cset = contact.ContactSet(W, np.ones(len(xy), bool), gap0, np.zeros(len(xy)), np.zeros(len(xy)), [])
    comp = contact.Compliance(factor.solve, iface.B)
    with pytest.raises(ContactError, match="did not settle at crank angle 12.00°"):
        contact.solve_contact(cset, iface, comp, None, rigid_dofs=(1,), max_iterations=1,
                              label="at crank angle 12.00° ")


def test_secant_start_keeps_bilateral_springs_bilateral():
    """The first, linearised solve of a cycle replaces every law by a secant spring; a spring that
    carries tension (the rigid_bore bearings' x and y springs) must stay bilateral there, a
    compression-only law (rollers, pins) compression-only."""
    hertz = contact.hertz_pin_law(length=9.0, pin_radius=3.0, flank_curvature=np.array([0.02, -0.05]),
                                  pin_modulus=2.06e5, pin_poisson=0.3, disc_modulus=2.06e5,
                                  disc_poisson=0.3, footprint_half_width=0.5)
    laws = [(np.arange(2), hertz), (np.array([2, 3]), contact.palmgren_law(9.0)),
            (np.array([4, 5]), contact.linear_law(7e5, bilateral=True)), (np.array([6]), contact.linear_law(7e5))]
    lever = np.r_[0.0, 0.0, 36.0, 36.0, 36.0, 36.0, 0.0]
    cset = contact.ContactSet(sp.csc_matrix(np.ones((1, 7))), np.zeros(7, bool), np.zeros(7), np.zeros(7),
                              lever, laws)
    # one interface column whose unit load has a moment of 60 N·mm about the disc centre
    body = contact.Body(cset, contact.Interface(None, None, None, np.array([[0.0, 0.0, 60.0]]), {}, {}), None)
    secants = contact._secant_stiffnesses(body, 2.0e5)
    assert [bilateral for _, _, bilateral in secants] == [False, False, True, False]
    assert all(1e4 < ks < 1e7 for _, ks, _ in secants)     # N/mm


def test_linear_law_open_fraction_keeps_a_weak_tension_spring():
    delta = np.array([-0.2, 0.0, 0.1])
    q, dq = contact.linear_law(1e5)(delta)
    assert np.array_equal(q, [0.0, 0.0, 1e4]) and np.array_equal(dq, [0.0, 0.0, 1e5])
    q, dq = contact.linear_law(1e5, open_fraction=1e-3)(delta)
    assert np.allclose(q, [-20.0, 0.0, 1e4], rtol=1e-15) and np.allclose(dq, [100.0, 100.0, 1e5], rtol=1e-15)


def test_footprint_columns_carry_unit_force_and_exact_moment(squeezed_cylinder):
    _, _, iface, _, _ = squeezed_cylinder
    res = iface.resultants
    force = np.einsum("ij,ij->i", res[:, :2], iface.directions)
    assert np.allclose(force, 1.0, atol=1e-12)
    # moment about the origin of a unit force at a rim point: x × d (the footprint is symmetric)
    moment = iface.points[:, 0] * iface.directions[:, 1] - iface.points[:, 1] * iface.directions[:, 0]
    assert np.allclose(res[:, 2], moment, atol=1e-3)


# ------------------------------------------------------------------------------------------------
# Reverse torque: the mirror image of forward torque
# ------------------------------------------------------------------------------------------------


def _mirrored_mesh(mesh, crank_angles_deg):
    """The mesh reflected in the x axis (y → −y): triangles and boundary loops reversed so that
    they keep their orientation; bore i becomes the bore at −α_i."""
    import dataclasses

    alpha = np.mod(np.asarray(crank_angles_deg, dtype=float), 360.0)
    image = [int(np.argmin(np.abs(np.angle(np.exp(1j * np.radians(alpha + a)))))) for a in alpha]
    boundaries = {}
    for name, edges in mesh.boundaries.items():
        if name.startswith("bore_"):
            name = f"bore_{image[int(name.split('_')[1])]}"
        boundaries[name] = np.ascontiguousarray(edges[::-1, ::-1])
    points = np.ascontiguousarray(mesh.points * np.array([1.0, -1.0]))
    triangles = np.ascontiguousarray(mesh.triangles[:, ::-1])
    return dataclasses.replace(mesh, points=points, triangles=triangles, boundaries=boundaries), image


@pytest.mark.slow
@pytest.mark.parametrize("pin_model", ["hertz", "rigid"])
def test_reverse_torque_is_the_mirror_image_of_forward_torque(tmp_path, pin_model):
    """A configuration symmetric about the x axis (cranks at 0°, 120°, 240°, fan holes between
    them, the unmodified profile's root on the x axis, no friction, bore springs instead of
    discrete rollers): −T at −θ on the mirrored mesh is the mirror image of +T at θ — bearing
    forces, pin forces and carrier rotation to 1e-9 relative. This exercises every place where
    the contact solve uses the sign of the torque (cold start, likely columns, carrier equation)."""
    import dataclasses

    from conftest import CASES_DIR

    from rvfem.case.definition import case_from_dict, case_to_dict, load_case
    from rvfem.mesh import mesh_case
    from rvfem.solve import cycle

    data = case_to_dict(load_case(CASES_DIR / "rv40e_fanholes.toml"))
    data["mesh"].update(size_flank=0.6, size_bore=0.6, size_interior=4.0)
    data["cranks"]["angles_deg"] = [0.0, 120.0, 240.0]
    data["crank_bearing"]["model"] = "rigid_bore"
    data["analysis"]["friction"] = 0.0
    data["pins"]["model"] = pin_model
    forward = case_from_dict(data, source="mirror test")
    data["loads"]["torque_Nm"] = -data["loads"]["torque_Nm"]
    reverse = case_from_dict(data, source="mirror test, reversed")
    mesh = mesh_case(forward, tmp_path)
    mirrored, image = _mirrored_mesh(mesh, forward.cranks.angles_deg)
    theta = np.radians([0.0, 17.0, 55.0, 200.0])
    s_forward, s_reverse = cycle.build_system(forward, mesh), cycle.build_system(reverse, mirrored)
    a = cycle.load_cycle(s_forward, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(s_forward))
    b = cycle.load_cycle(s_reverse, -theta, saved_angles_deg=(), stage=cycle.single_disc_stage(s_reverse))
    scale = a.bearing_loads.max()
    fa = a.bearing_forces                       # (n, N, 2)
    fb = b.bearing_forces[:, image]             # bearing at −α_i in place of bearing i
    np.testing.assert_allclose(fb[..., 0], fa[..., 0], rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(fb[..., 1], -fa[..., 1], rtol=0, atol=1e-9 * scale)
    zp = forward.pins.count
    pins = (zp - np.arange(zp)) % zp
    # each solve stops when its spring laws hold to 1e-8 of the force scale (NewtonOptions): the two
    # mirror images agree to that, not to round-off (Hertz pins are springs; rigid pins are exact)
    np.testing.assert_allclose(b.pin_forces[:, pins], a.pin_forces, rtol=0, atol=1e-8 * a.pin_forces.max())
    np.testing.assert_allclose(b.carrier_rotation, -a.carrier_rotation, rtol=1e-9)
    assert dataclasses.asdict(forward.loads)["torque_Nm"] > 0 > reverse.loads.torque_Nm
