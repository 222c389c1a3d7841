"""Off-screen rendering in a child process (:class:`RenderWorker`), served by
:class:`rvfem._child.ChildProcess`: the rendering check, then one series of stress images drawn
while the calling process does other work, and other drawings (the mesh picture) beside them.

The child's work is a sequence of calls of the module-level functions below: the check
(:func:`rvfem.outputs.render_check._probe_in_child`), :func:`_open_renderer`, one :func:`_draw`
per image and :func:`_close_renderer`, one after the other in the child's main thread; the other
drawings (:func:`rvfem._child.call_with_keywords`) in its second thread.
"""

from __future__ import annotations

import pickle
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from pathlib import Path

from rvfem._child import ChildProcess, ChildProcessEnded, call_with_keywords
from rvfem.errors import RenderError
from rvfem.outputs import render_check
from rvfem.outputs.render_check import RENDER_WINDOW_VARIABLE, _probe_error, _probe_in_child, _vtk_messages
from rvfem.outputs.render_scene import _ANTI_ALIASING, ANTI_ALIASING, PNG_COMPRESS_LEVEL, StressRenderer, StressScene

__all__ = ["Call", "ImageJob", "RenderWorker"]

ImageJob = tuple[str | Path, StressScene, dict]
"""One stress image for :meth:`RenderWorker.draw`: (PNG path, scene, keyword arguments of
:meth:`StressRenderer.write`)."""

Call = tuple[Callable, dict]
"""Another drawing for :meth:`RenderWorker.submit`: (function, keyword arguments). The function
must be importable by name (a module-level function, e.g. :func:`rvfem.outputs.plots.mesh_plot`)."""


# --------------------------------------------------------------------------------------------
# In the child process
# --------------------------------------------------------------------------------------------

_renderer: StressRenderer | None = None
"""The child's renderer (one plotter, one OpenGL context), from :func:`_open_renderer`."""


def _open_renderer(window_size: tuple[int, int], compress_level: int, anti_aliasing: str) -> None:
    """Make the child's renderer and warm it up (PyVista imported, plotter open)."""
    global _renderer
    _renderer = StressRenderer(window_size, compress_level=compress_level, anti_aliasing=anti_aliasing)
    _renderer.warm_up()


def _draw(path: Path, scene: StressScene, options: dict) -> Path:
    """Draw one stress image (its PNG file is written by the renderer's background thread)."""
    if _renderer is None:
        raise RenderError("the render process has no renderer")
    return _renderer.write(path, scene, **options)


def _close_renderer() -> tuple[int, str]:
    """Close the renderer once every PNG file is complete (raising a failed write); its frames
    and the anti-aliasing it used."""
    global _renderer
    renderer, _renderer = _renderer, None
    if renderer is None:
        raise RenderError("the render process has no renderer")
    renderer.close()
    return renderer.frames, renderer.anti_aliasing


# --------------------------------------------------------------------------------------------
# In the calling process
# --------------------------------------------------------------------------------------------


