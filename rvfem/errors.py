"""Exceptions raised by rvfem.

Every error a user can cause (a bad case file, an impossible geometry, a contact problem that does
not settle) is an :class:`RvfemError`; the command line turns these into one readable message and a
non-zero exit code. Anything else is a bug.
"""

from __future__ import annotations


class RvfemError(Exception):
    """Base class of all errors a user can cause and fix."""


class CaseError(RvfemError, ValueError):
    """A case file (or a case built in code) is incomplete, mistyped or non-physical."""


class GeometryError(RvfemError, ValueError):
    """The disc geometry is impossible: undercut profile, overlapping features, walls too thin."""


class MeshError(RvfemError, RuntimeError):
    """Gmsh could not mesh the disc, or the mesh is unusable."""


class ContactError(RvfemError, RuntimeError):
    """The contact problem has no solution or the active set does not settle."""


class OutputError(RvfemError, RuntimeError):
    """A result folder cannot be written: it exists already (and overwriting was not asked for), it
    is a file, or the file system refuses."""


class FolderNotEmptyError(OutputError):
    """A result folder rvfem wrote earlier is in the way and replacing it was not allowed.

    The message says so in the library's words (the ``overwrite`` argument); the command line
    words it with its option. ``folder`` is the folder's path.
    """

    def __init__(self, folder, message: str | None = None):
        self.folder = folder
        super().__init__(message or f"{folder} exists and is not empty; choose another output folder, or allow "
                                    "replacing it (overwrite)")


class RenderError(RvfemError, RuntimeError):
    """Off-screen rendering of the images is not possible on this machine."""
