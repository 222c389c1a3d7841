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

Adding a result: give :class:`Analysis` a new field with a default (``None`` when it does not
apply), compute it in :func:`analyse` (its stages after the model: ``_analyse_from_model`` and
``_evaluate``), add a piece to :data:`rvfem.outputs.summary.SUMMARY_PIECES` and its
keys to docs/outputs.md (a test checks that the documented and the written keys agree). The
physics and the sources of every formula are in docs/theory.md.
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
from dataclasses import dataclass, field
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
    "stress": "structural stress peak re-solved on P2 at its crank angles",
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


@dataclass(frozen=True)
class CaseProvenance:
    """Where the analysed case comes from.

    Attributes
    ----------
    file : str or None
        Case file path as given (None for a case built in code).
    sha256 : str or None
        sha256 of the case file's bytes.
    matches_file : bool
        True if the analysed case is exactly the file's (no overrides, not modified in code).
    overrides : dict
        Dotted case key → value, for every value set on top of the file: ``KEY=VALUE`` overrides
        (:attr:`rvfem.case.definition.Case.overrides`, ``rvfem ... --set``) and the options
        ``angle_step_deg``, ``bearing_model``, ``order`` (``--step``, ``--bearing-model``,
        ``--order``).
    defaults_used : tuple of (str, value)
        Dotted keys that neither the file nor an override sets, with the default value used.
    """

    file: str | None
    sha256: str | None
    matches_file: bool
    overrides: dict = field(default_factory=dict)
    defaults_used: tuple[tuple[str, Any], ...] = ()


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


@dataclass(frozen=True)
class RigidBearing:
    """One crank bearing in the rigid handbook evaluation.

    Attributes
    ----------
    loads : rvfem.evaluate.rigid.BearingLoadSummary
        Maximum, minimum (with crank angles, degrees), equivalent load (N) and L10h (hours).
    crank_angle_deg : float
        Position α_i of the crank, degrees.
    max_roller_load_N : float
        The most loaded roller: the largest roller load of rigid rings under the handbook forces
        over the cycle (:data:`rvfem.evaluate.hertz.RIGID_ROLLER_MODEL`), N.
    hertz_inner, hertz_outer : rvfem.evaluate.hertz.HertzLineContact
        Hertz contact of that roller on the eccentric (convex) and in the disc bore (concave).
    max_roller_theta_deg : float
        Crank angle of that roller load, degrees.
    depth : rvfem.evaluate.roller_life.BearingDepth or None
        κ, a_ISO, L_nm and L10r of the bearing under the handbook forces (the run's rigid column);
        None for a bearing model without discrete rollers.
    """

    loads: rigid.BearingLoadSummary
    crank_angle_deg: float
    max_roller_load_N: float
    hertz_inner: hertz.HertzLineContact
    hertz_outer: hertz.HertzLineContact
    max_roller_theta_deg: float = math.nan
    depth: BearingDepth | None = None


