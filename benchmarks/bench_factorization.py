"""Benchmark: stiffness assembly, factorisation and back-substitution per sparse solver.

Measures, on a disc-like annulus (inner radius 20 mm, outer 90 mm, unstructured Gmsh mesh of
about 15 000 vertices), for P1 and P2 elements:

* assembly of the plane-stress stiffness (:func:`rvfem.fem.build_model`),
* factorisation of the stiffness on the 3-DOF floating-body support,
* back-substitution of 1, 100 and 1000 right-hand-side columns,

for every solver that can be imported here:

``superlu``         scipy SuperLU, symmetric mode, MMD on AᵀA+A, no pivoting (rvfem's fallback)
``superlu-colamd``  scipy ``splu`` with its defaults (COLAMD, partial pivoting)
``factorized``      ``scipy.sparse.linalg.factorized`` (UMFPACK if scikit-umfpack is installed,
                    else SuperLU with defaults)
``cholmod``         CHOLMOD supernodal Cholesky via scikit-sparse (optional)
``pardiso``         Intel MKL PARDISO via pypardiso, SPD mode (optional)

Run with ``python benchmarks/bench_factorization.py [--nodes 15000] [--orders 1 2]``. Times are
wall-clock seconds (best of ``--repeat`` for single right-hand sides). The 1000-column solve runs
in blocks of ``--block`` columns to bound memory; the relative residual ‖K u − f‖/‖f‖ of a
single solve is printed as a sanity check.

Results (2-core x86-64 VM, 24 GB, Python 3.11, scipy 1.17.1, scikit-sparse 0.4.16 built from
source against Debian's SuiteSparse 5.12, pypardiso 0.4.7 with MKL 2026.2; 15 355 vertices,
30 202 triangles; seconds)::

    elem solver             DOFs    nnz(K)  assemble   factor    1 rhs  100 rhs  1000 rhs
    P1   cholmod           30710    425876     0.355    0.323   0.0043    0.363     3.772
    P1   pardiso           30710    425876     0.355    0.534   0.0051    0.615     5.064
    P1   superlu           30710    425876     0.355    0.247   0.0048    0.897     7.145
    P1   superlu-colamd    30710    425876     0.355    0.366   0.0098    0.396     6.934
    P1   factorized        30710    425876     0.355    0.368   0.0105    0.980     9.635
    P2   cholmod          121824   2786362     1.348    1.980   0.0337    2.173    23.856
    P2   pardiso          121824   2786362     1.348    1.088   0.1800    2.056    29.463
    P2   superlu          121824   2786362     1.348    2.632   0.0511   10.900    64.947
    P2   superlu-colamd   121824   2786362     1.348    6.059   0.0629    9.610   105.724
    P2   factorized       121824   2786362     1.348    4.464   0.0629    6.872    79.206

Later, with cholespy installed (CHOLMOD with METIS and a reference BLAS, from wheels: rvfem's
dependency for this reason) and neither scikit-sparse nor pypardiso, same machine and mesh, each
of rvfem's backends given what :func:`rvfem.fem.factorize_matrix` gives it (cholespy the lower
triangle and C-ordered right-hand sides)::

    elem solver             DOFs    nnz(K)  assemble   factor    1 rhs  100 rhs  1000 rhs
    P1   cholespy          30710    425876     0.106    0.168   0.0020    0.143     1.142
    P1   superlu           30710    425876     0.106    0.173   0.0040    0.230     2.689
    P2   cholespy         121824   2786708     0.276    1.419   0.0209    1.059    10.284
    P2   superlu          121824   2786708     0.276    1.354   0.0339    1.313    15.951

(blocks of 250 right-hand sides; cholespy is fastest at 8 per call, 0.8 ms a P1 column of the
default disc, see :data:`rvfem.fem.solve._SOLVE_BATCH`). cholespy's solve holds the interpreter,
so it gains nothing from threads; it still back-substitutes P1 columns 2.4x faster than SuperLU
(P2 1.6x) and its P2 factor takes 89 MB against SuperLU's 147 MB. Residuals up to 1.4e-12
(cholespy, P2).

In the first table all residuals were below 1e-12. Conclusions: CHOLMOD is the fastest for many right-hand sides
(about 2x SuperLU for P1, 2.7x for P2) but scikit-sparse ships no wheels and needs SuiteSparse
headers to build (0.5.0 does not build against SuiteSparse 5.12 at all), so it cannot be a
dependency. pypardiso installs from wheels but pulls in about 1 GB of MKL and only wins for P2;
not a dependency either. Both are used automatically when installed
(:data:`rvfem.fem.SOLVER_PREFERENCE`). Without them, SuperLU in symmetric mode with an MMD
ordering on AᵀA+A is the fallback: it factorises fastest of all for P1, and for P2 it beats
SuperLU's default COLAMD ordering 2.3x in factorisation and 1.6x in back-substitution. Back-substitution is memory-bound (SuperLU's factor has 4.3 M nonzeros for
P1, 22.6 M for P2), about 6 ms (P1) and 55 ms (P2) per column whatever the batch size.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import sys
import time
from pathlib import Path
from typing import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rvfem import fem  # noqa: E402
from rvfem.fem.solve import _C_ORDER, _FACTORIZERS, _LOWER_TRIANGLE, _submatrix  # noqa: E402


def annulus_mesh(n_vertices: int, r_in: float = 20.0, r_out: float = 90.0) -> tuple[np.ndarray, np.ndarray]:
    """Unstructured triangle mesh of an annulus with roughly ``n_vertices`` vertices (Gmsh)."""
    import gmsh

    area = math.pi * (r_out**2 - r_in**2)
    h = math.sqrt(2.0 / math.sqrt(3.0) * area / n_vertices)
    gmsh.initialize(["-noenv"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("annulus")
        outer = gmsh.model.occ.addDisk(0, 0, 0, r_out, r_out)
        inner = gmsh.model.occ.addDisk(0, 0, 0, r_in, r_in)
        gmsh.model.occ.cut([(2, outer)], [(2, inner)])
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMin", h)
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        _, _, conn = gmsh.model.mesh.getElements(2)
    finally:
        gmsh.finalize()
    xy = coords.reshape(-1, 3)[:, :2]
    tri = np.asarray(conn[0], dtype=np.int64).reshape(-1, 3)
    lookup = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    lookup[tags.astype(np.int64)] = np.arange(len(tags))
    tri = lookup[tri]
    used = np.unique(tri)
    remap = np.full(len(xy), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return np.ascontiguousarray(xy[used]), remap[tri]


def _superlu_colamd(a: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
    return spla.splu(a).solve


def _factorized(a: sp.csc_matrix) -> Callable[[np.ndarray], np.ndarray]:
    solve = spla.factorized(a)

    def many(b: np.ndarray) -> np.ndarray:
        if b.ndim == 1:
            return solve(b)
        return np.column_stack([solve(b[:, j]) for j in range(b.shape[1])])

    return many


def solvers() -> dict[str, Callable[[sp.csc_matrix], Callable[[np.ndarray], np.ndarray]]]:
    out: dict[str, Callable] = {}
    for name in fem.available_solvers():
        out[name] = _FACTORIZERS[name]
    out["superlu-colamd"] = _superlu_colamd
    out["factorized"] = _factorized
    return out


def bench(order: int, points: np.ndarray, triangles: np.ndarray, repeat: int, block: int) -> list[dict]:
    t0 = time.perf_counter()
    model = fem.build_model(points, triangles, 2.1e5, 0.3, 10.0, order)
    t_asm = time.perf_counter() - t0
    sup = fem.default_support(model)
    free = np.setdiff1d(np.arange(model.n_dofs), sup)
    kff = model.stiffness[free][:, free].tocsc()
    kff.sort_indices()
    n = kff.shape[0]
    rng = np.random.default_rng(0)
    rows = []
    for name, factory in solvers().items():
        # rvfem's own backends get what rvfem gives them (fem.factorize_matrix): the lower
        # triangle where the backend reads only that, right-hand sides in its own layout
        own = name in _FACTORIZERS
        k = _submatrix(model.stiffness, free, lower=name in _LOWER_TRIANGLE) if own else kff
        layout = "C" if own and name in _C_ORDER else "F"
        t0 = time.perf_counter()
        solve = factory(k)
        t_fac = time.perf_counter() - t0
        b1 = rng.standard_normal(n)
        t1 = math.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            x = solve(b1)
            t1 = min(t1, time.perf_counter() - t0)
        res = np.linalg.norm(kff @ np.asarray(x).ravel() - b1) / np.linalg.norm(b1)
        times = {}
        for m in (100, 1000):
            total = 0.0
            for lo in range(0, m, block):
                b = np.asarray(rng.standard_normal((n, min(block, m - lo))), order=layout)
                t0 = time.perf_counter()
                solve(b)
                total += time.perf_counter() - t0
            times[m] = total
        rows.append(
            dict(order=order, solver=name, dofs=model.n_dofs, nnz=model.stiffness.nnz, assembly=t_asm,
                 factor=t_fac, rhs1=t1, rhs100=times[100], rhs1000=times[1000], residual=res)
        )
        print(f"  P{order} {name:15s} done", file=sys.stderr, flush=True)
        del solve
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, default=15000, help="target number of mesh vertices")
    ap.add_argument("--orders", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--block", type=int, default=250)
    args = ap.parse_args(argv)

    points, triangles = annulus_mesh(args.nodes)
    print(f"annulus 20/90 mm: {len(points)} vertices, {len(triangles)} triangles")
    extra = [m for m in ("sksparse", "pypardiso", "scikits.umfpack") if importlib.util.find_spec(m.split(".")[0])]
    print(f"optional solver packages found: {', '.join(extra) or 'none'}")
    rows = []
    for order in args.orders:
        rows += bench(order, points, triangles, args.repeat, args.block)
    head = f"{'elem':4s} {'solver':15s} {'DOFs':>7s} {'nnz(K)':>9s} {'assemble':>9s} {'factor':>8s} " \
           f"{'1 rhs':>8s} {'100 rhs':>8s} {'1000 rhs':>9s} {'residual':>9s}"
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"P{r['order']:<3d} {r['solver']:15s} {r['dofs']:7d} {r['nnz']:9d} {r['assembly']:9.3f} "
              f"{r['factor']:8.3f} {r['rhs1']:8.4f} {r['rhs100']:8.3f} {r['rhs1000']:9.3f} {r['residual']:9.1e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
