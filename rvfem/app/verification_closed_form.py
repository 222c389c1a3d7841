"""The verification manual's checks against closed forms and published numbers: the FE core against
closed-form elasticity (section 1), contact against Hertz (section 2) and the seed numbers (section 3).

The reference computations that need more than a formula (closed-form elasticity fields, the
structured meshes they are compared on) are written here, independently of the code they check.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, ElementVector, FacetBasis, Functional, LinearForm, asm

from rvfem import fem
from rvfem.app.verification_check import CASES, Check, Section
from rvfem.case.definition import load_case
from rvfem.evaluate import bearing_checks, roller_slices
from rvfem.evaluate.hertz import hertz_peak_pressure, rigid_ring_factor
from rvfem.evaluate.iso281 import (
    bearing_speed_rpm,
    crank_bearing_rating,
    dynamic_load_rating,
    rating_life_hours,
)
from rvfem.evaluate.rigid import handbook_bearing_loads, summarize_bearing_loads
from rvfem.fem.model import _scalar_element
from rvfem.mesh import gmsh_session
from rvfem.solve import contact


# ------------------------------------------------------------------------------------------------
# 1. FE core against closed-form elasticity
# ------------------------------------------------------------------------------------------------

E, NU, THICK = 2.1e5, 0.3, 10.0


def quads_to_triangles(idx: np.ndarray) -> np.ndarray:
    """Two triangles per quad of a structured (rows × columns) grid of vertex indices, the diagonal
    alternating like a chequerboard (no preferred direction)."""
    a, b = idx[:-1, :-1], idx[1:, :-1]
    c, d = idx[1:, 1:], idx[:-1, 1:]
    alt = (np.add.outer(np.arange(a.shape[0]), np.arange(a.shape[1])) % 2).astype(bool)
    t1 = np.where(alt[..., None], np.stack([a, b, c], -1), np.stack([a, b, d], -1))
    t2 = np.where(alt[..., None], np.stack([a, c, d], -1), np.stack([b, c, d], -1))
    return np.concatenate([t1.reshape(-1, 3), t2.reshape(-1, 3)])


def structured_annulus(ri: float, ro: float, nr: int, nt: int):
    """Structured annulus mesh: points, triangles, inner and outer boundary edges."""
    r = np.linspace(ri, ro, nr + 1)
    th = np.linspace(0.0, 2.0 * np.pi, nt, endpoint=False)
    pts = np.stack([np.outer(r, np.cos(th)), np.outer(r, np.sin(th))], -1).reshape(-1, 2)
    ids = np.arange((nr + 1) * nt).reshape(nr + 1, nt)
    tris = quads_to_triangles(np.concatenate([ids, ids[:, :1]], axis=1))
    ring = lambda row: np.column_stack([row, np.roll(row, -1)])  # noqa: E731
    return pts, tris, ring(ids[0]), ring(ids[-1])


def structured_plate_with_hole(a: float, w: float, nt: int, nr: int, grading: float = 1.1):
    """Square plate [−w, w]² with a central hole of radius a (O-grid, graded towards the hole)."""
    th = np.linspace(0.0, 2.0 * np.pi, nt, endpoint=False)
    c, s = np.cos(th), np.sin(th)
    r_out = w / np.maximum(np.abs(c), np.abs(s))
    g = grading ** np.arange(nr)
    eta = np.concatenate([[0.0], np.cumsum(g) / g.sum()])
    r = a + np.outer(eta, r_out - a)
    pts = np.stack([r * c, r * s], -1).reshape(-1, 2)
    ids = np.arange((nr + 1) * nt).reshape(nr + 1, nt)
    tris = quads_to_triangles(np.concatenate([ids, ids[:, :1]], axis=1))
    ring = lambda row: np.column_stack([row, np.roll(row, -1)])  # noqa: E731
    return pts, tris, ring(ids[0]), ring(ids[-1])


def lame_solution(a: float, b: float, p: float):
    """Lamé ring under internal pressure p, plane stress (Timoshenko & Goodier, *Theory of
    Elasticity*, § 28): u(x, y) and σ_r, σ_θ (r)."""
    A = p * a * a / (b * b - a * a)
    B = p * a * a * b * b / (b * b - a * a)

    def u(x, y):
        f = ((1 - NU) * A + (1 + NU) * B / (x * x + y * y)) / E
        return f * x, f * y

    def grad(x, y):
        r2 = x * x + y * y
        f = ((1 - NU) * A + (1 + NU) * B / r2) / E
        df = -(1 + NU) * B / (E * r2 * r2)
        return np.array([[f + 2 * df * x * x, 2 * df * x * y], [2 * df * x * y, f + 2 * df * y * y]])

    return u, grad, (lambda r: (A - B / r**2, A + B / r**2))


def kirsch_stress(a: float, s0: float):
    """Kirsch: infinite plate with a hole of radius a under remote σ_xx = σ0 (Timoshenko & Goodier
    § 35): σ_xx, σ_yy, σ_xy at (x, y)."""

    def stress(x, y):
        r, th = np.hypot(x, y), np.arctan2(y, x)
        q = a * a / (r * r)
        srr = s0 / 2 * (1 - q) + s0 / 2 * (1 - 4 * q + 3 * q * q) * np.cos(2 * th)
        stt = s0 / 2 * (1 + q) - s0 / 2 * (1 + 3 * q * q) * np.cos(2 * th)
        srt = -s0 / 2 * (1 + 2 * q - 3 * q * q) * np.sin(2 * th)
        c, s = np.cos(th), np.sin(th)
        return (srr * c * c + stt * s * s - 2 * srt * s * c, srr * s * s + stt * c * c + 2 * srt * s * c,
                (srr - stt) * s * c + srt * (c * c - s * s))

    return stress


def traction_load(model, edges: np.ndarray, traction, n_quad: int = 4) -> np.ndarray:
    """b ∫ t·v ds of a traction t(x, y, nx, ny) (MPa) on boundary edges, assembled by scikit-fem's
    ``FacetBasis`` (independent of rvfem's footprint quadrature), N."""


    fb = FacetBasis(model.mesh, model.basis.elem, facets=fem.edge_indices(model, edges), intorder=2 * n_quad - 1)

    @LinearForm
    def load(v, w):
        tx, ty = traction(w.x[0], w.x[1], w.n[0], w.n[1])
        return tx * v[0] + ty * v[1]

    return model.thickness * asm(load, fb)


def lame_pressure_displacement_error(order: int, nr: int) -> float:
    """Max nodal displacement error / max displacement of the Lamé ring (pressure on the bore,
    floating body, rigid motion removed)."""

    a, b, p = 10.0, 20.0, 100.0
    pts, tris, inner, _ = structured_annulus(a, b, nr, 12 * nr)
    m = fem.build_model(pts, tris, E, NU, THICK, order)
    f = traction_load(m, inner, lambda x, y, nx, ny: (-p * nx, -p * ny))
    u = fem.factorize(m).solve(f)
    ud, _ = fem.remove_rigid_motion(m, u)
    u_ex, _, _ = lame_solution(a, b, p)
    ux, uy = u_ex(*m.node_coords.T)
    du = ud[m.node_dofs] - np.column_stack([ux, uy])
    return float(np.hypot(*du.T).max() / np.hypot(ux, uy).max())


def lame_dirichlet_errors(order: int, nr: int) -> tuple[float, float, float]:
    """h, L2 and energy-norm errors with the exact Lamé displacement prescribed on the boundary
    (no geometric error: the rates are the elements' own)."""


    a, b = 10.0, 20.0
    pts, tris, inner, outer = structured_annulus(a, b, nr, 8 * nr)
    m = fem.build_model(pts, tris, E, NU, 1.0, order)
    u_ex, g_ex, _ = lame_solution(a, b, 100.0)
    r = np.hypot(*m.node_coords.T)
    on_bnd = (np.abs(r - a) < 1e-9) | (np.abs(r - b) < 1e-9)
    if order == 2:
        on_bnd[m.n_vertices + fem.edge_indices(m, np.vstack([inner, outer]))] = True
    d = m.node_dofs[on_bnd].ravel()
    g = np.zeros(m.n_dofs)
    gx, gy = u_ex(*m.node_coords[on_bnd].T)
    g[m.node_dofs[on_bnd, 0]], g[m.node_dofs[on_bnd, 1]] = gx, gy
    free = np.setdiff1d(np.arange(m.n_dofs), d)
    k = m.stiffness.tocsr()
    u = g.copy()
    u[free] = spla.spsolve(k[free][:, free].tocsc(), -(k[free][:, d] @ g[d]))
    basis = Basis(m.mesh, ElementVector(_scalar_element(order)), intorder=8)
    lam, mu = fem.plane_stress_constants(E, NU)

    @Functional
    def l2(w):
        ex, ey = u_ex(w.x[0], w.x[1])
        return (w.uh[0] - ex) ** 2 + (w.uh[1] - ey) ** 2

    @Functional
    def energy(w):
        e = w.uh.grad - g_ex(w.x[0], w.x[1])
        eps = 0.5 * (e + np.swapaxes(e, 0, 1))
        tr = eps[0, 0] + eps[1, 1]
        return lam * tr * tr + 2 * mu * (eps * eps).sum(axis=(0, 1))

    uh = basis.interpolate(u)
    return (b - a) / nr, math.sqrt(l2.assemble(basis, uh=uh)), math.sqrt(energy.assemble(basis, uh=uh))


def kirsch_concentration() -> tuple[float, float]:
    """σ_xx/σ0 at the top of the hole and σ_yy/σ0 at its side, P2, exact tractions on the square."""

    a, w, s0 = 1.0, 8.0, 100.0
    pts, tris, _, outer = structured_plate_with_hole(a, w, 96, 28, 1.1)
    m = fem.build_model(pts, tris, E, NU, THICK, 2)
    s_ex = kirsch_stress(a, s0)

    def traction(x, y, nx, ny):
        sxx, syy, sxy = s_ex(x, y)
        return sxx * nx + sxy * ny, sxy * nx + syy * ny

    u = fem.factorize(m).solve(traction_load(m, outer, traction, n_quad=6))
    st = fem.stress_fields(m, u)
    top = int(np.argmin(np.hypot(pts[:, 0], pts[:, 1] - a)))
    side = int(np.argmin(np.hypot(pts[:, 0] - a, pts[:, 1])))
    return float(st.nodal.sxx[top] / s0), float(st.nodal.syy[side] / s0)


def fe_core_section() -> Section:
    checks = []
    src_lame = "Lamé thick ring, Timoshenko & Goodier, *Theory of Elasticity* § 28"
    coarse, fine = lame_pressure_displacement_error(1, 8), lame_pressure_displacement_error(1, 16)
    checks.append(Check("Lamé ring, P1, 16×192 mesh: max displacement error / max displacement", src_lame,
                        0.0, fine, fine, 2.5e-3, "relative"))
    rate = math.log2(coarse / fine)
    checks.append(Check("Lamé ring, P1: displacement convergence order (h → h/2)", src_lame + "; O(h²) for P1",
                        2.0, rate, rate - 2.0, 0.05, "rate"))
    p2 = lame_pressure_displacement_error(2, 16)
    checks.append(Check("Lamé ring, P2, 16×192 mesh: max displacement error / max displacement", src_lame,
                        0.0, p2, p2, 2.5e-4, "relative"))
    src_rate = "a priori estimate: ‖e‖_L2 = O(h^(k+1)), ‖e‖_energy = O(h^k) (exact Lamé field on the boundary)"
    for order, levels in ((1, (16, 32)), (2, (8, 16))):
        (h1, l1, e1), (h2, l2, e2) = (lame_dirichlet_errors(order, n) for n in levels)
        r_l2 = math.log(l1 / l2) / math.log(h1 / h2)
        r_en = math.log(e1 / e2) / math.log(h1 / h2)
        checks.append(Check(f"P{order}: L2 error convergence order", src_rate, order + 1.0, r_l2,
                            r_l2 - (order + 1.0), 0.05, "rate"))
        checks.append(Check(f"P{order}: energy error convergence order", src_rate, float(order), r_en,
                            r_en - order, 0.05, "rate"))
    sxx, syy = kirsch_concentration()
    src_k = "Kirsch plate with a hole, Timoshenko & Goodier § 35"
    checks.append(Check("Kirsch, P2: σ_xx/σ0 at the top of the hole", src_k, 3.0, sxx, sxx - 3.0, 0.008, "absolute"))
    checks.append(Check("Kirsch, P2: σ_yy/σ0 at the side of the hole", src_k, -1.0, syy, syy + 1.0, 0.007, "absolute"))
    return Section("1. FE core against closed-form elasticity",
                   "Structured meshes built with numpy, tractions assembled by scikit-fem's own facet "
                   "basis; plane stress, E = 2.1e5 MPa, ν = 0.3.", tuple(checks))


# ------------------------------------------------------------------------------------------------
# 2. Contact against Hertz
# ------------------------------------------------------------------------------------------------


def squeezed_cylinder_mesh(radius: float, size: float):
    """Gmsh mesh of a disc of ``radius`` (mm), ``size`` mm elements within |x| < 1 mm of the two
    poles (the contact zones against flat plates), growing away from them: points (n, 2),
    triangles (m, 3) and the rim's edges (k, 2)."""

    with gmsh_session("cylinder") as gmsh:
        gmsh.model.occ.addDisk(0, 0, 0, radius, radius)
        gmsh.model.occ.synchronize()
        field = gmsh.model.mesh.field
        f = field.add("MathEval")
        field.setString(f, "F", f"{size} + 0.2*Max(Abs(x) - 1.0, 0) + 0.2*Max({radius} - 0.8 - Abs(y), 0)")
        field.setAsBackgroundMesh(f)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.mesh.generate(2)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        _, _, tri = gmsh.model.mesh.getElements(2)
        _, _, lines = gmsh.model.mesh.getElements(1)
    index = np.zeros(int(tags.max()) + 1, dtype=int)
    index[tags.astype(int)] = np.arange(len(tags))
    return (xyz.reshape(-1, 3)[:, :2], index[tri[0].astype(int)].reshape(-1, 3),
            index[lines[0].astype(int)].reshape(-1, 2))


def hertz_cylinder(approach: float = 0.02) -> tuple[float, float, float, float]:
    """An elastic cylinder (R = 10 mm, L = 1 mm) squeezed between rigid plates, Signorini contacts on
    a 0.03 mm mesh: (FE half-width, Hertz half-width, FE peak pressure, Hertz peak pressure)."""


    R, L, Ec, nu, h = 10.0, 1.0, 2.0e5, 0.3, 0.03
    points, triangles, rim = squeezed_cylinder_mesh(R, h)
    model = fem.build_model(points, triangles, Ec, nu, L, order=1)
    factor = fem.factorize(model)
    iface = contact.build_interface(model, {"rim": rim}, fem.rigid_body_modes(model), {}, {"rim": 0.25 * h})
    grid = iface.grids["rim"]
    near = np.flatnonzero(np.abs(grid.polyline[:, 0]) < 0.9)
    cols, w = grid.columns_at(grid.chain.s[near], -grid.polyline[near] / R)
    n = len(near)
    W = sp.csc_matrix((w.ravel(), (cols.ravel(), np.repeat(np.arange(n), cols.shape[1]))),
                      shape=(iface.n_columns, n))
    xy = grid.polyline[near]
    gap0 = (R - np.abs(xy[:, 1])) - approach
    cset = contact.ContactSet(W, np.ones(n, bool), gap0, np.zeros(n), np.zeros(n), [])
    sol = contact.solve_contact(cset, iface, contact.Compliance(factor.solve, iface.B), None,
                                rigid_dofs=(1,), max_iterations=60)
    top = xy[:, 1] > 0
    force = sol.force[top].sum()
    b_hertz = math.sqrt(4 * force * R / (math.pi * Ec * L))
    p_hertz = 2 * force / (math.pi * b_hertz * L)
    loaded = sol.force[top] > 0
    x_top = np.abs(xy[top, 0])
    b_fe = 0.5 * (x_top[loaded].max() + x_top[~loaded].min())
    return float(b_fe), b_hertz, float(sol.force[top].max() / (h * L)), p_hertz


def contact_section() -> Section:
    b_fe, b_h, p_fe, p_h = hertz_cylinder()
    src = "Hertz line contact, Johnson, *Contact Mechanics* § 4.3 (cylinder on a rigid flat)"
    return Section("2. Contact against Hertz",
                   "Cylinder R = 10 mm, length 1 mm, E = 2e5 MPa, between rigid plates 0.02 mm closer "
                   "than touching; Signorini contacts at every rim vertex near the poles (0.03 mm mesh). "
                   "The Hertz values are computed from the FE contact force.",
                   (Check("half-width b, mm", src, b_h, b_fe, b_fe / b_h - 1.0, 0.05),
                    Check("peak pressure p0, MPa", src, p_h, p_fe, p_fe / p_h - 1.0, 0.03)))


# ------------------------------------------------------------------------------------------------
# 3. Seed numbers
# ------------------------------------------------------------------------------------------------


def seed_section() -> Section:
    gao = "Gao et al., *Lifespan evaluation for a standard RV reducer based on fatigue strength theory*"
    li = "Li et al., *Life calculation of the swivel-arm bearing of an RV reducer considering cycloid pitch error*"
    zhang = ("Zhang et al., *Contact load and EHL analysis of eccentric bearings in RV reducer considering "
             "roller profile modification*")
    crv = load_case(CASES / "crv80e.toml")
    loads = handbook_bearing_loads(crv)
    s4 = summarize_bearing_loads(loads, 4.0)[0]
    c_d = crank_bearing_rating(crv.crank_bearing)
    n_b = bearing_speed_rpm(crv.loads.speed_rpm, crv.pins.count, crv.cycloid.teeth)
    life = rating_life_hours(c_d, s4.equivalent_N, n_b)
    c_li = dynamic_load_rating(13, 6.0, 11.8, 36.0, b_m=1.0, lambda_nu=0.83)
    life_li = rating_life_hours(28378.5, 6115.8, 600.0)
    p_h = hertz_peak_pressure(1978.0, 8.5, 0.095)
    checks = (
        Check("CRV-80E handbook maximum bearing load (1° sampling), N", gao + ", eqs. 4-8", 5576.2, s4.max_N,
              s4.max_N / 5576.2 - 1.0, 2.5e-4),
        Check("CRV-80E fourth-power mean load, N", gao + ", eq. 9", 4374.1, s4.equivalent_N,
              s4.equivalent_N - 4374.1, 0.05, "absolute"),
        Check("CRV-80E dynamic load rating C_d, N", gao + ", eqs. 11-13", 21948.7, c_d, c_d - 21948.7, 0.05,
              "absolute"),
        Check("bearing speed, 40 pins at 15 rpm output, rpm", gao, 600.0, n_b, n_b / 600.0 - 1.0, 1e-12),
        Check("CRV-80E rated life L0, h", gao + ", eq. 14", 6008.0, life, life - 6008.0, 1.0, "absolute"),
        Check("RV-110E dynamic load rating C, N (b_m = 1, L = 11.8 mm)", li, 28378.5, c_li, c_li - 28378.5, 0.1,
              "absolute"),
        Check("RV-110E life at P_eq = 6115.8 N, 600 rpm, h", li, 4629.0, life_li, life_li - 4629.0, 0.1,
              "absolute"),
        Check("peak Hertz pressure, Q = 1978 N, L = 8.5 mm, b = 95 µm, MPa", zhang, 1560.0, p_h,
              p_h / 1560.0 - 1.0, 5e-4),
    )
    return Section("3. Seed numbers", "Published values reproduced from the papers' own inputs; "
                   "absolute tolerances are half a unit of the last printed digit.", checks)


def bearing_checks_section() -> Section:
    """13. The checks next to L10h: the rigid most loaded roller against Stribeck's closed form, its
    limit for many rollers, ISO 76's C0 by hand and the support-bearing reactions by beam statics."""
    z, force = 14, 3000.0
    q = roller_slices.rigid_ring_roller_loads(np.array([force, 0.0]), 2.0 * np.pi * np.arange(z) / z)
    cosines = np.clip(np.cos(2.0 * np.pi * np.arange(z) / z), 0.0, None)
    q_closed = force / float(np.sum(cosines ** (19.0 / 9.0)))
    # Z/Σcos^(19/9) → 1/((1/2π)∫cos^(19/9)ψ dψ over the loaded half) for many rollers
    limit = 2.0 * math.pi * math.gamma(19.0 / 18.0 + 1.0) / (math.gamma(0.5) * math.gamma((19.0 / 9.0 + 1.0) / 2.0))
    k_many = rigid_ring_factor(2000)
    bearing = load_case(CASES / "rv40e_fanholes.toml").crank_bearing
    d_we, d_pw = bearing.roller_diameter, bearing.pitch_diameter
    c0_hand = 44.0 * (1.0 - d_we / d_pw) * bearing.rollers * bearing.roller_length * d_we
    c0 = bearing_checks.crank_bearing_static_rating(bearing)
    span, z_ecc, p = 33.0, 11.5, 100.0
    r2 = float(bearing_checks.support_reactions(span, [z_ecc], np.array([[p, 0.0]]))[1, 0])
    checks = (
        Check("most loaded roller of rigid rings, Z = 14, F = 3000 N, a roller on the load line, N",
              "Stribeck, line contact: Q_max = F/Σcos^(19/9)ψ_j (Harris & Kotzalas)", q_closed, float(q.max()),
              float(q.max()) / q_closed - 1.0, 1e-10),
        Check("rigid-ring factor Q_max·Z/F for 2000 rollers",
              "its integral limit 2π/∫cos^(19/9)ψ dψ = 4.085 (Stribeck's 'about 4.08')", limit, k_many,
              k_many / limit - 1.0, 1e-6),
        Check("C0 of the shipped crank bearing (D_we 5, D_pw 31, Z 14, L_we 9 mm), N",
              "ISO 76: C0r = 44·(1 − D_we·cos α/D_pw)·i·Z·L_we·D_we·cos α", c0_hand, c0, c0 / c0_hand - 1.0, 1e-12),
        Check("support-bearing reaction R2 of one eccentric load P = 100 N at z = 11.5 mm, span 33 mm, N",
              "beam statics: R2 = P·z/L", p * z_ecc / span, r2, r2 / (p * z_ecc / span) - 1.0, 1e-12),
    )
    return Section("13. The checks next to L10h",
                   "The rigid most loaded roller (one model for the Hertz table, the slice table and rvfem rigid), "
                   "the static safety S0 = C0/P0 and the support bearings' loads (docs/theory.md). The same checks "
                   "and the run's end-to-end agreement are in tests/evaluate/test_bearing_checks.py.", checks)
