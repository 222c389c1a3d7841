"""Off-screen stress images (:mod:`rvfem.outputs.render`) on a small synthetic disc.

A series of images drawn with one :class:`~rvfem.outputs.render.StressRenderer` must look exactly like the
same images drawn one by one with a plotter of their own (nothing of one image is left in the
next), with one rendered frame per image; the anti-aliasing fallback, the background PNG writer's
errors and the repeated shapes are checked too. The images are small so that the module takes a
few seconds (every test needs an OpenGL context).
"""

from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np
import pytest
from conftest import structured_annulus

from rvfem.errors import RenderError
from rvfem.outputs import render, render_check, render_scene

pytestmark = pytest.mark.slow

SIZE = (480, 352)


def _read(path):
    from PIL import Image

    with Image.open(path) as im:
        assert im.format == "PNG" and im.size == SIZE
        return np.asarray(im.convert("RGB")).astype(int)




@pytest.fixture(scope="module")
def scenes():
    """Three images of one disc: the whole disc with the contact spots clipped, a close-up, and
    the whole disc at another angle with nothing clipped (no "above" colour)."""
    try:
        render.check_rendering()
    except RenderError as exc:  # pragma: no cover - a machine without off-screen OpenGL
        pytest.skip(str(exc))
    points, triangles, boundaries = structured_annulus()
    x, y = points.T
    r = np.hypot(x, y)
    pins = 33.0 * np.column_stack([np.cos(np.linspace(0, 2 * np.pi, 16, endpoint=False)),
                                   np.sin(np.linspace(0, 2 * np.pi, 16, endpoint=False))])
    bores = 19.0 * np.column_stack([np.cos([0.5, 2.6, 4.7]), np.sin([0.5, 2.6, 4.7])])

    forces = np.array([[900.0, 300.0], [-500.0, 700.0], [0.0, -400.0]])

    def scene(angle, top):
        turn = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        vm = top * (0.2 + 0.8 * np.exp(-((x - 30 * math.cos(angle)) ** 2 + (y - 30 * math.sin(angle)) ** 2) / 20))
        return render.StressScene(
            points=points, triangles=triangles, boundaries=boundaries, von_mises=vm,
            deformation=1e-3 * np.column_stack([-y, x]) / r.max(), magnification=500.0, clim=(0.0, 80.0),
            pin_centres=pins, pin_radius=2.0, pin_loaded=np.cos(np.arctan2(*pins.T[::-1]) - angle) > 0.3,
            bore_centres=bores, bearing_forces=forces @ turn.T, rigid_forces=0.9 * forces @ turn.T, force_scale=0.01,
            title=f"test disc at {math.degrees(angle):.0f}°")

    full = scene(0.3, 120.0)
    close = dataclasses.replace(full, magnification=0.0, clim=(0.0, 120.0), title="close-up")
    other = scene(2.0, 60.0)
    at = (30 * math.cos(0.3), 30 * math.sin(0.3))
    return [(full, {}), (close, dict(focus=at, half_height=6.0, marker=at, show_edges=True)), (other, {})]


def test_a_series_looks_like_single_images(scenes, tmp_path):
    with render.StressRenderer(SIZE) as renderer:
        series = [renderer.write(tmp_path / f"series_{k}.png", s, **kw) for k, (s, kw) in enumerate(scenes)]
        assert renderer.frames == len(scenes)
    for k, (s, kw) in enumerate(scenes):
        single = render.stress_image(tmp_path / f"single_{k}.png", s, window_size=SIZE, **kw)
        a, b = _read(series[k]), _read(single)
        differ = np.count_nonzero(np.abs(a - b).max(axis=2))
        assert differ <= 2, f"image {k}: {differ} pixels differ from the image drawn alone"
    images = [_read(p) for p in series]
    magenta = [np.all(im == (255, 0, 255), axis=2) for im in images]
    bar = slice(int(0.85 * SIZE[0]), None)          # the colour bar's band, right of the disc
    # the "above" colour, on the disc and as a swatch on the colour bar, only where the field is clipped
    assert magenta[0][:, :bar.start].any() and magenta[0][:, bar].any()
    assert not magenta[2].any()
    assert not np.array_equal(images[0], images[2])


def test_a_new_mesh_replaces_the_old_one(scenes, tmp_path):
    full, _ = scenes[0]
    points, triangles, boundaries = structured_annulus(r_in=12.0, r_out=28.0, n_r=4, n_t=40)
    other = dataclasses.replace(full, points=points, triangles=triangles, boundaries=boundaries,
                                von_mises=np.linspace(0.0, 100.0, len(points)), deformation=np.zeros_like(points))
    with render.StressRenderer(SIZE) as renderer:
        renderer.write(tmp_path / "first.png", full)
        second = renderer.write(tmp_path / "second.png", other)
        assert renderer.frames == 2   # building the new disc renders nothing
    alone = render.stress_image(tmp_path / "alone.png", other, window_size=SIZE)
    assert np.count_nonzero(np.abs(_read(second) - _read(alone)).max(axis=2)) <= 2


