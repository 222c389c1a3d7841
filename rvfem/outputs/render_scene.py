"""Drawing the stress images with PyVista/VTK: what one image shows (:class:`StressScene`), the
plotter that draws a series of them (:class:`StressRenderer`) and one image on its own
(:func:`stress_image`).

PyVista is imported only inside the functions that draw, after the rendering check
(:func:`rvfem.outputs.render_check.check_rendering`).
"""

from __future__ import annotations

import dataclasses
import logging
import math
import os
from collections.abc import Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rvfem.errors import RenderError
from rvfem.outputs.render_check import _pyvista

log = logging.getLogger("rvfem.outputs.render")   # the name users and their filters know

COLORMAP = "turbo"
ABOVE_COLOUR = "magenta"
"""Colour of stresses above the colour range (the contact spots when the range is clipped)."""
BACKGROUND = "white"
TITLE_FONT_SIZE = 16
"""Font size of an image's title (upper left; VTK points on the 1500 × 1100 window: the close-ups'
two-line titles read at the size of the colour bar's labels)."""
BAR_TITLE_SEPARATION_PX = 16
"""Pixels between the colour bar's title and the bar (its top label sticks out above the bar)."""
PNG_COMPRESS_LEVEL = 4
"""zlib level of the stress images' PNG files (0-9): 4 writes them in about 60 % of the time of
the default 6, 4 % larger."""

WARM_UP_SCALE = 0.2
"""Size of the warm-up frames of :meth:`StressRenderer.warm_up` relative to the images (each side)."""

ANTI_ALIASING = "fxaa"
"""Anti-aliasing of the stress images: ``"fxaa"`` (a post-processing pass: smooth edges at a
fraction of the cost of multi-sampling in a software OpenGL such as Mesa's llvmpipe; falls back to
MSAA where it does not render correctly), ``"msaa"`` (PyVista's default multi-sampling) or
``"none"``."""
_ANTI_ALIASING = ("fxaa", "msaa", "none")

_FIELD = "von Mises [MPa]"


def nice_factor(value: float) -> float:
    """Largest number of the form {1, 2, 5}·10^k not above ``value`` (> 0): the display
    magnification of deformations."""
    if not (value > 0 and math.isfinite(value)):
        return 1.0
    k = math.floor(math.log10(value))
    for m in (5.0, 2.0, 1.0):
        if m * 10.0**k <= value:
            return m * 10.0**k
    return 10.0**k  # pragma: no cover


@dataclass(frozen=True, eq=False)
class StressScene:
    """What one stress image shows (disc frame, mm, N, MPa).

    Attributes
    ----------
    points : ndarray (n, 2)
        Mesh vertices.
    triangles : ndarray (m, 3)
    boundaries : dict
        Boundary name → edges (drawn undeformed, thin, as a reference outline).
    von_mises : ndarray (n,)
        Vertex von Mises stress, MPa.
    deformation : ndarray (n, 2)
        Deformation to draw (magnified by ``magnification``), mm.
    magnification : float
    clim : (float, float)
        Colour range, MPa (the same for all angles of a run). Values above it are drawn in
        :data:`ABOVE_COLOUR` and the colour bar says so.
    pin_centres : ndarray (Zp, 2)
    pin_radius : float
    pin_loaded : ndarray (Zp,) of bool
        Pins in contact (drawn darker).
    bore_centres : ndarray (N, 2)
    bearing_forces : ndarray (N, 2)
        Force of each bearing on the disc (FE), N.
    rigid_forces : ndarray (N, 2) or None
        The handbook forces at the same angle, drawn in grey.
    force_scale : float
        Arrow length per newton, mm/N.
    title : str
        Text in the upper-left corner.
    """

    points: np.ndarray
    triangles: np.ndarray
    boundaries: dict
    von_mises: np.ndarray
    deformation: np.ndarray
    magnification: float
    clim: tuple[float, float]
    pin_centres: np.ndarray
    pin_radius: float
    pin_loaded: np.ndarray
    bore_centres: np.ndarray
    bearing_forces: np.ndarray
    rigid_forces: np.ndarray | None
    force_scale: float
    title: str


def _xyz(a: np.ndarray, z: float = 0.0) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    return np.column_stack([a, np.full(len(a), z)])


