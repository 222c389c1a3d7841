"""Writers of an :class:`~rvfem.app.analysis.Analysis`: one per format, and the atomic result folder.

Every writer has the form ``write_x(analysis, folder) -> list[Path]`` and writes into an existing
folder (sub-folders it needs are created). Each registers itself (:mod:`rvfem.outputs.registry`,
whose ``WRITER_MODULES`` lists this module and the other writer modules);
:func:`writers` lists them in the order a run calls them::

    write_tables      bearing_loads.csv, roller_loads.csv (bearing model "rollers"), pin_forces.csv,
                      cycle.csv, stress_history.csv
    write_case_json   case.json           the case as analysed; case_from_dict() reads it back
    write_vtk         vtk/disc.pvd and vtk/disc_theta_<θ>.vtu per kept field (ParaView)
    write_plots       plots/*.png (matplotlib)
    write_images      images/stress_theta_<θ>.png, the two stress close-ups (PyVista, off-screen),
                      images/mesh.png (matplotlib)
    write_report      report.html (self-contained)
    write_summary     summary.json

The content of ``summary.json`` is built in one place, :func:`build_summary`, from the result
sections (:func:`rvfem.results.registry.sections`); their key declarations generate the key table of
docs/outputs.md (a test checks that the table and the keys written agree).
:func:`result_folder` is the atomic result folder: results are written into a temporary folder next
to the target and moved into place only when complete.

File formats and keys: docs/outputs.md.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
import json
import logging
import math
import os
import shutil
import tempfile
import uuid
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

import numpy as np

from rvfem import __version__
from rvfem.case.definition import case_to_dict, file_sha256
from rvfem.errors import FolderNotEmptyError, OutputError
from rvfem.evaluate.hertz import RIGID_ROLLER_MODEL
from rvfem.evaluate.rigid import references
from rvfem.geometry import crank_centres
from rvfem.outputs import plots, render, tables, vtkio
from rvfem.outputs.plots import mesh_plot, rim_closeup
from rvfem.outputs.registry import Writer, register_writer, writers
from rvfem.outputs.report import write_report as _write_html
from rvfem.outputs.roller_outputs import roller_damage_calls, roller_pressure_calls
from rvfem.results import registry as sections_registry
from rvfem.results.bearing_checks import bearing_checks_dict
from rvfem.results.files import stress_image_name
from rvfem.results.format import ANGLE_DECIMALS, angle, json_ready
from rvfem.results.header import CLI_MODULES, CLI_SCRIPTS, SCHEMA_VERSION, VERSIONED_PACKAGES, command_line, environment
from rvfem.results.mass_strength import fatigue_point_data
from rvfem.results.references import references_dict
from rvfem.results.roller_depth import depth_life_dict
from rvfem.results.section import SummaryContext

log = logging.getLogger(__name__)

__all__ = [
    "ANGLE_DECIMALS",
    "SCHEMA_VERSION",
    "RIGID_SCHEMA_VERSION",
    "VERSIONED_PACKAGES",
    "CLI_MODULES",
    "CLI_SCRIPTS",
    "command_line",
    "environment",
    "IMAGE_SIZE",
    "DEFORMATION_DISPLAY_FRACTION",
    "SummaryContext",
    "json_ready",
    "RESULT_MARKER",
    "is_rvfem_folder",
    "mark_folder",
    "prepare_output_folder",
    "check_output_folder",
    "result_folder",
    "image_count",
    "build_summary",
    "rigid_summary",
    "write_case_json",
    "write_tables",
    "write_vtk",
    "write_images",
    "submit_images",
    "start_mesh_picture",
    "mesh_picture",
    "PendingImages",
    "write_plots",
    "plot_calls",
    "write_summary",
    "write_report",
    "Writer",
    "register_writer",
    "writers",
]


RIGID_SCHEMA_VERSION = 1
"""Version of the ``rvfem rigid --json`` layout (docs/outputs.md); bumped when a key changes meaning
or disappears."""

IMAGE_SIZE = (1500, 1100)
"""Size of the stress images, pixels (width, height)."""

DEFORMATION_DISPLAY_FRACTION = 0.03
"""The largest deformation of the kept fields is drawn as about this fraction of the pin-circle
radius (the magnification is rounded down to 1, 2 or 5·10^k and written on the image)."""

TickCallback = Callable[[int, int], None]
"""``tick(done, total)``: progress within a writer (images, VTK files)."""


# --------------------------------------------------------------------------------------------
# JSON
# --------------------------------------------------------------------------------------------


def _dump(obj: Any) -> str:
    return json.dumps(json_ready(obj), indent=2, allow_nan=False) + "\n"


# --------------------------------------------------------------------------------------------
# The atomic result folder
# --------------------------------------------------------------------------------------------


RESULT_MARKER = ".rvfem-results"
"""The marker file in every folder rvfem writes (result folders of ``run`` and ``hysteresis``,
study and optimisation folders, the folder of ``compare -o``). It holds one line naming what wrote
the folder and the rvfem version. rvfem replaces or writes into an existing non-empty folder only
if this file is in it: a folder rvfem did not write is never changed."""


def _is_nonempty_dir(path: Path) -> bool:
    return path.is_dir() and any(path.iterdir())


def is_rvfem_folder(path: str | os.PathLike) -> bool:
    """True if ``path`` is a folder rvfem wrote (it holds :data:`RESULT_MARKER`)."""
    return (Path(path) / RESULT_MARKER).is_file()


def mark_folder(folder: str | os.PathLike, what: str) -> Path:
    """Write :data:`RESULT_MARKER` into ``folder``: one line, ``rvfem <version> <what> <time>``
    (``what`` names the command, e.g. ``"run"``); returns its path."""
    path = Path(folder) / RESULT_MARKER
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    path.write_text(f"rvfem {__version__} {what} {stamp}: a folder rvfem wrote; rvfem replaces or writes into "
                    "a non-empty folder only if this file is in it\n", encoding="utf-8")
    return path


def _foreign_folder_error(out_dir: Path) -> OutputError:
    earlier = ""
    if (out_dir / "summary.json").is_file() or (out_dir / "study.json").is_file():
        # A result or study folder of an rvfem from before the marker: still refused (its files may
        # have been added to since), but the message says what it probably is.
        earlier = " (its summary.json or study.json suggests an earlier rvfem wrote it, before the marker)"
    return OutputError(f"{out_dir} is not empty and rvfem did not write it (no {RESULT_MARKER} file in it){earlier}; "
                       "rvfem replaces or writes into only folders it wrote: choose another output folder, or move "
                       "or delete this one yourself")


def check_output_folder(out_dir: str | os.PathLike, overwrite: bool) -> None:
    """Raise :class:`~rvfem.errors.OutputError` if ``out_dir`` cannot take the results: it is a file,
    a non-empty folder that rvfem did not write (no :data:`RESULT_MARKER` in it; refused whatever
    ``overwrite`` says), or a non-empty folder rvfem wrote and ``overwrite`` is false
    (:class:`~rvfem.errors.FolderNotEmptyError`)."""
    out_dir = Path(out_dir)
    if out_dir.exists() or out_dir.is_symlink():
        if not out_dir.is_dir():
            raise OutputError(f"{out_dir} exists and is not a folder; choose another output folder")
        if _is_nonempty_dir(out_dir):
            if not is_rvfem_folder(out_dir):
                raise _foreign_folder_error(out_dir)
            if not overwrite:
                raise FolderNotEmptyError(out_dir)


def prepare_output_folder(out_dir: str | os.PathLike, what: str, subfolders: tuple[str, ...] = ()) -> Path:
    """Create ``out_dir`` (and its parents) as a folder rvfem writes into in place, with
    :data:`RESULT_MARKER` and the ``subfolders`` named (e.g. a study's ``variants``); an existing
    folder is taken if it is empty or rvfem wrote it (a study or optimisation folder taken up
    again). Returns ``out_dir``.

    Raises
    ------
    OutputError
        ``out_dir`` is a file, a non-empty folder rvfem did not write, or it or a subfolder cannot be
        created.
    """
    out_dir = Path(out_dir)
    check_output_folder(out_dir, overwrite=True)
    folder = out_dir
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        if not is_rvfem_folder(out_dir):
            mark_folder(out_dir, what)
        for name in subfolders:
            folder = out_dir / name
            folder.mkdir(exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the folder {folder}: {exc.strerror or exc}") from None
    return out_dir


def _make_parents(out_dir: Path) -> list[Path]:
    """Create the missing parents of ``out_dir``; return the ones created (outermost first)."""
    missing = []
    p = out_dir.parent
    while not p.exists():
        missing.append(p)
        p = p.parent
    try:
        for p in reversed(missing):
            p.mkdir()
    except OSError as exc:
        raise OutputError(f"cannot create the folder {p}: {exc.strerror or exc}") from None
    return list(reversed(missing))


def _remove_created(created: list[Path]) -> None:
    for p in reversed(created):
        try:
            p.rmdir()
        except OSError:
            pass


def _commit(tmp: Path, out_dir: Path, overwrite: bool) -> None:
    """Move the complete results into place (atomic rename; an old folder goes only after)."""
    check_output_folder(out_dir, overwrite)
    if _is_nonempty_dir(out_dir):
        old = out_dir.with_name(f".{out_dir.name}.old-{uuid.uuid4().hex[:8]}")
        os.replace(out_dir, old)
        try:
            os.replace(tmp, out_dir)
        except BaseException:
            os.replace(old, out_dir)
            raise
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(tmp, out_dir)  # also replaces an empty folder


@contextlib.contextmanager
def result_folder(out_dir: str | os.PathLike, *, overwrite: bool = False, what: str = "run") -> Iterator[Path]:
    """The atomic result folder: yields a temporary folder to write into, next to ``out_dir``.

    On entry ``out_dir`` is checked (:func:`check_output_folder`) and its missing parents are
    created. The temporary folder starts with the marker :data:`RESULT_MARKER` (naming ``what``
    wrote it). When the block ends normally the temporary folder is renamed to ``out_dir`` (an
    existing non-empty ``out_dir`` is replaced only then, only with ``overwrite``, and only if
    rvfem wrote it: it holds the marker). When the block raises (an error, Ctrl-C) the temporary
    folder and the parents created are removed and an existing ``out_dir`` stays as it was.

    Raises
    ------
    OutputError
        ``out_dir`` is a file, a non-empty folder rvfem did not write, is not empty (without
        ``overwrite``: :class:`~rvfem.errors.FolderNotEmptyError`), or cannot be written.

    Examples
    --------
    >>> with result_folder("results/x", overwrite=True) as tmp:    # doctest: +SKIP
    ...     write_tables(analysis, tmp)
    """
    out_dir = Path(out_dir)
    check_output_folder(out_dir, overwrite)
    created = _make_parents(out_dir)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.partial-", dir=out_dir.parent))
    except OSError as exc:
        _remove_created(created)
        # the results are first written to a new folder beside out_dir: that is what failed
        raise OutputError(f"cannot create the folder {out_dir}: {exc.strerror or exc} (in {out_dir.parent})") from None
    try:
        umask = os.umask(0o022)
        os.umask(umask)
        os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes it private; the results are an ordinary folder
        try:
            mark_folder(tmp, what)
            yield tmp
        except OSError as exc:
            raise OutputError(f"cannot write the results: {exc.strerror or exc}") from None
        try:
            _commit(tmp, out_dir, overwrite)
        except OSError as exc:
            raise OutputError(f"cannot move the results into {out_dir}: {exc.strerror or exc}") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_created(created)
        raise


# --------------------------------------------------------------------------------------------
# summary.json: built in one place from typed pieces
# --------------------------------------------------------------------------------------------


def build_summary(analysis, context: SummaryContext | None = None) -> dict:
    """The content of ``summary.json`` (JSON-ready: non-finite numbers are None).

    Parameters
    ----------
    analysis : rvfem.app.analysis.Analysis
    context : SummaryContext, optional
        Files of the result folder and timings (default: none, e.g. for a summary in memory).
    """
    context = context or SummaryContext(timings=dict(analysis.timings))
    summary: dict[str, Any] = {}
    for section in sections_registry.sections():
        summary.update(section.summary(analysis, context))
    return json_ready(summary)


@register_writer("summary", order=70, stage=None, options=("summary",), files=("summary.json",))
def write_summary(analysis, folder: str | os.PathLike, *, summary: dict | None = None) -> list[Path]:
    """Write ``summary.json`` (the given ``summary``, or :func:`build_summary` with the files
    found in ``folder``)."""
    folder = Path(folder)
    if summary is None:
        summary = build_summary(analysis, SummaryContext(files=_files_in(folder, ("summary.json",)),
                                                         timings=dict(analysis.timings)))
    path = folder / "summary.json"
    path.write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    return [path]


def _files_in(folder: Path, extra: Iterable[str] = ()) -> tuple[str, ...]:
    found = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file() and p.name != RESULT_MARKER}
    return tuple(sorted(found | set(extra)))


# --------------------------------------------------------------------------------------------
# case.json and the CSV tables
# --------------------------------------------------------------------------------------------


@register_writer("case_json", order=20, stage="tables", files=("case.json",))
def write_case_json(analysis, folder: str | os.PathLike) -> list[Path]:
    """Write ``case.json``: the case as analysed (:func:`rvfem.case.definition.case_from_dict` reads it back)."""
    path = Path(folder) / "case.json"
    path.write_text(json.dumps(case_to_dict(analysis.case), indent=2) + "\n", encoding="utf-8")
    return [path]


@register_writer("tables", order=10, stage="tables", files=("bearing_loads.csv", "roller_loads.csv", "pin_forces.csv",
                                                        "cycle.csv", "stress_history.csv"))
def write_tables(analysis, folder: str | os.PathLike) -> list[Path]:
    """Write the CSV tables of the load cycle (:mod:`rvfem.outputs.tables`): ``bearing_loads.csv``,
    ``roller_loads.csv`` (discrete rollers only), ``pin_forces.csv``, ``cycle.csv``. The handbook
    and classical columns are NaN where those references are not defined (Zp − Zc ≠ 1)."""

    folder = Path(folder)
    a, cy, th = analysis, analysis.cycle, analysis.theta
    hb = a.rigid.loads   # NaN where the handbook is not defined
    out = [tables.write_bearing_loads(folder / "bearing_loads.csv", th, cy.bearing_forces,
                                      np.stack([hb.fx.T, hb.fy.T], axis=2), a.equal_share_forces)]
    if cy.roller_loads is not None:
        out.append(tables.write_roller_loads(folder / "roller_loads.csv", th, cy.roller_angles, cy.roller_loads))
    classical = (np.full(cy.pin_forces.shape, np.nan) if a.classical is None  # not defined for Zp − Zc ≠ 1
                 else a.classical.magnitude.T)
    out.append(tables.write_pin_forces(folder / "pin_forces.csv", th, a.pin_centres, cy.pin_forces, classical))
    out.append(tables.write_cycle_table(folder / "cycle.csv", th, cy.pins_in_contact, cy.carrier_rotation,
                                        cy.equilibrium_residual, cy.iterations))
    if a.stress.history is not None:
        out.append(tables.write_stress_history(folder / "stress_history.csv", a.stress.history))
    return out


# --------------------------------------------------------------------------------------------
# VTK
# --------------------------------------------------------------------------------------------


@register_writer("vtk", order=30, stage="vtk", options=("tick",), files=("vtk/*.vtu", "vtk/disc.pvd"),
                 ticks=lambda analysis: len(analysis.stress.snapshots))
def write_vtk(analysis, folder: str | os.PathLike, *, tick: TickCallback | None = None) -> list[Path]:
    """Write ``vtk/disc_theta_<θ>.vtu`` for every kept field and the collection ``vtk/disc.pvd``
    (:mod:`rvfem.outputs.vtkio`)."""

    vtk = Path(folder) / "vtk"
    vtk.mkdir(exist_ok=True)
    model = analysis.system.model
    snapshots = analysis.stress.snapshots
    points, triangles = model.mesh.p.T, model.mesh.t.T
    mesh = vtkio.vtu_mesh(points, triangles)   # the same in every file: encoded once
    out, entries = [], []
    for done, snap in enumerate(snapshots, start=1):
        name = vtkio.vtu_name(snap.theta_deg)
        out.append(vtkio.write_vtu(vtk / name, points, triangles, snap, mesh=mesh))
        entries.append((snap.theta_deg, name))
        if tick is not None and done < len(snapshots):
            tick(done, len(snapshots))
    out.append(vtkio.write_pvd(vtk / "disc.pvd", entries))
    cy = analysis.cycle
    if cy.von_mises_envelope is not None:
        structural, recovered = analysis.stress.structural, analysis.stress.recovered
        out.append(vtkio.write_envelope_vtu(
            vtk / vtkio.ENVELOPE_FILE, points, triangles, cy.von_mises_envelope, cy.von_mises_envelope_theta,
            element_order=model.order, structural_peak_MPa=None if structural is None else structural.von_mises_MPa,
            structural_peak_order=2 if recovered is not None else model.order, mesh=mesh,
            extra_point_data=fatigue_point_data(analysis)))
    return out


# --------------------------------------------------------------------------------------------
# Images and plots
# --------------------------------------------------------------------------------------------


def image_count(analysis) -> int:
    """Number of images :func:`write_images` draws (for a progress bar)."""
    s = analysis.stress
    return len(s.snapshots) + sum(pk is not None for pk in (s.peak, s.away_from_contacts)) + 1


@dataclass(frozen=True, eq=False)
class _ImageSet:
    """What :func:`write_images` draws: the stress images (PNG path, scene, keyword arguments of
    :meth:`rvfem.outputs.render.StressRenderer.write`) and the mesh picture (keyword arguments of
    :func:`rvfem.outputs.plots.mesh_plot`)."""

    stress: list
    mesh: dict


def _image_set(analysis, images: Path) -> _ImageSet:
    a, case, cy = analysis, analysis.case, analysis.cycle
    model, mesh, snapshots = a.system.model, a.mesh, a.stress.snapshots
    peak, away = a.stress.peak, a.stress.away_from_contacts
    vertices, triangles = model.mesh.p.T, model.mesh.t.T
    pin_xy, rigid_forces = a.pin_centres, a.rigid_forces
    k_max, _ = a.max_load_index
    max_def = max(float(np.max(np.hypot(*s.deformation.T))) for s in snapshots)
    magnification = render.nice_factor(DEFORMATION_DISPLAY_FRACTION * case.pins.circle_radius / max_def)
    f_ref = max(float(cy.bearing_loads.max()), float(a.rigid.loads.magnitude.max()))
    # colour range up to the peak away from the contacts (the structural field stays readable);
    # the contact spots above it are drawn in the "above" colour
    clim = (0.0, (away or peak).von_mises_MPa)
    bores = crank_centres(case)

    def scene(snap, label):
        k = snap.index
        pf = cy.pin_forces[k]
        return render.StressScene(
            points=vertices, triangles=triangles, boundaries=mesh.boundaries,
            von_mises=snap.stress.nodal.von_mises, deformation=snap.deformation,
            magnification=magnification, clim=clim,
            pin_centres=pin_xy[k], pin_radius=case.pins.radius,
            pin_loaded=pf > 1e-9 * max(float(pf.max()), 1.0),
            bore_centres=bores, bearing_forces=cy.bearing_forces[k], rigid_forces=rigid_forces[k],
            force_scale=0.85 * case.crank_bearing.bore_radius / f_ref,
            title=f"{case.name}   crank angle {snap.theta_deg:.1f}°{label}   von Mises on the disc deformed "
                  f"×{magnification:g}   bearings '{case.crank_bearing.model}', P{model.order}",
        )

    stress: list[tuple[Path, Any, dict[str, Any]]] = []
    for snap in snapshots:
        label = "  (max. bearing load)" if snap.index == k_max else ""
        stress.append((images / stress_image_name(snap.theta_deg), scene(snap, label), {}))
    half = max(5.0, 12.0 * case.mesh.size_bore)
    rec = a.stress.recovered
    for key, pk, what in (("stress_peak_closeup", peak, "contact-zone peak (mesh-dependent)"),
                          ("stress_away_from_contacts_closeup", away, "structural peak away from contacts")):
        if pk is None:
            continue
        snap = next(s for s in snapshots if math.isclose(s.theta_deg, pk.theta_deg))
        extra = ""
        if rec is not None and key == "stress_away_from_contacts_closeup":
            extra = f" (P2 re-solve: {rec.peak.von_mises_MPa:.0f} MPa)"
        close = dataclasses.replace(
            scene(snap, ""), magnification=0.0, clim=(0.0, pk.von_mises_MPa),
            title=f"{case.name}, crank angle {snap.theta_deg:.1f}°, close-up (undeformed), {what}\n"
                  f"von Mises {pk.von_mises_MPa:.0f} MPa (P{model.order}){extra} at the ring, "
                  f"{pk.feature_label}")
        stress.append((images / f"{key}.png", close, dict(focus=(pk.x_mm, pk.y_mm), half_height=half,
                                                          marker=(pk.x_mm, pk.y_mm), show_edges=True)))
    return _ImageSet(stress=stress, mesh=mesh_picture(a.system, images))


def mesh_picture(system, images: str | os.PathLike) -> dict:
    """The keyword arguments of :func:`rvfem.outputs.plots.mesh_plot` for ``images/mesh.png`` of a run:
    the whole mesh and a close-up of the rim under bore 1 and the teeth. It needs the model only,
    so a run can have it drawn while the load cycle is solved (:func:`start_mesh_picture`)."""

    case, mesh = system.case, system.mesh
    points = system.model.mesh.p.T
    centre, half = rim_closeup(points, mesh.boundaries)
    return dict(path=Path(images) / "mesh.png", points=points, triangles=system.model.mesh.t.T,
                boundaries=mesh.boundaries, closeup_centre=centre, closeup_half_height=half,
                title=f"{case.name}: {mesh.n_nodes} vertices, {mesh.n_elements} triangles "
                      f"(min quality {mesh.min_quality:.2f})",
                closeup_title="close-up: the rim under bore 1 and the teeth next to it")


def start_mesh_picture(system, folder: str | os.PathLike, worker) -> int:
    """Have a render worker's child process draw ``images/mesh.png`` at once (its second thread),
    while this process goes on; give the returned number to :func:`submit_images`.

    Raises
    ------
    RenderError
        If off-screen rendering is not possible here.
    """

    (number,) = worker.start_calls([(mesh_plot, mesh_picture(system, _images_folder(folder)))])
    return number


def _images_folder(folder: str | os.PathLike) -> Path:
    """``folder/images``, created if missing."""
    images = Path(folder) / "images"
    images.mkdir(exist_ok=True)
    return images


class PendingImages:
    """The images of :func:`submit_images`, being drawn by a :class:`rvfem.outputs.render.RenderWorker`;
    :meth:`result` waits for them, :meth:`calls_result` for the other calls."""

    def __init__(self, image_set: _ImageSet, worker, calls: list[int], mesh_call: int):
        self._set, self._worker, self._calls, self._mesh_call = image_set, worker, calls, mesh_call

    def add_calls(self, calls: Iterable[tuple[Callable, dict]]) -> None:
        """Hand further drawings (:func:`plot_calls`) to the child; :meth:`calls_result` waits for them too."""
        self._calls = self._calls + self._worker.start_calls(list(calls))

    def calls_result(self) -> list:
        """Wait for the calls given to :func:`submit_images` and :meth:`add_calls` (the child makes
        them one after the other, after the mesh picture if that was started first, else before it)
        and return what they returned.

        Raises
        ------
        RenderError, Exception
            From the render worker, or what a call raised.
        """
        return self._worker.wait_calls(self._calls)

    def result(self, *, tick: TickCallback | None = None) -> list[Path]:
        """Wait for the images.

        Parameters
        ----------
        tick : callable, optional
            ``tick(done, total)`` after each image but the last.

        Returns
        -------
        list of Path
            The stress images, the close-ups and the mesh picture, all complete.

        Raises
        ------
        RenderError, OSError
            From the render worker.
        """
        total = len(self._set.stress) + 1

        def one_more(done: int) -> None:
            if tick is not None and done < total:
                tick(done, total)

        done = self._worker.wait(tick=one_more)
        n = len(self._set.stress)
        return [Path(p) for p in done[:n]] + [Path(done[n + self._mesh_call])]


def submit_images(analysis, folder: str | os.PathLike, worker, *,
                  calls: Iterable[tuple[Callable, dict]] = (), mesh_call: int | None = None) -> PendingImages:
    """Start the images of :func:`write_images` in a render worker's child process, which draws
    them while this process does other work (the mesh picture in a second thread of the child);
    :meth:`PendingImages.result` waits for them.

    Parameters
    ----------
    analysis : rvfem.app.analysis.Analysis
    folder : path-like
    worker : rvfem.outputs.render.RenderWorker
        Checked (:meth:`~rvfem.outputs.render.RenderWorker.check`) or not; it draws one series.
    calls : iterable of (function, dict)
        Other drawings for the child's second thread (e.g. :func:`plot_calls`), made before the
        mesh picture unless that was started already; :meth:`PendingImages.calls_result` waits
        for them.
    mesh_call : int, optional
        The number :func:`start_mesh_picture` returned, if the mesh picture was started already.

    Returns
    -------
    PendingImages

    Raises
    ------
    RenderError
        If off-screen rendering is not possible here.
    """

    images = _images_folder(folder)
    image_set = _image_set(analysis, images)
    calls = list(calls)
    if mesh_call is not None:
        return PendingImages(image_set, worker, worker.submit(image_set.stress, calls=calls), mesh_call)
    numbers = worker.submit(image_set.stress, calls=calls + [(mesh_plot, image_set.mesh)])
    return PendingImages(image_set, worker, numbers[:-1], numbers[-1])


@register_writer("images", order=50, stage="images", options=("tick", "pending"), files=("images/*.png",),
                 renders=True, ticks=image_count)
def write_images(analysis, folder: str | os.PathLike, *, tick: TickCallback | None = None,
                 worker=None, pending: PendingImages | None = None) -> list[Path]:
    """Render ``images/``: von Mises on the deformed disc at every kept angle, close-ups of the two
    stress peaks (PyVista, off-screen) and the mesh (:func:`rvfem.outputs.plots.mesh_plot`).

    The stress images share one off-screen plotter (:class:`rvfem.outputs.render.StressRenderer`); the
    mesh picture is drawn by a second thread meanwhile. With a render worker
    (:class:`rvfem.outputs.render.RenderWorker`) both are drawn by its child process (see also
    :func:`submit_images`); with ``pending`` (what :func:`submit_images` returned) the images the
    worker is drawing are waited for. All files are complete on return.

    Raises
    ------
    RenderError
        If off-screen rendering is not possible here.
    """
    if pending is not None:
        return pending.result(tick=tick)
    if worker is not None:
        return submit_images(analysis, folder, worker).result(tick=tick)

    images = _images_folder(folder)
    total = image_count(analysis)
    out: list[Path] = []

    def done(path: Path) -> None:
        out.append(path)
        if tick is not None and len(out) < total:
            tick(len(out), total)

    image_set = _image_set(analysis, images)
    # the mesh picture (matplotlib) is drawn by a second thread while VTK renders the stress images;
    # the renderer is made first, so that PyVista (which imports matplotlib) is imported by this
    # thread alone
    with render.StressRenderer(IMAGE_SIZE) as renderer, \
            ThreadPoolExecutor(max_workers=1, thread_name_prefix="rvfem-mesh-plot") as pool:
        mesh_png = pool.submit(mesh_plot, **image_set.mesh)
        for path, scene, options in image_set.stress:
            done(renderer.write(path, scene, **options))
        done(mesh_png.result())
    return out


def plot_calls(analysis, folder: str | os.PathLike, group: str | None = None) -> list[tuple[Callable, dict]]:
    """The plots of :func:`write_plots` as calls: (function of :mod:`rvfem.outputs.plots`, keyword
    arguments), each drawing one PNG file and returning its path (``plots/`` is created); with
    ``group`` only those of the load cycle (``"cycle"``) or of the crank bearing in depth
    (``"roller_depth"``), which a render worker's child process can draw as soon as those exist.
    """
    if group not in (None, "cycle", "roller_depth"):
        raise ValueError(f"no plot group {group!r}; the groups are 'cycle' and 'roller_depth'")
    folder = Path(folder) / "plots"
    folder.mkdir(exist_ok=True)
    roller = [] if group == "cycle" else roller_pressure_calls(analysis, folder) + roller_damage_calls(analysis, folder)
    if group == "roller_depth":
        return roller
    a, case, cy, th = analysis, analysis.case, analysis.cycle, analysis.theta
    k_max, _ = a.max_load_index
    th_max = math.degrees(float(th[k_max]))
    classical = None if a.classical is None else a.classical.magnitude
    handbook = a.comparison.reference == "handbook"
    label = "rigid (handbook)" if handbook else "equal share of the FE pin resultant"
    calls: list[tuple[Callable, dict]] = [(plots.bearing_loads_plot, dict(
        path=folder / "bearing_loads.png", theta=th, flexible=cy.bearing_loads, rigid=a.reference_loads,
        reference_label=label,
        title=f"{case.name}: crank-bearing loads, flexible (FE, '{case.crank_bearing.model}') vs "
              + ("rigid handbook" if handbook else "equal share (handbook not defined for Zp − Zc ≠ 1)")))]
    if cy.roller_loads is not None:
        calls.append((plots.roller_loads_plot, dict(
            path=folder / "roller_loads.png", roller_angles=cy.roller_angles[k_max],
            roller_loads=cy.roller_loads[k_max], bearing_forces=cy.bearing_forces[k_max], theta_deg=th_max)))
    calls.append((plots.pin_forces_plot, dict(
        path=folder / "pin_forces.png", pin_index=np.arange(1, case.pins.count + 1), fe=cy.pin_forces[k_max],
        classical=None if classical is None else classical[:, k_max], theta_deg=th_max)))
    calls.append((plots.pins_in_contact_plot, dict(
        path=folder / "pins_in_contact.png", theta=th, count=cy.pins_in_contact, total=case.pins.count,
        classical=None if classical is None else np.count_nonzero(classical > 0, axis=0))))
    return calls + roller


@register_writer("plots", order=40, stage="plots", options=("pending",),
                 files=tuple(f"plots/{name}.png" for name in ("bearing_loads", "roller_loads", "pin_forces",
                                                            "pins_in_contact", "roller_pressure",
                                                            "roller_damage")))
def write_plots(analysis, folder: str | os.PathLike, *, pending: PendingImages | None = None) -> list[Path]:
    """Draw ``plots/``: bearing loads over θ (flexible vs the bearing-load reference: the handbook, or
    the equal share where it is not defined), roller loads and pin forces at the angle of the
    largest bearing load, pins in contact over θ (matplotlib, :mod:`rvfem.outputs.plots`). With
    ``pending`` (:func:`submit_images` given :func:`plot_calls`) the plots a render worker is
    drawing are waited for instead."""
    if pending is not None:
        return pending.calls_result()
    return [function(**kwargs) for function, kwargs in plot_calls(analysis, folder)]


# --------------------------------------------------------------------------------------------
# Report
# --------------------------------------------------------------------------------------------


@register_writer("report", order=60, stage="report", options=("summary",), files=("report.html",))
def write_report(analysis, folder: str | os.PathLike, *, summary: dict | None = None) -> list[Path]:
    """Write ``report.html`` (:mod:`rvfem.outputs.report`): the numbers of ``summary`` (default
    :func:`build_summary` with the files found in ``folder``) with the PNG files of ``folder``
    embedded."""
    folder = Path(folder)
    if summary is None:
        summary = build_summary(analysis, SummaryContext(
            files=_files_in(folder, ("report.html", "summary.json")), timings=dict(analysis.timings)))

    return [_write_html(folder / "report.html", summary, analysis.case, folder)]


# --------------------------------------------------------------------------------------------
# JSON for the command line (its screen text is :mod:`rvfem.app.screen`)
# --------------------------------------------------------------------------------------------


def rigid_summary(result) -> dict:
    """The rigid handbook evaluation (:class:`rvfem.app.analysis.RigidAnalysis`) as a JSON-ready dict
    (what ``rvfem rigid --json`` writes). Loads in N, angles in degrees, speeds in rpm, lives in
    hours, pressures in MPa, lengths in mm; non-finite numbers are None."""
    case, comp = result.case, result.loads.components
    bearings = [{
        "bearing": b.loads.bearing + 1,
        "crank_angle_deg": b.crank_angle_deg,
        "max_load_N": b.loads.max_N,
        "max_at_deg": angle(b.loads.max_at_deg),
        "min_load_N": b.loads.min_N,
        "min_at_deg": angle(b.loads.min_at_deg),
        "equivalent_load_N": b.loads.equivalent_N,
        "L10h_h": b.loads.L10h,
        "max_roller_load_N": b.max_roller_load_N,
        "max_roller_at_deg": angle(b.max_roller_theta_deg),
        "hertz_inner": dataclasses.asdict(b.hertz_inner),
        "hertz_outer": dataclasses.asdict(b.hertz_outer),
        "depth": depth_life_dict(b.depth),
    } for b in result.bearings]
    if not result.defined:   # the handbook is not defined (Zp − Zc ≠ 1): the same keys, null
        bearings = [{
            "bearing": i + 1, "crank_angle_deg": angle, "max_load_N": None, "max_at_deg": None, "min_load_N": None,
            "min_at_deg": None, "equivalent_load_N": None, "L10h_h": None, "max_roller_load_N": None,
            "max_roller_at_deg": None, "hertz_inner": None, "hertz_outer": None, "depth": None,
        } for i, angle in enumerate(case.cranks.angles_deg)]

    source = Path(case.source.removesuffix(" (with overrides)"))
    report = {
        "schema_version": RIGID_SCHEMA_VERSION,
        "rvfem_version": __version__,
        "environment": environment(),
        "case": case.name,
        "source": case.source,
        "case_sha256": file_sha256(source) if source.is_file() else None,
        "case_digest": case.digest(),
        "overrides": list(case.overrides),
        "model": "rigid handbook (equal load sharing, zero clearance)",
        "output_torque_Nm": case.loads.torque_Nm,
        "disc_torque_Nmm": comp.disc_torque_Nmm,
        "output_speed_rpm": case.loads.speed_rpm,
        "bearing_speed_rpm": result.bearing_speed_rpm,
        "k": comp.k,
        "k_y": comp.k_y,
        "sum_px_N": comp.sum_px,
        "sum_py_N": comp.sum_py,
        "equivalent_load_exponent": result.exponent,
        "angle_step_deg": result.angle_step_deg,
        "dynamic_load_rating_N": result.rating_N,
        "stribeck_factor": result.stribeck_factor,
        "rigid_roller_model": RIGID_ROLLER_MODEL,
        "bearing_checks": bearing_checks_dict(result.checks),
        "references": references_dict(result.references or references(case, fe=False)),
        "warnings": [w.as_dict() for w in result.warnings],
        "bearings": bearings,
    }
    if case.loads.duty_cycle:
        report["duty_cycle"] = None if result.duty_cycle is None else dataclasses.asdict(result.duty_cycle)
    return json_ready(report)