def test_a_warm_up_leaves_nothing_in_the_images(scenes, tmp_path):
    with render.StressRenderer(SIZE) as renderer:
        renderer.warm_up()
        assert renderer.frames == 0
        warm = [renderer.write(tmp_path / f"warm_{k}.png", s, **kw) for k, (s, kw) in enumerate(scenes)]
        assert renderer.frames == len(scenes) and renderer.anti_aliasing == "fxaa"
    with render.StressRenderer(SIZE) as renderer:
        cold = [renderer.write(tmp_path / f"cold_{k}.png", s, **kw) for k, (s, kw) in enumerate(scenes)]
    for a, b in zip(warm, cold):
        assert np.count_nonzero(np.abs(_read(a) - _read(b)).max(axis=2)) <= 2


def test_fxaa_that_does_not_render_falls_back_to_msaa(scenes, tmp_path, monkeypatch, caplog):
    full, _ = scenes[0]
    monkeypatch.setattr(render_scene, "_background_fraction", lambda image: 0.0)
    with caplog.at_level(logging.WARNING, logger="rvfem.outputs.render"), \
            render.StressRenderer(SIZE, anti_aliasing="fxaa") as renderer:
        path = renderer.write(tmp_path / "fallback.png", full)
        assert renderer.anti_aliasing == "msaa" and renderer.frames == 2
    assert "FXAA" in caplog.text
    with render.StressRenderer(SIZE, anti_aliasing="msaa") as renderer:
        msaa = renderer.write(tmp_path / "msaa.png", full)
    assert np.array_equal(_read(path), _read(msaa))


def test_anti_aliasing_is_checked():
    with pytest.raises(ValueError, match="anti_aliasing"):
        render.StressRenderer(SIZE, anti_aliasing="ssaa")


def test_png_errors_are_raised_when_the_renderer_closes(scenes, tmp_path):
    renderer = render.StressRenderer(SIZE)
    renderer.write(tmp_path / "missing" / "image.png", scenes[0][0])   # the folder does not exist
    with pytest.raises(OSError):
        renderer.close()
    with pytest.raises(RenderError, match="closed"):
        renderer.write(tmp_path / "again.png", scenes[0][0])


def test_a_blank_frame_is_an_error(scenes, tmp_path, monkeypatch):
    with render.StressRenderer(SIZE) as renderer:
        plotter = renderer._plotter()
        monkeypatch.setattr(plotter, "screenshot", lambda **kw: np.full((SIZE[1], SIZE[0], 3), 255, np.uint8))
        with pytest.raises(RenderError, match="blank"):
            renderer.write(tmp_path / "blank.png", scenes[0][0])
    assert not (tmp_path / "blank.png").exists()


def test_repeated_shapes_are_the_pyvista_shapes():
    pv = render._pyvista()
    shapes = render._Shapes(pv)
    centres = np.array([[3.0, -2.0], [10.0, 4.5]])
    discs = shapes.discs(centres, 0.5, 0.35, 2.0, 24)
    for k, c in enumerate(centres):
        one = pv.Disc(center=(c[0], c[1], 0.5), inner=0.35, outer=2.0, c_res=24)
        n = one.n_points
        np.testing.assert_allclose(discs.points[k * n:(k + 1) * n], one.points, atol=1e-5)
        np.testing.assert_array_equal(discs.faces.reshape(-1, 5)[k * one.n_cells:(k + 1) * one.n_cells, 1:],
                                      one.faces.reshape(-1, 5)[:, 1:] + k * n)
    starts = np.array([[1.0, 2.0], [-4.0, 0.0], [0.0, 0.0], [2.0, 2.0]])
    vectors = np.array([[3.0, 4.0], [0.0, -2.0], [0.0, 1.5], [-2.5, 0.7]])
    arrows = shapes.arrows(starts, vectors, 1.0, tip_length=0.22, tip_radius=0.09, shaft_radius=0.05)
    for k, (s, v) in enumerate(zip(starts, vectors)):
        one = pv.Arrow(start=(s[0], s[1], 1.0), direction=(v[0], v[1], 0.0), scale=float(np.hypot(*v)),
                       tip_length=0.22, tip_radius=0.09, shaft_radius=0.05)
        n = one.n_points
        np.testing.assert_allclose(arrows.points[k * n:(k + 1) * n], one.points, atol=1e-5)
    assert arrows.n_cells == len(starts) * one.n_cells
    assert shapes.discs(np.zeros((0, 2)), 0.0, 0.0, 1.0, 8) is None


