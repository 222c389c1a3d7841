"""VTK output for ParaView: one ``.vtu`` per kept crank angle and a ``.pvd`` collection over θ.

Each ``.vtu`` (VTK XML, binary, zlib-compressed: meshio and ParaView read it) is the disc mesh in
its own frame (z = 0) with

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

``disc_envelope.vtu`` (:func:`write_envelope_vtu`) holds the cycle's stress envelope; its von Mises
array is named with the cycle's element order (``von_mises_envelope_P1_MPa``), since the run's
headline structural peak is re-solved on P2.

The files of one run share the mesh: :func:`vtu_mesh` encodes the points and the cells once (zlib
level :data:`MESH_ZLIB_LEVEL`), and :func:`write_vtu` and :func:`write_envelope_vtu` take it
(``mesh=``) instead of encoding them again. The field arrays are compressed with zlib at level
:data:`ZLIB_LEVEL` with the strategy :data:`ZLIB_STRATEGY`. Every array is compressed in blocks of
32 KiB (VTK's ``vtkZLibDataCompressor`` layout).
"""

from __future__ import annotations

import base64
import os
import sys
import zlib
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np


from rvfem.evaluate.postprocess import FieldSnapshot
from rvfem.results.files import vtu_name

__all__ = ["POINT_FIELDS", "CELL_FIELDS", "ENVELOPE_FILE", "MESH_ZLIB_LEVEL", "ZLIB_LEVEL", "ZLIB_STRATEGY",
           "VtuMesh", "vtu_mesh", "vtu_name", "write_vtu", "write_pvd", "envelope_field", "write_envelope_vtu"]

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


def _xyz(a: np.ndarray) -> np.ndarray:
    return np.column_stack([a, np.zeros(len(a))])

ZLIB_LEVEL = 1
"""zlib level of the field arrays of the ``.vtu`` files (0-9)."""

ZLIB_STRATEGY = zlib.Z_RLE
"""zlib strategy of the field arrays. The stresses are nearly incompressible doubles (what zlib
gains on them is mostly the repeated sign and exponent bytes and the zero z components): run-length
matches at level 1 compress them in about a fifth of the time of zlib's default (level 6, default
strategy), the files about 1 % larger."""

MESH_ZLIB_LEVEL = 6
"""zlib level of the points and the cells (default strategy): encoded once per run, so the
smallest."""

_BLOCK_BYTES = 32768
_VTU_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.int64): "Int64"}
_VTK_TRIANGLE = 5


def _compressed(block, level: int, strategy: int) -> bytes:
    if strategy == zlib.Z_DEFAULT_STRATEGY:
        return zlib.compress(block, level)
    c = zlib.compressobj(level, zlib.DEFLATED, zlib.MAX_WBITS, 8, strategy)
    return c.compress(block) + c.flush()


def _encoded(data: np.ndarray, level: int, strategy: int) -> str:
    """An array as the text of a binary, zlib-compressed ``DataArray`` (VTK's block header, UInt32,
    then the compressed blocks, each base64-encoded)."""
    raw = memoryview(np.ascontiguousarray(data).data).cast("B")
    n = len(raw)
    blocks = [_compressed(raw[i:i + _BLOCK_BYTES], level, strategy) for i in range(0, n, _BLOCK_BYTES)]
    last = n - (len(blocks) - 1) * _BLOCK_BYTES if blocks else 0
    header = np.array([len(blocks), _BLOCK_BYTES, last] + [len(b) for b in blocks], dtype=np.uint32)
    return (base64.b64encode(header.tobytes()) + base64.b64encode(b"".join(blocks))).decode("ascii")


def _data_array(name: str, data: np.ndarray, level: int, strategy: int = zlib.Z_DEFAULT_STRATEGY) -> str:
    data = np.asarray(data)
    data = data.astype(data.dtype.newbyteorder("="), copy=False)
    components = f' NumberOfComponents="{data.shape[1]}"' if data.ndim == 2 else ""
    return (f'<DataArray type="{_VTU_TYPES[data.dtype]}" Name="{name}"{components} format="binary">\n'
            f"{_encoded(data, level, strategy)}\n</DataArray>\n")


