"""The contact Newton iteration in parts, on small problems with closed-form answers: one and two
compression-only springs, a Signorini contact with a known active set, friction with a known slip
direction, and the Newton matrix against finite differences of its residual."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from rvfem.solve import contact

# interface columns of a rigid toy body: unit forces +x, −x, +y, −y on it (no moment)
RESULTANTS = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0]])


class _Rigid:
    """The column compliance of a rigid body: zero."""

    C = np.zeros((4, 4), order="F")

    def ensure(self, columns):
        pass


def _body(columns, signorini, gap0, offset, lever, laws, load_columns=None):
    """A rigid toy body whose contact i acts on interface column ``columns[i]`` (a dict of column:
    weight for the load of a contact with friction in ``load_columns``)."""
    n = len(columns)
    W = sp.csc_matrix((np.ones(n), (columns, np.arange(n))), shape=(4, n))
    W_load = None
    if load_columns is not None:
        rows, cols, vals = [], [], []
        for j, weights in enumerate(load_columns):
            for c, w in weights.items():
                rows.append(c), cols.append(j), vals.append(w)
        W_load = sp.csc_matrix((vals, (rows, cols)), shape=(4, n))
    cset = contact.ContactSet(W, np.asarray(signorini, dtype=bool), np.asarray(gap0, dtype=float),
                              np.asarray(offset, dtype=float), np.asarray(lever, dtype=float), laws, W_load)
    iface = type("Interface", (), {"resultants": RESULTANTS})()
    return contact.Body(cset, iface, _Rigid())


def test_one_compression_only_spring_carries_the_carrier_torque():
    """A body held in x by a stiff ground spring, turned by the carrier through one linear spring of
    stiffness k and lever r: λ = T/r, and the spring's approach λ/k = r·φ − a."""
    k, k_ground, r, T = 2.0e4, 1.0e9, 40.0, 1.0e5
    body = _body([0, 1], [False, False], [0, 0], [0, 0], [r, 0.0],
                 [(np.array([0]), contact.linear_law(k)), (np.array([1]), contact.linear_law(k_ground, bilateral=True))])
    sol = contact.solve_bodies([body], T, rigid_dofs=(0,))[0]
    assert sol.force[0] == pytest.approx(T / r, rel=1e-12)
    a = sol.rigid[0]
    assert a == pytest.approx((T / r) / k_ground, rel=1e-9)      # the ground spring, compressed by λ
    assert r * sol.carrier_rotation - a == pytest.approx((T / r) / k, rel=1e-9)


def test_signorini_contact_with_a_known_active_set():
    """A body pressed in −x by a prestressed spring (offset d0) against two rigid contacts: the one
    with a 1 µm overlap closes (the body moves out by it), the one with a 10 µm gap stays open."""
    k, d0 = 1.0e5, 0.02
    body = _body([0, 0, 1], [True, True, False], [-0.001, 0.01, 0.0], [0.0, 0.0, d0], [0, 0, 0],
                 [(np.array([2]), contact.linear_law(k, bilateral=True))])
    sol = contact.solve_bodies([body], None, rigid_dofs=(0,))[0]
    assert sol.rigid[0] == pytest.approx(0.001, rel=1e-9)           # the overlap opened by moving out
    assert sol.force[0] == pytest.approx(k * (d0 + 0.001), rel=1e-9)
    assert sol.force[1] == 0.0
    assert sol.gap[1] == pytest.approx(0.011, rel=1e-9)
    assert sol.gap[0] == pytest.approx(0.0, abs=1e-12)


def test_friction_loads_along_the_known_slip_direction():
    """A rigid contact whose load on the body is λ·(d + μ·t) (d = +x, t = +y): the y spring that
    holds the body carries −μ·λ, the normal force is the x load alone."""
    k, d0, mu, k_y = 1.0e5, 0.01, 0.05, 3.0e4
    body = _body([0, 1, 2], [True, False, False], [0.0, 0.0, 0.0], [0.0, d0, 0.0], [0, 0, 0],
                 [(np.array([1, 2]), contact.linear_law(k, bilateral=True))],
                 load_columns=[{0: 1.0, 2: mu}, {1: 1.0}, {2: 1.0}])
    body.cset.laws[0] = (np.array([1]), contact.linear_law(k, bilateral=True))
    body.cset.laws.append((np.array([2]), contact.linear_law(k_y, bilateral=True)))
    sol = contact.solve_bodies([body], None, rigid_dofs=(0, 1))[0]
    lam = sol.force[0]
    assert lam == pytest.approx(k * d0, rel=1e-9)
    assert sol.force[2] == pytest.approx(-mu * lam, rel=1e-9)
    assert sol.vectors[0] == pytest.approx([lam, mu * lam], rel=1e-9)
    assert sol.rigid[1] == pytest.approx(mu * lam / k_y, rel=1e-9)


