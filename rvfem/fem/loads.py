"""Loads on the disc's boundary: boundary chains, footprint weights and load operators.

Contact and roller forces are not applied as nodal point loads but as line loads spread over a short
*footprint* of the boundary, so that results converge under mesh refinement (docs/theory.md,
"Footprint loads"). The load of a unit force distributed with a line density ρ(s) (1/mm, ∫ρ ds = 1)
is turned into *consistent* nodal loads ``W[i] = ∫ ρ(s) φ_i(s) ds`` with the element's own shape
functions φ_i restricted to the boundary edges (linear for P1; quadratic with the edge-midpoint node
for P2), integrated by Gauss quadrature ([1]_ § 3.5). The scalar weights ``W`` (one column per
footprint, columns sum to 1) and a direction per column give the sparse *load operator* ``B``
(:func:`load_operator`): ``B @ f`` is the global load vector of the forces ``f`` (N), and
``B.T @ u`` is the ρ-weighted average displacement of each footprint along its direction (mm) — the
work-conjugate quantity the contact solver needs.

Why not scikit-fem's ``FacetBasis``: a footprint covers parts of edges, its density has
square-root edges (the Hertz ellipse) and thousands of footprints share a handful of edges each.
A facet basis integrates whole facets with one fixed rule, which would either miss the footprint
ends or need an extremely high order; the hand-written quadrature integrates each overlap exactly
in the arcsine variable and builds all columns at once.

References
----------
.. [1] O. C. Zienkiewicz, R. L. Taylor, J. Z. Zhu, *The Finite Element Method: Its Basis and
   Fundamentals*, 7th ed., Butterworth-Heinemann, 2013 (consistent nodal loads).
.. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985 (Hertz line-contact
   pressure, eq. 4.43).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp
from scipy.spatial import cKDTree

from rvfem._arrays import chain_edges
from rvfem._arrays import readonly as _readonly
from rvfem.errors import MeshError
from rvfem.fem.model import FEModel, edge_indices, edge_outward_normals

__all__ = [
    "BoundaryChain",
    "boundary_chains",
    "footprint_weights",
    "load_operator",
]


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

    @functools.cached_property
    def _vertex_tree(self):
        return cKDTree(self.points[:-1])

    @functools.cached_property
    def _edges(self):
        """Edge start points, edge vectors and their squared lengths."""
        d = np.diff(self.points, axis=0)
        return self.points[:-1], d, np.einsum("ij,ij->i", d, d)

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
        a, d, ll = self._edges
        # points near the chain (contact points): the closest point lies on an edge next to one of
        # the nearest vertices; the others get the exhaustive search below
        k = len(a)
        if k > 16:
            _, near = self._vertex_tree.query(q, 2)
            cand = np.concatenate([near, near - 1], axis=1) % k                    # (m, 4) edges
            t = np.clip(np.einsum("mcj,mcj->mc", q[:, None] - a[cand], d[cand]) / ll[cand], 0.0, 1.0)
            r = q[:, None] - (a[cand] + t[..., None] * d[cand])
            d2 = np.einsum("mcj,mcj->mc", r, r)
            c = np.argmin(d2, axis=1)
            rows = np.arange(len(q))
            j, tj = cand[rows, c], t[rows, c]
            s_near = self.s[j] + tj * (self.s[j + 1] - self.s[j])
            dist_near = np.sqrt(d2[rows, c])
            close = dist_near <= 0.1 * np.sqrt(ll[j])     # well inside the neighbourhood
            if not close.all():
                s_near[~close], dist_near[~close] = self._locate_exhaustive(q[~close], a, d, ll)
            return s_near, dist_near
        return self._locate_exhaustive(q, a, d, ll)

    def _locate_exhaustive(self, q, a, d, ll):
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
        sorted by their first vertex index for a reproducible order; a loop starts at its
        smallest vertex.

    Raises
    ------
    MeshError
        If an edge is not a boundary edge, or three or more edges meet at a vertex.

    Notes
    -----
    The edges are ordered by :func:`rvfem._arrays.chain_edges` (the same ordering the mesher
    uses for its named boundaries) and each chain is then turned so that the outward normal of
    every edge, (t_y, −t_x) for the unit tangent t, points away from the edge's triangle.
    """
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if len(e) == 0:
        raise MeshError("no edges given")
    edge_outward_normals(model, e)                    # every edge on the boundary, or MeshError
    p = model.mesh.p.T
    chains = []
    for verts, closed in chain_edges(e):
        pairs = np.column_stack([verts[:-1], verts[1:]])
        normals = edge_outward_normals(model, pairs)
        d = p[pairs[:, 1]] - p[pairs[:, 0]]
        left = (d[:, 1] * normals[:, 0] - d[:, 0] * normals[:, 1]) > 0.0   # body on the left
        if left.any() and not left.all():
            j = int(np.flatnonzero(left != left[0])[0])
            raise MeshError(f"boundary branches at vertex {int(pairs[j, 0])} (the body changes side)")
        if not left[0]:
            verts = verts[::-1].copy()
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


