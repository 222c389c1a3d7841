"""The verification manual: every reference rvfem is checked against, recomputed and written out.

``python -m rvfem.app.verification docs/verification.md`` recomputes each check of the validation
ladder (docs/theory.md, section 10) from the same rvfem functions the test suite calls and writes a
Markdown table per rung: the quantity, its source, the reference value, rvfem's value, the error
and the tolerance. ``--check`` recomputes and compares with the file instead (exit status 1 when it
is stale). The inputs are fixed (shipped case files with coarse mesh overrides, structured meshes
built here with numpy), and every number is printed to a few significant digits. A relative error at
noise level is printed as a bound rather than as its digits, which differ between machines (BLAS
kernels, thread counts): below 1e-12 it is round-off (``< 1e-12``), below 1e-6 round-off amplified
by a solve (``< 1e-06``), each bound lowered to the check's tolerance where that is smaller
(:func:`noise_bound`). The document is then reproducible to the byte wherever every check passes.

The reference computations that need more than a formula (closed-form elasticity fields, the
structured meshes they are compared on, a beam integrated numerically) are written here,
independently of the code they check. The whole document takes under a minute of CPU time (coarse
meshes, 10° steps; about two minutes of wall time on a busy two-core machine).
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import math
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, ElementVector, FacetBasis, Functional, LinearForm, asm

from rvfem import fem
from rvfem.case.definition import RollerProfile, load_case
from rvfem.evaluate import compare, lubrication, rigid, roller_life, roller_slices, strength
from rvfem.evaluate.accuracy import ARCMIN_PER_RAD, accuracy_figures
from rvfem.evaluate.hertz import composite_modulus, hertz_peak_pressure, reduced_radius
from rvfem.evaluate.iso281 import (
    bearing_speed_rpm,
    crank_bearing_rating,
    dynamic_load_rating,
    rating_life_hours,
)
from rvfem.evaluate.rigid import (
    handbook_bearing_loads,
    load_cycle_angles,
    summarize_bearing_loads,
)
from rvfem.fem import crankshaft
from rvfem.fem.model import _scalar_element
from rvfem.geometry import Circle, FanHole, disc_geometry, mass
from rvfem.mesh import gmsh_session, mesh_case
from rvfem.solve import accuracy, contact, cycle, models
from rvfem.solve.cycle import build_system
from rvfem.units import nmm_from_nm

log = logging.getLogger(__name__)

__all__ = ["Check", "Section", "all_sections", "render", "main"]

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"
COARSE_MESH = ("mesh.size_flank=0.6", "mesh.size_bore=0.6", "mesh.size_interior=4", "mesh.size_hole=0.8")
STEP_DEG = 10.0
ROUND_OFF = 1e-12
"""Relative errors below this (or below the check's tolerance, if smaller) are round-off and printed
as the bound ``< 1e-12`` (:func:`noise_bound`)."""

NOISE_FLOOR = 1e-6
"""Relative errors below this (or below the check's tolerance, if smaller) and above
:data:`ROUND_OFF` are printed as the bound ``< 1e-06`` (:func:`noise_bound`).

The relative errors of the checks fall in three groups, decades apart (measured on the shipped
manual): round-off of an identity evaluated directly, 0 to 8e-16 (one 5.6e-14); round-off
amplified by a solve (iterative pair solves, a stiff limit of 1e14 N/mm, a sum of 2e5 trapezoids),
2.9e-11 to 3.3e-9, whose digits differ between machines (one printed 3.2e-09 where another printed
3.3e-09); and the accuracy of a discretisation or a model against a closed form, 2e-6 and above,
the same on every machine to the digits printed. The bounds lie between the groups, more than a
decade from every noise-level error (5.6e-14 and 2.9e-11 around 1e-12; 3.3e-9 below 1e-6, 1.8e-10
below a tolerance of 1e-8), so that no error flips between a figure and a bound from one machine to
the next; the accuracy error nearest a bound (2e-6) is a model's and does not move."""


@dataclass(frozen=True)
class Check:
    """One row of the manual.

    Attributes
    ----------
    quantity : str
        What is compared, with its unit.
    source : str
        Where the reference value comes from (a paper, a textbook, a closed form, a limit).
    reference, value : float or str
        The reference value and rvfem's value (a string for a statement such as "0 (exact)").
    error : float
        The measured error, in the sense of ``error_kind``.
    tolerance : float
        The largest error accepted (the test suite's tolerance for the same check).
    error_kind : str
        ``"relative"``, ``"absolute"`` (in the quantity's unit), ``"rate"`` (difference of a
        convergence order) or ``"relative to F_max"``.
    """

    quantity: str
    source: str
    reference: float | str
    value: float | str
    error: float
    tolerance: float
    error_kind: str = "relative"

    @property
    def passed(self) -> bool:
        return bool(abs(self.error) <= self.tolerance)


@dataclass(frozen=True)
class Section:
    """A rung of the validation ladder: a title, what it checks, its rows and what is pending."""

    title: str
    text: str
    checks: tuple[Check, ...]
    pending: tuple[str, ...] = ()


def _number(x, digits: int = 6) -> str:
    if isinstance(x, str):
        return x
    x = float(x)
    if x == 0.0:
        return "0"
    if not math.isfinite(x):
        return str(x)
    return f"{x:.{digits}g}"


def noise_bound(check: Check, error: float | None = None) -> float | None:
    """The bound a noise-level ``error`` (default the check's) is printed as, None if it is printed
    as a figure: for the relative error kinds (``relative``, ``relative to F_max``) below
    min(:data:`ROUND_OFF`, tolerance) that bound, else below min(:data:`NOISE_FLOOR`, tolerance)
    that one. Never above the tolerance: a bound is a pass. An absolute error (in the quantity's
    unit) and a rate are always printed as figures."""
    if not check.error_kind.startswith("relative") or check.tolerance <= 0:
        return None
    e = abs(check.error if error is None else float(error))
    for floor in (ROUND_OFF, NOISE_FLOOR):
        if e < min(floor, check.tolerance):
            return min(floor, check.tolerance)
    return None


def _error(check: Check) -> str:
    bound = noise_bound(check)
    return f"{abs(check.error):.2g}" if bound is None else f"< {bound:.0e}"


def _case(name: str, *overrides: str):
    return load_case(CASES / f"{name}.toml", COARSE_MESH + overrides if "fanholes" in name else
                     tuple(o for o in COARSE_MESH if "size_hole" not in o) + overrides)


def _thetas() -> np.ndarray:
    return load_cycle_angles(STEP_DEG)


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


# ------------------------------------------------------------------------------------------------
# 4-6. Rigid limits, equilibrium, symmetry (the FE chain on the RV-40E pair)
# ------------------------------------------------------------------------------------------------


@dataclass
class _Discs:
    """The coarse RV-40E discs and their models, built once per generator run."""

    cache: Path
    systems: dict

    def system(self, name: str, **options):
        key = (name, tuple(sorted(options.items())))
        if key not in self.systems:
            case = _case(name)
            self.systems[key] = build_system(case, mesh_case(case, self.cache), **options)
        return self.systems[key]


def rigid_limit_section(discs: _Discs) -> Section:
    theta = _thetas()
    stiff = dict(stiffness_scale=1e6, bearing_model="rigid_bore", bearing_stiffness_scale=1e3,
                 pin_model="linear", pin_stiffness_N_per_mm=3e5)
    # the handbook and the classical distribution have no friction
    case = _case("rv40e_solid", "analysis.friction=0")
    system = dataclasses.replace(discs.system("rv40e_solid", **stiff), case=case)
    one = cycle.load_cycle(system, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(system))
    hb = rigid.handbook_bearing_loads(case, theta)
    f_max = hb.magnitude.max()
    hb_vec = np.stack([hb.fx, hb.fy], axis=-1).transpose(1, 0, 2)
    e_vec = np.abs(one.bearing_forces - hb_vec).max() / f_max
    pins = rigid.classical_pin_forces(case, theta, exact_moment=True).magnitude.T
    e_pin = np.abs(one.pin_forces - pins).max() / pins.max()
    loaded = set(int(n) for n in one.pins_in_contact)
    pair_stage = cycle.build_stage(system, discs=2, influence=None)
    pair = cycle.load_cycle(system, theta, saved_angles_deg=(), stage=pair_stage)
    T = nmm_from_nm(case.loads.torque_Nm)
    share = np.abs(pair.disc_torque_Nmm / (T / 2) - 1.0).max()
    e_pair = np.abs(pair.bearing_loads.T - hb.magnitude).max() / f_max
    linear = discs.system("rv40e_solid", stiffness_scale=1e3)
    lin_case = _case("rv40e_solid", 'crank_bearing.stiffness_law="linear"',
                     "crank_bearing.linear_stiffness_N_per_mm=2e5", "analysis.friction=0")
    lin_system = dataclasses.replace(linear, case=lin_case,
                                     bearings=models.bearing_model("rollers")(lin_case, 1.0))
    lin = cycle.load_cycle(lin_system, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(lin_system))
    e_share = (np.abs(lin.bearing_forces - compare.equal_share_forces(lin_case, lin)).max()
               / lin.bearing_loads.max())
    hand = "handbook model, Gao et al. eqs. 4-10 (rigid disc, T/2 per disc)"
    classical = "classical rigid pin-force distribution F_i = F_max·sin φ_i/√(1 + K1² − 2K1 cos φ_i)"
    checks = (
        Check("one disc 10⁶× stiffer, rigid bores: bearing force vectors vs handbook", hand, "handbook",
              f"{f_max:.1f} N peak", e_vec, 0.03, "relative to F_max"),
        Check("same: pin forces vs the classical distribution", classical, "classical",
              f"{pins.max():.1f} N peak", e_pin, 0.01, "relative to F_max"),
        Check("same: pins in contact at every angle", "classical: half the pins (0 < φ < π)",
              case.pins.count // 2, "/".join(str(n) for n in sorted(loaded)),
              max(abs(n - case.pins.count // 2) for n in loaded), 0.0, "absolute"),
        Check("stiff disc 1000×, linear rollers: bearing forces vs equal share of the FE pin resultant",
              "handbook load sharing (each bearing 1/N of the pin resultant plus the torque share)",
              "equal share", f"{lin.bearing_loads.max():.1f} N peak", e_share, 0.005, "relative to F_max"),
        Check("two stiff discs on one carrier: torque share T_disc/(T/2) − 1", "rigid limit of the pair: "
              "equal stiffness gives equal shares", 0.0, share, share, 0.005, "absolute"),
        Check("two stiff discs: bearing loads vs handbook", hand, "handbook", f"{pair.bearing_loads.max():.1f} N peak",
              e_pair, 0.03, "relative to F_max"),
    )
    return Section("4. Rigid limits and the torque split of stiff discs",
                   f"Coarse RV-40E solid disc, {STEP_DEG:g}° steps; 'stiff' is the disc 10⁶× stiffer, "
                   "rigid-bore bearings 1000× stiffer and linear pin springs of 3e5 N/mm, no pin friction (the "
                   "handbook's assumptions).", checks)


def invariants_section(discs: _Discs) -> tuple[Section, Section]:
    theta = _thetas()
    solid = discs.system("rv40e_solid")
    case = solid.case
    one = cycle.load_cycle(solid, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(solid))
    c = cycle.crank_centres(case)
    moment = (c[None, :, 0] * one.bearing_forces[..., 1] - c[None, :, 1] * one.bearing_forces[..., 0]).sum(axis=1)
    e_moment = np.abs(moment / case.loads.disc_torque_Nmm - 1.0).max()
    fan = discs.system("rv40e_fanholes")
    stage = cycle.case_stage(fan)
    pair = cycle.load_cycle(fan, theta, saved_angles_deg=(), stage=stage)
    assert pair.disc_torque_Nmm is not None   # a stage's cycle has the disc torques
    T = nmm_from_nm(fan.case.loads.torque_Nm)
    e_carrier = np.abs(pair.disc_torque_Nmm.sum(axis=1) / T - 1.0).max()
    eq = Section("5. Equilibrium", "Every solve: pins and bearings balance on each disc; the carrier "
                 "takes the output torque.", (
                     Check("one disc: ‖ΣF‖ / Σλ over the cycle (solid)", "Newton's third law", 0.0,
                           float(one.equilibrium_residual.max()), float(one.equilibrium_residual.max()), 1e-9,
                           "relative"),
                     Check("one disc: bearings' moment about the centre / disc torque − 1 (solid)",
                           "moment balance", 0.0, e_moment, e_moment, 1e-9, "relative"),
                     Check("two discs on crankshafts: (T_A + T_B)/T_out − 1 (fan holes)", "carrier moment balance",
                           0.0, e_carrier, e_carrier, 1e-12, "relative"),
                     Check("two discs on crankshafts: ‖ΣF‖ / Σλ (fan holes)", "Newton's third law", 0.0,
                           float(pair.equilibrium_residual.max()), float(pair.equilibrium_residual.max()), 1e-9,
                           "relative"),
                 ))

    shift = int(round(360.0 / case.cranks.count / STEP_DEG))
    full_case = _case("rv40e_solid", "mesh.symmetric=false")
    full = build_system(full_case, mesh_case(full_case, discs.cache))
    every = cycle.load_cycle(full, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(full))
    F = every.bearing_loads
    e = max(np.abs(F[:, i] - np.roll(F[:, 0], i * shift)).max() for i in range(1, case.cranks.count)) / F.max()
    rows = [Check("one solid disc, full-disc mesh, every angle solved: bearing i at θ + 120°·i vs bearing 1 "
                  "at θ", "N-fold symmetry (Zc = 39 divisible by N = 3)", 0.0, float(e), float(e), 0.005,
                  "relative to F_max")]
    worst = 0.0
    for j in (7, 20, 33):               # pairs obtained by 120° turns and 180° swaps
        direct = cycle.solve_pair(stage, float(theta[j]))
        worst = max(worst, float(np.abs(direct.bearing_forces[0] - pair.bearing_forces[j]).max()))
    worst /= float(pair.bearing_loads.max())
    rows.append(Check("fan-hole pair on crankshafts, symmetric mesh: pairs turned and swapped from "
                      f"{pair.timings['pair_solves']} solved ones vs the same pairs solved directly",
                      "exact N-fold and mirror symmetry of the mesh and the load cycle", 0.0, worst, worst, 1e-8,
                      "relative to F_max"))
    sym = Section("6. Symmetry", "A full-disc (unstructured) mesh is not exactly symmetric: its bearing curves "
                  "agree to discretisation accuracy. The default mesh of an N-fold symmetric disc is one "
                  "360°/N sector copied by rotation: exactly symmetric, so the crank angles of one sector "
                  "give the others by turning, to round-off.", tuple(rows))
    return eq, sym


# ------------------------------------------------------------------------------------------------
# 7. Mesh convergence and P1 vs P2
# ------------------------------------------------------------------------------------------------


def convergence_section(discs: _Discs) -> Section:
    theta = _thetas()
    levels = (("coarse", ("mesh.size_flank=0.8", "mesh.size_bore=0.8", "mesh.size_interior=5",
                          "mesh.size_hole=1.0")),
              ("medium", COARSE_MESH),
              ("case file", ("mesh.size_flank=0.35", "mesh.size_bore=0.4", "mesh.size_interior=2.5",
                             "mesh.size_hole=0.5")))

    peaks, nodes = [], []
    for _, sizes in levels:
        case = load_case(CASES / "rv40e_fanholes.toml", sizes)
        mesh = mesh_case(case, discs.cache)
        system = cycle.build_system(case, mesh)
        one_disc = cycle.single_disc_stage(system)
        peaks.append(float(cycle.load_cycle(system, theta, saved_angles_deg=(), stage=one_disc).bearing_loads.max()))
        nodes.append(mesh.n_nodes)
    change = peaks[2] / peaks[1] - 1.0
    p2 = discs.system("rv40e_fanholes", order=2)
    p1 = discs.system("rv40e_fanholes")
    f2 = float(cycle.load_cycle(p2, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(p2)).bearing_loads.max())
    f1 = float(cycle.load_cycle(p1, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(p1)).bearing_loads.max())
    checks = (
        Check(f"fan-hole disc, one disc: peak bearing load, {nodes[1]} → {nodes[2]} nodes, N",
              "validation ladder (docs/theory.md § 10): < 1 % between the two finest meshes", peaks[1], peaks[2], change, 0.01),
        Check(f"same, {nodes[0]} → {nodes[1]} nodes (for the trend), N", "monotone approach", peaks[0], peaks[1],
              peaks[1] / peaks[0] - 1.0, 0.02),
        Check("fan-hole disc, medium mesh: peak bearing load P2 vs P1, N", "P2 is the reference", f2, f1,
              f1 / f2 - 1.0, 0.01),
    )
    return Section("7. Mesh convergence and P1 vs P2",
                   "Fan-hole disc, one disc with T/2, discrete rollers, peak of the three bearings' loads "
                   f"over a turn in {STEP_DEG:g}° steps.", checks)


# ------------------------------------------------------------------------------------------------
# 8. The reducer stage: beams, support springs, crankshaft limits
# ------------------------------------------------------------------------------------------------


def beam_by_integration(span: float, load_at: float, x: np.ndarray, EI: float) -> np.ndarray:
    """Deflection of a simply supported beam under a unit load, integrating M/EI twice (trapezoids,
    2e5 steps) with y(0) = y(L) = 0: independent of the closed forms."""
    s = np.linspace(0.0, span, 200001)
    M = np.where(s <= load_at, (span - load_at) / span * s, load_at / span * (span - s))
    k = M / EI
    slope = np.concatenate([[0.0], np.cumsum(0.5 * (k[1:] + k[:-1]) * np.diff(s))])
    y0 = np.concatenate([[0.0], np.cumsum(0.5 * (slope[1:] + slope[:-1]) * np.diff(s))])
    return np.interp(x, s, -(y0 - y0[-1] * s / span))


def reducer_section(discs: _Discs) -> Section:
    L, EI, kGA = 40.0, 2.0e9, 3.0e7
    roark = "Roark's *Formulas for Stress and Strain*, simply supported beam, central load: L³/(48EI)"
    f_mid = crankshaft.beam_influence(L, [L / 2], EI)[0, 0]
    z = np.array([13.0, 24.5])
    f_two = crankshaft.beam_influence(L, z, EI)
    ref_two = np.column_stack([beam_by_integration(L, z[j], z, EI) for j in range(2)])
    e_two = np.abs(f_two / ref_two - 1.0).max()
    f_shear = crankshaft.beam_influence(L, [L / 2], np.inf, kGA)[0, 0]
    c1, c2 = 2e-6, 5e-6
    f_spring = crankshaft.beam_influence(L, [L / 2], np.inf, None, (c1, c2))[0, 0]
    f_end = crankshaft.beam_influence(L, [1e-6 * L], np.inf, None, (c1, c2))[0, 0]
    checks = [
        Check("beam influence, central load, mm/N", roark, L**3 / (48 * EI), f_mid, f_mid / (L**3 / (48 * EI)) - 1,
              1e-14),
        Check("beam influence matrix, loads at 13 and 24.5 mm of 40 mm, mm/N (all four entries)",
              "M/EI integrated twice numerically (2e5 trapezoids)", float(ref_two[0, 1]), float(f_two[0, 1]),
              e_two, 1e-6),
        Check("Maxwell–Betti: f12 − f21, mm/N", "reciprocity", 0.0, float(f_two[0, 1] - f_two[1, 0]),
              float(f_two[0, 1] - f_two[1, 0]), 0.0, "absolute"),
        Check("shear only, central load, mm/N", "Timoshenko beam: L/(4κGA)", L / (4 * kGA), f_shear,
              f_shear / (L / (4 * kGA)) - 1, 1e-14),
        Check("support springs only, central load, mm/N", "springs and a lever: (c1 + c2)/4", (c1 + c2) / 4,
              f_spring, f_spring / ((c1 + c2) / 4) - 1, 1e-14),
        Check("support springs only, load at the support, mm/N", "the load goes into support 1: c1", c1, f_end,
              f_end / c1 - 1, 1e-5),
    ]
    theta = _thetas()[:6]
    fan = discs.system("rv40e_fanholes")
    rigid = cycle.load_cycle(fan, theta, saved_angles_deg=(), stage=cycle.build_stage(fan, discs=2, influence=None))
    stiff = cycle.load_cycle(fan, theta, saved_angles_deg=(), stage=cycle.build_stage(
        fan, discs=2, influence=1e-14 * np.array([[2.0, 1.0], [1.0, 2.0]])))
    e_stiff = np.abs(stiff.bearing_forces - rigid.bearing_forces).max() / np.abs(rigid.bearing_forces).max()
    checks.append(Check("crankshafts of 10¹⁴ N/mm vs rigid crank support: bearing forces",
                        "limit of a rigid crank support", "rigid support",
                        f"{np.abs(stiff.bearing_forces).max():.1f} N peak", e_stiff, 1e-6, "relative to F_max"))
    f = crankshaft.beam_influence(40.0, [15.0, 25.0], 2e9, 3e7, (2e-6, 2e-6))
    pair = cycle.solve_pair(cycle.build_stage(fan, discs=2, influence=f), 0.3)
    w = -np.einsum("kl,lnj->knj", f, pair.bearing_forces)
    e_w = np.abs(pair.eccentric_displacement - w).max() / np.abs(w).max()
    checks.append(Check("eccentric displacements vs −f·F of both discs' bearing forces",
                        "the crankshaft influence matrix", "−f·F", f"{np.abs(w).max() * 1000:.3f} µm peak",
                        e_w, 1e-12, "relative"))
    # reverse torque: with the cranks at 0°, 120°, 240° the configuration is mirror-symmetric about
    # the x axis, so −T at −θ is the mirror image (x, −y) of +T at θ, bearing at α ↔ bearing at −α



    base = load_case(CASES / "rv40e.toml")
    fwd = base.replace(cranks=dataclasses.replace(base.cranks, angles_deg=(0.0, 120.0, 240.0)))
    rev = fwd.replace(loads=dataclasses.replace(fwd.loads, torque_Nm=-fwd.loads.torque_Nm))
    th = np.radians(np.arange(0.0, 360.0, 7.0))
    a, b = handbook_bearing_loads(fwd, th), handbook_bearing_loads(rev, -th)
    mirror = [0, 2, 1]
    e_rev = max(np.abs(b.fx[mirror] - a.fx).max(), np.abs(b.fy[mirror] + a.fy).max()) / a.magnitude.max()
    checks.append(Check("handbook, reversed torque at −θ vs the mirror image of forward torque at θ",
                        "mirror symmetry of the configuration (cranks at 0°, 120°, 240°)", "mirror image",
                        f"{a.magnitude.max():.1f} N peak", e_rev, 1e-12, "relative to F_max"))
    return Section("8. The reducer stage: crankshaft beams, support springs, limits, reverse torque",
                   "Beam closed forms on a 40 mm span, EI = 2e9 N·mm², κGA = 3e7 N; the crankshaft "
                   f"limits on the coarse fan-hole pair (first six {STEP_DEG:g}° steps); the reverse-torque "
                   "mirror of the handbook model (the FE mirror, on a mirrored mesh, is tests/solve/test_contact.py).",
                   tuple(checks))


# ------------------------------------------------------------------------------------------------
# The document
# ------------------------------------------------------------------------------------------------


def _roller_pair_with_play(clearance: float, torque: float) -> tuple[float, float, float]:
    """A rigid body held by a stiff ground spring, turned by the carrier through two opposite
    Palmgren rollers with the radial clearance g each, started with both rollers open: (the loaded
    roller's force, the carrier travel φ, the closed form a + g + δ_Palmgren(T) of φ)."""
    length, k_ground = 9.0, 1e9
    law = contact.palmgren_law(length, contacts=2)
    iface = type("Interface", (), {"resultants": np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])})()
    compliance = type("Compliance", (), {"C": np.zeros((2, 2), order="F"), "ensure": lambda self, cols: None})()
    W = sp.csc_matrix(np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.0]]))
    cset = contact.ContactSet(W, np.zeros(3, dtype=bool), np.zeros(3), np.array([-clearance, -clearance, 0.0]),
                              np.array([1.0, -1.0, 0.0]),
                              [(np.arange(2), law), (np.array([2]), contact.linear_law(k_ground, bilateral=True))])
    start = [contact.AngleSolution(np.zeros(3), np.zeros((3, 2)), np.zeros(3), np.zeros(3), 0.0, 0)]
    sol = contact.solve_bodies([contact.Body(cset, iface, compliance)], torque, start=start, rigid_dofs=(0,))[0]
    palmgren = 2 * contact.PALMGREN_COEFFICIENT * torque**0.9 / length**0.8
    return float(sol.force[0]), float(sol.carrier_rotation), float(sol.rigid[0]) + clearance + palmgren


