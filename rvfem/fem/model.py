"""The plane-stress finite-element model of a disc: mesh, basis, stiffness, node and DOF maps.

The cycloid disc is a 2D linear-elastic body in plane stress (thickness *b*, Young's modulus *E*,
Poisson's ratio ν), discretised with Lagrange triangles of order 1 (P1, linear) or 2 (P2, quadratic,
straight-sided) through scikit-fem. Units follow the project convention: lengths in mm, forces in N,
moduli and stresses in MPa. The stiffness matrix is multiplied by the thickness, so ``K @ u`` is a
nodal *force* in N for a displacement ``u`` in mm. The derivation and the expected convergence rates
are in docs/theory.md ("Plane-stress finite elements").

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
:func:`build_model`, so ``model.node_dofs[vertices]`` translates a mesh's vertex indices (for
instance its boundary edges) into DOFs for P1 and P2 alike.

References
----------
.. [1] O. C. Zienkiewicz, R. L. Taylor, J. Z. Zhu, *The Finite Element Method: Its Basis and
   Fundamentals*, 7th ed., Butterworth-Heinemann, 2013 (plane stress, isoparametric triangles).
.. [2] S. P. Timoshenko, J. N. Goodier, *Theory of Elasticity*, 3rd ed., McGraw-Hill, 1970
   (plane-stress constitutive law).
.. [3] T. Gustafsson, G. D. McBain, "scikit-fem: A Python package for finite element assembly",
   JOSS 5(52), 2369, 2020.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
import scipy.sparse as sp
from skfem import (
    Basis,
    BilinearForm,
    ElementTriP1,
    ElementTriP2,
    ElementVector,
    MeshTri,
)
from skfem.assembly import Dofs
from skfem.models.elasticity import lame_parameters

from rvfem._arrays import readonly as _readonly
from rvfem.errors import MeshError

__all__ = [
    "FEModel",
    "build_model",
    "plane_stress_constants",
    "plane_stress_stiffness",
    "edge_indices",
    "edge_outward_normals",
]


def _scalar_element(order: int):
    """The scalar Lagrange triangle of the element order (1: P1, 2: P2)."""
    return ElementTriP1() if order == 1 else ElementTriP2()


@dataclass(frozen=True, eq=False)
class FEModel:
    """Assembled plane-stress finite-element model of one disc.

    Build it with :func:`build_model`; the stiffness is assembled once and never changes.

    Attributes
    ----------
    mesh : skfem.MeshTri
        The triangle mesh (vertices numbered as the ``points`` given to :func:`build_model`).
    basis : skfem.CellBasis
        Vector Lagrange basis (P1 or P2) whose DOF numbering ``stiffness`` uses (built on first
        access; the stiffness itself is assembled on the scalar basis, see
        :func:`plane_stress_stiffness`).
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
    order: int
    youngs_modulus: float
    poissons_ratio: float
    thickness: float
    stiffness: sp.csr_matrix
    node_coords: np.ndarray
    node_dofs: np.ndarray
    edges: np.ndarray
    _stress_basis: Any = field(repr=False)

    @cached_property
    def basis(self) -> Any:
        """Vector Lagrange basis (P1 or P2) with the DOF numbering of ``stiffness``."""
        return Basis(self.mesh, ElementVector(_scalar_element(self.order)))

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
    λ* = 2λμ/(λ + 2μ) = Eν/(1 − ν²); μ = E/(2(1 + ν)) is unchanged ([2]_ §§ 7, 15).
    :func:`skfem.models.elasticity.lame_parameters` gives the 3D (λ, μ); the correction is applied
    here.

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
    lam, mu = lame_parameters(float(youngs_modulus), float(poissons_ratio))
    return 2.0 * lam * mu / (lam + 2.0 * mu), mu


#: The three scalar gradient products the plane-stress stiffness is made of (trial ``u``, test
#: ``v``): D_xx = ∫ ∂xφ_i ∂xφ_j, D_yy = ∫ ∂yφ_i ∂yφ_j, D_xy = ∫ ∂xφ_i ∂yφ_j (row i, column j).
_D_XX = BilinearForm(lambda u, v, w: u.grad[0] * v.grad[0])
_D_YY = BilinearForm(lambda u, v, w: u.grad[1] * v.grad[1])
_D_XY = BilinearForm(lambda u, v, w: u.grad[1] * v.grad[0])


