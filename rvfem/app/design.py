"""One design of ``rvfem optimise``: the analysis its responses read, and a lean result folder.

An optimiser design reads the bearing loads against the reference (the load cycle), the disc mass
and the safety factors (the ``mass_strength`` section, from the P2 structural peak of the
``stress`` section) — nothing of the attribution, the crank bearing in depth, the transmission
accuracy, the pin-flank and Hertz checks, nor any plot, VTK file or image. :func:`run_design`
computes only :data:`DESIGN_SECTIONS` (and what they require) on the same mesh, crank angles and
P2 re-solve as ``rvfem run``: the responses are the very numbers of a full run of the same case
(a test compares them), at a fraction of the cost.

The folder holds ``case.json`` and a ``summary.json`` with the keys of
:data:`SUMMARY_SECTIONS` (the same keys and meanings as a full run's, docs/outputs.md), its
``timings_s`` and ``design_only: true``; ``rvfem run`` on the design's case (``best.toml`` for
the best one) gives the full folder.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

from rvfem.app.analysis import ProgressCallback, analyse
from rvfem.case.definition import Case
from rvfem.outputs import summary as outputs
from rvfem.results import registry as sections_registry
from rvfem.results.format import json_ready
from rvfem.results.section import SummaryContext

__all__ = ["DESIGN_SECTIONS", "SUMMARY_SECTIONS", "run_design"]

DESIGN_SECTIONS = ("stress", "mass_strength")
"""The result sections a design computes (besides the fixed front: mesh, model, rigid references,
load cycle): what :func:`rvfem.app.optimise.design_responses` reads."""

SUMMARY_SECTIONS = ("header", "model", "references", "bearings", "cycle", "stress", "mass_strength")
"""The sections whose keys a design's ``summary.json`` holds."""


def run_design(case: Case, out_dir: str | os.PathLike, *, cache_dir: str | os.PathLike | None = None,
               progress: ProgressCallback | None = None) -> dict[str, Any]:
    """Analyse ``case`` as an optimiser design and write its lean result folder (module docstring).

    Parameters
    ----------
    case : Case
        The design's case (overrides applied).
    out_dir : path
        Result folder; replaced if it exists (written into a temporary folder first).
    cache_dir : path, optional
        Mesh cache folder (:func:`rvfem.app.analysis.analyse`).
    progress : ProgressCallback, optional

    Returns
    -------
    dict
        The content of the ``summary.json`` written.

    Raises
    ------
    CaseError, GeometryError, MeshError, ContactError
        From the analysis.
    """
    started = time.perf_counter()
    analysis = analyse(case, cache_dir=cache_dir, progress=progress, sections=DESIGN_SECTIONS)
    with outputs.result_folder(Path(out_dir), overwrite=True) as tmp:
        written = outputs.write_case_json(analysis, tmp)
        timings = {**analysis.timings, "total": time.perf_counter() - started}
        context = SummaryContext(files=tuple(sorted({p.name for p in written} | {"summary.json"})), timings=timings)
        summary: dict[str, Any] = {}
        for name in SUMMARY_SECTIONS:
            summary.update(sections_registry.section(name).summary(analysis, context))
        summary.update(design_only=True, files=list(context.files), timings_s=dict(timings))
        summary = json_ready(summary)
        outputs.write_summary(analysis, tmp, summary=summary)
    return summary
