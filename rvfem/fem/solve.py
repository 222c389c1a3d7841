"""Solving with the disc's stiffness: factorisation on a minimal support, rigid-body modes.

Floating body
-------------
The disc is held only by contact and roller springs, so the bare ``K`` is singular (three rigid-body
modes). :func:`factorize` removes a minimal, statically determinate set of three DOFs (x and y of
one vertex, and the DOF of a far vertex perpendicular to the line joining them). For a
self-equilibrated load this changes the displacement only by a rigid-body motion (and the stresses
not at all); the contact solver carries the rigid motion as explicit unknowns
(:func:`rigid_body_modes`). Why this is exact, and how the condensed contact problem uses it, is
derived in docs/theory.md ("The condensed contact problem").

The sparse direct solver is chosen by measurement (``benchmarks/bench_factorization.py``):
CHOLMOD through scikit-sparse when installed, else CHOLMOD through cholespy (a dependency: its
wheels carry CHOLMOD), else PARDISO (pypardiso) when installed, else scipy's SuperLU in symmetric
mode.

References
----------
.. [1] O. C. Zienkiewicz, R. L. Taylor, J. Z. Zhu, *The Finite Element Method: Its Basis and
   Fundamentals*, 7th ed., Butterworth-Heinemann, 2013 (rigid-body modes, statically determinate
   supports).
.. [2] X. S. Li, J. W. Demmel, J. R. Gilbert et al., *SuperLU Users' Guide*, § 2.9 (symmetric mode).
"""

from __future__ import annotations

import atexit
import functools
import importlib.util
import logging
import time
import weakref
from dataclasses import dataclass, field
from typing import Callable, Literal

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rvfem._arrays import readonly as _readonly
from rvfem.fem.model import FEModel

__all__ = [
    "SOLVER_PREFERENCE",
    "available_solvers",
    "default_support",
    "Factorization",
    "factorize",
    "factorize_matrix",
    "rigid_body_modes",
    "remove_rigid_motion",
]

logger = logging.getLogger(__name__)


#: Order in which ``solver="auto"`` tries the backends, by measurement: fastest first at
#: back-substituting many columns (benchmarks/README.md, "Sparse solvers").
SOLVER_PREFERENCE: tuple[str, ...] = ("cholmod", "cholespy", "pardiso", "superlu")


def available_solvers() -> tuple[str, ...]:
    """Sparse direct solvers importable here, in :data:`SOLVER_PREFERENCE` order.

    ``"superlu"`` (scipy) is always available and ``"cholespy"`` is a dependency of rvfem (it
    may still be missing where it has no wheels); ``"cholmod"`` needs scikit-sparse and
    ``"pardiso"`` needs pypardiso (Intel MKL), neither of which is a dependency.
    """
    found = []
    for name in SOLVER_PREFERENCE:
        if name == "superlu":
            found.append(name)
        elif name == "cholmod" and importlib.util.find_spec("sksparse") is not None:
            found.append(name)
        elif name == "cholespy" and importlib.util.find_spec("cholespy") is not None:
            found.append(name)
        elif name == "pardiso" and importlib.util.find_spec("pypardiso") is not None:
            found.append(name)
    return tuple(found)


#: SuperLU's supernode relaxation and panel size (``relax``, ``panel_size`` of
#: :func:`scipy.sparse.linalg.splu`; SuperLU user guide § 2.11.1, ``sp_ienv``). SciPy's defaults are
#: 10 and 20; on the default fan-hole disc 2 and 8 factorise and back-substitute faster
#: (benchmarks/README.md, "Sparse solvers"); the factor has the same nonzeros, the solutions
#: differ by round-off (≤ 2e-12 relative). Keep both
#: small: SciPy 1.17's SuperLU corrupts its heap with a panel size of 24.
SUPERLU_RELAX = 2
SUPERLU_PANEL_SIZE = 8