def plane_stress_stiffness(scalar_basis: Any, vector_element_dofs: np.ndarray, lam: float,
                           mu: float) -> sp.csr_matrix:
    """Stiffness ``∫ ε(v) : C ε(u) dA`` of the isotropic law σ = λ tr(ε) I + 2μ ε, built from
    scikit-fem assemblies on the scalar basis.

    For u = φ_j e_a and v = φ_i e_b (φ the scalar shape functions, e_x, e_y the unit vectors) the
    bilinear form splits into the scalar gradient products D_xx, D_yy, D_xy (:data:`_D_XX`…)
    ([1]_ ch. 6, the element matrix B_iᵀ D B_j written out)::

        K_xx = (λ + 2μ) D_xx + μ D_yy        K_xy = λ D_xy + μ D_xyᵀ
        K_yx = λ D_xyᵀ + μ D_xy              K_yy = (λ + 2μ) D_yy + μ D_xx

    This is scikit-fem's ``linear_elasticity(λ, μ)`` on the vector basis term by term: three
    scalar forms of 6×6 (P1: 3×3) cheap local products per triangle instead of one vector form of
    12×12 (P1: 6×6) tensor products, half of whose components are zero; the two agree to
    round-off (tests/fem/test_fem.py).

    Parameters
    ----------
    scalar_basis : skfem.CellBasis
        Scalar Lagrange basis (P1 or P2) with its default quadrature.
    vector_element_dofs : numpy.ndarray
        ``(2·n_local, n_elements)`` element DOFs of ``ElementVector`` of the same element
        (``skfem.assembly.Dofs(mesh, ElementVector(element)).element_dofs``): local DOF 2k + c is
        component c (x, y) of scalar local function k. Gives the global numbering of the result.
    lam, mu : float
        Lamé constants times the thickness, MPa·mm = N/mm (the plane-stress λ* for plane stress).

    Returns
    -------
    scipy.sparse.csr_matrix
        ``(2·N, 2·N)``, sorted indices, no stored zeros; N the scalar DOF count.
    """
    n = scalar_basis.N
    nb = scalar_basis.Nbfun
    # One form at a time, keeping its element data only (the three share their indices); what is
    # no longer needed is dropped as soon as possible: the P2 disc's assembly peaks at about 2.5×
    # the finished matrix instead of 5×.
    first = _D_XX.elemental(scalar_basis)
    rows, cols = (np.ascontiguousarray(ix, dtype=np.int32) for ix in first.indices)
    dxx = first.data
    del first
    dyy, dxy = (form.elemental(scalar_basis).data for form in (_D_YY, _D_XY))
    # element data are laid out (trial j, test i, element): the local transpose swaps the first two
    dyx = dxy.reshape(nb, nb, -1).transpose(1, 0, 2).ravel()
    # Duplicates summed by scipy, two blocks at a time as the real and imaginary parts of complex
    # data (summed independently, exactly as two real matrices would be); the same (rows, cols)
    # give the same structure for all four blocks.
    pair = [sp.coo_matrix(((lam + 2.0 * mu) * dxx + mu * dyy + 1j * (lam * dxy + mu * dyx), (rows, cols)),
                          shape=(n, n)).tocsr()]
    pair.append(sp.coo_matrix((lam * dyx + mu * dxy + 1j * ((lam + 2.0 * mu) * dyy + mu * dxx), (rows, cols)),
                              shape=(n, n)).tocsr())
    del rows, cols, dxx, dyy, dxy, dyx
    if not (np.array_equal(pair[0].indptr, pair[1].indptr)
            and np.array_equal(pair[0].indices, pair[1].indices)):
        raise AssertionError("the stiffness blocks have different structures")  # pragma: no cover
    # scalar entry (s, t) → the 2×2 block [[K_xx, K_xy], [K_yx, K_yy]] at rows 2s, 2s + 1 and
    # columns 2t, 2t + 1
    block_data = np.stack([pair[0].data.real, pair[0].data.imag, pair[1].data.real, pair[1].data.imag],
                          axis=-1).reshape(-1, 2, 2)
    indices, indptr = pair[0].indices, pair[0].indptr
    del pair
    k_int = sp.bsr_matrix((block_data, indices, indptr), shape=(2 * n, 2 * n))
    del block_data
    k_int = k_int.tocsr()
    # global numbering of the vector element: component c of scalar DOF s → vdofs[c, s]
    vdofs = np.empty((2, n), dtype=np.int64)
    for c in range(2):
        vdofs[c, scalar_basis.element_dofs] = vector_element_dofs[c::2]
    if not np.array_equal(vdofs.T.ravel(), np.arange(2 * n)):
        inverse = np.empty(2 * n, dtype=np.int64)
        inverse[vdofs.T.ravel()] = np.arange(2 * n)
        k_int = k_int[inverse][:, inverse].tocsr()
    k_int.eliminate_zeros()
    k_int.sort_indices()
    return k_int


