"""The column map of a disc's rotation by 2π/N (docs/theory.md § 9a).

On an exactly N-fold symmetric mesh the footprint columns turn into each other by the rotation of the
disc by 2π/N (:func:`column_rotation`); the column compliance then back-substitutes one column of each
orbit only (:class:`rvfem.solve.contact_compliance.Compliance`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from rvfem.solve.contact_interface import Interface


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
    cols_of: list[list[int]] = [[] for _ in range(len(sites))]
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


def column_orbits(Q: sp.csr_matrix, order: int):
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
    site_columns: list[list[int]] = [[] for _ in range(site.max() + 1)]
    for c, s in enumerate(site):
        site_columns[s].append(c)
    members = [np.asarray(m) for m in site_columns]
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