@dataclass(frozen=True, eq=False)
class VtuMesh:
    """The mesh part of a ``.vtu`` file, encoded once for every file of the mesh.

    Attributes
    ----------
    n_points, n_cells : int
    xml : str
        The ``Points`` and ``Cells`` elements.
    """

    n_points: int
    n_cells: int
    xml: str


def vtu_mesh(points: np.ndarray, triangles: np.ndarray, *, level: int = MESH_ZLIB_LEVEL) -> VtuMesh:
    """Encode the mesh of the ``.vtu`` files: points (z = 0) and triangles.

    Parameters
    ----------
    points : ndarray (n_vertices, 2)
        Mesh vertices, mm.
    triangles : ndarray (n_elements, 3)
        Vertex indices.
    level : int
        zlib level (default strategy).

    Returns
    -------
    VtuMesh
    """
    xyz = _xyz(np.asarray(points, dtype=float))
    tri = np.asarray(triangles, dtype=np.int64)
    n = len(tri)
    xml = ("<Points>\n" + _data_array("Points", xyz, level) + "</Points>\n<Cells>\n"
           + _data_array("connectivity", tri.reshape(-1), level)
           + _data_array("offsets", 3 * np.arange(1, n + 1, dtype=np.int64), level)
           + _data_array("types", np.full(n, _VTK_TRIANGLE, dtype=np.int64), level) + "</Cells>\n")
    return VtuMesh(n_points=len(xyz), n_cells=n, xml=xml)


def _write_unstructured_grid(path: Path, mesh: VtuMesh, point_data: dict[str, np.ndarray],
                             cell_data: dict[str, np.ndarray], level: int, strategy: int,
                             field_data: dict[str, np.ndarray] | None = None) -> Path:
    byte_order = "LittleEndian" if sys.byteorder == "little" else "BigEndian"
    parts = ['<?xml version="1.0"?>\n',
             f'<VTKFile type="UnstructuredGrid" version="0.1" byte_order="{byte_order}" '
             'compressor="vtkZLibDataCompressor">\n<UnstructuredGrid>\n']
    if field_data:  # values of the whole data set (ParaView: Information panel, "Field Data")
        parts.append("<FieldData>\n")
        parts += [_data_array(name, values, level, strategy).replace(
            ' format="binary"', f' NumberOfTuples="{len(values)}" format="binary"', 1)
            for name, values in field_data.items()]
        parts.append("</FieldData>\n")
    parts += [f'<Piece NumberOfPoints="{mesh.n_points}" NumberOfCells="{mesh.n_cells}">\n', mesh.xml]
    for tag, data in (("PointData", point_data), ("CellData", cell_data)):
        if data:
            parts.append(f"<{tag}>\n")
            parts += [_data_array(name, values, level, strategy) for name, values in data.items()]
            parts.append(f"</{tag}>\n")
    parts.append("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    path.write_bytes("".join(parts).encode("ascii"))
    return path


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
              snapshot: FieldSnapshot, *, mesh: VtuMesh | None = None, level: int = ZLIB_LEVEL,
              strategy: int = ZLIB_STRATEGY) -> Path:
    """Write the disc with the fields of one snapshot as a ``.vtu`` file.

    Parameters
    ----------
    path : path-like
    points : ndarray (n_vertices, 2)
        Mesh vertices, mm.
    triangles : ndarray (n_elements, 3)
        Vertex indices, in the element order of the stresses (``model.mesh.t.T``).
    snapshot : FieldSnapshot
    mesh : VtuMesh, optional
        ``vtu_mesh(points, triangles)``, encoded once for the files of a series (``points`` and
        ``triangles`` are then not encoded again).
    level, strategy : int
        zlib level and strategy of the field arrays.

    Returns
    -------
    Path
    """
    path = Path(path)
    nodal, element = snapshot.stress.nodal, snapshot.stress.element
    angle = np.asarray(nodal.angle1, dtype=float)
    point_data = {
        "displacement_mm": _xyz(snapshot.displacement),
        "deformation_mm": _xyz(snapshot.deformation),
        **_stress_arrays(nodal),
        "s1_direction": np.column_stack([np.cos(angle), np.sin(angle), np.zeros(len(angle))]),
    }
    if mesh is None:
        mesh = vtu_mesh(points, triangles)
    return _write_unstructured_grid(path, mesh, point_data, _stress_arrays(element), level, strategy)


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