@dataclass(frozen=True, eq=False)
class RigidAnalysis:
    """The rigid handbook evaluation of a case: loads, rating, lives, Hertz, duty cycle.

    Where the handbook model is not defined (Zp − Zc ≠ 1) the evaluation keeps its layout with
    nothing made up: ``loads`` are NaN (:func:`rvfem.evaluate.rigid.undefined_loads`), ``bearings`` is
    empty, ``duty_cycle`` is None and ``references`` says why.

    Attributes
    ----------
    case : Case
    loads : rvfem.evaluate.rigid.RigidLoads
        Bearing forces over the sampled crank angles (and the handbook components k, k_y, ΣP…);
        NaN where the handbook is not defined.
    bearings : tuple of RigidBearing
        One per bearing; empty where the handbook is not defined.
    rating_N : float
        ISO 281 dynamic load rating C of the crank bearing, N.
    bearing_speed_rpm : float
        n_b = n_out·Zp/(Zp − Zc), rpm.
    exponent : float
        Equivalent-load exponent p.
    stribeck_factor : float
        k of the most loaded roller Q_max = k·F_max/Z of the rigid rings (the largest over the
        bearings; :func:`rvfem.evaluate.hertz.rigid_ring_factor` for a roller on the load line).
    duty_cycle : rvfem.evaluate.iso281.DutyCycleLife or None
        Service life of the case's duty cycle from the shortest bearing life (None without a duty
        cycle, or where the handbook is not defined).
    references : rvfem.evaluate.rigid.References or None
        Which rigid references are defined for the case and why (:func:`rvfem.evaluate.rigid.references`,
        as for the rigid evaluation alone: the equal share of the FE pin resultant is not part of
        it).
    warnings : tuple of rvfem.evaluate.validity.ResultWarning
        Results outside their model's range (:func:`rvfem.evaluate.validity.rigid_warnings`: P/C, lives
        under 1 h, Hertz pressures); empty when all hold.
    checks : rvfem.evaluate.bearing_checks.BearingChecks or None
        Static safety S0 and minimum load of the crank bearing under the handbook forces (no support
        bearings: the rigid model has no crankshaft beam); None where the handbook is not defined.
    """

    case: Case
    loads: rigid.RigidLoads
    bearings: tuple[RigidBearing, ...]
    rating_N: float
    bearing_speed_rpm: float
    exponent: float
    stribeck_factor: float
    duty_cycle: iso281.DutyCycleLife | None
    references: References | None = None
    warnings: tuple[ResultWarning, ...] = ()
    checks: BearingChecks | None = None

    @property
    def angle_step_deg(self) -> float:
        """Crank-angle step actually used, degrees."""
        return 360.0 / self.loads.theta.size

    @property
    def defined(self) -> bool:
        """True if the handbook model applies to the case (the loads are numbers, not NaN)."""
        return bool(self.bearings)


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


@dataclass(frozen=True, eq=False)
class StressResult:
    """Disc stresses of a load cycle.

    Attributes
    ----------
    peak : rvfem.evaluate.postprocess.PeakStress
        Largest vertex von Mises stress over every solved crank angle (the cycle's envelope).
    away_from_contacts : rvfem.evaluate.postprocess.PeakStress or None
        The same ignoring a band along the tooth profile and the bores (the structural peak).
    band_mm : dict
        Boundary name → width of the ignored band, mm.
    snapshots : tuple of rvfem.evaluate.postprocess.FieldSnapshot
        The kept fields (saved angles, largest bearing load, the two peaks, ``field_step_deg``).
    recovered : rvfem.evaluate.postprocess.RecoveredPeak or None
        The structural peak re-solved on P2 at its crank angles with the cycle's forces, with its
        convergence check (None when ``analyse(..., recover_stress=False)`` or when no vertex lies
        outside the contact bands). This is the structural peak the reports lead with.
    history : rvfem.evaluate.postprocess.HotSpotHistory or None
        Vertex stresses over every solved crank angle at the structural peak and the contact-zone
        peak (for a fatigue check).
    """

    peak: PeakStress
    away_from_contacts: PeakStress | None
    band_mm: dict[str, float]
    snapshots: tuple[FieldSnapshot, ...]
    recovered: RecoveredPeak | None = None
    history: HotSpotHistory | None = None

    @property
    def structural(self) -> PeakStress | None:
        """The structural peak away from contacts to report: P2-recovered if available, else P1."""
        if self.recovered is not None:
            return self.recovered.peak
        return self.away_from_contacts