def _check_material(order: int, youngs_modulus: float, poissons_ratio: float, thickness: float) -> None:
    """Reject an unknown element order and non-physical material data.

    Parameters
    ----------
    order : int
        Element order; 1 or 2.
    youngs_modulus : float
        E, MPa; positive.
    poissons_ratio : float
        ν; 0 ≤ ν < 0.5 (ν = 0.5, the incompressible limit, makes λ infinite).
    thickness : float
        b, mm; positive.

    Raises
    ------
    ValueError
        Naming the first offending value.
    """
    if order not in (1, 2):
        raise ValueError(f"element order must be 1 or 2, got {order!r}")
    if not (youngs_modulus > 0.0):
        raise ValueError(f"Young's modulus must be positive, got {youngs_modulus!r} MPa")
    if not (0.0 <= poissons_ratio < 0.5):
        raise ValueError(f"Poisson's ratio must be in [0, 0.5), got {poissons_ratio!r}")
    if not (thickness > 0.0):
        raise ValueError(f"thickness must be positive, got {thickness!r} mm")


def _check_triangle_areas(points: np.ndarray, triangles: np.ndarray) -> None:
    """Reject degenerate (zero-area) triangles.

    Twice the signed area of triangle (a, b, c) is the cross product
    2A = (b − a)_x (c − a)_y − (b − a)_y (c − a)_x (mm²), positive counter-clockwise. A triangle
    is degenerate when |2A| ≤ 10⁻¹⁴ · D², D the largest extent of the points along x or y (mm),
    i.e. its area is at round-off level relative to the mesh's size.

    Parameters
    ----------
    points : numpy.ndarray
        ``(n, 2)`` float64 vertex coordinates, mm.
    triangles : numpy.ndarray
        ``(m, 3)`` integer vertex indices, in range.

    Raises
    ------
    MeshError
        With the count of degenerate triangles and the index of the first.
    """
    a, b, c = (points[triangles[:, k]] for k in range(3))
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    scale2 = np.ptp(points, axis=0).max() ** 2
    bad = np.abs(area2) <= 1e-14 * scale2
    if bad.any():
        raise MeshError(f"{int(bad.sum())} degenerate (zero-area) triangles, e.g. #{int(np.flatnonzero(bad)[0])}")


def _checked_mesh(points: np.ndarray, triangles: np.ndarray) -> MeshTri:
    """The scikit-fem triangle mesh of checked vertex and triangle arrays.

    Parameters
    ----------
    points : array_like
        ``(n, 2)`` vertex coordinates, mm, n ≥ 3; every vertex must belong to a triangle.
    triangles : array_like of int
        ``(m, 3)`` vertex indices of the triangles (either orientation), m ≥ 1.

    Returns
    -------
    skfem.MeshTri
        Vertices numbered as ``points``.

    Raises
    ------
    MeshError
        For malformed arrays, indices out of range, unused vertices or degenerate triangles
        (:func:`_check_triangle_areas`).
    """
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
    _check_triangle_areas(points, triangles)
    return MeshTri(
        np.ascontiguousarray(points.T),
        np.ascontiguousarray(triangles.T.astype(np.int64)),
    )


