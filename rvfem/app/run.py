"""The analyst's main job: one case from the case file to a folder of results.

:func:`run_case` runs the whole chain — check → mesh (cached) → rigid handbook model → flexible
load cycle → evaluation → outputs — and writes::

    DIR/summary.json        key numbers (schema: docs/outputs.md)
    DIR/report.html         self-contained report (images embedded)
    DIR/case.json           the case as analysed (after overrides); case_from_dict() reads it back
    DIR/bearing_loads.csv   θ, per bearing Fx, Fy, |F| flexible, rigid and equal share
    DIR/roller_loads.csv    roller loads (bearing model "rollers")
    DIR/pin_forces.csv      FE and classical pin forces
    DIR/cycle.csv           pins in contact, carrier rotation, residual, iterations per angle
    DIR/vtk/disc.pvd        ParaView collection over θ of DIR/vtk/disc_theta_*.vtu
    DIR/images/*.png        von Mises on the deformed disc per kept angle, close-ups, the mesh
    DIR/plots/*.png         bearing loads, roller loads, pin forces, pins in contact

It is :func:`rvfem.app.analysis.analyse` (everything computed, nothing written) followed by the writers
of :mod:`rvfem.outputs.summary`, one per format. With images, off-screen rendering is checked by a child
process (:class:`rvfem.outputs.render.RenderWorker`) started with the run: the check runs while the mesh
and the model are built, and the run waits for it before the load cycle (a failed check stops the
run there); the same process then draws the stress images and the plots of the load cycle, from
the end of the ``stress`` section on, and the plots of the crank bearing in depth, from its end on,
while the other sections are computed and the other files written. Nothing is lost: the outputs are written into a temporary
folder next to DIR (:func:`rvfem.outputs.summary.result_folder`) and moved into place only when complete. An existing non-empty DIR is replaced only with ``overwrite=True`` (and only
after the new results are complete); a run that fails or is interrupted leaves neither DIR (nor
the previous results changed) nor the temporary folder.

Example (notebook)::

    from rvfem.app.run import run_case
    result = run_case("cases/rv40e_fanholes.toml", "results/rv40e_fanholes", overwrite=True)
    result.summary["bearings"][0]["flexible"]["max_load_N"]
"""

from __future__ import annotations

import dataclasses
import itertools
import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from rvfem.app import analysis as _analysis
from rvfem.app.analysis import (
    Analysis,
    CONTACT_BAND_ELEMENTS,
    CaseProvenance,
    ProgressCallback,
    Stages,
    analyse,
    resolve_case,
)
from rvfem.app import screen
from rvfem.case.definition import Case
from rvfem.outputs import summary as outputs
from rvfem.outputs.render import RenderWorker
from rvfem.outputs.summary import IMAGE_SIZE, SCHEMA_VERSION

log = logging.getLogger(__name__)

__all__ = [
    "SCHEMA_VERSION",
    "STAGES",
    "CONTACT_BAND_ELEMENTS",
    "IMAGE_SIZE",
    "RunSummary",
    "ProgressCallback",
    "run_stages",
    "outside_stages",
    "run_case",
    "summary_text",
]

STAGES: dict[str, str] = {
    **_analysis.STAGES,
    "check": "checking the case, the output folder and off-screen rendering",
    "tables": "writing summary tables (CSV)",
    "vtk": "writing VTK files for ParaView",
    "plots": "plotting",
    "images": "rendering stress images",
    "report": "writing the report",
}
"""Stages of a run in the order of a run without images, with a one-line description (what the progress callback reports):
those of :func:`rvfem.app.analysis.analyse`, then one per writer. With images, the stress images and
the plots are drawn by a child process (:class:`rvfem.outputs.render.RenderWorker`) from the start of the
writers on (the mesh picture from the end of the ``model`` stage on, during the load cycle), while
this process writes the tables and the VTK files and then computes the attribution (it enters only
the summary and the report; stage ``attribution``, reported after ``vtk``); the ``plots`` and
``images`` stages are then the waits for the child process."""