def clearance_section(discs: _Discs) -> Section:
    theta = _thetas()
    force, phi, phi_ref = _roller_pair_with_play(0.01, 500.0)
    # a 5 µm preload on a (1000×) rigid disc at a vanishing torque: every roller at Palmgren's load
    # of its 2.5 µm approach
    stiff = discs.system("rv40e_solid", stiffness_scale=1e3)
    pre_case = _case("rv40e_solid", "crank_bearing.radial_clearance=-0.005", "loads.torque_Nm=0.001")
    pre = dataclasses.replace(stiff, case=pre_case, bearings=models.bearing_model("rollers")(pre_case, 1.0))
    rollers = cycle.solve_angle(pre, 0.3).roller_loads
    assert rollers is not None   # the 'rollers' bearing model
    b = pre_case.crank_bearing
    q = (0.0025 * b.roller_length**0.8 / (2 * contact.PALMGREN_COEFFICIENT)) ** (1 / 0.9)
    # a 20 µm clearance on the flexible disc: every angle carries the torque (rvfem 0.3 lost it)
    gap_case = _case("rv40e_solid", "crank_bearing.radial_clearance=0.02")
    base = discs.system("rv40e_solid")
    gap = dataclasses.replace(base, case=gap_case, bearings=models.bearing_model("rollers")(gap_case, 1.0))
    run = cycle.load_cycle(gap, theta, saved_angles_deg=(), stage=cycle.single_disc_stage(gap))
    T = gap_case.loads.disc_torque_Nmm
    e_torque = max(abs(r.solution.residual["torque_Nmm"] / T - 1.0) for r in run.solutions)
    palmgren = "Palmgren's line contact δ = 2·3.84e-5·Q^0.9/L^0.8 (Harris & Kotzalas), both raceways"
    checks = (
        Check("roller pair with 10 µm play, started with both rollers open: loaded roller force, N",
              "equilibrium: the carrier torque T on a unit lever", 500.0, force, force / 500.0 - 1.0, 1e-9),
        Check("same: carrier travel φ, mm", "a + g + δ_Palmgren(T) (" + palmgren + ")", phi_ref, phi,
              phi / phi_ref - 1.0, 1e-7),
        Check("5 µm preload, disc 1000× stiffer, 1e-3 N·m: every roller's load, N",
              palmgren + " at the 2.5 µm approach", q, f"{rollers.min():.1f}–{rollers.max():.1f}",
              float(np.abs(rollers / q - 1.0).max()), 0.01),
        Check("20 µm clearance, flexible disc: torque carried at every angle, T_disc",
              "the carrier equation Σ m·λ = T_disc", 1.0, 1.0 + e_torque, e_torque, 1e-9),
    )
    return Section("9. Crank-bearing clearance and preload",
                   f"Coarse RV-40E solid disc, {STEP_DEG:g}° steps, one disc with T/2. A clearance opens every "
                   "roller by half of it at zero load, a preload (negative clearance) compresses every roller "
                   "by half of it; the solve carries the disc through a clearance onto its rollers.", checks)


