"""The writers of a result folder, registered by name (as meshio registers its file formats).

A writer is a function ``write(analysis, folder, **options) -> list[Path]`` that writes one kind of
file into ``folder`` and returns the paths it wrote. Its module registers it where it is defined::

    @register_writer("vtk", order=30, stage="vtk", options=("tick",), files=("vtk/*.vtu", "vtk/disc.pvd"),
                     ticks=lambda analysis: len(analysis.stress.snapshots))
    def write_vtk(analysis, folder, *, tick=None): ...

and :func:`writers` lists the registered writers in their ``order``: a run
(:func:`rvfem.app.run.run_case`) calls them one after the other, so a new output is one
registered function, with no change to the run.

The modules of rvfem's own writers are listed in one place, :data:`WRITER_MODULES` (as meshio lists
its formats in its ``__init__``), and :func:`writers` imports them (:mod:`importlib`) before it
answers: the list is complete whatever was imported first, and a writer in a new module of this
package is that module plus its line in :data:`WRITER_MODULES` (a test fails for a module under
``rvfem/outputs`` that registers a writer and is not listed). The import is lazy, in
:func:`writers`, so that importing this module stays light and the writer modules (which import it)
form no import circle. A writer registered from outside the package (a notebook, a test module)
exists once its module has been imported.

The options a writer may take (it names those it takes in ``options``; the run passes them):

``tick``
    ``tick(done, total)``: progress within the writer (the run reports it as the writer's stage).
``pending``
    The drawings a render worker started (:class:`rvfem.outputs.summary.PendingImages`), to be
    waited for instead of drawn here; None when this process draws.
``summary``
    The ``summary.json`` content. The writers that take it run after the summary is built, and
    the files they write must be named exactly in ``files`` (the summary lists them before they
    exist).
"""

from __future__ import annotations

import fnmatch
import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable

from rvfem.results.registry import sections

__all__ = ["OPTIONS", "SECTION_WRITER_ORDER", "WRITER_MODULES", "Writer", "register_writer", "writers"]

WRITER_MODULES = (
    "rvfem.outputs.summary",          # tables, case.json, vtk, plots, images, report, summary.json
    "rvfem.outputs.roller_outputs",   # roller_pressure.csv
)
"""The modules of rvfem's own writers, each registering its writers with :func:`register_writer`;
:func:`writers` imports them."""

OPTIONS = ("tick", "pending", "summary")
"""The options a writer may take (see the module's docstring)."""


@dataclass(frozen=True)
class Writer:
    """A registered writer.

    Attributes
    ----------
    name : str
        Its name (unique).
    order : int
        Writers run in increasing order.
    write : callable
        ``write(analysis, folder, **options) -> list[Path]``.
    stage : str or None
        The progress stage of a run that reports it (several writers may share one); None for a
        writer that runs after every stage (``summary.json``, which holds their times).
    options : tuple of str
        The options of :data:`OPTIONS` it takes.
    files : tuple of str
        The files it writes, relative to the folder, as patterns (``fnmatch``: ``vtk/*.vtu``).
    renders : bool
        It draws images off-screen: a run without images leaves it out.
    ticks : callable or None
        ``ticks(analysis) -> int``, the progress steps of its stage (one if None).
    """

    name: str
    order: int
    write: Callable[..., list[Path]]
    stage: str | None
    options: tuple[str, ...] = ()
    files: tuple[str, ...] = ()
    renders: bool = False
    ticks: Callable[[Any], int] | None = None

    @property
    def needs_summary(self) -> bool:
        """It writes from the ``summary.json`` content (and runs after the summary is built)."""
        return "summary" in self.options

    def owns(self, relative: str) -> bool:
        """Whether the file ``relative`` (a POSIX path relative to the folder) is one of :attr:`files`."""
        return any(fnmatch.fnmatchcase(relative, pattern) for pattern in self.files)


_WRITERS: dict[str, Writer] = {}


def register_writer(name: str, order: int, *, stage: str | None, options: Iterable[str] = (),
                    files: Iterable[str] = (), renders: bool = False,
                    ticks: Callable[[Any], int] | None = None) -> Callable[[Callable], Callable]:
    """Decorator registering a writer (see :class:`Writer` for the arguments); returns the
    function unchanged.

    Raises
    ------
    ValueError
        ``name`` or ``order`` is taken by another writer, or an option is unknown.
    """
    options = tuple(options)
    unknown = set(options) - set(OPTIONS)
    if unknown:
        raise ValueError(f"writer {name!r}: unknown options {sorted(unknown)} (known: {', '.join(OPTIONS)})")

    def register(write: Callable) -> Callable:
        for other in _WRITERS.values():
            if other.name != name and other.order == order:
                raise ValueError(f"writer {name!r}: order {order} is taken by the writer {other.name!r}")
            if other.name == name and other.write.__qualname__ != write.__qualname__:
                raise ValueError(f"a writer named {name!r} is registered already ({other.write.__qualname__})")
        _WRITERS[name] = Writer(name=name, order=order, write=write, stage=stage, options=options,
                                files=tuple(files), renders=renders, ticks=ticks)
        return write

    return register


SECTION_WRITER_ORDER = 1000
"""Order of the first result section's writer (:attr:`rvfem.results.section.Section.writers`): after
every registered writer, in the sections' order, with the tables' progress stage."""


def _section_writers() -> list[Writer]:
    """The files the result sections write (:attr:`rvfem.results.section.Section.writers`), as writers."""
    found = [w for s in sections() for w in s.writers]
    return [Writer(name=w.name, order=SECTION_WRITER_ORDER + i, write=w.write, stage="tables", files=w.files)
            for i, w in enumerate(found)]


def writers(*, images: bool = True) -> tuple[Writer, ...]:
    """The registered writers in their order (those of every module of :data:`WRITER_MODULES`, and
    any registered since), then the result sections' writers; without those that render if
    ``images`` is False."""
    for module in WRITER_MODULES:
        importlib.import_module(module)
    every = sorted([*_WRITERS.values(), *_section_writers()], key=lambda w: w.order)
    return tuple(w for w in every if images or not w.renders)
