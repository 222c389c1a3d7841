"""Plots of a load cycle and the picture of the mesh (matplotlib, Agg canvas: no display needed).

Each function draws one figure into a PNG file and returns its path. The figures come from the
one factory, :func:`rvfem.outputs.figures.new_figure` (``Figure`` with an Agg canvas, never
:mod:`matplotlib.pyplot`, so no global backend is touched; matplotlib imported only there), and are
written by :func:`rvfem.outputs.figures.save_figure`.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from rvfem.names import feature_label
from rvfem.outputs.figures import new_figure, save_figure

__all__ = ["mesh_plot", "mesh_preview", "rim_closeup", "bearing_loads_plot", "roller_loads_plot", "pin_forces_plot", "pins_in_contact_plot"]

COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")


def _degree_axis(ax) -> None:
    ax.set_xlim(0.0, 360.0)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel("crank angle θ [°]")
    ax.grid(True, lw=0.4, alpha=0.6)


def bearing_loads_plot(path: str | os.PathLike, theta: np.ndarray, flexible: np.ndarray, rigid: np.ndarray, *,
                       title: str = "", reference_label: str = "rigid (handbook)") -> Path:
    """Bearing load |F| over the crank angle, flexible (solid) and a rigid reference (dashed).

    Parameters
    ----------
    path : path-like
        PNG to write.
    theta : ndarray (n,)
        Crank angles, rad.
    flexible, rigid : ndarray (n, N)
        |F| of each bearing, N: FE and the reference (the handbook, or the equal share of the FE pin
        resultant where the handbook is not defined).
    title : str
    reference_label : str
        The reference in the legend.
    """
    fig = new_figure((10.0, 5.2))
    ax = fig.subplots()
    deg = np.degrees(theta)
    order = np.argsort(deg)
    for i in range(flexible.shape[1]):
        c = COLOURS[i % len(COLOURS)]
        ax.plot(deg[order], flexible[order, i], color=c, lw=1.8, label=f"bearing {i + 1}, flexible (FE)")
        ax.plot(deg[order], rigid[order, i], color=c, lw=1.2, ls="--", label=f"bearing {i + 1}, {reference_label}")
    _degree_axis(ax)
    ax.set_ylabel("bearing load |F| [N]")
    ax.set_ylim(bottom=0.0)
    ax.set_title(title or "Crank-bearing loads over one crank revolution")
    # below the axes: inside it would hide the minima (small loads at every angle)
    ax.legend(ncol=flexible.shape[1], fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13),
              frameon=False)
    fig.tight_layout()
    return save_figure(fig, path)


def roller_loads_plot(path: str | os.PathLike, roller_angles: np.ndarray, roller_loads: np.ndarray,
                      bearing_forces: np.ndarray, *, theta_deg: float, title: str = "") -> Path:
    """Roller load distribution of every bearing at one crank angle (polar bars).

    Parameters
    ----------
    path : path-like
    roller_angles : ndarray (N, Z)
        Roller positions about each bore centre, rad (disc frame).
    roller_loads : ndarray (N, Z)
        N.
    bearing_forces : ndarray (N, 2)
        Force of each bearing on the disc, N (drawn as a line from the centre).
    theta_deg : float
        The crank angle, degrees (for the title).
    title : str
    """
    n = roller_loads.shape[0]
    fig = new_figure((4.2 * n, 4.8))
    axes = fig.subplots(1, n, subplot_kw={"projection": "polar"}, squeeze=False)[0]
    qmax = float(np.max(roller_loads)) or 1.0
    for i, ax in enumerate(axes):
        z = roller_loads.shape[1]
        ax.bar(roller_angles[i], roller_loads[i], width=2 * math.pi / z * 0.6, color=COLOURS[i % len(COLOURS)],
               alpha=0.85)
        f = bearing_forces[i]
        # direction in which the bore presses on the rollers: opposite to the force on the disc
        ax.annotate("", xy=(math.atan2(-f[1], -f[0]), 0.9 * qmax), xytext=(0, 0),
                    arrowprops=dict(arrowstyle="->", color="black", lw=1.2))
        ax.set_ylim(0, 1.05 * qmax)
        ax.set_title(f"bearing {i + 1}: |F| = {np.hypot(*f):.0f} N\nQ_max = {roller_loads[i].max():.0f} N",
                     fontsize=9)
        ax.tick_params(labelsize=7)
    fig.suptitle(title or f"Roller loads [N] at θ = {theta_deg:.1f}° (arrow: load of the bore on the rollers)",
                 fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path)


def pin_forces_plot(path: str | os.PathLike, pin_index: np.ndarray, fe: np.ndarray, classical: np.ndarray | None, *,
                    theta_deg: float, title: str = "") -> Path:
    """Pin forces at one crank angle: FE (bars) against the classical rigid distribution (line).

    Parameters
    ----------
    path : path-like
    pin_index : ndarray (Zp,)
        Pin numbers (1-based) to label the x axis.
    fe, classical : ndarray (Zp,)
        Pin force magnitudes, N; ``classical`` None where the distribution is not defined
        (Zp − Zc ≠ 1): the FE bars alone.
    theta_deg : float
    title : str
    """
    fig = new_figure((10.0, 4.8))
    ax = fig.subplots()
    ax.bar(pin_index, fe, width=0.7, color="tab:blue", label="FE (flexible disc)")
    if classical is not None:
        ax.plot(pin_index, classical, "o-", color="tab:red", ms=3.5, lw=1.2,
                label="classical rigid distribution (moment exact)")
        other = f"classical: {int(np.count_nonzero(classical > 0))}"
    else:
        other = "classical distribution not defined for Zp − Zc ≠ 1"
    ax.set_xlabel("pin number")
    ax.set_ylabel("pin force [N]")
    ax.set_xlim(pin_index.min() - 0.8, pin_index.max() + 0.8)
    ax.grid(True, axis="y", lw=0.4, alpha=0.6)
    ax.set_title(title or f"Pin forces at θ = {theta_deg:.1f}° (FE: {int(np.count_nonzero(fe > 0))} pins in "
                          f"contact, {other})")
    ax.legend(fontsize=9)
    fig.tight_layout()
    return save_figure(fig, path)


def pins_in_contact_plot(path: str | os.PathLike, theta: np.ndarray, count: np.ndarray, total: int, *,
                         classical: np.ndarray | None = None, title: str = "") -> Path:
    """Number of pins in contact over the crank angle.

    Parameters
    ----------
    path : path-like
    theta : ndarray (n,)
        Crank angles, rad.
    count : ndarray (n,)
        Pins in contact (FE).
    total : int
        Number of pins Zp.
    classical : ndarray (n,), optional
        Loaded pins of the classical rigid distribution.
    title : str
    """
    fig = new_figure((10.0, 3.8))
    ax = fig.subplots()
    deg = np.degrees(theta)
    order = np.argsort(deg)
    ax.step(deg[order], count[order], where="mid", color="tab:blue", lw=1.5, label="FE")
    if classical is not None:
        ax.step(deg[order], classical[order], where="mid", color="tab:red", lw=1.0, ls="--",
                label="classical rigid distribution")
    _degree_axis(ax)
    ax.set_ylabel(f"pins in contact (of {total})")
    lo = min(int(count.min()), int(classical.min()) if classical is not None else total)
    hi = max(int(count.max()), int(classical.max()) if classical is not None else 0)
    ax.set_ylim(lo - 1.5, hi + 1.5)
    ax.set_title(title or "Pins in contact over one crank revolution")
    # below the axes: inside it would hide the curves (the count spans the whole height)
    ax.legend(fontsize=9, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)
    fig.tight_layout()
    return save_figure(fig, path)


def mesh_plot(path: str | os.PathLike, points: np.ndarray, triangles: np.ndarray, boundaries: dict, *,
              closeup_centre: tuple[float, float], closeup_half_height: float = 8.0, title: str = "",
              subtitle: str = "", closeup_title: str = "close-up", dpi: int = 150) -> Path:
    """The mesh: the whole disc (left) and a close-up (right), element edges thin, boundaries coloured.

    The one picture of the mesh, used by ``rvfem mesh`` (:func:`mesh_preview`) and
    by ``rvfem run`` (``images/mesh.png``).

    Parameters
    ----------
    path : path-like
        PNG to write (its folder is created if missing).
    points : ndarray (n, 2)
        Mesh vertices, mm.
    triangles : ndarray (m, 3)
        Vertex indices of the (linear) triangles.
    boundaries : dict
        Boundary name → edges (vertex index pairs), as :attr:`rvfem.mesh.DiscMesh.boundaries`.
    closeup_centre : (float, float)
        Centre of the close-up, mm.
    closeup_half_height : float
        Half of the close-up's visible height, mm.
    title, subtitle, closeup_title : str
        Title of the left panel, of the figure, and of the close-up.
    dpi : int
        Resolution.

    Returns
    -------
    Path
    """
    fig = new_figure((13.0, 6.5))
    axes = fig.subplots(1, 2)
    pts = np.asarray(points, dtype=float)
    x, y = pts[:, 0], pts[:, 1]
    colours = {"profile": "tab:red", "central_hole": "tab:green"}
    cycle = ["tab:blue", "tab:orange", "tab:purple", "tab:brown", "tab:olive", "tab:cyan"]

    handles = {}
    for ax in axes:
        ax.triplot(x, y, np.asarray(triangles), lw=0.15, color="0.35")
        for i, (name, edges) in enumerate(boundaries.items()):
            loop = np.append(np.asarray(edges)[:, 0], np.asarray(edges)[0, 0])
            line, = ax.plot(x[loop], y[loop], lw=1.0, color=colours.get(name, cycle[i % len(cycle)]))
            handles[feature_label(name)] = line
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
    cx, cy = closeup_centre
    h = closeup_half_height
    axes[1].set_xlim(cx - h, cx + h)
    axes[1].set_ylim(cy - h, cy + h)
    axes[1].set_title(closeup_title)
    axes[0].set_title(title)
    # where the close-up is: a frame on the whole disc
    from matplotlib.patches import Rectangle

    axes[0].add_patch(Rectangle((cx - h, cy - h), 2 * h, 2 * h, fill=False, lw=1.4, color="black", zorder=5))
    axes[0].annotate("close-up", (cx + h, cy + h), xytext=(4, 4), textcoords="offset points", fontsize=9)
    # the key of the boundary colours (names as users read them, numbered from 1)
    fig.legend(list(handles.values()), list(handles), loc="lower center", ncol=min(len(handles), 6),
               fontsize=8, frameon=False)
    if subtitle:
        fig.suptitle(subtitle)
    fig.tight_layout(rect=(0, 0.07, 1, 0.94 if subtitle else 0.97))
    return save_figure(fig, path, dpi=dpi)


def rim_closeup(points: np.ndarray, boundaries: dict, bore: str = "bore_0",
                min_half_height: float = 8.0) -> tuple[tuple[float, float], float]:
    """Where the mesh pictures look closely: the rim between the bore ``bore`` and the teeth.

    The window is centred between the bore's vertex farthest from the disc centre and the tooth
    profile's vertex nearest to it, and is large enough to hold both with a margin (at least
    ``min_half_height``), so that the teeth are in view however thick the rim is.

    Parameters
    ----------
    points : ndarray (n, 2)
        Mesh vertices, mm.
    boundaries : dict
        Boundary name → edges (vertex index pairs); ``bore`` and ``profile`` are used.
    bore : str
        The bore's boundary name (mesh numbering, from 0).
    min_half_height : float
        Smallest half height of the window, mm.

    Returns
    -------
    ((float, float), float)
        Centre of the window and its half height, mm.
    """
    pts = np.asarray(points, dtype=float)
    b = np.unique(np.asarray(boundaries[bore]).ravel())
    outer = pts[b[np.argmax(np.hypot(pts[b, 0], pts[b, 1]))]]
    prof = pts[np.unique(np.asarray(boundaries["profile"]).ravel())]
    tooth = prof[np.argmin(np.hypot(*(prof - outer).T))]
    centre = 0.5 * (outer + tooth)
    half = max(min_half_height, 0.5 * float(np.hypot(*(tooth - outer))) + 3.0)
    return (float(centre[0]), float(centre[1])), half


def mesh_preview(mesh, path: str | os.PathLike, *, title: str = "", dpi: int = 150) -> Path:
    """The preview ``rvfem mesh`` writes next to a cached mesh: :func:`mesh_plot` of the whole disc
    and of the rim under bore 1 with the teeth next to it (:func:`rim_closeup`).

    Parameters
    ----------
    mesh : rvfem.mesh.DiscMesh
    path : path-like
        PNG to write.
    title : str
        Title of the left panel (default: the mesh file's name).
    dpi : int
    """
    pts = np.asarray(mesh.points, dtype=float)
    half = 8.0
    if "bore_0" in mesh.boundaries:
        c, half = rim_closeup(pts, mesh.boundaries)
        where = "close-up: the rim under bore 1 and the teeth next to it"
    else:
        c = pts[np.asarray(mesh.boundaries["profile"])[0, 0]]
        where = "close-up: tooth profile"
    return mesh_plot(path, pts, mesh.triangles, mesh.boundaries, closeup_centre=(float(c[0]), float(c[1])),
                     closeup_half_height=half,
                     title=title or mesh.path.stem,
                     subtitle=f"{mesh.n_nodes} nodes, {mesh.n_elements} triangles (P1), "
                              f"min {mesh.quality_measure} = {mesh.min_quality:.3f}",
                     closeup_title=where, dpi=dpi)