def _footprint_arcs(
    chain: BoundaryChain,
    centres: np.ndarray,
    half_widths: np.ndarray | float,
    shape: str,
) -> tuple[np.ndarray, np.ndarray, tuple[float, ...]]:
    """Checked footprint centres and half-widths, and the shifts under which a chain is searched.

    Parameters
    ----------
    chain : BoundaryChain
    centres : array_like
        ``(m,)`` arc length of the footprint centres, mm.
    half_widths : array_like or float
        ``(m,)`` or scalar footprint half-width a, mm.
    shape : str
        Name of the footprint density; only checked here.

    Returns
    -------
    c : numpy.ndarray
        ``(m,)`` float64 centres, mm; wrapped into [0, L) on a closed chain of length L.
    a : numpy.ndarray
        ``(m,)`` float64 half-widths, mm (a writable copy).
    shifts : tuple of float
        Arc-length shifts of the chain, mm: (−L, 0, L) on a closed chain, so that a footprint
        crossing the seam s = 0 ≡ L also finds the edges on the other side of it; (0,) on an
        open chain.

    Raises
    ------
    ValueError
        As :func:`footprint_weights`.
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
        shifts: tuple[float, ...] = (-length, 0.0, length)
    else:
        if (c - a < -1e-12 * length).any() or (c + a > length * (1 + 1e-12)).any():
            raise ValueError("footprint runs off the end of an open boundary chain")
        shifts = (0.0,)
    return c, a, shifts


def _footprint_edges(
    chain: BoundaryChain,
    c: np.ndarray,
    a: np.ndarray,
    shifts: tuple[float, ...],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every pair of a footprint and a (shifted) chain edge whose arcs may overlap.

    Edge k spans the arc lengths ``[s_k + h, s_{k+1} + h]`` under the shift h; footprint j spans
    ``[c_j − a_j, c_j + a_j]``. Both are sorted intervals, so the candidate edges of a footprint
    are one contiguous run found by two binary searches; pairs that merely touch are discarded
    later by :func:`_footprint_pieces`.

    Parameters
    ----------
    chain : BoundaryChain
    c, a : numpy.ndarray
        ``(m,)`` centres and half-widths from :func:`_footprint_arcs`, mm.
    shifts : tuple of float
        Arc-length shifts of the chain, mm (:func:`_footprint_arcs`).

    Returns
    -------
    cols : numpy.ndarray
        ``(n,)`` footprint (column) index of each pair.
    eidx : numpy.ndarray
        ``(n,)`` index of the pair's edge in ``chain.edges``.
    shift : numpy.ndarray
        ``(n,)`` the shift under which the pair was found, mm.
    """
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
    return np.concatenate(col_l), np.concatenate(edge_l), np.concatenate(shift_l)


def _footprint_pieces(
    chain: BoundaryChain,
    c: np.ndarray,
    a: np.ndarray,
    cols: np.ndarray,
    eidx: np.ndarray,
    shift: np.ndarray,
) -> tuple[np.ndarray, ...]:
    """The overlap of each footprint and edge, relative to the footprint centre.

    Working in v = s − c ∈ [−a, a] rather than in s gives neighbouring pieces of one footprint
    bit-identical break points, so their weights telescope to 1 without cancellation error.

    Parameters
    ----------
    chain : BoundaryChain
    c, a : numpy.ndarray
        ``(m,)`` centres and half-widths, mm.
    cols, eidx, shift : numpy.ndarray
        ``(n,)`` candidate pairs from :func:`_footprint_edges`.

    Returns
    -------
    tuple of numpy.ndarray
        ``(cols, eidx, aa, v_start, le, v0, v1)``, each ``(p,)`` for the p pairs that overlap on
        an arc of positive length: column and edge index, the footprint's half-width a (mm), the
        edge's start relative to the centre (mm), the edge's length (mm) and the overlap
        ``[v0, v1]`` ⊂ [−a, a] (mm).
    """
    s0, s1 = chain.s[:-1], chain.s[1:]
    cc, aa = c[cols], a[cols]
    v_start = (s0[eidx] + shift) - cc                       # edge start, relative to the centre
    v_end = (s1[eidx] + shift) - cc
    le = s1[eidx] - s0[eidx]
    v0 = np.maximum(-aa, v_start)
    v1 = np.minimum(aa, v_end)
    keep = v1 > v0
    return tuple(x[keep] for x in (cols, eidx, aa, v_start, le, v0, v1))


