"""The public entry points: mesh a disc (whole, or one sector copied round it) into the cache, read a
mesh file back, and mesh a case or reuse its cached mesh."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from rvfem.case.definition import Case
from rvfem.errors import MeshError
from rvfem.geometry import DiscGeometry, disc_geometry
from rvfem.mesh.cache import _cache_file, mesh_path
from rvfem.mesh.disc_mesh import QUALITY_MEASURE, DiscMesh
from rvfem.mesh.extract import _extract
from rvfem.mesh.gmsh_model import _build_model
from rvfem.mesh.sector_copy import _add_discrete, _mesh_sector
from rvfem.mesh.session import gmsh_session
from rvfem.mesh.symmetry import _sector_cut

def read_msh(path: str | os.PathLike, from_cache: bool = True) -> DiscMesh:
    """Read a disc mesh written by :func:`mesh_case` (physical groups as described in :mod:`rvfem.mesh`)."""
    path = Path(path)
    if not path.is_file():
        raise MeshError(f"{path}: no such mesh file")
    with gmsh_session() as g:
        g.open(str(path))
        return _extract(g, path, from_cache)


def mesh_geometry(geom: DiscGeometry, path: str | os.PathLike) -> DiscMesh:
    """Mesh a checked :class:`~rvfem.geometry.DiscGeometry` and write the ``.msh`` to ``path``.

    An N-fold symmetric disc (:func:`symmetry_order`) is meshed as one sector copied N times when
    a sector cut clears the features (:data:`CUT_CLEARANCE`); the mesh then has ``symmetry == N``.
    Otherwise the whole disc is meshed (``symmetry == 1``).

    The file is written under a unique temporary name in the same folder and moved into place with
    :func:`os.replace` (atomic on POSIX and Windows), so a crash never leaves a half file, and
    several processes meshing the same case at once each publish a complete file: a reader sees
    either no file or a whole one (the last writer wins; the meshes are identical).
    """
    path = Path(path)
    cut = _sector_cut(geom)
    fd, tmp_name = _cache_file(path)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        with gmsh_session() as g:
            if cut is None:
                _build_model(g, geom)
                g.model.mesh.generate(2)
            else:
                assembled = _mesh_sector(g, geom, cut)
                g.clear()
                _add_discrete(g, assembled)
            mesh = _extract(g, path, from_cache=False)
            if cut is not None and not (np.array_equal(mesh.points, assembled.points)
                                        and np.array_equal(mesh.triangles, assembled.triangles)
                                        and all(np.array_equal(mesh.boundaries[k], v)
                                                for k, v in assembled.boundaries.items())):
                raise MeshError("the assembled sector mesh does not read back from Gmsh unchanged")
            if mesh.min_quality <= 0:
                raise MeshError(f"Gmsh produced inverted or degenerate triangles "
                                f"(min {QUALITY_MEASURE} = {mesh.min_quality:.3g})")
            g.write(str(tmp))
        os.chmod(tmp, 0o644)                 # mkstemp creates 0600; a cache is shared
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return mesh


def mesh_case(case: Case, cache_dir: str | os.PathLike = "meshes", *, use_cache: bool = True,
              geometry: DiscGeometry | None = None) -> DiscMesh:
    """Mesh the disc of a case, or reuse the cached mesh.

    Parameters
    ----------
    case : Case
    cache_dir : path
        Directory of cached meshes (created if missing), relative to the working directory.
    use_cache : bool
        Reuse ``mesh_path(case, cache_dir)`` if it exists (default); False always re-meshes.
    geometry : DiscGeometry, optional
        The already built geometry of ``case`` (built and checked here otherwise). The geometry is
        checked on every call, also on a cache hit, so a geometry error is never hidden by a cache.

    Returns
    -------
    DiscMesh

    Raises
    ------
    GeometryError
        The geometry check failed (nothing is meshed).
    MeshError
        Gmsh failed or produced an unusable mesh.
    OutputError
        ``cache_dir`` is a file or cannot be written.
    """
    geom = geometry if geometry is not None else disc_geometry(case)
    path = mesh_path(case, cache_dir)
    if use_cache and path.is_file():
        try:
            mesh = read_msh(path, from_cache=True)
            if mesh.symmetry == 1:
                _sector_cut(geom)    # says why the whole disc is meshed (a notice), as when it was meshed
            return mesh
        except MeshError:
            pass     # unreadable cache entry: re-mesh; the new file replaces it atomically
    return mesh_geometry(geom, path)
