"""The slice contacts of the crank-bearing rollers solved many at a time: one solve per distinct
active set (:class:`SliceSolver`), the slices coupled through the half-space influence matrix of
:func:`rvfem.evaluate.roller_slices.rectangle_influence`.

The contact conditions and the model are those of :mod:`rvfem.evaluate.roller_slices`; the solver
and its cost are described in docs/theory.md § 12 ("The solver and its cost").
"""

from __future__ import annotations

import numpy as np

from rvfem._arrays import single_threaded_blas

__all__ = ["SliceSolver", "solve_slices", "influence_inverse", "WAVE_STRIDES"]


def solve_slices(influence: np.ndarray, area_mm2: np.ndarray, interference_mm: np.ndarray,
                 load_N: np.ndarray, max_iterations: int = 60, *,
                 inverse: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Pressures of many slice contacts sharing one influence matrix (active-set method).

    For every contact k: p ≥ 0 and C·p = δ_k + g_k on the slices in contact, C·p ≥ δ_k + g_k on
    the others, Σ p·A = Q_k. Solved by a :class:`SliceSolver` whose shapes are the interferences
    themselves (a few contacts at a time); a cycle's contacts, whose interferences are
    combinations of two shapes, use :class:`SliceSolver` directly.

    Parameters
    ----------
    influence : ndarray (n, n)
        C, mm/MPa (:func:`rvfem.evaluate.roller_slices.rectangle_influence`).
    area_mm2 : ndarray (n,)
        Area A_j of each slice's rectangle, mm².
    interference_mm : ndarray (m, n)
        g_k,j = ψ_k·x_j − z(x_j), mm (the approach of slice j relative to mid-length).
    load_N : ndarray (m,)
        Q_k > 0, N.
    max_iterations : int
        Active-set iterations.
    inverse : ndarray (n, n), optional
        C⁻¹, when the caller keeps it with C (computed here otherwise).

    Returns
    -------
    pressure : ndarray (m, n)
        p, MPa.
    approach : ndarray (m,)
        δ, mm.
    """
    g = np.atleast_2d(np.asarray(interference_mm, dtype=float))
    q = np.asarray(load_N, dtype=float).reshape(-1)
    m, n = g.shape
    p = np.zeros((m, n))
    delta = np.zeros(m)
    for lo in range(0, m, _SHAPES_PER_SOLVER):
        rows = slice(lo, min(m, lo + _SHAPES_PER_SOLVER))
        solver = SliceSolver(influence, area_mm2, g[rows], inverse=inverse)
        p[rows], delta[rows] = solver.solve(np.eye(g[rows].shape[0]), q[rows], max_iterations)
        inverse = solver.inverse
    return p, delta


_SHAPES_PER_SOLVER = 4
"""Contacts of :func:`solve_slices` solved together, each interference one shape of the solver."""


def influence_inverse(influence: np.ndarray) -> np.ndarray:
    """C⁻¹ of an influence matrix (:func:`rvfem.evaluate.roller_slices.rectangle_influence`), for :func:`solve_slices`'s
    ``inverse``, 1/(mm/MPa).

    The slices' C is centrosymmetric (C_(n−1−i)(n−1−j) = C_ij: the layout is symmetric about the
    roller's middle). With n = 2m, P = diag(I, J) (J reverses m entries) turns it into
    [[A, D], [D, A]] (A = C[:m, :m], D = C[:m, m:]·J), whose inverse is ½[[X + Y, X − Y], [X − Y,
    X + Y]] with X = (A + D)⁻¹, Y = (A − D)⁻¹: two inverses of half the size, a quarter of the
    work. Any other C is inverted as it is."""
    c = np.asarray(influence, dtype=float)
    n = c.shape[0]
    with single_threaded_blas():
        if n < 2 or n % 2 or not np.array_equal(c, c[::-1, ::-1]):
            return np.linalg.inv(c)
        m = n // 2
        a, d = c[:m, :m], c[:m, m:][:, ::-1]
        x, y = np.linalg.inv(a + d), np.linalg.inv(a - d)
    plus, minus = 0.5 * (x + y), 0.5 * (x - y)
    h = np.empty_like(c)
    h[:m, :m] = plus
    h[:m, m:] = minus[:, ::-1]
    h[m:, :m] = minus[::-1, :]
    h[m:, m:] = plus[::-1, ::-1]
    return h


_BATCH_ELEMENTS = 1 << 21
"""Largest temporary array of one batch of the solver (elements; 16 MB)."""

WAVE_STRIDES = (64, 8, 1)
"""The waves of a :meth:`SliceSolver.solve`: every 64th contact in the order of load starts with
every slice in contact, then every 8th and then every contact not solved yet from the final active
set of its nearest solved neighbour in that order."""


class SliceSolver:
    """Slice contacts sharing one influence matrix whose interferences are combinations of a few
    shapes: g_k = Σ_r c_kr·f_r (a cycle's contacts on one raceway: g = ψ·x − z, the shapes x and
    z, the coefficients ψ and −1).

    The contact conditions of :func:`solve_slices` are linear in (δ, c) once the active set S
    (the slices in contact) is known: with M = [1, f_1, …, f_r] (n × (r + 1)) and
    U_S = C_SS⁻¹·M_S (zero off S),

        p = U·v,   v = (δ, c_1, …, c_r),   δ = (Q − Σ_r c_r·A·U_r)/(A·U_0),

    and the gap w − s = C·p − (δ + g) = (C·U − M)·v, zero on S. So every distinct active set is
    solved once, for r + 1 right-hand sides, whichever contacts have it, and each contact costs
    O(n·r) per active-set iteration: no influence product and no solve per contact. The active
    sets of a roller's contacts repeat over a cycle (its loads and tilts do), so the distinct
    sets are far fewer than the contacts (about a quarter with 400 slices on the default case).

    U_S comes from the smaller of two systems: C_SS itself (|S| unknowns) or the block inverse
    C_SS⁻¹ = H_SS − H_SI·H_II⁻¹·H_IS with H = C⁻¹ (|I| unknowns, I the slices out of contact: a
    loaded roller has only a few beyond the corners' first µm); sets with the same number of
    unknowns are solved as one batch.

    Parameters
    ----------
    influence : ndarray (n, n)
        C, mm/MPa (:func:`rvfem.evaluate.roller_slices.rectangle_influence`).
    area_mm2 : ndarray (n,)
        A_j, mm².
    shapes : ndarray (r, n)
        f_r, mm.
    inverse : ndarray (n, n), optional
        C⁻¹ (computed when first needed otherwise).
    """

    def __init__(self, influence: np.ndarray, area_mm2: np.ndarray, shapes: np.ndarray,
                 inverse: np.ndarray | None = None):
        self.influence = np.asarray(influence, dtype=float)
        self.area = np.asarray(area_mm2, dtype=float)
        n = self.influence.shape[0]
        shapes = np.atleast_2d(np.asarray(shapes, dtype=float))
        self.modes = np.ascontiguousarray(np.concatenate([np.ones((1, n)), shapes], axis=0).T)   # M, (n, r + 1)
        self._inverse = None if inverse is None else np.asarray(inverse, dtype=float)
        self._hm: np.ndarray | None = None
        self._sets: dict[bytes, int] = {}
        r1 = self.modes.shape[1]
        self._count = 0                               # sets solved; their rows of:
        self._u = np.zeros((0, n, r1))                # U of every set, (·, n, r + 1)
        self._gap = np.zeros((0, n, r1))              # C·U − M
        self._masks = np.zeros((0, n), dtype=bool)    # S
        self._au = np.zeros((0, r1))                  # A·U
        self._reach = np.ones(n, dtype=bool)          # R (:meth:`_set_reach`)
        self._reach_known = False
        self._reach_index = np.zeros(0, dtype=int)
        self._h_reach: np.ndarray | None = None       # (C_RR)⁻¹
        self._hm_reach = np.zeros((0, 0))
        self._c_beyond = np.zeros((0, 0))

    @property
    def inverse(self) -> np.ndarray:
        """H = C⁻¹, 1/(mm/MPa)."""
        if self._inverse is None:
            self._inverse = influence_inverse(self.influence)
        return self._inverse

    def solve(self, coefficients: np.ndarray, load_N: np.ndarray,
              max_iterations: int = 60) -> tuple[np.ndarray, np.ndarray]:
        """Pressures (MPa, (m, n)) and approaches (mm, (m,)) of the contacts g_k = Σ_r c_kr·f_r
        (``coefficients`` (m, r)) under the loads Q_k (N, (m,)).

        Active-set iterations as in :func:`solve_slices` (drop the slices in tension, add the
        penetrating ones, until neither is left), in waves (:data:`WAVE_STRIDES`): every 64th
        contact in the order of load (and then of the coefficients) starts with every slice in
        contact; the others start from the final set of their nearest solved neighbour in that
        order, which is mostly their own, so that few intermediate sets are solved. The start does
        not change the answer, only how soon it is found: the iterations end where the contact
        conditions hold."""
        coef = np.atleast_2d(np.asarray(coefficients, dtype=float))
        q = np.asarray(load_N, dtype=float).reshape(-1)
        m = q.size
        n = self.modes.shape[0]
        p = np.zeros((m, n))
        delta = np.zeros(m)
        active = np.ones((m, n), dtype=bool)
        order = np.lexsort(tuple(coef.T[::-1]) + (q,))
        solved = np.zeros(m, dtype=bool)
        with single_threaded_blas():
            for stride in WAVE_STRIDES:
                wave = np.zeros(m, dtype=bool)
                wave[order[::stride]] = True
                wave[order[-1]] = True
                wave &= ~solved
                if solved.any():                 # start from the nearest solved contact in the order
                    place = np.flatnonzero(solved[order])
                    where = np.flatnonzero(wave[order])
                    k = np.clip(np.searchsorted(place, where), 1, place.size) - 1
                    after = np.minimum(k + 1, place.size - 1)
                    k = np.where(np.abs(place[after] - where) < np.abs(place[k] - where), after, k)
                    active[order[where]] = active[order[place[k]]]
                rows = np.flatnonzero(wave)
                self._iterate(rows, coef, q, active, p, delta, max_iterations)
                solved |= wave
                if not self._reach_known and not solved.all():   # worth it for many contacts only
                    self._set_reach(coef, delta[rows])
        return np.clip(p, 0.0, None), delta

    def _iterate(self, pending, coef, q, active, p, delta, max_iterations) -> None:
        """Active-set iterations of the contacts ``pending`` from their sets in ``active``;
        writes the pressures, approaches and final sets into ``p``, ``delta`` and ``active``."""
        n, r = self.modes.shape
        shapes = self.modes[:, 1:]
        for _ in range(max_iterations):
            if pending.size == 0:
                return
            ids = self._set_ids(active[pending])
            chunk = max(1, _BATCH_ELEMENTS // (2 * n * r))
            for lo in range(0, pending.size, chunk):
                rows = pending[lo:lo + chunk]
                sid = ids[lo:lo + chunk]
                u = self._u[sid]                                               # (b, n, r + 1)
                au = self._au[sid]                                             # A·U, (b, r + 1)
                d = (q[rows] - np.einsum("br,br->b", au[:, 1:], coef[rows])) / au[:, 0]
                v = np.concatenate([d[:, None], coef[rows]], axis=1)[:, :, None]
                p[rows] = (u @ v)[..., 0]
                delta[rows] = d
                gap = (self._gap[sid] @ v)[..., 0]                             # w − s: negative = penetration
                act = active[rows]
                negative = act & (p[rows] < 0.0)
                penetrating = ~act & (gap < -1e-12 * np.maximum(np.abs(d[:, None]), 1e-9))
                new = act & ~negative | penetrating
                empty = ~new.any(axis=1)       # never leave a contact without a slice: keep the most interfering one
                if empty.any():
                    new[empty, np.argmax(coef[rows[empty]] @ shapes.T, axis=1)] = True
                active[rows] = new
            pending = pending[(active[pending] != self._set_masks(ids)).any(axis=1)]
        if pending.size:
            raise RuntimeError(f"slice contact did not settle in {max_iterations} active-set iterations")

    def _set_masks(self, ids: np.ndarray) -> np.ndarray:
        """The active sets of the given set numbers, (len(ids), n) bool."""
        return self._masks[ids]

    def _set_ids(self, act: np.ndarray) -> np.ndarray:
        """The number of every row's active set, solving the sets not seen yet (:meth:`_solve_sets`)."""
        packed = np.ascontiguousarray(np.packbits(act, axis=1))
        keys = [row.tobytes() for row in packed]
        new: dict[bytes, int] = {}
        for k, key in enumerate(keys):
            if key not in self._sets and key not in new:
                new[key] = k
        if new:
            first = np.fromiter(new.values(), dtype=int, count=len(new))
            start = self._count
            self._solve_sets(act[first])
            for j, key in enumerate(new):
                self._sets[key] = start + j
        return np.fromiter((self._sets[key] for key in keys), dtype=int, count=len(keys))

    def _set_reach(self, coef: np.ndarray, delta: np.ndarray) -> None:
        """The slices R that a contact of this solver may touch, and (C_RR)⁻¹: those whose
        interference g_j comes within twice the largest approach of the first wave (which holds
        the heaviest contact) of the surface, for some contact of the call. A slice beyond it is out
        of contact in every set met so far; its gap is checked like any other, so that a set
        reaching past R is still solved, through all of C⁻¹ (:meth:`_solve_sets`)."""
        g = coef @ self.modes[:, 1:].T
        reach = g.max(axis=0, initial=-np.inf) + 2.0 * max(float(np.max(delta, initial=0.0)), 0.0) > 0.0
        self._reach = reach
        self._reach_known = True
        if reach.all() or not reach.any():
            return
        index = np.flatnonzero(reach)
        self._reach_index = index
        beyond = np.flatnonzero(~reach)
        h = self.inverse                                   # (C_RR)⁻¹ = H_RR − H_RT·H_TT⁻¹·H_TR
        self._h_reach = h[np.ix_(index, index)] - h[np.ix_(index, beyond)] @ np.linalg.solve(
            h[np.ix_(beyond, beyond)], h[np.ix_(beyond, index)])
        self._hm_reach = self._h_reach @ self.modes[index]
        self._c_beyond = self.influence[~reach]

    def _solve_sets(self, masks: np.ndarray) -> None:
        """U and C·U − M of the active sets ``masks`` (s, n), appended in their order: batches of
        the sets with the same system and number of unknowns k: C_SS (k = |S|), the block inverse
        of (C_RR)⁻¹ when S lies within the reach R (k = |R \\ S|) or of C⁻¹ (k = |I|), whichever
        has the fewest."""
        s_count, n = masks.shape
        size = masks.sum(axis=1)
        method = np.zeros(s_count, dtype=int)                 # 0: C_SS; 1: C⁻¹; 2: (C_RR)⁻¹
        unknowns = size.copy()
        outside = n - size
        use = outside < unknowns
        method[use], unknowns[use] = 1, outside[use]
        if self._h_reach is not None:
            within = ~(masks & ~self._reach).any(axis=1)
            rest = self._reach_index.size - size
            use = within & (rest < unknowns)
            method[use], unknowns[use] = 2, rest[use]
        r = self.modes.shape[1]
        u_all = np.zeros((s_count, n, r))
        gap_all = np.zeros((s_count, n, r))
        key = method * (n + 1) + unknowns
        for kk in np.unique(key):
            rows = np.flatnonzero(key == kk)
            how, k = divmod(int(kk), n + 1)
            batch = max(1, _BATCH_ELEMENTS // max(k * k, k * n, n * r))
            for lo in range(0, rows.size, batch):
                part = rows[lo:lo + batch]
                if how == 0:
                    u_all[part], gap_all[part] = self._direct(masks[part], k)
                elif how == 1:
                    u_all[part], gap_all[part] = self._through_inverse(masks[part], k)
                else:
                    u_all[part], gap_all[part] = self._through_reach(masks[part], k)
        end = self._count + s_count
        if end > self._u.shape[0]:                    # grow the stores (doubling)
            size = max(end, 2 * self._u.shape[0], 64)
            for name in ("_u", "_gap", "_masks", "_au"):
                old = getattr(self, name)
                grown = np.zeros((size,) + old.shape[1:], dtype=old.dtype)
                grown[:self._count] = old[:self._count]
                setattr(self, name, grown)
        self._u[self._count:end] = u_all
        self._gap[self._count:end] = gap_all
        self._masks[self._count:end] = masks
        self._au[self._count:end] = self.area @ u_all
        self._count = end

    def _direct(self, mask: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
        """U and C·U − M of sets of k slices in contact: U_S = C_SS⁻¹·M_S."""
        m, n = mask.shape
        c, modes = self.influence, self.modes
        at = np.arange(m)[:, None]
        s = np.nonzero(mask)[1].reshape(m, k)
        u_s = np.linalg.solve(c[s[:, :, None], s[:, None, :]], modes[s])         # (m, k, r + 1)
        u = np.zeros((m, n, modes.shape[1]))
        u[at, s] = u_s
        gap = c[:, s].transpose(1, 0, 2) @ u_s - modes[None]
        gap[at, s] = 0.0                                                        # C_SS·U_S = M_S
        return u, gap

    def _through_inverse(self, mask: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
        """U and C·U − M of sets with k slices out of contact (I): U = (H − H_:I·H_II⁻¹·H_I:)·M'
        with M' = M zero on I, i.e. Y = H·M − H_:I·M_I, U = Y − H_:I·H_II⁻¹·Y_I."""
        m, n = mask.shape
        if self._hm is None:
            self._hm = self.inverse @ self.modes
        u = _block_inverse_solve(self.inverse, self._hm, self.modes, mask, k)
        gap = np.zeros_like(u)
        if k:
            at = np.arange(m)[:, None]
            i = np.nonzero(~mask)[1].reshape(m, k)
            gap[at, i] = self.influence[i] @ u - self.modes[i]                  # C_IS·U_S − M_I
        return u, gap

    def _through_reach(self, mask: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_through_inverse` within the reach R: the block inverse of (C_RR)⁻¹ with the k
        slices of R out of contact; the gaps beyond R from their rows of C."""
        m, n = mask.shape
        index = self._reach_index
        modes = self.modes
        assert self._h_reach is not None              # only sets within a reach come here
        u = np.zeros((m, n, modes.shape[1]))
        local = mask[:, index]
        u[:, index] = _block_inverse_solve(self._h_reach, self._hm_reach, modes[index], local, k)
        gap = np.zeros_like(u)
        if k:
            at = np.arange(m)[:, None]
            i = index[np.nonzero(~local)[1].reshape(m, k)]
            gap[at, i] = self.influence[i] @ u - modes[i]
        gap[:, ~self._reach] = self._c_beyond @ u - modes[~self._reach]
        return u, gap


def _block_inverse_solve(h: np.ndarray, hm: np.ndarray, modes: np.ndarray, mask: np.ndarray, k: int) -> np.ndarray:
    """U = C_SS⁻¹·M_S (zero on I) for sets with k slices out of contact, from H = C⁻¹ and H·M:
    C_SS⁻¹ = H_SS − H_SI·H_II⁻¹·H_IS, so with Y = H·M − H_:I·M_I (H applied to M zero on I),
    U = Y − H_:I·H_II⁻¹·Y_I, (m, n, r + 1)."""
    m, n = mask.shape
    if k == 0:
        return np.broadcast_to(hm, (m,) + hm.shape).copy()
    at = np.arange(m)[:, None]
    i = np.nonzero(~mask)[1].reshape(m, k)
    h_i = h[:, i].transpose(1, 0, 2)                                               # (m, n, k): H_:I
    y = hm[None] - h_i @ modes[i]
    z = np.linalg.solve(h[i[:, :, None], i[:, None, :]], y[at, i])
    u = y - h_i @ z
    u[at, i] = 0.0
    return u
