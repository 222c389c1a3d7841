"""Small array utilities shared by the modules: read-only arrays, the first of equal maxima, the
ordering of mesh edges, points in a polygon, giving freed memory back and single-threaded BLAS for
small systems."""

from __future__ import annotations

import ctypes
import functools

import numpy as np
from threadpoolctl import ThreadpoolController

from rvfem.errors import MeshError


def readonly(a, dtype=None) -> np.ndarray:
    """A C-contiguous, write-protected copy or view of ``a`` (for arrays held by frozen dataclasses)."""
    a = np.ascontiguousarray(a, dtype=dtype)
    a.setflags(write=False)
    return a


def release_freed_memory() -> None:
    """Give the free pages of the C heap back to the system (glibc's ``malloc_trim(0)``, see
    malloc_trim(3)); nothing elsewhere.

    Freed NumPy temporaries of up to 32 MiB stay in glibc's heap, resident, until reused (the
    allocator raises its mmap threshold to the size of freed mmapped blocks). After the P2
    assembly and factorisation that is about 90 MB of the default disc's run, at the time its
    peak is reached; the call takes a few milliseconds and changes no state.
    """

    try:
        ctypes.CDLL(None).malloc_trim(0)       # the C library already loaded into the process
    except (OSError, AttributeError, TypeError):  # not glibc (or no dlopen of the process)
        pass


TIE_RTOL = 1e-9
"""Values within this fraction of the largest count as equal to it (:func:`near_max`)."""


def near_max(a, rtol: float = TIE_RTOL) -> np.ndarray:
    """Flat indices (C order) of the entries of ``a`` within ``rtol`` of its largest: on a
    symmetric disc the maxima of a load cycle come in equal copies (bearing i at θ, bearing i + 1
    at θ + 360°/N) that differ by round-off only, and the choice among them must not depend on
    it."""
    a = np.asarray(a, dtype=float)
    top = float(np.max(a))
    return np.flatnonzero(a.ravel() >= top - rtol * abs(top))


def first_max(a, rtol: float = TIE_RTOL) -> tuple[int, ...]:
    """Index of the first largest entry of ``a`` (C order) among those within ``rtol`` of the
    largest (:func:`near_max`)."""
    a = np.asarray(a, dtype=float)
    flat = int(near_max(a, rtol)[0])
    return tuple(int(i) for i in np.unravel_index(flat, a.shape))


def max_load_index(bearing_forces: np.ndarray) -> tuple[int, int]:
    """Angle index and bearing index of the largest bearing load |F| of a cycle (the first of
    equal ones, :func:`first_max`).

    Parameters
    ----------
    bearing_forces : ndarray (n, N, 2)

    Returns
    -------
    (int, int)
    """
    k, i = first_max(np.linalg.norm(bearing_forces, axis=2))
    return int(k), int(i)


def chain_edges(edges) -> tuple[tuple[np.ndarray, bool], ...]:
    """Order undirected edges into connected chains of vertices.

    Parameters
    ----------
    edges : array_like of int
        ``(k, 2)`` vertex pairs, any order and orientation; repeated edges count once.

    Returns
    -------
    tuple of (numpy.ndarray, bool)
        One ``(vertices, closed)`` pair per connected component, sorted by their smallest vertex.
        A closed chain (a loop) starts and ends at its smallest vertex (``vertices[0] ==
        vertices[-1]``) and runs first towards the smaller of that vertex's two neighbours; an
        open chain runs from its end with the smaller index to the other end. The direction is
        therefore a convention: callers orient the chains (body on the left, say) themselves.

    Raises
    ------
    MeshError
        If three or more edges meet at a vertex (the edges do not form simple curves).
    """
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    e = np.unique(np.sort(e, axis=1), axis=0)
    e = e[e[:, 0] != e[:, 1]]
    neighbours: dict[int, list[int]] = {}
    for a, b in e.tolist():
        neighbours.setdefault(a, []).append(b)
        neighbours.setdefault(b, []).append(a)
    branching = [v for v, n in neighbours.items() if len(n) > 2]
    if branching:
        raise MeshError(f"boundary branches at vertex {min(branching)} ({len(neighbours[min(branching)])} edges meet)")
    chains = []
    unvisited = set(neighbours)
    while unvisited:
        first = min(unvisited)
        ends = [v for v in _component(neighbours, first) if len(neighbours[v]) == 1]
        start = min(ends) if ends else first
        seq = [start]
        prev, cur = None, start
        while True:
            nxt = [v for v in sorted(neighbours[cur]) if v != prev]
            if not nxt:                                   # the other end of an open chain
                break
            prev, cur = cur, nxt[0]
            seq.append(cur)
            if cur == start:                              # once round a loop
                break
        unvisited.difference_update(seq)
        chains.append((np.asarray(seq, dtype=np.int64), bool(not ends)))
    return tuple(chains)


def _component(neighbours: dict[int, list[int]], start: int) -> set[int]:
    """Vertices connected to ``start``."""
    seen, todo = {start}, [start]
    while todo:
        for w in neighbours[todo.pop()]:
            if w not in seen:
                seen.add(w)
                todo.append(w)
    return seen


@functools.lru_cache(maxsize=1)
def _blas_libraries() -> ThreadpoolController:
    """The process's BLAS libraries, found once: reading the process's memory map takes about
    2 ms, as long as a small contact solve."""
    return ThreadpoolController()


def single_threaded_blas():
    """A context in which BLAS runs on one thread.

    For the many small dense systems of the contact solves (about 100 unknowns) and the roller
    slices: threaded BLAS only contends for the cores there (two BLAS threads on two cores ran a
    load cycle's per-angle solves 7× slower and a hysteresis loop's 2-4× slower than one;
    benchmarks/README.md, "Load cycle"). Nested uses are cheap.
    """
    return _blas_libraries().limit(limits=1, user_api="blas")


def points_in_polygon(points: np.ndarray, vertices: np.ndarray, bins: int = 64) -> np.ndarray:
    """Which of ``points`` (m, 2) lie inside the closed polygon ``vertices`` (n, 2), by the
    even-odd rule: a horizontal ray from the point crosses the polygon's edges an odd number of
    times (a point on an edge may count either way).

    The points are sorted into ``bins`` horizontal bands, and each band's points are tested
    against the edges that reach into it only (vectorised per band): a profile of 10⁴ edges
    against 10³ points costs a few milliseconds.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    v = np.asarray(vertices, dtype=float)
    a, b = v, np.roll(v, -1, axis=0)
    inside = np.zeros(len(p), dtype=bool)
    if len(p) == 0 or len(v) < 3:
        return inside
    lo, hi = np.minimum(a[:, 1], b[:, 1]), np.maximum(a[:, 1], b[:, 1])
    y0, y1 = float(v[:, 1].min()), float(v[:, 1].max())
    width = (y1 - y0) / bins or 1.0
    band = np.clip(((p[:, 1] - y0) // width).astype(int), -1, bins)
    for k in np.unique(band):
        if k < 0 or k >= bins:
            continue                                      # above or below every edge: outside
        at = np.flatnonzero(band == k)
        e = np.flatnonzero((hi >= y0 + k * width) & (lo <= y0 + (k + 1) * width))
        x, y = p[at, :1], p[at, 1:]
        ea, eb = a[e], b[e]
        straddles = (ea[:, 1] > y) != (eb[:, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            cross = ea[:, 0] + (y - ea[:, 1]) * (eb[:, 0] - ea[:, 0]) / (eb[:, 1] - ea[:, 1])
        inside[at] = np.count_nonzero(straddles & (x < cross), axis=1) % 2 == 1
    return inside
