"""The one figure factory and the one way a figure is saved, for every plot of every command.

A figure is a :class:`matplotlib.figure.Figure` on its own Agg canvas, never one of
:mod:`matplotlib.pyplot`: no global backend is touched (a notebook's inline backend is left alone)
and no display is needed. Matplotlib is imported only inside these functions: the solver never
needs it, and importing :mod:`rvfem` must not load it.

Every PNG is written at :data:`DPI` dots per inch with the figure's own extent (no tight bounding
box: each plot lays itself out with ``tight_layout``, so its pixel size follows from its size in
inches alone). The picture of the mesh asks for its own, finer resolution
(:func:`rvfem.outputs.plots.mesh_plot`).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["DPI", "PNG_COMPRESS_LEVEL", "new_figure", "save_figure"]

DPI = 120
"""Resolution of every plot's PNG, dots per inch."""

PNG_COMPRESS_LEVEL = 3
"""zlib level of the plots' PNG files (0-9). The plots are large white areas with thin lines and
text: level 3 encodes them in about two thirds of the time of zlib's default (6, what matplotlib
asks for otherwise), with the same pixels; the files of a run come out about 10 % smaller together
(the mesh picture a quarter smaller, the line plots up to a fifth larger)."""


def new_figure(size: tuple[float, float]) -> Figure:
    """An empty figure of ``size`` (width, height in inches) on an Agg canvas.

    Parameters
    ----------
    size : (float, float)
        Width and height, inches.

    Returns
    -------
    matplotlib.figure.Figure
        Add its axes with ``fig.subplots(...)`` or ``fig.add_subplot(...)``.
    """
    from matplotlib.backends.backend_agg import (
        FigureCanvasAgg,  # drawing only: matplotlib is a heavy import the solver never needs
    )
    from matplotlib.figure import (
        Figure,  # drawing only: matplotlib is a heavy import the solver never needs
    )

    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    return fig


def _drop_layout_placeholder(fig: Figure) -> None:
    """Forget the do-nothing layout engine ``fig.tight_layout()`` leaves behind.

    ``tight_layout`` lays the figure out once and then sets a placeholder layout engine that does
    nothing; but ``savefig`` sees *a* layout engine and draws the whole figure once more (with
    rendering switched off) before the real drawing, for a layout that is already done (a tenth
    to a fifth of a plot's time). Without the placeholder the PNG is the same, drawn once. A
    layout engine that lays out (constrained, or the rcParams' automatic layouts) is kept.
    """
    import matplotlib as mpl  # drawing only: matplotlib is a heavy import the solver never needs
    from matplotlib.layout_engine import PlaceHolderLayoutEngine

    automatic = mpl.rcParams["figure.autolayout"] or mpl.rcParams["figure.constrained_layout.use"]
    if isinstance(fig.get_layout_engine(), PlaceHolderLayoutEngine) and not automatic:
        fig.set_layout_engine(None)


def save_figure(fig: Figure, path: str | os.PathLike[str], *, dpi: int = DPI) -> Path:
    """Write ``fig`` as a PNG at ``path`` (its folder is created if missing) and close it.

    The figure is cleared once written (its artists and their data are released: a figure of
    :func:`new_figure` is held by no registry, so this is all that closing it means).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure, from :func:`new_figure`.
    path : path-like
        PNG to write.
    dpi : int
        Resolution, dots per inch (:data:`DPI` unless a picture needs its own).

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _drop_layout_placeholder(fig)
    fig.savefig(path, dpi=dpi, bbox_inches=None, pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
    fig.clear()
    return path
