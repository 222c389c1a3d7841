"""Contact solve on the condensed disc: pins, crank-bearing rollers and the carrier rotation.

The model (docs/theory.md) in the disc's body frame:

* The disc is a 2D plane-stress body; its stiffness K never changes with the crank angle θ.
* Every load that can act on the disc enters through a fixed **footprint grid** on its boundary:
  column k is a unit force (1 N) in direction d_k, spread over the boundary arc around the grid
  point x_k with an elliptical (Hertz-like) density of half-width a. Pin contacts use the profile
  grid (direction: inward normal of the profile), rollers use a grid on each bore (direction:
  radially outward from the bore centre, i.e. into the disc material). A contact between grid points
  shares its force between the two neighbouring columns (linear interpolation), so its load and
  its displacement are work-conjugate.
* **Condensation** (docs/theory.md § 6): the compliance of the floating disc between grid columns,
  C = Bᵀ Π K_s⁻¹ Πᵀ B, is computed lazily, column by column, the first time a column carries load,
  and reused for every later crank angle (K_s is K with a statically determinate 3-DOF support, Π
  removes the rigid motion; see :class:`Compliance`). The disc's rigid-body motion ``a``
  (2 translations, 1 rotation) is an unknown of the small system. On an exactly N-fold symmetric
  mesh only one sector's columns are back-substituted (:func:`column_rotation`, § 9a).
* Pins are rigid (Signorini: gap ≥ 0, force ≥ 0, force·gap = 0, primal–dual active set) or
  compliant: the Hertz pin–flank line contact (:func:`hertz_pin_law`), Palmgren's roller formula
  or a linear spring (:mod:`rvfem.solve.models`). Rollers are compression-only springs along their
  radial line with the Palmgren law for both raceways, δ = 2·3.84e-5·Q^0.9 / L^0.8 (mm, N), or a
  linear stiffness; the approach is the radial relative displacement of eccentric and bore minus
  half the radial clearance.
* The carrier with its eccentrics is one rigid body that can only rotate. **Torque convention**:
  its rotation φ turns the eccentric centres c_i about the *disc centre* (eccentric displacement
  φ·ẑ×c_i) and its conjugate load is the disc torque T_disc = T_out/discs as a moment about the
  disc centre. This is the handbook's convention (ΣP_x·e·Zc = T_disc, Gao et al. eq. 4); about the
  reducer axis the same pin forces give a moment larger by Zp/Zc.

Per crank angle the unknowns are the contact forces λ (pins and rollers), the rigid motion ``a``
and φ; the equations are the contact laws, the disc's equilibrium Rᵀλ = 0 and the carrier's
Σ m_c λ_c = T_disc. They are solved by a semismooth Newton method (the primal–dual active set for
the rigid pins) on this small dense system.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from scipy.special import lambertw

from rvfem import fem
from rvfem._arrays import readonly as _readonly
from rvfem.errors import ContactError

log = logging.getLogger(__name__)

__all__ = [
    "FootprintGrid",
    "Interface",
    "Compliance",
    "column_rotation",
    "ContactSet",
    "AngleSolution",
    "build_interface",
    "palmgren_law",
    "linear_law",
    "hertz_pin_approach",
    "hertz_pin_law",
    "solve_contact",
    "solve_bodies",
    "Body",
]

# ------------------------------------------------------------------------------------------------
# Footprint grids and the load operator B
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FootprintGrid:
    """The footprint columns of one closed boundary: one or two columns per boundary vertex.

    Attributes
    ----------
    name : str
        Boundary name (``"profile"``, ``"bore_0"``, ...).
    offset : int
        Index of the grid's first column among all columns of the interface.
    chain : rvfem.fem.BoundaryChain
        The boundary loop.
    stride : int
        Columns sit at every ``stride``-th vertex of the chain (arc lengths ``chain.s[::stride]``).
    centre : ndarray (2,) or None
        Bore centre for bore grids (one column per vertex, pushing radially away from it), None
        for the profile (two columns per vertex, unit forces in x and y, so that a contact force
        of any direction is represented exactly).
    """

    name: str
    offset: int
    chain: object
    centre: np.ndarray | None = None
    stride: int = 1

    @property
    def components(self) -> int:
        """Columns per vertex: 1 (radial, bores) or 2 (x and y, profile)."""
        return 1 if self.centre is not None else 2

    @functools.cached_property
    def arcs(self) -> np.ndarray:
        """Arc lengths of the column positions, mm, with the loop length appended."""
        return _readonly(np.append(self.chain.s[:-1][::self.stride], self.chain.s[-1]))

    @functools.cached_property
    def count(self) -> int:
        """Number of column positions."""
        return len(self.arcs) - 1

    @property
    def polyline(self) -> np.ndarray:
        """Column positions (vertices) in loop order, (count, 2), mm."""
        return self.chain.points[:-1][::self.stride]

    def arc_of(self, points: np.ndarray) -> np.ndarray:
        """Arc length of the boundary point closest to each of ``points``, mm."""
        return self.chain.locate(points)[0]

    def columns_at(self, s: np.ndarray, direction: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Columns and weights of unit forces at arc positions ``s``.

        The force is shared linearly between the two neighbouring vertices. On a radial grid the
        direction is the columns' own (``direction`` is ignored); on an x/y grid ``direction``
        ((m, 2) unit vectors, the force on the disc) is required.

        Returns
        -------
        cols, weights : ndarray (m, 2) radial or (m, 4) x/y
        """
        arc = self.arcs
        s = np.mod(np.asarray(s, dtype=float), arc[-1])
        i = np.clip(np.searchsorted(arc, s, side="right") - 1, 0, self.count - 1)
        t = (s - arc[i]) / (arc[i + 1] - arc[i])
        j = (i + 1) % self.count
        if self.components == 1:
            return self.offset + np.stack([i, j], axis=1), np.stack([1.0 - t, t], axis=1)
        d = np.asarray(direction, dtype=float)
        cols = self.offset + np.stack([2 * i, 2 * i + 1, 2 * j, 2 * j + 1], axis=1)
        w = np.stack([(1 - t) * d[:, 0], (1 - t) * d[:, 1], t * d[:, 0], t * d[:, 1]], axis=1)
        return cols, w


@dataclass(frozen=True)
class Interface:
    """All footprint columns of a disc and their load operator.

    Attributes
    ----------
    B : scipy.sparse.csc_matrix (n_dofs, n_cols)
        Column k is the consistent nodal load vector of the unit footprint load k.
    points, directions : ndarray (n_cols, 2)
        Grid point and force direction (on the disc) of each column.
    resultants : ndarray (n_cols, 3)
        Bᵀ·R: the exact force (Fx, Fy, N) and moment about the disc centre (Mz, N·mm) of each column.
    grids : dict name → FootprintGrid
    """

    B: sp.csc_matrix
    points: np.ndarray
    directions: np.ndarray
    resultants: np.ndarray
    grids: dict[str, FootprintGrid]
    half_widths: dict[str, float]

    @property
    def n_columns(self) -> int:
        return self.B.shape[1]


def build_interface(model, boundaries: dict[str, np.ndarray], rigid_modes: np.ndarray,
                    bore_centres: dict[str, np.ndarray], half_width: dict[str, float],
                    stride: dict[str, int] | None = None) -> Interface:
    """Build the footprint columns and the load operator B on the named boundaries.

    Column k of a boundary sits at its k-th vertex; its unit force is spread over the arc
    |s − s_k| ≤ a with the Hertz (elliptical) density and turned into consistent nodal loads
    (:func:`rvfem.fem.footprint_weights`, :func:`rvfem.fem.load_operator`).

    Parameters
    ----------
    model : rvfem.fem.FEModel
        P1 or P2 model of the disc.
    boundaries : dict name → (k, 2) int
        Boundary edges (mesh vertex indices) of each closed boundary that gets columns.
    rigid_modes : ndarray (n_dofs, 3)
        Rigid-body modes (x translation, y translation, rotation about the origin).
    bore_centres : dict name → (2,)
        Centre of each bore: one column per vertex, pushing radially away from the centre (into
        the disc). Boundaries not listed get two columns per vertex (x and y), so that contact
        forces keep their exact direction (the profile: a direction interpolated between vertex
        normals is off by several degrees near the inflection points of coarse profiles).
    half_width : dict name → float
        Footprint half-width a per boundary, mm.
    stride : dict name → int, optional
        Columns at every stride-th vertex (default 1). With a half-width above the column spacing
        the footprints still overlap, and fewer columns mean fewer back-substitutions.
    """

    blocks, points, directions, grids, widths = [], [], [], {}, {}
    offset = 0
    for name, edges in boundaries.items():
        chains = fem.boundary_chains(model, edges)
        if len(chains) != 1 or not chains[0].closed:
            raise ValueError(f"boundary '{name}' is not one closed loop")
        chain = chains[0]
        centre = bore_centres.get(name)
        grid = FootprintGrid(name, offset, chain, None if centre is None else np.asarray(centre, float),
                             (stride or {}).get(name, 1))
        grids[name] = grid
        widths[name] = a = float(half_width[name])
        weights = fem.footprint_weights(model, chain, grid.arcs[:-1], a)
        if grid.components == 1:
            d_k = grid.polyline - grid.centre
            d_k /= np.linalg.norm(d_k, axis=1)[:, None]
            blocks.append(fem.load_operator(model, weights, d_k))
        else:
            d_k = np.tile(np.eye(2), (grid.count, 1))
            bx = fem.load_operator(model, weights, (1.0, 0.0))
            by = fem.load_operator(model, weights, (0.0, 1.0))
            order = np.argsort(np.r_[2 * np.arange(grid.count), 2 * np.arange(grid.count) + 1], kind="stable")
            blocks.append(sp.hstack([bx, by]).tocsc()[:, order])
        points.append(np.repeat(grid.polyline, grid.components, axis=0))
        directions.append(d_k)
        offset += grid.components * grid.count
    B = sp.hstack(blocks).tocsc()
    return Interface(B, np.vstack(points), np.vstack(directions), np.asarray(B.T @ rigid_modes), grids, widths)