def _outline(pv, points: np.ndarray, boundaries: dict, z: float):
    pieces = []
    for edges in boundaries.values():
        loop = np.append(np.asarray(edges)[:, 0], np.asarray(edges)[0, 0])
        pieces.append(pv.lines_from_points(_xyz(points[loop], z)))
    return pieces[0].merge(pieces[1:]) if len(pieces) > 1 else pieces[0]


def _top_view(plotter, centre: tuple[float, float], half_height: float) -> None:
    cx, cy = centre
    plotter.camera_position = [(cx, cy, 1000.0), (cx, cy, 0.0), (0.0, 1.0, 0.0)]
    plotter.enable_parallel_projection()
    plotter.camera.parallel_scale = half_height


class _Shapes:
    """Many copies of a small PyVista shape as one mesh, from a template built once.

    ``pv.Disc`` and ``pv.Arrow`` cost milliseconds each (a VTK source and a transform filter);
    here each kind of shape is built once and its copies are placed with numpy.
    """

    def __init__(self, pv):
        self._pv = pv
        self._templates: dict[tuple, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def _template(self, key: tuple, build) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if key not in self._templates:
            mesh = build()
            if mesh.n_lines or mesh.n_strips or mesh.n_verts:  # pragma: no cover - VTK sources make polygons
                raise RenderError(f"cannot repeat the shape {key[0]}: not made of polygons only")
            faces = np.asarray(mesh.faces, dtype=np.int64).copy()
            is_id = np.ones(len(faces), dtype=bool)
            i = 0
            while i < len(faces):
                is_id[i] = False
                i += int(faces[i]) + 1
            self._templates[key] = (np.asarray(mesh.points, dtype=float), faces, is_id)
        return self._templates[key]

    def _copies(self, template, points: np.ndarray):
        """One mesh of the template's copies with the points ``points`` (k, n, 3)."""
        _, faces, is_id = template
        k, n = points.shape[:2]
        tiled = np.tile(faces, k)
        tiled[np.tile(is_id, k)] += np.repeat(np.arange(k, dtype=np.int64) * n, int(is_id.sum()))
        return self._pv.PolyData(points.reshape(-1, 3), tiled)

    def discs(self, centres: np.ndarray | Sequence[tuple[float, float]], z: float, inner: float, outer: float, c_res: int):
        """Filled discs (rings if ``inner`` > 0) in the plane ``z`` (as ``pv.Disc``), or None."""
        centres = np.asarray(centres, dtype=float).reshape(-1, 2)
        if len(centres) == 0:
            return None
        template = self._template(("disc", float(inner), float(outer), int(c_res)),
                                  lambda: self._pv.Disc(center=(0.0, 0.0, 0.0), inner=inner, outer=outer,
                                                        c_res=c_res))
        offsets = np.column_stack([centres, np.full(len(centres), float(z))])
        return self._copies(template, template[0][None, :, :] + offsets[:, None, :])

    def arrows(self, starts: np.ndarray, vectors: np.ndarray, z: float, *, tip_length: float, tip_radius: float,
               shaft_radius: float):
        """Arrows in the plane ``z`` from ``starts`` along ``vectors`` (x, y), as long as the vectors
        (as ``pv.Arrow(start, direction=vector, scale=|vector|)``), or None."""
        starts = np.asarray(starts, dtype=float).reshape(-1, 2)
        vectors = np.asarray(vectors, dtype=float).reshape(-1, 2)
        if len(starts) == 0:
            return None
        template = self._template(("arrow", float(tip_length), float(tip_radius), float(shaft_radius)),
                                  lambda: self._pv.Arrow(start=(0.0, 0.0, 0.0), direction=(1.0, 0.0, 0.0),
                                                         scale=1.0, tip_length=tip_length, tip_radius=tip_radius,
                                                         shaft_radius=shaft_radius))
        length = np.hypot(vectors[:, 0], vectors[:, 1])
        c, s = vectors[:, 0] / length, vectors[:, 1] / length
        # the orientation pv.Arrow gives a direction (c, s, 0): x → (c, s, 0), z → ±z (the sign of
        # c), y → z × x
        zs = np.where(c < 0.0, -1.0, 1.0)[:, None]
        p = template[0]
        x = c[:, None] * p[None, :, 0] - zs * s[:, None] * p[None, :, 1]
        y = s[:, None] * p[None, :, 0] + zs * c[:, None] * p[None, :, 1]
        points = np.stack([x, y, np.broadcast_to(zs * p[None, :, 2], x.shape)], axis=-1) * length[:, None, None]
        points += np.column_stack([starts, np.full(len(starts), float(z))])[:, None, :]
        return self._copies(template, points)


def _bearing_arrows(shapes: _Shapes, pl, scene: StressScene) -> None:
    """Arrows of the bearing forces at the bore centres (FE black, handbook grey), labels, legend."""
    centres = np.asarray(scene.bore_centres, dtype=float)
    sets = [(np.asarray(scene.bearing_forces, dtype=float), "black", 0.035)]
    if scene.rigid_forces is not None:
        sets.insert(0, (np.asarray(scene.rigid_forces, dtype=float), "#9a9a9a", 0.05))
    for forces, colour, shaft in sets:
        drawn = np.hypot(forces[:, 0], forces[:, 1]) > 0
        arrows = shapes.arrows(centres[drawn], forces[drawn] * scene.force_scale, 1.0, tip_length=0.22,
                               tip_radius=0.09, shaft_radius=shaft)
        if arrows is not None:
            pl.add_mesh(arrows, color=colour, lighting=False, render=False)
    fe = np.asarray(scene.bearing_forces, dtype=float)
    hb = None if scene.rigid_forces is None else np.asarray(scene.rigid_forces, dtype=float)
    labels, anchors = [], []
    longest = max(float(np.max(np.hypot(*fe.T))), 0.0 if hb is None else float(np.max(np.hypot(*hb.T))))
    for i, (c, f) in enumerate(zip(centres, fe)):
        text = f"B{i + 1}: FE {np.hypot(*f):.0f} N"
        if hb is not None:
            text += f"\nhandbook {np.hypot(*hb[i]):.0f} N"
        labels.append(text)
        # above or below the centre, on the side the FE arrow does not point to (the text is
        # horizontal: a vertical offset clears the arrows' start at the centre)
        away = np.array([0.0, -1.0 if f[1] >= 0 else 1.0])
        edges = scene.boundaries.get(f"bore_{i}")
        radius = (float(np.mean(np.hypot(*(np.asarray(scene.points)[np.asarray(edges)[:, 0]] - c).T)))
                  if edges is not None else longest * scene.force_scale)
        anchors.append(c + away * 0.55 * radius)
    # no box: the labels sit inside the (empty, white) bores, and a box does not fit two centred lines
    pl.add_point_labels(np.column_stack([np.asarray(anchors), np.full(len(anchors), 2.0)]), labels, font_size=16,
                        point_size=1, text_color="black", shape=None, always_visible=True, show_points=False,
                        justification_horizontal="center", render=False)
    key = ["black arrows: FE bearing forces on the disc"]
    if scene.rigid_forces is not None:
        key.append("grey arrows: handbook (rigid) forces")
    key += ["dark pins: in contact", "grey outline: undeformed disc"]
    top = float(np.max(scene.von_mises))
    if top > scene.clim[1] * (1 + 1e-9):
        key.append(f"{ABOVE_COLOUR}: above {scene.clim[1]:.0f} MPa (contact spots, up to {top:.0f} MPa)")
    pl.add_text("\n".join(key), position="lower_right", font_size=10, color="black", render=False)


def _same_array(a, b) -> bool:
    return a is b or (np.shape(a) == np.shape(b) and np.array_equal(a, b))


def _same_boundaries(a: dict, b: dict) -> bool:
    return a is b or (list(a) == list(b) and all(_same_array(a[k], b[k]) for k in a))


class StressRenderer:
    """Stress images of one disc drawn in turn with one off-screen plotter.

    A new plotter costs an OpenGL context, and the first frame of a context uploads the disc mesh
    and compiles the shaders; a series of images therefore shares one plotter. The disc mesh
    (points and triangles) is built once; per image its points (the magnified deformation) and
    its von Mises values are updated in place, with the colour range, the "above" colour and the
    element edges. What differs between images (pins, force arrows, labels, texts, marker, scale
    bar, locator inset) is added for one image and removed after its frame. Each image is exactly
    one rendered frame.

    The PNG files are encoded and written by a background thread while the next image renders:
    a file is complete only when :meth:`close` has returned (use the renderer as a context
    manager). The plotter is used only by the thread that created the renderer.

    Parameters
    ----------
    window_size : (int, int)
        Image size in pixels (width, height).
    compress_level : int
        zlib level of the PNG files, 0 (none) to 9 (smallest, slowest).
    anti_aliasing : {"fxaa", "msaa", "none"}
        Smoothing of the edges (:data:`ANTI_ALIASING`). With ``"fxaa"`` the first image of the
        whole disc is checked, and the renderer switches to ``"msaa"`` (with a warning in the
        log) if the pass does not render correctly here.

    Attributes
    ----------
    window_size : (int, int)
    compress_level : int
    anti_aliasing : str
        The anti-aliasing in use (``"msaa"`` after a fallback).
    frames : int
        Frames rendered so far (one per image, two for an image redrawn after a fallback).

    Raises
    ------
    RenderError
        If off-screen rendering is not available.

    Examples
    --------
    >>> with StressRenderer((1500, 1100)) as renderer:            # doctest: +SKIP
    ...     for k, scene in enumerate(scenes):
    ...         renderer.write(f"stress_{k}.png", scene)
    """

    def __init__(self, window_size: tuple[int, int] = (1500, 1100), *, compress_level: int = PNG_COMPRESS_LEVEL,
                 anti_aliasing: str = ANTI_ALIASING):
        if anti_aliasing not in _ANTI_ALIASING:
            raise ValueError(f"anti_aliasing must be one of {', '.join(_ANTI_ALIASING)}, not {anti_aliasing!r}")
        self.anti_aliasing = anti_aliasing
        self._pv = _pyvista()
        self._shapes = _Shapes(self._pv)
        self.window_size = (int(window_size[0]), int(window_size[1]))
        self.compress_level = int(compress_level)
        self.frames = 0
        # pyvista's plotter, the disc's mesh and its actor once set up (pyvista is imported lazily)
        self._pl: Any = None
        self._disc: Any = None
        self._disc_actor: Any = None
        self._mesh: tuple | None = None
        self._writer = ThreadPoolExecutor(max_workers=1, thread_name_prefix="rvfem-png")
        self._pending: list[Future] = []
        self._closed = False
        self._fxaa_checked = False
        self._plotter()

    def __enter__(self) -> StressRenderer:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close(raise_errors=exc_type is None)

    def _plotter(self):
        if self._pl is None:
            pl = self._pv.Plotter(off_screen=True, window_size=list(self.window_size))
            pl.set_background(BACKGROUND)
            if self.anti_aliasing != "msaa":
                pl.disable_anti_aliasing()
            if self.anti_aliasing == "fxaa":
                pl.renderer.SetUseFXAA(True)
            pl.render_window.AddObserver("StartEvent", self._count_frame)
            self._pl = pl
        return self._pl

    def _count_frame(self, *_) -> None:
        self.frames += 1

    def warm_up(self) -> None:
        """Draw two throwaway frames of a small synthetic disc, the whole disc and a close-up,
        with every kind of actor of the images: the first real image then finds the shaders
        compiled and the fonts loaded (a render worker does this while the analysis runs).

        Nothing is written and :attr:`frames` is not counted; the next image rebuilds its disc.
        The two frames are drawn in a window of :data:`WARM_UP_SCALE` times the size (same aspect
        ratio), then the window gets its size back: compiling the shaders and loading the fonts
        does not depend on the size, and the full-size frames (their anti-aliasing pass over every
        pixel in a software OpenGL) cost about twice as much CPU time, taken from the analysis the
        warm-up runs beside. The images come out the same.
        """
        if self._closed:
            raise RenderError("the stress renderer is closed")
        scene = _warm_up_scene()
        frames = self.frames
        pl = self._plotter()
        pl.window_size = [max(1, round(WARM_UP_SCALE * n)) for n in self.window_size]
        try:
            self._frame(scene, None, None, None, False)
            self._frame(dataclasses.replace(scene, magnification=0.0), (6.0, 0.0), 2.0, (6.0, 0.0), True)
        finally:
            if self._pl is not None:
                self._pl.window_size = list(self.window_size)
        self.frames = frames

    def _set_mesh(self, scene: StressScene) -> None:
        """Build the disc mesh, its colour bar and the undeformed outline (once per mesh)."""
        if self._mesh is not None:
            points, triangles, boundaries = self._mesh
            if (_same_array(points, scene.points) and _same_array(triangles, scene.triangles)
                    and _same_boundaries(boundaries, scene.boundaries)):
                return
        pv, pl = self._pv, self._plotter()
        pl.clear()
        pts = np.asarray(scene.points, dtype=float)
        disc = pv.PolyData.from_regular_faces(_xyz(pts), np.asarray(scene.triangles, dtype=np.int64))
        disc.point_data[_FIELD] = np.zeros(len(pts))
        # the colour bar of add_mesh renders a frame despite render=False (once the plotter has
        # rendered before): not a frame of any image
        pl.suppress_rendering = True
        try:
            actor = pl.add_mesh(disc, scalars=_FIELD, cmap=COLORMAP, clim=[0.0, 1.0], show_edges=False,
                                edge_color="#303030", line_width=0.5, lighting=False, render=False,
                                scalar_bar_args=dict(title=_FIELD, vertical=True, color="black", fmt="%.0f",
                                                     n_labels=6, position_x=0.87, position_y=0.2, width=0.06,
                                                     height=0.62, title_font_size=22, label_font_size=18))
        finally:
            pl.suppress_rendering = False
        actor.mapper.lookup_table.above_range_color = ABOVE_COLOUR
        actor.mapper.lookup_table.SetUseAboveRangeColor(False)
        bar = pl.scalar_bars[_FIELD]
        bar.SetAboveRangeAnnotation("above")
        # the title clear above the top label (which is centred on the bar's end), not over it
        bar.SetVerticalTitleSeparation(BAR_TITLE_SEPARATION_PX)
        pl.add_mesh(_outline(pv, pts, scene.boundaries, 0.2), color="#7f7f7f", line_width=1.0, lighting=False,
                    render=False)
        self._disc, self._disc_actor = actor.mapper.dataset, actor
        self._mesh = (scene.points, scene.triangles, scene.boundaries)

    def _update_disc(self, scene: StressScene, show_edges: bool) -> None:
        """The deformed points, the von Mises values, the colour range and the edges of one image."""
        pts = np.asarray(scene.points, dtype=float)
        disc, actor = self._disc, self._disc_actor
        disc.points = _xyz(pts + scene.magnification * np.asarray(scene.deformation, dtype=float))
        values = disc.point_data[_FIELD]
        values[:] = np.asarray(scene.von_mises, dtype=float)
        disc.GetPointData().GetArray(_FIELD).Modified()
        disc.Modified()
        clipped = float(np.max(scene.von_mises)) > scene.clim[1] * (1 + 1e-9)
        lut = actor.mapper.lookup_table
        actor.mapper.scalar_range = (float(scene.clim[0]), float(scene.clim[1]))
        lut.scalar_range = (float(scene.clim[0]), float(scene.clim[1]))
        lut.SetUseAboveRangeColor(clipped)
        self._pl.scalar_bars[_FIELD].SetDrawAboveRangeSwatch(clipped)
        actor.prop.show_edges = bool(show_edges)

    def write(self, path: str | os.PathLike, scene: StressScene, *, focus: tuple[float, float] | None = None,
              half_height: float | None = None, marker: tuple[float, float] | None = None,
              show_edges: bool = False) -> Path:
        """Render von Mises on the deformed disc with pins, bearing force arrows and a colour bar.

        Parameters
        ----------
        path : path-like
            PNG file to write (complete when :meth:`close` returns).
        scene : StressScene
        focus : (float, float), optional
            Centre of a close-up, mm (default: the whole disc, with the bearing forces).
        half_height : float, optional
            Half of the visible height, mm (default: the pin ring with a margin; 5 mm for a
            close-up).
        marker : (float, float), optional
            Point to mark with a small ring (e.g. the peak stress), undeformed position, mm.
        show_edges : bool
            Draw the element edges (for close-ups).

        Returns
        -------
        Path

        Raises
        ------
        RenderError
            If the rendered image is blank (off-screen rendering does not work here), or the
            renderer is closed.
        """
        if self._closed:
            raise RenderError("the stress renderer is closed")
        path = Path(path)
        img = self._frame(scene, focus, half_height, marker, show_edges)
        if img is None or int(np.min(img)) == int(np.max(img)):
            raise RenderError(f"the rendered image {path.name} is blank; off-screen rendering does not work here")
        if self.anti_aliasing == "fxaa" and focus is None and not self._fxaa_checked:
            # FXAA is a post-processing pass; where it does not work (some OpenGL stacks return a
            # dark frame) the whole-disc image lacks its wide white margin: use MSAA instead
            self._fxaa_checked = True
            if _background_fraction(img) < 0.05:
                log.warning("FXAA anti-aliasing does not render correctly here; the stress images use MSAA")
                self._restart("msaa")
                img = self._frame(scene, focus, half_height, marker, show_edges)
        self._pending.append(self._writer.submit(_write_png, path, np.array(img, copy=True), self.compress_level))
        return path

    def _restart(self, anti_aliasing: str) -> None:
        """A new plotter with another anti-aliasing (the next frame rebuilds the disc)."""
        if self._pl is not None:
            self._pl.close()
        self._pl = self._disc = self._disc_actor = self._mesh = None
        self.anti_aliasing = anti_aliasing

    def _frame(self, scene: StressScene, focus: tuple[float, float] | None, half_height: float | None,
               marker: tuple[float, float] | None, show_edges: bool) -> np.ndarray:
        """Render one image and return its pixels; the per-image actors are removed again."""
        pv = self._pv
        self._set_mesh(scene)
        pl = self._pl
        self._update_disc(scene, show_edges)
        window_size = self.window_size
        before = set(pl.renderer.actors)
        inset = None
        try:
            loaded = np.asarray(scene.pin_loaded, dtype=bool)
            centres = np.asarray(scene.pin_centres, dtype=float)
            for flag, colour in ((True, "#4d4d4d"), (False, "#c8c8c8")):
                pins = self._shapes.discs(centres[loaded == flag], 0.5, 0.0, scene.pin_radius, 48)
                if pins is not None:
                    pl.add_mesh(pins, color=colour, lighting=False, render=False)
            closeup = focus is not None
            if not closeup:
                _bearing_arrows(self._shapes, pl, scene)
            if marker is not None:
                ring = self._shapes.discs([marker], 3.0, 0.35, 0.5, 32)
                pl.add_mesh(ring, color="black", lighting=False, render=False)
            title = pl.add_text(scene.title, position="upper_left", font_size=TITLE_FONT_SIZE, color="black",
                                render=False)
            _text_background(title)

            if focus is None:
                # the whole disc on the left, the colour bar and the legend in the free band on the right
                r_view = 1.1 * float(np.max(np.hypot(*np.asarray(scene.pin_centres).T)) + scene.pin_radius)
                aspect = window_size[0] / window_size[1]
                focus = (max(0.0, r_view * aspect - 1.02 * r_view), 0.0)
                half_height = r_view if half_height is None else half_height
            elif half_height is None:
                half_height = 5.0
            if closeup:
                _scale_bar(pv, pl, focus, half_height, window_size[0] / window_size[1])
                inset = _locator_inset(pv, pl, np.asarray(scene.points, dtype=float), scene.boundaries, focus,
                                       half_height, window_size[0] / window_size[1],
                                       fxaa=self.anti_aliasing == "fxaa")
            _top_view(pl, focus, half_height)
            pl.render()  # the frame (a no-op before the plotter's first screenshot, which renders it)
            return pl.screenshot(return_img=True)
        finally:
            added = [name for name in pl.renderer.actors if name not in before]
            if added:
                pl.remove_actor(added, render=False)
            if inset is not None:
                ren, layers = inset
                pl.render_window.RemoveRenderer(ren)
                pl.render_window.SetNumberOfLayers(layers)

    def close(self, raise_errors: bool = True) -> None:
        """Wait for the PNG files, close the plotter; raise the first error of a PNG write.

        Parameters
        ----------
        raise_errors : bool
            Raise an error of a PNG write (else it is logged only).

        Raises
        ------
        OSError
            A PNG file could not be written.
        """
        if self._closed:
            return
        self._closed = True
        errors = []
        for future in self._pending:
            exc = future.exception()
            if exc is not None:
                errors.append(exc)
        self._pending.clear()
        self._writer.shutdown(wait=True)
        if self._pl is not None:
            self._pl.close()
            self._pl = None
        self._disc = self._disc_actor = None
        for exc in errors[1:] if raise_errors else errors:
            log.error("writing a stress image failed: %s", exc)
        if errors and raise_errors:
            raise errors[0]


def _warm_up_scene() -> StressScene:
    """A small disc (an annulus) with pins, bearing forces and clipped stresses."""
    r = np.linspace(4.0, 10.0, 3)
    t = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    rr, tt = np.meshgrid(r, t, indexing="ij")
    points = np.column_stack([(rr * np.cos(tt)).ravel(), (rr * np.sin(tt)).ravel()])
    idx = np.arange(points.shape[0]).reshape(len(r), len(t))
    a, b = idx[:-1, :], np.roll(idx[:-1, :], -1, axis=1)
    c, d = idx[1:, :], np.roll(idx[1:, :], -1, axis=1)
    triangles = np.vstack([np.column_stack([a.ravel(), b.ravel(), d.ravel()]),
                           np.column_stack([a.ravel(), d.ravel(), c.ravel()])])
    loop = lambda k: np.column_stack([idx[k], np.roll(idx[k], -1)])  # noqa: E731
    pins = 11.0 * np.column_stack([np.cos(t[::3]), np.sin(t[::3])])
    bores = np.array([[6.5, 0.0], [-3.25, 5.63], [-3.25, -5.63]])
    forces = np.array([[300.0, 100.0], [-200.0, 250.0], [0.0, -150.0]])
    return StressScene(points=points, triangles=triangles, boundaries={"central_hole": loop(0), "profile": loop(-1)},
                       von_mises=np.hypot(*points.T) * 10.0, deformation=np.zeros_like(points), magnification=1.0,
                       clim=(0.0, 80.0), pin_centres=pins, pin_radius=1.0, pin_loaded=pins[:, 0] > 0,
                       bore_centres=bores, bearing_forces=forces, rigid_forces=0.9 * forces, force_scale=0.005,
                       title="warm-up")


def _background_fraction(image: np.ndarray) -> float:
    """Fraction of the pixels in the background colour."""
    from pyvista import (
        Color,  # rendering only (the render worker): pyvista and VTK are heavy imports
    )

    rgb = np.asarray(Color(BACKGROUND).int_rgb, dtype=image.dtype)
    return float(np.count_nonzero(np.all(image[..., :3] == rgb, axis=-1))) / (image.shape[0] * image.shape[1])


def _write_png(path: Path, image: np.ndarray, compress_level: int) -> Path:
    from PIL import Image  # rendering only: image post-processing of the render worker

    Image.fromarray(image).save(path, format="PNG", compress_level=compress_level)
    return path


def stress_image(path: str | os.PathLike, scene: StressScene, *, focus: tuple[float, float] | None = None,
                 half_height: float | None = None, marker: tuple[float, float] | None = None,
                 show_edges: bool = False, window_size: tuple[int, int] = (1500, 1100)) -> Path:
    """Render von Mises on the deformed disc with pins, bearing force arrows and a colour bar.

    One image with a plotter of its own; a series of images is faster with one
    :class:`StressRenderer`.

    Parameters
    ----------
    path : path-like
        PNG file to write.
    scene : StressScene
    focus : (float, float), optional
        Centre of the view, mm (default the disc centre).
    half_height : float, optional
        Half of the visible height, mm (default: the pin ring with a margin; 5 mm for a close-up).
    marker : (float, float), optional
        Point to mark with a small ring (e.g. the peak stress), undeformed position, mm.
    show_edges : bool
        Draw the element edges (for close-ups).
    window_size : (int, int)
        Image size in pixels (width, height).

    Returns
    -------
    Path

    Raises
    ------
    RenderError
        If off-screen rendering is not available.
    """
    with StressRenderer(window_size) as renderer:
        path = renderer.write(path, scene, focus=focus, half_height=half_height, marker=marker,
                              show_edges=show_edges)
    return path


def _text_background(actor) -> None:
    """A white, nearly opaque box behind a text (the close-ups' titles lie over the mesh)."""
    try:
        prop = actor.GetTextProperty()
        prop.SetBackgroundColor(1.0, 1.0, 1.0)
        prop.SetBackgroundOpacity(0.85)
    except AttributeError:  # pragma: no cover - a VTK without text backgrounds
        pass


def _scale_bar(pv, pl, focus: tuple[float, float], half_height: float, aspect: float) -> None:
    """A scale bar in the lower-left corner of a close-up: a round length (1, 2 or 5·10^k mm) of
    about a fifth of the view's height, labelled."""
    length = nice_factor(0.4 * half_height)
    x0 = focus[0] - aspect * half_height * 0.25      # right of the locator inset (lower left)
    y0 = focus[1] - half_height * 0.86
    bar = pv.Box(bounds=(x0, x0 + length, y0, y0 + 0.015 * half_height * 2, 3.0, 3.2))
    pl.add_mesh(bar, color="black", lighting=False, render=False)
    pl.add_point_labels([(x0, y0 + 0.06 * half_height, 3.5)], [f"{length:g} mm"], font_size=16,
                        point_size=1, text_color="black", shape_color="white", shape_opacity=0.85,
                        always_visible=True, show_points=False, render=False)


def _locator_inset(pv, pl, points: np.ndarray, boundaries: dict, focus: tuple[float, float], half_height: float,
                   aspect: float, *, fxaa: bool = False):
    """A small view of the whole disc in the lower-left corner with a red frame where the close-up is.

    Returns the inset's renderer (added to the plotter's window) and the window's number of
    layers before it, to remove it again.
    """
    from vtkmodules.vtkRenderingCore import (  # rendering only (the render worker): VTK is a heavy import
        vtkActor,
        vtkPolyDataMapper,
        vtkRenderer,
    )

    ren = vtkRenderer()
    ren.SetViewport(0.005, 0.005, 0.255, 0.345)
    ren.SetBackground(1.0, 1.0, 1.0)
    ren.SetLayer(1)
    ren.SetPreserveColorBuffer(False)   # its own white background over the close-up
    ren.SetUseFXAA(fxaa)                # anti-aliased like the close-up (else by the window's MSAA)
    win = pl.render_window
    layers = win.GetNumberOfLayers()
    win.SetNumberOfLayers(max(2, layers))
    outline = _outline(pv, points, boundaries, 0.0)
    w, h = aspect * half_height, half_height
    cx, cy = focus
    frame = pv.lines_from_points(np.array([[cx - w, cy - h, 1.0], [cx + w, cy - h, 1.0], [cx + w, cy + h, 1.0],
                                           [cx - w, cy + h, 1.0], [cx - w, cy - h, 1.0]]))
    r = 1.05 * float(np.max(np.hypot(points[:, 0], points[:, 1])))
    backdrop = pv.Plane(center=(0.0, 0.0, -1.0), direction=(0.0, 0.0, 1.0), i_size=4 * r, j_size=4 * r)
    for mesh, colour, width in ((backdrop, (1.0, 1.0, 1.0), 1.0), (outline, (0.3, 0.3, 0.3), 1.0),
                                (frame, (0.85, 0.0, 0.0), 3.0)):
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(mesh)
        actor = vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().SetColor(*colour)
        actor.GetProperty().SetLineWidth(width)
        actor.GetProperty().LightingOff()
        ren.AddActor(actor)
    cam = ren.GetActiveCamera()
    cam.ParallelProjectionOn()
    cam.SetPosition(0.0, 0.0, 1000.0)
    cam.SetFocalPoint(0.0, 0.0, 0.0)
    cam.SetViewUp(0.0, 1.0, 0.0)
    cam.SetParallelScale(r)
    ren.SetInteractive(False)
    win.AddRenderer(ren)
    return ren, layers
