"""The disc mesh: linear triangles, the named boundary loops and the element quality."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rvfem.errors import MeshError

QUALITY_MEASURE = "minSICN"
"""Gmsh's element quality reported as :attr:`DiscMesh.min_quality`: the minimal signed inverse
condition number (1 for an equilateral triangle, 0 for a degenerate one, < 0 inverted)."""


@dataclass(frozen=True, eq=False)
class DiscMesh:
    """A linear triangle mesh of the disc.

    Attributes
    ----------
    points : ndarray (n, 2) float64, C-contiguous
        Node coordinates, mm (disc frame).
    triangles : ndarray (m, 3) int64, C-contiguous
        Node indices, counter-clockwise.
    boundaries : dict[str, ndarray (k, 2)]
        Boundary name → edges (node index pairs) ordered along the closed curve so that
        ``edges[i, 1] == edges[i + 1, 0]`` and the last edge ends where the first starts. The
        disc lies on the left of every loop: the profile runs counter-clockwise, the holes
        clockwise.
    path : Path
        The ``.msh`` file (Gmsh 4.1 format).
    min_quality : float
        Smallest element quality, measured as :data:`quality_measure`.
    quality_measure : str
        ``"minSICN"`` (Gmsh's minimal signed inverse condition number).
    from_cache : bool
        True if the mesh was read from an existing file rather than generated.
    symmetry : int
        N if the mesh was built from one 360°/N sector, else 1. The mesh is then exactly N-fold
        symmetric: ``rotation_permutation(points, N)`` maps it onto itself (nodes, triangles,
        ``profile`` onto ``profile``, the central hole onto itself, every bore onto a bore and every
        hole onto a hole: ``bore_i`` onto ``bore_{i+1}`` for cranks numbered counter-clockwise).
    """

    points: np.ndarray = field(repr=False)
    triangles: np.ndarray = field(repr=False)
    boundaries: dict = field(repr=False)
    path: Path
    min_quality: float
    quality_measure: str = QUALITY_MEASURE
    from_cache: bool = False
    symmetry: int = 1

    @property
    def n_nodes(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.triangles.shape[0])

    @property
    def area(self) -> float:
        """Sum of the triangle areas, mm²."""
        p = self.points[self.triangles]
        a = p[:, 1] - p[:, 0]
        b = p[:, 2] - p[:, 0]
        return float(0.5 * np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]))

    def boundary_nodes(self, name: str) -> np.ndarray:
        """Node indices of a named boundary in order along the curve (each node once)."""
        try:
            return self.boundaries[name][:, 0].copy()
        except KeyError:
            raise MeshError(f"no boundary named {name!r}; the mesh has {sorted(self.boundaries)}") from None