@dataclass(frozen=True)
class DutyCycleFE:
    """The duty cycle evaluated with the flexible model at every duty-cycle torque.

    The service life of :class:`DutyCycleResult` ``flexible`` scales the rated flexible life with
    (T_i/T0)^(10/3) (Gao et al. eq. 18): it assumes the bearing loads grow linearly with the
    torque. The FE model is not linear (contact sets, Palmgren roller law, clearance), so here the
    load cycle is solved at each distinct positive duty-cycle torque (same disc model and
    compliance, no new factorisation) and Palmgren-Miner is applied to the bearing lives from
    those equivalent loads: 1/L = Σ s_i/L_i per bearing, s_i the time shares, L_i the L10h at the
    row's F_m and bearing speed; the service life is the shortest bearing's.

    Attributes
    ----------
    torques_Nm : tuple of float
        Distinct positive duty-cycle output torques, N·m.
    equivalent_load_N : tuple of tuple of float
        Flexible F_m per torque and bearing, N.
    linear_scaling_error_percent : tuple of float
        Per torque: largest over the bearings of F_m(T_i)/(F_m(T0)·T_i/T0) − 1, %.
    service_life_h : float
        Palmgren-Miner service life from the FE loads at every torque, hours.
    linear_scaling_life_h : float
        The same from the linear scaling (= ``DutyCycleResult.flexible.service_life_h``), hours.
    seconds : float
        Wall time of the extra load cycles, s.
    """

    torques_Nm: tuple[float, ...]
    equivalent_load_N: tuple[tuple[float, ...], ...]
    linear_scaling_error_percent: tuple[float, ...]
    service_life_h: float
    linear_scaling_life_h: float
    seconds: float

    @property
    def life_difference_percent(self) -> float:
        """(FE at every torque − linear scaling)/linear scaling of the service life, %."""
        return 100.0 * (self.service_life_h / self.linear_scaling_life_h - 1.0)


@dataclass(frozen=True)
class DutyCycleResult:
    """Duty-cycle service life (Palmgren-Miner) from the rigid and the flexible bearing lives
    (both scaled linearly with the torque, Gao et al. eq. 18), and the flexible one from the FE
    at every duty-cycle torque (``flexible_fe``, None when not computed). ``rigid`` is None where
    the handbook is not defined (Zp − Zc ≠ 1)."""

    rigid: iso281.DutyCycleLife | None
    flexible: iso281.DutyCycleLife
    flexible_fe: DutyCycleFE | None = None


def duty_cycle_fe(system, thetas: np.ndarray, cycle, comparison, linear_life_h: float) -> DutyCycleFE:
    """Solve the flexible load cycle at every distinct positive duty-cycle torque of the case and
    the service life from those loads (:class:`DutyCycleFE`; sources: ISO 281 life, Gao et al.
    eqs. 16-18 with the FE loads in place of the linear scaling).

    Parameters
    ----------
    system : rvfem.solve.cycle.DiscSystem
        The case's disc model (its compliance is reused).
    thetas : ndarray
        Crank angles, rad (those of ``cycle``).
    cycle : rvfem.solve.cycle.CycleResult
        The cycle at the case's own torque (reused for a duty row at that torque).
    comparison : rvfem.evaluate.compare.Comparison
        Its comparison (F_m at the case's torque).
    linear_life_h : float
        The linear-scaling service life, hours.
    """

    t0 = time.perf_counter()
    case = system.case
    rows = case.loads.duty_cycle
    rated_T = case.loads.torque_Nm
    torques = sorted({float(r.torque_Nm) for r in rows if r.torque_Nm > 0})
    rated_fm = [b.flexible.equivalent_N for b in comparison.bearings]
    fm: dict[float, list[float]] = {}
    for torque in torques:
        if math.isclose(torque, rated_T, rel_tol=1e-12):
            fm[torque] = rated_fm
            continue
        # the same system at another operating point: no new factorisation, the compliance
        # columns and contact sets of the case's cycle reused
        op = cycle_module.OperatingPoint(torque, case.analysis.friction)
        cyc = cycle_module.load_cycle(system, thetas, op=op, saved_angles_deg=())
        fm[torque] = [float(equivalent_load(f, case.analysis.equivalent_load_exponent))
                      for f in cyc.bearing_loads.T]
    errors = tuple(100.0 * max((f / (f0 * t / rated_T) - 1.0 for f, f0 in zip(fm[t], rated_fm)), key=abs)
                   for t in torques)
    rating = iso281.crank_bearing_rating(case.crank_bearing)
    total = sum(r.time_share for r in rows)
    lives = []
    for i in range(len(rated_fm)):
        damage = 0.0  # Σ s_i / L_i, 1/h
        for r in rows:
            if r.torque_Nm <= 0:
                continue
            n_b = iso281.bearing_speed_rpm(r.speed_rpm, case.pins.count, case.cycloid.teeth)
            life = iso281.rating_life_hours(rating, fm[float(r.torque_Nm)][i], n_b)
            # a life that underflows to 0 h is infinite damage, not a division by zero
            damage += (r.time_share / total) / life if life > 0 else math.inf
        lives.append(math.inf if damage == 0 else 1.0 / damage)
    return DutyCycleFE(torques_Nm=tuple(torques), equivalent_load_N=tuple(tuple(fm[t]) for t in torques),
                       linear_scaling_error_percent=errors, service_life_h=min(lives),
                       linear_scaling_life_h=linear_life_h, seconds=time.perf_counter() - t0)


