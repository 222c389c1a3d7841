"""The plot worker of a run without images (rvfem.outputs.plot_worker): its child process draws
the same files this process would, and where the child is gone the plots are drawn here."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from rvfem.outputs import plots
from rvfem.outputs.plot_worker import PlotWorker


def _calls(folder):
    theta = np.radians(np.arange(0.0, 360.0, 10.0))
    count = 20 + (np.arange(len(theta)) % 3)
    return [(plots.pins_in_contact_plot, dict(path=folder / "pins_in_contact.png", theta=theta, count=count,
                                              total=40)),
            (plots.pin_forces_plot, dict(path=folder / "pin_forces.png", pin_index=np.arange(1, 11),
                                         fe=np.linspace(0.0, 900.0, 10), classical=None, theta_deg=15.0))]


def _pixels(path):
    with Image.open(path) as image:
        return np.asarray(image)


def test_the_child_draws_the_files_this_process_would(tmp_path):
    here, there = tmp_path / "here", tmp_path / "there"
    expected = [function(**kwargs) for function, kwargs in _calls(here)]
    with PlotWorker() as worker:
        drawn = worker.submit(_calls(there)).calls_result()
    assert [p.name for p in drawn] == [p.name for p in expected]
    for a, b in zip(expected, drawn):
        assert b.parent == there
        assert np.array_equal(_pixels(a), _pixels(b))


def test_plots_a_closed_worker_did_not_draw_are_drawn_here(tmp_path):
    worker = PlotWorker()
    pending = worker.submit(_calls(tmp_path))
    worker.close()   # ends the child, perhaps before it drew
    drawn = pending.calls_result()
    assert [p.name for p in drawn] == ["pins_in_contact.png", "pin_forces.png"]
    assert all(p.is_file() and _pixels(p).std() > 0 for p in drawn)


def test_an_error_of_a_plot_is_raised_here(tmp_path):
    with PlotWorker() as worker:
        pending = worker.submit([(plots.pin_forces_plot, dict(path=tmp_path / "x.png", pin_index=np.arange(1, 4),
                                                              fe=np.ones(5), classical=None, theta_deg=0.0))])
        with pytest.raises(ValueError):
            pending.calls_result()
