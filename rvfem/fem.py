"""Finite-element core: plane-stress stiffness of the disc, load operators, factorisation, stresses.

The cycloid disc is a 2D linear-elastic body in plane stress (thickness *b*, Young's modulus *E*,
Poisson's ratio ν), discretised with Lagrange triangles of order 1 (P1, linear) or 2 (P2, quadratic,
straight-sided) through scikit-fem. Units follow the project convention: lengths in mm, forces in N,
moduli and stresses in MPa. The stiffness matrix is multiplied by the thickness, so ``K @ u`` is a
nodal *force* in N for a displacement ``u`` in mm.

Nodes and degrees of freedom
----------------------------
A *node* here is a Lagrange interpolation node of the scalar element:

* P1: the mesh vertices, node ``i`` = vertex ``i``;
* P2: the mesh vertices first (node ``i`` = vertex ``i``, ``i < n_vertices``), then one node at the
  midpoint of every mesh edge (node ``n_vertices + f`` sits on edge ``f`` of
  :attr:`FEModel.edges`).

Every node has an x and a y degree of freedom; :attr:`FEModel.node_dofs` maps node → (x DOF, y DOF)
in the global numbering of the stiffness matrix. The displacement of node ``i`` is
``u[model.node_dofs[i]]``. The mesh vertices are numbered exactly as the ``points`` passed to
:func:`build_model`, so :func:`vertex_dofs` translates a mesh's vertex indices (for instance its
boundary edges) into DOFs for P1 and P2 alike.

Loads on the boundary
---------------------
Contact and roller forces are not applied as nodal point loads but as line loads spread over a short
*footprint* of the boundary, so that results converge under mesh refinement. The load of a unit
force distributed with a line density ρ(s) (1/mm, ∫ρ ds = 1) is turned into *consistent* nodal
loads ``W[i] = ∫ ρ(s) φ_i(s) ds`` with the element's own shape functions φ_i restricted to the
boundary edges (linear for P1; quadratic with the edge-midpoint node for P2), integrated by Gauss
quadrature. The scalar weights ``W`` (one column per footprint, columns sum to 1) and a direction
per column give the sparse *load operator* ``B`` (:func:`load_operator`): ``B @ f`` is the global
load vector of the forces ``f`` (N), and ``B.T @ u`` is the ρ-weighted average displacement of each
footprint along its direction (mm) — the work-conjugate quantity the contact solver needs.

Floating body
-------------
The disc is held only by contact and roller springs, so the bare ``K`` is singular (three rigid-body
modes). :func:`factorize` removes a minimal, statically determinate set of three DOFs (x and y of
one vertex, and the DOF of a far vertex perpendicular to the line joining them). For a
self-equilibrated load this changes the displacement only by a rigid-body motion (and the stresses
not at all); the contact solver carries the rigid motion as explicit unknowns
(:func:`rigid_body_modes`).

References
----------
.. [1] O. C. Zienkiewicz, R. L. Taylor, J. Z. Zhu, *The Finite Element Method: Its Basis and
   Fundamentals*, 7th ed., Butterworth-Heinemann, 2013 (plane stress, consistent loads,
   stress recovery).
.. [2] S. P. Timoshenko, J. N. Goodier, *Theory of Elasticity*, 3rd ed., McGraw-Hill, 1970
   (plane-stress constitutive law).
.. [3] T. Gustafsson, G. D. McBain, "scikit-fem: A Python package for finite element assembly",
   JOSS 5(52), 2369, 2020.
"""

from __future__ import annotations

import importlib.util
import logging
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, ElementTriP1, ElementTriP2, ElementVector, MeshTri, asm
from skfem.models.elasticity import linear_elasticity

from ._arrays import readonly as _readonly
from .errors import MeshError

__all__ = [
    "FEModel",
    "build_model",
    "plane_stress_constants",
    "vertex_dofs",
    "edge_indices",
    "edge_outward_normals",
    "BoundaryChain",
    "boundary_chains",
    "line_load_weights",
    "footprint_weights",
    "load_operator",
    "traction_vector",
    "SOLVER_PREFERENCE",
    "available_solvers",
    "default_support",
    "Factorization",
    "factorize",
    "factorize_matrix",
    "rigid_body_modes",
    "rigid_motion",
    "add_rigid_motion",
    "remove_rigid_motion",
    "StressState",
    "StressFields",
    "stress_fields",
    "nodal_stress_operator",
]

logger = logging.getLogger(__name__)


# --------------------------------------------------------------------------------------------
# Model
# --------------------------------------------------------------------------------------------




@dataclass(frozen=True, eq=False)
class FEModel:
    """Assembled plane-stress finite-element model of one disc.

    Build it with :func:`build_model`; the stiffness is assembled once and never changes.

    Attributes
    ----------
    mesh : skfem.MeshTri
        The triangle mesh (vertices numbered as the ``points`` given to :func:`build_model`).
    basis : skfem.CellBasis
        Vector Lagrange basis (P1 or P2) used to assemble ``stiffness``.
    order : int
        Element order, 1 or 2.
    youngs_modulus : float
        E, MPa.
    poissons_ratio : float
        ν, dimensionless.
    thickness : float
        Disc thickness b, mm.
    stiffness : scipy.sparse.csr_matrix
        Global stiffness K, N/mm, shape ``(n_dofs, n_dofs)``, symmetric positive semi-definite
        (three rigid-body modes).
    node_coords : numpy.ndarray
        ``(n_nodes, 2)`` coordinates of the Lagrange nodes, mm (vertices, then edge midpoints for
        P2).
    node_dofs : numpy.ndarray
        ``(n_nodes, 2)`` global x and y DOF index of every node.
    edges : numpy.ndarray
        ``(n_edges, 2)`` vertex indices of every mesh edge (sorted within a row); for P2, node
        ``n_vertices + f`` is the midpoint of edge ``f``.
    """

    mesh: MeshTri
    basis: Any
    order: int
    youngs_modulus: float
    poissons_ratio: float
    thickness: float
    stiffness: sp.csr_matrix
    node_coords: np.ndarray
    node_dofs: np.ndarray
    edges: np.ndarray
    _stress_basis: Any = field(repr=False)

    @property
    def n_vertices(self) -> int:
        """Number of mesh vertices."""
        return int(self.mesh.p.shape[1])

    @property
    def n_nodes(self) -> int:
        """Number of Lagrange nodes (vertices, plus edge midpoints for P2)."""
        return int(self.node_coords.shape[0])

    @property
    def n_dofs(self) -> int:
        """Number of degrees of freedom (2 per node)."""
        return int(self.stiffness.shape[0])

    @property
    def n_elements(self) -> int:
        """Number of triangles."""
        return int(self.mesh.t.shape[1])


