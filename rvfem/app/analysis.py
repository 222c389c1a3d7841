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
import importlib
import logging
import math
import os
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from types import MappingProxyType
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, NamedTuple

import numpy as np
import platformdirs

from rvfem._arrays import release_freed_memory
from rvfem._child import ChildProcess, ChildProcessEnded
from rvfem.case.definition import (
    Case,
    apply_overrides,
    case_to_dict,
    file_sha256,
    load_case,
    parse_override,
)
from rvfem.case.registry import bearing_model_names
from rvfem.errors import CaseError, ContactError
from rvfem.evaluate import (
    attribution,
    bearing_checks,
    compare,
    hertz,
    iso281,
    postprocess,
    rigid,
    roller_life,
    roller_slices,
    validity,
)
from rvfem.evaluate import accuracy as accuracy_eval
from rvfem.evaluate.compare import equal_share_forces
from rvfem.evaluate.postprocess import max_load_index
from rvfem.evaluate.rigid import equivalent_load
from rvfem.geometry import disc_geometry, pin_centres
from rvfem.mesh import mesh_case
from rvfem.solve import cycle as cycle_module
from rvfem.solve import models
from rvfem.solve.cycle import AngleLoads, build_system
from rvfem.results import attribution as attribution_section
from rvfem.results import registry as sections_registry
from rvfem.results.section import Section
from rvfem.results.duty_cycle import duty_cycle_fe
from rvfem.results.accuracy import run_accuracy
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

if TYPE_CHECKING:  # the heavier modules are imported where used
    from rvfem.evaluate.compare import Comparison
    from rvfem.evaluate.attribution import Attribution
    from rvfem.evaluate.bearing_checks import BearingChecks
    from rvfem.evaluate.postprocess import FieldSnapshot, HotSpotHistory, PeakStress, RecoveredPeak
    from rvfem.evaluate.rigid import PinForces, References
    from rvfem.evaluate.roller_life import BearingDepth, CrankBearingDepth
    from rvfem.evaluate.validity import ResultWarning
    from rvfem.geometry import DiscGeometry
    from rvfem.mesh import DiscMesh
    from rvfem.solve.cycle import CycleResult, DiscSystem

log = logging.getLogger(__name__)

