"""The analyst's main job: one case from the case file to a folder of results.

:func:`run_case` runs the whole chain — check → mesh (cached) → rigid handbook model → flexible
load cycle → evaluation → outputs — and writes::

    DIR/summary.json        key numbers (schema: docs/outputs.md)
    DIR/report.html         self-contained report (images embedded)
    DIR/case.json           the case as analysed (after overrides); case_from_dict() reads it back
    DIR/bearing_loads.csv   θ, per bearing Fx, Fy, |F| flexible and rigid
    DIR/roller_loads.csv    roller loads (bearing model "rollers")
    DIR/pin_forces.csv      FE and classical pin forces
    DIR/cycle.csv           pins in contact, carrier rotation, residual, iterations per angle
    DIR/vtk/disc.pvd        ParaView collection over θ of DIR/vtk/disc_theta_*.vtu
    DIR/images/*.png        von Mises on the deformed disc per kept angle, close-ups, the mesh
    DIR/plots/*.png         bearing loads, roller loads, pin forces, pins in contact

Nothing is lost: the outputs are written into a temporary folder next to DIR and moved into place
only when complete. An existing non-empty DIR is replaced only with ``overwrite=True`` (and only
after the new results are complete); a run that fails or is interrupted leaves neither DIR (nor
the previous results changed) nor the temporary folder.

Example (notebook)::

    from rvfem.run import run_case
    result = run_case("cases/rv40e_fanholes.toml", "results/rv40e_fanholes", overwrite=True)
    result.summary["bearings"][0]["flexible"]["max_load_N"]
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import os
import shutil
import tempfile
import time
import tomllib
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from . import __version__
from .case import Case, case_to_dict, file_sha256, load_case
from .errors import CaseError, OutputError

log = logging.getLogger(__name__)

__all__ = [
    "SCHEMA_VERSION",
    "STAGES",
    "CONTACT_BAND_ELEMENTS",
    "RunSummary",
    "ProgressCallback",
    "run_case",
    "summary_text",
]

SCHEMA_VERSION = 1
"""Version of the ``summary.json`` layout (docs/outputs.md); bumped when a key changes meaning or
disappears (new keys do not bump it)."""

STAGES: dict[str, str] = {
    "check": "checking the case, the output folder and off-screen rendering",
    "mesh": "meshing the disc (cached)",
    "model": "assembling and factorising the disc model",
    "rigid": "rigid handbook model",
    "cycle": "flexible load cycle",
    "evaluation": "evaluation: rigid vs flexible, stresses, Hertz",
    "tables": "writing summary tables (CSV)",
    "vtk": "writing VTK files for ParaView",
    "images": "rendering stress images",
    "plots": "plotting",
    "report": "writing the report",
}
"""Stages of a run in order, with a one-line description (what the progress callback reports)."""

CONTACT_BAND_ELEMENTS = 6.0
"""Width of the band along the tooth profile and the bores excluded from the "away from contacts"
stress peak, in element sizes there (``mesh.size_flank``, ``mesh.size_bore``): four times the
footprint half-width over which the pin and roller forces are spread."""

ProgressCallback = Callable[[str, int, int], None]
"""``progress(stage, done, total)``: called with ``done = 0`` when a stage of :data:`STAGES` starts,
with ``done = total`` when it ends, and after every crank angle of the ``cycle`` stage
(``total`` = number of angles). An exception raised by the callback (e.g. KeyboardInterrupt)
aborts the run cleanly."""

IMAGE_SIZE = (1500, 1100)
DEFORMATION_DISPLAY_FRACTION = 0.03
"""The largest deformation of the kept fields is drawn as about this fraction of the pin-circle
radius (the magnification is rounded down to 1, 2 or 5·10^k and written on the image)."""


@dataclass(frozen=True, eq=False)
class RunSummary:
    """Result of :func:`run_case`.

    Attributes
    ----------
    out_dir : Path
        The result folder (complete).
    summary : dict
        The content of ``summary.json``.
    case : Case
        The case as analysed (overrides applied).
    system : rvfem.cycle.DiscSystem
        The factorised disc model (for further solves from a notebook).
    cycle : rvfem.cycle.CycleResult
    comparison : rvfem.compare.Comparison
    files : tuple of str
        Files written, relative to ``out_dir``.
    """

    out_dir: Path
    summary: dict
    case: Case
    system: Any
    cycle: Any
    comparison: Any
    files: tuple[str, ...]


# --------------------------------------------------------------------------------------------
# Case and options
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _CaseInfo:
    file: str | None
    sha256: str | None
    matches_file: bool
    overrides: dict
    defaults_used: tuple[tuple[str, Any], ...]


def _defaults_used(path: Path, case: Case) -> tuple[tuple[str, Any], ...]:
    """Dotted keys of ``case`` that the file does not set (the reader's defaults), with values."""
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return ()
    out: list[tuple[str, Any]] = []

    def walk(full: Any, given: Any, prefix: str) -> None:
        if not isinstance(full, dict):
            return
        for key, value in full.items():
            dotted = f"{prefix}{key}"
            if not isinstance(given, dict) or key not in given:
                if value not in ([], {}, "", None):
                    out.append((dotted, value))
            elif isinstance(value, dict):
                walk(value, given[key], dotted + ".")

    walk(case_to_dict(case), raw, "")
    return tuple(out)


def _resolve_case(case: Case | str | os.PathLike, angle_step_deg: float | None, bearing_model: str | None,
                  order: int | None) -> tuple[Case, _CaseInfo]:
    if isinstance(case, Case):
        base = case
        path = Path(case.source)
        if path.is_file():
            try:
                matches = load_case(path) == case
            except CaseError:
                matches = False
        else:
            path, matches = None, False
    else:
        path = Path(case)
        base = load_case(path)
        matches = True
    file_info = (str(path), file_sha256(path)) if path is not None else (None, None)
    defaults = _defaults_used(path, base) if (path is not None and matches) else ()

    overrides: dict[str, Any] = {}
    analysis, bearing = base.analysis, base.crank_bearing
    if angle_step_deg is not None:
        if not (isinstance(angle_step_deg, (int, float)) and angle_step_deg > 0):
            raise CaseError(f"the angle step must be positive, got {angle_step_deg!r}")
        analysis = dataclasses.replace(analysis, angle_step_deg=float(angle_step_deg))
        overrides["analysis.angle_step_deg"] = float(angle_step_deg)
    if order is not None:
        if order not in (1, 2):
            raise CaseError(f"the element order must be 1 or 2, got {order!r}")
        analysis = dataclasses.replace(analysis, element_order=int(order))
        overrides["analysis.element_order"] = int(order)
    if bearing_model is not None:
        if bearing_model not in ("rollers", "rigid_bore"):
            raise CaseError(f"the bearing model must be 'rollers' or 'rigid_bore', got {bearing_model!r}")
        bearing = dataclasses.replace(bearing, model=bearing_model)
        overrides["crank_bearing.model"] = bearing_model
    try:
        effective = base.replace(analysis=analysis, crank_bearing=bearing) if overrides else base
    except CaseError as exc:
        given = ", ".join(f"{k} = {v}" for k, v in overrides.items())
        raise CaseError(f"the overrides ({given}) are not valid: {exc}") from None
    return effective, _CaseInfo(file_info[0], file_info[1], matches and not overrides, overrides, defaults)


def _cycle_thetas(case: Case) -> np.ndarray:
    n = int(round(360.0 / case.analysis.angle_step_deg))
    if n < 4:
        raise CaseError(f"the angle step {case.analysis.angle_step_deg:g}° leaves fewer than 4 angles per turn")
    if not math.isclose(n * case.analysis.angle_step_deg, 360.0, rel_tol=1e-9):
        log.warning("angle step %g° does not divide 360°: using %d angles (step %.6g°)",
                    case.analysis.angle_step_deg, n, 360.0 / n)
    return np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)