def test_a_render_worker_draws_what_the_renderer_draws(scenes, tmp_path):
    jobs = [(tmp_path / f"worker_{k}.png", s, kw) for k, (s, kw) in enumerate(scenes)]
    ticks = []
    with render.RenderWorker(SIZE) as worker:
        assert worker.check(wait=True) == render.check_rendering()
        paths = worker.draw(jobs, tick=ticks.append)
        assert worker.frames == len(scenes) and worker.anti_aliasing == "fxaa"
    assert paths == [p for p, _, _ in jobs] and ticks == list(range(1, len(scenes) + 1))
    with render.StressRenderer(SIZE) as renderer:
        here = [renderer.write(tmp_path / f"here_{k}.png", s, **kw) for k, (s, kw) in enumerate(scenes)]
    for a, b in zip(paths, here):
        assert np.array_equal(_read(a), _read(b))


def test_a_render_worker_raises_the_errors_of_its_process(scenes, tmp_path):
    with render.RenderWorker(SIZE) as worker:
        with pytest.raises(OSError):   # the folder does not exist
            worker.draw([(tmp_path / "missing" / "image.png", scenes[0][0], {})])
        with pytest.raises(RenderError, match="one series"):
            worker.submit([(tmp_path / "again.png", scenes[0][0], {})])


def test_a_render_worker_makes_other_calls_meanwhile(scenes, tmp_path):
    import shutil

    source = tmp_path / "source.txt"
    source.write_text("x")
    calls = [(shutil.copyfile, dict(src=source, dst=tmp_path / f"copy_{k}.txt")) for k in range(2)]
    with render.RenderWorker(SIZE) as worker:
        worker.submit([(tmp_path / "image.png", scenes[0][0], {})], calls=calls)
        assert worker.wait_calls() == [tmp_path / "copy_0.txt", tmp_path / "copy_1.txt"]
        assert worker.wait() == [tmp_path / "image.png", tmp_path / "copy_0.txt", tmp_path / "copy_1.txt"]
    assert (tmp_path / "copy_1.txt").read_text() == "x" and (tmp_path / "image.png").is_file()
    with render.RenderWorker(SIZE) as worker:
        worker.submit([(tmp_path / "image2.png", scenes[0][0], {})],
                      calls=[(shutil.copyfile, dict(src=tmp_path / "missing.txt", dst=tmp_path / "c.txt"))])
        with pytest.raises(FileNotFoundError):
            worker.wait_calls()
    # calls started before the images (a run's mesh picture during its load cycle) are numbered
    # first; those of the images follow, then those started after the images (a run's plots once
    # the results they show are computed); once the worker is waited for, no more
    with render.RenderWorker(SIZE) as worker:
        early = worker.start_calls([(shutil.copyfile, dict(src=source, dst=tmp_path / "early.txt"))])
        later = worker.submit([(tmp_path / "image3.png", scenes[0][0], {})],
                              calls=[(shutil.copyfile, dict(src=source, dst=tmp_path / "late.txt"))])
        last = worker.start_calls([(shutil.copyfile, dict(src=source, dst=tmp_path / "last.txt"))])
        assert (early, later, last) == ([0], [1], [2])
        assert worker.wait_calls(later) == [tmp_path / "late.txt"]
        assert worker.wait() == [tmp_path / "image3.png", tmp_path / "early.txt", tmp_path / "late.txt",
                                 tmp_path / "last.txt"]
        with pytest.raises(RenderError, match="before the render worker is waited for"):
            worker.start_calls([(shutil.copyfile, dict(src=source, dst=tmp_path / "too_late.txt"))])
    assert (tmp_path / "early.txt").read_text() == "x" and (tmp_path / "last.txt").read_text() == "x"
    assert not (tmp_path / "too_late.txt").exists()


def test_a_crashing_render_worker_is_the_rendering_error(monkeypatch):
    monkeypatch.setattr(render_check, "_PROBE", "import os; os.abort()")
    monkeypatch.setattr(render_check, "_probe_result", None)
    with render.RenderWorker(SIZE) as worker:
        with pytest.raises(RenderError, match="off-screen rendering is not available.*crashed.*--no-images"):
            worker.check()
    # the process knows it now: a new worker fails at once, without a child process
    worker = render.RenderWorker(SIZE)
    with pytest.raises(RenderError, match="crashed"):
        worker.check(wait=False)


def test_a_failed_check_stops_a_run_before_the_load_cycle(monkeypatch, tmp_path):
    from rvfem.app import run

    monkeypatch.setattr(render_check, "_PROBE", "import os; os.abort()")
    monkeypatch.setattr(render_check, "_probe_result", None)
    reached = []

    def analyse(case, *, progress, **kwargs):
        for stage in ("mesh", "model", "rigid", "cycle"):
            progress(stage, 0, 1)
            reached.append(stage)
            progress(stage, 1, 1)
        raise AssertionError("the load cycle ran")

    monkeypatch.setattr(run, "analyse", analyse)
    from conftest import CASES_DIR

    with pytest.raises(RenderError, match="off-screen rendering is not available.*crashed"):
        run.run_case(CASES_DIR / "rv40e_fanholes.toml", tmp_path / "out")
    assert reached == ["mesh", "model", "rigid"]
    assert list(tmp_path.iterdir()) == []