def roller_depth_section() -> Section:
    """11. The crank bearing in depth: Hertz check of Zhang et al., the logarithmic profile's design
    property, the lamina life at the rating, the film against a second formula, the crankshaft slope."""
    zhang = ("Zhang et al., *Contact load and elastohydrodynamic lubrication analysis of eccentric bearings in RV "
             "reducer considering the effects of roller profile modification*")
    p_zhang = hertz_peak_pressure(1978.0, 8.5, 0.095)
    e_star, r_in = composite_modulus(206000.0, 0.3), reduced_radius(2.5, 13.0, concave=False)
    log = roller_slices.roller_contact(1978.0, 9.0, r_in, e_star, RollerProfile(kind="logarithmic", design_load_N=1978.0),
                                       slices=60)
    case = _case("rv40e_fanholes")
    c = crank_bearing_rating(case.crank_bearing)
    qci, qce = roller_life.lamina_ratings(case, 30)
    z = case.crank_bearing.rollers
    damage = []
    for phase in np.linspace(0.0, 2.0 * math.pi / z, 8, endpoint=False):
        q = roller_slices.rigid_ring_roller_loads(np.array([c, 0.0]), phase + 2.0 * np.pi * np.arange(z) / z)
        lam = np.repeat(q[:, None] / 30.0, 30, axis=1)
        damage.append(1.0 / float(roller_life.lamina_life_mrev(lam, lam, qci, qce, inner_rotates=True)))
    life = 1.0 / float(np.mean(damage))
    film = lubrication.pan_hamrock_film(143.0, r_in, e_star, 0.025, 0.474, 20.0).minimum_um
    film_dh = lubrication.dowson_higginson_min_film(143.0, r_in, e_star, 0.025, 0.474, 20.0)
    span, ei = 33.0, 206000.0 * math.pi * 20.0**4 / 64.0
    slope = float(roller_life.beam_slope_influence(span, [1e-9, span / 2.0], ei)[0, 1])
    checks = (
        Check("Hertz peak of Zhang et al.'s roller, Q = 1978 N, L = 8.5 mm, b = 95 µm, MPa", zhang + ", p_h = 1.56 GPa",
              1560.0, p_zhang, p_zhang / 1560.0 - 1.0, 0.005),
        Check("logarithmic (Johns–Gohar) roller at its design load 1978 N: peak / Hertz at Q/L",
              "Lundberg's profile: uniform pressure along the roller", 1.0, log.edge_factor, log.edge_factor - 1.0, 0.01),
        Check("lamina life (ISO/TS 16281) at P = C, rigid rings, straight rollers, 10⁶ rev",
              "definition of the basic dynamic load rating C (ISO 281)", 1.0, life, life - 1.0, 0.01),
        Check("minimum film, 143 N/mm, 25 mPa·s, 0.47 m/s, α = 20/GPa (Pan & Hamrock), µm",
              "Dowson & Higginson's line-contact h_min", film_dh, film, film / film_dh - 1.0, 0.10),
        Check("crankshaft slope at a support under a central load, rad/N",
              "Roark: P·L²/(16·EI)", span**2 / (16.0 * ei), slope, slope / (span**2 / (16.0 * ei)) - 1.0, 1e-6),
    )
    return Section("11. The crank bearing in depth",
                   "The slice model of a roller on an elastic half-space, the ISO/TS 16281 lamina life, the EHL film "
                   "and the crankshaft's slope at the eccentrics (docs/theory.md § 12). The slice model against a "
                   "two-dimensional half-space solve is in tests/evaluate/test_roller_slices.py.", checks)