def _footprint_quadrature(
    shape: str,
    aa: np.ndarray,
    v0: np.ndarray,
    v1: np.ndarray,
    n_quad: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Gauss points and weights of the footprint density ρ over each piece ``[v0, v1]``.

    * ``"elliptic"``, ρ(v) = 2/(π a) · √(1 − (v/a)²) ([2]_ eq. 4.43): with v = a sin θ,
      ρ dv = (2/π) cos²θ dθ, which is smooth, so the ``n_quad`` Gauss–Legendre points are placed
      in θ ∈ [arcsin(v0/a), arcsin(v1/a)] and the rule converges exponentially despite the
      square-root edges of ρ at v = ±a;
    * ``"uniform"``, ρ = 1/(2a): the points are placed in v directly.

    Parameters
    ----------
    shape : {"elliptic", "uniform"}
    aa : numpy.ndarray
        ``(p,)`` half-width a of each piece's footprint, mm.
    v0, v1 : numpy.ndarray
        ``(p,)`` ends of the pieces relative to the footprint centre, mm (−a ≤ v0 < v1 ≤ a).
    n_quad : int
        Gauss points per piece.

    Returns
    -------
    vq : numpy.ndarray
        ``(p, n_quad)`` positions of the points relative to the footprint centre, mm.
    wt : numpy.ndarray
        ``(p, n_quad)`` weights ρ dv of the points (dimensionless): ∑ wt f(vq) ≈ ∫ ρ f dv over
        the piece, and the weights of a whole footprint sum to 1.
    """
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
    return vq, wt


def _footprint_matrix(
    model: FEModel,
    chain: BoundaryChain,
    cols: np.ndarray,
    eidx: np.ndarray,
    v_start: np.ndarray,
    le: np.ndarray,
    vq: np.ndarray,
    wt: np.ndarray,
    n_columns: int,
) -> sp.csc_matrix:
    """Consistent nodal weights W[i, j] = ∫ ρ_j φ_i ds from the quadrature of every piece.

    The shape functions φ_i of the edge's nodes (:func:`_edge_shape`) are evaluated at the local
    coordinate t = (v − v_start)/le ∈ [0, 1] of each point and weighted with ρ dv ([1]_ § 3.5);
    the contributions of all pieces to a node are summed by the sparse constructor.

    Parameters
    ----------
    model : FEModel
    chain : BoundaryChain
    cols, eidx, v_start, le : numpy.ndarray
        ``(p,)`` column, edge index, edge start relative to the centre (mm) and edge length (mm)
        of each piece (:func:`_footprint_pieces`).
    vq, wt : numpy.ndarray
        ``(p, n_quad)`` points (mm) and weights (dimensionless) from
        :func:`_footprint_quadrature`.
    n_columns : int
        Number of footprints m.

    Returns
    -------
    scipy.sparse.csc_matrix
        ``(n_nodes, m)``.
    """
    t = np.clip((vq - v_start[:, None]) / le[:, None], 0.0, 1.0)
    phi = _edge_shape(model.order, t)                      # (n_local, n_pieces, n_quad)
    vals = np.einsum("lpq,pq->pl", phi, wt)                # (n_pieces, n_local)
    nodes = _edge_nodes(model, chain.edges[eidx])          # (n_pieces, n_local)
    rows = nodes.ravel()
    cidx = np.broadcast_to(cols[:, None], nodes.shape).ravel()
    return sp.csc_matrix((vals.ravel(), (rows, cidx)), shape=(model.n_nodes, n_columns))


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
      distribution ([2]_ eq. 4.43);
    * ``"uniform"``: ρ(s) = 1/(2a).

    Only the edges the arc overlaps get entries, so thousands of columns are cheap. Each overlap
    is integrated separately with ``n_quad`` Gauss points; for the elliptic density in the
    variable θ = arcsin((s − c)/a), where ρ ds = (2/π) cos²θ dθ is smooth, so the quadrature
    converges exponentially despite the square-root edges of ρ.

    The steps are parts of their own: the checked arcs (:func:`_footprint_arcs`), the edges each
    arc may overlap (:func:`_footprint_edges`), the overlaps (:func:`_footprint_pieces`), the
    quadrature of ρ over them (:func:`_footprint_quadrature`) and the consistent nodal weights
    (:func:`_footprint_matrix`).

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
    c, a, shifts = _footprint_arcs(chain, centres, half_widths, shape)
    cols, eidx, shift = _footprint_edges(chain, c, a, shifts)
    cols, eidx, aa, v_start, le, v0, v1 = _footprint_pieces(chain, c, a, cols, eidx, shift)
    vq, wt = _footprint_quadrature(shape, aa, v0, v1, n_quad)
    return _footprint_matrix(model, chain, cols, eidx, v_start, le, vq, wt, len(c))


def load_operator(model: FEModel, weights: sp.spmatrix, directions: npt.ArrayLike) -> sp.csc_matrix:
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
        ``(n_nodes, m)`` from :func:`footprint_weights`.
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
