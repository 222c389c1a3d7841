"""The header of ``summary.json``: schema and rvfem versions, the environment a result was computed
in, and where the case comes from (file, checksum, overrides, defaults used)."""

from __future__ import annotations

import datetime
import platform
import shlex
import sys
from pathlib import Path
from importlib import metadata
from typing import Any

from rvfem import __version__
from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ["CLI_MODULES", "CLI_SCRIPTS", "SCHEMA_VERSION", "SECTION", "VERSIONED_PACKAGES", "command_line",
           "environment"]

SCHEMA_VERSION = 2
"""Version of the ``summary.json`` layout (docs/outputs.md); bumped when a key changes meaning or
disappears (new keys do not bump it)."""

VERSIONED_PACKAGES = ("numpy", "scipy", "scikit-fem", "gmsh", "vtk", "pyvista", "matplotlib", "meshio")
"""Packages whose installed versions ``summary.json`` records (``environment.versions``)."""

CLI_MODULES = ("rvfem", "rvfem.__main__", "rvfem.app.cli")
"""Modules whose ``python -m`` run is the ``rvfem`` command (``__main__.__spec__.name``)."""

CLI_SCRIPTS = ("rvfem", "rvfem.exe", "rvfem-script.py")
"""File names of the ``rvfem`` console script (``sys.argv[0]``) on POSIX and Windows."""


def command_line() -> str | None:
    """The command line of this process if it is the ``rvfem`` command (None from Python, a
    notebook or a test runner), shell-quoted.

    Decided from the entry point, not from where the files lie: the process is the ``rvfem``
    command if its ``__main__`` module is :mod:`rvfem` run with ``python -m rvfem`` (or
    ``-m rvfem.app.cli``; the name of ``__main__.__spec__`` is one of :data:`CLI_MODULES`), or if
    it is a plain script (no module spec) named ``rvfem``, the console script the installation
    writes (:data:`CLI_SCRIPTS`). ``python -m pytest`` started in a folder named ``rvfem`` is
    not the command.
    """

    argv = list(sys.argv)
    if not argv:
        return None
    main = sys.modules.get("__main__")
    spec = getattr(main, "__spec__", None)
    name = getattr(spec, "name", None)
    if name in CLI_MODULES:
        return shlex.join(["rvfem", *argv[1:]])
    if name in (None, "__main__") and Path(argv[0]).name in CLI_SCRIPTS:
        return shlex.join(["rvfem", *argv[1:]])
    return None


def environment() -> dict[str, Any]:
    """When, how and with what a result was computed: UTC date and time, the command line
    (:func:`command_line`), Python, the platform and the versions of
    :data:`VERSIONED_PACKAGES` (None if not installed)."""

    versions: dict[str, str | None] = {}
    for name in VERSIONED_PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return {
        "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "command_line": command_line(),
        "python": platform.python_version(),
        "platform": platform.platform(),
        "versions": versions,
    }



def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    """``schema_version``, ``rvfem_version``, ``environment`` and ``case``."""
    p, case = a.provenance, a.case
    return {
        "schema_version": SCHEMA_VERSION,
        "rvfem_version": __version__,
        "environment": environment(),
        "case": {
            "name": case.name,
            "description": case.description,
            "file": p.file,
            "sha256": p.sha256,
            "matches_file": p.matches_file,
            "digest": case.digest(),
            "overrides": dict(p.overrides),
            "defaults_used": {k: v for k, v in p.defaults_used},
        },
    }


KEYS = (
    KeyRow('`schema_version`',
           'int',
           '2 (1 → 2: `peak_von_mises_MPa` is now the structural peak; mesh features are numbered from 1; `stress.peak_element_von_mises_MPa` was removed, it depended on `--field-step` and had no location)'),
    KeyRow('`rvfem_version`',
           'str',
           'version of rvfem that wrote the file'),
    KeyRow('`environment`',
           'object',
           'when, how and with what the result was computed (also in `rvfem rigid --json`)'),
    KeyRow('`environment.date_utc`',
           'str',
           'UTC date and time, ISO 8601 (`2026-01-31T12:00:00Z`)'),
    KeyRow('`environment.command_line`',
           'str or null',
           'the `rvfem …` command line (null when run from Python or a notebook)'),
    KeyRow('`environment.python`, `environment.platform`',
           'str',
           'Python version and platform'),
    KeyRow('`environment.versions`',
           'object',
           'installed version of each of numpy, scipy, scikit-fem, gmsh, vtk, pyvista, matplotlib, meshio (null if not installed)'),
    KeyRow('`case`',
           'object',
           'where the case comes from'),
    KeyRow('`case.name`, `case.description`',
           'str',
           'from the case'),
    KeyRow('`case.file`',
           'str or null',
           'case file path as given (null for a case built in code)'),
    KeyRow('`case.sha256`',
           'str or null',
           "sha256 of the case file's bytes (`rvfem.case.definition.file_sha256`)"),
    KeyRow('`case.matches_file`',
           'bool',
           "true if the analysed case is exactly the file's (no overrides, not modified in code)"),
    KeyRow('`case.digest`',
           'str',
           'sha256 of the canonical case data (`Case.digest()`), also for cases built in code'),
    KeyRow('`case.overrides`',
           'object',
           'dotted case key → value, for every value set on top of the file (`--set`, `--step`, `--bearing-model`, `--order`)'),
    KeyRow('`case.defaults_used`',
           'object',
           'dotted case key → default value, for keys neither the case file nor an override sets'),
)

SECTION = Section("header", summary, KEYS,
                  screen=lambda s: screen_lines.header_lines(s), screen_rank=0)
