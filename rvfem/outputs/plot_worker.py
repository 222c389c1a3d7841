"""The plots of a run without images drawn by a child process while this one writes the other files.

With images, the render worker's child process draws the plots beside the stress images
(:class:`rvfem.outputs.render.RenderWorker`). Without them (``rvfem run --no-images``) a
:class:`PlotWorker` does it: a child process (:class:`rvfem._child.ChildProcess`) started with the
run imports matplotlib and the plot functions while the analysis runs (about half a second of
imports the writers no longer wait for), and once the analysis is done it draws the plots
(:func:`rvfem.outputs.summary.plot_calls`) while this process writes the tables and the VTK files.
The ``plots`` stage is then the wait for them.

Where the child cannot be started or ends before it answers, the plots are drawn in this process:
the files are the same either way.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from concurrent.futures import Future

from rvfem._child import ChildProcess, ChildProcessEnded
from rvfem.outputs import plots, roller_outputs

log = logging.getLogger(__name__)

__all__ = ["PendingPlots", "PlotWorker"]

_PLOT_MODULES = (plots, roller_outputs)
"""The modules of the plot functions (:func:`rvfem.outputs.summary.plot_calls`): the child imports
them with this module, before the first plot."""


def _import_plotting() -> None:
    """In the child: import matplotlib's figure and Agg canvas ahead of the plots (the plot
    modules came with this module)."""
    from matplotlib.backends import backend_agg  # noqa: F401  drawing only: imported in the child
    from matplotlib.figure import Figure  # noqa: F401


def _call(function: Callable, kwargs: dict):
    """In the child: ``function(**kwargs)`` (:class:`ChildProcess` passes positional arguments only)."""
    return function(**kwargs)


class PendingPlots:
    """Plots a :class:`PlotWorker` is drawing; :meth:`calls_result` waits for them."""

    def __init__(self, calls: Sequence[tuple[Callable, dict]], futures: Sequence[Future] | None):
        self._calls, self._futures = list(calls), None if futures is None else list(futures)

    def calls_result(self) -> list:
        """Wait for the plots and return what the calls returned (their PNG paths), in order.
        Those the child did not draw (it ended, or could not be started) are drawn here.

        Raises
        ------
        Exception
            What a call raised.
        """
        if self._futures is None:
            return [function(**kwargs) for function, kwargs in self._calls]
        out = []
        for (function, kwargs), future in zip(self._calls, self._futures):
            try:
                out.append(future.result())
            except ChildProcessEnded as exc:
                log.warning("the process drawing the plots ended (%s); drawing them here", exc)
                out.append(function(**kwargs))
        return out


class PlotWorker:
    """A child process that imports matplotlib at once and draws the plots it is given later.

    Examples
    --------
    >>> with PlotWorker() as worker:                                   # doctest: +SKIP
    ...     analysis = analyse(case)                    # the child imports matplotlib meanwhile
    ...     pending = worker.submit(plot_calls(analysis, folder))
    ...     write_tables(analysis, folder)              # while the child draws
    ...     paths = pending.calls_result()
    """

    def __init__(self) -> None:
        self._child: ChildProcess | None = None
        try:
            self._child = ChildProcess("plots", forward_logs=True)
        except OSError as exc:  # pragma: no cover - cannot start the interpreter itself
            log.info("cannot start a process for the plots (%s); they are drawn in this process", exc)
            return
        self._child.call(_import_plotting)

    def __enter__(self) -> PlotWorker:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def submit(self, calls: Sequence[tuple[Callable, dict]]) -> PendingPlots:
        """Have the child draw ``calls`` (function of :mod:`rvfem.outputs.plots`, keyword arguments;
        functions importable by name, arguments picklable), one after the other; returns at once."""
        calls = list(calls)
        if self._child is None:
            return PendingPlots(calls, None)
        return PendingPlots(calls, [self._child.call(_call, function, dict(kwargs)) for function, kwargs in calls])

    def close(self) -> None:
        """End the child process (at once if it is still drawing)."""
        if self._child is not None:
            child, self._child = self._child, None
            child.close()
