"""VTK output for ParaView: one ``.vtu`` per kept crank angle and a ``.pvd`` collection over θ.

Each ``.vtu`` (written with meshio, binary, zlib-compressed) is the disc mesh in its own frame
(z = 0) with

point data (at the mesh vertices)
    ``displacement_mm`` (3 components, z = 0; as solved, includes the disc's rigid-body motion),
    ``deformation_mm`` (the same minus its best-fitting rigid motion: use it with ParaView's
    *Warp By Vector*), ``sxx_MPa``, ``syy_MPa``, ``sxy_MPa`` (vertex values, area-weighted average
    of the adjacent elements), ``von_mises_MPa``, ``s1_MPa``, ``s2_MPa`` (in-plane principal
    stresses, s1 ≥ s2; derived from the averaged components) and ``s1_direction`` (unit vector of
    s1, z = 0);
cell data (one value per triangle)
    the element stresses under the same names (the constant P1 stress, or the P2 stress at the
    centroid).

For P2 models the file holds the linear mesh and the vertex values only (the edge-midpoint nodes
are dropped). The ``.pvd`` lists the files with the crank angle in degrees as the time value, so
ParaView's time controls step through the cycle.
"""

from __future__ import annotations

import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from .postprocess import FieldSnapshot

__all__ = ["POINT_FIELDS", "CELL_FIELDS", "ENVELOPE_FILE", "vtu_name", "write_vtu", "write_pvd", "write_envelope_vtu"]

#: Point-data arrays of every ``.vtu`` (name → number of components).
POINT_FIELDS = {
    "displacement_mm": 3,
    "deformation_mm": 3,
    "sxx_MPa": 1,
    "syy_MPa": 1,
    "sxy_MPa": 1,
    "von_mises_MPa": 1,
    "s1_MPa": 1,
    "s2_MPa": 1,
    "s1_direction": 3,
}

#: Cell-data arrays of every ``.vtu``.
CELL_FIELDS = ("sxx_MPa", "syy_MPa", "sxy_MPa", "von_mises_MPa", "s1_MPa", "s2_MPa")


def vtu_name(theta_deg: float) -> str:
    """File name of the field at crank angle θ (degrees): ``disc_theta_060.00.vtu``."""
    return f"disc_theta_{theta_deg % 360.0:06.2f}.vtu"


def _xyz(a: np.ndarray) -> np.ndarray:
    return np.column_stack([a, np.zeros(len(a))])


def _stress_arrays(state) -> dict[str, np.ndarray]:
    return {
        "sxx_MPa": np.asarray(state.sxx, dtype=float),
        "syy_MPa": np.asarray(state.syy, dtype=float),
        "sxy_MPa": np.asarray(state.sxy, dtype=float),
        "von_mises_MPa": np.asarray(state.von_mises, dtype=float),
        "s1_MPa": np.asarray(state.s1, dtype=float),
        "s2_MPa": np.asarray(state.s2, dtype=float),
    }


def write_vtu(path: str | os.PathLike, points: np.ndarray, triangles: np.ndarray,
              snapshot: FieldSnapshot) -> Path:
    """Write the disc with the fields of one snapshot as a ``.vtu`` file.

    Parameters
    ----------
    path : path-like
    points : ndarray (n_vertices, 2)
        Mesh vertices, mm.
    triangles : ndarray (n_elements, 3)
        Vertex indices, in the element order of the stresses (``model.mesh.t.T``).
    snapshot : FieldSnapshot

    Returns
    -------
    Path
    """
    import meshio

    path = Path(path)
    nodal, element = snapshot.stress.nodal, snapshot.stress.element
    angle = np.asarray(nodal.angle1, dtype=float)
    point_data = {
        "displacement_mm": _xyz(snapshot.displacement),
        "deformation_mm": _xyz(snapshot.deformation),
        **_stress_arrays(nodal),
        "s1_direction": np.column_stack([np.cos(angle), np.sin(angle), np.zeros(len(angle))]),
    }
    cell_data = {name: [values] for name, values in _stress_arrays(element).items()}
    mesh = meshio.Mesh(_xyz(np.asarray(points, dtype=float)), [("triangle", np.asarray(triangles, dtype=np.int64))],
                       point_data=point_data, cell_data=cell_data)
    meshio.write(path, mesh, file_format="vtu", binary=True, compression="zlib")
    return path


def write_pvd(path: str | os.PathLike, entries: list[tuple[float, str]]) -> Path:
    """Write a ParaView collection file.

    Parameters
    ----------
    path : path-like
        The ``.pvd`` file.
    entries : list of (float, str)
        (time value — the crank angle in degrees, file name relative to the ``.pvd``'s folder).

    Returns
    -------
    Path
    """
    path = Path(path)
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    for time, name in sorted(entries):
        lines.append(f'    <DataSet timestep="{time:.6g}" group="" part="0" file={quoteattr(name)}/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


ENVELOPE_FILE = "disc_envelope.vtu"
"""File name of the stress envelope in ``vtk/`` (not part of the ``.pvd`` time series)."""


def write_envelope_vtu(path: str | os.PathLike, points: np.ndarray, triangles: np.ndarray,
                       von_mises: np.ndarray, theta: np.ndarray) -> Path:
    """Write the cycle's stress envelope as a ``.vtu``: point data ``von_mises_envelope_MPa``
    (the largest vertex von Mises stress of every vertex over every solved crank angle) and
    ``envelope_theta_deg`` (the crank angle at which it occurs).

    Parameters
    ----------
    path : path-like
    points : ndarray (n_vertices, 2)
    triangles : ndarray (n_elements, 3)
    von_mises : ndarray (n_vertices,)
        MPa.
    theta : ndarray (n_vertices,)
        rad.
    """
    import meshio

    path = Path(path)
    mesh = meshio.Mesh(_xyz(np.asarray(points, dtype=float)), [("triangle", np.asarray(triangles, dtype=np.int64))],
                       point_data={"von_mises_envelope_MPa": np.asarray(von_mises, dtype=float),
                                   "envelope_theta_deg": np.degrees(np.asarray(theta, dtype=float))})
    meshio.write(path, mesh, file_format="vtu", binary=True, compression="zlib")
    return path