# --------------------------------------------------------------------------------------------
# Output folder
# --------------------------------------------------------------------------------------------


def _is_nonempty_dir(path: Path) -> bool:
    return path.is_dir() and any(path.iterdir())


def _check_target(out_dir: Path, overwrite: bool) -> None:
    if out_dir.exists() or out_dir.is_symlink():
        if not out_dir.is_dir():
            raise OutputError(f"{out_dir} exists and is not a folder; choose another output folder")
        if _is_nonempty_dir(out_dir) and not overwrite:
            raise OutputError(f"{out_dir} exists and is not empty; choose another output folder or pass "
                              "--overwrite (overwrite=True) to replace it")


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
    """Move the complete results into place (atomic rename; the old folder goes only after)."""
    _check_target(out_dir, overwrite)
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


# --------------------------------------------------------------------------------------------
# Summary
# --------------------------------------------------------------------------------------------


def _stats_dict(s) -> dict:
    return {
        "max_load_N": s.max_N,
        "max_at_deg": s.max_at_deg,
        "min_load_N": s.min_N,
        "min_at_deg": s.min_at_deg,
        "equivalent_load_N": s.equivalent_N,
        "L10h_h": s.L10h,
    }


def _hertz_dict(h) -> dict:
    return {
        "roller_load_N": h.roller_load_N,
        "bearing": None if h.bearing is None else h.bearing + 1,
        "roller": None if h.roller is None else h.roller + 1,
        "theta_deg": h.theta_deg,
        "inner": dataclasses.asdict(h.inner),
        "outer": dataclasses.asdict(h.outer),
    }