def test_newton_matrix_is_the_derivative_of_its_residual():
    """The Jacobian built apart (:func:`rvfem.solve.contact.newton_matrix`) against central differences of
    the residual it returns, on a two-spring, one-contact body with a carrier and smooth (closed)
    spring laws."""
    law = contact.palmgren_law(9.0, contacts=2)
    body = _body([0, 1, 2], [False, False, True], [0.0, 0.0, 0.0], [0.004, 0.003, 0.0], [30.0, -20.0, 0.0],
                 [(np.array([0, 1]), law)])
    problem = contact.ContactProblem([body], 5.0e4)
    it = contact.NewtonIterate(np.array([800.0, 300.0, 50.0]), np.array([1e-4, -2e-4, 1e-6]), 2e-5,
                               np.array([False, False, True])).update(problem)
    kappa = 1.0e5
    Jm, r = contact.newton_matrix(problem, it, it.q, it.dq, kappa)
    x0 = np.concatenate([it.lam, it.a, [it.phi]])
    scale = np.concatenate([[1.0] * 3, [1e-6] * 3, [1e-7]])
    for j in range(x0.size):
        h = 1e-3 * scale[j]
        res = []
        for sgn in (1, -1):
            x = x0.copy()
            x[j] += sgn * h
            t = contact.NewtonIterate(x[:3], x[3:6], x[6], it.active).update(problem)
            res.append(contact.newton_matrix(problem, t, t.q, t.dq, kappa)[1])
        fd = (res[0] - res[1]) / (2 * h)
        assert np.allclose(Jm[:, j], fd, rtol=1e-5, atol=1e-6 * np.abs(Jm[:, j]).max() + 1e-12), j


def test_a_mechanism_is_stepped_onto_its_springs_and_an_empty_one_is_an_error():
    """Every spring open and nothing else holding the body: the regularised step moves it onto a
    spring (:func:`rvfem.solve.contact.newton_step`); with no spring at all the problem is a mechanism."""
    law = contact.palmgren_law(9.0, contacts=2)
    body = _body([0, 1, 1], [False, False, False], [0, 0, 0], [-0.01, -0.01, 0.0], [1.0, -1.0, 0.0],
                 [(np.array([0, 1]), law), (np.array([2]), contact.linear_law(1e9, bilateral=True))])
    problem = contact.ContactProblem([body], 500.0, rigid_dofs=(0,))
    it = contact.initial_iterate(problem, None, 1e-9)
    assert np.all(it.dq[:2] == 0.0)                     # both rollers open: a mechanism
    colscale = np.ones(problem.n)
    step = contact.newton_step(problem, it, 1e6, colscale)
    assert step[problem.nc + problem.nr] > 0.01          # the carrier turns through the clearance
    lonely = _body([2], [False], [0], [0.0], [0.0], [(np.array([0]), contact.linear_law(1e9, bilateral=True))])
    # the carrier turns nothing: its torque cannot be carried by any contact
    problem = contact.ContactProblem([lonely], 500.0, rigid_dofs=(0,))
    it = contact.initial_iterate(problem, None, 1e-9)
    with pytest.raises(contact.ContactError, match="mechanism"):
        contact.newton_step(problem, it, 1e6, np.ones(problem.n))


class _Elastic:
    """A column compliance of a toy body: a fixed symmetric positive definite C (mm/N)."""

    C = np.asfortranarray(np.array([[4.0, 1.0, 0.5, 0.2], [1.0, 3.0, 0.3, 0.1],
                                    [0.5, 0.3, 5.0, 0.7], [0.2, 0.1, 0.7, 2.0]]) * 1e-6)

    def ensure(self, columns):
        pass


def _two_elastic_bodies(law):
    """Two elastic toy bodies on one carrier, each with a loaded and an open spring of one shared
    (elementwise) law, a closed rigid contact and an open one, and bilateral ground springs in x
    and y (no moments: solved with the rotations left out)."""
    bodies = []
    for sign in (1.0, -1.0):
        b = _body([0, 0, 2, 3, 1, 3], [False, False, True, True, False, False], [0.0, 0.0, -1e-4, 0.05, 0.0, 0.0],
                  [0.004, -0.01, 0.0, 0.0, 0.0, 0.0], [30.0 * sign, 10.0 * sign, 0.0, 0.0, 0.0, 0.0],
                  [(np.array([0, 1]), law), (np.array([4, 5]), contact.linear_law(1e7, bilateral=True))])
        bodies.append(contact.Body(b.cset, b.interface, _Elastic()))
    return bodies