def summary_text(summary: dict) -> str:
    """The screen text of a run's summary (:func:`rvfem.app.screen.summary_text`) with the time of
    its stages."""
    return screen.summary_text(summary, tuple(STAGES))


def run_stages(case: Case, *, images: bool = True) -> tuple[str, ...]:
    """The stages a run of ``case`` reports, in the order it reports them (each once; a subset of
    :data:`STAGES`).

    With images the attribution is computed after the VTK files, while the render worker draws,
    and the ``images`` stage is the wait for the images; without images it is computed beside the
    stress stage. The ``duty_cycle`` stage is there only when the case has a duty cycle, the
    ``roller_slices`` stage only with the bearing model ``rollers``.

    Parameters
    ----------
    case : Case
    images : bool
        As :func:`run_case`'s ``images``.

    Returns
    -------
    tuple of str
    """
    analysis = ["mesh", "model", "rigid", "cycle", "evaluation", "stress"]
    duty = ["duty_cycle"] if case.loads.duty_cycle else []
    duty += ["accuracy"] + (["roller_slices"] if case.crank_bearing.model == "rollers" else [])
    if images:
        order = ["check", *analysis, *duty, "tables", "vtk", "attribution", "plots", "images", "report"]
    else:
        order = ["check", *analysis, "attribution", *duty, "tables", "vtk", "plots", "report"]
    return tuple(order)


@dataclass(frozen=True, eq=False)
class RunSummary:
    """Result of :func:`run_case`.

    Attributes
    ----------
    out_dir : Path
        The result folder (complete).
    summary : dict
        The content of ``summary.json``.
    analysis : rvfem.app.analysis.Analysis
        Everything computed (mesh, model, cycle, comparison, stresses, Hertz, …).
    files : tuple of str
        Files written, relative to ``out_dir``.
    """

    out_dir: Path
    summary: dict
    analysis: Analysis
    files: tuple[str, ...]

    @property
    def case(self) -> Case:
        """The case as analysed (overrides applied)."""
        return self.analysis.case

    @property
    def system(self):
        """The factorised disc model (:class:`rvfem.solve.cycle.DiscSystem`), for further solves."""
        return self.analysis.system

    @property
    def cycle(self):
        """The flexible load cycle (:class:`rvfem.solve.cycle.CycleResult`)."""
        return self.analysis.cycle

    @property
    def comparison(self):
        """Rigid vs flexible per bearing (:class:`rvfem.evaluate.compare.Comparison`)."""
        return self.analysis.comparison


