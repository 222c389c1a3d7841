"""Stresses of a displacement field: per element, at the vertices, and as a linear operator.

σ = λ* tr(ε) I + 2μ ε with ε = sym ∇u and the plane-stress constants λ*, μ of
:func:`~rvfem.fem.model.plane_stress_constants` ([1]_ § 4.2, [2]_ § 15). Element stresses are
evaluated from the gradients of scikit-fem's scalar basis functions
(:func:`displacement_gradients`) at the reference vertices and the centroid of every triangle. Vertex stresses are recovered by area-weighted averaging of the element
values at the vertex over the triangles sharing it: for P1 (constant element stress) this is the
lumped-mass L2 projection onto continuous P1 ([1]_ § 14.3); for P2 the element stress is linear and
its vertex values are averaged. :func:`stress_fields` and :func:`nodal_stress_operator` share one
implementation of that average (:func:`_vertex_weights`) and of the constitutive law
(:func:`plane_stress_components`), so the envelope over a load cycle and the saved fields agree to round-off.

References
----------
.. [1] O. C. Zienkiewicz, R. L. Taylor, J. Z. Zhu, *The Finite Element Method: Its Basis and
   Fundamentals*, 7th ed., Butterworth-Heinemann, 2013 (stress recovery).
.. [2] S. P. Timoshenko, J. N. Goodier, *Theory of Elasticity*, 3rd ed., McGraw-Hill, 1970
   (plane stress, principal stresses).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rvfem._arrays import readonly as _readonly
from rvfem.fem.model import FEModel, plane_stress_constants

__all__ = [
    "StressState",
    "StressFields",
    "stress_fields",
    "displacement_gradients",
    "plane_stress_components",
    "nodal_stress_operator",
]


@dataclass(frozen=True, eq=False)
class StressState:
    """Plane-stress state (σ_zz = τ_xz = τ_yz = 0) at a set of points, MPa.

    Attributes
    ----------
    sxx, syy, sxy : numpy.ndarray
        Cartesian components.
    von_mises : numpy.ndarray
        √(σxx² − σxx σyy + σyy² + 3 τxy²).
    s1, s2 : numpy.ndarray
        In-plane principal stresses, s1 ≥ s2 (the third principal stress is σ_zz = 0).
    angle1 : numpy.ndarray
        Direction of s1 from the x axis, rad, in (−π/2, π/2].
    """

    sxx: np.ndarray
    syy: np.ndarray
    sxy: np.ndarray
    von_mises: np.ndarray
    s1: np.ndarray
    s2: np.ndarray
    angle1: np.ndarray

    @classmethod
    def from_components(cls, sxx: np.ndarray, syy: np.ndarray, sxy: np.ndarray) -> "StressState":
        """Derive von Mises and principal stresses from the Cartesian components (MPa): Mohr's
        circle with centre (σxx + σyy)/2 and radius √(((σxx − σyy)/2)² + τxy²) ([2]_ § 15)."""
        centre = 0.5 * (sxx + syy)
        radius = np.hypot(0.5 * (sxx - syy), sxy)
        vm = np.sqrt(np.maximum(sxx**2 - sxx * syy + syy**2 + 3.0 * sxy**2, 0.0))
        angle = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)
        return cls(*(_readonly(a) for a in (sxx, syy, sxy, vm, centre + radius, centre - radius, angle)))


@dataclass(frozen=True, eq=False)
class StressFields:
    """Stresses of a displacement field.

    Attributes
    ----------
    nodal : StressState
        At the mesh vertices (``n_vertices`` values): recovered by area-weighted averaging of the
        element stresses evaluated at the vertex over the triangles sharing it. For P1 (constant
        element stress) this is the lumped-mass L2 projection onto continuous P1; for P2 the
        element stress is linear and its vertex values are averaged. Derived quantities (von
        Mises, principal) are computed from the averaged components.
    element : StressState
        One value per triangle: the (constant) element stress for P1, the value at the
        centroid (= element mean of the linear field) for P2.
    """

    nodal: StressState
    element: StressState


def plane_stress_components(model: FEModel, g: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(σxx, σyy, σxy), MPa, from displacement gradients ``g[i, j] = ∂u_i/∂x_j`` (any trailing
    shape)."""
    lam, mu = plane_stress_constants(model.youngs_modulus, model.poissons_ratio)
    exx, eyy = g[0, 0], g[1, 1]
    exy = 0.5 * (g[0, 1] + g[1, 0])
    tr = exx + eyy
    return lam * tr + 2.0 * mu * exx, lam * tr + 2.0 * mu * eyy, 2.0 * mu * exy


