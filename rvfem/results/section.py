"""What a result section is: :class:`Section`, the rows of its key table and what the summary
needs besides the analysis.

A section is one result of an analysis — the bearing loads and their deltas, the stresses, the
crank bearing in depth, the accuracy, mass and strength, the attribution, the duty cycle, the
warnings. It declares

- what it **requires** (results computed before it: ``case``, ``system``, ``cycle``, … or other
  sections' names) and how it is **computed** (``compute(inputs) → frozen dataclass``; None for the
  results the analysis's fixed front makes: the case, the mesh, the model and the load cycle),
- its **summary keys** (``summary(analysis, context) → dict`` of top-level keys of ``summary.json``)
  and their documentation (:class:`KeyRow`; the key table of docs/outputs.md is generated from
  them, :func:`rvfem.results.registry.key_table`),
- its **screen lines** and a **report partial** (both from its part of the summary, so that a
  summary read back from disk gives the same), its **warnings** and the **writers** of its files.

Sections are listed in one explicit place, :data:`rvfem.results.registry.BUILTIN_SECTIONS`; a
section from outside the package adds itself with one
:func:`rvfem.results.registry.register_section` line.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

__all__ = ["KeyRow", "Section", "SectionWriter", "SummaryContext", "SectionInputs"]


class KeyRow(NamedTuple):
    """One row of the ``summary.json`` key table (docs/outputs.md), as markdown.

    Attributes
    ----------
    keys : str
        The backquoted key paths (``"`model.nodes`, `model.dofs`"``); a row starting with
        ``&nbsp;`` lists keys of each object named in the row above it.
    type : str
        The JSON type(s).
    meaning : str
        What the value is, its unit and its source.
    """

    keys: str
    type: str
    meaning: str


@dataclass(frozen=True)
class SummaryContext:
    """What the summary needs besides the analysis.

    Attributes
    ----------
    files : tuple of str
        Files of the result folder, relative paths (posix).
    timings : dict
        Wall time per stage (s), including the writers' and ``total``.
    """

    files: tuple[str, ...] = ()
    timings: Mapping[str, float] = dataclasses.field(default_factory=dict)


@dataclass(frozen=True)
class SectionWriter:
    """A file a section writes into the result folder (a table of its own).

    Attributes
    ----------
    name : str
        The writer's name among the run's writers (:func:`rvfem.outputs.registry.writers`).
    files : tuple of str
        The files it writes, relative to the folder (patterns).
    write : callable
        ``write(analysis, folder) -> list of Path``.
    """

    name: str
    files: tuple[str, ...]
    write: Callable[[Any, Path], list[Path]]


SectionInputs = Mapping[str, Any]
"""What a section's ``compute`` is given: the results it ``requires`` by name, and ``options``
(:class:`rvfem.results.analysis.AnalysisOptions`) and ``progress`` (``progress(done, total)``
within the section's stage) always."""


@dataclass(frozen=True)
class Section:
    """One result section of an analysis (the module docstring says what each part is for).

    Attributes
    ----------
    name : str
        The section's name (``"accuracy"``); its result is the :class:`~rvfem.results.analysis.Analysis`
        field of that name, or ``analysis.extra[name]`` for a section that is not one of rvfem's own.
    summary : callable
        ``summary(analysis, context) -> dict``: its top-level keys of ``summary.json`` (JSON-ready
        after :func:`rvfem.results.format.json_ready`).
    keys : tuple of KeyRow
        The documentation of those keys, in the order of the key table.
    requires : tuple of str
        The results ``compute`` reads (given to it by name, with ``options`` and ``progress``).
    compute : callable or None
        ``compute(inputs) -> result``; None where the analysis's fixed front makes the result.
        Sections are computed in the order of their stage among the analysis's stages (those
        without a stage after them), and one that requires ``analysis`` (the whole result so far)
        after every other.
    applies : callable or None
        ``applies(inputs) -> bool``: False leaves the result None without computing it or
        reporting its stage (default: always computed).
    stage : str or None
        The progress stage the computation reports (:data:`rvfem.app.analysis.STAGES`); a stage
        already reported by an earlier section gets this section's time added to it silently.
    executor : str
        ``"inline"``, or ``"thread"``: started on the analysis's background thread as soon as
        what it requires is there, and waited for (its stage) where the declared order reaches it.
    screen : callable or None
        ``screen(summary) -> list of str``: lines for the screen after a run, from the summary.
    screen_rank : float
        Where the lines go among the other sections' (smaller first).
    report : callable or None
        ``report(summary) -> list of [quantity, value]``: its rows of the report's "Other results"
        table, from the summary.
    writers : tuple of SectionWriter
        The files it writes; a run calls them with the tables (:func:`rvfem.outputs.registry.writers`
        lists them after the registered writers).
    """

    name: str
    summary: Callable[[Any, SummaryContext], dict[str, Any]]
    keys: tuple[KeyRow, ...]
    requires: tuple[str, ...] = ()
    compute: Callable[[SectionInputs], Any] | None = None
    applies: Callable[[SectionInputs], bool] | None = None
    stage: str | None = None
    executor: str = "inline"
    screen: Callable[[dict[str, Any]], list[str]] | None = None
    screen_rank: float = 100.0
    report: Callable[[dict[str, Any]], list[list[str]]] | None = None
    writers: tuple[SectionWriter, ...] = ()

    def __post_init__(self) -> None:
        if self.executor not in ("inline", "thread"):
            raise ValueError(f"section {self.name!r}: executor must be 'inline' or 'thread', got {self.executor!r}")
