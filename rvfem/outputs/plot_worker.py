"""Matplotlib figures drawn by a child process while the caller computes (:class:`PlotWorker`).

Importing Matplotlib and drawing a few figures costs a command about a second of one core. A
command that solves for longer than that (``rvfem hysteresis``, ``rvfem wear``) starts a
:class:`PlotWorker` first: its child process (:class:`rvfem._child.ChildProcess`) imports
Matplotlib on the other core while the command solves, and draws each figure as soon as it is
submitted. The stress images of ``rvfem run`` have their own worker
(:class:`rvfem.outputs.render.RenderWorker`), which also checks off-screen rendering.
"""

from __future__ import annotations

import importlib
import logging
import pickle
from collections.abc import Callable
from concurrent.futures import Future

from rvfem._child import ChildProcess, ChildProcessEnded, call_with_keywords

log = logging.getLogger(__name__)

__all__ = ["PlotWorker"]

_WARM_MODULES = ("matplotlib.backends.backend_agg", "matplotlib.figure", "rvfem.outputs.figures")
"""What the child imports before the first figure."""


def _warm_up() -> None:
    """In the child: import Matplotlib's Agg canvas and figure (:mod:`rvfem.outputs.figures`)."""
    for name in _WARM_MODULES:
        importlib.import_module(name)


class PlotWorker:
    """Figures drawn by a child process, in the order submitted, while this process goes on.

    The child starts at once and imports Matplotlib. :meth:`submit` hands it one figure: a
    module-level function (importable by name) and its arguments (pickled), which writes its
    file. :meth:`wait` waits for every figure submitted and raises the exception of a drawing
    that failed. Where no child process can be started, or where it ends before a figure is
    drawn, the figure is drawn in this process instead (logged), so a figure is never lost to
    the worker. Use it as a context manager: leaving the block without an exception waits for
    the figures; the child is closed in any case.

    Parameters
    ----------
    name : str
        What the figures are for (in the child's command line and error messages).

    Examples
    --------
    >>> with PlotWorker("hysteresis plots") as plots:            # doctest: +SKIP
    ...     loops = solve()                                     # meanwhile Matplotlib is imported
    ...     plots.submit(hysteresis_plot, "plots/hysteresis.png", torque, branch, mean, figures, T)
    ...     shares = solve_more()                               # meanwhile the plot is drawn
    """

    def __init__(self, name: str = "plots"):
        self.name = name
        self._jobs: list[tuple[Future, Callable, tuple, dict]] = []
        self._child: ChildProcess | None = None
        try:
            self._child = ChildProcess(name, forward_logs=True)
            self._child.call(_warm_up)
        except OSError as exc:  # pragma: no cover - the interpreter itself cannot be started
            log.info("the %s are drawn in this process: %s", name, exc)

    def submit(self, function: Callable, *args, **kwargs) -> None:
        """Draw ``function(*args, **kwargs)`` in the child (here, when there is no child)."""
        if self._child is None:
            function(*args, **kwargs)
            return
        try:
            future = self._child.call(call_with_keywords, function, args, kwargs)
        except (pickle.PicklingError, AttributeError, TypeError) as exc:
            raise TypeError(f"{getattr(function, '__name__', function)!r} cannot be handed to the {self.name} "
                            f"process (a module-level function with picklable arguments): {exc}") from exc
        self._jobs.append((future, function, args, kwargs))

    def wait(self) -> None:
        """Wait for every figure submitted; draw here those the child ended before drawing.

        Raises
        ------
        Exception
            The exception of a drawing that failed (the first one).
        """
        jobs, self._jobs = self._jobs, []
        for future, function, args, kwargs in jobs:
            try:
                future.result()
            except ChildProcessEnded as exc:
                log.info("the %s process ended (%s): %s drawn in this process", self.name, exc,
                         getattr(function, "__name__", function))
                function(*args, **kwargs)

    def close(self) -> None:
        """End the child process (a figure it is drawing is abandoned)."""
        child, self._child = self._child, None
        if child is not None:
            child.close()

    def __enter__(self) -> PlotWorker:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            if exc_type is None:
                self.wait()
        finally:
            self.close()