def _vertex_weights(model: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """Weights of the vertex average: ``(w, denominator)`` with ``w[k, e]`` the area of triangle
    ``e`` (for its local vertex k) and ``denominator[v]`` the area of all triangles at vertex v,
    mm². The vertex value is Σ_(k,e at v) w[k, e]·σ_e(vertex k) / denominator[v]."""
    t = model.mesh.t                                        # (3, n_elements)
    p = model.mesh.p
    area = 0.5 * np.abs(
        (p[0, t[1]] - p[0, t[0]]) * (p[1, t[2]] - p[1, t[0]])
        - (p[1, t[1]] - p[1, t[0]]) * (p[0, t[2]] - p[0, t[0]])
    )
    w = np.tile(area, (3, 1))
    denom = np.bincount(t.ravel(), weights=w.ravel(), minlength=model.n_vertices)
    return w, denom


def nodal_stress_operator(model: FEModel, vertices: np.ndarray | Sequence[int] | None = None) -> sp.csr_matrix:
    """The linear map from displacements to the vertex stresses of :func:`stress_fields`.

    ``S @ u`` stacks (σxx, σyy, σxy) at the mesh vertices — area-averaged element values, exactly
    as ``stress_fields(model, u).nodal`` — for many fields at the cost of one sparse product each
    (the load cycle's stress envelope uses it at every crank angle).

    Parameters
    ----------
    model : FEModel
    vertices : array_like of int, optional
        Only the rows of these vertices, in the order given (default all; one may come twice): the hot-spot histories need a few rows, and
        the whole operator's assembly holds about 100 MB of temporaries on the default disc. The
        rows are those of the whole operator exactly (the same entries, summed in the same order).

    Returns
    -------
    scipy.sparse.csr_matrix
        ``(3·m, n_dofs)``, MPa/mm, m the number of vertices (``n_vertices`` by default); rows
        ``[0, m)`` σxx, ``[m, 2m)`` σyy, ``[2m, 3m)`` σxy, the vertices in the order given.
    """
    basis = model._stress_basis                              # scalar: one function per local node
    t = model.mesh.t
    nv = model.n_vertices
    row_of = np.arange(nv)
    elements: slice | np.ndarray = slice(None)
    if vertices is not None:
        vertices = np.asarray(vertices, dtype=np.int64).ravel()
        distinct, which = np.unique(vertices, return_inverse=True)
        if distinct.size < vertices.size:    # the rows of each vertex once, then in the order given
            rows = nodal_stress_operator(model, distinct)
            return rows[np.concatenate([which + c * distinct.size for c in range(3)])]
        row_of = np.full(nv, -1)
        row_of[vertices] = np.arange(vertices.size)
        elements = np.flatnonzero((row_of[t] >= 0).any(axis=0))   # the triangles at those vertices
        nv = vertices.size
    w, denom = _vertex_weights(model)
    w, tt = w[:, elements], t[:, elements]
    n_el = tt.shape[1]
    blocks = len(basis.basis) * 2 * 3 * 3
    rows = np.empty((blocks, n_el), dtype=np.int64)
    cols = np.empty((blocks, n_el), dtype=np.int64)
    vals = np.empty((blocks, n_el))
    b = 0
    for a, (phi_a,) in enumerate(basis.basis):
        dphi = phi_a.grad[:, elements, :3]                   # (2, n_elements, 3 vertices)
        for i in range(2):                                   # the vector function (a, component i)
            g = np.zeros((2,) + dphi.shape)
            g[i] = dphi
            comps = plane_stress_components(model, g)                  # each (n_elements, 3 vertices)
            dof = model.node_dofs[basis.element_dofs[a][elements], i]
            for c, sc in enumerate(comps):
                for k in range(3):
                    v = tt[k]
                    rows[b] = np.where(row_of[v] >= 0, c * nv + row_of[v], -1)
                    cols[b] = dof
                    vals[b] = sc[:, k] * w[k] / denom[v]
                    b += 1
    keep = (rows >= 0).ravel() if vertices is not None else slice(None)     # −1: another vertex
    return sp.csr_matrix((vals.ravel()[keep], (rows.ravel()[keep], cols.ravel()[keep])),
                         shape=(3 * nv, model.n_dofs))


def displacement_gradients(model: FEModel, u: np.ndarray) -> np.ndarray:
    """Displacement gradients ``g[i, j] = ∂u_i/∂x_j`` at the three vertices (local points 0, 1, 2)
    and the centroid (3) of every triangle, from the gradients of scikit-fem's scalar basis
    functions at those points.

    Parameters
    ----------
    model : FEModel
    u : numpy.ndarray
        ``(n_dofs,)`` displacement, mm.

    Returns
    -------
    numpy.ndarray
        ``(2, 2, n_elements, 4)``, dimensionless.
    """
    u = np.asarray(u, dtype=np.float64)
    if u.shape != (model.n_dofs,):
        raise ValueError(f"u must have shape ({model.n_dofs},), got {u.shape}")
    basis = model._stress_basis                              # scalar: ∂u_i/∂x_j = Σ_a u_i,a ∂φ_a/∂x_j
    components = u[model.node_dofs]                          # (n_nodes, 2): u_x, u_y of each node
    g = np.zeros((2, 2) + basis.basis[0][0].grad.shape[1:])
    for a, (phi_a,) in enumerate(basis.basis):
        ua = components[basis.element_dofs[a]]               # (n_elements, 2)
        for i in range(2):
            g[i] += ua[:, i][None, :, None] * phi_a.grad
    return g


def stress_fields(model: FEModel, u: np.ndarray, *, gradients: np.ndarray | None = None) -> StressFields:
    """Plane stresses of a displacement field, per element and at the vertices.

    Parameters
    ----------
    model : FEModel
    u : numpy.ndarray
        ``(n_dofs,)`` displacement, mm. Rigid-body motions produce no stress (to first order).
    gradients : numpy.ndarray, optional
        ``displacement_gradients(model, u)`` if already computed (then ``u`` is not read again).

    Returns
    -------
    StressFields
        MPa.
    """
    g = displacement_gradients(model, u) if gradients is None else gradients   # (2, 2, n_elements, 4)
    sxx, syy, sxy = plane_stress_components(model, g)

    element = StressState.from_components(sxx[:, 3].copy(), syy[:, 3].copy(), sxy[:, 3].copy())

    idx = model.mesh.t.ravel()                              # vertex of (local k, element e)
    w, denom = _vertex_weights(model)
    wts = w.ravel()

    def avg(f: np.ndarray) -> np.ndarray:
        return np.bincount(idx, weights=wts * f[:, :3].T.ravel(), minlength=model.n_vertices) / denom

    nodal = StressState.from_components(avg(sxx), avg(syy), avg(sxy))
    return StressFields(nodal=nodal, element=element)