__all__ = [
    "STAGES",
    "CONTACT_BAND_ELEMENTS",
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

STAGES: dict[str, str] = {
    "check": "checking the case",
    "mesh": "meshing the disc (cached)",
    "model": "assembling and factorising the disc model",
    "rigid": "rigid handbook model",
    "cycle": "flexible load cycle",
    "evaluation": "evaluation: rigid vs flexible, stresses, Hertz",
    "stress": "stresses: the structural peak re-solved on P2 at its crank angles, the hot spots' histories",
    "attribution": "attribution: the reducer-stage models step by step (computed beside other stages)",
    "duty_cycle": "flexible load cycle at the other duty-cycle torques",
    "accuracy": "torsional rigidity and lost motion at crank angle 0",
    "roller_slices": "crank bearing in depth: slices along every roller, film and lives",
}
"""Stages of :func:`analyse` in order, with a one-line description (what the progress callback
reports)."""

CONTACT_BAND_ELEMENTS = 6.0
"""Width of the band along the tooth profile and the bores excluded from the "away from contacts"
stress peak, in element sizes there (``mesh.size_flank``, ``mesh.size_bore``): four times the
footprint half-width over which the pin and roller forces are spread."""

MIN_ANGLES = 4
"""Fewest crank angles per turn a load cycle may have."""

ProgressCallback = Callable[[str, int, int], None]
"""``progress(stage, done, total)``: called with ``done = 0`` when a stage starts, with
``done = total`` when it ends, and after every crank angle of the ``cycle`` stage (``total`` =
number of angles). An exception raised by the callback (e.g. KeyboardInterrupt) aborts the
analysis."""


class Stages:
    """Times named stages and reports them to an optional progress callback.

    Parameters
    ----------
    progress : ProgressCallback, optional
    descriptions : dict
        Stage name → one-line description (logged at INFO level when the stage starts).
    """

    def __init__(self, progress: ProgressCallback | None, descriptions: Mapping[str, str] = STAGES):
        self.progress = progress
        self.descriptions = descriptions
        self.seconds: dict[str, float] = {}

    def start(self, name: str, total: int = 1) -> float:
        """Report the start of stage ``name``; returns the start time (``time.perf_counter``)."""
        log.info("%s", self.descriptions.get(name, name))
        if self.progress is not None:
            self.progress(name, 0, total)
        return time.perf_counter()

    def tick(self, name: str, done: int, total: int) -> None:
        """Report progress within stage ``name``."""
        if self.progress is not None:
            self.progress(name, done, total)

    def end(self, name: str, started: float, total: int = 1) -> None:
        """Record the wall time of stage ``name`` (s) and report its end."""
        self.seconds[name] = time.perf_counter() - started
        if self.progress is not None:
            self.progress(name, total, total)


class _StageSteps:
    """``progress(done, total)`` of a library function's steps within stage ``name`` of ``stages``
    (``extra`` steps of the stage follow the function's); the last step is reported by
    :meth:`end`, which ends the stage."""

    def __init__(self, stages: Stages, name: str, extra: int = 0):
        self.stages, self.name, self.extra, self.total = stages, name, extra, 1

    def __call__(self, done: int, total: int) -> None:
        self.total = total + self.extra
        if done < self.total:
            self.stages.tick(self.name, done, self.total)

    def end(self, started: float) -> None:
        """End the stage started at ``started`` (:meth:`Stages.start`)."""
        self.stages.end(self.name, started, self.total)


# --------------------------------------------------------------------------------------------
# The case as analysed
# --------------------------------------------------------------------------------------------




_WITH_OVERRIDES = " (with overrides)"  # suffix rvfem.case.definition.load_case gives Case.source with overrides


def _defaults_used(raw: dict, case: Case) -> tuple[tuple[str, Any], ...]:
    """Dotted keys of ``case`` that ``raw`` (the file's data) does not set, with their values."""
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


def _read_raw(path: Path) -> dict | None:
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return None


def resolve_case(case: Case | str | os.PathLike, *, overrides: tuple[str, ...] = (),
                 angle_step_deg: float | None = None, bearing_model: str | None = None,
                 order: int | None = None) -> tuple[Case, CaseProvenance]:
    """The case to analyse, with the options applied, and where it comes from.

    Parameters
    ----------
    case : Case or path
        A case (built in code, or read with :func:`rvfem.case.definition.load_case`, overrides included) or
        the path of a case file.
    overrides : tuple of str
        ``KEY=VALUE`` overrides applied when ``case`` is a path (see :func:`rvfem.case.definition.load_case`).
    angle_step_deg : float, optional
        Crank-angle step, degrees (overrides ``analysis.angle_step_deg``).
    bearing_model : str, optional
        Overrides ``crank_bearing.model`` (one of :func:`rvfem.case.registry.bearing_model_names`).
    order : {1, 2}, optional
        Overrides ``analysis.element_order``.

    Returns
    -------
    (Case, CaseProvenance)

    Raises
    ------
    CaseError
        A bad file, override or option (one line naming the key).
    """

    source = _case_source(case, overrides)
    given = _overrides_given(source.base)
    defaults = _file_defaults(source)
    effective, options = _with_options(source.base, angle_step_deg=angle_step_deg, order=order,
                                       bearing_model=bearing_model)
    given.update(options)
    path = source.path
    provenance = CaseProvenance(
        file=str(path) if path is not None else None,
        sha256=file_sha256(path) if path is not None else None,
        matches_file=source.matches and not given,
        overrides=given,
        defaults_used=defaults,
    )
    return effective, provenance


@dataclass(frozen=True, eq=False)
class _CaseSource:
    """A case before the options of :func:`resolve_case`, and its file.

    Attributes
    ----------
    base : Case
        The case as given, or as read from its file with the ``KEY=VALUE`` overrides.
    path : Path or None
        Its case file (None for a case whose ``source`` is no file).
    matches : bool
        True if ``base`` is exactly what its file and its overrides give.
    """

    base: Case
    path: Path | None
    matches: bool


def _case_source(case: Case | str | os.PathLike, overrides: tuple[str, ...]) -> _CaseSource:
    """The case to resolve: a :class:`Case` as given (its file found from ``Case.source`` and read
    again to tell whether the case is still the file's), or the case file ``case`` read with
    ``overrides``."""
    if not isinstance(case, Case):
        path = Path(case)
        return _CaseSource(base=load_case(path, overrides), path=path, matches=True)
    source = case.source[: -len(_WITH_OVERRIDES)] if case.source.endswith(_WITH_OVERRIDES) else case.source
    path = Path(source)
    if not path.is_file():
        return _CaseSource(base=case, path=None, matches=False)
    try:
        matches = load_case(path, case.overrides) == case
    except CaseError:
        matches = False
    return _CaseSource(base=case, path=path, matches=matches)


def _overrides_given(base: Case) -> dict[str, Any]:
    """Dotted case key → value of the case's ``KEY=VALUE`` overrides (:attr:`Case.overrides`)."""
    given: dict[str, Any] = {}
    for text in base.overrides:
        parts, value = parse_override(text)
        given[".".join(parts)] = value
    return given


def _file_defaults(source: _CaseSource) -> tuple[tuple[str, Any], ...]:
    """The defaults the case uses (:func:`_defaults_used`): keys that neither its file nor its
    overrides set; none known for a case that is not its file's (or whose file cannot be read)."""
    if source.path is None or not source.matches:
        return ()
    raw = _read_raw(source.path)
    if raw is None:
        return ()
    return _defaults_used(apply_overrides(raw, source.base.overrides), source.base)


def _with_options(base: Case, *, angle_step_deg: float | None, order: int | None,
                  bearing_model: str | None) -> tuple[Case, dict[str, Any]]:
    """``base`` with the options of :func:`resolve_case` applied (each checked; the case is checked
    again as a whole), and the options as dotted case key → value (empty without options: ``base``
    is returned as it is)."""
    options: dict[str, Any] = {}
    analysis, bearing = base.analysis, base.crank_bearing
    if angle_step_deg is not None:
        if not (isinstance(angle_step_deg, (int, float)) and angle_step_deg > 0):
            raise CaseError(f"the angle step must be positive, got {angle_step_deg!r}")
        analysis = dataclasses.replace(analysis, angle_step_deg=float(angle_step_deg))
        options["analysis.angle_step_deg"] = float(angle_step_deg)
    if order is not None:
        if order not in (1, 2):
            raise CaseError(f"the element order must be 1 or 2, got {order!r}")
        analysis = dataclasses.replace(analysis, element_order=int(order))
        options["analysis.element_order"] = int(order)
    if bearing_model is not None:
        names = bearing_model_names()
        if bearing_model not in names:
            raise CaseError(f"the bearing model must be one of {', '.join(repr(n) for n in names)}, "
                            f"got {bearing_model!r}")
        bearing = dataclasses.replace(bearing, model=bearing_model)
        options["crank_bearing.model"] = bearing_model
    if not options:
        return base, options
    try:
        effective = base.replace(analysis=analysis, crank_bearing=bearing)
    except CaseError as exc:
        text = ", ".join(f"{k} = {v}" for k, v in options.items())
        raise CaseError(f"the overrides ({text}) are not valid: {exc}") from None
    return dataclasses.replace(effective, overrides=base.overrides), options


def cycle_angles(case: Case) -> np.ndarray:
    """Crank angles of a load cycle of ``case``: :func:`rvfem.evaluate.rigid.load_cycle_angles` at
    ``analysis.angle_step_deg``, at least :data:`MIN_ANGLES` of them, rad.

    Raises
    ------
    CaseError
        If the step leaves fewer than four angles per turn.
    """
    step = case.analysis.angle_step_deg
    if int(round(360.0 / step)) < MIN_ANGLES:
        raise CaseError(f"the angle step {step:g}° leaves fewer than {MIN_ANGLES} angles per turn")
    return rigid.load_cycle_angles(step)


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
        ``progress(done, total)`` after the slices of each bearing (bearing model ``rollers``).

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












def repository_path(relative: str | os.PathLike, start: str | os.PathLike | None = None) -> Path:
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


def _p2_system(system, mesh):
    """The P2 model of the cycle's disc (same mesh, models and geometry), assembled and factorised."""
    return _build_p2(system.case, mesh, system.bearing_model, system.pin_model, system.geometry)


def _build_p2(case, mesh, bearing_model, pin_model, geometry=None):
    """The P2 model of a case's disc, assembled and factorised; the heap its temporaries leave
    behind is given back (:func:`rvfem._arrays.release_freed_memory`)."""

    system_p2 = build_system(case, mesh, order=2, bearing_model=bearing_model, geometry=geometry,
                             pin_model=pin_model)
    release_freed_memory()
    return system_p2


class _CycleLoads(NamedTuple):
    """The part of a load cycle the P2 recovery reads (:func:`rvfem.evaluate.postprocess.recover_peak`):
    the crank angles and, for the angles it re-solves, their :class:`rvfem.solve.cycle.AngleLoads`."""

    theta: np.ndarray
    solutions: dict


#: The P2 model of the child process of :class:`_P2Model` (one per child).
_CHILD_P2: list = []


def _p2_child_build(case, mesh, bearing_model, pin_model, geometry) -> float:
    """In the child process of :class:`_P2Model`: build the P2 model; its wall time, s."""
    system_p2, seconds = _timed(_build_p2, case, mesh, bearing_model, pin_model, geometry)
    _CHILD_P2[:] = [system_p2]
    return seconds


def _p2_child_recover(cycle_loads, angles, points, boundaries, band, away, setup):
    """In the child process of :class:`_P2Model`: the recovered peak (without its P1 value)."""

    return postprocess.recover_peak(_CHILD_P2[0], cycle_loads, angles, points, boundaries, exclude=band,
                                    p1_peak=away, setup_seconds=setup)


def _models_in_package(case) -> bool:
    """Whether the case's bearing and pin models are rvfem's own, which a child process knows too
    (a model registered at run time, by a notebook or a test module, exists in this process only:
    its P2 model is then built on a thread here)."""
    try:
        classes = (models.bearing_model(case.crank_bearing.model), models.pin_model(case.pins.model))
    except KeyError:
        return False
    return all(c.__module__.split(".")[0] == "rvfem" for c in classes)


def _start_p2_child():
    """A child process for :class:`_P2Model`, already importing what it needs; None where no
    child process can be started (the P2 model is then built on a thread)."""

    try:
        child = ChildProcess("P2 model", niceness=P2_CHILD_NICENESS)
    except OSError as exc:
        log.info("the P2 model is built on a thread (%s)", exc)
        return None
    child.call(_p2_child_imports)
    return child


def _p2_child_imports() -> None:
    """In the child process of :class:`_P2Model`: import the modules of the P2 model."""

    for name in ("rvfem.solve.cycle", "rvfem.evaluate.postprocess"):
        importlib.import_module(name)


#: Niceness added to the P2 model's child process (Unix ``nice``): where the two compete for the
#: processor, the mesh, the model and the load cycle go first (the P2 model has the whole cycle's
#: time to be ready).
P2_CHILD_NICENESS = 10


class _P2Model:
    """The P2 model of a P1 cycle's disc (same mesh and models), built beside the load cycle.

    It is built in a child process (:class:`rvfem._child.ChildProcess`): its assembly and
    factorisation would otherwise take turns with the load cycle in this interpreter (CHOLMOD
    through cholespy holds it), and its few hundred MB stay out of this process. The angles to
    re-solve go there as :class:`rvfem.solve.cycle.AngleLoads`, the recovered peak comes back. Without a
    ``child`` (none could be started), the model is built on the ``background`` thread from
    :meth:`start` and used here.
    """

    def __init__(self, system, mesh, background, child=None):
        self._child = child
        self._pending = None
        if child is not None:
            self._built = child.call(_p2_child_build, system.case, mesh, system.bearing_model, system.pin_model,
                                     system.geometry)     # one message: the geometry's case is the case
        else:
            self._built, self._pending = None, (background, system, mesh)

    def start(self) -> None:
        """Start the build on the background thread (without a child; once). Called when the cycle
        has solved its first angle: its compliance columns are computed by then, and the two would
        only take turns in this interpreter (cholespy holds it)."""
        if self._pending is not None:
            background, system, mesh = self._pending
            self._pending = None
            self._built = background.submit(_timed, _p2_system, system, mesh)

    def recover_in_child(self, system, cycle, angles, mesh, band, away):
        """:func:`rvfem.evaluate.postprocess.recover_peak` made in the child process, with the P1 value at
        the peak added here; None without a child, or when it has ended (e.g. ended by the system
        for want of memory: the P2 model is then built here, :meth:`model`)."""

        if self._child is None:
            return None
        try:
            setup = self._built.result()
            ks = {postprocess.nearest_index(cycle.theta, float(a)) for a in angles}
            roots: dict = {}
            loads = _CycleLoads(np.asarray(cycle.theta), {k: AngleLoads.of(cycle.solutions[k], roots) for k in ks})
            recovered = self._child.call(_p2_child_recover, loads, angles, mesh.points, mesh.boundaries, band,
                                         away, setup).result()
        except ChildProcessEnded as exc:
            log.warning("%s; the P2 model is built here instead", exc)
            self._child.close()             # its pipes and reader now (closing again is harmless)
            self._child, self._built = None, None
            return None
        return dataclasses.replace(recovered, p1_at_peak_MPa=postprocess.p1_stress_at(system, cycle, recovered.peak))

    def model(self, system, mesh):
        """The P2 model in this process and the time it took, s: the one the ``background`` thread
        built, or one built now."""
        if self._built is not None:
            return self._built.result()
        return _timed(_p2_system, system, mesh)

    def close(self) -> None:
        """End the child process (its P2 model with it)."""
        if self._child is not None:
            self._child.close()


def _recover_structural_peak(system, cycle, mesh, band, away, p2=None):
    """The structural peak recovered on P2 (:func:`rvfem.evaluate.postprocess.recover_peak`) at the P1
    envelope's peak angles. The P2 model of the same mesh is ``p2`` (a :class:`_P2Model`, built
    beside the load cycle) or built here, or is the cycle's own for a P2 case."""

    angles = postprocess.peak_angles(cycle, mesh.points, mesh.boundaries, exclude=band)
    if system.model.order == 2:
        system_p2, system_p1, setup = system, None, 0.0
    elif p2 is None:
        (system_p2, setup), system_p1 = _timed(_p2_system, system, mesh), system
    elif (recovered := p2.recover_in_child(system, cycle, angles, mesh, band, away)) is not None:
        return recovered
    else:
        (system_p2, setup), system_p1 = p2.model(system, mesh), system
    return postprocess.recover_peak(system_p2, cycle, angles, mesh.points, mesh.boundaries, exclude=band,
                                    p1_peak=away, system_p1=system_p1, setup_seconds=setup)


def kept_field_angles(case: Case, field_step_deg: float | None) -> tuple[float, ...]:
    """Crank angles (degrees) whose fields a load cycle keeps: the case's ``saved_angles_deg`` and
    every ``field_step_deg`` degrees if given (checked: in (0°, 360°], else CaseError)."""
    saved = tuple(case.analysis.saved_angles_deg)
    if field_step_deg is not None:
        if not (isinstance(field_step_deg, (int, float)) and 0 < field_step_deg <= 360):
            raise CaseError(f"the field step must be in (0°, 360°], got {field_step_deg!r}")
        saved = saved + tuple(np.arange(0.0, 360.0, field_step_deg))
    return saved


def analyse(case: Case | str | os.PathLike, *, overrides: tuple[str, ...] = (),
            angle_step_deg: float | None = None, bearing_model: str | None = None, order: int | None = None,
            field_step_deg: float | None = None, cache_dir: str | os.PathLike | None = None,
            progress: ProgressCallback | None = None, provenance: CaseProvenance | None = None,
            recover_stress: bool = True, duty_fe: bool = True, attribute: bool = True,
            on_model: Callable[[Any], None] | None = None) -> Analysis:
    """Analyse a case completely, in memory.

    Parameters
    ----------
    case : Case or path
        A case or the path of a case file.
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
        leaves ``Analysis.attribution`` None for the caller to fill (:func:`attribution_of`):
        :func:`rvfem.app.run.run_case` computes it while the output files are drawn.
    on_model : callable, optional
        ``on_model(system)`` with the disc's :class:`rvfem.solve.cycle.DiscSystem` once it is built,
        before the load cycle (:func:`rvfem.app.run.run_case` has the mesh picture drawn meanwhile).

    Returns
    -------
    Analysis

    Raises
    ------
    CaseError, GeometryError, MeshError, ContactError
        From the stages.
    """

    stages = Stages(progress)
    checked = _checked_case(case, provenance, stages, overrides=overrides, angle_step_deg=angle_step_deg,
                            bearing_model=bearing_model, order=order, field_step_deg=field_step_deg)
    case = checked.case
    # the P2 model of the stress stage is built in a child process beside the load cycle
    # (:class:`_P2Model`); the process starts now, so that its imports are done meanwhile
    child = (_start_p2_child() if recover_stress and case.analysis.element_order == 1 and _models_in_package(case)
             else None)
    background = ThreadPoolExecutor(1, thread_name_prefix="rvfem-background")
    try:
        model = _disc_model(case, stages, cache_dir, checked)
        if on_model is not None:
            on_model(model.system)
        options = AnalysisOptions(recover_stress=recover_stress, duty_fe=duty_fe, attribute=attribute)
        return _analyse_from_model(case, checked.provenance, stages, model, background, options, child)
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


def _checked_case(case, provenance: CaseProvenance | None, stages: Stages, *, overrides: tuple[str, ...],
                  angle_step_deg: float | None, bearing_model: str | None, order: int | None,
                  field_step_deg: float | None) -> _CheckedCase:
    """The ``check`` stage of :func:`analyse`: the case resolved with its options and its angles
    checked; without the stage when ``provenance`` is given (``case`` is then resolved already)."""
    if provenance is None:
        t = stages.start("check")
        case, provenance = resolve_case(case, overrides=overrides, angle_step_deg=angle_step_deg,
                                        bearing_model=bearing_model, order=order)
        saved = kept_field_angles(case, field_step_deg)
        thetas = cycle_angles(case)
        stages.end("check", t)
    else:
        if not isinstance(case, Case):
            raise TypeError("analyse(..., provenance=...) needs a resolved Case")
        saved = kept_field_angles(case, field_step_deg)
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


def _disc_model(case: Case, stages: Stages, cache_dir: str | os.PathLike | None, checked: _CheckedCase) -> _DiscModel:
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
                        child: ChildProcess | None = None) -> Analysis:
    """The stages of :func:`analyse` after the model: its fixed front (the rigid references, the load
    cycle and its stress envelope), then every result section (:func:`_compute_sections`)."""
    # the rigid model before the cycle: a case outside every rigid reference fails fast
    t = stages.start("rigid")
    references = rigid.references(case)
    if not (references.handbook.defined or references.equal_share.defined):
        raise CaseError(f"{case.source}: {references.equal_share.why}")
    steps = _StageSteps(stages, "rigid", extra=1)   # the slices of each bearing, then the rest
    rigid_analysis = analyse_rigid(case, model.thetas, progress=steps)
    classical = (rigid.classical_pin_forces(case, model.thetas, exact_moment=True)
                 if references.classical_pin_forces.defined else None)
    log.info("%s: bearing loads compared with %s", case.name, rigid.REFERENCE_NAMES[references.bearing_loads])
    steps.end(t)

    system, mesh, n = model.system, model.mesh, len(model.thetas)
    t = stages.start("cycle", n)
    # the P2 model of the stress section, built in a child process during the load cycle
    p2 = _P2Model(system, mesh, background, child) if options.recover_stress and system.model.order == 1 else None
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
                   lambda system_, cycle_, mesh_, band, away: _recover_structural_peak(system_, cycle_, mesh_, band, away, p2)),
        }
        stages.end("evaluation", t)
        computed, seconds = _compute_sections(available, stages, background, release={"stress": p2})
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
    band = {"profile": CONTACT_BAND_ELEMENTS * case.mesh.size_flank}
    band.update({f"bore_{i}": CONTACT_BAND_ELEMENTS * case.mesh.size_bore for i in range(case.cranks.count)})
    away = postprocess.peak_von_mises(cycle, mesh.points, mesh.boundaries, exclude=band)
    snapshots = postprocess.field_snapshots(
        system, cycle, extra_angles=[math.radians(pk.theta_deg) for pk in (peak, away) if pk is not None])
    return StressEnvelope(peak=peak, away_from_contacts=away, band_mm=band, snapshots=snapshots)