@dataclass(frozen=True, eq=False)
class Analysis:
    """Everything one analysis of a case computed (see the module docstring); writes nothing.

    Attributes
    ----------
    case : Case
        The case as analysed (overrides applied).
    provenance : CaseProvenance
        Case file, checksum, overrides and defaults used.
    geometry : rvfem.geometry.DiscGeometry
    mesh : rvfem.mesh.DiscMesh
    system : rvfem.solve.cycle.DiscSystem
        The factorised disc model (for further solves).
    theta : ndarray (n,)
        Crank angles of the cycle, rad.
    rigid : RigidAnalysis
        The handbook evaluation at the same angles (``rigid.loads`` are the handbook curves; NaN
        where the handbook is not defined, Zp − Zc ≠ 1).
    classical : rvfem.evaluate.rigid.PinForces or None
        Classical rigid pin forces at the same angles (moment exact at every angle); None where the
        distribution does not hold (Zp − Zc ≠ 1, :func:`rvfem.evaluate.rigid.classical_applicable`).
    cycle : rvfem.solve.cycle.CycleResult
        The flexible load cycle.
    comparison : rvfem.evaluate.compare.Comparison
        Rigid, flexible and equal-share load statistics and lives per bearing; the deltas are
        against ``references.bearing_loads``.
    stress : StressResult
    hertz : dict of str to rvfem.evaluate.hertz.RollerHertz
        ``fe_rollers`` (bearing model ``rollers`` only), ``stribeck_rigid``, ``stribeck_flexible``.
    torsional_stiffness_Nm_per_arcmin : float
        Disc torque / mean carrier rotation.
    duty_cycle : DutyCycleResult or None
        None if the case has no duty cycle.
    timings : dict
        Wall time per stage of :data:`STAGES` (s), the model set-up details ``model_*``,
        ``cycle_per_angle`` and, with the attribution, ``attribution_compute`` (its own wall time;
        the stage ``attribution`` is the wait for it when :func:`analyse` computes it beside other
        stages, the computation itself when ``rvfem run`` does, after the VTK files).
    attribution : rvfem.evaluate.attribution.Attribution or None
        None from ``analyse(..., attribute=False)`` until the caller adds it. The flexibility
        effect step by step: handbook → equal share of the FE pin resultant →
        one disc with T/discs → two discs sharing the carrier → crankshafts (those that apply;
        without the handbook where it is not defined); ``attribution.final`` is the case's own
        model (``cycle``).
    references : rvfem.evaluate.rigid.References or None
        The rigid references the run is compared with, and why (:func:`rvfem.evaluate.rigid.references`).
    warnings : tuple of rvfem.evaluate.validity.ResultWarning
        Results outside their model's range (:func:`rvfem.evaluate.validity.analysis_warnings`: P/C,
        lives under 1 h, Hertz pressures, disc stress against the yield strength, deformation
        against the element size); empty when all hold.
    roller_depth : rvfem.evaluate.roller_life.CrankBearingDepth or None
        The crank bearing in depth (slice pressures, film, κ, a_ISO, L_nm, L10r; rigid and flexible);
        None for a bearing model without discrete rollers.
    accuracy : dict or None
        Torsional rigidity (N·m/arcmin) and lost motion (arcmin) of the stage at the case's torque
        from a few points of the hysteresis loop at crank angle 0 (:func:`run_accuracy`); None when
        they could not be solved.
    bearing_checks : rvfem.evaluate.bearing_checks.BearingChecks or None
        Static safety S0 and minimum load of the crank bearing (rigid and flexible) and the support
        bearings' loads and lives.
    """

    case: Case
    provenance: CaseProvenance
    geometry: DiscGeometry
    mesh: DiscMesh
    system: DiscSystem
    theta: np.ndarray
    rigid: RigidAnalysis
    classical: PinForces
    cycle: CycleResult
    comparison: Comparison
    stress: StressResult
    hertz: dict[str, hertz.RollerHertz]
    torsional_stiffness_Nm_per_arcmin: float
    duty_cycle: DutyCycleResult | None = None
    timings: dict = field(default_factory=dict)
    attribution: Attribution | None = None
    references: References | None = None
    warnings: tuple[ResultWarning, ...] = ()
    roller_depth: CrankBearingDepth | None = None
    accuracy: dict | None = None
    bearing_checks: BearingChecks | None = None

    @property
    def max_load_index(self) -> tuple[int, int]:
        """(angle index, bearing index) of the largest FE bearing load of the cycle."""

        return max_load_index(self.cycle.bearing_forces)

    @property
    def rigid_forces(self) -> np.ndarray | list[None]:
        """Handbook force of every bearing on the disc, (n, N, 2), N (the layout of
        ``cycle.bearing_forces``); where the handbook is not defined (Zp − Zc ≠ 1) a list of n
        None, one per crank angle (nothing to draw or compare)."""
        if not self.rigid.defined:
            return [None] * len(self.theta)
        hb = self.rigid.loads
        return np.stack([hb.fx.T, hb.fy.T], axis=2)

    @property
    def equal_share_forces(self) -> np.ndarray:
        """Equal share of the FE pin resultant for every bearing, (n, N, 2), N
        (:func:`rvfem.evaluate.compare.equal_share_forces`): the bearing-load reference for any tooth
        difference."""

        return equal_share_forces(self.case, self.cycle)

    @property
    def reference_loads(self) -> np.ndarray:
        """|F| of the bearing-load reference the deltas are against, (n, N), N: the handbook, or the
        equal share of the FE pin resultant where the handbook is not defined."""
        if self.comparison.reference == "handbook":
            return np.asarray(self.rigid.loads.magnitude).T
        return np.linalg.norm(self.equal_share_forces, axis=2)

    @property
    def pin_centres(self) -> np.ndarray:
        """Pin centres in the disc frame at every crank angle, (n, Zp, 2), mm."""

        return np.stack([pin_centres(self.case, float(th)) for th in self.theta])


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
        geometry, mesh, system = _disc_model(case, stages, cache_dir)
        if on_model is not None:
            on_model(system)
        return _analyse_from_model(case, checked.provenance, stages, checked.thetas, checked.saved, geometry, mesh,
                                   system, background, recover_stress, duty_fe, attribute, child)
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


