"""The lazily computed compliance of the floating disc between footprint columns.

Condensation (docs/theory.md § 6): C = Bᵀ Π K_s⁻¹ Πᵀ B is computed column by column, the first time a
column carries load, and reused for every later crank angle (K_s is K with a statically determinate
3-DOF support, Π removes the rigid motion; see :class:`Compliance`).
"""

from __future__ import annotations

import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import scipy.sparse as sp

from rvfem.solve.contact_rotation import column_orbits


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
    rotation by 2π/N, :func:`rvfem.solve.contact_rotation.column_rotation`), ``C = Q C Qᵀ`` and only
    the columns of one 360°/N sector are back-substituted; the others follow as ``C[:, c] = Qᵏ C[:, J] Qᵏ[c, J]ᵀ``,
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
        Column map of the disc's N-fold rotation symmetry (:func:`rvfem.solve.contact_rotation.column_rotation`).
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
        self._orbits = None if rotation is None else column_orbits(sp.csr_matrix(rotation), self.order)
        self._lock = threading.Lock()

    def scaled(self, factor: float) -> "Compliance":
        """The compliance of the same disc with its stiffness × ``factor`` (its Young's modulus;
        linear elasticity: every displacement ÷ ``factor``): the columns known so far carried over
        divided by ``factor``, the rest back-substituted on the same factorisation when first
        needed, scaled alike. A new cache; this one is left as it is."""
        factor = float(factor)
        new = object.__new__(Compliance)
        new.__dict__.update(self.__dict__)

        def solve(rhs, _solve=self._solve):
            return _solve(rhs) / factor

        new._solve = solve
        with self._lock:
            new.C = np.asfortranarray(self.C / factor)
            new.known = self.known.copy()
        new.solve_seconds, new.columns_solved, new.columns_mapped = 0.0, 0, 0
        if self._free is not None:
            solve_free, B_f, B_fT, BtZ, HRvtZ = self._free

            def free_solve(rhs, _solve=solve_free):
                return _solve(rhs) / factor

            new._free = (free_solve, B_f, B_fT, BtZ / factor, HRvtZ / factor)
            new._rhs = threading.local()
        new._lock = threading.Lock()
        return new

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
        :attr:`workers` threads (SciPy's SuperLU releases the GIL, benchmarks/README.md, "Load cycle";
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