_ANALYSIS_FIELDS = tuple(f.name for f in dataclasses.fields(Analysis) if f.name not in ("timings", "extra"))
"""The fields of :class:`~rvfem.results.analysis.Analysis` the results fill (by name)."""


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


def _compute_sections(available: dict[str, Any], stages: Stages, background: ThreadPoolExecutor,
                      release: Mapping[str, Any] = MappingProxyType({})) -> tuple[dict[str, Any], dict[str, float]]:
    """Compute every result section that has a ``compute`` (:func:`rvfem.results.registry.sections`).

    The order: by their stage among :data:`STAGES` (the order the user sees), those without a stage
    after them, and those that require ``analysis`` (the whole result so far) last, each group in the
    sections' order. A ``thread`` section starts on ``background`` as soon as the front is done and
    is waited for (its stage) at its turn. ``release[name].close()`` is called once section
    ``name`` is done (the P2 model after the stress). Returns the results by section name and the
    wall time of the thread sections' own work (s), by name.
    """
    chosen = [s for s in sections_registry.sections() if s.compute is not None]
    order = sorted(chosen, key=lambda s: ("analysis" in s.requires, _stage_rank(s.stage)))
    results: dict[str, Any] = {}
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

    started = {s.name: background.submit(_timed, s.compute, inputs(s)) for s in order
               if s.compute is not None and s.executor == "thread" and "analysis" not in s.requires and applies(s)}
    for s in order:
        if s.compute is None or (s.name not in started and not applies(s)):
            results[s.name] = None
            continue
        stage = s.stage
        steps = _StageSteps(stages, stage) if stage is not None and stage not in stages.seconds else None
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
    return results, seconds


def attribution_of(system: DiscSystem, thetas: np.ndarray, cycle: CycleResult) -> Attribution:
    """The attribution of a case's flexible load cycle (the ``attribution`` section,
    :func:`rvfem.results.attribution.compute`)."""
    return attribution_section.compute({"system": system, "theta": thetas, "cycle": cycle})


def attribution_warnings(result: Attribution | None) -> tuple[ResultWarning, ...]:
    """The warnings of the attribution steps that could not be made
    (:func:`rvfem.evaluate.attribution.skipped_warnings`); none for None."""
    return attribution.skipped_warnings(result)


def _timed(function: Callable[..., Any], *args: Any, **kwargs: Any) -> tuple[Any, float]:
    """``(function(*args, **kwargs), wall time in s)``."""
    t0 = time.perf_counter()
    return function(*args, **kwargs), time.perf_counter() - t0
