"""The stages of an analysis: their names in order, their timing and their progress reports.

:data:`STAGES` lists the stages of :func:`rvfem.app.analysis.analyse` in the order the user sees
them (the result sections are computed in that order); :class:`Stages` times them and reports them
to a progress callback (:data:`ProgressCallback`).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Mapping
from typing import Any

log = logging.getLogger("rvfem.app.analysis")

__all__ = ["STAGES", "ProgressCallback", "StageSteps", "Stages", "timed"]

STAGES: dict[str, str] = {
    "check": "checking the case",
    "mesh": "meshing the disc (cached)",
    "model": "assembling and factorising the disc model",
    "rigid": "rigid handbook model",
    "cycle": "flexible load cycle",
    "evaluation": "evaluation: rigid vs flexible, stresses, Hertz",
    "stress": "stresses: the structural peak re-solved on P2 at its crank angles, the hot spots' histories",
    "attribution": "attribution: the reducer-stage models step by step (computed beside other stages)",
    "duty_cycle": "flexible load cycle at the other duty-cycle torques",
    "accuracy": "torsional rigidity and lost motion at crank angle 0",
    "roller_slices": "crank bearing in depth: slices along every roller, film and lives",
}
"""Stages of :func:`analyse` in order, with a one-line description (what the progress callback
reports)."""

ProgressCallback = Callable[[str, int, int], None]
"""``progress(stage, done, total)``: called with ``done = 0`` when a stage starts, with
``done = total`` when it ends, and after every crank angle of the ``cycle`` stage (``total`` =
number of angles). An exception raised by the callback (e.g. KeyboardInterrupt) aborts the
analysis."""


class Stages:
    """Times named stages and reports them to an optional progress callback.

    Parameters
    ----------
    progress : ProgressCallback, optional
    descriptions : dict
        Stage name → one-line description (logged at INFO level when the stage starts).
    """

    def __init__(self, progress: ProgressCallback | None, descriptions: Mapping[str, str] = STAGES):
        self.progress = progress
        self.descriptions = descriptions
        self.seconds: dict[str, float] = {}

    def start(self, name: str, total: int = 1) -> float:
        """Report the start of stage ``name``; returns the start time (``time.perf_counter``)."""
        log.info("%s", self.descriptions.get(name, name))
        if self.progress is not None:
            self.progress(name, 0, total)
        return time.perf_counter()

    def tick(self, name: str, done: int, total: int) -> None:
        """Report progress within stage ``name``."""
        if self.progress is not None:
            self.progress(name, done, total)

    def end(self, name: str, started: float, total: int = 1) -> None:
        """Record the wall time of stage ``name`` (s) and report its end."""
        self.seconds[name] = time.perf_counter() - started
        if self.progress is not None:
            self.progress(name, total, total)


class StageSteps:
    """``progress(done, total)`` of a library function's steps within stage ``name`` of ``stages``
    (``extra`` steps of the stage follow the function's); the last step is reported by
    :meth:`end`, which ends the stage."""

    def __init__(self, stages: Stages, name: str, extra: int = 0):
        self.stages, self.name, self.extra, self.total = stages, name, extra, 1

    def __call__(self, done: int, total: int) -> None:
        self.total = total + self.extra
        if done < self.total:
            self.stages.tick(self.name, done, self.total)

    def end(self, started: float) -> None:
        """End the stage started at ``started`` (:meth:`Stages.start`)."""
        self.stages.end(self.name, started, self.total)


def timed(function: Callable[..., Any], *args: Any, **kwargs: Any) -> tuple[Any, float]:
    """``(function(*args, **kwargs), wall time in s)``."""
    t0 = time.perf_counter()
    return function(*args, **kwargs), time.perf_counter() - t0
