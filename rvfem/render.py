"""Off-screen images of the disc with PyVista/VTK: stresses on the deformed disc, close-ups.

The picture of the mesh is drawn with matplotlib (:func:`rvfem.plots.mesh_plot`), which needs no
OpenGL.

No display is needed. On Linux the module selects VTK's EGL render window
(``VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow``, unless the variable is already set) before VTK is
imported, so VTK neither looks for an X server nor warns about one. Because a VTK that cannot open
any OpenGL context may crash the interpreter instead of raising, :func:`check_rendering` first
renders a tiny scene in a child process and turns a failure into a :class:`~rvfem.errors.
RenderError` with the reason; the image functions call it before touching VTK.

PyVista is imported only inside the functions that draw (importing :mod:`rvfem.render` is cheap).
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import RenderError

__all__ = [
    "RENDER_WINDOW_VARIABLE",
    "DEFAULT_RENDER_WINDOW",
    "StressScene",
    "check_rendering",
    "nice_factor",
    "stress_image",
]

RENDER_WINDOW_VARIABLE = "VTK_DEFAULT_OPENGL_WINDOW"
"""Environment variable through which VTK ≥ 9.4 chooses its OpenGL render window class."""

DEFAULT_RENDER_WINDOW = "vtkEGLRenderWindow"
"""Render window used when the variable is not set (Linux): off-screen EGL, no X server."""

COLORMAP = "turbo"
ABOVE_COLOUR = "magenta"
"""Colour of stresses above the colour range (the contact spots when the range is clipped)."""
BACKGROUND = "white"

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
    if rc is not None and rc < 0:
        reason = f"VTK crashed (signal {-rc})"
    elif rc == 0 and parts:
        reason = "VTK rendered a blank image"
    else:
        reason = "VTK could not render"
    details = _vtk_messages(err)
    _probe_result = RenderError(
        f"off-screen rendering is not available ({reason} with render window {chosen}"
        f"{': ' + details if details else ''}); install the EGL runtime (e.g. Debian/Ubuntu 'libegl1') "
        f"or OSMesa, set {RENDER_WINDOW_VARIABLE} to a render window that works here, "
        "or skip the images (rvfem run --no-images)"
    )
    raise _probe_result


def _pyvista():
    check_rendering()
    _select_render_window()
    import pyvista

    return pyvista


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


def _save(plotter, path: Path) -> Path:
    try:
        img = plotter.screenshot(str(path), return_img=True)
    finally:
        plotter.close()
    if img is None or np.asarray(img).std() == 0:
        raise RenderError(f"the rendered image {path.name} is blank; off-screen rendering does not work here")
    return path


def _bearing_arrows(pv, pl, scene: StressScene) -> None:
    """Arrows of the bearing forces at the bore centres (FE black, handbook grey), labels, legend."""
    centres = np.asarray(scene.bore_centres, dtype=float)
    sets = [(np.asarray(scene.bearing_forces, dtype=float), "black", 0.035)]
    if scene.rigid_forces is not None:
        sets.insert(0, (np.asarray(scene.rigid_forces, dtype=float), "#9a9a9a", 0.05))
    for forces, colour, shaft in sets:
        for c, f in zip(centres, forces):
            mag = float(np.hypot(*f))
            if mag <= 0:
                continue
            arrow = pv.Arrow(start=(c[0], c[1], 1.0), direction=(f[0], f[1], 0.0), scale=mag * scene.force_scale,
                             tip_length=0.22, tip_radius=0.09, shaft_radius=shaft)
            pl.add_mesh(arrow, color=colour, lighting=False)
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
                        justification_horizontal="center")
    key = ["black arrows: FE bearing forces on the disc"]
    if scene.rigid_forces is not None:
        key.append("grey arrows: handbook (rigid) forces")
    key += ["dark pins: in contact", "grey outline: undeformed disc"]
    top = float(np.max(scene.von_mises))
    if top > scene.clim[1] * (1 + 1e-9):
        key.append(f"{ABOVE_COLOUR}: above {scene.clim[1]:.0f} MPa (contact spots, up to {top:.0f} MPa)")
    pl.add_text("\n".join(key), position="lower_right", font_size=10, color="black")


def stress_image(path: str | os.PathLike, scene: StressScene, *, focus: tuple[float, float] | None = None,
                 half_height: float | None = None, marker: tuple[float, float] | None = None,
                 show_edges: bool = False, window_size: tuple[int, int] = (1500, 1100)) -> Path:
    """Render von Mises on the deformed disc with pins, bearing force arrows and a colour bar.

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
    pv = _pyvista()
    path = Path(path)
    pts = np.asarray(scene.points, dtype=float)
    disc = pv.PolyData.from_regular_faces(_xyz(pts + scene.magnification * np.asarray(scene.deformation)),
                                         np.asarray(scene.triangles, dtype=np.int64))
    disc.point_data["von Mises [MPa]"] = np.asarray(scene.von_mises, dtype=float)

    pl = pv.Plotter(off_screen=True, window_size=list(window_size))
    pl.set_background(BACKGROUND)
    clipped = float(np.max(scene.von_mises)) > scene.clim[1] * (1 + 1e-9)
    pl.add_mesh(disc, scalars="von Mises [MPa]", cmap=COLORMAP, clim=list(scene.clim), show_edges=show_edges,
                edge_color="#303030", line_width=0.5, lighting=False,
                above_color=ABOVE_COLOUR if clipped else None,
                scalar_bar_args=dict(title="von Mises [MPa]", vertical=True, color="black", fmt="%.0f",
                                     n_labels=6, position_x=0.87, position_y=0.25, width=0.06, height=0.65,
                                     title_font_size=20, label_font_size=18))
    pl.add_mesh(_outline(pv, pts, scene.boundaries, 0.2), color="#7f7f7f", line_width=1.0, lighting=False)

    pins = [pv.Disc(center=(x, y, 0.5), inner=0.0, outer=scene.pin_radius, c_res=48)
            for x, y in np.asarray(scene.pin_centres, dtype=float)]
    loaded = np.asarray(scene.pin_loaded, dtype=bool)
    for flag, colour in ((True, "#4d4d4d"), (False, "#c8c8c8")):
        chosen = [p for p, f in zip(pins, loaded) if bool(f) == flag]
        if chosen:
            pl.add_mesh(chosen[0].merge(chosen[1:]) if len(chosen) > 1 else chosen[0], color=colour,
                        lighting=False)

    closeup = focus is not None
    if not closeup:
        _bearing_arrows(pv, pl, scene)
    if marker is not None:
        ring = pv.Disc(center=(marker[0], marker[1], 3.0), inner=0.35, outer=0.5, c_res=32)
        pl.add_mesh(ring, color="black", lighting=False)
    title = pl.add_text(scene.title, position="upper_left", font_size=12 if not closeup else 11, color="black")
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
        _locator_inset(pv, pl, pts, scene.boundaries, focus, half_height, window_size[0] / window_size[1])
    _top_view(pl, focus, half_height)
    return _save(pl, path)


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
    pl.add_mesh(bar, color="black", lighting=False)
    pl.add_point_labels([(x0, y0 + 0.06 * half_height, 3.5)], [f"{length:g} mm"], font_size=16,
                        point_size=1, text_color="black", shape_color="white", shape_opacity=0.85,
                        always_visible=True, show_points=False)