def run_case(case: Case | str | os.PathLike, out_dir: str | os.PathLike, *, angle_step_deg: float | None = None,
             bearing_model: str | None = None, order: int | None = None, overwrite: bool = False,
             progress: ProgressCallback | None = None, cache_dir: str | os.PathLike | None = None,
             images: bool = True, field_step_deg: float | None = None,
             overrides: tuple[str, ...] = ()) -> RunSummary:
    """Run a case completely and write its result folder.

    Parameters
    ----------
    case : Case or path
        A case (e.g. built or modified in code, or read with overrides) or the path of a case file.
    out_dir : path
        Result folder; must not exist or be empty unless ``overwrite``.
    angle_step_deg : float, optional
        Crank-angle step, degrees (overrides ``analysis.angle_step_deg``).
    bearing_model : str, optional
        Overrides ``crank_bearing.model`` (:func:`rvfem.case.registry.bearing_model_names`).
    order : {1, 2}, optional
        Element order; overrides ``analysis.element_order``.
    overwrite : bool
        Replace an existing non-empty ``out_dir`` (only once the new results are complete).
    progress : callable, optional
        See :data:`ProgressCallback`; the stages are :data:`STAGES`.
    cache_dir : path, optional
        Mesh cache folder; default :func:`rvfem.app.analysis.default_cache_dir` (the repository's
        ``meshes/`` in a source checkout, else the per-user cache).
    images : bool
        Render the PyVista images (needs off-screen OpenGL; checked while the mesh and the model
        are built, and before the load cycle).
    field_step_deg : float, optional
        Also keep the displacement/stress fields every ``field_step_deg`` degrees (more VTU frames
        for a ParaView animation); by default only the case's ``analysis.saved_angles_deg``, the
        angle of the largest bearing load and the angles of the stress peaks.
    overrides : tuple of str
        ``KEY=VALUE`` case overrides when ``case`` is a path (:func:`rvfem.case.definition.load_case`).

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
    stages = Stages(progress, STAGES)
    out_dir = Path(out_dir)

    checked = _checked_run(case, out_dir, stages, overrides=overrides, angle_step_deg=angle_step_deg,
                           bearing_model=bearing_model, order=order, field_step_deg=field_step_deg,
                           overwrite=overwrite, images=images)
    worker = checked.worker
    try:
        with outputs.result_folder(out_dir, overwrite=overwrite) as tmp:
            try:
                result, drawings = _analyse_for_run(checked, tmp, stages, progress=progress, cache_dir=cache_dir,
                                                    field_step_deg=field_step_deg)
                summary, files, result = _write_outputs(result, tmp, stages, worker, t_run, drawings)
            finally:
                if worker is not None:
                    worker.close()   # before the folder is moved or removed: nothing writes into it
    finally:
        if worker is not None:
            worker.close()

    return RunSummary(out_dir=out_dir, summary=summary, analysis=result, files=files)


@dataclass(frozen=True, eq=False)
class _CheckedRun:
    """What the ``check`` stage of :func:`run_case` gives.

    Attributes
    ----------
    case : Case
        The case with the options applied (:func:`rvfem.app.analysis.resolve_case`).
    provenance : CaseProvenance
    worker : rvfem.outputs.render.RenderWorker or None
        The render worker checking off-screen rendering (None without images).
    """

    case: Case
    provenance: CaseProvenance
    worker: RenderWorker | None


def _checked_run(case: Case | str | os.PathLike, out_dir: Path, stages: Stages, *, overrides: tuple[str, ...],
                 angle_step_deg: float | None, bearing_model: str | None, order: int | None,
                 field_step_deg: float | None, overwrite: bool, images: bool) -> _CheckedRun:
    """The ``check`` stage of :func:`run_case`: the case resolved with its options, its angles and
    the output folder checked, and with images the render worker started (its rendering check
    runs meanwhile; one this process knows to fail raises at once)."""
    t = stages.start("check")
    case, provenance = resolve_case(case, overrides=overrides, angle_step_deg=angle_step_deg,
                                    bearing_model=bearing_model, order=order)
    _analysis.cycle_angles(case)
    _analysis.kept_field_angles(case, field_step_deg)
    outputs.check_output_folder(out_dir, overwrite)
    worker = None
    if images:
        worker = RenderWorker(IMAGE_SIZE)   # checks off-screen rendering meanwhile
        worker.check(wait=False)            # raises at once if this process knows it fails
    stages.end("check", t)
    return _CheckedRun(case=case, provenance=provenance, worker=worker)


def _analyse_for_run(checked: _CheckedRun, tmp: Path, stages: Stages, *, progress: ProgressCallback | None,
                     cache_dir: str | os.PathLike | None, field_step_deg: float | None):
    """The analysis of a run (:func:`rvfem.app.analysis.analyse`); returns it and what the render
    worker was handed meanwhile (:class:`_Drawings`; empty without a worker).

    With a render worker the mesh picture is handed to it once the model is built (it draws
    during the load cycle), the load cycle waits for its rendering check, the stress images and
    the plots of the load cycle are handed to it as soon as the ``stress`` section is computed and
    the plots of the crank bearing in depth once the ``roller_depth`` section is (it draws them
    while the other sections are computed: the crank bearing in depth, the L10r steps, ...), and the attribution is
    left for :func:`_write_outputs` to compute while the worker draws; the waits for the
    rendering check count in the ``check`` stage. (Handing the drawings over early: 0.91 of the run's
    wall time on the default case, benchmarks/README.md, "Overlap of the run's processes".)
    """
    worker = checked.worker
    waited, drawings = [0.0], _Drawings()

    def draw_mesh(system):   # the worker draws the mesh picture during the load cycle
        t = time.perf_counter()
        try:
            drawings.mesh_call = outputs.start_mesh_picture(system, tmp, worker)
        finally:
            waited[0] += time.perf_counter() - t   # the rendering check, if not done

    def draw_stress_images(partial):   # the worker draws them beside the sections after the stress
        drawings.started = time.perf_counter()
        drawings.images = outputs.submit_images(partial, tmp, worker, mesh_call=drawings.mesh_call,
                                                calls=outputs.plot_calls(partial, tmp, group="cycle"))
        drawings.handover_s = time.perf_counter() - drawings.started

    def draw_roller_plots(partial):    # every result the other plots show is computed by now
        if drawings.images is not None:
            t = time.perf_counter()
            drawings.images.add_calls(outputs.plot_calls(partial, tmp, group="roller_depth"))
            drawings.plots_handed = True
            drawings.handover_s += time.perf_counter() - t

    # with a render worker the attribution is computed here while the worker draws
    result = analyse(checked.case, provenance=checked.provenance, field_step_deg=field_step_deg,
                     cache_dir=cache_dir, progress=_checked_before_cycle(progress, worker, waited),
                     attribute=worker is None,
                     after={"model": draw_mesh, "stress": draw_stress_images, "roller_depth": draw_roller_plots}
                     if worker is not None else {})
    stages.seconds["check"] += waited[0]
    return result, drawings


@dataclass
class _Drawings:
    """What a run's render worker was handed during the analysis (:func:`_analyse_for_run`).

    Attributes
    ----------
    mesh_call : int or None
        The number of the mesh picture's call (:func:`rvfem.outputs.summary.start_mesh_picture`).
    images : PendingImages or None
        The stress images and the plots of the load cycle, handed over once the ``stress`` section
        was computed.
    plots_handed : bool
        The plots of the crank bearing in depth were handed over too (once the ``roller_depth``
        section was computed).
    started : float or None
        When they were handed over (``time.perf_counter``).
    handover_s : float
        The time handing them over took (building the scenes, sending them), s.
    """

    mesh_call: int | None = None
    images: outputs.PendingImages | None = None
    plots_handed: bool = False
    started: float | None = None
    handover_s: float = 0.0


def _checked_before_cycle(progress: ProgressCallback | None, worker, waited: list[float]) -> ProgressCallback:
    """The progress callback of the analysis: waits for the rendering check of ``worker`` (if any)
    when the load cycle starts (its RenderError aborts the analysis), adding the wait to
    ``waited[0]``, then reports to ``progress``."""

    def report(stage: str, done: int, total: int) -> None:
        if worker is not None and stage == "cycle" and done == 0:
            t = time.perf_counter()
            try:
                worker.check()
            finally:
                waited[0] += time.perf_counter() - t
        if progress is not None:
            progress(stage, done, total)

    return report


def _write_outputs(result, tmp: Path, stages: Stages, worker, t_run: float, drawings: _Drawings | None = None):
    """Write every file of the result folder ``tmp``; returns the summary, the files and the
    analysis (with its attribution).

    The writers are the registered ones (:func:`rvfem.outputs.summary.writers`), in their order:
    those that do not need the summary by :func:`_write_files`; then the summary is built, and the
    writers that take it run, ``report.html`` in the ``report`` stage and ``summary.json`` (stage
    None) last, holding the time of every stage. The images and the plots are handed to ``worker``
    first (its child process draws them meanwhile); this process writes the tables and the VTK
    files, then computes the attribution (if the analysis left it: it enters only the summary and
    the report; after the VTK files, which a thread of pure Python beside them would slow down),
    then waits for the plots and the images. Without a worker the plots are drawn here.
    """
    computed = []

    def attribute() -> None:
        t = stages.start("attribution")
        computed.append(_analysis.timed(_analysis.attribution_of, result.system, result.theta, result.cycle))
        stages.end("attribution", t)

    registered = outputs.writers(images=worker is not None)
    written = _write_files(result, tmp, stages, worker, [w for w in registered if not w.needs_summary],
                           drawings or _Drawings(), meanwhile=attribute if result.attribution is None else None)
    if computed:
        (value, seconds), = computed
        result = dataclasses.replace(result, attribution=value,
                                     warnings=result.warnings + _analysis.attribution_warnings(value),
                                     timings={**result.timings, "attribution_compute": seconds})

    last = [w for w in registered if w.needs_summary]
    t = stages.start("report")
    timings = {"check": stages.seconds["check"], **result.timings,
               **{k: v for k, v in stages.seconds.items() if k != "check"}}
    timings["total"] = time.perf_counter() - t_run
    timings["other"] = outside_stages(timings)
    files = tuple(sorted({p.relative_to(tmp).as_posix() for p in written} | {f for w in last for f in w.files}))
    summary = outputs.build_summary(result, outputs.SummaryContext(files=files, timings=timings))
    for w in last:
        if w.stage is not None:
            w.write(result, tmp, summary=summary)   # report.html
    stages.end("report", t)
    summary["timings_s"]["report"] = stages.seconds["report"]
    summary["timings_s"]["total"] = time.perf_counter() - t_run
    summary["timings_s"]["other"] = outside_stages(summary["timings_s"])
    for w in last:
        if w.stage is None:
            w.write(result, tmp, summary=summary)   # summary.json, with the time of every stage
    return summary, files, result


def outside_stages(timings: dict) -> float:
    """The part of the wall time ``timings["total"]`` that no stage of :data:`STAGES` holds, s:
    the handing over between the stages (the summary, the bearing checks, starting the child
    processes). The stages are spans of this process's wall time one after the other (work done
    beside them by a thread or a child process counts only as the wait for it), so
    ``total = Σ stages + other``."""
    return timings["total"] - sum(float(timings.get(stage, 0.0)) for stage in STAGES)


def _write_files(result, tmp: Path, stages: Stages, worker, registered: list[outputs.Writer], drawings: _Drawings,
                 meanwhile: Callable[[], None] | None = None) -> list[Path]:
    """Call the ``registered`` writers (the tables, the VTK files, the plots and the images), each
    run of writers sharing a stage reported as that stage. With ``worker`` the plots and the images
    are handed to it first, those that ``drawings`` does not hold already (and the mesh picture
    unless it was started already), and the writers taking ``pending`` wait for them;
    ``meanwhile()`` is called before the first of those."""
    t_submit = time.perf_counter()
    pending = None
    if worker is not None:   # the child process draws the plots too (it has matplotlib loaded)
        if drawings.images is not None:
            pending = drawings.images
            if not drawings.plots_handed:
                pending.add_calls(outputs.plot_calls(result, tmp, group="roller_depth"))
        else:
            pending = outputs.submit_images(result, tmp, worker, calls=outputs.plot_calls(result, tmp),
                                            mesh_call=drawings.mesh_call)
    submitted = time.perf_counter() - t_submit + drawings.handover_s
    if drawings.started is not None:
        t_submit = drawings.started

    written: list[Path] = []
    drawn = t_submit   # when the last writer waiting for the worker's drawings had them
    for stage, stage_writers in itertools.groupby(registered, key=lambda w: w.stage):
        group = list(stage_writers)
        waits = any("pending" in w.options for w in group)
        if meanwhile is not None and waits:
            meanwhile()
            meanwhile = None
        total = next((w.ticks(result) for w in group if w.ticks is not None), 1)
        t = stages.start(stage, total)
        for w in group:
            options = {"tick": lambda done, n, stage=stage: stages.tick(stage, done, n), "pending": pending}
            written += w.write(result, tmp, **{k: options[k] for k in w.options})
        stages.end(stage, t, total)
        if waits:
            drawn = time.perf_counter()
    if meanwhile is not None:   # no writer waited for the worker
        meanwhile()
    if pending is not None:
        stages.seconds["images"] += submitted   # handing the drawings over counts as drawing
        # the child process draws while this one writes: the stages above are only the waits for it
        stages.seconds["drawing_background"] = drawn - t_submit
    return written