def _stiff_accuracy_stage(discs: _Discs, *overrides: str):
    """The coarse solid RV-40E in the stiff limit of the accuracy checks: disc ×10³, linear pins of
    2·10⁸ N/mm and rollers of 3·10⁷ N/mm, rigid eccentrics, both discs; ``overrides`` add the play."""
    case = _case("rv40e_solid", "pins.model='linear'", "pins.linear_stiffness_N_per_mm=2e8",
                 "crank_bearing.stiffness_law='linear'", "crank_bearing.linear_stiffness_N_per_mm=3e7", *overrides)
    system = build_system(case, mesh_case(case, discs.cache), stiffness_scale=1e3)
    return cycle.build_stage(system, discs=2, influence=None)


def accuracy_section(discs: _Discs) -> Section:
    T = 412.0
    linear = _case("rv40e_solid", "pins.model='linear'", "pins.linear_stiffness_N_per_mm=2e5",
                   "crank_bearing.stiffness_law='linear'", "crank_bearing.linear_stiffness_N_per_mm=3e5")
    stage = cycle.case_stage(build_system(linear, mesh_case(linear, discs.cache)))
    loop = accuracy.hysteresis_loop(stage, 0.3, T, steps=8)
    phi = cycle.solve_pair(stage, 0.3, op=cycle.OperatingPoint(T)).results[0].carrier_rotation
    plus = loop.torque_Nm > 0
    e_lin = float(np.abs(loop.torque_Nm[plus] / loop.rotation_rad[plus] / (T / phi) - 1.0).max())
    dr, g2 = 0.01, 0.01
    eq = _stiff_accuracy_stage(discs, f"cycloid.modification.equidistant={dr}")
    fig_eq = accuracy_figures(*_loop_arrays(accuracy.hysteresis_loop(eq, 0.0, T, steps=8)), T)
    c = eq.first.case
    ref_eq = 2.0 * dr / (c.cycloid.eccentricity * c.cycloid.teeth) * ARCMIN_PER_RAD
    cl = _stiff_accuracy_stage(discs, f"crank_bearing.radial_clearance={g2}")
    fig_cl = accuracy_figures(*_loop_arrays(accuracy.hysteresis_loop(cl, 0.0, T, steps=8)), T)
    ref_cl = g2 / c.cranks.circle_radius * ARCMIN_PER_RAD
    liu = ("Liu et al., Degradation law analysis and life estimation of transmission accuracy of RV reducer "
           "based on tooth surface and bearing wear, § 4.4")
    checks = (
        Check("linear pins and rollers, no play: T/φ at every step of the + branches / T_R/φ(T_R)",
              "one stage solve at T_R (φ ∝ T without gaps)", 1.0, 1.0 + e_lin, e_lin, 1e-7),
        Check("lost motion, equidistant ΔR_rp = 10 µm only, stiff limit, arcmin",
              "ΔB_c = (180·60/π)·ΔE/(e·Zc), ΔE = 2ΔR_rp (" + liu + ")", ref_eq, fig_eq.lost_motion_arcmin,
              fig_eq.lost_motion_arcmin / ref_eq - 1.0, 0.02),
        Check("lost motion, crank-bearing clearance 10 µm only, stiff limit, θ = 0, arcmin",
              "ΔB_tb = (180·60/π)·Δu/a_sp, a_sp = r0 (" + liu + ")", ref_cl, fig_cl.lost_motion_arcmin,
              fig_cl.lost_motion_arcmin / ref_cl - 1.0, 0.02),
    )
    return Section("10. Transmission accuracy: the hysteresis loop",
                   "Coarse RV-40E solid disc, both discs on one carrier, input locked (crank angle held), the "
                   "loop 0 → +412 → 0 → −412 → 0 N·m in 8 steps. Stiff limit: disc ×10³, linear pins 2·10⁸ N/mm, "
                   "rollers 3·10⁷ N/mm, rigid eccentrics. The closed forms use e·Zc because the carrier rotation "
                   "turns the eccentrics about the disc centre (docs/theory.md § 9b).", checks)