def plane_stress_constants(youngs_modulus: float, poissons_ratio: float) -> tuple[float, float]:
    """Lamé constants of the plane-stress constitutive law.

    Plane stress (σ_zz = 0) eliminates ε_zz, which replaces the first Lamé constant λ by
    λ* = 2λμ/(λ + 2μ) = Eν/(1 − ν²); μ = E/(2(1 + ν)) is unchanged ([2]_ §§ 7, 15). Note that
    :func:`skfem.models.elasticity.lame_parameters` returns the 3D (plane-strain) λ.

    Parameters
    ----------
    youngs_modulus : float
        E, MPa.
    poissons_ratio : float
        ν.

    Returns
    -------
    (float, float)
        (λ*, μ) in MPa.
    """
    e, nu = float(youngs_modulus), float(poissons_ratio)
    return e * nu / (1.0 - nu * nu), e / (2.0 * (1.0 + nu))


def build_model(
    points: np.ndarray,
    triangles: np.ndarray,
    youngs_modulus: float,
    poissons_ratio: float,
    thickness: float,
    order: int = 1,
) -> FEModel:
    """Assemble the plane-stress stiffness of a triangle mesh.

    Parameters
    ----------
    points : numpy.ndarray
        ``(n, 2)`` vertex coordinates, mm. Every vertex must belong to a triangle.
    triangles : numpy.ndarray
        ``(m, 3)`` vertex indices of the triangles (either orientation).
    youngs_modulus : float
        E, MPa.
    poissons_ratio : float
        ν, 0 ≤ ν < 0.5.
    thickness : float
        Disc thickness b, mm. Multiplies the stiffness: ``K`` is in N/mm.
    order : int, optional
        1 (linear P1 triangles) or 2 (quadratic P2 triangles with straight sides).

    Returns
    -------
    FEModel

    Raises
    ------
    ValueError
        For non-physical material data or an unknown order.
    MeshError
        For malformed arrays, unused vertices or degenerate triangles.

    Notes
    -----
    ``K = b ∫ ε(v) : C ε(u) dA`` with the plane-stress law σ = λ* tr(ε) I + 2μ ε
    (:func:`plane_stress_constants`). scikit-fem's default quadrature (degree 2·order) integrates
    it exactly on straight-sided triangles.
    """
    if order not in (1, 2):
        raise ValueError(f"element order must be 1 or 2, got {order!r}")
    if not (youngs_modulus > 0.0):
        raise ValueError(f"Young's modulus must be positive, got {youngs_modulus!r} MPa")
    if not (0.0 <= poissons_ratio < 0.5):
        raise ValueError(f"Poisson's ratio must be in [0, 0.5), got {poissons_ratio!r}")
    if not (thickness > 0.0):
        raise ValueError(f"thickness must be positive, got {thickness!r} mm")

    points = np.asarray(points, dtype=np.float64)
    triangles = np.asarray(triangles)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) < 3:
        raise MeshError(f"points must have shape (n, 2) with n >= 3, got {points.shape}")
    if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) < 1:
        raise MeshError(f"triangles must have shape (m, 3), got {triangles.shape}")
    if not np.issubdtype(triangles.dtype, np.integer):
        raise MeshError("triangles must hold integer vertex indices")
    if triangles.min() < 0 or triangles.max() >= len(points):
        raise MeshError("triangle vertex index out of range")
    used = np.zeros(len(points), dtype=bool)
    used[triangles.ravel()] = True
    if not used.all():
        raise MeshError(
            f"{int((~used).sum())} vertices belong to no triangle (e.g. vertex "
            f"{int(np.flatnonzero(~used)[0])}); remove them before building the model"
        )
    a, b, c = (points[triangles[:, k]] for k in range(3))
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    scale2 = np.ptp(points, axis=0).max() ** 2
    bad = np.abs(area2) <= 1e-14 * scale2
    if bad.any():
        raise MeshError(f"{int(bad.sum())} degenerate (zero-area) triangles, e.g. #{int(np.flatnonzero(bad)[0])}")

    mesh = MeshTri(
        np.ascontiguousarray(points.T),
        np.ascontiguousarray(triangles.T.astype(np.int64)),
    )
    scalar = ElementTriP1() if order == 1 else ElementTriP2()
    basis = Basis(mesh, ElementVector(scalar))
    lam, mu = plane_stress_constants(youngs_modulus, poissons_ratio)
    stiffness = asm(linear_elasticity(lam * thickness, mu * thickness), basis).tocsr()
    stiffness.sort_indices()

    edges = np.ascontiguousarray(mesh.facets.T.astype(np.int64))
    if order == 1:
        node_coords = mesh.p.T.copy()
        node_dofs = basis.nodal_dofs.T.astype(np.int64)
    else:
        mid = 0.5 * (mesh.p[:, mesh.facets[0]] + mesh.p[:, mesh.facets[1]])
        node_coords = np.vstack([mesh.p.T, mid.T])
        node_dofs = np.vstack([basis.nodal_dofs.T, basis.facet_dofs.T]).astype(np.int64)
    if not np.array_equal(np.sort(node_dofs.ravel()), np.arange(basis.N)):
        raise AssertionError("node/DOF map does not cover the DOFs exactly once")  # pragma: no cover

    # Local points (reference triangle vertices 0, 1, 2 and the centroid) for stress recovery.
    xi = np.array([[0.0, 1.0, 0.0, 1.0 / 3.0], [0.0, 0.0, 1.0, 1.0 / 3.0]])
    stress_basis = Basis(mesh, ElementVector(scalar), quadrature=(xi, np.full(4, 0.125)))

    return FEModel(
        mesh=mesh,
        basis=basis,
        order=order,
        youngs_modulus=float(youngs_modulus),
        poissons_ratio=float(poissons_ratio),
        thickness=float(thickness),
        stiffness=stiffness,
        node_coords=_readonly(node_coords),
        node_dofs=_readonly(node_dofs),
        edges=_readonly(edges),
        _stress_basis=stress_basis,
    )


