"""Meshing the disc with Gmsh (OpenCASCADE kernel), caching and previews.

The disc is one plane surface: the outer curve loop is the cycloid profile (one interpolating
spline per tooth space, :attr:`~rvfem.geometry.Profile.spline_points`), the inner loops are the
central hole, the crank-bearing bores and the lightening holes. Because :func:`~rvfem.geometry.
disc_geometry` has already proved that no two features touch, the surface is built directly with
holes (``occ.addPlaneSurface`` with several curve loops) — no boolean operations, so the curve tags
we create are the tags we group, and nothing has to be re-identified afterwards.

Mesh: linear triangles (the FE stage builds P2 on top), Frontal-Delaunay, sizes from a background
field only (``Mesh.MeshSizeExtendFromBoundary = 0``, ``Mesh.MeshSizeFromPoints = 0``,
``Mesh.MeshSizeFromCurvature = 0``): ``size_flank`` on the profile, ``size_bore`` on the bores,
``size_hole`` (default ``HOLE_SIZE_FACTOR·size_bore``, capped by ``size_interior``) on the central
hole and the lightening holes, each held over a band and then growing linearly (``SIZE_GROWTH`` mm per mm) to
``size_interior``.

Physical groups: curves ``profile``, ``central_hole``, ``bore_0`` …, ``hole_0`` … (fan holes
first, then round holes, then the holes of registered hole shapes) and the surface ``disc``.
Bores and holes are numbered from 0 (Python indexing; ``bore_0`` is the bore of bearing 1), in
the file as in :attr:`DiscMesh.boundaries`; what users read is numbered from 1
(:func:`rvfem.evaluate.postprocess.user_feature_name`).

Symmetric discs: when the disc maps onto itself under a rotation by 2π/N about its centre (N the
number of cranks; :func:`symmetry_order`) and ``mesh.symmetric`` is true, only one 360°/N sector is
meshed and the mesh is copied N times by rotation, so the mesh is exactly N-fold symmetric and
conforming. The sector is bounded by Zc/N profile splines, an arc of the central hole and two
radial *cuts* from the central hole to a tooth tip, the second the first rotated by 2π/N; the cuts
are periodic in Gmsh (``setPeriodic``), so their nodes match and the copies are merged along them.
The tip is the one of a sector whose cut keeps the widest clearance to the features, counted in
element sizes of each feature; below :data:`CUT_CLEARANCE` element sizes the whole disc is meshed
instead. Every curve of the disc is still built (the sector surface uses its own), so the size
field is that of the whole disc. The assembled mesh is written through Gmsh as discrete entities
with the same physical groups (plus a surface group ``symmetry_<N>``), and read back by the same
code as any other mesh file.

Cache: the ``.msh`` is written to ``cache_dir/<case name>-<key>.msh`` where ``key`` hashes only the
inputs that shape the mesh (profile and feature geometry, mesh sizes, the mesher version); loads,
material, thickness and analysis options do not invalidate it. A cached file is read back through
Gmsh, so a cache hit returns exactly the arrays a fresh mesh would. Files appear atomically (a
unique temporary file in the cache folder, then :func:`os.replace`), so processes that build the
same mesh at the same time never see or leave a partial file.

Gmsh's global state is only ever touched inside :func:`gmsh_session`.

The package's modules, one concern each, from the bottom up: :mod:`~rvfem.mesh.disc_mesh` (the
mesh), :mod:`~rvfem.mesh.session` (the Gmsh session), :mod:`~rvfem.mesh.cache` (the cache key and
files), :mod:`~rvfem.mesh.sizes` (the size field), :mod:`~rvfem.mesh.symmetry` (the symmetry order
and the sector cut), :mod:`~rvfem.mesh.gmsh_model` (building the Gmsh model),
:mod:`~rvfem.mesh.extract` (reading the mesh out of Gmsh), :mod:`~rvfem.mesh.sector_copy` (copying
one sector round the disc) and :mod:`~rvfem.mesh.meshing` (the entry points). This module is their
public face: every name below is reached as ``rvfem.mesh.X``.
"""

from __future__ import annotations

from rvfem.mesh.cache import MESHER_VERSION as MESHER_VERSION
from rvfem.mesh.cache import mesh_key, mesh_path
from rvfem.mesh.disc_mesh import QUALITY_MEASURE, DiscMesh
from rvfem.mesh.extract import SYMMETRY_GROUP as SYMMETRY_GROUP
from rvfem.mesh.meshing import mesh_case, mesh_geometry, read_msh
from rvfem.mesh.session import gmsh_session
from rvfem.mesh.sizes import BAND_FACTOR as BAND_FACTOR
from rvfem.mesh.sizes import HOLE_SIZE_FACTOR as HOLE_SIZE_FACTOR
from rvfem.mesh.sizes import SIZE_GROWTH as SIZE_GROWTH
from rvfem.mesh.symmetry import CUT_CLEARANCE as CUT_CLEARANCE
from rvfem.mesh.symmetry import SYMMETRY_TOLERANCE as SYMMETRY_TOLERANCE
from rvfem.mesh.symmetry import rotation_permutation, symmetry_order

__all__ = [
    "DiscMesh",
    "gmsh_session",
    "mesh_key",
    "mesh_path",
    "mesh_case",
    "mesh_geometry",
    "read_msh",
    "rotation_permutation",
    "symmetry_order",
    "QUALITY_MEASURE",
]