# ------------------------------------------------------------------------------------------------
# Lazily computed compliance between columns
# ------------------------------------------------------------------------------------------------


MAP_CHUNK = 256
"""Columns rotated at a time by :meth:`Compliance.ensure` (bounds its temporaries)."""


class Compliance:
    """C = Bᵀ K⁺ B, computed a batch of columns at a time when first needed and cached.

    Holds the only mutable state of a solve (the cache); one instance per disc model.

    With ``rigid_modes`` the compliance is the floating disc's, free of the 3-DOF support of
    K_s: every column load is first balanced by a rigid-mode load on the mesh vertices and the
    displacement is then freed of its rigid motion (the vertices' least-squares rigid fit is
    zero), ``C = Bᵀ Π K_s⁻¹ Πᵀ B`` with Π = I − R (R_vᵀ R)⁻¹ R_vᵀ (R the rigid modes, R_v their
    vertex rows). For the self-equilibrated loads of a contact solve this changes C only by
    rigid-motion terms, which the rigid-motion unknowns of the solve absorb: the contact forces
    are those of the supported form. Its value is that C no longer depends on where the support
    sits, so that it inherits the disc's symmetry: with ``rotation`` (the column map Q of a
    rotation by 2π/N, :func:`column_rotation`), ``C = Q C Qᵀ`` and only the columns of one
    360°/N sector are back-substituted; the others follow as ``C[:, c] = Qᵏ C[:, J] Qᵏ[c, J]ᵀ``,
    J the columns of the grid point that Qᵏ carries onto column c's.

    Parameters
    ----------
    solve : callable
        ``solve(rhs)`` → K_s⁻¹·rhs for a dense (n_dofs, m) array.
    B : sparse (n_dofs, n_cols)
    batch : int
        Right-hand sides per back-substitution call.
    workers : int, optional
        Threads for the back-substitutions (default min(4, cores)).
    rigid_modes : ndarray (n_dofs, 3), optional
        Rigid-body modes (:func:`rvfem.fem.rigid_body_modes`); None keeps the supported form
        ``Bᵀ K_s⁻¹ B`` (then ``rotation`` is not allowed).
    vertex_dofs : ndarray of int, optional
        DOFs of the mesh vertices (default all DOFs): the rigid fit uses these only, so that a P1
        and a P2 model of the same mesh give the rigid motion the same meaning.
    rotation : sparse (n_cols, n_cols), optional
        Column map of the disc's N-fold rotation symmetry (:func:`column_rotation`).
    order : int
        N, the order of ``rotation``.
    free : (ndarray, callable), optional
        The free DOFs of K_s and the solve on them alone (:meth:`rvfem.fem.Factorization.solve_free`):
        the columns are then back-substituted on the free DOFs (faster, equal to round-off).
    """

    def __init__(self, solve, B: sp.csc_matrix, batch: int = 16, workers: int | None = None, *,
                 rigid_modes: np.ndarray | None = None, vertex_dofs: np.ndarray | None = None,
                 rotation: sp.spmatrix | None = None, order: int = 1, free=None):
        self._solve = solve
        self.batch = batch  # right-hand sides per back-substitution call (measured optimum)
        self.workers = workers or min(4, os.cpu_count() or 1)
        self.B = B
        n = B.shape[1]
        self.C = np.zeros((n, n), order="F")     # filled a column at a time
        self.known = np.zeros(n, dtype=bool)
        self.solve_seconds = 0.0
        self.columns_solved = 0
        self.columns_mapped = 0
        self._rigid = None
        if rigid_modes is not None:
            R = np.asarray(rigid_modes, dtype=float)
            Rv = np.zeros_like(R)
            rows = slice(None) if vertex_dofs is None else np.asarray(vertex_dofs, dtype=int)
            Rv[rows] = R[rows]
            H = np.linalg.inv(Rv.T @ R)                     # (R_vᵀ R)⁻¹, 3×3
            self._rigid = (R, Rv, H, np.asarray(B.T @ R))   # Bᵀ R: (n_cols, 3)
        elif rotation is not None:
            raise ValueError("a rotation map needs the floating compliance (give rigid_modes)")
        self._free = None
        if free is not None and self._rigid is not None:
            dofs, solve_free = free
            dofs = np.asarray(dofs)
            B_f = sp.csc_matrix(B[dofs])
            Rv_f = np.ascontiguousarray(Rv[dofs])
            Z_f = solve_free(Rv_f @ H.T)                    # K_ff⁻¹ (R_v Hᵀ), (n_free, 3)
            self._free = (solve_free, B_f, B_f.T.tocsr(), np.asarray(B_f.T @ Z_f), H @ (Rv_f.T @ Z_f))
            self._rhs = threading.local()                   # a zeroed right-hand-side block per thread
        self.order = int(order) if rotation is not None else 1
        self._orbits = None if rotation is None else _column_orbits(sp.csr_matrix(rotation), self.order)
        self._lock = threading.Lock()

    @property
    def symmetric(self) -> bool:
        """True when columns are mapped by the disc's rotation symmetry."""
        return self._orbits is not None

    def rotation_power(self, k: int) -> sp.csr_matrix:
        """Qᵏ, the column map of a rotation by k·2π/N (identity for k = 0)."""
        if self._orbits is None:
            raise ValueError("this compliance has no rotation map")
        return self._orbits[2][int(k) % self.order]

    def field(self, load: np.ndarray) -> np.ndarray:
        """Displacement (n_dofs,) or (n_dofs, m) of the disc under nodal loads, mm, in the frame
        of this compliance (support-free with ``rigid_modes``); add the rigid motion of a solve."""
        load = np.asarray(load, dtype=float)
        if self._rigid is None:
            return self._solve(load)
        R, Rv, H, _ = self._rigid
        u = self._solve(load - Rv @ (H.T @ (R.T @ load)))      # Πᵀ·load: balanced on the vertices
        return u - R @ (H @ (Rv.T @ u))                        # Π·u: no rigid fit on the vertices

    def fields(self, loads: np.ndarray) -> np.ndarray:
        """:meth:`field` of many load cases, (n_dofs, m) → (n_dofs, m): back-substituted in
        batches of at most :attr:`batch` on :attr:`workers` threads, as the compliance columns
        are."""
        loads = np.asarray(loads, dtype=float)
        out = np.empty_like(loads)
        m = loads.shape[1]
        size = max(1, min(self.batch, -(-m // self.workers)))     # every thread gets a share
        parts = [slice(i, min(i + size, m)) for i in range(0, m, size)]

        def fill(part):
            out[:, part] = self.field(loads[:, part])

        self._map(fill, parts)
        return out

    def _map(self, fill, parts) -> None:
        """``fill(part)`` for every part, on :attr:`workers` threads when there are several."""
        if len(parts) > 1 and self.workers > 1:
            with ThreadPoolExecutor(self.workers) as pool:
                list(pool.map(fill, parts))
        else:
            for part in parts:
                fill(part)

    def _direct(self, part: np.ndarray) -> np.ndarray:
        """C[:, part] by back-substitution."""
        Bp = self.B[:, part]
        if self._rigid is None:
            return np.asarray(self.B.T @ self._solve(Bp.toarray()))
        R, Rv, H, BtR = self._rigid
        if self._free is None:
            X = self._solve(Bp.toarray() - Rv @ (H.T @ np.asarray(Bp.T @ R).T))   # K_s⁻¹ Πᵀ B_part
            return np.asarray(self.B.T @ X) - BtR @ (H @ (Rv.T @ X))               # Bᵀ Π X
        # on the free DOFs, by superposition: K_s⁻¹ Πᵀ B_part = Y − Z·c with Y = K_ff⁻¹ B_part,
        # Z = K_ff⁻¹ R_v Hᵀ and c = Rᵀ B_part; nothing is copied through the whole DOF numbering.
        # The rigid fit of Y, H·R_vᵀ·Y = Zᵀ·B_part (K_ff is symmetric), is read off BᵀZ instead of
        # from Y
        solve_free, B_f, B_fT, BtZ, HRvtZ = self._free
        rhs, rows, cols = self._scatter(B_f, part)
        try:
            Y = solve_free(rhs)
        finally:
            rhs[rows, cols] = 0.0
        c = BtR[part].T
        return (np.asarray(B_fT @ Y) - BtZ @ c) - BtR @ (BtZ[part].T - HRvtZ @ c)

    def _scatter(self, B_f: sp.csc_matrix, part: np.ndarray):
        """B_f[:, part] written into this thread's zeroed block (C-ordered, reused: no page faults
        of a fresh 2–3 MB array per call), with the rows and columns written (to be zeroed again)."""
        block = getattr(self._rhs, "block", None)
        if block is None or block.shape[1] != len(part):
            block = self._rhs.block = np.zeros((B_f.shape[0], len(part)))
        starts = B_f.indptr[part]
        counts = B_f.indptr[part + 1] - starts
        first = np.concatenate([[0], np.cumsum(counts)[:-1]])
        pos = np.repeat(starts - first, counts) + np.arange(int(counts.sum()))
        rows, cols = B_f.indices[pos], np.repeat(np.arange(len(part)), counts)
        block[rows, cols] = B_f.data[pos]
        return block, rows, cols

    def ensure(self, columns: np.ndarray) -> None:
        """Make sure ``C[:, columns]`` is available.

        Missing columns are back-substituted in batches of :attr:`batch` right-hand sides, on
        :attr:`workers` threads (SciPy's SuperLU releases the GIL: 1.6× on two cores, measured;
        cholespy holds it, and its systems use one thread); with a rotation map only those of one
        sector, the rest are rotated copies.
        """
        columns = np.asarray(columns, dtype=int)
        if self.known[columns].all():
            return
        with self._lock:        # one filler at a time (the attribution runs on its own thread)
            self._ensure(columns)

    def _ensure(self, columns: np.ndarray) -> None:
        need = np.unique(columns[~self.known[columns]])
        if need.size == 0:
            return
        t0 = time.perf_counter()
        if self._orbits is None:
            self._back_substitute(need)
        else:
            root, power, powers = self._orbits
            masters = np.unique(np.concatenate([root[c] for c in need]))
            self._back_substitute(masters[~self.known[masters]])
            mapped = need[~self.known[need]]
            ks = power[mapped]
            groups = [(k, part) for k in np.unique(ks) for cs_k in [mapped[ks == k]]
                      for part in np.array_split(cs_k, -(-cs_k.size // MAP_CHUNK))]
            for k, cs in groups:       # in chunks: the temporaries are (n_cols, chunk) arrays
                # C[:, cs] = Qᵏ·C[:, J]·Qᵏ[cs, J]ᵀ: row c of Qᵏ holds the one or two columns of
                # the root point (J) that turn into column c, so the middle product is a sum
                # of at most two weighted columns of C
                rows = powers[k][cs]
                start, count = rows.indptr[:-1], np.diff(rows.indptr)
                turned = self.C[:, rows.indices[start]] * rows.data[start]
                two = np.flatnonzero(count == 2)
                turned[:, two] += self.C[:, rows.indices[start[two] + 1]] * rows.data[start[two] + 1]
                self.C[:, cs] = powers[k] @ turned
            self.known[mapped] = True
            self.columns_mapped += mapped.size
        self.solve_seconds += time.perf_counter() - t0

    def _back_substitute(self, need: np.ndarray) -> None:
        if need.size == 0:
            return
        parts = [need[i:i + self.batch] for i in range(0, need.size, self.batch)]

        def fill(part):
            self.C[:, part] = self._direct(part)

        self._map(fill, parts)
        self.known[need] = True
        self.columns_solved += need.size


def column_rotation(iface: Interface, order: int, tol: float = 1e-9) -> sp.csr_matrix | None:
    """The column map Q of a rotation of the disc by 2π/``order`` about its centre.

    Column c (a unit footprint force at point x_c in direction d_c) turns into the force R·d_c
    at R·x_c, which the columns at R·x_c represent exactly: Q[c', c] = d_c'·(R·d_c) (one radial
    bore column, or the x and y columns of a profile point). Exact for an exactly symmetric mesh
    (the footprint weights of corresponding grid points are then the same); None when some turned
    point or direction has no columns to take it (the interface is not symmetric).

    Parameters
    ----------
    iface : Interface
    order : int
        N ≥ 2.
    tol : float
        Relative position tolerance (of the largest radius).
    """

    a = 2.0 * np.pi / order
    Rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    pts, dirs = iface.points, iface.directions
    sites, site_of = np.unique(pts, axis=0, return_inverse=True)
    site_of = site_of.ravel()
    scale = float(np.abs(sites).max())
    dist, image = cKDTree(sites).query(sites @ Rot.T)
    if dist.max() > tol * scale:
        return None
    cols_of = [[] for _ in range(len(sites))]
    for c, s in enumerate(site_of):
        cols_of[s].append(c)
    rows, cols, vals = [], [], []
    turned = dirs @ Rot.T
    for c in range(len(pts)):
        targets = cols_of[image[site_of[c]]]
        w = dirs[targets] @ turned[c]
        if abs(float(np.linalg.norm(dirs[targets].T @ w - turned[c]))) > 1e-9:
            return None
        rows += targets
        cols += [c] * len(targets)
        vals += list(w)
    n = len(pts)
    Q = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    Q.data[np.abs(Q.data) < 1e-15] = 0.0
    Q.eliminate_zeros()
    return Q


def _column_orbits(Q: sp.csr_matrix, order: int):
    """Orbits of the interface columns under Q.

    Returns, for every column c, the columns J of its orbit's root grid point and the power k
    with c among the images of J under Qᵏ; and the powers Q⁰ … Q^(N−1) (CSR). Columns that Q
    couples (the x and y columns of one profile point) form one grid point.
    """

    n = Q.shape[0]
    powers = [sp.identity(n, format="csr")]
    for _ in range(1, order):
        powers.append((Q @ powers[-1]).tocsr())
    pattern = abs(Q)
    _, site = connected_components(pattern.T @ pattern, directed=False)
    members = [[] for _ in range(site.max() + 1)]
    for c, s in enumerate(site):
        members[s].append(c)
    members = [np.asarray(m) for m in members]
    Qc = Q.tocsc()
    image = np.empty(len(members), dtype=int)
    image[site] = site[Qc.indices[Qc.indptr[:-1]]]      # grid point each point turns into
    root_site = np.full(len(members), -1)
    power_site = np.zeros(len(members), dtype=int)
    for s in range(len(members)):
        if root_site[s] >= 0:
            continue
        t = s
        for k in range(order):
            root_site[t], power_site[t] = s, k
            t = image[t]
        if t != s:
            raise ValueError("the column map is not of the given order")
    root = [members[root_site[s]] for s in site]
    return root, np.asarray(power_site[site], dtype=int), powers


# ------------------------------------------------------------------------------------------------
# Contact laws
# ------------------------------------------------------------------------------------------------


PALMGREN_COEFFICIENT = 3.84e-5
"""Palmgren's line-contact approach coefficient, steel on steel: δ = 3.84e-5·Q^0.9/L^0.8 (mm, N;
Harris & Kotzalas, *Rolling Bearing Analysis*). The roller springs here and the Hertz evaluation
(:func:`rvfem.evaluate.hertz.palmgren_approach`) share it."""


def palmgren_law(length: float, contacts: int = 2):
    """Force–approach law of a roller line contact after Palmgren.

    δ = contacts · 3.84e-5 · Q^0.9 / L^0.8  (δ mm, Q N, L mm; Harris & Kotzalas, *Rolling Bearing
    Analysis*, line contact, one roller–raceway contact each; see
    :func:`rvfem.evaluate.hertz.palmgren_approach`), inverted to
    Q(δ) = (δ · L^0.8 / (contacts · 3.84e-5))^(1/0.9) for δ > 0, 0 otherwise.

    Returns a function ``law(delta) -> (Q, dQ/dδ)`` (arrays).
    """
    c = contacts * PALMGREN_COEFFICIENT / length**0.8
    p = 1.0 / 0.9

    def law(delta):
        d = np.maximum(delta, 0.0)
        q = (d / c) ** p
        dq = np.where(d > 0, p / c * (d / c) ** (p - 1.0), 0.0)
        return q, dq

    return law


def linear_law(stiffness: float, bilateral: bool = False, open_fraction: float = 0.0):
    """Linear spring Q = k·δ (compression only unless ``bilateral``), k in N/mm.

    ``open_fraction`` > 0 regularises a compression-only spring: at δ ≤ 0 it keeps the stiffness
    ``open_fraction``·k (a weak tension spring) instead of none. Only the first, linearised solve
    of a cycle uses it (:func:`solve_bodies`).
    """

    def law(delta):
        if bilateral:
            return stiffness * delta, np.full_like(delta, stiffness)
        if open_fraction > 0:
            k = np.where(delta > 0, stiffness, open_fraction * stiffness)
            return k * delta, k
        return stiffness * np.maximum(delta, 0.0), np.where(delta > 0, stiffness, 0.0)

    return law


def hertz_pin_approach(Q, *, length: float, pin_radius: float, flank_curvature, pin_modulus: float,
                       pin_poisson: float, disc_modulus: float, disc_poisson: float,
                       footprint_half_width: float):
    """Approach δ (mm) of a pin–flank Hertz line contact at the force Q (N), and dδ/dQ (mm/N).

    Parameters
    ----------
    Q : array_like
        Contact force, N (> 0).
    length : float
        Contact length L (the disc width), mm; P = Q/L is the load per unit length.
    pin_radius : float
        R_p, mm.
    flank_curvature : array_like
        Signed curvature κ of the flank at the contact point, 1/mm: positive where the flank is
        convex (near the tips), negative where it is concave (near the roots).
    pin_modulus, pin_poisson, disc_modulus, disc_poisson : float
        E (MPa) and ν of the pin and of the disc.
    footprint_half_width : float
        Half-width w of the elliptical footprint over which the FE model spreads the pin force, mm.

    Returns
    -------
    delta, ddelta_dQ : ndarray

    Notes
    -----
    Hertz line contact (Johnson, *Contact Mechanics*, §4.2 and §5.6, plane strain): relative
    curvature 1/R = 1/R_p + κ, contact modulus 1/E* = (1 − ν_p²)/E_p + (1 − ν_d²)/E_d, half-width
    a = √(4PR/(πE*)). The approach is the sum of two parts:

    * the pin: approach of its centre to the contact, Johnson's line-contact result for a
      cylinder, δ_p = P(1 − ν_p²)/(πE_p)·(2 ln(4R_p/a) − 1);
    * the disc: the FE model already deforms the disc under the force spread elliptically over
      ±w; what it lacks is the difference between the Hertz pressure of half-width a and that
      footprint. On a half-plane (plane strain) the approach of the surface point above depth z
      under an elliptical pressure of half-width c is, integrating the strain of the Hertz
      subsurface stresses along the axis,
      2P/(πE)·[(1 − ν²)·asinh(z/c) − ν(1 + ν)·(z√(c² + z²) − z²)/c²]
      → 2P(1 − ν²)/(πE)·[ln(2z/c) − ν/(2(1 − ν))] for z ≫ c; in the difference of c = a and c = w
      the depth and the Poisson term cancel: δ_d = 2P(1 − ν_d²)/(πE_d)·ln(w/a).

    The "depth" convention is therefore: the pin's centre, and for the disc the far field the FE
    model resolves (the sum pin law + FE does not depend on w as long as a and w are small
    against the flank radius). δ(Q) increases up to a half-width a0 where dδ/dP would vanish
    (≈1.2 mm for steel, r_rp = 3 mm, w = 0.5 mm: far beyond any pin load, but a trial approach
    of the solver may get there); beyond a0/√e it is continued linearly with its tangent.
    """
    Q = np.maximum(np.asarray(Q, dtype=float), 1e-300)
    kappa = np.asarray(flank_curvature, dtype=float)
    # a concave flank tighter than the pin (a negative equidistant modification at the root) is
    # not a Hertz contact: the relative radius is capped at 1000 r_rp (conforming)
    inv_r = np.maximum(1.0 / pin_radius + kappa, 1e-3 / pin_radius)
    cp = (1.0 - pin_poisson**2) / (np.pi * pin_modulus)
    cd = (1.0 - disc_poisson**2) / (np.pi * disc_modulus)
    e_star = 1.0 / (np.pi * (cp + cd))
    # dδ/dP = cp·(2 ln(4R_p/a) − 2) + 2cd·(ln(w/a) − ½) vanishes at a0; beyond a_lim = a0/√e
    # (where it is still cp + cd) the law is continued with its tangent, so that it stays monotone
    # for any trial approach of the solver (a_lim ≈ 0.7 mm for steel, r_rp = 3, w = 0.5 mm:
    # thousands of newtons per pin even at the conforming roots)
    ln_a0 = (cp * (2.0 * np.log(4.0 * pin_radius) - 2.0) + cd * (2.0 * np.log(footprint_half_width) - 1.0)) / (2.0 * (cp + cd))
    a_lim = np.exp(ln_a0 - 0.5)
    P_lim = a_lim**2 * np.pi * e_star * inv_r / 4.0

    def parts(P):
        a = np.sqrt(4.0 * P / (inv_r * np.pi * e_star))
        d = P * (cp * (2.0 * np.log(4.0 * pin_radius / a) - 1.0) + 2.0 * cd * np.log(footprint_half_width / a))
        # d ln a / dP = 1/(2P)
        dd = cp * (2.0 * np.log(4.0 * pin_radius / a) - 2.0) + 2.0 * cd * (np.log(footprint_half_width / a) - 0.5)
        return d, dd

    P = Q / length
    beyond = P > P_lim
    d, dd = parts(np.where(beyond, P_lim, P))
    delta = np.where(beyond, d + dd * (P - P_lim), d)
    return delta, dd / length


def hertz_pin_law(**params):
    """Force–approach law of the pin–flank Hertz line contact (:func:`hertz_pin_approach`),
    inverted: ``law(delta) -> (Q, dQ/dδ)`` per pin (arrays broadcast against the pins' curvatures).

    The inversion is closed-form. Below the tangent continuation the approach of
    :func:`hertz_pin_approach` is δ = P·(α − β ln P) with P = Q/L, β = c_p + c_d and
    α = c_p(2 ln 4R_p − 1) + 2c_d ln w − β ln(4R/(πE*)) (ln a = ½ ln(4PR/(πE*)) substituted).
    With P = e^(α/β − t) this is t·e^(−t) = δ·e^(−α/β)/β, whose root on the rising branch
    (dδ/dP = β(t − 1) > 0, t ≥ 2 below the continuation point) is t = −W₋₁(−δ·e^(−α/β)/β), W₋₁
    the lower real branch of Lambert's W function (Corless et al., "On the Lambert W function",
    Adv. Comput. Math. 5, 1996). Beyond the continuation point the law is linear. One Newton step
    on ln P polishes the result to round-off. δ ≤ 0 gives Q = 0 and dQ/dδ = 0 (compression
    only, as Palmgren's law).
    """

    curvature = np.asarray(params["flank_curvature"], dtype=float)
    length = float(params["length"])
    pin_radius, w = float(params["pin_radius"]), float(params["footprint_half_width"])
    cp = (1.0 - params["pin_poisson"] ** 2) / (np.pi * params["pin_modulus"])
    cd = (1.0 - params["disc_poisson"] ** 2) / (np.pi * params["disc_modulus"])
    beta = cp + cd
    e_star = 1.0 / (np.pi * beta)
    inv_r = np.maximum(1.0 / pin_radius + curvature, 1e-3 / pin_radius)   # as hertz_pin_approach
    alpha = (cp * (2.0 * np.log(4.0 * pin_radius) - 1.0) + 2.0 * cd * np.log(w)
             - beta * np.log(4.0 / (inv_r * np.pi * e_star)))
    # the continuation point of hertz_pin_approach: dδ/dP = β there, i.e. t = 2
    P_lim = np.exp(alpha / beta - 2.0)
    d_lim = 2.0 * beta * P_lim

    def law(delta):
        delta = np.asarray(delta, dtype=float)
        shape = np.broadcast(delta, curvature).shape
        d = np.broadcast_to(delta, shape)
        a_, b_ = np.broadcast_to(alpha, shape), np.broadcast_to(P_lim, shape)
        dl = np.broadcast_to(d_lim, shape)
        q = np.zeros(shape)
        dq = np.zeros(shape)
        pos = d > 0
        if not np.any(pos):
            return q, dq
        dp, ap, Pl, dlp = d[pos], a_[pos], b_[pos], dl[pos]
        linear = dp > dlp
        P = Pl + (dp - dlp) / beta                                   # tangent continuation
        rising = ~linear
        if np.any(rising):
            z = dp[rising] / beta * np.exp(-ap[rising] / beta)
            t = -np.real(lambertw(-z, k=-1))
            lnP = ap[rising] / beta - t
            # one Newton step on ln P: f = ln δ(P) − ln δ, f' = 1 − 1/t (δ = βtP)
            t1 = ap[rising] / beta - lnP
            f = np.log(beta * t1) + lnP - np.log(dp[rising])
            lnP = lnP - f / (1.0 - 1.0 / t1)
            P = P.copy()
            P[rising] = np.exp(lnP)
        # dδ/dP = β(t − 1) on the rising branch (t ≥ 2), β on the continuation
        slope = beta * (np.maximum(ap / beta - np.log(P), 2.0) - 1.0)
        q[pos] = P * length
        dq[pos] = length / slope                                     # dQ/dδ = L·dP/dδ
        return q, dq

    return law


# ------------------------------------------------------------------------------------------------
# One crank angle
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ContactSet:
    """The contacts of one crank angle, in interface terms.

    Attributes
    ----------
    W : sparse (n_cols, n_contacts)
        Weights of each contact on the interface columns.
    signorini : ndarray bool (n_contacts,)
        True for rigid pins (gap ≥ 0 ⟂ λ ≥ 0); False for springs.
    gap0 : ndarray (n_contacts,)
        Initial gap of Signorini contacts (mm, negative = overlap), 0 for springs.
    offset : ndarray (n_contacts,)
        Constant part of a spring's approach (mm): −gap for compliant pins, −clearance/2 for rollers.
    lever : ndarray (n_contacts,)
        m_c: approach per unit carrier rotation (mm/rad) = c_i × F̂_c for bearing contacts.
    laws : list of (slice, law)
        Force laws of the spring contacts.
    W_load : sparse (n_cols, n_contacts) or None
        Weights of the *load* of each contact if it differs from ``W`` (Coulomb friction at the
        pins: the force on the disc is λ·(d + μ·s·t), normal plus friction along the known sliding
        direction, while the gap is still measured along the normal d). None: same as ``W``.
    """

    W: sp.csc_matrix
    signorini: np.ndarray
    gap0: np.ndarray
    offset: np.ndarray
    lever: np.ndarray
    laws: list
    W_load: sp.csc_matrix | None = None
    bearing: np.ndarray | None = None

    @property
    def load_weights(self) -> sp.csc_matrix:
        """The weights the contact forces load the disc along: ``W_load``, or ``W`` without one."""
        return self.W if self.W_load is None else self.W_load


@dataclass(frozen=True)
class AngleSolution:
    """Solution of one crank angle.

    Attributes
    ----------
    force : ndarray (n_contacts,)
        Contact force magnitudes λ (N), on the disc along each contact's direction.
    vectors : ndarray (n_contacts, 2)
        Force vectors on the disc, N.
    gap : ndarray (n_contacts,)
        Final gap of Signorini contacts / −approach of springs, mm.
    rigid : ndarray (3,)
        Rigid-body motion of the disc relative to the K_s support: ux, uy (mm), rotation (rad).
    carrier_rotation : float
        φ, rad.
    iterations : int
    residual : dict
        Equilibrium residuals: ``force_N`` (|ΣF|), ``moment_Nmm`` (|ΣM| about the disc centre),
        ``carrier_Nmm`` (|Σ m λ − T|), ``relative`` (force residual / total contact force).
    """

    force: np.ndarray
    vectors: np.ndarray
    gap: np.ndarray
    rigid: np.ndarray
    carrier_rotation: float
    iterations: int
    residual: dict = field(default_factory=dict)


def extrapolated_start(before: AngleSolution, last: AngleSolution) -> AngleSolution:
    """A warm start for the next of equally spaced crank angles: the contact forces (kept ≥ 0),
    the rigid motion and the carrier rotation extrapolated linearly from the last two solutions.

    On the default fan-hole case the Newton iterations per angle fall from 4.5 (the last
    solution as the start) to 2.4; the solutions agree within the iteration's tolerance
    (bearing loads to 3e-9 of the peak)."""
    return dataclasses.replace(last, force=np.maximum(2.0 * last.force - before.force, 0.0),
                               rigid=2.0 * last.rigid - before.rigid,
                               carrier_rotation=2.0 * last.carrier_rotation - before.carrier_rotation)


@dataclass(frozen=True)
class Body:
    """One elastic body of a contact solve: its contacts at this crank angle, its footprint
    interface and its (lazily filled) column compliance. Two discs of the same mesh may share one
    :class:`Compliance`."""

    cset: ContactSet
    interface: Interface
    compliance: Compliance

    def moments(self) -> np.ndarray:
        """Moment about the disc centre of each contact's load per unit force, N·mm/N."""
        return np.asarray(self.cset.load_weights.T @ self.interface.resultants[:, 2])


def solve_contact(cset: ContactSet, iface: Interface, compliance: Compliance, torque: float, *,
                  start: AngleSolution | None = None, max_iterations: int = 50, label: str = "",
                  tol_gap: float = 1e-9, names: list[str] | None = None,
                  rigid_dofs: tuple[int, ...] = (0, 1, 2)) -> AngleSolution:
    """Solve the contact problem of one body at one crank angle (semismooth Newton / primal–dual
    active set).

    Parameters
    ----------
    cset : ContactSet
    iface : Interface
    compliance : Compliance
        Lazily filled column compliance C (filled further as contacts become active).
    torque : float or None
        Disc torque T_disc, N·mm (moment about the disc centre, see module docstring). None: no
        carrier (the body is loaded by the contacts' prescribed gaps alone).
    start : AngleSolution, optional
        Warm start (usually the previous crank angle). Without one, a first solve with secant
        linear springs provides the start (Palmgren's law has zero stiffness at zero load).
    max_iterations : int
        Bound of the Newton / active-set loop.
    label : str
        Names the crank angle in error messages.
    tol_gap : float
        Gap tolerance of the rigid pins, mm.
    names : list of str, optional
        Contact names for error messages.
    rigid_dofs : tuple of int
        Rigid-body motions of the body that are unknowns (0: x, 1: y, 2: rotation). A motion left
        out is held by the support of K_s; use this only for a mode no contact can resist (e.g.
        the rotation of a round body under frictionless radial contacts), whose load is zero.

    Raises
    ------
    ContactError
        If the active set does not settle within ``max_iterations``; names the contacts that keep
        flipping.
    """
    return solve_bodies([Body(cset, iface, compliance)], torque,
                        start=None if start is None else [start], max_iterations=max_iterations,
                        label=label, tol_gap=tol_gap, names=names, rigid_dofs=rigid_dofs)[0]


def solve_bodies(bodies: list[Body], torque: float | None, *, coupling: np.ndarray | None = None,
                 start: list[AngleSolution] | None = None, max_iterations: int = 50, label: str = "",
                 tol_gap: float = 1e-9, names: list[str] | None = None,
                 rigid_dofs: tuple[int, ...] = (0, 1, 2), g_cache: dict | None = None) -> list[AngleSolution]:
    """Solve the contacts of several bodies that share one carrier rotation.

    Each body has its own contacts and rigid-body motion (and is in equilibrium on its own); the
    carrier rotation φ is common and its equation is Σ_bodies Σ_c m_c·λ_c = ``torque`` (the total
    torque: for the two discs of a reducer stage, T_out; each disc's share is an output). The
    optional ``coupling`` matrix H adds an approach −H·λ to every contact: the eccentrics of a
    crankshaft move under the forces of all the discs it carries (see :mod:`rvfem.solve.cycle`).

    Parameters
    ----------
    bodies : list of Body
    torque : float or None
        Total torque on the carrier, N·mm (None: no carrier unknown).
    coupling : ndarray (n_contacts, n_contacts), optional
        Symmetric positive semidefinite compliance added between the contacts of all bodies
        (contacts numbered body after body), mm/N.
    start : list of AngleSolution, optional
        Warm start, one per body.
    max_iterations, label, tol_gap, names, rigid_dofs
        As in :func:`solve_contact` (``names`` lists the contacts of all bodies in order).
    g_cache : dict, optional
        Keeps the contact compliance between solves of the same contacts (:class:`NewtonOptions`).

    Returns
    -------
    list of AngleSolution
        One per body; ``residual["torque_Nmm"]`` is the body's share of the torque.
    """
    options = NewtonOptions(max_iterations, label, tol_gap, names, tuple(rigid_dofs), g_cache)
    sizes = [b.cset.W.shape[1] for b in bodies]
    if start is not None and [s.force.shape for s in start] != [(n,) for n in sizes]:
        start = None
    if start is None and torque is not None and any(b.cset.laws for b in bodies):
        # the secant springs keep the tension side of their laws: a bilateral spring (the
        # rigid_bore bearings' x and y springs) made compression-only would be a different problem,
        # one whose disc may be nearly a mechanism once such a spring opens (with pin friction its
        # active-set iteration then cycles without end)
        secants = [_secant_stiffnesses(b, torque / len(bodies)) for b in bodies]

        def linearised(open_fraction):
            return [dataclasses.replace(b, cset=dataclasses.replace(b.cset, laws=[
                (idx, linear_law(ks, bilateral=bilateral, open_fraction=open_fraction))
                for idx, ks, bilateral in secant])) for b, secant in zip(bodies, secants)]

        # the first linear solve engages the springs that can carry the torque: the bearings' and
        # the pins whose force on the disc opposes the bearings' torque (or that overlap). The pins
        # of the other side stay open, so their compliance columns, which the cycle never needs
        # again, are not computed (about 50 of the default disc's). If that start does not
        # settle, every spring is engaged. And if that does not settle either: a step that opens
        # every pin spring of a disc (a clearance all round, e.g. an equidistant modification,
        # wider than the approaches of the first step, with stiff bearings) leaves the disc's and
        # the carrier's rotation free, the next Newton matrix is singular and the iteration
        # cycles. Open springs that keep a weak stiffness never leave a mechanism; their small
        # tensile forces are only a start, which the solve below removes
        # A start that settles but from which the solve itself does not (a radial clearance larger
        # than the first step's approaches can leave every roller open at the start) is followed
        # by the next way of starting.
        torque_side = np.concatenate([_torque_side(b, torque) for b in bodies])
        everything = np.ones(torque_side.size, dtype=bool)
        attempts = [(0.0, everything), (OPEN_SPRING_FRACTION, everything)]
        if not torque_side.all():
            attempts.insert(0, (0.0, torque_side))
        for i, (open_fraction, engaged) in enumerate(attempts):
            try:
                first = _newton(linearised(open_fraction), torque, coupling, None, options, engaged=engaged)
                return _newton(bodies, torque, coupling, first, options)
            except ContactError:
                if i == len(attempts) - 1:
                    raise
    return _newton(bodies, torque, coupling, start, options)


OPEN_SPRING_FRACTION = 1e-3
"""Stiffness of an open compression-only spring in the fallback linearised start, relative to its
secant stiffness (:func:`solve_bodies`)."""


@dataclass(frozen=True)
class NewtonOptions:
    """Options of the semismooth Newton / primal–dual active-set iteration (:func:`solve_bodies`).

    Attributes
    ----------
    max_iterations : int
        Bound of the iteration.
    label : str
        Names the crank angle in error messages (ends with a space).
    tol_gap : float
        Gap tolerance of the rigid (Signorini) contacts, mm.
    names : list of str or None
        Contact names for error messages.
    rigid_dofs : tuple of int
        Rigid-body motions of each body that are unknowns (0: x, 1: y, 2: rotation).
    g_cache : dict or None
        Keeps the contact compliance G of each set of bodies between solves (:class:`ContactProblem`):
        solves of the same contacts at other torques (a hysteresis loop) fill it once. None: each
        solve builds its own.
    """

    max_iterations: int = 50
    label: str = ""
    tol_gap: float = 1e-9
    names: list | None = None
    rigid_dofs: tuple = (0, 1, 2)
    g_cache: dict | None = None

    def name(self, i: int) -> str:
        return self.names[i] if self.names else str(i)


class ContactProblem:
    """The contact problem of bodies sharing one carrier, as functions of the unknowns.

    Unknowns: the contact forces λ (n_c), each body's rigid motion a (3 per body) and the carrier
    rotation φ (when there is a carrier). A contact's approach is δ = offset + lever·φ − v with
    v = G·λ + R_c·a, G = Wᵀ C W_load (+ the crankshaft coupling H) the compliance between the
    contacts; a spring's force is its law q(δ); a rigid contact has the gap g = gap0 + v ≥ 0.
    The equations: springs λ = q(δ), active rigid contacts g = 0, inactive ones λ = 0, each body
    in equilibrium (R_Lᵀλ = 0) and the carrier Σ lever·λ = T.

    G is filled column by column as contacts become loaded: column j once the load columns of
    contact j are known (C is filled column-wise and symmetric, so the rows of every other contact
    come with them); a column of C never changes once computed, so neither does G's.
    """

    def __init__(self, bodies: list, torque: float | None, coupling: np.ndarray | None = None,
                 rigid_dofs: tuple = (0, 1, 2), g_cache: dict | None = None):
        self.bodies = bodies
        self.nb = nb = len(bodies)
        csets = [b.cset for b in bodies]
        self.offs = offs = np.concatenate([[0], np.cumsum([c.W.shape[1] for c in csets])]).astype(int)
        self.nc = nc = int(offs[-1])
        self.nr = nr = 3 * nb                        # rigid-motion unknowns, 3 per body
        self.dropped = [k for k in range(3) if k not in rigid_dofs]
        self.Rc = np.zeros((nc, nr))                 # rigid motion → approach, per contact
        self.RL = np.zeros((nc, nr))                 # Fx, Fy, Mz on its body per unit λ
        self.Rfull = np.zeros((nc, 3))
        self.subs = [self._weights(k, b) for k, b in enumerate(bodies)]
        self.moment = self.RL[:, 2::3].sum(axis=1)  # Mz of each contact on its own body
        self.carrier = torque is not None            # without a carrier: no φ unknown
        self.torque = 0.0 if torque is None else torque
        self.sig = np.concatenate([c.signorini for c in csets])
        self.gap0 = np.concatenate([c.gap0 for c in csets])
        self.offset = np.concatenate([c.offset for c in csets])
        self.lever = np.concatenate([c.lever for c in csets])
        self.laws = [(offs[k] + np.asarray(idx, dtype=int), law) for k, c in enumerate(csets) for idx, law in c.laws]
        self.spring = ~self.sig
        self.si = np.flatnonzero(self.spring)
        self.r_typ = max(float(np.abs(self.lever).max()), 1.0)
        self.n = nc + nr + 1 if self.carrier else nc + nr
        self.eq = slice(nc, nc + nr)
        self.row_scale = np.tile([1.0, 1.0, 1.0 / self.r_typ], nb)
        self.scale_f = max(abs(self.torque) / self.r_typ, 1.0)
        self.G = np.zeros((nc, nc)) if coupling is None else np.array(coupling, dtype=float)
        self.filled = np.zeros(nc, dtype=bool)
        self._open_tangent = None
        if g_cache is not None:
            self._share_G(g_cache, csets, coupling)

    def _share_G(self, cache: dict, csets: list, coupling) -> None:
        """Take G and its filled columns from ``cache`` if the same contact sets (by identity), the
        same compliances and the same coupling filled them before, else put this problem's there.
        G depends on the contacts' weights, the compliance and the coupling only, and its columns
        never change once computed, so the arrays are shared and filled further in place."""
        key = tuple(id(c) for c in csets) + tuple(id(b.compliance) for b in self.bodies)
        entry = cache.get(key)
        same = (entry is not None and all(a is b for a, b in zip(entry[0], csets))
                and ((entry[1] is None and coupling is None)
                     or (entry[1] is not None and coupling is not None and np.array_equal(entry[1], coupling))))
        if same:
            self.G, self.filled = entry[2], entry[3]
        else:
            cache[key] = (list(csets), None if coupling is None else np.array(coupling), self.G, self.filled)

    def _weights(self, k: int, body) -> tuple:
        """Fill body k's rows of R_c and R_L; its weights on the interface columns it touches."""
        c, rows = body.cset, slice(self.offs[k], self.offs[k + 1])
        W = c.W.tocsc()                              # gaps/approaches are measured along W
        WL = c.load_weights.tocsc()                  # loads act along W_load
        self.Rc[rows, 3 * k:3 * k + 3] = np.asarray(W.T @ body.interface.resultants)
        self.RL[rows, 3 * k:3 * k + 3] = np.asarray(WL.T @ body.interface.resultants)
        self.Rfull[rows] = self.RL[rows, 3 * k:3 * k + 3]
        for d in self.dropped:
            self.Rc[rows, 3 * k + d] = 0.0
            self.RL[rows, 3 * k + d] = 0.0
        # the weights on the touched columns alone: the same CSC arrays with the column indices
        # renumbered (W's arrays read as CSR are Wᵀ)
        touched = np.unique(np.concatenate([W.indices, WL.indices]))
        Wsub_T = sp.csr_matrix((W.data, np.searchsorted(touched, W.indices), W.indptr),
                               shape=(W.shape[1], len(touched)))
        WL_dense = sp.csc_matrix((WL.data, np.searchsorted(touched, WL.indices), WL.indptr),
                                 shape=(len(touched), WL.shape[1])).toarray()
        return touched, Wsub_T, WL_dense, WL_dense != 0

    def G_full(self, idx: np.ndarray) -> np.ndarray:
        """G with the columns of contacts ``idx`` valid (the others are not read with weight)."""
        new = idx[~self.filled[idx]]
        if new.size:
            offs = self.offs
            for k, (b, (touched, WsubT, WL_dense, nonzero)) in enumerate(zip(self.bodies, self.subs)):
                local = new[(new >= offs[k]) & (new < offs[k + 1])] - offs[k]
                if local.size:
                    used = np.flatnonzero(nonzero[:, local].any(axis=1))      # their load columns
                    b.compliance.ensure(touched[used])
                    block = _submatrix(b.compliance.C, touched, touched[used])
                    self.G[offs[k]:offs[k + 1], offs[k] + local] += WsubT @ (block @ WL_dense[np.ix_(used, local)])
            self.filled[new] = True
        return self.G

    def G_cols(self, idx: np.ndarray) -> np.ndarray:
        if idx.size == 0:
            return np.zeros((self.nc, 0))
        return self.G_full(idx)[:, idx]

    def state(self, lam, a, phi) -> tuple:
        """(v, δ, q(δ), dq/dδ) at the unknowns λ, a, φ."""
        v = self.G_full(np.flatnonzero(lam != 0)) @ lam + self.Rc @ a      # λ = 0 off the valid columns
        delta = self.offset + self.lever * phi - v
        q = np.zeros(self.nc)
        dq = np.zeros(self.nc)
        for idx, law in self.laws:
            q[idx], dq[idx] = law(delta[idx])
        return v, delta, q, dq

    def unbalance(self, lam) -> float:
        """The largest residual of the bodies' and the carrier's equilibrium (N, N·mm / r_typ)."""
        unbalanced = float(np.abs((self.RL.T @ lam) * self.row_scale).max())
        if self.carrier:
            unbalanced = max(unbalanced, abs(self.lever @ lam - self.torque) / self.r_typ)
        return unbalanced

    def open_tangent(self) -> np.ndarray:
        """Secant stiffness of every spring at the force it is expected to carry (computed once)."""
        if self._open_tangent is None:
            k = np.zeros(self.nc)
            t_ref = self.torque if self.torque else self.r_typ     # no torque: the secant at about 1 N
            for b, (lo, hi) in zip(self.bodies, zip(self.offs[:-1], self.offs[1:])):
                for idx, ks, _ in _secant_stiffnesses(b, t_ref / self.nb):
                    k[lo + np.arange(hi - lo)[idx]] = ks
            self._open_tangent = k
        return self._open_tangent

    def solutions(self, it: "NewtonIterate", iterations: int) -> list[AngleSolution]:
        """One :class:`AngleSolution` per body from a converged iterate.

        λ from the last Newton step satisfies the (linear) equilibrium equations to round-off and
        the spring laws to the iteration's tolerance; it is not replaced by q(δ), which would trade
        the former for the latter."""
        sig, lever = self.sig, self.lever
        lam = np.where(sig & ~it.active, 0.0, it.lam)
        gap_out = np.where(sig, self.gap0 + it.v, -it.delta)
        carrier_res = float(abs(lever @ lam - self.torque))
        out = []
        for k in range(self.nb):
            rows = slice(self.offs[k], self.offs[k + 1])
            lk, Rk = lam[rows], self.Rfull[rows]
            res_f = float(np.linalg.norm(Rk[:, :2].T @ lk))
            residual = {
                "force_N": res_f,
                "moment_Nmm": float(abs(Rk[:, 2] @ lk)),
                "carrier_Nmm": carrier_res,
                "relative": res_f / max(float(np.abs(lk).sum()), 1e-30),
                "torque_Nmm": float(lever[rows] @ lk),
            }
            out.append(AngleSolution(lk, Rk[:, :2] * lk[:, None], gap_out[rows], it.a[3 * k:3 * k + 3],
                                     float(it.phi), iterations, residual))
        return out


@dataclass
class NewtonIterate:
    """The unknowns of one Newton iterate and what follows from them (:meth:`ContactProblem.state`),
    with the active set of the rigid contacts."""

    lam: np.ndarray
    a: np.ndarray
    phi: float
    active: np.ndarray
    v: np.ndarray = None
    delta: np.ndarray = None
    q: np.ndarray = None
    dq: np.ndarray = None

    def update(self, problem: ContactProblem) -> "NewtonIterate":
        self.v, self.delta, self.q, self.dq = problem.state(self.lam, self.a, self.phi)
        return self


def initial_iterate(problem: ContactProblem, start: list | None, tol_gap: float) -> NewtonIterate:
    """The first iterate: a warm start's forces, rigid motions and carrier rotation, with its
    loaded rigid contacts and any overlapping one active; cold, zero unknowns with the touching
    rigid contacts active whose force on the body opposes the torque (the others can only be
    loaded by a reversed torque). The active-set loop corrects either guess."""
    sig, gap0 = problem.sig, problem.gap0
    if start is not None:
        lam = np.concatenate([s.force for s in start])
        active = sig & ((lam > 0) | (gap0 < -tol_gap))
        it = NewtonIterate(lam, np.concatenate([s.rigid for s in start]), start[0].carrier_rotation, active)
    else:
        active = sig & (gap0 <= tol_gap) & (problem.moment * problem.torque <= 0)
        active |= first_to_close(problem, active)
        it = NewtonIterate(np.zeros(problem.nc), np.zeros(problem.nr), 0.0, active)
    return it.update(problem)


def first_to_close(problem: ContactProblem, active: np.ndarray) -> np.ndarray:
    """The rigid contacts a cold start adds to ``active``: per body whose rigid contacts on the
    torque's side (force on the body against the torque) are all open, the one that a rotation of
    the body about its centre closes first (smallest gap / |moment arm|).

    Such a body has a backlash all round (a positive equidistant modification with rigid pins: at
    zero load no pin touches). With none of its rigid contacts active, the rotation of the body and
    the carrier is held by nothing: the first Newton matrix is singular, exactly so for a profile
    without pitch errors (the solve then stops as a mechanism) and up to round-off otherwise (the
    step then depends on the round-off). The torque turns the body through its backlash onto its
    pins; starting with the first pin it meets active, the active-set loop adds the others."""
    out = np.zeros(problem.nc, dtype=bool)
    if not problem.carrier or not problem.torque:
        return out
    arm = np.abs(problem.moment)
    side = problem.sig & (problem.moment * problem.torque < 0) & (arm > 0)
    for lo, hi in zip(problem.offs[:-1], problem.offs[1:]):
        candidates = np.flatnonzero(side[lo:hi]) + lo
        if candidates.size and not active[candidates].any():
            out[candidates[np.argmin(problem.gap0[candidates] / arm[candidates])]] = True
    return out


def penalty_scale(problem: ContactProblem, active: np.ndarray) -> float:
    """κ, N/mm: the gap rows' scale, the inverse median self-compliance of the active rigid
    contacts (1e6 without any, or on a rigid body)."""
    if not active.any():
        return 1e6
    idx = np.flatnonzero(active)
    compliance = float(np.median(np.diag(problem.G_cols(idx)[idx])))
    return 1.0 / compliance if compliance > 0 else 1e6


def newton_matrix(problem: ContactProblem, it: NewtonIterate, q: np.ndarray, dq: np.ndarray,
                  kappa: float) -> tuple[np.ndarray, np.ndarray]:
    """The Newton matrix and residual of the contact problem at an iterate, with the spring
    forces ``q`` and tangents ``dq`` (those of the laws, or of a linearised or regularised law).

    Rows: springs λ − q(δ); active rigid contacts κ·g; inactive ones λ; each body's equilibrium
    (scaled to N); the carrier (Σ lever·λ − T)/r_typ. Columns: λ, a, φ."""
    p = problem
    nc, nr, n, eq, si = p.nc, p.nr, p.n, p.eq, p.si
    lam, active = it.lam, it.active
    J = np.flatnonzero(active | (p.spring & (dq > 0)) | (lam != 0))   # the forces that move the approaches
    Gj = p.G_cols(J)
    Jm = np.zeros((n, n))
    r = np.zeros(n)
    r[si] = lam[si] - q[si]
    Jm[si, si] = 1.0
    Jm[np.ix_(si, J)] += dq[si, None] * Gj[si]
    Jm[si, eq] = dq[si, None] * p.Rc[si]
    if p.carrier:
        Jm[si, nc + nr] = -dq[si] * p.lever[si]
    ai = np.flatnonzero(active)
    r[ai] = kappa * (p.gap0[ai] + it.v[ai])
    Jm[np.ix_(ai, J)] = kappa * Gj[ai]
    Jm[ai, eq] = kappa * p.Rc[ai]
    ii = np.flatnonzero(p.sig & ~active)
    r[ii] = lam[ii]
    Jm[ii, ii] = 1.0
    r[eq] = (p.RL.T @ lam) * p.row_scale
    Jm[eq, :nc] = p.RL.T * p.row_scale[:, None]
    if p.carrier:
        r[nc + nr] = (p.lever @ lam - p.torque) / p.r_typ
        Jm[nc + nr, :nc] = p.lever / p.r_typ
    for k in range(p.nb):
        for d in p.dropped:
            Jm[nc + 3 * k + d, nc + 3 * k + d] = 1.0
    return Jm, r


def known_rows(problem: ContactProblem, active: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """Rows whose step is known: open springs (dq = 0: λ = q) and inactive rigid contacts (λ = 0).

    Their steps are known, and the rest is a smaller system (about half the contacts are open).
    An open spring's force becomes exactly 0: a solve of the whole system would leave round-off
    (1e-18 N), which would mark it as loaded and fetch its compliance columns."""
    known = np.zeros(problem.n, dtype=bool)
    known[problem.si[dq[problem.si] == 0]] = True
    known[np.flatnonzero(problem.sig & ~active)] = True
    return known


def linearised_start_laws(problem: ContactProblem, it: NewtonIterate, engaged: np.ndarray) -> None:
    """The first linear solve of a cold start: the ``engaged`` springs acting both ways, so that the
    system is stable; the others open (``it.q``, ``it.dq`` overwritten)."""
    for idx, law in problem.laws:
        on = engaged[idx]
        it.q[idx] = np.where(on, law(np.abs(it.delta[idx]))[0] * np.sign(it.delta[idx]), 0.0)
        it.dq[idx] = np.where(on, law(np.ones(np.size(it.delta[idx])))[1], 0.0)


def newton_step(problem: ContactProblem, it: NewtonIterate, kappa: float, colscale: np.ndarray,
                label: str = "") -> np.ndarray:
    """The Newton step at an iterate (:func:`newton_matrix`, :func:`_reduced_step`).

    If the linearised system is a mechanism (every spring that could hold a rigid motion of a
    body or of the carrier is open: zero tangent, Palmgren's law at δ ≤ 0, e.g. a radial clearance
    wider than the approaches of the current iterate), the step is the Newton step of the
    regularised law the cold start uses (an open spring keeps OPEN_SPRING_FRACTION of its secant
    stiffness as a weak tension spring): it moves the body through the clearance onto its rollers.
    The next steps are the true law's again, so the solution is unchanged.

    Raises
    ------
    ContactError
        If even that system is a mechanism (no contact at all can hold the body).
    """
    Jm, r = newton_matrix(problem, it, it.q, it.dq, kappa)
    step = _reduced_step(Jm, r, colscale, known_rows(problem, it.active, it.dq))
    if step is not None:
        return step
    opened = problem.spring & (it.dq == 0)
    k_open = OPEN_SPRING_FRACTION * problem.open_tangent()
    q = it.q.copy()
    q[opened] = k_open[opened] * np.minimum(it.delta[opened], 0.0)
    dq = np.where(opened, k_open, it.dq)
    Jm, r = newton_matrix(problem, it, q, dq, kappa)
    step = _reduced_step(Jm, r, colscale, known_rows(problem, it.active, dq))
    if step is None:
        raise ContactError(
            f"the contact problem {label}is a mechanism: no contact holds the disc or the carrier "
            "(every pin and roller is open). Check the radial clearance, the profile "
            "modifications and the torque.")
    return step


def _not_settled(problem: ContactProblem, it: NewtonIterate, history: list, spring_history: list,
                 options: NewtonOptions) -> ContactError:
    """The error of an iteration that did not settle: the contacts that kept flipping and the
    springs whose law is not met."""
    changes = np.zeros(problem.nc, dtype=int)
    for states in (history, spring_history):
        for h0, h1 in zip(states[:-1], states[1:]):
            changes += h0 != h1
    flipping = [options.name(i) for i in np.flatnonzero(changes)]
    spring, lam, q = problem.spring, it.lam, it.q
    worst = np.argsort(-np.abs(lam - q) * spring)[:5]
    unsettled = [options.name(i) for i in worst if spring[i] and abs(lam[i] - q[i]) > 1e-8 * problem.scale_f]
    return ContactError(
        f"contact active set did not settle {options.label}within {options.max_iterations} iterations"
        + (f"; contacts that keep flipping: {', '.join(flipping)}" if flipping else "")
        + (f"; springs whose force law is not met: {', '.join(unsettled)}" if unsettled else "")
        + ". Check the profile modifications, the clearances and the pin friction (analysis.friction), "
        "or refine the angle step; a set that has not settled by now keeps cycling, so raising "
        "analysis.max_active_set_iterations rarely helps."
    )


def _newton(bodies, torque, coupling, start, options: NewtonOptions, engaged=None) -> list[AngleSolution]:
    """Semismooth Newton / primal–dual active set on :class:`ContactProblem` from ``start`` (a warm
    start per body, or None). ``engaged``: the first step is the linear solve of
    :func:`linearised_start_laws` (a cold start's linearised problem).

    Converged when the active set is unchanged by a step, every body and the carrier are in
    equilibrium, the spring laws hold to 1e-8 of the force scale and the active gaps are closed to
    ``tol_gap``."""
    problem = ContactProblem(bodies, torque, coupling, options.rigid_dofs, options.g_cache)
    p = problem
    it = initial_iterate(problem, start, options.tol_gap)
    kappa = penalty_scale(problem, it.active)
    colscale = np.concatenate([np.ones(p.nc), np.tile([1 / kappa, 1 / kappa, 1 / (kappa * p.r_typ)], p.nb),
                               [1 / (kappa * p.r_typ)]])
    history, spring_history = [], []
    for iteration in range(1, options.max_iterations + 1):
        first_linear = engaged is not None and iteration == 1
        if first_linear:
            linearised_start_laws(problem, it, engaged)
        inactive = np.flatnonzero(p.sig & ~it.active)
        step = newton_step(problem, it, kappa, colscale, options.label)
        it.lam = it.lam + step[:p.nc]
        it.lam[inactive] = 0.0
        it.a = it.a + step[p.eq]
        if p.carrier:
            it.phi = it.phi + step[p.nc + p.nr]
        it.update(problem)
        gap = p.gap0 + it.v
        new_active = p.sig & ((it.lam - kappa * gap) > 0)
        history.append(new_active)
        spring_history.append(p.spring & (it.dq > 0))
        spring_res = float(np.abs(it.lam[p.spring] - it.q[p.spring]).max()) if p.spring.any() else 0.0
        gap_res = float(np.abs(gap[it.active]).max()) if it.active.any() else 0.0
        # equilibrium of every body and of the carrier: met by every solved step (the equations are
        # linear), missed only where a step could not be solved
        balanced = p.unbalance(it.lam) <= 1e-9 * max(p.scale_f, float(np.abs(it.lam).sum()))
        settled = np.array_equal(new_active, it.active)
        it.active = new_active
        if (settled and balanced and spring_res <= 1e-8 * p.scale_f and gap_res <= options.tol_gap
                and not first_linear):
            return problem.solutions(it, iteration)
    raise _not_settled(problem, it, history, spring_history, options)


def _reduced_step(Jm: np.ndarray, r: np.ndarray, colscale: np.ndarray, known: np.ndarray) -> np.ndarray | None:
    """The Newton step of the system ``Jm·step = −r``: the ``known`` rows' steps are −r (their
    rows are identity rows), the rest solved with the columns scaled by ``colscale``. None if that
    system is singular and inconsistent (a mechanism: a rigid motion no contact resists)."""
    fixed, free = np.flatnonzero(known), np.flatnonzero(~known)
    step = np.zeros(r.size)
    step[fixed] = -r[fixed]
    cscale = colscale[free]
    A = Jm[np.ix_(free, free)] * cscale[None, :]
    rhs = -r[free] - Jm[np.ix_(free, fixed)] @ step[fixed]
    try:
        y = np.linalg.solve(A, rhs)
    except np.linalg.LinAlgError:
        y = np.linalg.lstsq(A, rhs, rcond=None)[0]
        if np.abs(A @ y - rhs).max() > 1e-8 * max(float(np.abs(rhs).max()), 1e-30):
            return None
    step[free] = y * cscale
    return step


def _submatrix(C: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """C[rows][:, cols] of a large Fortran-ordered C, gathered through its flat view: the same
    values as ``C[np.ix_(rows, cols)]`` in about half the time (measured on the default disc's
    3501² C)."""
    return C.ravel(order="F").take(rows[:, None] + cols[None, :] * C.shape[0])   # a view: C is F-ordered


def _torque_side(body: Body, torque: float) -> np.ndarray:
    """The contacts of a body engaged in the first linear solve of a cycle (:func:`solve_bodies`):
    all but the pins whose force on the disc turns it the way the torque does (those only a
    reversed torque loads), unless they overlap. All of them when the set does not say which
    contacts are pins."""
    cset = body.cset
    n = cset.W.shape[1]
    if cset.bearing is None or not torque:
        return np.ones(n, dtype=bool)
    return (np.asarray(cset.bearing) >= 0) | (body.moments() * torque <= 0) | (cset.offset > 0)


def _secant_stiffnesses(body: Body, torque: float) -> list[tuple[np.ndarray, float, bool]]:
    """A secant stiffness (N/mm) per spring group for the first, linearised solve of a cycle, and
    whether the group's law also carries tension (bilateral springs stay bilateral).

    Each group gets the secant of its own law at a force of the order it will carry: a bearing
    contact (with a carrier lever) about a quarter of T/r (r its lever arm); a pin about the mean
    force of the loaded half of the pins, T/(½·Σ|m_j|) with m_j the moment of a unit pin force
    about the disc centre. One secant for every group (the bearings') would give a compliant pin
    the stiffness of a bearing, a thousand times too stiff, and the first Newton steps then
    oscillate between contact states without settling.
    """
    cset = body.cset
    moments = np.abs(body.moments())
    out = []
    for idx, law in cset.laws:
        lever = np.abs(cset.lever[idx]).max() if np.size(idx) else 0.0
        if lever > 0:
            q_ref = abs(torque) / lever / 4.0
        else:
            q_ref = abs(torque) / max(0.5 * float(moments[idx].sum()), 1e-30)
        ks = _secant(law, q_ref)
        out.append((idx, ks, _carries_tension(law, q_ref / ks)))
    return out


def _carries_tension(law, delta: float) -> bool:
    """True if a force law gives a tensile (negative) force at the negative approach −δ (a
    bilateral spring), False for a compression-only law (zero force there)."""
    return bool(np.all(law(np.array([-delta]))[0] < 0))


def _secant(law, q_ref: float) -> float:
    """Secant stiffness q_ref/δ of a force law at the force q_ref (bisection for δ in (0, 1] mm)."""
    lo, hi = 0.0, 1.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if law(np.array([mid]))[0][0] < q_ref:
            lo = mid
        else:
            hi = mid
    return q_ref / max(hi, 1e-15)