ANGLE_DECIMALS = 9
"""Crank angles computed from radians (``envelope_theta_deg``) are rounded to this many decimals:
no float noise such as 255.00000000000003."""

ENVELOPE_FILE = "disc_envelope.vtu"
"""File name of the stress envelope in ``vtk/`` (not part of the ``.pvd`` time series)."""


def envelope_field(element_order: int) -> str:
    """Name of the envelope's von Mises array: ``von_mises_envelope_P1_MPa`` for the P1 cycle.

    The envelope is the load cycle's own vertex stress, of the cycle's element order; the headline
    structural peak of a run is re-solved on P2 (P1 vertex stresses lie low at a hole fillet), so
    the name says which order the field is.
    """
    return f"von_mises_envelope_P{int(element_order)}_MPa"


def write_envelope_vtu(path: str | os.PathLike, points: np.ndarray, triangles: np.ndarray,
                       von_mises: np.ndarray, theta: np.ndarray, *, element_order: int = 1,
                       structural_peak_MPa: float | None = None, structural_peak_order: int | None = None,
                       mesh: VtuMesh | None = None, level: int = ZLIB_LEVEL,
                       strategy: int = ZLIB_STRATEGY, extra_point_data: dict | None = None) -> Path:
    """Write the cycle's stress envelope as a ``.vtu``: point data :func:`envelope_field`
    (``von_mises_envelope_P1_MPa``: the largest vertex von Mises stress of every vertex over every
    solved crank angle, of the cycle's element order) and ``envelope_theta_deg`` (the crank angle at
    which it occurs); field data ``element_order`` and, when given, the headline structural peak
    ``structural_peak_von_mises_MPa`` with its ``structural_peak_element_order`` (2 where it was
    re-solved on P2), to compare the field with.

    Parameters
    ----------
    path : path-like
    points : ndarray (n_vertices, 2)
    triangles : ndarray (n_elements, 3)
    von_mises : ndarray (n_vertices,)
        MPa.
    theta : ndarray (n_vertices,)
        rad.
    element_order : int
        Element order of the load cycle the envelope comes from.
    structural_peak_MPa : float, optional
        The run's structural stress peak (``summary.json`` ``peak_von_mises_MPa``).
    structural_peak_order : int, optional
        Its element order (default: ``element_order``).
    mesh : VtuMesh, optional
        ``vtu_mesh(points, triangles)`` (see :func:`write_vtu`).
    level, strategy : int
        zlib level and strategy of the arrays.
    extra_point_data : dict, optional
        More point arrays (name → (n_vertices,)), e.g. ``fatigue_safety_factor_P1``.

    Returns
    -------
    Path
    """
    if mesh is None:
        mesh = vtu_mesh(points, triangles)
    point_data = {envelope_field(element_order): np.asarray(von_mises, dtype=float),
                  "envelope_theta_deg": np.round(np.degrees(np.asarray(theta, dtype=float)), ANGLE_DECIMALS)}
    point_data.update({k: np.asarray(v, dtype=float) for k, v in (extra_point_data or {}).items()})
    field_data = {"element_order": np.array([element_order], dtype=np.int64)}
    if structural_peak_MPa is not None:
        field_data["structural_peak_von_mises_MPa"] = np.array([structural_peak_MPa], dtype=float)
        field_data["structural_peak_element_order"] = np.array(
            [element_order if structural_peak_order is None else structural_peak_order], dtype=np.int64)
    return _write_unstructured_grid(Path(path), mesh, point_data, {}, level, strategy, field_data)