class RenderWorker:
    """Off-screen rendering in a child process: the rendering check, then one series of stress
    images drawn while the calling process does other work.

    The child process starts at once. It renders the small scene of
    :func:`~rvfem.outputs.render_check.check_rendering` (the check: a VTK without a usable OpenGL
    context may crash its process, and here that is not the caller's), then imports PyVista and
    opens its plotter, all while the caller computes. :meth:`check` waits for the check's result;
    :meth:`draw` hands over the images and waits for them. Log records of the child (e.g. the
    anti-aliasing fallback) are logged again here.

    Parameters
    ----------
    window_size : (int, int)
        Image size in pixels (width, height).
    compress_level : int
        zlib level of the PNG files.
    anti_aliasing : {"fxaa", "msaa", "none"}
        As for :class:`~rvfem.outputs.render_scene.StressRenderer`.
    timeout_s : float
        Give up the check after this many seconds.

    Attributes
    ----------
    frames : int
        Frames rendered by :meth:`draw`.
    anti_aliasing : str
        The anti-aliasing used (``"msaa"`` after a fallback).

    Examples
    --------
    >>> with RenderWorker((1500, 1100)) as worker:                  # doctest: +SKIP
    ...     worker.check()                      # before a long computation
    ...     scenes = ...
    ...     worker.draw([(f"stress_{k}.png", scene, {}) for k, scene in enumerate(scenes)])
    """

    def __init__(self, window_size: tuple[int, int] = (1500, 1100), *, compress_level: int = PNG_COMPRESS_LEVEL,
                 anti_aliasing: str = ANTI_ALIASING, timeout_s: float = 120.0):
        if anti_aliasing not in _ANTI_ALIASING:
            raise ValueError(f"anti_aliasing must be one of {', '.join(_ANTI_ALIASING)}, not {anti_aliasing!r}")
        self.window_size = (int(window_size[0]), int(window_size[1]))
        self.anti_aliasing = anti_aliasing
        self.frames = 0
        self._timeout_s = float(timeout_s)
        env = render_check._render_environment()
        self._chosen = env.get(RENDER_WINDOW_VARIABLE, "VTK's default")
        self._checked: str | RenderError | None = None
        self._jobs: list | None = None
        self._calls: list[Future] = []
        self._images: list[Future] = []
        self._finish: Future | None = None
        self._waited = False
        self._child: ChildProcess | None = None
        if isinstance(render_check._probe_result, RenderError):   # this process knows already: no child
            self._checked = render_check._probe_result
            return
        try:
            self._child = ChildProcess("render", env=env, forward_logs=True)
        except OSError as exc:  # pragma: no cover - cannot start the interpreter itself
            self._checked = _probe_error(None, blank=False, stderr=str(exc), chosen=self._chosen)
            return
        self._started = time.monotonic()
        self._probe = self._child.call(_probe_in_child, render_check._PROBE)
        self._opened = self._child.call(_open_renderer, self.window_size, int(compress_level), anti_aliasing)

    def __enter__(self) -> RenderWorker:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close()

    def check(self, wait: bool = True) -> str | None:
        """Wait for the rendering check of the child process.

        Parameters
        ----------
        wait : bool
            Wait for the check; else return None if it has not finished yet.

        Returns
        -------
        str or None
            The VTK render window class that worked (e.g. ``vtkEGLRenderWindow``); None if the
            check is still running (``wait=False``).

        Raises
        ------
        RenderError
            As :func:`~rvfem.outputs.render_check.check_rendering`: off-screen rendering is not
            available, with VTK's reason.
        """
        if isinstance(self._checked, str):
            return self._checked
        if isinstance(self._checked, RenderError):
            raise self._checked
        remaining = self._started + self._timeout_s - time.monotonic()
        if not wait and not self._probe.done() and remaining > 0:
            return None
        blank = False
        try:
            words = self._probe.result(timeout=max(0.0, remaining))
        except FutureTimeout:
            rc, stderr = None, f"no image after {self._timeout_s:g} s"
        except ChildProcessEnded as exc:   # VTK crashed the process
            rc, stderr = exc.returncode, exc.stderr
        except Exception as exc:  # noqa: BLE001 - the check raised (e.g. PyVista does not import)
            rc, stderr = 1, f"{type(exc).__name__}: {exc}"
        else:
            if len(words) == 3 and words[1] == "1":
                self._checked = render_check._probe_result = words[2]
                return words[2]
            rc, stderr, blank = 0, "", bool(words)   # it rendered, but nothing
        self._checked = render_check._probe_result = _probe_error(rc, blank=blank, stderr=stderr,
                                                                  chosen=self._chosen)
        self.close()
        raise self._checked

    def draw(self, jobs: Sequence[ImageJob], *, calls: Sequence[Call] = (),
             tick: Callable[[int], None] | None = None) -> list:
        """Draw a series of stress images in the child process and wait for them (:meth:`submit`
        and :meth:`wait`).

        Parameters
        ----------
        jobs : sequence of (path, StressScene, dict)
            PNG file, scene and keyword arguments of :meth:`StressRenderer.write`.
        calls : sequence of (function, dict)
            Other drawings (see :meth:`submit`).
        tick : callable, optional
            ``tick(done)`` after each image drawn (its PNG file may still be being written).

        Returns
        -------
        list
            The PNG files, all complete, then what the calls returned.
        """
        self.submit(jobs, calls=calls)
        return self.wait(tick=tick)

    def start_calls(self, calls: Sequence[Call]) -> list[int]:
        """Hand over drawings that need no stress images, which the child process makes in its
        second thread one after the other (e.g. the mesh picture while the caller still computes,
        or the plots while the stress images are drawn); what they return comes with
        :meth:`wait_calls` and :meth:`wait` like the calls of :meth:`submit`. Before or after
        :meth:`submit`, as long as :meth:`wait` has not begun; returns at once.

        Parameters
        ----------
        calls : sequence of (function, dict)
            As for :meth:`submit`.

        Returns
        -------
        list of int
            The numbers of the calls (for :meth:`wait_calls`).

        Raises
        ------
        RenderError
            Off-screen rendering is not available, or the worker is waited for already.
        """
        self.check()
        if self._waited:
            raise RenderError("calls must be started before the render worker is waited for")
        return self._start(calls)

    def _send(self, function: Callable, *args, background: bool = False) -> Future:
        if self._child is None:
            raise RenderError("the render worker is closed")
        try:
            return self._child.call(function, *args, background=background)
        except (pickle.PicklingError, AttributeError, TypeError) as exc:
            raise TypeError(f"the images and calls cannot be handed to the render process "
                            f"(functions must be importable by name): {exc}") from exc

    def _start(self, calls: Sequence[Call]) -> list[int]:
        first = len(self._calls)
        for function, kwargs in calls:
            self._calls.append(self._send(call_with_keywords, function, (), dict(kwargs), background=True))
        return list(range(first, len(self._calls)))

    def submit(self, jobs: Sequence[ImageJob], *, calls: Sequence[Call] = ()) -> list[int]:
        """Hand a series of stress images over to the child process, which starts drawing them
        (once per worker); :meth:`wait` waits for them.

        Parameters
        ----------
        jobs : sequence of (path, StressScene, dict)
            PNG file, scene and keyword arguments of :meth:`StressRenderer.write`.
        calls : sequence of (function, dict)
            Other drawings the child process makes in its second thread while it renders the
            images (e.g. :func:`rvfem.outputs.plots.mesh_plot`: matplotlib, no OpenGL), one after
            the other. Each function must be importable by name; its arguments and its return
            value are pickled.

        Returns
        -------
        list of int
            The numbers of the calls (for :meth:`wait_calls`; they follow those of
            :meth:`start_calls`).

        Raises
        ------
        RenderError
            Off-screen rendering is not available, or the worker has drawn its series already.
        """
        self.check()
        if self._jobs is not None:
            raise RenderError("a render worker draws one series of images")
        jobs = [(Path(path), scene, dict(options)) for path, scene, options in jobs]
        self._jobs = jobs
        numbers = self._start(calls)
        self._images = [self._send(_draw, path, scene, options) for path, scene, options in jobs]
        self._finish = self._send(_close_renderer)
        return numbers

    def wait(self, *, tick: Callable[[int], None] | None = None) -> list:
        """Wait for the images and the calls of :meth:`submit`.

        Parameters
        ----------
        tick : callable, optional
            ``tick(done)`` after each image drawn (its PNG file may still be being written).

        Returns
        -------
        list
            The PNG files, all complete, then what the calls returned, in the order of their
            numbers (those of :meth:`start_calls` first).

        Raises
        ------
        RenderError
            An image is blank, or the child process ended unexpectedly.
        OSError
            A PNG file could not be written.
        Exception
            What a call raised.
        """
        self._submitted()
        assert self._jobs is not None and self._finish is not None
        self._waited = True
        try:
            self._opened.result()
            for done, image in enumerate(self._images, 1):
                image.result()
                if tick is not None:
                    tick(done)
            self.frames, self.anti_aliasing = self._finish.result()
            results = [call.result() for call in self._calls]
        except ChildProcessEnded as exc:
            raise self._ended(exc) from None
        except BaseException:
            self.close()
            raise
        return [path for path, _, _ in self._jobs] + results

    def wait_calls(self, numbers: Sequence[int] | None = None) -> list:
        """Wait for the calls of these numbers (those :meth:`start_calls` and :meth:`submit`
        returned; all by default), which the child makes one after the other, and return what
        they returned.

        Raises
        ------
        RenderError
            The child process ended unexpectedly.
        Exception
            What a call raised.
        """
        self._submitted()
        chosen = range(len(self._calls)) if numbers is None else [int(j) for j in numbers]
        try:
            return [self._calls[j].result() for j in chosen]
        except ChildProcessEnded as exc:
            raise self._ended(exc) from None

    def _submitted(self) -> None:
        if self._jobs is None:
            raise RenderError("no images were submitted to the render worker")
        if self._child is None and not (self._finish is not None and self._finish.done()):
            raise RenderError("the render worker is closed")

    def _ended(self, exc: ChildProcessEnded) -> RenderError:
        """The error of a child process that ended before it answered (closing the worker)."""
        rc = exc.returncode
        details = _vtk_messages(exc.stderr)
        how = f"crashed (signal {-rc})" if rc is not None and rc < 0 else f"ended (exit code {rc})"
        self.close()
        return RenderError(f"the process drawing the stress images {how}{': ' + details if details else ''}")

    def close(self) -> None:
        """End the child process (at once if it is still drawing) and release its pipes."""
        if self._child is not None:
            child, self._child = self._child, None
            child.close()