def _disc_model(case: Case, stages: Stages, cache_dir: str | os.PathLike | None):
    """The ``mesh`` and ``model`` stages of :func:`analyse`: the disc geometry, its mesh (cached in
    ``cache_dir``, default :func:`default_cache_dir`) and the assembled, factorised disc model
    (:class:`rvfem.solve.cycle.DiscSystem`)."""
    t = stages.start("mesh")
    geometry = disc_geometry(case)
    mesh = mesh_case(case, default_cache_dir() if cache_dir is None else cache_dir, geometry=geometry)
    stages.end("mesh", t)

    t = stages.start("model")
    system = cycle_module.build_system(case, mesh, geometry=geometry)
    stages.end("model", t)
    return geometry, mesh, system


def _analyse_from_model(case, provenance, stages, thetas, saved, geometry, mesh, system, background,
                        recover_stress, duty_fe, attribute=True, child=None):
    """The stages of :func:`analyse` after the model; ``background`` runs the work beside them."""

    # the rigid model before the cycle: a case outside every rigid reference fails fast
    t = stages.start("rigid")
    references = rigid.references(case)
    if not (references.handbook.defined or references.equal_share.defined):
        raise CaseError(f"{case.source}: {references.equal_share.why}")
    steps = _StageSteps(stages, "rigid", extra=1)   # the slices of each bearing, then the rest
    rigid_analysis = analyse_rigid(case, thetas, progress=steps)
    classical = (rigid.classical_pin_forces(case, thetas, exact_moment=True)
                 if references.classical_pin_forces.defined else None)
    log.info("%s: bearing loads compared with %s", case.name, rigid.REFERENCE_NAMES[references.bearing_loads])
    steps.end(t)

    n = len(thetas)
    t = stages.start("cycle", n)

    # the P2 model of the stress stage, built in a child process during the load cycle
    p2 = _P2Model(system, mesh, background, child) if recover_stress and system.model.order == 1 else None

    try:
        def report(i: int, total: int) -> None:  # the last angle is reported by stages.end
            if p2 is not None:
                p2.start()
            if i < total:
                stages.tick("cycle", i, total)

        cycle = cycle_module.load_cycle(system, thetas, progress=report, saved_angles_deg=saved, stress_envelope=True)
        stages.end("cycle", t, n)

        t = stages.start("evaluation")
        comparison = compare.rigid_vs_flexible(case, cycle)
        # peaks over every solved angle (the cycle's stress envelope); their fields are kept too
        peak = postprocess.peak_von_mises(cycle, mesh.points, mesh.boundaries)
        band = {"profile": CONTACT_BAND_ELEMENTS * case.mesh.size_flank}
        band.update({f"bore_{i}": CONTACT_BAND_ELEMENTS * case.mesh.size_bore for i in range(case.cranks.count)})
        away = postprocess.peak_von_mises(cycle, mesh.points, mesh.boundaries, exclude=band)
        snapshots = postprocess.field_snapshots(
            system, cycle, extra_angles=[math.radians(pk.theta_deg) for pk in (peak, away) if pk is not None])
        stages.end("evaluation", t)

        # what the flexibility effect is made of: the modelling steps the case's own model does not
        # already give, on the same angles and the same compliance. Mostly small dense solves, it runs
        # beside the stress stage (whose P2 re-solve is made in the P2 model's child process); the
        # two share read-only data and the P1 compliance, whose cache is locked
        pending = background.submit(_timed, attribution_of, system, thetas, cycle) if attribute else None
        stress, roller_hertz, stiffness, duty = _evaluate(
            case, stages, system, mesh, cycle, comparison, rigid_analysis, peak, away, band, snapshots,
            recover_stress, p2)
    finally:
        if p2 is not None:          # the P2 model (a few hundred MB) is not needed any more
            p2.close()
            p2 = None
    attribution = None
    if pending is not None:
        t = stages.start("attribution")
        attribution, attribution_seconds = pending.result()
        stages.end("attribution", t)
    # the secondary analyses below (and the attribution's steps) may not refuse a case whose load
    # cycle solved: one that cannot be made is left out with a warning that says why
    not_computed = list(attribution_warnings(attribution))
    if duty is not None and duty_fe:
        duty = _duty_cycle_stage(stages, system, thetas, cycle, comparison, duty, not_computed)

    accuracy = _accuracy_stage(stages, system)
    timings = dict(stages.seconds)
    if pending is not None:
        timings["attribution_compute"] = attribution_seconds
    timings.update({"model_" + k: v for k, v in system.setup_seconds.items()})
    timings["cycle_per_angle"] = stages.seconds["cycle"] / n
    result = Analysis(case=case, provenance=provenance, geometry=geometry, mesh=mesh, system=system,
                      theta=np.asarray(thetas), rigid=rigid_analysis, classical=classical, cycle=cycle,
                      comparison=comparison, stress=stress, hertz=roller_hertz,
                      torsional_stiffness_Nm_per_arcmin=stiffness, duty_cycle=duty, timings=timings,
                      attribution=attribution, references=references, accuracy=accuracy)
    result = _with_roller_depth(result, stages)
    return dataclasses.replace(result, warnings=result.warnings + tuple(not_computed)) if not_computed else result