def vertex_dofs(model: FEModel, vertices: np.ndarray) -> np.ndarray:
    """Global DOF indices of mesh vertices.

    Parameters
    ----------
    model : FEModel
    vertices : array_like of int
        Vertex indices (any shape), as numbered in the mesh's ``points``.

    Returns
    -------
    numpy.ndarray
        Shape ``vertices.shape + (2,)``: the x and y DOF of each vertex. For P2 these are the
        vertex DOFs only; the edge-midpoint DOFs are reached through :attr:`FEModel.node_dofs`
        (node ``n_vertices + edge index``) or, for loads, through :func:`line_load_weights` and
        :func:`footprint_weights`, which include them.
    """
    v = np.asarray(vertices, dtype=np.int64)
    if v.size and (v.min() < 0 or v.max() >= model.n_vertices):
        raise IndexError("vertex index out of range")
    return model.node_dofs[v]


def edge_indices(model: FEModel, edges: np.ndarray) -> np.ndarray:
    """Index into :attr:`FEModel.edges` of each given vertex pair.

    Parameters
    ----------
    model : FEModel
    edges : array_like of int
        ``(k, 2)`` vertex pairs, either orientation.

    Returns
    -------
    numpy.ndarray
        ``(k,)`` edge indices (for P2, node ``n_vertices + index`` is the edge's midpoint).

    Raises
    ------
    MeshError
        If a pair is not an edge of the mesh.
    """
    e = np.sort(np.asarray(edges, dtype=np.int64).reshape(-1, 2), axis=1)
    nv = model.n_vertices
    keys = model.edges[:, 0] * nv + model.edges[:, 1]
    order = np.argsort(keys)
    q = e[:, 0] * nv + e[:, 1]
    pos = np.searchsorted(keys, q, sorter=order)
    pos = np.minimum(pos, len(keys) - 1)
    idx = order[pos]
    missing = keys[idx] != q
    if missing.any():
        j = int(np.flatnonzero(missing)[0])
        raise MeshError(f"vertex pair {tuple(int(x) for x in e[j])} is not an edge of the mesh")
    return idx


def edge_outward_normals(model: FEModel, edges: np.ndarray) -> np.ndarray:
    """Outward unit normals of boundary edges.

    Parameters
    ----------
    model : FEModel
    edges : array_like of int
        ``(k, 2)`` vertex pairs of boundary edges.

    Returns
    -------
    numpy.ndarray
        ``(k, 2)`` unit normals pointing out of the body (away from the edge's only triangle).

    Raises
    ------
    MeshError
        If an edge is not on the boundary of the mesh.
    """
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    f = edge_indices(model, e)
    f2t = model.mesh.f2t
    if (f2t[1, f] != -1).any():
        j = int(np.flatnonzero(f2t[1, f] != -1)[0])
        raise MeshError(f"edge {tuple(int(x) for x in e[j])} is interior, not on the boundary")
    tri = model.mesh.t[:, f2t[0, f]]                      # (3, k)
    third = tri.sum(axis=0) - e[:, 0] - e[:, 1]
    p = model.mesh.p.T
    d = p[e[:, 1]] - p[e[:, 0]]
    n = np.column_stack([d[:, 1], -d[:, 0]])
    n /= np.linalg.norm(n, axis=1)[:, None]
    inward = np.einsum("ij,ij->i", n, p[third] - p[e[:, 0]]) > 0.0
    n[inward] *= -1.0
    return n


