"""The result of one analysis of a case, typed: :class:`Analysis` and the results it holds that have
no home in a lower layer (the rigid evaluation, the stresses, the duty cycle, the case's provenance).

The analysis computes them (:func:`rvfem.app.analysis.analyse`, a scheduler over the result
sections of :mod:`rvfem.results.registry`); the writers of :mod:`rvfem.outputs` and the sections'
summaries read them. Nothing here computes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from rvfem.case.definition import Case
from rvfem.evaluate import hertz, iso281, rigid
from rvfem.evaluate.compare import equal_share_forces
from rvfem.evaluate.postprocess import max_load_index
from rvfem.geometry import pin_centres

if TYPE_CHECKING:  # the heavier modules are imported where used
    from rvfem.evaluate.attribution import Attribution
    from rvfem.evaluate.bearing_checks import BearingChecks
    from rvfem.evaluate.compare import Comparison
    from rvfem.evaluate.design_checks import DesignChecks
    from rvfem.evaluate.pin_flank import PinFlankHertz
    from rvfem.evaluate.postprocess import FieldSnapshot, HotSpotHistory, PeakStress, RecoveredPeak
    from rvfem.evaluate.rigid import PinForces, References
    from rvfem.evaluate.roller_life import BearingDepth, CrankBearingDepth, L10rSteps
    from rvfem.evaluate.validity import ResultWarning
    from rvfem.geometry import DiscGeometry
    from rvfem.mesh import DiscMesh
    from rvfem.solve.cycle import CycleResult, DiscSystem

__all__ = ["rigid_bearing_forces", "Analysis", "AnalysisOptions", "CaseProvenance", "DutyCycleFE", "DutyCycleResult", "RigidAnalysis",
           "RigidBearing", "StressResult"]


def rigid_bearing_forces(rigid_analysis: RigidAnalysis, theta: np.ndarray) -> np.ndarray | list[None]:
    """Handbook force of every bearing on the disc, (n, N, 2), N (the layout of
    ``cycle.bearing_forces``); where the handbook is not defined (Zp − Zc ≠ 1) a list of n None,
    one per crank angle (nothing to draw or compare)."""
    if not rigid_analysis.defined:
        return [None] * len(theta)
    hb = rigid_analysis.loads
    return np.stack([hb.fx.T, hb.fy.T], axis=2)


@dataclass(frozen=True)
class AnalysisOptions:
    """What an analysis computes and how (the choices of :func:`rvfem.app.analysis.analyse`).

    Attributes
    ----------
    angle_step_deg, bearing_model, order : optional
        Override ``analysis.angle_step_deg`` (degrees), ``crank_bearing.model`` and
        ``analysis.element_order`` (:func:`rvfem.app.analysis.resolve_case`); None keeps the case's.
    field_step_deg : float, optional
        Also keep the fields every ``field_step_deg`` degrees.
    recover_stress : bool
        Re-solve the structural peak on P2 (stage ``stress``).
    duty_fe : bool
        Solve the flexible cycle at every other duty-cycle torque (stage ``duty_cycle``).
    attribute : bool
        Compute the attribution (stage ``attribution``).
    sections : tuple of str, optional
        Compute only these result sections (:func:`rvfem.results.registry.sections`, by name) and
        the sections they require; the others are left None. None (the default) computes every
        section. A design of ``rvfem optimise`` computes only what its responses read (the stress
        and the mass and strength): the same numbers, without the stages nobody reads.
    """

    angle_step_deg: float | None = None
    bearing_model: str | None = None
    order: int | None = None
    field_step_deg: float | None = None
    recover_stress: bool = True
    duty_fe: bool = True
    attribute: bool = True
    sections: tuple[str, ...] | None = None


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
    overrides : dict[str, Any]
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
    overrides: dict[str, Any] = field(default_factory=dict[str, Any])
    defaults_used: tuple[tuple[str, Any], ...] = ()


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


@dataclass(frozen=True, eq=False)
class StressResult:
    """Disc stresses of a load cycle.

    Attributes
    ----------
    peak : rvfem.evaluate.postprocess.PeakStress
        Largest vertex von Mises stress over every solved crank angle (the cycle's envelope).
    away_from_contacts : rvfem.evaluate.postprocess.PeakStress or None
        The same ignoring a band along the tooth profile and the bores (the structural peak).
    band_mm : dict[str, Any]
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
    at every duty-cycle torque (``flexible_fe``, None when not computed; ``fe_not_computed`` says why
where it could not be solved). ``rigid`` is None where
    the handbook is not defined (Zp − Zc ≠ 1)."""

    rigid: iso281.DutyCycleLife | None
    flexible: iso281.DutyCycleLife
    flexible_fe: DutyCycleFE | None = None
    fe_not_computed: str | None = None


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
    timings : dict[str, Any]
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
    roller_life_steps : tuple of rvfem.evaluate.roller_life.L10rSteps or None
        The flexible/rigid L10r ratio of every bearing in steps (handbook → pin friction → flexible
        bearing forces → load sharing → tilt), each a factor; None without discrete rollers or
        without the handbook.
    accuracy : dict or None
        Torsional rigidity (N·m/arcmin) and lost motion (arcmin) of the stage at the case's torque
        from a few points of the hysteresis loop at crank angle 0 (:func:`run_accuracy`); None when
        they could not be solved.
    bearing_checks : rvfem.evaluate.bearing_checks.BearingChecks or None
        Static safety S0 and minimum load of the crank bearing (rigid and flexible) and the support
        bearings' loads and lives.
    mass_strength : rvfem.evaluate.design_checks.DesignChecks or None
        Disc mass and inertia, static and fatigue safety (None until computed).
    pin_flank : rvfem.evaluate.pin_flank.PinFlankHertz or None
        The pin–flank Hertz contact over the cycle: its peak pressure, where, the subsurface shear
        and the contact-fatigue safety (None until computed).
    extra : mapping of str to object
        The results of sections registered from outside rvfem (:func:`rvfem.results.registry.register_section`),
        by section name; read-only.
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
    timings: dict[str, Any] = field(default_factory=dict[str, Any])
    attribution: Attribution | None = None
    references: References | None = None
    warnings: tuple[ResultWarning, ...] = ()
    roller_depth: CrankBearingDepth | None = None
    roller_life_steps: tuple[L10rSteps, ...] | None = None
    accuracy: dict[str, Any] | None = None
    bearing_checks: BearingChecks | None = None
    mass_strength: DesignChecks | None = None
    pin_flank: PinFlankHertz | None = None
    extra: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))

    @property
    def max_load_index(self) -> tuple[int, int]:
        """(angle index, bearing index) of the largest FE bearing load of the cycle."""

        return max_load_index(self.cycle.bearing_forces)

    @property
    def rigid_forces(self) -> np.ndarray | list[None]:
        """Handbook force of every bearing on the disc, (n, N, 2), N (the layout of
        ``cycle.bearing_forces``); where the handbook is not defined (Zp − Zc ≠ 1) a list of n
        None, one per crank angle (nothing to draw or compare)."""
        return rigid_bearing_forces(self.rigid, self.theta)

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