def _accuracy_stage(stages: Stages, system) -> dict | None:
    """The ``accuracy`` stage of :func:`analyse` (:func:`run_accuracy`)."""
    t = stages.start("accuracy")
    accuracy = run_accuracy(system)
    stages.end("accuracy", t)
    return accuracy


def _duty_cycle_stage(stages, system, thetas, cycle, comparison, duty, not_computed: list):
    """The ``duty_cycle`` stage of :func:`analyse`: ``duty`` with the flexible FE at every duty-cycle
    torque (:func:`duty_cycle_fe`); if that does not solve, ``duty`` as it is and a ``not_computed``
    warning appended to ``not_computed``."""
    t = stages.start("duty_cycle")
    try:
        duty = dataclasses.replace(duty, flexible_fe=duty_cycle_fe(system, thetas, cycle, comparison,
                                                                   duty.flexible.service_life_h))
    except ContactError as exc:
        log.info("the flexible FE at every duty-cycle torque not computed: %s", exc)
        not_computed.append(validity.ResultWarning(
            "not_computed", f"the flexible FE at every duty-cycle torque not computed: {exc}; the service "
            "life is the linear scaling of the case's own cycle", 1.0, 0.0, ""))
    stages.end("duty_cycle", t)
    return duty


def _with_roller_depth(result: Analysis, stages: Stages | None = None) -> Analysis:
    """The analysis with the crank bearing in depth (slices of every roller, film, a_ISO, L_nm and
    L10r, rigid and flexible; :func:`rvfem.evaluate.roller_life.crank_bearing_depth`; stage
    ``roller_slices`` of ``stages`` when the cycle has roller loads) and all warnings."""
    stages = Stages(None) if stages is None else stages
    sliced = result.cycle.roller_loads is not None
    if sliced:
        t = stages.start("roller_slices")
    steps = _StageSteps(stages, "roller_slices")
    rigid_depths = tuple(b.depth for b in result.rigid.bearings if b.depth is not None)
    depth = roller_life.crank_bearing_depth(result.case, result.theta, result.cycle, result.rigid_forces,
                                            result.comparison, result.rigid.rating_N, result.rigid.bearing_speed_rpm,
                                            rigid_depths=rigid_depths or None,
                                            progress=steps)
    if depth is not None:
        result.timings["roller_depth"] = depth.seconds
    checks = _bearing_checks(result)
    if sliced:
        steps.end(t)
        result.timings["roller_slices"] = stages.seconds["roller_slices"]
    return dataclasses.replace(result, roller_depth=depth, bearing_checks=checks,
                               warnings=validity.analysis_warnings(result) + validity.roller_depth_warnings(depth)
                               + validity.bearing_check_warnings(checks))


