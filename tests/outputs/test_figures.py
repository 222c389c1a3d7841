"""The one figure factory and its save function (rvfem.outputs.figures): every plot's PNG has the
pixel size its size in inches times the resolution gives, is written into a folder made for it,
and leaves no figure behind and no global backend touched."""

from __future__ import annotations

import subprocess
import sys

from PIL import Image

from rvfem.outputs.figures import DPI, new_figure, save_figure


def test_saved_png_is_its_size_in_inches_times_the_resolution(tmp_path):
    fig = new_figure((7.0, 3.5))
    fig.subplots().plot([0.0, 1.0], [0.0, 1.0])
    path = save_figure(fig, tmp_path / "new" / "folder" / "line.png")
    with Image.open(path) as image:
        assert image.size == (round(7.0 * DPI), round(3.5 * DPI))
    assert fig.axes == []   # closed: its axes and their artists released


def test_a_picture_may_ask_for_its_own_resolution(tmp_path):
    fig = new_figure((2.0, 1.0))
    fig.subplots()
    with Image.open(save_figure(fig, tmp_path / "fine.png", dpi=150)) as image:
        assert image.size == (300, 150)


def test_the_factory_needs_no_pyplot_and_leaves_the_backend_alone(tmp_path):
    script = f"""
import sys
import matplotlib
matplotlib.use("svg")     # stands for a notebook's inline backend
from rvfem.outputs.figures import new_figure, save_figure
fig = new_figure((3.0, 2.0))
fig.subplots().plot([0, 1], [1, 0])
save_figure(fig, {str(tmp_path / "p.png")!r})
assert matplotlib.get_backend() == "svg", matplotlib.get_backend()
assert "matplotlib.pyplot" not in sys.modules
print("ok")
"""
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def _laid_out_figure():
    fig = new_figure((5.0, 3.0))
    axes = fig.subplots(1, 2)
    axes[0].plot([0.0, 1.0, 2.0], [1.0, 3.0, 2.0], label="a line")
    axes[1].bar([1, 2, 3], [3.0, 1.0, 2.0])
    axes[0].set_title("a title that tight_layout makes room for")
    axes[0].legend()
    fig.tight_layout()
    return fig


def test_a_laid_out_plot_is_drawn_once_with_the_pixels_matplotlib_draws(tmp_path):
    import numpy as np

    reference = _laid_out_figure()
    reference.savefig(tmp_path / "reference.png", dpi=DPI)   # matplotlib's own savefig: drawn twice

    fig = _laid_out_figure()
    draws = []
    draw = fig.draw
    fig.draw = lambda renderer: (draws.append(renderer), draw(renderer))[1]
    path = save_figure(fig, tmp_path / "once.png")
    assert len(draws) == 1
    with Image.open(path) as once, Image.open(tmp_path / "reference.png") as ref:
        assert np.array_equal(np.asarray(once), np.asarray(ref))