def _loop_arrays(loop) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return loop.torque_Nm, loop.rotation_rad, loop.branch


def _sector_disc_checks() -> tuple[Check, ...]:
    """A disc of a 3600-gon (circumradius 60 mm), a central hole (12), three bores (9 at 36 mm) and
    three sharp annular-sector holes (17…49 mm, 0.6 rad) against the closed forms."""
    n, R, beta = 3600, 60.0, 2 * math.pi / 3600
    a_out = 0.5 * n * R * R * math.sin(beta)
    j_out = a_out * R * R * (2 + math.cos(beta)) / 6
    a_ref = a_out - math.pi * 12**2 - 3 * math.pi * 9**2 - 3 * 0.3 * (49**2 - 17**2)
    j_ref = (j_out - math.pi * 12**4 / 2 - 3 * (math.pi * 9**4 / 2 + math.pi * 9**2 * 36**2)
             - 3 * 0.3 * (49**4 - 17**4) / 2)
    ang = 2 * np.pi * np.arange(n) / n
    outline = np.stack([R * np.cos(ang), R * np.sin(ang)], axis=1)
    area, polar = mass.polygon_area_polar(outline)
    for f in [Circle("central_hole", (0.0, 0.0), 12.0)] + [
            Circle(f"bore_{i}", (36 * math.cos(a), 36 * math.sin(a)), 9.0) for i, a in enumerate(np.radians([90, 210, 330]))] + [
            FanHole(f"hole_{i}", 17.0, 49.0, math.radians(30 + 120 * i), 0.3, 0.0) for i in range(3)]:
        a, j = mass.outline_area_polar(f)
        area, polar = area - a, polar - j
    source = "closed forms: n-gon, circles by parallel axes, annular sectors α(r_o² − r_i²), α(r_o⁴ − r_i⁴)/2"
    return (Check("disc with three annular-sector holes: area, mm²", source, a_ref, area, area / a_ref - 1, 1e-9),
            Check("same: polar moment ∬ r² dA, mm⁴", source, j_ref, polar, polar / j_ref - 1, 1e-9))