def _bearing_checks(result: Analysis) -> bearing_checks.BearingChecks:
    """Static safety, minimum load and support bearings of a run
    (:func:`rvfem.evaluate.bearing_checks.case_bearing_checks`)."""
    bearings = result.comparison.bearings
    models_ = {"flexible": [b.flexible for b in bearings]}
    if result.rigid.defined and all(b.rigid is not None for b in bearings):
        models_["rigid"] = [b.rigid for b in bearings if b.rigid is not None]
    return bearing_checks.case_bearing_checks(
        result.case, result.theta, result.rigid.rating_N, result.rigid.bearing_speed_rpm,
        {m: max(s.max_N for s in v) for m, v in models_.items()},
        {m: min(s.min_N for s in v) for m, v in models_.items()}, result.cycle.disc_bearing_forces)


def run_accuracy(system) -> dict | None:
    """Torsional rigidity and lost motion of the case's stage at its torque and pin friction, at
    crank angle 0, from six solves on the factorised disc (:func:`rvfem.evaluate.accuracy.quick_figures`;
    ``rvfem hysteresis`` gives the whole loop averaged over a mesh period). None if a solve fails
    (logged): the run's other results do not depend on it."""
    case = system.case
    try:
        figures = accuracy_eval.quick_figures(cycle_module.case_stage(system), abs(float(case.loads.torque_Nm)),
                                              float(case.analysis.friction))
    except (ContactError, ValueError) as exc:
        log.warning("torsional rigidity and lost motion not computed: %s", exc)
        return None
    return {**figures, "crank_angle_deg": 0.0, "torque_Nm": abs(float(case.loads.torque_Nm))}