# --------------------------------------------------------------------------------------------
# Boundary chains and consistent line loads
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class BoundaryChain:
    """One connected piece of boundary (a closed loop or an open path), ordered by arc length.

    The chain runs so that the body lies on its *left*: the outward normal of an edge with unit
    tangent t is (t_y, −t_x). Outer boundaries therefore run counter-clockwise and holes clockwise.
    Arc length s is measured along the polygon of straight mesh edges from ``vertices[0]``.

    Attributes
    ----------
    vertices : numpy.ndarray
        ``(k + 1,)`` vertex indices in order; for a closed chain the last equals the first.
    s : numpy.ndarray
        ``(k + 1,)`` arc length at the vertices, mm; ``s[0] = 0``, ``s[-1]`` = length.
    points : numpy.ndarray
        ``(k + 1, 2)`` vertex coordinates, mm.
    closed : bool
        True for a loop.
    """

    vertices: np.ndarray
    s: np.ndarray
    points: np.ndarray
    closed: bool

    @property
    def edges(self) -> np.ndarray:
        """``(k, 2)`` oriented vertex pairs of the chain's edges."""
        return np.column_stack([self.vertices[:-1], self.vertices[1:]])

    @property
    def length(self) -> float:
        """Total length, mm."""
        return float(self.s[-1])

    @property
    def normals(self) -> np.ndarray:
        """``(k, 2)`` outward unit normals of the edges."""
        d = np.diff(self.points, axis=0)
        d /= np.linalg.norm(d, axis=1)[:, None]
        return np.column_stack([d[:, 1], -d[:, 0]])

    def _wrap(self, s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=np.float64)
        if self.closed:
            return np.mod(s, self.length)
        if (s < -1e-12 * self.length).any() or (s > self.length * (1 + 1e-12)).any():
            raise ValueError("arc length outside an open chain")
        return np.clip(s, 0.0, self.length)

    def _edge_of(self, s: np.ndarray) -> np.ndarray:
        k = len(self.vertices) - 1
        return np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, k - 1)

    def point_at(self, s: np.ndarray) -> np.ndarray:
        """Coordinates ``(..., 2)`` of the points at arc lengths ``s`` (mm)."""
        s = self._wrap(s)
        i = self._edge_of(s)
        t = (s - self.s[i]) / (self.s[i + 1] - self.s[i])
        return self.points[i] + t[..., None] * (self.points[i + 1] - self.points[i])

    def normal_at(self, s: np.ndarray) -> np.ndarray:
        """Outward unit normals ``(..., 2)`` of the edges containing arc lengths ``s``."""
        return self.normals[self._edge_of(self._wrap(s))]

    def locate(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Arc length of the closest point of the chain to each of ``points``.

        Parameters
        ----------
        points : array_like
            ``(m, 2)`` coordinates, mm.

        Returns
        -------
        s : numpy.ndarray
            ``(m,)`` arc length of the closest chain point, mm.
        distance : numpy.ndarray
            ``(m,)`` distance to it, mm.
        """
        q = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        a, d = self.points[:-1], np.diff(self.points, axis=0)
        ll = np.einsum("ij,ij->i", d, d)
        s_out = np.empty(len(q))
        dist = np.empty(len(q))
        chunk = max(1, 2_000_000 // max(len(a), 1))
        for lo in range(0, len(q), chunk):
            qq = q[lo:lo + chunk, None, :]
            t = np.clip(np.einsum("mkj,kj->mk", qq - a[None], d) / ll, 0.0, 1.0)
            r = qq - (a[None] + t[..., None] * d[None])
            d2 = np.einsum("mkj,mkj->mk", r, r)
            j = np.argmin(d2, axis=1)
            rows = np.arange(len(j))
            s_out[lo:lo + chunk] = self.s[j] + t[rows, j] * (self.s[j + 1] - self.s[j])
            dist[lo:lo + chunk] = np.sqrt(d2[rows, j])
        return s_out, dist


def boundary_chains(model: FEModel, edges: np.ndarray) -> tuple[BoundaryChain, ...]:
    """Order a set of boundary edges into connected chains.

    Parameters
    ----------
    model : FEModel
    edges : array_like of int
        ``(k, 2)`` vertex pairs of boundary edges (e.g. one entry of a mesh's ``boundaries``),
        any order and orientation.

    Returns
    -------
    tuple of BoundaryChain
        One chain per connected component, body on the left (see :class:`BoundaryChain`),
        sorted by their first vertex index for a reproducible order.

    Raises
    ------
    MeshError
        If an edge is not a boundary edge, or three or more edges meet at a vertex.
    """
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if len(e) == 0:
        raise MeshError("no edges given")
    e = np.unique(np.sort(e, axis=1), axis=0)
    normals = edge_outward_normals(model, e)
    p = model.mesh.p.T
    # Orient each edge so that the body is on its left: outward normal = (t_y, -t_x).
    d = p[e[:, 1]] - p[e[:, 0]]
    flip = (d[:, 1] * normals[:, 0] - d[:, 0] * normals[:, 1]) < 0.0
    e[flip] = e[flip][:, ::-1]
    nxt: dict[int, int] = {}
    prv: dict[int, int] = {}
    for a, b in e.tolist():
        if a in nxt or b in prv:
            raise MeshError(f"boundary branches at vertex {a if a in nxt else b}")
        nxt[a] = b
        prv[b] = a
    chains = []
    unvisited = set(nxt)
    while unvisited:
        start = min(unvisited)
        v = start
        while v in prv:  # walk back to the start of an open path (or once round a loop)
            v = prv[v]
            if v == start:
                break
        first = v
        closed = False
        seq = [first]
        while v in nxt:
            v = nxt[v]
            seq.append(v)
            if v == first:
                closed = True
                break
        unvisited.difference_update(seq)
        if closed:  # start the loop at its smallest vertex
            loop = seq[:-1]
            i0 = int(np.argmin(loop))
            seq = loop[i0:] + loop[:i0] + [loop[i0]]
        verts = np.asarray(seq, dtype=np.int64)
        pts = p[verts]
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
        chains.append(BoundaryChain(_readonly(verts), _readonly(s), _readonly(pts), closed))
    chains.sort(key=lambda c: int(c.vertices.min()))
    return tuple(chains)


def _edge_shape(order: int, t: np.ndarray) -> np.ndarray:
    """1D Lagrange shape functions on an edge, local coordinate t ∈ [0, 1] from vertex a to b.

    Returns ``(n_local,) + t.shape``: P1 (a, b); P2 (a, b, midpoint).
    """
    if order == 1:
        return np.stack([1.0 - t, t])
    return np.stack([(1.0 - t) * (1.0 - 2.0 * t), t * (2.0 * t - 1.0), 4.0 * t * (1.0 - t)])


def _edge_nodes(model: FEModel, e: np.ndarray) -> np.ndarray:
    """``(k, n_local)`` node indices of oriented edges ``e`` (vertex a, vertex b[, midpoint])."""
    if model.order == 1:
        return e
    return np.column_stack([e, model.n_vertices + edge_indices(model, e)])


def _gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w  # on [0, 1]


def line_load_weights(
    model: FEModel,
    edges: np.ndarray,
    density: Callable[[np.ndarray, np.ndarray], np.ndarray],
    n_quad: int = 4,
) -> sp.csc_matrix:
    """Consistent nodal weights of scalar line-load densities on a set of edges.

    ``W[i, j] = Σ_edges ∫ ρ_j(x(s), y(s)) φ_i(s) ds``, by ``n_quad``-point Gauss–Legendre quadrature
    on each straight edge ([1]_ § 3.5). Multiply by a direction with :func:`load_operator` to get
    loads in N.

    Parameters
    ----------
    model : FEModel
    edges : array_like of int
        ``(k, 2)`` vertex pairs of mesh edges.
    density : callable
        ``density(x, y)`` with ``x``, ``y`` of shape ``(k, n_quad)`` (mm) returns the line density
        (per mm, e.g. N/mm) at those points, shape ``(k, n_quad)`` for one column or
        ``(m, k, n_quad)`` for ``m`` columns.
    n_quad : int, optional
        Gauss points per edge. Exact for polynomial densities of degree ≤ 2·n_quad − 1 − order.

    Returns
    -------
    scipy.sparse.csc_matrix
        ``(n_nodes, m)`` weights; column sums equal ∫ρ_j ds.
    """
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    tq, wq = _gauss(n_quad)
    p = model.mesh.p.T
    pa, pb = p[e[:, 0]], p[e[:, 1]]
    length = np.linalg.norm(pb - pa, axis=1)
    x = pa[:, 0, None] + tq[None] * (pb - pa)[:, 0, None]
    y = pa[:, 1, None] + tq[None] * (pb - pa)[:, 1, None]
    rho = np.asarray(density(x, y), dtype=np.float64)
    if rho.shape == x.shape:
        rho = rho[None]
    if rho.ndim != 3 or rho.shape[1:] != x.shape:
        raise ValueError(f"density returned shape {rho.shape}, expected {x.shape} or (m, *{x.shape})")
    phi = _edge_shape(model.order, tq)                        # (n_local, n_quad)
    vals = np.einsum("mkq,lq,q,k->mkl", rho, phi, wq, length)  # (m, k, n_local)
    nodes = _edge_nodes(model, e)                              # (k, n_local)
    m = rho.shape[0]
    rows = np.broadcast_to(nodes[None], vals.shape).ravel()
    cols = np.broadcast_to(np.arange(m)[:, None, None], vals.shape).ravel()
    return sp.csc_matrix((vals.ravel(), (rows, cols)), shape=(model.n_nodes, m))


def footprint_weights(
    model: FEModel,
    chain: BoundaryChain,
    centres: np.ndarray,
    half_widths: np.ndarray | float,
    shape: str = "elliptic",
    n_quad: int = 10,
) -> sp.csc_matrix:
    """Consistent nodal weights of unit loads spread over short arcs of a boundary chain.

    Column j distributes a unit force over the arc ``[c_j − a_j, c_j + a_j]`` (arc length along
    ``chain``) with the density

    * ``"elliptic"``: ρ(s) = 2/(π a) · √(1 − ((s − c)/a)²), the Hertz line-contact pressure
      distribution (K. L. Johnson, *Contact Mechanics*, 1985, eq. 4.43);
    * ``"uniform"``: ρ(s) = 1/(2a).

    Only the edges the arc overlaps get entries, so thousands of columns are cheap. Each overlap
    is integrated separately with ``n_quad`` Gauss points; for the elliptic density in the
    variable θ = arcsin((s − c)/a), where ρ ds = (2/π) cos²θ dθ is smooth, so the quadrature
    converges exponentially despite the square-root edges of ρ.

    Parameters
    ----------
    model : FEModel
    chain : BoundaryChain
        From :func:`boundary_chains`.
    centres : array_like
        ``(m,)`` arc length of the footprint centres, mm (wrapped modulo the length on a closed
        chain; see :meth:`BoundaryChain.locate`).
    half_widths : array_like or float
        ``(m,)`` or scalar footprint half-width a, mm; less than half the length of a closed
        chain.
    shape : {"elliptic", "uniform"}
    n_quad : int, optional
        Gauss points per overlapped edge.

    Returns
    -------
    scipy.sparse.csc_matrix
        ``(n_nodes, m)``. Every column sums to 1 (to quadrature accuracy: ~1e-16 for
        ``n_quad = 10``, ~5e-13 for 8, ~1e-8 for 6) and its first moments are ∫ρ x ds and
        ∫ρ y ds (the interpolation reproduces linear functions), so the force and the moment of
        the distributed load are preserved.

    Raises
    ------
    ValueError
        For a non-positive half-width, a footprint running off an open chain, or a half-width
        of half the loop or more.
    """
    c = np.atleast_1d(np.asarray(centres, dtype=np.float64))
    a = np.broadcast_to(np.asarray(half_widths, dtype=np.float64), c.shape).copy()
    if c.ndim != 1:
        raise ValueError("centres must be one-dimensional")
    if (a <= 0.0).any():
        raise ValueError("footprint half-widths must be positive")
    if shape not in ("elliptic", "uniform"):
        raise ValueError(f"unknown footprint shape {shape!r}")
    length = chain.length
    if chain.closed:
        if (a >= 0.5 * length).any():
            raise ValueError("footprint half-width must be less than half the loop length")
        c = np.mod(c, length)
        shifts = (-length, 0.0, length)
    else:
        if (c - a < -1e-12 * length).any() or (c + a > length * (1 + 1e-12)).any():
            raise ValueError("footprint runs off the end of an open boundary chain")
        shifts = (0.0,)

    s0, s1 = chain.s[:-1], chain.s[1:]
    lo, hi = c - a, c + a
    col_l, edge_l, shift_l = [], [], []
    for sh in shifts:
        first = np.searchsorted(s1 + sh, lo, side="right")
        last = np.searchsorted(s0 + sh, hi, side="left")
        cnt = np.maximum(last - first, 0)
        if cnt.sum() == 0:
            continue
        cols = np.repeat(np.arange(len(c)), cnt)
        offs = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        col_l.append(cols)
        edge_l.append(np.repeat(first, cnt) + offs)
        shift_l.append(np.full(cnt.sum(), sh))
    cols = np.concatenate(col_l)
    eidx = np.concatenate(edge_l)
    shift = np.concatenate(shift_l)

    # Work relative to the footprint centre, v = s − c ∈ [−a, a]: neighbouring pieces then share
    # bit-identical break points and the weights telescope to 1 without cancellation error.
    cc, aa = c[cols], a[cols]
    v_start = (s0[eidx] + shift) - cc                       # edge start, relative to the centre
    v_end = (s1[eidx] + shift) - cc
    le = s1[eidx] - s0[eidx]
    v0 = np.maximum(-aa, v_start)
    v1 = np.minimum(aa, v_end)
    keep = v1 > v0
    cols, eidx, aa, v_start, le, v0, v1 = (x[keep] for x in (cols, eidx, aa, v_start, le, v0, v1))

    tq, wq = _gauss(n_quad)
    if shape == "elliptic":
        th0 = np.arcsin(np.clip(v0 / aa, -1.0, 1.0))
        th1 = np.arcsin(np.clip(v1 / aa, -1.0, 1.0))
        th = th0[:, None] + tq[None] * (th1 - th0)[:, None]
        vq = aa[:, None] * np.sin(th)
        wt = (th1 - th0)[:, None] * wq[None] * (2.0 / np.pi) * np.cos(th) ** 2
    else:
        vq = v0[:, None] + tq[None] * (v1 - v0)[:, None]
        wt = (v1 - v0)[:, None] * wq[None] / (2.0 * aa[:, None])
    t = np.clip((vq - v_start[:, None]) / le[:, None], 0.0, 1.0)
    phi = _edge_shape(model.order, t)                      # (n_local, n_pieces, n_quad)
    vals = np.einsum("lpq,pq->pl", phi, wt)                # (n_pieces, n_local)
    nodes = _edge_nodes(model, chain.edges[eidx])          # (n_pieces, n_local)
    rows = nodes.ravel()
    cidx = np.broadcast_to(cols[:, None], nodes.shape).ravel()
    return sp.csc_matrix((vals.ravel(), (rows, cidx)), shape=(model.n_nodes, len(c)))


def load_operator(model: FEModel, weights: sp.spmatrix, directions: np.ndarray) -> sp.csc_matrix:
    """Global load operator B from scalar nodal weights and one direction per column.

    Column j of ``B`` is the load vector of a unit force along ``directions[j]`` distributed with
    the weights ``weights[:, j]``: ``B[node_dofs[i, 0], j] = W[i, j] d_jx`` and
    ``B[node_dofs[i, 1], j] = W[i, j] d_jy``. Hence ``B @ f`` is the global load vector (N) of
    forces ``f`` (N), and ``B.T @ u`` is the weighted average displacement (mm) of every footprint
    along its direction — the displacement work-conjugate to ``f``.

    Parameters
    ----------
    model : FEModel
    weights : scipy.sparse matrix
        ``(n_nodes, m)`` from :func:`footprint_weights` or :func:`line_load_weights`.
    directions : array_like
        ``(m, 2)`` direction of each column, or ``(2,)`` for all. Not normalised here: pass unit
        vectors for "unit force" columns.

    Returns
    -------
    scipy.sparse.csc_matrix
        ``(n_dofs, m)``.
    """
    w = sp.coo_matrix(weights)
    if w.shape[0] != model.n_nodes:
        raise ValueError(f"weights must have {model.n_nodes} rows, got {w.shape[0]}")
    d = np.broadcast_to(np.asarray(directions, dtype=np.float64), (w.shape[1], 2))
    rows = np.concatenate([model.node_dofs[w.row, 0], model.node_dofs[w.row, 1]])
    cols = np.concatenate([w.col, w.col])
    vals = np.concatenate([w.data * d[w.col, 0], w.data * d[w.col, 1]])
    return sp.csc_matrix((vals, (rows, cols)), shape=(model.n_dofs, w.shape[1]))


def traction_vector(
    model: FEModel,
    edges: np.ndarray,
    traction: Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]],
    n_quad: int = 4,
) -> np.ndarray:
    """Consistent global load vector of a traction on boundary edges.

    ``F = b ∫ t · v ds`` over the edges, where b is the disc thickness: the traction is a stress
    on the disc's rim (MPa = N/mm²), so the line load is t·b (N/mm). A pressure p acting on the
    boundary is ``t = −p n``.

    Parameters
    ----------
    model : FEModel
    edges : array_like of int
        ``(k, 2)`` vertex pairs of boundary edges.
    traction : callable
        ``traction(x, y, nx, ny) -> (tx, ty)``: x, y the quadrature points (mm) and n the edge's
        outward unit normal, arrays of shape ``(k, n_quad)``; returns the traction components
        (MPa) at those points.
    n_quad : int, optional
        Gauss points per edge.

    Returns
    -------
    numpy.ndarray
        ``(n_dofs,)`` load vector, N.
    """
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    n = edge_outward_normals(model, e)
    nx = np.broadcast_to(n[:, 0, None], (len(e), n_quad))
    ny = np.broadcast_to(n[:, 1, None], (len(e), n_quad))

    def dens(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        tx, ty = traction(x, y, nx, ny)
        return model.thickness * np.stack([np.broadcast_to(tx, x.shape), np.broadcast_to(ty, x.shape)])

    w = line_load_weights(model, e, dens, n_quad=n_quad)
    f = np.zeros(model.n_dofs)
    np.add.at(f, model.node_dofs[:, 0], np.asarray(w[:, 0].todense()).ravel())
    np.add.at(f, model.node_dofs[:, 1], np.asarray(w[:, 1].todense()).ravel())
    return f


# --------------------------------------------------------------------------------------------
# Rigid-body modes
# --------------------------------------------------------------------------------------------


def rigid_body_modes(model: FEModel, centre: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """The three rigid-body modes of the disc as displacement vectors.

    Parameters
    ----------
    model : FEModel
    centre : (float, float), optional
        Centre of the rotation mode, mm.

    Returns
    -------
    numpy.ndarray
        ``(n_dofs, 3)``: unit translation in x (mm), unit translation in y (mm), and a small
        rotation of 1 rad about ``centre`` linearised, u = (−(y − y_c), x − x_c) (mm/rad).
        ``K @ R`` vanishes to round-off.
    """
    r = np.zeros((model.n_dofs, 3))
    xy = model.node_coords - np.asarray(centre, dtype=np.float64)
    dx, dy = model.node_dofs[:, 0], model.node_dofs[:, 1]
    r[dx, 0] = 1.0
    r[dy, 1] = 1.0
    r[dx, 2] = -xy[:, 1]
    r[dy, 2] = xy[:, 0]
    return r


def rigid_motion(
    model: FEModel,
    translation: tuple[float, float] = (0.0, 0.0),
    rotation: float = 0.0,
    centre: tuple[float, float] = (0.0, 0.0),
) -> np.ndarray:
    """Displacement vector of a small rigid motion.

    Parameters
    ----------
    model : FEModel
    translation : (float, float)
        (u_x, u_y), mm.
    rotation : float
        Small rotation about ``centre``, rad, counter-clockwise positive (linearised).
    centre : (float, float)
        mm.

    Returns
    -------
    numpy.ndarray
        ``(n_dofs,)``, mm.
    """
    return rigid_body_modes(model, centre) @ np.array([translation[0], translation[1], rotation])


def add_rigid_motion(
    model: FEModel,
    u: np.ndarray,
    translation: tuple[float, float] = (0.0, 0.0),
    rotation: float = 0.0,
    centre: tuple[float, float] = (0.0, 0.0),
) -> np.ndarray:
    """Return ``u`` plus the small rigid motion of :func:`rigid_motion` (``u`` is not modified)."""
    return np.asarray(u, dtype=np.float64) + rigid_motion(model, translation, rotation, centre)


def remove_rigid_motion(
    model: FEModel, u: np.ndarray, centre: tuple[float, float] = (0.0, 0.0)
) -> tuple[np.ndarray, np.ndarray]:
    """Split off the rigid-body part of a displacement field (least squares over the nodes).

    Parameters
    ----------
    model : FEModel
    u : numpy.ndarray
        ``(n_dofs,)`` displacement, mm.
    centre : (float, float), optional
        Centre of the rotation, mm.

    Returns
    -------
    u_deformation : numpy.ndarray
        ``u`` minus its best-fitting rigid motion (nodal least squares), mm.
    motion : numpy.ndarray
        ``(3,)``: translation x, y (mm) and rotation (rad) removed.
    """
    r = rigid_body_modes(model, centre)
    q, *_ = np.linalg.lstsq(r, u, rcond=None)
    return u - r @ q, q


# --------------------------------------------------------------------------------------------
# Factorisation
# --------------------------------------------------------------------------------------------

#: Order in which ``solver="auto"`` tries the backends, by measurement
#: (``benchmarks/bench_factorization.py``, numbers in its docstring): on a 15k-vertex annulus
#: CHOLMOD back-substitutes 1000 columns in 3.8 s (P1) / 24 s (P2), PARDISO in 5.1 s / 29 s,
#: SuperLU (symmetric mode, MMD on AᵀA+A) in 7.1 s / 65 s; factorisation 0.2–2.6 s for all.
SOLVER_PREFERENCE: tuple[str, ...] = ("cholmod", "pardiso", "superlu")


def available_solvers() -> tuple[str, ...]:
    """Sparse direct solvers importable here, in :data:`SOLVER_PREFERENCE` order.

    ``"superlu"`` (scipy) is always available; ``"cholmod"`` needs scikit-sparse and
    ``"pardiso"`` needs pypardiso (Intel MKL). Neither is a dependency of rvfem.
    """
    found = []
    for name in SOLVER_PREFERENCE:
        if name == "superlu":
            found.append(name)
        elif name == "cholmod" and importlib.util.find_spec("sksparse") is not None:
            found.append(name)
        elif name == "pardiso" and importlib.util.find_spec("pypardiso") is not None:
            found.append(name)
    return tuple(found)


def _factor_superlu(a: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
    # Symmetric positive definite: a symmetric fill-reducing ordering on A + A^T and no
    # numerical pivoting keep SuperLU's fill close to a Cholesky factor's (SuperLU user guide,
    # § 2.9, "symmetric mode").
    lu = spla.splu(
        a,
        permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )
    return lu.solve


def _factor_cholmod(a: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
    from sksparse.cholmod import cholesky  # optional

    factor = cholesky(a)
    return factor


def _factor_pardiso(a: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
    import pypardiso  # optional

    solver = pypardiso.PyPardisoSolver(mtype=2)  # real symmetric positive definite
    upper = sp.triu(a, format="csr")
    upper.sort_indices()
    solver.factorize(upper)

    def solve(b: np.ndarray) -> np.ndarray:
        return solver.solve(upper, np.asarray(b, dtype=np.float64))

    return solve


_FACTORIZERS = {"superlu": _factor_superlu, "cholmod": _factor_cholmod, "pardiso": _factor_pardiso}


@dataclass(frozen=True, eq=False)
class Factorization:
    """A factorised stiffness with a minimal support, ready for many right-hand sides.

    Attributes
    ----------
    solver : str
        Backend used ("cholmod", "pardiso" or "superlu").
    support_dofs : numpy.ndarray
        ``(3,)`` (or user-given) DOFs held at zero displacement.
    free_dofs : numpy.ndarray
        All other DOFs.
    n_dofs : int
    factor_seconds : float
        Wall time of the factorisation, s.
    """

    solver: str
    support_dofs: np.ndarray
    free_dofs: np.ndarray
    n_dofs: int
    factor_seconds: float
    _solve: Callable[[np.ndarray], np.ndarray] = field(repr=False)

    def solve(self, rhs: np.ndarray | sp.spmatrix) -> np.ndarray:
        """Solve ``K u = rhs`` with ``u = 0`` at the support DOFs.

        Parameters
        ----------
        rhs : numpy.ndarray or scipy.sparse matrix
            ``(n_dofs,)`` or ``(n_dofs, m)`` loads, N. Entries at the support DOFs are ignored
            (they become support reactions). For a self-equilibrated load the reactions vanish
            and the result is the floating body's response up to a rigid-body motion; otherwise
            the support carries the imbalance.

        Returns
        -------
        numpy.ndarray
            Displacements, mm, shaped like ``rhs`` (dense).
        """
        b = rhs.toarray() if sp.issparse(rhs) else np.asarray(rhs, dtype=np.float64)
        if b.shape[0] != self.n_dofs or b.ndim > 2:
            raise ValueError(f"rhs must have shape ({self.n_dofs},) or ({self.n_dofs}, m), got {b.shape}")
        u = np.zeros(b.shape)
        if b.ndim == 2 and b.shape[1] == 0:
            return u
        u[self.free_dofs] = np.asarray(self._solve(np.asarray(b[self.free_dofs], order="F"))).reshape(
            u[self.free_dofs].shape
        )
        return u


def default_support(model: FEModel) -> np.ndarray:
    """A minimal statically determinate support: three DOFs that remove the rigid-body modes.

    Vertex A is the vertex with the smallest x, vertex B the one farthest from A; A is held in x
    and y, B perpendicular to AB (in y if AB is closer to the x axis, else in x). A long lever
    arm keeps the reduced stiffness well conditioned.

    Returns
    -------
    numpy.ndarray
        ``(3,)`` DOF indices.
    """
    p = model.mesh.p.T
    ia = int(np.argmin(p[:, 0]))
    ib = int(np.argmax(np.sum((p - p[ia]) ** 2, axis=1)))
    d = p[ib] - p[ia]
    comp_b = 1 if abs(d[0]) >= abs(d[1]) else 0
    return np.array([model.node_dofs[ia, 0], model.node_dofs[ia, 1], model.node_dofs[ib, comp_b]])


def factorize_matrix(
    stiffness: sp.spmatrix, support_dofs: np.ndarray, solver: str = "auto"
) -> Factorization:
    """Factorise a symmetric positive (semi-)definite stiffness with DOFs held at zero.

    Parameters
    ----------
    stiffness : scipy.sparse matrix
        ``(n, n)``, N/mm.
    support_dofs : array_like of int
        DOFs removed (held at zero). They must make the remaining matrix positive definite.
    solver : {"auto", "cholmod", "pardiso", "superlu"}
        "auto" takes the first of :func:`available_solvers` (the choice is logged at INFO level).

    Returns
    -------
    Factorization
    """
    n = stiffness.shape[0]
    sup = np.unique(np.asarray(support_dofs, dtype=np.int64))
    free = np.setdiff1d(np.arange(n), sup)
    if solver == "auto":
        solver = available_solvers()[0]
    elif solver not in _FACTORIZERS:
        raise ValueError(f"unknown solver {solver!r}; choose from {sorted(_FACTORIZERS)} or 'auto'")
    k = sp.csc_matrix(stiffness)[free][:, free].tocsc()
    k.sort_indices()
    t0 = time.perf_counter()
    solve = _FACTORIZERS[solver](k)
    dt = time.perf_counter() - t0
    logger.info("factorised %d DOFs (nnz %d) with %s in %.3f s", k.shape[0], k.nnz, solver, dt)
    return Factorization(solver, _readonly(sup), _readonly(free), int(n), dt, solve)


def factorize(model: FEModel, support_dofs: np.ndarray | None = None, solver: str = "auto") -> Factorization:
    """Factorise the model's stiffness on a minimal support (floating-body trick).

    Parameters
    ----------
    model : FEModel
    support_dofs : array_like of int, optional
        DOFs held at zero; default :func:`default_support` (three DOFs, statically determinate).
    solver : {"auto", "cholmod", "pardiso", "superlu"}
        See :func:`factorize_matrix`.

    Returns
    -------
    Factorization
    """
    sup = default_support(model) if support_dofs is None else support_dofs
    return factorize_matrix(model.stiffness, sup, solver)


# --------------------------------------------------------------------------------------------
# Stresses
# --------------------------------------------------------------------------------------------


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
        """Derive von Mises and principal stresses from the Cartesian components (MPa)."""
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


def nodal_stress_operator(model: FEModel) -> sp.csr_matrix:
    """The linear map from displacements to the vertex stresses of :func:`stress_fields`.

    ``S @ u`` stacks (σxx, σyy, σxy) at the mesh vertices — area-averaged element values, exactly
    as ``stress_fields(model, u).nodal`` — for many fields at the cost of one sparse product each
    (the load cycle's stress envelope uses it at every crank angle).

    Returns
    -------
    scipy.sparse.csr_matrix
        ``(3·n_vertices, n_dofs)``, MPa/mm; rows ``[0, nv)`` σxx, ``[nv, 2nv)`` σyy, ``[2nv, 3nv)`` σxy.
    """
    lam, mu = plane_stress_constants(model.youngs_modulus, model.poissons_ratio)
    basis = model._stress_basis
    t = model.mesh.t
    p = model.mesh.p
    area = 0.5 * np.abs(
        (p[0, t[1]] - p[0, t[0]]) * (p[1, t[2]] - p[1, t[0]])
        - (p[1, t[1]] - p[1, t[0]]) * (p[0, t[2]] - p[0, t[0]])
    )
    nv = model.n_vertices
    denom = np.bincount(t.ravel(), weights=np.tile(area, 3), minlength=nv)
    rows, cols, vals = [], [], []
    for i, (field_i,) in enumerate(basis.basis):
        g = field_i.grad[:, :, :, :3]                       # (2, 2, n_elements, 3 vertices)
        exx, eyy, exy = g[0, 0], g[1, 1], 0.5 * (g[0, 1] + g[1, 0])
        comps = (lam * (exx + eyy) + 2 * mu * exx, lam * (exx + eyy) + 2 * mu * eyy, 2 * mu * exy)
        dof = basis.element_dofs[i]
        for c, sc in enumerate(comps):                      # sc: (n_elements, 3)
            for k in range(3):
                v = t[k]
                rows.append(c * nv + v)
                cols.append(dof)
                vals.append(sc[:, k] * area / denom[v])
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(3 * nv, model.n_dofs))


def stress_fields(model: FEModel, u: np.ndarray) -> StressFields:
    """Plane stresses of a displacement field, per element and at the vertices.

    σ = λ* tr(ε) I + 2μ ε with ε = sym ∇u and λ*, μ from :func:`plane_stress_constants`.

    Parameters
    ----------
    model : FEModel
    u : numpy.ndarray
        ``(n_dofs,)`` displacement, mm. Rigid-body motions produce no stress (to first order).

    Returns
    -------
    StressFields
        MPa.
    """
    u = np.asarray(u, dtype=np.float64)
    if u.shape != (model.n_dofs,):
        raise ValueError(f"u must have shape ({model.n_dofs},), got {u.shape}")
    lam, mu = plane_stress_constants(model.youngs_modulus, model.poissons_ratio)
    g = model._stress_basis.interpolate(u).grad           # (2, 2, n_elements, 4)
    exx, eyy = g[0, 0], g[1, 1]
    exy = 0.5 * (g[0, 1] + g[1, 0])
    tr = exx + eyy
    sxx = lam * tr + 2.0 * mu * exx
    syy = lam * tr + 2.0 * mu * eyy
    sxy = 2.0 * mu * exy

    element = StressState.from_components(sxx[:, 3].copy(), syy[:, 3].copy(), sxy[:, 3].copy())

    t = model.mesh.t                                        # (3, n_elements)
    p = model.mesh.p
    area = 0.5 * np.abs(
        (p[0, t[1]] - p[0, t[0]]) * (p[1, t[2]] - p[1, t[0]])
        - (p[1, t[1]] - p[1, t[0]]) * (p[0, t[2]] - p[0, t[0]])
    )
    nv = model.n_vertices
    idx = t.ravel()                                         # vertex of (local k, element e)
    wts = np.tile(area, 3)
    denom = np.bincount(idx, weights=wts, minlength=nv)

    def avg(f: np.ndarray) -> np.ndarray:
        return np.bincount(idx, weights=wts * f[:, :3].T.ravel(), minlength=nv) / denom

    nodal = StressState.from_components(avg(sxx), avg(syy), avg(sxy))
    return StressFields(nodal=nodal, element=element)
