"""The footprint grids of a disc and the load operator B (:mod:`rvfem.solve.contact`).

Every load that can act on the disc enters through a fixed footprint grid on its boundary: column k
is a unit force (1 N) in direction d_k, spread over the boundary arc around the grid point x_k with
an elliptical (Hertz-like) density of half-width a. Pin contacts use the profile grid (direction:
inward normal of the profile), rollers use a grid on each bore (direction: radially outward from the
bore centre, i.e. into the disc material). A contact between grid points shares its force between
the two neighbouring columns (linear interpolation), so its load and its displacement are
work-conjugate.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rvfem import fem
from rvfem._arrays import readonly as _readonly


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
    spacing : float or None
        When given, the columns sit at equal arc-length steps of about ``spacing`` (mm) instead of
        at the vertices, whatever the mesh: a contact grid that stays the same when the mesh is
        refined (``stride`` is then not used). Their count is a multiple of ``multiple``.
    multiple : int
        With ``spacing``: the column count is rounded to a multiple of it (the mesh's rotation
        symmetry N, so that the equal steps of an N-fold symmetric loop turn into each other).
    """

    name: str
    offset: int
    chain: fem.BoundaryChain
    centre: np.ndarray | None = None
    stride: int = 1
    spacing: float | None = None
    multiple: int = 1

    @property
    def components(self) -> int:
        """Columns per vertex: 1 (radial, bores) or 2 (x and y, profile)."""
        return 1 if self.centre is not None else 2

    @functools.cached_property
    def arcs(self) -> np.ndarray:
        """Arc lengths of the column positions, mm, with the loop length appended."""
        if self.spacing is None:
            return _readonly(np.append(self.chain.s[:-1][::self.stride], self.chain.s[-1]))
        length = float(self.chain.s[-1])
        m = max(1, int(self.multiple))
        n = m * max(1, round(length / (m * float(self.spacing))))
        return _readonly(np.linspace(0.0, length, n + 1))

    @functools.cached_property
    def count(self) -> int:
        """Number of column positions."""
        return len(self.arcs) - 1

    @functools.cached_property
    def polyline(self) -> np.ndarray:
        """Column positions (vertices, or the points at :attr:`arcs`) in loop order, (count, 2), mm."""
        if self.spacing is None:
            return self.chain.points[:-1][::self.stride]
        return _readonly(self.chain.point_at(self.arcs[:-1]))

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
                    stride: dict[str, int] | None = None, *, spacing: dict[str, float] | None = None,
                    multiple: int = 1) -> Interface:
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
    spacing : dict name → float, optional
        Boundaries whose columns sit at equal arc-length steps of about this spacing (mm) instead
        of at the vertices (:class:`FootprintGrid`): a contact grid independent of the mesh.
    multiple : int
        The column count of a ``spacing`` grid is a multiple of it (the mesh's rotation symmetry).
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
                             (stride or {}).get(name, 1), (spacing or {}).get(name), multiple)
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