def attribution_of(system, thetas, cycle):
    """The attribution of a case's flexible load cycle (:func:`rvfem.evaluate.attribution.attribution`): the
    modelling steps the case's own model does not already give, on the same angles and the same
    compliance."""

    return attribution.attribution(system, thetas, cycles={attribution.case_step(system.case): cycle})


def attribution_warnings(result) -> tuple:
    """The warnings of the attribution steps that could not be made
    (:func:`rvfem.evaluate.attribution.skipped_warnings`); none for None."""
    return attribution.skipped_warnings(result)


def _timed(function, *args, **kwargs):
    """``(function(*args, **kwargs), wall time in s)``."""
    t0 = time.perf_counter()
    return function(*args, **kwargs), time.perf_counter() - t0


def _evaluate(case, stages, system, mesh, cycle, comparison, rigid_analysis, peak, away, band, snapshots,
              recover_stress, p2=None):
    """The stress stage (the structural peak re-solved on P2) and the rest of the evaluation:
    hot-spot histories, Hertz, torsional stiffness, duty-cycle lives from the rigid and flexible
    loads. Returns (StressResult, Hertz results, stiffness, DutyCycleResult or None)."""

    recovered = None
    if recover_stress and away is not None:
        t = stages.start("stress")
        recovered = _recover_structural_peak(system, cycle, mesh, band, away, p2)
        stages.end("stress", t)
        if not any(math.isclose(s.theta_deg, recovered.peak.theta_deg, abs_tol=1e-9) for s in snapshots):
            snapshots = postprocess.field_snapshots(system, cycle, extra_angles=[
                math.radians(x) for x in (peak.theta_deg, away.theta_deg, recovered.peak.theta_deg)])
    t = time.perf_counter()
    spots = {"structural": recovered.peak if recovered is not None else away, "contact_zone": peak}
    spots = {k: v for k, v in spots.items() if v is not None}
    factors = {}
    if recovered is not None and recovered.p1_at_peak_MPa > 0:
        factors["structural"] = recovered.peak.von_mises_MPa / recovered.p1_at_peak_MPa
    history = postprocess.hot_spot_history(system, cycle, spots, factors)
    stress = StressResult(peak=peak, away_from_contacts=away, band_mm=band, snapshots=snapshots,
                          recovered=recovered, history=history)
    rigid_forces = None
    if rigid_analysis.defined:
        hb = rigid_analysis.loads
        rigid_forces = np.stack([hb.fx.T, hb.fy.T], axis=2)
    roller_hertz = hertz.most_loaded_roller_hertz(
        case, cycle.theta, cycle.bearing_forces, cycle.roller_loads, rigid_forces,
        None if rigid_forces is None else roller_slices.case_rigid_roller_loads(case, cycle.theta, rigid_forces),
        roller_slices.case_rigid_roller_loads(case, cycle.theta, cycle.bearing_forces))
    stiffness = cycle.torsional_stiffness_Nm_per_arcmin(case.loads.disc_torque_Nmm)
    duty = None
    if case.loads.duty_cycle:
        duty = DutyCycleResult(
            rigid=(iso281.case_duty_cycle_life(case, [b.rigid.L10h for b in comparison.bearings])
                   if rigid_analysis.defined else None),
            flexible=iso281.case_duty_cycle_life(case, [b.flexible.L10h for b in comparison.bearings]))
    stages.seconds["evaluation"] += time.perf_counter() - t
    return stress, roller_hertz, stiffness, duty