def _locator_inset(pv, pl, points: np.ndarray, boundaries: dict, focus: tuple[float, float], half_height: float,
                   aspect: float) -> None:
    """A small view of the whole disc in the lower-left corner with a red frame where the close-up is."""
    import vtk

    ren = vtk.vtkRenderer()
    ren.SetViewport(0.005, 0.005, 0.255, 0.345)
    ren.SetBackground(1.0, 1.0, 1.0)
    ren.SetLayer(1)
    ren.SetPreserveColorBuffer(False)   # its own white background over the close-up
    win = pl.render_window
    win.SetNumberOfLayers(max(2, win.GetNumberOfLayers()))
    outline = _outline(pv, points, boundaries, 0.0)
    w, h = aspect * half_height, half_height
    cx, cy = focus
    frame = pv.lines_from_points(np.array([[cx - w, cy - h, 1.0], [cx + w, cy - h, 1.0], [cx + w, cy + h, 1.0],
                                           [cx - w, cy + h, 1.0], [cx - w, cy - h, 1.0]]))
    r = 1.05 * float(np.max(np.hypot(points[:, 0], points[:, 1])))
    backdrop = pv.Plane(center=(0.0, 0.0, -1.0), direction=(0.0, 0.0, 1.0), i_size=4 * r, j_size=4 * r)
    for mesh, colour, width in ((backdrop, (1.0, 1.0, 1.0), 1.0), (outline, (0.3, 0.3, 0.3), 1.0),
                                (frame, (0.85, 0.0, 0.0), 3.0)):
        mapper = vtk.vtkPolyDataMapper()
        mapper.SetInputData(mesh)
        actor = vtk.vtkActor()
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