def _node_maps(mesh: MeshTri, dofs: Dofs, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Edges, Lagrange node coordinates and the node → DOF map of the vector element.

    Parameters
    ----------
    mesh : skfem.MeshTri
    dofs : skfem.assembly.Dofs
        DOFs of ``ElementVector`` of the scalar P1 or P2 element on ``mesh``.
    order : int
        1 or 2.

    Returns
    -------
    edges : numpy.ndarray
        ``(n_edges, 2)`` int64 vertex indices of every mesh edge (scikit-fem's facets).
    node_coords : numpy.ndarray
        ``(n_nodes, 2)`` coordinates, mm: the vertices, then for P2 the edge midpoints
        (a + b)/2 in the order of ``edges``.
    node_dofs : numpy.ndarray
        ``(n_nodes, 2)`` int64 global x and y DOF of every node.
    """
    edges = np.ascontiguousarray(mesh.facets.T.astype(np.int64))
    if order == 1:
        node_coords = mesh.p.T.copy()
        node_dofs = dofs.nodal_dofs.T.astype(np.int64)
    else:
        mid = 0.5 * (mesh.p[:, mesh.facets[0]] + mesh.p[:, mesh.facets[1]])
        node_coords = np.vstack([mesh.p.T, mid.T])
        node_dofs = np.vstack([dofs.nodal_dofs.T, dofs.facet_dofs.T]).astype(np.int64)
    if not np.array_equal(np.sort(node_dofs.ravel()), np.arange(dofs.N)):
        raise AssertionError("node/DOF map does not cover the DOFs exactly once")  # pragma: no cover
    return edges, node_coords, node_dofs


def _stress_recovery_basis(mesh: MeshTri, scalar: Any) -> Any:
    """Scalar basis evaluated where stresses are recovered: each triangle's vertices and centroid.

    The four local points are the reference triangle's vertices (0, 0), (1, 0), (0, 1) and its
    centroid (1/3, 1/3); the weights (1/8 each, summing to the reference area 1/2) are never used
    for integration.

    Parameters
    ----------
    mesh : skfem.MeshTri
    scalar : skfem.Element
        The scalar P1 or P2 triangle of the model.

    Returns
    -------
    skfem.CellBasis
    """
    # Local points (reference triangle vertices 0, 1, 2 and the centroid) for stress recovery.
    xi = np.array([[0.0, 1.0, 0.0, 1.0 / 3.0], [0.0, 0.0, 1.0, 1.0 / 3.0]])
    # A scalar basis: the gradient of a displacement component is that of its scalar field, and the
    # vector basis (2× the functions, half of each zero) would hold 4× the data (77 MB on P2)
    return Basis(mesh, scalar, quadrature=(xi, np.full(4, 0.125)))


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
    (:func:`plane_stress_constants`), assembled by :func:`plane_stress_stiffness`.
    scikit-fem's default quadrature (degree 2·order) integrates it exactly on straight-sided
    triangles.

    The parts: :func:`_check_material`, :func:`_checked_mesh` (with
    :func:`_check_triangle_areas`), :func:`plane_stress_stiffness`, :func:`_node_maps` and
    :func:`_stress_recovery_basis`.
    """
    _check_material(order, youngs_modulus, poissons_ratio, thickness)
    mesh = _checked_mesh(points, triangles)
    scalar = _scalar_element(order)
    dofs = Dofs(mesh, ElementVector(scalar))
    lam, mu = plane_stress_constants(youngs_modulus, poissons_ratio)
    stiffness = plane_stress_stiffness(Basis(mesh, scalar), dofs.element_dofs, lam * thickness, mu * thickness)
    edges, node_coords, node_dofs = _node_maps(mesh, dofs, order)
    stress_basis = _stress_recovery_basis(mesh, scalar)

    return FEModel(
        mesh=mesh,
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