def test_reduced_newton_step_solves_the_whole_newton_system():
    """The step built from the unknown steps' rows alone (:func:`rvfem.solve.contact_newton.reduced_newton_step`)
    solves the whole Newton system Jm·step = −r of :func:`rvfem.solve.contact.newton_matrix`, and is
    the very step of its reduction by the known rows, on two elastic bodies with a loaded and an
    open spring, an active and an inactive rigid contact each."""
    from rvfem.solve.contact_newton import reduced_newton_step
    problem = contact.ContactProblem(_two_elastic_bodies(contact.palmgren_law(9.0, contacts=2)), 5.0e4,
                                     rigid_dofs=(0, 1))
    lam = np.array([800.0, 0.0, 50.0, 0.0, 800.0, 50.0, 600.0, 0.0, 40.0, 0.0, 600.0, 40.0])
    it = contact.NewtonIterate(lam, np.zeros(6), 2e-5, problem.sig & (problem.gap0 < 0)).update(problem)
    assert (it.dq[problem.spring] == 0).any() and (it.dq[problem.spring] > 0).any()
    kappa = 1.0e5
    colscale = np.concatenate([np.ones(problem.nc), np.full(problem.n - problem.nc, 1e-5)])
    Jm, r = contact.newton_matrix(problem, it, it.q, it.dq, kappa)
    step = reduced_newton_step(problem, it, it.q, it.dq, kappa, colscale)
    assert np.allclose(Jm @ step, -r, rtol=0, atol=1e-9 * np.abs(r).max())
    known = contact.known_rows(problem, it.active, it.dq)
    assert np.array_equal(step, contact._reduced_step(Jm, r, colscale, known))


def test_a_shared_elementwise_law_is_evaluated_once_for_both_bodies():
    """The springs of two bodies with one elementwise law are one group of the problem, and their
    forces are the law's at each spring's own approach."""
    law = contact.palmgren_law(9.0, contacts=2)
    problem = contact.ContactProblem(_two_elastic_bodies(law), 5.0e4)
    assert sum(1 for _, g in problem.laws if g is law) == 1
    it = contact.NewtonIterate(np.zeros(problem.nc), np.zeros(6), 1e-4, np.zeros(problem.nc, dtype=bool)).update(problem)
    springs = np.array([0, 1, 6, 7])
    q, dq = law(it.delta[springs])
    assert np.array_equal(it.q[springs], q) and np.array_equal(it.dq[springs], dq)


def test_a_kept_contact_problem_solves_as_a_fresh_one():
    """Solves of the same contacts at several torques with one ``g_cache`` (the torque-independent
    parts of the problem and G kept between them) give the solutions of solves without it."""
    bodies = [_body([0, 1, 0], [False, False, False], [0, 0, 0], [0.002, 0, -0.001], [40.0, 0.0, 20.0],
                    [(np.array([0, 2]), contact.palmgren_law(9.0, contacts=2)),
                     (np.array([1]), contact.linear_law(1.0e9, bilateral=True))])]
    cache: dict = {}
    for T in (5.0e4, 2.0e4, 5.0e4, 1.0e3):
        kept = contact.solve_bodies(bodies, T, g_cache=cache, rigid_dofs=(0,))
        fresh = contact.solve_bodies(bodies, T, rigid_dofs=(0,))
        for a, b in zip(kept, fresh):
            assert np.array_equal(a.force, b.force) and np.array_equal(a.rigid, b.rigid)
            assert a.carrier_rotation == b.carrier_rotation
    assert any(isinstance(k, tuple) and k and k[0] == "parts" for k in cache)


@pytest.mark.parametrize("q_ref", [1e-3, 3.0, 850.0, 2.0e4, 1.0e6])
def test_the_secant_bisection_is_eighty_halvings(q_ref):
    """The secant stiffness of a cold start (:func:`rvfem.solve.contact_newton._bisected_secant`,
    which skips the halvings a monotone law's probe force decides) is that of 80 plain halvings of
    (0, 1] mm, for Palmgren's law and the Hertz pin law."""
    from rvfem.solve.contact_newton import _bisected_secant

    def halvings(law):
        lo, hi = 0.0, 1.0
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if law(np.array([mid]))[0][0] < q_ref:
                lo = mid
            else:
                hi = mid
        return q_ref / max(hi, 1e-15)

    pin = contact.hertz_pin_law(length=15.0, pin_radius=3.0, flank_curvature=np.array([0.02, -0.01]),
                                pin_modulus=2.06e5, pin_poisson=0.3, disc_modulus=2.06e5, disc_poisson=0.3,
                                footprint_half_width=0.5)
    for law in (contact.palmgren_law(9.0, contacts=2), pin, contact.linear_law(3.0e5)):
        assert _bisected_secant(law, q_ref) == halvings(law)