def _factor_superlu(a: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
    # Symmetric positive definite: a symmetric fill-reducing ordering on A + A^T and no
    # numerical pivoting keep SuperLU's fill close to a Cholesky factor's (SuperLU user guide,
    # § 2.9, "symmetric mode").
    lu = spla.splu(
        a,
        permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
        relax=SUPERLU_RELAX,
        panel_size=SUPERLU_PANEL_SIZE,
    )
    return lu.solve


def _factor_cholmod(a: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
    from sksparse.cholmod import cholesky  # optional

    factor = cholesky(a)
    return factor


class _CholespyFactor:
    """CHOLMOD (its own choice of ordering and of a supernodal or simplicial factor) as wrapped by
    cholespy, which ships wheels with CHOLMOD, METIS and a reference BLAS; called with
    right-hand sides, it solves (C-ordered ones: :data:`_C_ORDER`; the solve holds the GIL).

    CHOLMOD reads the lower triangle only (stype −1), which is all it is given
    (:data:`_LOWER_TRIANGLE`), as a CSR matrix: cholespy converts it into CSC arrays of its own,
    which it then sorts and resizes in place (given CSC arrays, it would do so to NumPy's
    buffers). Factors are dropped at interpreter exit (:func:`_drop_cholespy_factors`): nanobind,
    which cholespy is built with, reports every instance still alive when its module is torn down
    as a leak, which factors held by lingering objects (a notebook's results) would be.
    """

    alive: weakref.WeakSet = weakref.WeakSet()

    def __init__(self, lower: sp.csr_matrix):
        from cholespy import CholeskySolverD, MatrixType  # optional

        self.factor = CholeskySolverD(lower.shape[0], lower.indptr.astype(np.int32),
                                      lower.indices.astype(np.int32), lower.data, MatrixType.CSR)
        _CholespyFactor.alive.add(self)

    def __call__(self, b: np.ndarray) -> np.ndarray:
        b = np.ascontiguousarray(b, dtype=np.float64)
        x = np.empty_like(b)
        self.factor.solve(b, x)
        return x


@atexit.register
def _drop_cholespy_factors() -> None:
    for holder in list(_CholespyFactor.alive):
        holder.factor = None


def _factor_pardiso(a: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
    import pypardiso  # optional

    solver = pypardiso.PyPardisoSolver(mtype=2)  # real symmetric positive definite
    upper = sp.triu(a, format="csr")
    upper.sort_indices()
    solver.factorize(upper)

    def solve(b: np.ndarray) -> np.ndarray:
        return solver.solve(upper, np.asarray(b, dtype=np.float64))

    return solve


#: Backends whose solve holds the GIL: their back-substitutions gain nothing from threads.
_SERIAL_SOLVES = frozenset({"cholespy"})
#: Backends given the lower triangle of the stiffness only (as a CSR matrix).
_LOWER_TRIANGLE = frozenset({"cholespy"})
#: Backends that take C-ordered right-hand sides (the others Fortran-ordered ones).
_C_ORDER = frozenset({"cholespy"})
#: Right-hand sides per call, by backend (see :class:`Factorization`); 16 for the others.
_SOLVE_BATCH = {"cholespy": 8}

_FACTORIZERS: dict[str, Callable[[sp.csc_matrix], Callable[[np.ndarray], np.ndarray]]] = {"superlu": _factor_superlu, "cholmod": _factor_cholmod, "cholespy": _CholespyFactor,
                "pardiso": _factor_pardiso}


@dataclass(frozen=True, eq=False)
class Factorization:
    """A factorised stiffness with a minimal support, ready for many right-hand sides.

    Attributes
    ----------
    solver : str
        Backend used ("cholmod", "cholespy", "pardiso" or "superlu").
    support_dofs : numpy.ndarray
        ``(3,)`` (or user-given) DOFs held at zero displacement.
    free_dofs : numpy.ndarray
        All other DOFs.
    n_dofs : int
    factor_seconds : float
        Wall time of the factorisation, s.
    concurrent : bool
        Whether back-substitutions on several threads run at once (SuperLU releases the GIL;
        cholespy holds it, so threads would only take turns).
    batch : int
        Right-hand sides per back-substitution call that cost least per column (measured on the
        default fan-hole disc, 38k DOFs: SuperLU 16; cholespy 8, whose reference-BLAS
        solve slows down once the block of right-hand sides leaves the cache; benchmarks/README.md,
        "Sparse solvers").
    """

    solver: str
    support_dofs: np.ndarray
    free_dofs: np.ndarray
    n_dofs: int
    factor_seconds: float
    concurrent: bool
    batch: int
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
        b = rhs.toarray() if sp.issparse(rhs) else np.asarray(rhs, dtype=np.float64)  # type: ignore[union-attr]  # issparse narrows to a sparse matrix, unseen by mypy
        if b.shape[0] != self.n_dofs or b.ndim > 2:
            raise ValueError(f"rhs must have shape ({self.n_dofs},) or ({self.n_dofs}, m), got {b.shape}")
        u = np.zeros(b.shape)
        if b.ndim == 2 and b.shape[1] == 0:
            return u
        # the free DOFs are a few contiguous runs between the support DOFs: copied run by run
        # (fancy indexing of a block of right-hand sides costs as much as a quarter of its solve)
        runs = self._free_runs
        order: Literal["C", "F"] = "C" if self.solver in _C_ORDER else "F"     # the backend's own layout: no copies
        free = np.empty((len(self.free_dofs),) + b.shape[1:], order=order)
        for (lo, hi), at in runs:
            free[at:at + hi - lo] = b[lo:hi]
        x = self.solve_free(free)
        for (lo, hi), at in runs:
            u[lo:hi] = x[at:at + hi - lo]
        return u

    def solve_free(self, b_free: np.ndarray) -> np.ndarray:
        """``K_ff⁻¹ b_free`` on the free DOFs alone (``(len(free_dofs),)`` or ``(len(free_dofs), m)``),
        without the copies into and out of the whole DOF numbering that :meth:`solve` makes."""
        order: Literal["C", "F"] = "C" if self.solver in _C_ORDER else "F"
        b = np.asarray(b_free, dtype=np.float64, order=order)
        return np.asarray(self._solve(b)).reshape(b.shape)

    @functools.cached_property
    def _free_runs(self) -> tuple[tuple[tuple[int, int], int], ...]:
        """((first, end), position in the free DOFs) of every run of consecutive free DOFs."""
        f = np.asarray(self.free_dofs)
        breaks = np.flatnonzero(np.diff(f) != 1) + 1
        starts = np.concatenate([[0], breaks])
        ends = np.concatenate([breaks, [len(f)]])
        return tuple(((int(f[a]), int(f[e - 1]) + 1), int(a)) for a, e in zip(starts, ends) if e > a)


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


def _submatrix(stiffness: sp.spmatrix, keep: np.ndarray, lower: bool = False) -> sp.spmatrix:
    """``stiffness[keep][:, keep]`` of a symmetric matrix with sorted indices, in one pass over the
    entries (fancy indexing copies the whole matrix twice; for the P2 disc that is 100 MB).

    The whole matrix comes as CSC: the rows of the CSR form taken as the columns, which gives the
    transpose, the same matrix as the stiffness is symmetric (tests/fem/test_fem.py). With ``lower``
    only its lower triangle comes, as CSR.
    """
    k = sp.csr_matrix(stiffness)
    k.sort_indices()
    n = k.shape[0]
    kept = np.zeros(n, dtype=bool)
    kept[keep] = True
    number = np.cumsum(kept, dtype=np.int32) - 1            # new index of a kept DOF
    row = np.repeat(np.arange(n, dtype=np.int32), np.diff(k.indptr))
    entry = kept[k.indices] & kept[row]
    if lower:
        entry &= k.indices <= row       # column ≤ row
    counts = np.bincount(row[entry], minlength=n)[kept]
    del row
    indptr = np.concatenate([[0], np.cumsum(counts)])
    shape = (int(kept.sum()),) * 2
    form = sp.csr_matrix if lower else sp.csc_matrix
    sub = form((k.data[entry], number[k.indices[entry]], indptr), shape=shape)
    sub.has_sorted_indices = True                         # kept entries stay in order
    return sub


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
    solver : {"auto", "cholmod", "cholespy", "pardiso", "superlu"}
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
    k = _submatrix(stiffness, free, lower=solver in _LOWER_TRIANGLE)
    t0 = time.perf_counter()
    solve = _FACTORIZERS[solver](k)
    dt = time.perf_counter() - t0
    logger.info("factorised %d DOFs (nnz %d) with %s in %.3f s", k.shape[0], k.nnz, solver, dt)
    return Factorization(solver, _readonly(sup), _readonly(free), int(n), dt, solver not in _SERIAL_SOLVES,
                         _SOLVE_BATCH.get(solver, 16), solve)


def factorize(model: FEModel, support_dofs: np.ndarray | None = None, solver: str = "auto") -> Factorization:
    """Factorise the model's stiffness on a minimal support (floating-body trick).

    Parameters
    ----------
    model : FEModel
    support_dofs : array_like of int, optional
        DOFs held at zero; default :func:`default_support` (three DOFs, statically determinate).
    solver : {"auto", "cholmod", "cholespy", "pardiso", "superlu"}
        See :func:`factorize_matrix`.

    Returns
    -------
    Factorization
    """
    sup = default_support(model) if support_dofs is None else support_dofs
    return factorize_matrix(model.stiffness, sup, solver)


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
