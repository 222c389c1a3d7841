"""Figures drawn by a child process (rvfem.outputs.plot_worker.PlotWorker): the same PNG as drawn
here, a drawing's error raised to the caller, and a figure drawn here when the child is gone."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from rvfem.outputs.accuracy import shares_plot
from rvfem.outputs.plot_worker import PlotWorker

SHARES = {"pin–flank contact": 0.05, "disc body": 0.24, "crank-bearing rollers": 0.29}


def _pixels(path):
    with Image.open(path) as image:
        return np.asarray(image)


def test_a_figure_of_the_child_is_the_figure_drawn_here(tmp_path):
    with PlotWorker("test plots") as plots:
        plots.submit(shares_plot, tmp_path / "child" / "shares.png", SHARES, title="shares")
    shares_plot(tmp_path / "here" / "shares.png", SHARES, title="shares")
    np.testing.assert_array_equal(_pixels(tmp_path / "child" / "shares.png"), _pixels(tmp_path / "here" / "shares.png"))


def test_a_drawing_that_fails_raises_its_error_to_the_caller(tmp_path):
    with pytest.raises(TypeError, match="not iterable"):
        with PlotWorker("test plots") as plots:
            plots.submit(shares_plot, tmp_path / "shares.png", None)        # shares: None


def test_a_figure_the_child_did_not_draw_is_drawn_here(tmp_path):
    plots = PlotWorker("test plots")
    plots._child._proc.kill()                    # the child is gone before the figure
    plots.submit(shares_plot, tmp_path / "shares.png", SHARES)
    plots.wait()
    plots.close()
    assert (tmp_path / "shares.png").stat().st_size > 5000


def test_a_function_that_cannot_be_handed_over_is_named(tmp_path):
    with PlotWorker("test plots") as plots:
        with pytest.raises(TypeError, match="module-level function"):
            plots.submit(lambda: None)