def mass_strength_section(discs: _Discs) -> Section:
    """Disc mass and polar inertia against closed forms and the mesh integral; the fatigue safety
    factor against the Goodman line by hand."""
    case = _case("rv40e_fanholes")
    props = mass.disc_mass_properties(disc_geometry(case))
    m = mesh_case(case, discs.cache)
    a_mesh, j_mesh = mass.mesh_area_polar(m.points, m.triangles)
    theta = np.radians(np.arange(0.0, 360.0, 1.0))
    steel = case.material
    sa, sm = 300.0, 200.0
    s1 = sm + sa * np.sin(theta)
    amp, mean = strength.amplitude_mean(strength.signed_von_mises(s1, np.zeros_like(s1)))
    hand = 1.0 / (sa / steel.fatigue_limit + sm / steel.ultimate_strength)
    sf = strength.goodman_safety_factor(float(amp), float(mean), steel.fatigue_limit, steel.ultimate_strength)
    sf48 = strength.goodman_safety_factor(48 * float(amp), 48 * float(mean), steel.fatigue_limit,
                                          steel.ultimate_strength)
    checks = _sector_disc_checks() + (
        Check("coarse fan-hole disc: area from the P1 mesh, mm²", "Green's theorem over the outlines (rvfem.geometry.mass)",
              props.area_mm2, a_mesh, a_mesh / props.area_mm2 - 1, 5e-4),
        Check("same: polar moment from the P1 mesh, mm⁴", "Green's theorem over the outlines",
              props.polar_mm4, j_mesh, j_mesh / props.polar_mm4 - 1, 5e-4),
        Check("plate, σ = 200 + 300 sin θ MPa uniaxial: fatigue safety factor",
              f"Goodman by hand, 1/(σ_a/σ_W + σ_m/R_m), σ_W = {steel.fatigue_limit:g}, R_m = {steel.ultimate_strength:g} MPa",
              hand, sf, sf / hand - 1, 1e-12),
        Check("same, load × 48: fatigue safety factor", "proportional scaling: S/48", hand / 48, sf48,
              sf48 / (hand / 48) - 1, 1e-12),
    )
    return Section("12. Disc mass, inertia and fatigue strength",
                   "Mass and polar inertia by Green's theorem over the outlines (docs/theory.md § 13) against closed "
                   "forms and against the coarse P1 mesh (straight-sided triangles: the chords of the curved "
                   "boundaries, an error falling as h²); the fatigue safety factor (FKM signed von Mises on the "
                   "Goodman line) of a plate under an alternating uniaxial stress against the hand calculation.",
                   checks)


