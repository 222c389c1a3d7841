"""The mesh cache: the key of the inputs that shape the mesh, the file it is cached in, and the
temporary file a new mesh is written to before it is moved into place."""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path

import gmsh

from rvfem.case.definition import Case, case_to_dict, registered_hole_shapes
from rvfem.errors import OutputError
from rvfem.geometry import SPLINE_POINTS_PER_SEGMENT

MESHER_VERSION = 4
"""Bumped whenever a change here changes the mesh for the same inputs (invalidates caches)."""


def mesh_key(case: Case) -> str:
    """sha256 (hex) of the inputs that shape the mesh.

    Included: cycloid teeth, eccentricity, central hole, modifications and pitch errors; pin count,
    pin-circle radius and pin radius; cranks; the bore radius; the holes (each hole shape's
    :meth:`~rvfem.geometry.HoleShape.mesh_key_part` of its table); the mesh sizes and
    ``mesh.symmetric``; :data:`MESHER_VERSION`, the number of spline points per tooth space and
    the Gmsh version. Not included: thickness, material, loads, analysis options, bearing data
    other than the bore radius, ``mesh.min_wall`` (a check, not a shape) and the case name.
    """
    d = case_to_dict(case)
    cyc = {k: v for k, v in d["cycloid"].items() if k != "thickness"}
    shaping = {
        "cycloid": cyc,
        "pins": {k: d["pins"][k] for k in ("count", "circle_radius", "radius")},
        "cranks": d["cranks"],
        "bore_radius": d["crank_bearing"]["bore_radius"],
        "mesh": {k: d["mesh"].get(k) for k in ("size_flank", "size_bore", "size_interior", "size_hole",
                                               "size_fillet", "symmetric")},
        "mesher": MESHER_VERSION,
        "spline_points": SPLINE_POINTS_PER_SEGMENT,
        "gmsh": gmsh.__version__,
    }
    shaping.update(_holes_key(case))
    return hashlib.sha256(json.dumps(shaping, sort_keys=True).encode()).hexdigest()


def _holes_key(case: Case) -> dict:
    """The holes' part of the mesh key: each registered hole shape's part of its table. The
    built-in shapes (:attr:`~rvfem.geometry.HoleShape.always_in_mesh_key`) have a top-level entry,
    None without a table, as in the keys of earlier versions (their cached meshes stay valid);
    the other shapes appear under ``"holes"`` when the case has their table."""
    out: dict = {}
    for shape in registered_hole_shapes():
        table = case.hole_table(shape.name)
        part = None if table is None else shape.mesh_key_part(table)
        if shape.always_in_mesh_key:
            out[shape.name] = part
        elif table is not None:
            out.setdefault("holes", {})[shape.name] = part
    return out


def mesh_path(case: Case, cache_dir: str | os.PathLike = "meshes") -> Path:
    """Where the mesh of ``case`` is cached: ``cache_dir/<name>-<first 12 hex of key>.msh``."""
    safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in case.name)
    return Path(cache_dir) / f"{safe}-{mesh_key(case)[:12]}.msh"


def _cache_file(path: Path) -> tuple[int, str]:
    """Create the folder of ``path`` (the mesh cache) and a temporary file in it; ``(fd, name)``.

    Raises
    ------
    OutputError
        The folder is a file, or cannot be created or written (the error names the mesh cache,
        not the results).
    """
    folder = path.parent
    blocked = next((p for p in (folder, *folder.parents) if p.exists() and not p.is_dir()), None)
    if blocked is not None:
        raise OutputError(f"the mesh cache folder {folder} cannot be used: {blocked} is a file, not a folder; "
                          "choose another mesh cache folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        return tempfile.mkstemp(dir=folder, prefix=f".{path.stem}.", suffix=".tmp.msh")
    except OSError as exc:
        raise OutputError(f"cannot write into the mesh cache folder {folder}: {exc.strerror or exc}; choose another "
                          "mesh cache folder") from None
