"""One analysis of a case, computed and held in memory: nothing is written.

:func:`analyse` runs the chain check → mesh (cached) → FE model → rigid handbook model → flexible
load cycle → evaluation (rigid vs flexible, stresses, Hertz, stiffness, duty cycle) and returns an
:class:`Analysis`, a frozen object with every result a report needs. The writers of
:mod:`rvfem.outputs.summary` turn it into files; :func:`rvfem.app.run.run_case` chains the two. A notebook or a
design study uses :func:`analyse` directly::

    from rvfem.app.analysis import analyse
    a = analyse("cases/rv40e_fanholes.toml", angle_step_deg=5.0)
    a.comparison.bearings[0].delta_max_percent, a.stress.peak.von_mises_MPa

:func:`analyse_rigid` is the rigid handbook evaluation alone (what ``rvfem rigid`` prints): loads,
ISO 281 rating and life, Stribeck/Hertz pressures and the duty cycle, in milliseconds.

:func:`analyse` is a scheduler: after its fixed front (check, mesh, model, rigid references, load
cycle and its stress envelope) it computes every result section of :mod:`rvfem.results.registry` in
the order of their stages, with the P2 model in a child process and the attribution on a background
thread as executor choices. Adding a result is a section (:class:`rvfem.results.section.Section`: what
it requires, its ``compute``, its summary keys and their documentation, its screen lines and report
rows) and its line in :data:`rvfem.results.registry.BUILTIN_SECTIONS`, or one
:func:`rvfem.results.registry.register_section` line from outside the package; its result is the
:class:`Analysis` field of its name or ``Analysis.extra[name]``. The physics and the sources of every
formula are in docs/theory.md.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
import platformdirs

from rvfem._child import ChildProcess
from rvfem.app.case_resolution import MIN_ANGLES, cycle_angles, resolve_case
from rvfem.app.p2_model import P2Model, models_in_package, recover_structural_peak, start_p2_child
from rvfem.app.stages import STAGES, ProgressCallback, Stages, StageSteps, timed
from rvfem.case.definition import Case
from rvfem.case.mesh_checks import contact_grid_spacing
from rvfem.errors import CaseError
from rvfem.evaluate import attribution, bearing_checks, compare, hertz, iso281, postprocess, rigid, roller_life, roller_slices, validity
from rvfem.geometry import disc_geometry
from rvfem.mesh import mesh_case
from rvfem.results import attribution as attribution_section
from rvfem.results import registry as sections_registry
from rvfem.results.analysis import (
    Analysis,
    AnalysisOptions,
    CaseProvenance,
    DutyCycleFE,
    DutyCycleResult,
    RigidAnalysis,
    RigidBearing,
    StressResult,
)
from rvfem.results.duty_cycle import duty_cycle_fe
from rvfem.results.section import Section
from rvfem.solve import cycle as cycle_module

if TYPE_CHECKING:  # the heavier modules are imported where used
    from rvfem.evaluate.attribution import Attribution
    from rvfem.evaluate.postprocess import FieldSnapshot, PeakStress
    from rvfem.evaluate.validity import ResultWarning
    from rvfem.geometry import DiscGeometry
    from rvfem.mesh import DiscMesh
    from rvfem.solve.cycle import CycleResult, DiscSystem

log = logging.getLogger(__name__)

__all__ = [
    "STAGES",
    "CONTACT_BAND_ELEMENTS",
    "MIN_ANGLES",
    "AnalysisOptions",
    "StressEnvelope",
    "attribution_of",
    "attribution_warnings",
    "ProgressCallback",
    "Stages",
    "CaseProvenance",
    "RigidBearing",
    "RigidAnalysis",
    "StressResult",
    "DutyCycleFE",
    "DutyCycleResult",
    "duty_cycle_fe",
    "Analysis",
    "resolve_case",
    "cycle_angles",
    "kept_field_angles",
    "default_cache_dir",
    "repository_path",
    "analyse_rigid",
    "analyse",
]

CONTACT_BAND_ELEMENTS = 6.0
"""Width of the band along the tooth profile and the bores excluded from the "away from contacts"
stress peak, in element sizes there (``mesh.size_flank``, ``mesh.size_bore``, or the contact grid's
spacing where it is coarser): four times the footprint half-width over which the pin and roller
forces are spread."""




# --------------------------------------------------------------------------------------------
# The case as analysed
# --------------------------------------------------------------------------------------------




# --------------------------------------------------------------------------------------------
# Rigid handbook evaluation (``rvfem rigid``)
# --------------------------------------------------------------------------------------------






def analyse_rigid(case: Case, theta: np.ndarray | None = None,
                  progress: Callable[[int, int], None] | None = None) -> RigidAnalysis:
    """Rigid handbook evaluation of a case (Gao et al. eqs. 4-14 and 20-22; see docs/theory.md).

    Parameters
    ----------
    case : Case
    theta : ndarray, optional
        Crank angles, rad; default one turn at ``analysis.angle_step_deg``
        (:func:`rvfem.evaluate.rigid.load_cycle_angles`).
    progress : callable, optional
        ``progress(done, total)`` after the slices of each raceway of each bearing (bearing model ``rollers``).

    Returns
    -------
    RigidAnalysis
        For Zp − Zc ≠ 1 the handbook is not defined: NaN loads, no bearings, and the reason in
        ``references``.

    Raises
    ------
    CaseError
        If the cranks are not equally spaced (no rigid reference applies).
    """
    refs = rigid.references(case, fe=False)
    exponent = case.analysis.equivalent_load_exponent
    rating = iso281.crank_bearing_rating(case.crank_bearing)
    speed = iso281.case_bearing_speed_rpm(case)
    if not refs.handbook.defined and case.pins.count - case.cycloid.teeth != 1:
        log.info("%s: the handbook model is %s", case.name, refs.handbook.why)
        return RigidAnalysis(case=case, loads=rigid.undefined_loads(case, theta), bearings=(), rating_N=rating,
                             bearing_speed_rpm=speed, exponent=exponent,
                             stribeck_factor=hertz.rigid_ring_factor(case.crank_bearing.rollers),
                             duty_cycle=None, references=refs)
    loads = rigid.handbook_bearing_loads(case, theta)
    mat = case.material
    forces = np.stack([loads.fx.T, loads.fy.T], axis=2)                     # (n, N, 2)
    rollers = roller_slices.case_rigid_roller_loads(case, loads.theta, forces)   # the one rigid roller model
    summaries = rigid.summarize_bearing_loads(loads, exponent)
    depths = {}
    if case.crank_bearing.model == "rollers":
        depths = {d.bearing: d for d in roller_life.rigid_bearing_depths(
            case, loads.theta, forces, {s.bearing: s.equivalent_N for s in summaries}, rating, speed,
            progress=progress)}
    bearings, factors = [], []
    for s in summaries:
        k, j = np.unravel_index(int(np.argmax(rollers[:, s.bearing])), rollers[:, s.bearing].shape)
        q = float(rollers[k, s.bearing, j])
        factors.append(case.crank_bearing.rollers * q / float(np.linalg.norm(forces[k, s.bearing])))
        inner, outer = hertz.roller_raceway_contacts(case.crank_bearing, q, youngs_modulus_MPa=mat.youngs_modulus,
                                                     poissons_ratio=mat.poissons_ratio)
        bearings.append(RigidBearing(
            loads=rigid.with_rating_life(s, rating, speed),
            crank_angle_deg=case.cranks.angles_deg[s.bearing],
            max_roller_load_N=q,
            hertz_inner=inner,
            hertz_outer=outer,
            max_roller_theta_deg=math.degrees(float(loads.theta[k])),
            depth=depths.get(s.bearing),
        ))
    # every L10h is set (rigid.with_rating_life)
    duty = iso281.case_duty_cycle_life(case, [b.loads.L10h for b in bearings if b.loads.L10h is not None])
    c0 = bearing_checks.crank_bearing_static_rating(case.crank_bearing)
    checks = bearing_checks.BearingChecks(
        static={"rigid": bearing_checks.static_safety(c0, max(s.max_N for s in summaries))},
        minimum={"rigid": bearing_checks.minimum_load(min(s.min_N for s in summaries), rating)},
        support=None, support_note="the handbook model has no crankshaft beam: support-bearing loads come with rvfem run")
    result = RigidAnalysis(case=case, loads=loads, bearings=tuple(bearings), rating_N=rating, bearing_speed_rpm=speed,
                           exponent=exponent, stribeck_factor=max(factors), duty_cycle=duty,
                           references=refs, checks=checks)
    return dataclasses.replace(result, warnings=validity.rigid_warnings(result) + validity.bearing_check_warnings(checks))


# --------------------------------------------------------------------------------------------
# The full analysis
# --------------------------------------------------------------------------------------------












def repository_path(relative: str | os.PathLike[str], start: str | os.PathLike[str] | None = None) -> Path:
    """Find a repository file (e.g. ``cases/rv40e_fanholes.toml``) from wherever Python runs.

    Jupyter, nbconvert and editors start a notebook's kernel in the notebook's folder, not in the
    repository root. This looks for ``relative`` in ``start`` (default: the current directory)
    and then in each of its parent folders, and returns the first that exists.

    Parameters
    ----------
    relative : path
        Path relative to the repository root.
    start : path, optional
        Where to start looking; default the current directory.

    Returns
    -------
    Path
        The path found (absolute).

    Raises
    ------
    CaseError
        If no folder from ``start`` up to the file-system root holds ``relative``.
    """
    relative = Path(relative)
    if relative.is_absolute():
        if relative.exists():
            return relative
        raise CaseError(f"{relative}: no such file")
    here = Path(start if start is not None else os.getcwd()).resolve()
    for folder in (here, *here.parents):
        if (folder / relative).exists():
            return folder / relative
    raise CaseError(f"{relative}: not found in {here} or any folder above it")


def default_cache_dir() -> Path:
    """The default mesh cache: ``meshes/`` of the repository when rvfem runs from a source checkout
    (a folder holding ``pyproject.toml``, ``rvfem/`` and ``meshes/`` above the package), otherwise
    the per-user cache folder of the platform (``platformdirs.user_cache_dir("rvfem")/meshes``,
    e.g. ``~/.cache/rvfem/meshes`` on Linux). Never the current directory: running from elsewhere
    must not start a new cache there."""
    root = Path(__file__).resolve().parents[2]
    if (root / "pyproject.toml").is_file() and (root / "meshes").is_dir():
        return root / "meshes"

    return Path(platformdirs.user_cache_dir("rvfem")) / "meshes"


def kept_field_angles(case: Case, field_step_deg: float | None) -> tuple[float, ...]:
    """Crank angles (degrees) whose fields a load cycle keeps: the case's ``saved_angles_deg`` and
    every ``field_step_deg`` degrees if given (checked: in (0°, 360°], else CaseError)."""
    saved = tuple(case.analysis.saved_angles_deg)
    if field_step_deg is not None:
        if not (isinstance(field_step_deg, (int, float)) and 0 < field_step_deg <= 360):
            raise CaseError(f"the field step must be in (0°, 360°], got {field_step_deg!r}")
        saved = saved + tuple(np.arange(0.0, 360.0, field_step_deg))
    return saved


def analyse(case: Case | str | os.PathLike[str], options: AnalysisOptions | None = None, *,
            overrides: tuple[str, ...] = (), cache_dir: str | os.PathLike[str] | None = None,
            progress: ProgressCallback | None = None, provenance: CaseProvenance | None = None,
            after: Mapping[str, Callable[[Any], None]] = MappingProxyType({}), **choices: Any) -> Analysis:
    """Analyse a case completely, in memory.

    The choices of what to compute are an :class:`~rvfem.results.analysis.AnalysisOptions` (``options``),
    or its fields given by name (``analyse(case, angle_step_deg=5.0, recover_stress=False)``; those
    given by name replace the ones of ``options``). An unknown name raises TypeError.

    Parameters
    ----------
    case : Case or path
        A case or the path of a case file.
    options : AnalysisOptions, optional
        The choices below together (default: every default).
    overrides : tuple of str
        ``KEY=VALUE`` overrides when ``case`` is a path (:func:`rvfem.case.definition.load_case`).
    angle_step_deg, bearing_model, order : optional
        Override ``analysis.angle_step_deg`` (degrees), ``crank_bearing.model`` and
        ``analysis.element_order`` (see :func:`resolve_case`).
    field_step_deg : float, optional
        Also keep the displacement/stress fields every ``field_step_deg`` degrees (by default only
        the case's ``analysis.saved_angles_deg``, the angle of the largest bearing load and the
        angles of the stress peaks).
    cache_dir : path, optional
        Mesh cache folder; default :func:`default_cache_dir`.
    progress : ProgressCallback, optional
    provenance : CaseProvenance, optional
        If given, ``case`` is taken as already resolved (by :func:`resolve_case`) and the ``check``
        stage is skipped.
    recover_stress : bool
        Re-solve the disc on P2 at the structural peak's crank angles with the cycle's forces
        (:func:`rvfem.evaluate.postprocess.recover_peak`; stage ``stress``).
    duty_fe : bool
        With a duty cycle: also solve the flexible load cycle at every other duty-cycle torque and
        give the service life from those loads (:func:`duty_cycle_fe`; stage ``duty_cycle``, one
        load cycle per torque, no new factorisation).
    attribute : bool
        Compute the attribution (:func:`rvfem.evaluate.attribution.attribution`, stage ``attribution``). False
        leaves ``Analysis.attribution`` None for the caller to fill (:func:`attribution_of`).
    sections : tuple of str, optional
        Only these result sections and those they require (:func:`selected_sections`; default all).
    after : mapping of str to callable, optional
        ``after[name](result)`` once ``name`` is computed: ``"model"`` with the disc's
        :class:`rvfem.solve.cycle.DiscSystem` (before the load cycle), a result section's name with
        the :class:`Analysis` so far (later sections at their defaults). :func:`rvfem.app.run.run_case`
        so hands the mesh picture, the stress images and the plots to its render worker early.

    Returns
    -------
    Analysis

    Raises
    ------
    CaseError, GeometryError, MeshError, ContactError
        From the stages.
    """

    try:
        options = dataclasses.replace(options or AnalysisOptions(), **choices)
    except TypeError as exc:
        raise TypeError(f"analyse(): {exc}; the choices are the fields of AnalysisOptions "
                        f"({', '.join(f.name for f in dataclasses.fields(AnalysisOptions))})") from None
    stages = Stages(progress)
    checked = _checked_case(case, provenance, stages, overrides, options)
    case = checked.case
    # the P2 model is built in a child process beside the load cycle (:class:`P2Model`): started now, it imports meanwhile
    child = (start_p2_child() if options.recover_stress and case.analysis.element_order == 1
             and models_in_package(case) else None)
    background = ThreadPoolExecutor(1, thread_name_prefix="rvfem-background")
    try:
        model = _disc_model(case, stages, cache_dir, checked)
        if "model" in after:
            after["model"](model.system)
        return _analyse_from_model(case, checked.provenance, stages, model, background, options, child, after)
    finally:
        background.shutdown(wait=True, cancel_futures=True)
        if child is not None:
            child.close()


@dataclass(frozen=True, eq=False)
class _CheckedCase:
    """The case :func:`analyse` analyses, checked.

    Attributes
    ----------
    case : Case
        The case with the options applied (:func:`resolve_case`).
    provenance : CaseProvenance
    thetas : ndarray
        Crank angles of the load cycle, rad (:func:`cycle_angles`).
    saved : tuple of float
        Crank angles whose fields the cycle keeps, degrees (:func:`kept_field_angles`).
    """

    case: Case
    provenance: CaseProvenance
    thetas: np.ndarray
    saved: tuple[float, ...]


def _checked_case(case: Case | str | os.PathLike[str], provenance: CaseProvenance | None, stages: Stages,
                  overrides: tuple[str, ...], options: AnalysisOptions) -> _CheckedCase:
    """The ``check`` stage of :func:`analyse`: the case resolved with its options and its angles
    checked; without the stage when ``provenance`` is given (``case`` is then resolved already).
    An unknown result section among the options is said here, before any work."""
    selected_sections(options.sections)
    if provenance is None:
        t = stages.start("check")
        case, provenance = resolve_case(case, overrides=overrides, angle_step_deg=options.angle_step_deg,
                                        bearing_model=options.bearing_model, order=options.order)
        saved = kept_field_angles(case, options.field_step_deg)
        thetas = cycle_angles(case)
        stages.end("check", t)
    else:
        if not isinstance(case, Case):
            raise TypeError("analyse(..., provenance=...) needs a resolved Case")
        saved = kept_field_angles(case, options.field_step_deg)
        thetas = cycle_angles(case)
    return _CheckedCase(case=case, provenance=provenance, thetas=thetas, saved=saved)


@dataclass(frozen=True, eq=False)
class _DiscModel:
    """The disc model of :func:`analyse` and the crank angles it is solved at."""

    geometry: DiscGeometry
    mesh: DiscMesh
    system: DiscSystem
    thetas: np.ndarray
    saved: tuple[float, ...]


def _disc_model(case: Case, stages: Stages, cache_dir: str | os.PathLike[str] | None, checked: _CheckedCase) -> _DiscModel:
    """The ``mesh`` and ``model`` stages of :func:`analyse`: the disc geometry, its mesh (cached in
    ``cache_dir``, default :func:`default_cache_dir`) and the assembled, factorised disc model
    (:class:`rvfem.solve.cycle.DiscSystem`), with the angles of ``checked``."""
    t = stages.start("mesh")
    geometry = disc_geometry(case)
    mesh = mesh_case(case, default_cache_dir() if cache_dir is None else cache_dir, geometry=geometry)
    stages.end("mesh", t)

    t = stages.start("model")
    system = cycle_module.build_system(case, mesh, geometry=geometry)
    stages.end("model", t)
    return _DiscModel(geometry=geometry, mesh=mesh, system=system, thetas=checked.thetas, saved=checked.saved)


@dataclass(frozen=True, eq=False)
class StressEnvelope:
    """The load cycle's stress envelope as the ``evaluation`` stage finds it (what the ``stress``
    section starts from): the peak anywhere, the peak away from the contact bands, the bands' widths
    (mm) and the kept fields."""

    peak: PeakStress
    away_from_contacts: PeakStress | None
    band_mm: dict[str, float]
    snapshots: tuple[FieldSnapshot, ...]


def _analyse_from_model(case: Case, provenance: CaseProvenance, stages: Stages, model: _DiscModel,
                        background: ThreadPoolExecutor, options: AnalysisOptions,
                        child: ChildProcess | None = None,
                        after: Mapping[str, Callable[[Any], None]] = MappingProxyType({})) -> Analysis:
    """The stages of :func:`analyse` after the model: its fixed front (the rigid references, the load
    cycle and its stress envelope), then every result section (:func:`_compute_sections`)."""
    # the rigid model before the cycle: a case outside every rigid reference fails fast
    t = stages.start("rigid")
    references = rigid.references(case)
    if not (references.handbook.defined or references.equal_share.defined):
        raise CaseError(f"{case.source}: {references.equal_share.why}")
    steps = StageSteps(stages, "rigid", extra=1)   # the slices of each bearing, then the rest
    rigid_analysis = analyse_rigid(case, model.thetas, progress=steps)
    classical = (rigid.classical_pin_forces(case, model.thetas, exact_moment=True)
                 if references.classical_pin_forces.defined else None)
    log.info("%s: bearing loads compared with %s", case.name, rigid.REFERENCE_NAMES[references.bearing_loads])
    steps.end(t)

    system, mesh, n = model.system, model.mesh, len(model.thetas)
    t = stages.start("cycle", n)
    # the P2 model of the stress section, built in a child process during the load cycle
    p2 = P2Model(system, mesh, background, child) if options.recover_stress and system.model.order == 1 else None
    try:
        def report(i: int, total: int) -> None:  # the last angle is reported by stages.end
            if p2 is not None:
                p2.start()
            if i < total:
                stages.tick("cycle", i, total)

        cycle = cycle_module.load_cycle(system, model.thetas, progress=report, saved_angles_deg=model.saved,
                                        stress_envelope=True)
        stages.end("cycle", t, n)

        t = stages.start("evaluation")
        envelope = _stress_envelope(case, system, mesh, cycle)
        available: dict[str, Any] = {
            "case": case, "provenance": provenance, "geometry": model.geometry, "mesh": mesh, "system": system,
            "theta": np.asarray(model.thetas), "rigid": rigid_analysis, "classical": classical, "references": references,
            "cycle": cycle, "comparison": compare.rigid_vs_flexible(case, cycle), "stress_envelope": envelope,
            "torsional_stiffness_Nm_per_arcmin": cycle.torsional_stiffness_Nm_per_arcmin(case.loads.disc_torque_Nmm),
            "options": options,
            "p2": (None if not options.recover_stress else
                   lambda system_, cycle_, mesh_, band, away: recover_structural_peak(system_, cycle_, mesh_, band, away, p2)),
        }
        stages.end("evaluation", t)
        computed, seconds = _compute_sections(available, stages, background, release={"stress": p2},
                                              only=options.sections, after=after)
    finally:
        if p2 is not None:          # the P2 model (a few hundred MB) is not needed any more
            p2.close()
    timings = dict(stages.seconds)
    timings.update({f"{name}_compute": s for name, s in seconds.items()})
    timings.update({"model_" + k: v for k, v in system.setup_seconds.items()})
    timings["cycle_per_angle"] = stages.seconds["cycle"] / n
    if computed.get("roller_depth") is not None:
        timings["roller_depth"] = computed["roller_depth"].seconds
    return _analysis_of({**available, **computed}, timings)


def _stress_envelope(case: Case, system: DiscSystem, mesh: DiscMesh, cycle: CycleResult) -> StressEnvelope:
    """The peaks over every solved angle (the cycle's stress envelope), anywhere and away from the
    contact bands (:data:`CONTACT_BAND_ELEMENTS` element sizes), and the kept fields with theirs."""
    peak = postprocess.peak_von_mises(cycle, mesh.points, mesh.boundaries)
    assert peak is not None               # nothing excluded: the disc's largest vertex stress
    size = {"profile": max(case.mesh.size_flank, contact_grid_spacing(case)["profile"]),
            "bore": max(case.mesh.size_bore, contact_grid_spacing(case)["bore"])}
    band = {"profile": CONTACT_BAND_ELEMENTS * size["profile"]}
    band.update({f"bore_{i}": CONTACT_BAND_ELEMENTS * size["bore"] for i in range(case.cranks.count)})
    away = postprocess.peak_von_mises(cycle, mesh.points, mesh.boundaries, exclude=band)
    snapshots = postprocess.field_snapshots(
        system, cycle, extra_angles=[math.radians(pk.theta_deg) for pk in (peak, away) if pk is not None])
    return StressEnvelope(peak=peak, away_from_contacts=away, band_mm=band, snapshots=snapshots)


_ANALYSIS_FIELDS = tuple(f.name for f in dataclasses.fields(Analysis) if f.name not in ("timings", "extra"))
"""The fields of :class:`~rvfem.results.analysis.Analysis` the results fill (by name)."""

_REQUIRED_FIELDS = tuple(f.name for f in dataclasses.fields(Analysis)
                         if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING)
"""The fields of :class:`~rvfem.results.analysis.Analysis` without a default."""


def _analysis_of(results: Mapping[str, Any], timings: dict[str, float]) -> Analysis:
    """The :class:`Analysis` of the results so far: the fields by name, the results of sections
    from outside rvfem in ``extra``."""
    own = {name: results[name] for name in _ANALYSIS_FIELDS if name in results}
    extra = {s.name: results[s.name] for s in sections_registry.sections()
             if s.name not in _ANALYSIS_FIELDS and s.name in results}
    return Analysis(**own, timings=timings, extra=MappingProxyType(extra))


def _stage_rank(stage: str | None) -> int:
    order = list(STAGES)
    return order.index(stage) if stage in order else len(order)


def selected_sections(only: Sequence[str] | None) -> tuple[Section, ...]:
    """The result sections an analysis computes: every one for None, else those named in ``only``
    and, recursively, the sections they require (by name), in the registry's order.

    Raises
    ------
    CaseError
        A name that is no result section (the message lists the known ones).
    """
    every = sections_registry.sections()
    if only is None:
        return every
    by_name = {s.name: s for s in every}
    unknown = [name for name in only if name not in by_name]
    if unknown:
        raise CaseError(f"no result section {unknown[0]!r}; known: {', '.join(by_name)}")
    wanted: set[str] = set()
    todo = list(only)
    while todo:
        name = todo.pop()
        if name in wanted:
            continue
        wanted.add(name)
        todo += [r for r in by_name[name].requires if r in by_name]
    return tuple(s for s in every if s.name in wanted)


def _compute_sections(available: dict[str, Any], stages: Stages, background: ThreadPoolExecutor,
                      release: Mapping[str, Any] = MappingProxyType({}),
                      only: Sequence[str] | None = None,
                      after: Mapping[str, Callable[[Any], None]] = MappingProxyType({}),
                      ) -> tuple[dict[str, Any], dict[str, float]]:
    """Compute every result section that has a ``compute`` (:func:`rvfem.results.registry.sections`).

    The order: by their stage among :data:`STAGES` (the order the user sees), those without a stage
    after them, and those that require ``analysis`` (the whole result so far) last, each group in the
    sections' order. A ``thread`` section starts on ``background`` as soon as the front is done and
    is waited for (its stage) at its turn. ``release[name].close()`` is called once section
    ``name`` is done (the P2 model after the stress), then ``after[name](analysis)`` with the
    :class:`Analysis` of the results so far (those not computed yet at their defaults, None; also
    for a section that does not apply). Returns the results by section name and the
    wall time of the thread sections' own work (s), by name. With ``only``, just the sections of
    :func:`selected_sections` (the others are left out of the results: None in the analysis).
    """
    chosen = [s for s in selected_sections(only) if s.compute is not None]
    order = sorted(chosen, key=lambda s: ("analysis" in s.requires, _stage_rank(s.stage)))
    # the sections left out are None, as those that do not apply
    results: dict[str, Any] = {s.name: None for s in sections_registry.sections()
                               if s.compute is not None and s not in chosen}
    seconds: dict[str, float] = {}

    def inputs(section: Section, progress: Callable[[int, int], None] | None = None) -> dict[str, Any]:
        given = {**available, **results}
        if "analysis" in section.requires:
            given["analysis"] = _analysis_of(given, dict(stages.seconds))
        missing = [r for r in section.requires if r not in given]
        if missing:
            raise RuntimeError(f"result section {section.name!r} requires {', '.join(missing)}, which nothing computed "
                               "before it")
        return {**given, "progress": progress or (lambda done, total: None)}

    def applies(section: Section) -> bool:
        return section.applies is None or bool(section.applies({**available, **results}))

    started = {s.name: background.submit(timed, s.compute, inputs(s)) for s in order
               if s.compute is not None and s.executor == "thread" and "analysis" not in s.requires and applies(s)}

    def done(section: Section) -> None:
        if section.name in after:   # the fields no section has given yet: None, or their defaults
            pending = {name: None for name in _REQUIRED_FIELDS if name not in available and name not in results}
            after[section.name](_analysis_of({**available, **pending, **results}, dict(stages.seconds)))

    for s in order:
        if s.compute is None or (s.name not in started and not applies(s)):
            results[s.name] = None
            done(s)
            continue
        stage = s.stage
        steps = StageSteps(stages, stage) if stage is not None and stage not in stages.seconds else None
        t = stages.start(stage) if steps is not None and stage is not None else time.perf_counter()
        if s.name in started:
            results[s.name], seconds[s.name] = started[s.name].result()
        else:
            results[s.name] = s.compute(inputs(s, steps))
        if steps is not None:
            steps.end(t)
        elif stage is not None:
            stages.seconds[stage] += time.perf_counter() - t
        if s.name in release and release[s.name] is not None:
            release[s.name].close()
        done(s)
    return results, seconds


def attribution_of(system: DiscSystem, thetas: np.ndarray, cycle: CycleResult) -> Attribution:
    """The attribution of a case's flexible load cycle (the ``attribution`` section,
    :func:`rvfem.results.attribution.compute`)."""
    return attribution_section.compute({"system": system, "theta": thetas, "cycle": cycle})


def attribution_warnings(result: Attribution | None) -> tuple[ResultWarning, ...]:
    """The warnings of the attribution steps that could not be made
    (:func:`rvfem.evaluate.attribution.skipped_warnings`); none for None."""
    return attribution.skipped_warnings(result)