def all_sections(cache_dir: str | Path | None = None) -> list[Section]:
    """Compute every section (meshes cached in ``cache_dir``, a temporary folder by default)."""

    with tempfile.TemporaryDirectory() as tmp:
        discs = _Discs(Path(cache_dir) if cache_dir is not None else Path(tmp), {})
        sections = [fe_core_section(), contact_section(), seed_section(), rigid_limit_section(discs)]
        sections.extend(invariants_section(discs))
        sections.append(convergence_section(discs))
        sections.append(reducer_section(discs))
        sections.append(clearance_section(discs))
        sections.append(accuracy_section(discs))
        sections.append(roller_depth_section())
        sections.append(mass_strength_section(discs))
    return sections


def _value(check: Check) -> str:
    """rvfem's value; against a reference of 0 the value is an error and is printed like one
    (:func:`_error`: two digits, or the bound of :func:`noise_bound` at noise level): its later
    digits depend on the alignment of arrays in the BLAS kernels and change from run to run
    (CHOLMOD's with a reference BLAS do)."""
    v = check.value
    if not isinstance(v, str) and check.reference == 0:
        bound = noise_bound(check, float(v))
        return _number(v, 2) if bound is None else f"< {bound:.0e}"
    return _number(v)


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def render(sections: list[Section]) -> str:
    """The Markdown text of the manual."""
    total = sum(len(s.checks) for s in sections)
    passed = sum(c.passed for s in sections for c in s.checks)
    pending = [p for s in sections for p in s.pending]
    out = [
        "# Verification manual",
        "",
        "<!-- generated by `python -m rvfem.app.verification docs/verification.md`; do not edit by hand -->",
        "",
        "Each row recomputes one reference of the validation ladder (docs/theory.md, section 10) with the same "
        "rvfem functions the test suite calls: the quantity, the source of the reference value, the reference, "
        "rvfem's value, the error and the tolerance (the test suite's for the same check). Errors are relative "
        "unless the column says otherwise. Relative errors at noise level, whose digits differ between machines, "
        "are printed as bounds: below 1e-12 round-off (< 1e-12), below 1e-6 round-off amplified by a solve "
        "(< 1e-06), each bound lowered to the tolerance where that is smaller. "
        "Regenerate with `python -m rvfem.app.verification docs/verification.md` (under a minute of CPU "
        "time); `--check` compares instead and fails when this file is stale.",
        "",
        f"**{passed} of {total} checks within tolerance; {len(pending)} pending.**",
        "",
    ]
    for s in sections:
        out += [f"## {s.title}", "", s.text, "",
                "| quantity | source | reference | rvfem | error | kind | tolerance | |",
                "|---|---|---|---|---|---|---|---|"]
        for c in s.checks:
            out.append(f"| {_cell(c.quantity)} | {_cell(c.source)} | {_number(c.reference)} | {_value(c)} | "
                       f"{_error(c)} | {c.error_kind} | {c.tolerance:.2g} | {'ok' if c.passed else '**FAIL**'} |")
        out.append("")
        for p in s.pending:
            out += [f"*Pending.* {p}", ""]
    return "\n".join(out).rstrip("\n") + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m rvfem.app.verification", description=__doc__.splitlines()[0])
    parser.add_argument("path", nargs="?", default=str(ROOT / "docs" / "verification.md"),
                        help="the manual to write (or to check)")
    parser.add_argument("--check", action="store_true", help="compare with the file instead of writing it")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    text = render(all_sections())
    log.info("verification computed in %.0f s", time.perf_counter() - t0)
    path = Path(args.path)
    if args.check:
        current = path.read_text(encoding="utf-8") if path.is_file() else ""
        if current != text:
            print(f"{path} is stale: regenerate it with python -m rvfem.app.verification {path}", file=sys.stderr)
            return 1
        print(f"{path} is up to date")
        return 0
    path.write_text(text, encoding="utf-8")
    print(f"wrote {path} ({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
