"""Tests of the FE core (rvfem.fem) against closed-form elasticity and exact invariants.

References used below
---------------------
* Lamé thick-walled ring under internal pressure p (plane stress), inner radius a, outer b:
  σ_r = A − B/r², σ_θ = A + B/r², A = p a²/(b² − a²), B = p a² b²/(b² − a²),
  u_r = [(1 − ν) A r + (1 + ν) B / r] / E  (Timoshenko & Goodier, Theory of Elasticity, § 28).
* Kirsch: infinite plate with a circular hole of radius a under remote uniaxial stress σ0 along x
  (Timoshenko & Goodier § 35); displacements with the plane-stress κ = (3 − ν)/(1 + ν).

Meshes are built here with numpy (structured, mapped), independent of the project's mesher, and
boundary tractions are assembled with scikit-fem's own ``FacetBasis`` (:func:`traction_load`),
independent of rvfem's footprint quadrature. Every tolerance is about 2-3× the error measured when
it was set; the measured value is in the comment next to it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import ElementTriP1, ElementTriP2, ElementVector, FacetBasis, LinearForm, asm
from skfem.assembly import Dofs

from rvfem import fem

# the structured meshes, the Lamé closed form and the Dirichlet-Lamé error norms are the ones the
# verification manual reports (one implementation for both)
from rvfem.app.verification import (
    kirsch_stress,
    lame_dirichlet_errors,
    quads_to_triangles,
)
from rvfem.app.verification import lame_solution as lame
from rvfem.app.verification import structured_annulus as annulus
from rvfem.errors import MeshError
from rvfem.fem import loads as fe_loads
from rvfem.fem import model as fe_model

E, NU, THICK = 2.1e5, 0.3, 10.0


# --------------------------------------------------------------------------------------------
# Meshes
# --------------------------------------------------------------------------------------------


def plate_with_hole(a: float, w: float, nt: int, nr: int, grading: float = 1.12):
    """Square plate [−w, w]² with a central hole of radius a, O-grid mesh: nt rays (multiple of 8,
    so the square's corners are vertices) graded geometrically from the hole to the square.
    Returns points, triangles, hole edges, outer edges."""
    assert nt % 8 == 0
    th = np.linspace(0.0, 2.0 * np.pi, nt, endpoint=False)
    c, s = np.cos(th), np.sin(th)
    r_out = w / np.maximum(np.abs(c), np.abs(s))
    g = grading ** np.arange(nr)
    eta = np.concatenate([[0.0], np.cumsum(g) / g.sum()])
    r = a + np.outer(eta, r_out - a)                          # (nr+1, nt)
    pts = np.stack([r * c, r * s], -1).reshape(-1, 2)
    ids = np.arange((nr + 1) * nt).reshape(nr + 1, nt)
    idx = np.concatenate([ids, ids[:, :1]], axis=1)
    tris = quads_to_triangles(idx)
    ring = lambda row: np.column_stack([row, np.roll(row, -1)])  # noqa: E731
    return pts, tris, ring(ids[0]), ring(ids[-1])


# --------------------------------------------------------------------------------------------
# Closed forms
# --------------------------------------------------------------------------------------------


def kirsch(a: float, s0: float):
    mu = E / (2 * (1 + NU))
    kap = (3 - NU) / (1 + NU)

    def u(x, y):
        r, th = np.hypot(x, y), np.arctan2(y, x)
        k = s0 * a / (8 * mu)
        ux = k * ((r / a) * (kap + 1) * np.cos(th) + 2 * (a / r) * ((1 + kap) * np.cos(th) + np.cos(3 * th))
                  - 2 * (a / r) ** 3 * np.cos(3 * th))
        uy = k * ((r / a) * (kap - 3) * np.sin(th) + 2 * (a / r) * ((1 - kap) * np.sin(th) + np.sin(3 * th))
                  - 2 * (a / r) ** 3 * np.sin(3 * th))
        return ux, uy

    stress = kirsch_stress(a, s0)        # σ_xx, σ_yy, σ_xy (the verification manual's closed form)

    return u, stress


def hoop(st: fem.StressState, xy: np.ndarray) -> np.ndarray:
    r = np.hypot(xy[:, 0], xy[:, 1])
    c, s = xy[:, 0] / r, xy[:, 1] / r
    return st.sxx * s * s + st.syy * c * c - 2 * st.sxy * s * c


def radial(st: fem.StressState, xy: np.ndarray) -> np.ndarray:
    r = np.hypot(xy[:, 0], xy[:, 1])
    c, s = xy[:, 0] / r, xy[:, 1] / r
    return st.sxx * c * c + st.syy * s * s + 2 * st.sxy * s * c


def boundary_nodes(model: fem.FEModel) -> np.ndarray:
    """Mask of the nodes on the mesh boundary (vertices, and P2 midpoints of boundary edges)."""
    bf = model.mesh.boundary_facets()
    mask = np.zeros(model.n_nodes, dtype=bool)
    mask[model.edges[bf].ravel()] = True
    if model.order == 2:
        mask[model.n_vertices + bf] = True
    return mask


def centroids(model: fem.FEModel) -> np.ndarray:
    return model.mesh.p[:, model.mesh.t].mean(axis=1).T


def traction_load(model: fem.FEModel, edges: np.ndarray, traction, n_quad: int = 4) -> np.ndarray:
    """Consistent load vector b ∫ t·v ds of a traction t(x, y, n) (MPa) on boundary edges, N,
    assembled by scikit-fem on a facet basis with ``n_quad`` Gauss points per edge."""
    fb = FacetBasis(model.mesh, model.basis.elem, facets=fem.edge_indices(model, edges),
                    intorder=2 * n_quad - 1)

    @LinearForm
    def load(v, w):
        tx, ty = traction(w.x[0], w.x[1], w.n[0], w.n[1])
        return tx * v[0] + ty * v[1]

    return model.thickness * asm(load, fb)


# --------------------------------------------------------------------------------------------
# Model basics
# --------------------------------------------------------------------------------------------


def test_plane_stress_law_gives_uniaxial_stress_for_the_poisson_strain():
    """Hooke's law, independently: a uniaxial stress σ0 strains the sheet by ε_xx = σ0/E,
    ε_yy = −ν σ0/E. The plane-stress constants must map that strain back to (σ0, 0) — the 3D λ
    would not (it assumes ε_zz = 0)."""
    lam, mu = fem.plane_stress_constants(E, NU)
    s0 = 150.0
    exx, eyy = s0 / E, -NU * s0 / E
    # measured: 0, 4.7e-17·σ0, 0, 0 (tolerances at the round-off floor)
    assert lam * (exx + eyy) + 2 * mu * exx == pytest.approx(s0, rel=2e-16)
    assert abs(lam * (exx + eyy) + 2 * mu * eyy) <= 1.5e-16 * s0
    assert mu == pytest.approx(E / (2 * (1 + NU)), rel=2e-16)
    assert lam == pytest.approx(E * NU / (1 - NU**2), rel=2e-16)


@pytest.mark.parametrize("order", [1, 2])
def test_stiffness_symmetric_psd_with_exactly_three_rigid_modes(order):
    pts, tris, _, _ = annulus(5.0, 9.0, 2, 12)
    m = fem.build_model(pts, tris, E, NU, THICK, order)
    k = m.stiffness
    kmax = abs(k).max()
    assert abs(k - k.T).max() <= 3e-16 * kmax                        # measured 1.2e-16
    r = fem.rigid_body_modes(m)
    assert np.abs(k @ r).max() <= 5e-16 * kmax * np.abs(r).max()     # measured 1.9e-16
    ev = np.linalg.eigvalsh(k.toarray())
    assert np.all(np.abs(ev[:3]) <= 8e-16 * ev[-1])     # three zero modes (measured 3.0e-16) ...
    assert ev[3] > 1.5e-4 * ev[-1]                       # ... and no more (measured 3.9e-4, P2)


@pytest.mark.parametrize("order", [1, 2])
def test_stiffness_equals_scikit_fem_linear_elasticity(order):
    """The stiffness assembled from scalar gradient products (plane_stress_stiffness) is
    scikit-fem's generic vector form ``linear_elasticity(λ*, μ)`` on the same P1/P2 basis, entry
    by entry to round-off, in the same DOF numbering. Unstructured mesh (scikit-fem's refined
    circle) with the plane-stress constants times the thickness, as build_model uses them."""
    from skfem import MeshTri, asm
    from skfem.models.elasticity import linear_elasticity

    mesh = MeshTri.init_circle(3)
    m = fem.build_model(mesh.p.T, mesh.t.T, E, NU, THICK, order)
    lam, mu = fem.plane_stress_constants(E, NU)
    reference = asm(linear_elasticity(lam * THICK, mu * THICK), m.basis).tocsr()
    assert m.stiffness.shape == reference.shape
    assert abs(m.stiffness - reference).max() <= 1e-15 * abs(reference).max()    # measured 3.4e-16 (P2)
    # no structural zeros beyond the generic form's pattern, apart from round-off-sized entries
    extra = abs(m.stiffness) - abs(m.stiffness).multiply(reference != 0)
    assert abs(extra).max() <= 1e-15 * abs(reference).max()                      # measured 2.2e-17


def test_plane_stress_stiffness_follows_the_given_vector_numbering():
    """With a scrambled global numbering of the vector DOFs, plane_stress_stiffness returns the
    same matrix with rows and columns renumbered: K'[π(a), π(b)] = K[a, b]."""
    from skfem import Basis, ElementTriP2, ElementVector, MeshTri
    from skfem.assembly import Dofs

    from rvfem.fem.model import plane_stress_stiffness

    mesh = MeshTri.init_circle(2)
    basis = Basis(mesh, ElementTriP2())
    dofs = Dofs(mesh, ElementVector(ElementTriP2())).element_dofs
    k = plane_stress_stiffness(basis, dofs, 2.0, 3.0)
    pi = np.random.default_rng(3).permutation(k.shape[0])
    k_scrambled = plane_stress_stiffness(basis, pi[dofs], 2.0, 3.0)
    assert abs(k_scrambled[pi][:, pi] - k).max() == 0.0


def test_stiffness_scales_with_thickness_and_modulus():
    pts, tris, _, _ = annulus(5.0, 9.0, 2, 12)
    k1 = fem.build_model(pts, tris, E, NU, 1.0, 1).stiffness
    k2 = fem.build_model(pts, tris, 2 * E, NU, 3.0, 1).stiffness
    assert abs(k2 - 6.0 * k1).max() <= 4e-16 * abs(k2).max()         # measured 1.6e-16


def test_constant_strain_patch_gives_exact_stress():
    # Patch test: a linear displacement field is reproduced exactly, and so is its stress.
    pts, tris, _, _ = annulus(5.0, 9.0, 3, 16)
    lam, mu = fem.plane_stress_constants(E, NU)
    g = np.array([[1e-3, 4e-4], [-2e-4, -5e-4]])           # ∂u_i/∂x_j
    eps = 0.5 * (g + g.T)
    sig = lam * np.trace(eps) * np.eye(2) + 2 * mu * eps
    for order in (1, 2):
        m = fem.build_model(pts, tris, E, NU, THICK, order)
        u = np.zeros(m.n_dofs)
        u[m.node_dofs] = m.node_coords @ g.T
        st = fem.stress_fields(m, u)
        for s in (st.nodal, st.element):
            tol = 2e-14 * abs(sig).max()                           # measured 7.1e-15 (P2)
            assert np.allclose(s.sxx, sig[0, 0], rtol=0, atol=tol)
            assert np.allclose(s.syy, sig[1, 1], rtol=0, atol=tol)
            assert np.allclose(s.sxy, sig[0, 1], rtol=0, atol=tol)
        # interior nodes are in equilibrium: K u has no load away from the boundary
        f = m.stiffness @ u
        inner = ~boundary_nodes(m)
        assert np.abs(f[m.node_dofs[inner]]).max() <= 3e-14 * np.abs(f).max()   # measured 1.2e-14


def test_p2_stress_recovery_of_a_quadratic_field_is_exact():
    # A quadratic displacement has a linear stress field, which P2 represents exactly: element
    # (centroid) values and the vertex averages must both equal the exact stress.
    pts, tris, _, _ = annulus(5.0, 9.0, 3, 16)
    m = fem.build_model(pts, tris, E, NU, THICK, 2)
    lam, mu = fem.plane_stress_constants(E, NU)
    x, y = m.node_coords.T
    u = np.zeros(m.n_dofs)
    u[m.node_dofs[:, 0]] = 1e-4 * (x * x - 2 * x * y)
    u[m.node_dofs[:, 1]] = 1e-4 * (3 * y * y + x * y)

    def exact(x, y):
        exx, eyy, exy = 1e-4 * (2 * x - 2 * y), 1e-4 * (6 * y + x), 0.5e-4 * (-2 * x + y)
        return lam * (exx + eyy) + 2 * mu * exx, lam * (exx + eyy) + 2 * mu * eyy, 2 * mu * exy

    st = fem.stress_fields(m, u)
    for s, xy in ((st.nodal, m.mesh.p.T), (st.element, centroids(m))):
        ref = exact(*xy.T)
        scale = np.abs(ref).max()
        for got, want in zip((s.sxx, s.syy, s.sxy), ref):
            assert np.abs(got - want).max() <= 1.5e-14 * scale    # measured 4.9e-15


def test_derived_stresses_match_the_full_tensor():
    rng = np.random.default_rng(1)
    sxx, syy, sxy = rng.normal(size=(3, 50)) * 100.0
    s = fem.StressState.from_components(sxx, syy, sxy)
    for i in range(50):
        t = np.array([[sxx[i], sxy[i], 0], [sxy[i], syy[i], 0], [0, 0, 0.0]])
        ev = np.linalg.eigvalsh(t[:2, :2])
        assert s.s1[i] == pytest.approx(ev[1], abs=1.5e-13)         # measured 5.7e-14 MPa
        assert s.s2[i] == pytest.approx(ev[0], abs=1.5e-13)         # measured 2.8e-14 MPa
        dev = t - np.trace(t) / 3 * np.eye(3)
        assert s.von_mises[i] == pytest.approx(math.sqrt(1.5 * np.sum(dev * dev)), rel=5e-16)  # measured 2.2e-16
        n1 = np.array([math.cos(s.angle1[i]), math.sin(s.angle1[i])])
        assert n1 @ t[:2, :2] @ n1 == pytest.approx(s.s1[i], abs=1e-13)   # measured 2.8e-14 MPa


def test_build_model_rejects_bad_input():
    pts, tris, _, _ = annulus(5.0, 9.0, 2, 12)
    with pytest.raises(MeshError, match="belong to no triangle"):
        fem.build_model(np.vstack([pts, [[100.0, 0.0]]]), tris, E, NU, THICK)
    bad = tris.copy()
    bad[0] = [bad[0, 0], bad[0, 0], bad[0, 1]]
    with pytest.raises(MeshError, match="degenerate"):
        fem.build_model(pts, bad, E, NU, THICK)
    with pytest.raises(ValueError, match="order"):
        fem.build_model(pts, tris, E, NU, THICK, order=3)
    with pytest.raises(ValueError, match="Poisson"):
        fem.build_model(pts, tris, E, 0.5, THICK)


def test_build_model_parts_check_material_and_mesh():
    for args, msg in [((3, E, NU, THICK), "order"), ((1, 0.0, NU, THICK), "Young"),
                      ((1, E, -0.1, THICK), "Poisson"), ((1, E, NU, float("nan")), "thickness")]:
        with pytest.raises(ValueError, match=msg):
            fe_model._check_material(*args)
    fe_model._check_material(2, E, 0.0, THICK)                        # ν = 0 is allowed
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    tris = np.array([[0, 1, 2], [1, 3, 2]], dtype=np.int32)
    mesh = fe_model._checked_mesh(pts.tolist(), tris)
    assert np.array_equal(mesh.p.T, pts) and mesh.t.shape == (3, 2)
    fe_model._check_triangle_areas(pts, tris[:, ::-1])               # clockwise is fine
    # a sliver of twice-area 1e-15 on a mesh of extent 1: |2A| ≤ 1e-14·D²
    sliver = np.vstack([pts, [[0.5, 0.5 + 1e-15]]])
    with pytest.raises(MeshError, match="1 degenerate.*#1"):
        fe_model._check_triangle_areas(sliver, np.array([[0, 1, 2], [1, 4, 2]]))
    with pytest.raises(MeshError, match="integer"):
        fe_model._checked_mesh(pts, tris.astype(float))
    with pytest.raises(MeshError, match="out of range"):
        fe_model._checked_mesh(pts, tris + 1)
    with pytest.raises(MeshError, match=r"shape \(m, 3\)"):
        fe_model._checked_mesh(pts, tris[:, :2])


@pytest.mark.parametrize("order", [1, 2])
def test_node_maps_and_stress_recovery_points(order):
    pts, tris, _, _ = annulus(5.0, 9.0, 2, 12)
    m = fem.build_model(pts, tris, E, NU, THICK, order)
    scalar = ElementTriP1() if order == 1 else ElementTriP2()
    edges, coords, dofs = fe_model._node_maps(m.mesh, Dofs(m.mesh, ElementVector(scalar)), order)
    assert edges.dtype == dofs.dtype == np.int64 and edges.flags.c_contiguous
    assert np.array_equal(edges, m.edges) and np.array_equal(coords, m.node_coords)
    assert np.array_equal(dofs, m.node_dofs)
    sb = fe_model._stress_recovery_basis(m.mesh, scalar)
    tri = m.mesh.t
    xy = np.moveaxis(np.asarray(sb.global_coordinates()), 0, -1)   # (n_el, 4, 2)
    p = m.mesh.p.T
    assert np.allclose(xy[:, :3], np.stack([p[tri[k]] for k in range(3)], axis=1), rtol=0, atol=1e-13)
    assert np.allclose(xy[:, 3], p[tri].mean(axis=0), rtol=0, atol=1e-13)


def test_node_numbering_vertices_first_then_p2_midpoints():
    pts, tris, _, _ = annulus(5.0, 9.0, 2, 12)
    m1 = fem.build_model(pts, tris, E, NU, THICK, 1)
    m2 = fem.build_model(pts, tris, E, NU, THICK, 2)
    assert m1.n_nodes == len(pts) and m1.n_dofs == 2 * len(pts)
    assert m2.n_nodes == len(pts) + len(m2.edges)
    for m in (m1, m2):
        assert np.array_equal(m.node_coords[: len(pts)], pts)
        assert np.array_equal(np.sort(m.node_dofs.ravel()), np.arange(m.n_dofs))
    mid = m2.node_coords[len(pts):]
    assert np.array_equal(mid, 0.5 * (pts[m2.edges[:, 0]] + pts[m2.edges[:, 1]]))   # exact
    # a rigid translation in x moves exactly the x DOFs
    r = fem.rigid_body_modes(m2)
    assert np.all(r[m2.node_dofs[:, 0], 0] == 1) and np.all(r[m2.node_dofs[:, 1], 0] == 0)


# --------------------------------------------------------------------------------------------
# Lamé ring (floating body, pressure traction)
# --------------------------------------------------------------------------------------------


def _lame_pressure_errors(order: int, nr: int) -> dict[str, float]:
    """Full ring, internal pressure as a traction on the (polygonal) bore, floating body."""
    a, b, p = 10.0, 20.0, 100.0
    pts, tris, inner, _ = annulus(a, b, nr, 12 * nr)
    m = fem.build_model(pts, tris, E, NU, THICK, order)
    f = traction_load(m, inner, lambda x, y, nx, ny: (-p * nx, -p * ny))
    # the resultant of a pressure on a closed loop is zero: self-equilibrated
    assert np.abs(fem.rigid_body_modes(m).T @ f).max() <= 2e-16 * np.abs(f).sum()   # measured 7.0e-17
    fac = fem.factorize(m)
    u = fac.solve(f)
    reactions = (m.stiffness @ u - f)[fac.support_dofs]
    assert np.abs(reactions).max() <= 5e-11 * np.abs(f).max()       # measured 1.7e-11 (P2, nr = 16)
    ud, _ = fem.remove_rigid_motion(m, u)

    u_ex, _, s_ex = lame(a, b, p)
    ux, uy = u_ex(*m.node_coords.T)
    du = ud[m.node_dofs] - np.column_stack([ux, uy])
    st = fem.stress_fields(m, u)
    c = centroids(m)
    sr_ex, st_ex = s_ex(np.hypot(*c.T))
    v_in = np.unique(inner)
    bore = s_ex(a)[1]                                   # σ_θ(a) = p (b² + a²)/(b² − a²)
    return {
        "u": np.hypot(*du.T).max() / np.hypot(ux, uy).max(),
        "element_hoop": np.abs(hoop(st.element, c) - st_ex).max() / p,
        "element_radial": np.abs(radial(st.element, c) - sr_ex).max() / p,
        "bore_hoop": np.abs(hoop(st.nodal, pts)[v_in] - bore).max() / bore,
        "bore_hoop_bias": (bore - hoop(st.nodal, pts)[v_in].mean()) / bore,
    }


def test_lame_ring_p1_errors_and_their_orders():
    coarse, fine = _lame_pressure_errors(1, 8), _lame_pressure_errors(1, 16)
    rate = {k: math.log2(coarse[k] / fine[k]) for k in coarse}
    # nodal displacement O(h²); constant element stresses at the centroid O(h) (at the bore,
    # where dσ_θ/dr = 2B/a³ is largest); vertex averaging at the bore is biased low by O(h).
    assert fine["u"] < 2.5e-3                                          # measured 1.89e-3
    assert rate["u"] == pytest.approx(2.0, abs=0.05)                   # measured 1.976
    assert rate["element_hoop"] == pytest.approx(1.0, abs=0.15)        # measured 0.891 (pre-asymptotic)
    assert rate["element_radial"] == pytest.approx(1.0, abs=0.08)      # measured 0.965
    assert fine["bore_hoop_bias"] > 0                                  # measured 0.0179
    assert rate["bore_hoop_bias"] == pytest.approx(1.0, abs=0.1)       # measured 1.045


def test_lame_ring_p2_errors_and_the_geometric_limit():
    coarse, fine = _lame_pressure_errors(2, 8), _lame_pressure_errors(2, 16)
    # 192 straight chords per circle
    assert fine["u"] < 2.5e-4                                          # measured 1.69e-4
    assert fine["element_hoop"] < 6e-4 and fine["element_radial"] < 6e-4   # measured 4.1e-4, 4.3e-4
    assert fine["bore_hoop"] < 3e-3                                    # measured 1.93e-3
    # With the pressure on straight-edged P2 the error is dominated by the polygonal boundary,
    # O(h²) — not the O(h³) of P2 on the exact geometry (see the manufactured test below).
    assert math.log2(coarse["u"] / fine["u"]) == pytest.approx(2.0, abs=0.2)   # measured 2.09


# --------------------------------------------------------------------------------------------
# Convergence rates (manufactured: exact Lamé displacement prescribed on the whole boundary)
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("order, levels", [(1, (4, 8, 16, 32)), (2, (4, 8, 16))])
def test_convergence_rates_match_theory(order, levels):
    res = [lame_dirichlet_errors(order, n) for n in levels]
    h = np.array([r[0] for r in res])
    l2 = np.array([r[1] for r in res])
    en = np.array([r[2] for r in res])
    rate_l2 = np.log(l2[-2] / l2[-1]) / np.log(h[-2] / h[-1])
    rate_en = np.log(en[-2] / en[-1]) / np.log(h[-2] / h[-1])
    # a priori estimates for smooth solutions: ‖e‖_L2 = O(h^(k+1)), ‖e‖_energy = O(h^k)
    # measured: P1 2.003 (L2), 1.007 (energy); P2 3.023 (L2), 2.001 (energy)
    assert rate_l2 == pytest.approx(order + 1, abs=0.05)
    assert rate_en == pytest.approx(order, abs=0.05)
    # errors decrease monotonically at every level
    assert np.all(np.diff(l2) < 0) and np.all(np.diff(en) < 0)


# --------------------------------------------------------------------------------------------
# Kirsch plate with a hole (exact tractions on the outer square: no finite-width effect)
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def kirsch_p2():
    a, w, s0 = 1.0, 8.0, 100.0
    pts, tris, hole, outer = plate_with_hole(a, w, 96, 28, 1.1)
    m = fem.build_model(pts, tris, E, NU, THICK, 2)
    _, s_ex = kirsch(a, s0)

    def traction(x, y, nx, ny):
        sxx, syy, sxy = s_ex(x, y)
        return sxx * nx + sxy * ny, sxy * nx + syy * ny

    f = traction_load(m, outer, traction, n_quad=6)
    u = fem.factorize(m).solve(f)
    return m, u, a, s0, pts, hole


def test_kirsch_stress_concentration_at_the_hole(kirsch_p2):
    m, u, a, s0, pts, hole = kirsch_p2
    st = fem.stress_fields(m, u)
    top = int(np.argmin(np.hypot(pts[:, 0], pts[:, 1] - a)))
    side = int(np.argmin(np.hypot(pts[:, 0] - a, pts[:, 1])))
    assert np.allclose(pts[top], [0.0, a], rtol=0, atol=2e-16)         # measured 6.1e-17 mm
    # σ_xx = 3 σ0 at θ = 90°, σ_yy = −σ0 at θ = 0 (Kirsch). The tolerance covers the polygonal
    # hole (96 chords, O(h²)) and the vertex averaging of P2 stresses.
    assert st.nodal.sxx[top] / s0 == pytest.approx(3.0, abs=0.008)        # measured +0.0035
    assert st.nodal.syy[side] / s0 == pytest.approx(-1.0, abs=0.007)      # measured −0.0028
    assert st.nodal.von_mises.max() / s0 == pytest.approx(3.0, abs=0.007)  # measured +0.0028


def test_kirsch_full_field_away_from_the_hole(kirsch_p2):
    m, u, a, s0, pts, hole = kirsch_p2
    st = fem.stress_fields(m, u)
    u_ex, s_ex = kirsch(a, s0)
    r = np.hypot(*pts.T)
    far = r >= 1.5 * a
    ref = s_ex(*pts[far].T)
    for got, want in zip((st.nodal.sxx, st.nodal.syy, st.nodal.sxy), ref):
        assert np.abs(got[far] - want).max() / s0 < 5e-3  # measured ≤ 3.6e-3 (P2, 96 chords)
    # displacement: equal up to a rigid motion (the FE body floats)
    ux, uy = u_ex(*m.node_coords.T)
    ue = np.zeros(m.n_dofs)
    ue[m.node_dofs[:, 0]], ue[m.node_dofs[:, 1]] = ux, uy
    diff, _ = fem.remove_rigid_motion(m, u - ue)
    assert np.abs(diff).max() / np.abs(ue).max() < 5e-4       # measured 1.96e-4


# --------------------------------------------------------------------------------------------
# Floating body: minimal support vs. the constrained (bordered) system
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("order", [1, 2])
def test_minimal_support_gives_the_floating_body_solution(order):
    pts, tris, _, _ = annulus(5.0, 9.0, 4, 32)
    m = fem.build_model(pts, tris, E, NU, THICK, order)
    rng = np.random.default_rng(3)
    r = fem.rigid_body_modes(m)
    f = rng.normal(size=m.n_dofs)
    f -= r @ np.linalg.solve(r.T @ r, r.T @ f)               # self-equilibrated: Rᵀ f = 0
    # reference: K u + R λ = f, Rᵀ u = 0 (the floating body with its rigid part removed)
    n = m.n_dofs
    big = sp.bmat([[m.stiffness, sp.csr_matrix(r)], [sp.csr_matrix(r.T), None]]).tocsc()
    ref = spla.spsolve(big, np.concatenate([f, np.zeros(3)]))
    u_ref, lam = ref[:n], ref[n:]
    assert np.abs(lam).max() <= 2e-15 * np.abs(f).max()    # no force needed to hold it (measured 5.9e-16)

    s_ref = fem.stress_fields(m, u_ref).nodal
    supports = [fem.default_support(m), np.array([0, 1, m.node_dofs[len(pts) // 2 + 3, 0]])]
    for sup in supports:
        fac = fem.factorize(m, support_dofs=sup, solver="superlu")
        u = fac.solve(f)
        assert np.all(u[sup] == 0.0)
        # differs from the reference by a rigid motion only ...
        d, _ = fem.remove_rigid_motion(m, u - u_ref)
        assert np.abs(d).max() <= 1.5e-12 * np.abs(u_ref).max()     # measured 6.0e-13 (P2)
        # ... so the stresses are the same
        s = fem.stress_fields(m, u).nodal
        assert np.abs(s.von_mises - s_ref.von_mises).max() <= 1e-12 * s_ref.von_mises.max()  # measured 3.3e-13


@pytest.mark.parametrize("order", [1, 2])
def test_superlu_with_its_supernode_settings_solves_to_round_off(order):
    """SuperLU with rvfem's supernode relaxation and panel size (fem.solve.SUPERLU_RELAX,
    SUPERLU_PANEL_SIZE) on a mesh with thousands of DOFs (many supernodes and panels): the
    residual of K_ff u = f is at round-off, and the solution is the one of SciPy's default
    settings to round-off."""
    pts, tris, _, _ = annulus(5.0, 9.0, 10, 96)
    m = fem.build_model(pts, tris, E, NU, THICK, order)
    fac = fem.factorize(m, solver="superlu")
    rhs = np.random.default_rng(11).normal(size=(m.n_dofs, 5))
    u = fac.solve(rhs)
    kff = m.stiffness[fac.free_dofs][:, fac.free_dofs].tocsc()
    f = rhs[fac.free_dofs]
    residual = kff @ u[fac.free_dofs] - f
    assert np.abs(residual).max() <= 1e-11 * np.abs(f).max()       # measured 7.8e-13 (P2)
    default = spla.splu(kff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                        options={"SymmetricMode": True}).solve(f)
    assert np.abs(u[fac.free_dofs] - default).max() <= 1e-12 * np.abs(default).max()  # measured 6.9e-14 (P2)


@pytest.mark.parametrize("solver", fem.available_solvers())
def test_every_available_solver_agrees_with_spsolve(solver):
    pts, tris, _, _ = annulus(5.0, 9.0, 4, 32)
    m = fem.build_model(pts, tris, E, NU, THICK, 2)
    fac = fem.factorize(m, solver=solver)
    assert fac.solver == solver
    rng = np.random.default_rng(5)
    rhs = rng.normal(size=(m.n_dofs, 7))
    u = fac.solve(rhs)
    kff = m.stiffness[fac.free_dofs][:, fac.free_dofs].tocsc()
    ref = spla.spsolve(kff, rhs[fac.free_dofs])
    # measured 1.1e-13 (SuperLU), 3.1e-13 (cholespy); the backward-stable bound κ(K_ff)·ε is 8.7e-12
    assert np.abs(u[fac.free_dofs] - ref).max() <= 1e-12 * np.abs(ref).max()
    assert np.all(u[fac.support_dofs] == 0.0)
    # vector and sparse right-hand sides, same answers
    # measured 0 with SuperLU (the same factor); other backends may block differently
    assert np.allclose(fac.solve(rhs[:, 2]), u[:, 2], rtol=0, atol=1e-15 * np.abs(u).max())
    assert np.allclose(fac.solve(sp.csc_matrix(rhs)), u, rtol=0, atol=1e-15 * np.abs(u).max())
    with pytest.raises(ValueError):
        fac.solve(np.zeros(m.n_dofs + 1))


def test_auto_solver_is_the_first_available():
    pts, tris, _, _ = annulus(5.0, 9.0, 2, 12)
    m = fem.build_model(pts, tris, E, NU, THICK, 1)
    assert fem.factorize(m).solver == fem.available_solvers()[0]
    assert "superlu" in fem.available_solvers()


def test_remove_rigid_motion_recovers_a_rigid_motion_written_out():
    pts, tris, _, _ = annulus(5.0, 9.0, 2, 12)
    m = fem.build_model(pts, tris, E, NU, THICK, 2)
    x, y = m.node_coords.T
    tx, ty, om, xc, yc = 0.1, -0.2, 1e-3, 1.0, 2.0
    rigid = np.zeros(m.n_dofs)
    rigid[m.node_dofs[:, 0]] = tx - om * (y - yc)             # small rotation about (xc, yc)
    rigid[m.node_dofs[:, 1]] = ty + om * (x - xc)
    rest, q = fem.remove_rigid_motion(m, rigid, centre=(xc, yc))
    np.testing.assert_allclose(q, [tx, ty, om], rtol=2e-15)    # measured 8.9e-16
    assert np.abs(rest).max() <= 2e-16                         # measured 6.9e-17 mm
    # a deformation with no rigid part (Rᵀu = 0) survives unchanged when a rigid motion is added
    u0 = np.random.default_rng(0).normal(size=m.n_dofs)
    r = fem.rigid_body_modes(m, (xc, yc))
    u0 -= r @ np.linalg.solve(r.T @ r, r.T @ u0)
    rest, q = fem.remove_rigid_motion(m, u0 + rigid, centre=(xc, yc))
    np.testing.assert_allclose(q, [tx, ty, om], rtol=3e-15)    # measured 1.1e-15
    assert np.abs(rest - u0).max() <= 1e-15                    # measured 4.4e-16 mm


# --------------------------------------------------------------------------------------------
# Boundary chains and footprint operators
# --------------------------------------------------------------------------------------------


def _signed_area(points: np.ndarray) -> float:
    x, y = points[:-1].T
    x1, y1 = points[1:].T
    return 0.5 * float(np.sum(x * y1 - x1 * y))


@pytest.mark.parametrize("order", [1, 2])
def test_boundary_chains_are_ordered_with_the_body_on_the_left(order):
    pts, tris, inner, outer = annulus(5.0, 9.0, 2, 24)
    m = fem.build_model(pts, tris, E, NU, THICK, order)
    rng = np.random.default_rng(0)
    shuffled = np.vstack([inner, outer])[rng.permutation(48)]
    shuffled[::3] = shuffled[::3, ::-1]
    chains = fem.boundary_chains(m, shuffled)
    assert len(chains) == 2 and all(c.closed for c in chains)
    by_r = sorted(chains, key=lambda c: np.hypot(*c.points[0]))
    hole, rim = by_r
    assert _signed_area(rim.points) > 0 > _signed_area(hole.points)   # CCW outside, CW hole
    mid = 0.5 * (rim.points[:-1] + rim.points[1:])
    assert np.all(np.einsum("ij,ij->i", rim.normals, mid) > 0)       # outward = away from centre
    mid = 0.5 * (hole.points[:-1] + hole.points[1:])
    assert np.all(np.einsum("ij,ij->i", hole.normals, mid) < 0)      # outward = into the hole
    assert rim.length == pytest.approx(2 * 24 * 9.0 * math.sin(math.pi / 24), rel=3e-16)   # measured 1.1e-16
    # locate / point_at round trip, including the wrap-around point
    s = np.array([0.0, 0.3, 17.2, rim.length - 1e-3])
    s_back, dist = rim.locate(rim.point_at(s))
    assert np.allclose(s_back, s, rtol=0, atol=2e-16) and np.all(dist < 2e-16)   # measured 5.6e-17 mm
    # an open chain (half of the outer circle)
    half = outer[:12]
    (open_chain,) = fem.boundary_chains(m, half)
    assert not open_chain.closed and len(open_chain.vertices) == 13


def test_interior_or_branching_boundary_is_rejected():
    pts, tris, inner, outer = annulus(5.0, 9.0, 2, 12)
    m = fem.build_model(pts, tris, E, NU, THICK, 1)
    interior = np.array([[inner[0, 0], inner[0, 0] + 12]])            # a radial, interior edge
    with pytest.raises(MeshError, match="interior"):
        fem.boundary_chains(m, np.vstack([inner, interior]))
    # two triangles touching at one vertex ("bow tie"): four boundary edges meet there
    bow = fem.build_model(
        np.array([[0.0, 0.0], [1.0, 0.5], [1.0, -0.5], [-1.0, 0.5], [-1.0, -0.5]]),
        np.array([[0, 2, 1], [0, 3, 4]]), E, NU, THICK, 1,
    )
    with pytest.raises(MeshError, match="branches"):
        fem.boundary_chains(bow, np.array([[0, 1], [1, 2], [2, 0], [0, 3], [3, 4], [4, 0]]))


def _exact_footprint_moments(chain, c, a, shape):
    """Force and first moments of a footprint by an independent fine midpoint rule."""
    n = 200_000
    if shape == "elliptic":
        th = (np.arange(n) + 0.5) / n * np.pi - np.pi / 2
        s = c + a * np.sin(th)
        w = (2 / np.pi) * np.cos(th) ** 2 * (np.pi / n)
    else:
        s = c - a + (np.arange(n) + 0.5) / n * 2 * a
        w = np.full(n, 1.0 / n)
    xy = chain.point_at(s)
    return w.sum(), w @ xy[:, 0], w @ xy[:, 1]


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("shape", ["elliptic", "uniform"])
def test_footprint_operator_conserves_force_and_moment(order, shape):
    pts, tris, inner, outer = annulus(5.0, 9.0, 3, 40)
    m = fem.build_model(pts, tris, E, NU, THICK, order)
    (rim,) = fem.boundary_chains(m, outer)
    # centres everywhere incl. across the chain's start (wrap-around), widths from well below
    # one edge (1.41 mm) to several edges
    c = np.array([0.0, 0.05, rim.length - 0.2, 3.3, 10.0, 25.0, 41.0, 55.9])
    a = np.array([0.3, 0.02, 0.9, 2.5, 0.7, 4.0, 0.1, 1.6])
    ang = np.linspace(0, 2 * np.pi, len(c), endpoint=False) + 0.3
    d = np.column_stack([np.cos(ang), np.sin(ang)])
    w = fem.footprint_weights(m, rim, c, a, shape=shape)
    assert w.shape == (m.n_nodes, len(c))
    assert np.allclose(np.asarray(w.sum(axis=0)).ravel(), 1.0, rtol=0, atol=1e-14)   # measured 4.7e-15
    b = fem.load_operator(m, w, d)
    xy = m.node_coords
    fx = np.asarray(b[m.node_dofs[:, 0]].sum(axis=0)).ravel()
    fy = np.asarray(b[m.node_dofs[:, 1]].sum(axis=0)).ravel()
    assert np.allclose(fx, d[:, 0], rtol=0, atol=1e-14) and np.allclose(fy, d[:, 1], rtol=0, atol=1e-14)   # measured 4.1e-15
    moment = np.asarray(b[m.node_dofs[:, 1]].T @ xy[:, 0] - b[m.node_dofs[:, 0]].T @ xy[:, 1]).ravel()
    for j in range(len(c)):
        f0, mx, my = _exact_footprint_moments(rim, c[j], a[j], shape)
        assert f0 == pytest.approx(1.0, abs=3e-16)                               # measured 1.1e-16
        # the error is the reference's midpoint rule, O(n⁻²)
        assert moment[j] == pytest.approx(mx * d[j, 1] - my * d[j, 0], abs=2e-11)  # measured 7.0e-12 N·mm
    # transpose: weighted average displacement of a rigid motion
    r = fem.rigid_body_modes(m)
    avg = b.T @ r
    assert np.allclose(avg[:, 0], d[:, 0], rtol=0, atol=1e-14)     # measured 4.1e-15
    assert np.allclose(avg[:, 1], d[:, 1], rtol=0, atol=1e-14)
    assert np.allclose(avg[:, 2], moment, rtol=0, atol=1e-14)      # measured 3.6e-15 mm
    # every column touches only the nodes of the edges its arc overlaps
    nnz_per_col = np.diff(w.indptr)
    assert nnz_per_col.max() <= (order + 1) * (2 * a.max() / 1.41 + 2) + 1


def test_footprint_validation():
    pts, tris, inner, outer = annulus(5.0, 9.0, 2, 12)
    m = fem.build_model(pts, tris, E, NU, THICK, 1)
    (rim,) = fem.boundary_chains(m, outer)
    (half,) = fem.boundary_chains(m, outer[:6])
    with pytest.raises(ValueError, match="half the loop"):
        fem.footprint_weights(m, rim, [1.0], rim.length / 2)
    with pytest.raises(ValueError, match="runs off"):
        fem.footprint_weights(m, half, [0.1], 0.5)
    with pytest.raises(ValueError, match="positive"):
        fem.footprint_weights(m, rim, [1.0], 0.0)


# the parts of footprint_weights, each against what it promises


def test_footprint_arcs_wrap_a_loop_and_check_an_open_chain():
    pts, tris, inner, outer = annulus(5.0, 9.0, 2, 12)
    m = fem.build_model(pts, tris, E, NU, THICK, 1)
    (rim,) = fem.boundary_chains(m, outer)
    (half,) = fem.boundary_chains(m, outer[:6])
    L = rim.length
    c, a, shifts = fe_loads._footprint_arcs(rim, [-1.0, 2.0, L + 3.0], 0.5, "elliptic")
    assert np.array_equal(c, np.mod([-1.0, 2.0, L + 3.0], L)) and shifts == (-L, 0.0, L)
    assert np.array_equal(a, [0.5, 0.5, 0.5]) and a.flags.writeable and a.dtype == np.float64
    c, a, shifts = fe_loads._footprint_arcs(half, 1.0, [0.5], "uniform")
    assert np.array_equal(c, [1.0]) and shifts == (0.0,)
    with pytest.raises(ValueError, match="one-dimensional"):
        fe_loads._footprint_arcs(rim, [[1.0]], 0.5, "elliptic")
    with pytest.raises(ValueError, match="unknown footprint shape"):
        fe_loads._footprint_arcs(rim, [1.0], 0.5, "box")


def test_footprint_edges_and_pieces_tile_each_footprint_across_the_seam():
    pts, tris, inner, outer = annulus(5.0, 9.0, 2, 24)
    m = fem.build_model(pts, tris, E, NU, THICK, 1)
    (rim,) = fem.boundary_chains(m, outer)
    k = len(rim.edges)
    # across the seam s = 0 ≡ L, inside one edge, exactly on a vertex, over several edges
    c, a, shifts = fe_loads._footprint_arcs(rim, [0.1, 3.0, rim.s[5], 20.0],
                                            [0.8, 0.2, 1.0, 4.0], "elliptic")
    cols, eidx, shift = fe_loads._footprint_edges(rim, c, a, shifts)
    assert {0, k - 1} <= set(eidx[cols == 0].tolist())             # both sides of the seam
    assert set(shift[(cols == 0) & (eidx == k - 1)].tolist()) == {-rim.length}
    cols, eidx, aa, v_start, le, v0, v1 = fe_loads._footprint_pieces(rim, c, a, cols, eidx, shift)
    assert np.all(v1 > v0) and np.array_equal(aa, a[cols])
    assert np.array_equal(le, rim.s[eidx + 1] - rim.s[eidx])
    assert np.all(v0 >= v_start) and np.all(v1 <= v_start + le + 1e-14)
    for j in range(len(c)):
        order = np.argsort(v0[cols == j])
        lo, hi = v0[cols == j][order], v1[cols == j][order]
        # pieces meet at bit-identical break points and cover [−a, a] exactly
        assert lo[0] == -a[j] and hi[-1] == a[j] and np.array_equal(hi[:-1], lo[1:])
    assert np.count_nonzero(cols == 2) == 2                            # centred on a vertex
    assert np.count_nonzero(cols == 1) == 1                            # inside one edge


@pytest.mark.parametrize("shape", ["elliptic", "uniform"])
def test_footprint_quadrature_integrates_the_density_in_closed_form(shape):
    a = np.array([0.7, 0.7, 2.0, 2.0, 1.3])
    v0 = np.array([-0.7, -0.2, -2.0, 0.5, -1.3])
    v1 = np.array([-0.2, 0.7, 2.0, 1.9, 1.3])
    vq, wt = fe_loads._footprint_quadrature(shape, a, v0, v1, 10)
    assert vq.shape == wt.shape == (5, 10)
    assert np.all((vq >= v0[:, None]) & (vq <= v1[:, None]))
    if shape == "elliptic":
        # ρ = 2/(πa)·√(1 − (v/a)²), v = a sin θ: ∫ρ dv = (θ + sin θ cos θ)/π,
        # ∫vρ dv = −2a cos³θ/(3π) between the ends (Johnson eq. 4.43)
        th0, th1 = np.arcsin(v0 / a), np.arcsin(v1 / a)
        f = lambda t: (t + np.sin(t) * np.cos(t)) / np.pi            # noqa: E731
        g = lambda t: -2.0 * a * np.cos(t) ** 3 / (3.0 * np.pi)       # noqa: E731
        force, moment = f(th1) - f(th0), g(th1) - g(th0)
    else:
        force, moment = (v1 - v0) / (2 * a), (v1**2 - v0**2) / (4 * a)
    assert np.allclose(wt.sum(axis=1), force, rtol=0, atol=1e-14)          # measured 4.8e-15
    assert np.allclose((wt * vq).sum(axis=1), moment, rtol=0, atol=5e-16)  # measured 1.7e-16 mm
    assert wt[2].sum() == pytest.approx(1.0, abs=1e-14)                     # a whole footprint


@pytest.mark.parametrize("order", [1, 2])
def test_footprint_matrix_puts_a_point_load_on_the_edge_nodes(order):
    """A single quadrature point of weight 1 at local coordinate t gives the nodes of its edge
    the values of their shape functions there: (1 − t, t) for P1, and for P2 the quadratic
    (1 − t)(1 − 2t), t(2t − 1), 4t(1 − t) with the midpoint node."""
    pts, tris, inner, outer = annulus(5.0, 9.0, 2, 12)
    m = fem.build_model(pts, tris, E, NU, THICK, order)
    (rim,) = fem.boundary_chains(m, outer)
    t = 0.3
    e = 4
    le = rim.s[e + 1] - rim.s[e]
    w = fe_loads._footprint_matrix(m, rim, np.array([1]), np.array([e]), np.array([-0.5]),
                                   np.array([le]), np.array([[-0.5 + t * le]]), np.array([[1.0]]), 2)
    assert w.shape == (m.n_nodes, 2) and w[:, 0].nnz == 0
    a_, b_ = rim.edges[e]
    col = w[:, 1].toarray().ravel()
    if order == 1:
        expected = {a_: 1 - t, b_: t}
    else:
        mid = m.n_vertices + fem.edge_indices(m, rim.edges[e:e + 1])[0]
        expected = {a_: (1 - t) * (1 - 2 * t), b_: t * (2 * t - 1), mid: 4 * t * (1 - t)}
    assert np.count_nonzero(col) == len(expected)
    for node, value in expected.items():
        assert col[node] == pytest.approx(value, abs=1e-15)


@pytest.mark.parametrize("order", [1, 2])
def test_nodal_stress_operator_equals_stress_fields(order):
    """The linear operator behind the load cycle's stress envelope reproduces stress_fields."""
    from skfem import MeshTri

    from rvfem.fem.stress import displacement_gradients

    mesh = MeshTri.init_circle(3)
    model = fem.build_model(mesh.p.T, mesh.t.T, 2.0e5, 0.3, 2.0, order=order)
    u = np.random.default_rng(1).normal(size=model.n_dofs)
    nodal = fem.stress_fields(model, u).nodal
    # the same fields from gradients evaluated beforehand
    again = fem.stress_fields(model, u, gradients=displacement_gradients(model, u))
    assert np.array_equal(again.nodal.von_mises, nodal.von_mises)
    nv = model.n_vertices
    s = fem.nodal_stress_operator(model) @ u
    for k, comp in enumerate((nodal.sxx, nodal.syy, nodal.sxy)):
        assert np.allclose(s[k * nv:(k + 1) * nv], comp, rtol=0, atol=1e-15 * np.abs(comp).max())  # measured 3.5e-16
    # the rows of a few vertices (in the order given) are the whole operator's rows exactly
    some = np.array([nv - 1, 0, nv // 2, 7])
    whole = fem.nodal_stress_operator(model).tocsr()
    rows = fem.nodal_stress_operator(model, some)
    assert rows.shape == (3 * some.size, model.n_dofs)
    assert (rows - whole[np.concatenate([some + c * nv for c in range(3)])]).count_nonzero() == 0
