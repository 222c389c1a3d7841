"""The rendering check: whether VTK can render off-screen here, found out in a child process.

A VTK that cannot open any OpenGL context may crash the interpreter instead of raising, so
:func:`check_rendering` renders a tiny scene (:data:`_PROBE`) in a child Python process first and
turns a failure into a :class:`~rvfem.errors.RenderError` with VTK's reason; the answer is kept for
the process (:data:`_probe_result`). On Linux VTK's EGL render window is selected
(``VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow``, unless the variable is already set) before VTK
is imported, so VTK neither looks for an X server nor warns about one.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import subprocess
import sys

from rvfem.errors import RenderError

RENDER_WINDOW_VARIABLE = "VTK_DEFAULT_OPENGL_WINDOW"
"""Environment variable through which VTK ≥ 9.4 chooses its OpenGL render window class."""

DEFAULT_RENDER_WINDOW = "vtkEGLRenderWindow"
"""Render window used when the variable is not set (Linux): off-screen EGL, no X server."""

_PROBE = r"""
import pyvista as pv
pl = pv.Plotter(off_screen=True, window_size=(64, 48))
pl.add_mesh(pv.Sphere(), color="red")
img = pl.screenshot(return_img=True)
name = pl.render_window.GetClassName()
pl.close()
print("RVFEM-RENDER", int(img.std() > 0), name)
"""

_probe_result: str | RenderError | None = None


def _render_environment() -> dict[str, str]:
    env = dict(os.environ)
    if sys.platform.startswith("linux"):
        env.setdefault(RENDER_WINDOW_VARIABLE, DEFAULT_RENDER_WINDOW)
    return env


def _select_render_window() -> None:
    """Choose the off-screen render window before VTK creates one (Linux only)."""
    if sys.platform.startswith("linux"):
        os.environ.setdefault(RENDER_WINDOW_VARIABLE, DEFAULT_RENDER_WINDOW)


def _vtk_messages(stderr: str) -> str:
    text = re.sub(r"\x1b\[[0-9;]*m", "", stderr)
    found = []
    for line in text.splitlines():
        m = re.search(r"(?:WARN|ERR)\|\s*(.*)", line)
        msg = (m.group(1) if m else "").strip()
        if msg and msg not in found:
            found.append(msg)
    if not found:
        tail = [ln.strip() for ln in text.splitlines() if ln.strip()]
        found = tail[-1:]
    return "; ".join(found[:3])


def check_rendering(timeout_s: float = 120.0) -> str:
    """Make sure VTK can render off-screen here; the result is cached for the process.

    Renders a small scene in a child Python process (a VTK without a usable OpenGL context can
    crash its process) with the same render-window selection as the image functions.

    Parameters
    ----------
    timeout_s : float
        Give up after this many seconds.

    Returns
    -------
    str
        The VTK render window class that worked (e.g. ``vtkEGLRenderWindow``).

    Raises
    ------
    RenderError
        With VTK's own reason (no EGL/OSMesa library, no X server, crash) and what to do.
    """
    global _probe_result
    if isinstance(_probe_result, str):
        return _probe_result
    if isinstance(_probe_result, RenderError):
        raise _probe_result
    env = _render_environment()
    chosen = env.get(RENDER_WINDOW_VARIABLE, "VTK's default")
    try:
        proc = subprocess.run([sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True,
                              timeout=timeout_s)
        rc, out, err = proc.returncode, proc.stdout, proc.stderr
    except subprocess.TimeoutExpired:
        rc, out, err = None, "", f"no image after {timeout_s:g} s"
    except OSError as exc:  # pragma: no cover - cannot start the interpreter itself
        rc, out, err = None, "", str(exc)
    line = next((ln for ln in out.splitlines() if ln.startswith("RVFEM-RENDER ")), "")
    parts = line.split()
    if rc == 0 and len(parts) == 3 and parts[1] == "1":
        _probe_result = parts[2]
        return _probe_result
    _probe_result = _probe_error(rc, blank=rc == 0 and bool(parts), stderr=err, chosen=chosen)
    raise _probe_result


def _probe_error(rc: int | None, *, blank: bool, stderr: str, chosen: str) -> RenderError:
    """The error of a failed rendering check: the probe's exit code (negative: killed by a signal;
    None: it could not start or did not finish), whether it rendered a blank image, its stderr."""
    if rc is not None and rc < 0:
        reason = f"VTK crashed (signal {-rc})"
    elif blank:
        reason = "VTK rendered a blank image"
    else:
        reason = "VTK could not render"
    details = _vtk_messages(stderr)
    return RenderError(
        f"off-screen rendering is not available ({reason} with render window {chosen}"
        f"{': ' + details if details else ''}); install the EGL runtime (e.g. Debian/Ubuntu 'libegl1') "
        f"or OSMesa, set {RENDER_WINDOW_VARIABLE} to a render window that works here, "
        "or skip the images (rvfem run --no-images)"
    )


def _pyvista():
    check_rendering()
    _select_render_window()
    import pyvista  # rendering only (the render worker): pyvista and VTK are heavy imports

    return pyvista



def _probe_in_child(code: str) -> list[str]:
    """In the render worker's child process: run the rendering check's program (:data:`_PROBE`),
    keep its answer for the process (its renderer need not check again) and return the words of
    its ``RVFEM-RENDER`` line (``[]`` if it printed none)."""
    global _probe_result
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "<rendering check>", "exec"), {"__name__": "__rvfem_probe__"})
    line = next((ln for ln in out.getvalue().splitlines() if ln.startswith("RVFEM-RENDER ")), "")
    words = line.split()
    if len(words) == 3 and words[1] == "1":
        _probe_result = words[2]
    return words
