"""Off-screen images of the disc with PyVista/VTK: stresses on the deformed disc, close-ups.

The picture of the mesh is drawn with matplotlib (:func:`rvfem.outputs.plots.mesh_plot`), which needs no
OpenGL.

No display is needed. On Linux VTK's EGL render window is selected
(``VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow``, unless the variable is already set) before VTK is
imported, so VTK neither looks for an X server nor warns about one. Because a VTK that cannot open
any OpenGL context may crash the interpreter instead of raising, :func:`check_rendering` first
renders a tiny scene in a child process and turns a failure into a :class:`~rvfem.errors.
RenderError` with the reason; the image functions call it before touching VTK.

A series of stress images is drawn with one :class:`StressRenderer`: one plotter (one OpenGL
context), the disc mesh built once and updated per image, the PNG files written by a background
thread. :class:`RenderWorker` does it in a child process (:class:`rvfem._child.ChildProcess`)
while the caller computes. PyVista is imported only inside the functions that draw (importing
:mod:`rvfem.outputs.render` is cheap).

The module gathers three of one concern each:

- :mod:`rvfem.outputs.render_check`: the rendering check (:func:`check_rendering`);
- :mod:`rvfem.outputs.render_scene`: the drawing (:class:`StressScene`, :class:`StressRenderer`,
  :func:`stress_image`, :func:`nice_factor`);
- :mod:`rvfem.outputs.render_worker`: the child process (:class:`RenderWorker`).
"""

from __future__ import annotations

from rvfem.outputs.render_check import (
    DEFAULT_RENDER_WINDOW,
    RENDER_WINDOW_VARIABLE,
    _pyvista,
    check_rendering,
)
from rvfem.outputs.render_scene import (
    ABOVE_COLOUR,
    ANTI_ALIASING,
    BACKGROUND,
    COLORMAP,
    PNG_COMPRESS_LEVEL,
    StressRenderer,
    StressScene,
    _Shapes,
    nice_factor,
    stress_image,
)
from rvfem.outputs.render_worker import Call, ImageJob, RenderWorker

__all__ = [
    "RENDER_WINDOW_VARIABLE",
    "DEFAULT_RENDER_WINDOW",
    "RenderWorker",
    "StressRenderer",
    "StressScene",
    "check_rendering",
    "nice_factor",
    "stress_image",
]

_REEXPORTED = (ABOVE_COLOUR, ANTI_ALIASING, BACKGROUND, COLORMAP, PNG_COMPRESS_LEVEL, Call, ImageJob, _Shapes, _pyvista)