def _peak_dict(peak) -> dict:
    return {
        "x_mm": peak.x_mm,
        "y_mm": peak.y_mm,
        "radius_mm": peak.radius_mm,
        "theta_deg": peak.theta_deg,
        "feature": peak.feature,
        "feature_label": peak.feature_label,
        "distance_to_feature_mm": peak.distance_to_feature_mm,
    }


def _finite(obj: Any) -> Any:
    """JSON-safe copy: numpy scalars to Python, non-finite floats to None."""
    if isinstance(obj, dict):
        return {str(k): _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def summary_text(summary: dict) -> str:
    """One screen of text with the key numbers of a ``summary.json`` (what ``rvfem run`` prints)."""
    c, m = summary["case"], summary["model"]
    lines = [
        f"Case {c['name']}" + (f" ({c['file']})" if c.get("file") else "") +
        (f", overrides: {', '.join(f'{k} = {v}' for k, v in c['overrides'].items())}" if c["overrides"] else ""),
        f"  model: bearings '{m['bearing_model']}', P{m['element_order']}, {m['nodes']} nodes, {m['dofs']} dofs, "
        f"{m['elements']} elements; {m['angles']} crank angles (step {m['angle_step_deg']:g}°)",
        f"  torque {m['output_torque_Nm']:g} N·m on {m['discs']} discs = {m['disc_torque_Nmm'] / 1000:g} N·m per disc "
        f"about the disc centre; C = {m['dynamic_load_rating_N']:.0f} N, n_b = {m['bearing_speed_rpm']:g} rpm",
        "",
        f"  {'bearing':>7} {'model':<9} {'max N':>8} {'at °':>6} {'min N':>8} {'at °':>6} {'F_m N':>8} {'L10h h':>9}",
    ]
    for b in summary["bearings"]:
        for key in ("rigid", "flexible"):
            s = b[key]
            lines.append(f"  {b['bearing'] if key == 'rigid' else '':>7} {key:<9} {s['max_load_N']:8.0f} "
                         f"{s['max_at_deg']:6.1f} {s['min_load_N']:8.0f} {s['min_at_deg']:6.1f} "
                         f"{s['equivalent_load_N']:8.0f} {s['L10h_h']:9.0f}")
        lines.append(f"  {'':>7} {'delta':<9} {b['delta_max_percent']:+7.1f}% {'':>6} {b['delta_min_percent']:+7.1f}% "
                     f"{'':>6} {b['delta_equivalent_percent']:+7.1f}%  life ratio {b['life_ratio']:.2f}")
    at = summary["peak_von_mises_at"]
    away = summary["stress"]["away_from_contacts"]
    h = summary["hertz"]
    fe = h.get("fe_rollers")
    lines += [
        "",
        f"  peak von Mises {summary['peak_von_mises_MPa']:.0f} MPa at ({at['x_mm']:.1f}, {at['y_mm']:.1f}) mm, "
        f"{at['feature_label']}, θ = {at['theta_deg']:.1f}°"
        + (f"; away from contacts {away['peak_von_mises_MPa']:.0f} MPa near {away['at']['feature_label']}"
           if away else ""),
        f"  pins in contact {summary['pins_in_contact']['min']}–{summary['pins_in_contact']['max']} of "
        f"{summary['pins_in_contact']['of']}; torsional stiffness {summary['torsional_stiffness_Nm_per_arcmin']:.1f} "
        f"N·m/arcmin; equilibrium residual {summary['equilibrium_residual']:.1e}",
    ]
    sr = h["stribeck_rigid"]
    hertz = (f"  Hertz, most loaded roller: rigid Stribeck Q = {sr['roller_load_N']:.0f} N, p_in "
             f"{sr['inner']['peak_pressure_MPa']:.0f} / p_out {sr['outer']['peak_pressure_MPa']:.0f} MPa")
    if fe:
        hertz += (f"; FE Q = {fe['roller_load_N']:.0f} N, p_in {fe['inner']['peak_pressure_MPa']:.0f} / p_out "
                  f"{fe['outer']['peak_pressure_MPa']:.0f} MPa")
    t = summary["timings_s"]
    lines += [
        hertz,
        f"  wall time {t['total']:.1f} s (cycle {t['cycle']:.1f} s, images {t.get('images', 0.0):.1f} s); "
        f"{len(summary['files'])} files",
    ]
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------
# The run
# --------------------------------------------------------------------------------------------


class _Stages:
    """Times the stages and reports them to the progress callback."""

    def __init__(self, progress: ProgressCallback | None):
        self.progress = progress
        self.seconds: dict[str, float] = {}

    def start(self, name: str, total: int = 1) -> float:
        log.info("%s", STAGES[name])
        if self.progress is not None:
            self.progress(name, 0, total)
        return time.perf_counter()

    def tick(self, name: str, done: int, total: int) -> None:
        if self.progress is not None:
            self.progress(name, done, total)

    def end(self, name: str, started: float, total: int = 1) -> None:
        self.seconds[name] = time.perf_counter() - started
        if self.progress is not None:
            self.progress(name, total, total)


def run_case(case: Case | str | os.PathLike, out_dir: str | os.PathLike, *, angle_step_deg: float | None = None,
             bearing_model: str | None = None, order: int | None = None, overwrite: bool = False,
             progress: ProgressCallback | None = None, cache_dir: str | os.PathLike = "meshes",
             images: bool = True, field_step_deg: float | None = None) -> RunSummary:
    """Run a case completely and write its result folder.

    Parameters
    ----------
    case : Case or path
        A case (e.g. built or modified in code) or the path of a case file.
    out_dir : path
        Result folder; must not exist or be empty unless ``overwrite``.
    angle_step_deg : float, optional
        Crank-angle step, degrees (overrides ``analysis.angle_step_deg``).
    bearing_model : {"rollers", "rigid_bore"}, optional
        Overrides ``crank_bearing.model``.
    order : {1, 2}, optional
        Element order; overrides ``analysis.element_order``.
    overwrite : bool
        Replace an existing non-empty ``out_dir`` (only once the new results are complete).
    progress : callable, optional
        See :data:`ProgressCallback`.
    cache_dir : path
        Mesh cache folder.
    images : bool
        Render the PyVista images (needs off-screen OpenGL; checked before anything is computed).
    field_step_deg : float, optional
        Also keep the displacement/stress fields every ``field_step_deg`` degrees (more VTU frames
        for a ParaView animation and a denser search for the stress peak); by default only the
        case's ``analysis.saved_angles_deg`` and the angle of the largest bearing load.

    Returns
    -------
    RunSummary

    Raises
    ------
    CaseError, GeometryError, MeshError, ContactError
        From the stages.
    OutputError
        The output folder exists (without ``overwrite``) or cannot be written.
    RenderError
        Off-screen rendering is impossible (only with ``images=True``).
    """
    t_run = time.perf_counter()
    stages = _Stages(progress)
    out_dir = Path(out_dir)

    t = stages.start("check")
    case, info = _resolve_case(case, angle_step_deg, bearing_model, order)
    thetas = _cycle_thetas(case)
    if field_step_deg is not None and not (0 < field_step_deg <= 360):
        raise CaseError(f"the field step must be in (0°, 360°], got {field_step_deg!r}")
    _check_target(out_dir, overwrite)
    if images:
        from .render import check_rendering

        check_rendering()
    created = _make_parents(out_dir)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.partial-", dir=out_dir.parent))
    except OSError as exc:
        _remove_created(created)
        raise OutputError(f"cannot write into {out_dir.parent}: {exc.strerror or exc}") from None
    try:
        umask = os.umask(0o022)
        os.umask(umask)
        os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes it private; the results are an ordinary folder
        stages.end("check", t)
        result = _run_stages(case, info, thetas, tmp, stages, cache_dir=cache_dir, images=images,
                             field_step_deg=field_step_deg, t_run=t_run)
        try:
            _commit(tmp, out_dir, overwrite)
        except OSError as exc:
            raise OutputError(f"cannot move the results into {out_dir}: {exc.strerror or exc}") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_created(created)
        raise
    return dataclasses.replace(result, out_dir=out_dir)


def _run_stages(case: Case, info: _CaseInfo, thetas: np.ndarray, tmp: Path, stages: _Stages, *,
                cache_dir, images: bool, field_step_deg: float | None, t_run: float) -> RunSummary:
    from . import compare, postprocess, rigid
    from .cycle import bore_centres, build_system, load_cycle
    from .evaluation import STRIBECK_FACTOR, duty_cycle_life
    from .geometry import disc_geometry, pin_centres
    from .mesh import mesh_case

    # -- mesh, model ---------------------------------------------------------------------------
    t = stages.start("mesh")
    geometry = disc_geometry(case)
    mesh = mesh_case(case, cache_dir, geometry=geometry)
    stages.end("mesh", t)

    t = stages.start("model")
    system = build_system(case, mesh)
    model = system.model
    stages.end("model", t)

    # -- rigid model (before the cycle: a case outside the handbook's assumptions fails fast) ----
    t = stages.start("rigid")
    hb = rigid.handbook_bearing_loads(case, thetas)
    classical = rigid.classical_pin_forces(case, thetas, exact_moment=True)
    stages.end("rigid", t)

    # -- flexible cycle ------------------------------------------------------------------------
    n = len(thetas)
    saved = tuple(case.analysis.saved_angles_deg)
    if field_step_deg is not None:
        saved = saved + tuple(np.arange(0.0, 360.0, field_step_deg))
    t = stages.start("cycle", n)
    def report(i: int, total: int) -> None:  # the last angle is reported by stages.end
        if i < total:
            stages.tick("cycle", i, total)

    cycle = load_cycle(system, thetas, progress=report, saved_angles_deg=saved, stress_envelope=True)
    stages.end("cycle", t, n)

    # -- evaluation ----------------------------------------------------------------------------
    t = stages.start("evaluation")
    comparison = compare.rigid_vs_flexible(case, cycle)
    # peaks over every solved angle (the cycle's stress envelope); their fields are kept too
    peak = postprocess.peak_von_mises(cycle, mesh.points, mesh.boundaries)
    band = {"profile": CONTACT_BAND_ELEMENTS * case.mesh.size_flank}
    band.update({f"bore_{i}": CONTACT_BAND_ELEMENTS * case.mesh.size_bore for i in range(case.cranks.count)})
    away = postprocess.peak_von_mises(cycle, mesh.points, mesh.boundaries, exclude=band)
    snapshots = postprocess.field_snapshots(
        system, cycle, extra_angles=[math.radians(pk.theta_deg) for pk in (peak, away) if pk is not None])
    k_max, i_max = postprocess.max_load_index(cycle.bearing_forces)
    # the first bearing among equals (the handbook curves are exact shifts of each other)
    rigid_max = max(comparison.bearings, key=lambda b: round(b.rigid.max_N, 6))
    hertz = postprocess.roller_hertz(case, cycle, rigid_max.rigid.max_N, rigid_max.rigid.max_at_deg,
                                     rigid_max.bearing)
    stiffness = cycle.torsional_stiffness_Nm_per_arcmin(case.loads.disc_torque_Nmm)
    stages.end("evaluation", t)

    files: list[str] = []

    def rel(p: Path) -> str:
        s = p.relative_to(tmp).as_posix()
        files.append(s)
        return s

    rigid_forces = np.stack([hb.fx.T, hb.fy.T], axis=2)              # (n, N, 2)
    pin_xy = np.stack([pin_centres(case, float(th)) for th in thetas])  # (n, Zp, 2)
    title = f"{case.name}"

    try:
        # -- tables ------------------------------------------------------------------------
        from . import tables

        t = stages.start("tables")
        rel(tables.write_bearing_loads(tmp / "bearing_loads.csv", thetas, cycle.bearing_forces, rigid_forces))
        if cycle.roller_loads is not None:
            rel(tables.write_roller_loads(tmp / "roller_loads.csv", thetas, cycle.roller_angles, cycle.roller_loads))
        rel(tables.write_pin_forces(tmp / "pin_forces.csv", thetas, pin_xy, cycle.pin_forces,
                                    classical.magnitude.T))
        rel(tables.write_cycle_table(tmp / "cycle.csv", thetas, cycle.pins_in_contact, cycle.carrier_rotation,
                                     cycle.equilibrium_residual, cycle.iterations))
        case_json = tmp / "case.json"
        case_json.write_text(json.dumps(case_to_dict(case), indent=2) + "\n", encoding="utf-8")
        rel(case_json)
        stages.end("tables", t)

        # -- VTK ---------------------------------------------------------------------------
        from . import vtkio

        t = stages.start("vtk", len(snapshots))
        (tmp / "vtk").mkdir()
        triangles = model.mesh.t.T
        vertices = model.mesh.p.T
        entries = []
        field_files: dict[int, dict] = {}
        for snap in snapshots:
            name = vtkio.vtu_name(snap.theta_deg)
            rel(vtkio.write_vtu(tmp / "vtk" / name, vertices, triangles, snap))
            entries.append((snap.theta_deg, name))
            field_files[snap.index] = {"theta_deg": snap.theta_deg, "vtu": f"vtk/{name}"}
        rel(vtkio.write_pvd(tmp / "vtk" / "disc.pvd", entries))
        stages.end("vtk", t, len(snapshots))

        # -- images ------------------------------------------------------------------------
        image_files: dict[str, str] = {}
        if images:
            from . import render

            t = stages.start("images", len(snapshots) + 3)
            (tmp / "images").mkdir()
            max_def = max(float(np.max(np.hypot(*s.deformation.T))) for s in snapshots)
            magnification = render.nice_factor(DEFORMATION_DISPLAY_FRACTION * case.pins.circle_radius / max_def)
            f_ref = max(float(cycle.bearing_loads.max()), float(hb.magnitude.max()))
            # colour range up to the peak away from the contacts (the structural field stays readable);
            # the contact spots above it are drawn in the "above" colour
            clim = (0.0, (away or peak).von_mises_MPa)
            bores = bore_centres(case)

            def scene(snap, label):
                k = snap.index
                pf = cycle.pin_forces[k]
                return render.StressScene(
                    points=vertices, triangles=triangles, boundaries=mesh.boundaries,
                    von_mises=snap.stress.nodal.von_mises, deformation=snap.deformation,
                    magnification=magnification, clim=clim,
                    pin_centres=pin_xy[k], pin_radius=case.pins.radius,
                    pin_loaded=pf > 1e-9 * max(float(pf.max()), 1.0),
                    bore_centres=bores, bearing_forces=cycle.bearing_forces[k], rigid_forces=rigid_forces[k],
                    force_scale=0.85 * case.crank_bearing.bore_radius / f_ref,
                    title=f"{title}   crank angle {snap.theta_deg:.1f}°{label}   von Mises on the disc deformed "
                          f"×{magnification:g}   bearings '{case.crank_bearing.model}', P{model.order}",
                )

            done = 0
            for snap in snapshots:
                label = "  (max. bearing load)" if snap.index == k_max else ""
                path = tmp / "images" / f"stress_theta_{snap.theta_deg % 360:06.2f}.png"
                render.stress_image(path, scene(snap, label), window_size=IMAGE_SIZE)
                image_files[f"stress_theta_{snap.theta_deg % 360:06.2f}"] = rel(path)
                field_files[snap.index]["image"] = image_files[f"stress_theta_{snap.theta_deg % 360:06.2f}"]
                done += 1
                stages.tick("images", done, len(snapshots) + 3)
            half = max(5.0, 12.0 * case.mesh.size_bore)
            for key, pk in (("stress_peak_closeup", peak), ("stress_away_from_contacts_closeup", away)):
                if pk is None:
                    continue
                snap = next(s for s in snapshots if math.isclose(s.theta_deg, pk.theta_deg))
                path = tmp / "images" / f"{key}.png"
                close = dataclasses.replace(
                    scene(snap, ""), magnification=0.0, clim=(0.0, pk.von_mises_MPa),
                    title=f"{title}   crank angle {snap.theta_deg:.1f}°   close-up (undeformed): von Mises "
                          f"{pk.von_mises_MPa:.0f} MPa at the ring, {pk.feature_label}")
                render.stress_image(path, close, focus=(pk.x_mm, pk.y_mm), half_height=half,
                                    marker=(pk.x_mm, pk.y_mm), show_edges=True, window_size=IMAGE_SIZE)
                image_files[key] = rel(path)
                done += 1
                stages.tick("images", done, len(snapshots) + 3)
            b0 = bores[0] * (1.0 + (case.crank_bearing.bore_radius + 3.0) / np.hypot(*bores[0]))
            path = render.mesh_image(tmp / "images" / "mesh.png", vertices, triangles, mesh.boundaries,
                                     title=f"{title}: {mesh.n_nodes} vertices, {mesh.n_elements} triangles "
                                           f"(min quality {mesh.min_quality:.2f})",
                                     closeup_centre=(float(b0[0]), float(b0[1])))
            image_files["mesh"] = rel(path)
            stages.end("images", t, len(snapshots) + 3)

        # -- plots -------------------------------------------------------------------------
        from . import plots

        t = stages.start("plots")
        (tmp / "plots").mkdir()
        plot_files: dict[str, str] = {}
        plot_files["bearing_loads"] = rel(plots.bearing_loads_plot(
            tmp / "plots" / "bearing_loads.png", thetas, cycle.bearing_loads, hb.magnitude.T,
            title=f"{title}: crank-bearing loads, flexible (FE, '{case.crank_bearing.model}') vs rigid handbook"))
        th_max = math.degrees(float(thetas[k_max]))
        if cycle.roller_loads is not None:
            plot_files["roller_loads"] = rel(plots.roller_loads_plot(
                tmp / "plots" / "roller_loads.png", cycle.roller_angles[k_max], cycle.roller_loads[k_max],
                cycle.bearing_forces[k_max], theta_deg=th_max))
        plot_files["pin_forces"] = rel(plots.pin_forces_plot(
            tmp / "plots" / "pin_forces.png", np.arange(1, case.pins.count + 1), cycle.pin_forces[k_max],
            classical.magnitude[:, k_max], theta_deg=th_max))
        plot_files["pins_in_contact"] = rel(plots.pins_in_contact_plot(
            tmp / "plots" / "pins_in_contact.png", thetas, cycle.pins_in_contact, case.pins.count,
            classical=np.count_nonzero(classical.magnitude > 0, axis=0)))
        stages.end("plots", t)

        # -- summary and report ------------------------------------------------------------
        t = stages.start("report")
        b = case.crank_bearing
        bearings = []
        for bc in comparison.bearings:
            bearings.append({
                "bearing": bc.bearing + 1,
                "crank_angle_deg": case.cranks.angles_deg[bc.bearing],
                "rigid": _stats_dict(bc.rigid),
                "flexible": _stats_dict(bc.flexible),
                "equal_share": _stats_dict(bc.equal_share),
                "delta_max_percent": bc.delta_max_percent,
                "delta_min_percent": bc.delta_min_percent,
                "delta_equivalent_percent": bc.delta_equivalent_percent,
                "life_ratio": bc.life_ratio,
            })
        summary: dict[str, Any] = {
            "schema_version": SCHEMA_VERSION,
            "rvfem_version": __version__,
            "case": {
                "name": case.name,
                "description": case.description,
                "file": info.file,
                "sha256": info.sha256,
                "matches_file": info.matches_file,
                "digest": case.digest(),
                "overrides": info.overrides,
                "defaults_used": {k: v for k, v in info.defaults_used},
            },
            "model": {
                "bearing_model": b.model,
                "element_order": model.order,
                "pin_model": system.pin_model,
                "pin_friction": case.analysis.friction,
                "nodes": model.n_nodes,
                "vertices": model.n_vertices,
                "dofs": model.n_dofs,
                "elements": model.n_elements,
                "mesh_file": mesh.path.name,
                "mesh_min_quality": mesh.min_quality,
                "angle_step_deg": 360.0 / n,
                "angles": n,
                "output_torque_Nm": case.loads.torque_Nm,
                "discs": case.loads.discs,
                "disc_torque_Nmm": case.loads.disc_torque_Nmm,
                "torque_convention": "disc torque T_out/discs = moment of the pin forces about the disc centre "
                                     "(handbook: sum P_x = T/(2 e Zc))",
                "radial_clearance_mm": b.radial_clearance,
                "equivalent_load_exponent": comparison.exponent,
                "dynamic_load_rating_N": comparison.rating_N,
                "bearing_speed_rpm": comparison.bearing_speed_rpm,
                "handbook_k_y": comparison.handbook_k_y,
                "fe_pin_resultant_ratio": comparison.pin_resultant_ratio,
            },
            "bearings": bearings,
            "max_bearing_load": {
                "bearing": i_max + 1,
                "theta_deg": th_max,
                "flexible_N": float(cycle.bearing_loads[k_max, i_max]),
            },
            "pins_in_contact": {
                "min": int(cycle.pins_in_contact.min()),
                "max": int(cycle.pins_in_contact.max()),
                "mean": float(cycle.pins_in_contact.mean()),
                "of": case.pins.count,
            },
            "peak_von_mises_MPa": peak.von_mises_MPa,
            "peak_von_mises_at": _peak_dict(peak),
            "stress": {
                "peak_element_von_mises_MPa": max(float(s.stress.element.von_mises.max()) for s in snapshots),
                "away_from_contacts": None if away is None else {
                    "peak_von_mises_MPa": away.von_mises_MPa,
                    "at": _peak_dict(away),
                    "profile_band_mm": band["profile"],
                    "bore_band_mm": band.get("bore_0"),
                },
                "field_angles_deg": [s.theta_deg for s in snapshots],
            },
            "torsional_stiffness_Nm_per_arcmin": stiffness,
            "carrier_rotation_arcmin": {
                "min": float(np.degrees(cycle.carrier_rotation.min()) * 60.0),
                "max": float(np.degrees(cycle.carrier_rotation.max()) * 60.0),
                "mean": float(np.degrees(cycle.carrier_rotation.mean()) * 60.0),
            },
            "equilibrium_residual": float(cycle.equilibrium_residual.max()),
            "active_set_iterations": {"max": int(cycle.iterations.max()), "mean": float(cycle.iterations.mean())},
            "hertz": {
                "stribeck_factor": STRIBECK_FACTOR,
                "fe_rollers": _hertz_dict(hertz["fe_rollers"]) if "fe_rollers" in hertz else None,
                "stribeck_rigid": _hertz_dict(hertz["stribeck_rigid"]),
                "stribeck_flexible": _hertz_dict(hertz["stribeck_flexible"]),
            },
            "fields": [field_files[k] for k in sorted(field_files, key=lambda k: field_files[k]["theta_deg"])],
            "images": image_files,
            "plots": plot_files,
        }
        if case.loads.duty_cycle:
            duty = {}
            for key in ("rigid", "flexible"):
                life = min(bb[key]["L10h_h"] for bb in bearings)
                d = duty_cycle_life(case.loads.duty_cycle, life, case.loads.speed_rpm, case.loads.torque_Nm)
                duty[key] = {"rated_life_h": life, **dataclasses.asdict(d)}
            summary["duty_cycle"] = duty

        from .report import write_report

        timings = dict(stages.seconds)
        timings.update({
            "model_" + k: v for k, v in system.setup_seconds.items()
        })
        timings["cycle_per_angle"] = stages.seconds["cycle"] / n
        summary["timings_s"] = timings
        summary["files"] = sorted(files + ["report.html", "summary.json"])
        summary["timings_s"]["total"] = time.perf_counter() - t_run
        summary = _finite(summary)
        write_report(tmp / "report.html", summary, case, tmp)
        stages.end("report", t)
        summary["timings_s"]["report"] = stages.seconds["report"]
        summary["timings_s"]["total"] = time.perf_counter() - t_run
        (tmp / "summary.json").write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    except OSError as exc:
        raise OutputError(f"cannot write the results: {exc}") from None

    return RunSummary(out_dir=tmp, summary=summary, case=case, system=system, cycle=cycle,
                      comparison=comparison, files=tuple(summary["files"]))
