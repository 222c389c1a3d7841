"""Where the models behind a result hold, and a one-line warning for every result outside.

rvfem's results come from models with a range: the ISO 281 rating life, Hertz line contact, a
linear-elastic disc, small displacements. An overloaded case (48 × the rated torque, a 1 mm pitch
error) still gives numbers; this module says which of them are outside their model's range. It
computes, it does not print: :func:`check_limits` is a pure function of plain numbers,
:func:`analysis_warnings` and :func:`rigid_warnings` read them from an
:class:`~rvfem.app.analysis.Analysis` or a :class:`~rvfem.app.analysis.RigidAnalysis` (which carry the
result as their ``warnings``); ``summary.json``, ``rvfem rigid --json``, the report and the
screen present them (docs/outputs.md, "Warnings").

The limits, one constant each (sources in the docstrings and in docs/outputs.md):

======================  =======================================================  ================
code                    warns when                                               limit
======================  =======================================================  ================
``load_ratio``          P/C = F_m/C of a bearing is above                        0.5
``life_under_1h``       a bearing life (L10h, duty-cycle service life) is under  1 h
``hertz_pressure``      a roller–raceway Hertz peak pressure is above            4000 MPa (steel)
``disc_stress_yield``   the disc's structural stress peak (von Mises) is above   the material's
                        (``material.yield_strength``)                            R_p0.2
``fatigue_safety``      a hot spot's fatigue safety factor (FKM signed von        1
                        Mises on the Goodman line) is below
``large_displacement``  the largest disc deformation is above, of the element    10 %
                        size at the contacts
======================  =======================================================  ================
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Iterable

import numpy as np

from rvfem.evaluate.strength import FATIGUE_CRITERION, hot_spot_fatigue

__all__ = [
    "LOAD_RATIO_LIMIT",
    "MIN_LIFE_H",
    "HERTZ_PRESSURE_LIMIT_MPA",
    "bearing_check_warnings",
    "BEARING_STEEL_MODULUS_MPA",
    "BEARING_STEEL_POISSONS_RATIO",
    "hertz_pressure_limit_MPa",
    "bearing_depth_warnings",
    "PLACEHOLDER_YIELD_STRENGTH_MPA",
    "DISPLACEMENT_FRACTION_LIMIT",
    "ResultWarning",
    "check_limits",
    "analysis_warnings",
    "rigid_warnings",
    "KAPPA_RANGE",
    "roller_depth_warnings",
    "FATIGUE_SAFETY_LIMIT",
]

FATIGUE_SAFETY_LIMIT = 1.0
"""Smallest fatigue safety factor of a hot spot reported without a warning."""

LOAD_RATIO_LIMIT = 0.5
"""Largest P/C (equivalent load over the dynamic load rating) for which the ISO 281 rating life is
reported without a warning. The rating-life formula L10 = (C/P)^(10/3) was fitted to endurance
tests at moderate loads, where subsurface fatigue ends the life; rolling-bearing makers treat
P > 0.5·C as outside its range (plastic deformation at the contacts governs there). On the
shipped crank bearing, Stribeck's most loaded roller at F_m = 0.5·C already presses the raceway
at about 3000 MPa, three quarters of the static limit :data:`HERTZ_PRESSURE_LIMIT_MPA`."""

MIN_LIFE_H = 1.0
"""A bearing life under one hour (one that a table in whole hours shows as 0 h) is a load far beyond
the bearing's capacity, not a life."""

HERTZ_PRESSURE_LIMIT_MPA = 4000.0
"""Largest Hertz peak pressure of a roller–raceway line contact reported without a warning, MPa:
ISO 76:2006, 3.1, defines the basic static load rating of radial roller bearings as the load that
gives 4000 MPa at the centre of the most heavily loaded contact, where the total permanent
deformation of roller and raceway is about 1/10 000 of the roller diameter. Above it the
raceways deform plastically: Hertz's elastic theory and the rating life no longer hold."""

BEARING_STEEL_MODULUS_MPA = 206000.0
"""Young's modulus of bearing steel, MPa (with :data:`BEARING_STEEL_POISSONS_RATIO`): the material
of the limit :data:`HERTZ_PRESSURE_LIMIT_MPA`."""

BEARING_STEEL_POISSONS_RATIO = 0.3


def hertz_pressure_limit_MPa(youngs_modulus_MPa: float = BEARING_STEEL_MODULUS_MPA,
                             poissons_ratio: float = BEARING_STEEL_POISSONS_RATIO) -> float:
    """The limit :data:`HERTZ_PRESSURE_LIMIT_MPA` for Hertz pressures computed with the given
    material (both bodies of the contact, as :func:`rvfem.evaluate.hertz.crank_bearing_hertz` has them).

    ISO 76's 4000 MPa is a pressure on bearing steel. A case whose material is not steel (the
    rigid-disc limit of ``rv40e_classical`` has 6 × steel's modulus, a numerical device) gets
    pressures scaled by sqrt(E'/E'_steel), E' = E/(1 − ν²), for the same roller load; the limit is
    scaled the same way, so that the check asks whether the roller load would exceed the static
    capacity of a steel bearing. For bearing steel it is 4000 MPa.
    """
    def reduced(e: float, nu: float) -> float:
        return e / (1.0 - nu * nu)

    return HERTZ_PRESSURE_LIMIT_MPA * math.sqrt(
        reduced(youngs_modulus_MPa, poissons_ratio) / reduced(BEARING_STEEL_MODULUS_MPA, BEARING_STEEL_POISSONS_RATIO))


PLACEHOLDER_YIELD_STRENGTH_MPA = 1600.0
"""Yield strength of the disc material, MPa: a **placeholder** until the case gives strength data
(the disc-strength issue). The lower end of published 0.2 % proof stresses of through-hardened
bearing steel (GCr15 / 100Cr6, hardened and tempered at low temperature, about 1.6–2 GPa), the
material of every shipped case. A structural peak above it means the linear-elastic disc model
does not hold (and the disc would yield)."""

DISPLACEMENT_FRACTION_LIMIT = 0.1
"""Largest deformation of the disc (rigid-body motion removed), as a fraction of the element size
at the contacts (the smaller of ``mesh.size_flank`` and ``mesh.size_bore``), reported without a
warning. The model is linear: the contact gaps, the pin and roller footprints (spread over about
1.5 elements) and the stresses are evaluated on the undeformed disc. A deformation of a tenth of
an element moves a footprint by a tenth of its width; beyond that the small-displacement
assumption is no longer met at the resolution the mesh gives."""


@dataclass(frozen=True)
class ResultWarning:
    """One result outside its model's range.

    Attributes
    ----------
    code : str
        What is checked, a stable key: ``load_ratio``, ``life_under_1h``, ``hertz_pressure``,
        ``disc_stress_yield``, ``large_displacement``, ``fatigue_safety``.
    message : str
        One line for the user: the value, where it occurs, the limit and what it means.
    value : float
        The offending value (the worst of its kind), in ``unit``.
    limit : float
        The limit it crosses, in ``unit``.
    unit : str
        Unit of ``value`` and ``limit`` (``""`` for a ratio).
    """

    code: str
    message: str
    value: float
    limit: float
    unit: str

    def as_dict(self) -> dict:
        """The JSON object of ``summary.json`` and ``rvfem rigid --json`` (``warnings[]``)."""
        return asdict(self)


def _finite(items: Iterable[tuple[str, float | None]]) -> list[tuple[str, float]]:
    return [(label, float(v)) for label, v in items if v is not None and math.isfinite(float(v))]


def _sig(value: float, digits: int = 3) -> str:
    """``value`` with ``digits`` significant figures, plainly written below 10^6."""
    if value == 0 or not math.isfinite(value):
        return f"{value:g}"
    if 1e-3 <= abs(value) < 1e6:
        decimals = max(0, digits - 1 - math.floor(math.log10(abs(value))))
        return f"{value:.{decimals}f}"
    return f"{value:.{digits - 1}e}"


def check_limits(*, load_ratios: Iterable[tuple[str, float | None]] = (),
                 lives_h: Iterable[tuple[str, float | None]] = (),
                 hertz_MPa: Iterable[tuple[str, float | None]] = (),
                 hertz_limit_MPa: float = HERTZ_PRESSURE_LIMIT_MPA,
                 disc_stress_MPa: float | None = None,
                 yield_strength_MPa: float = PLACEHOLDER_YIELD_STRENGTH_MPA,
                 deformation_mm: float | None = None,
                 element_size_mm: float | None = None) -> tuple[ResultWarning, ...]:
    """The warnings of a set of results: one per limit crossed, naming the worst value.

    Parameters
    ----------
    load_ratios : iterable of (str, float)
        (where, P/C) of every bearing and model, e.g. ``("bearing 1, flexible", 0.12)``.
    lives_h : iterable of (str, float)
        (where, life in hours): L10h of every bearing and model, duty-cycle service lives.
    hertz_MPa : iterable of (str, float)
        (where, Hertz peak pressure in MPa) of the roller–raceway contacts evaluated.
    hertz_limit_MPa : float
        Their limit (default :data:`HERTZ_PRESSURE_LIMIT_MPA`, bearing steel; see
        :func:`hertz_pressure_limit_MPa` for another material).
    disc_stress_MPa : float, optional
        The disc's structural stress peak (von Mises), MPa.
    yield_strength_MPa : float
        Yield strength of the disc material, MPa (default :data:`PLACEHOLDER_YIELD_STRENGTH_MPA`).
    deformation_mm : float, optional
        Largest deformation of the disc (rigid-body motion removed), mm.
    element_size_mm : float, optional
        Element size at the contacts, mm (needed with ``deformation_mm``).

    Returns
    -------
    tuple of ResultWarning
        In the order of the parameters; empty when every result is inside its range. Values
        that are None or not finite (an infinite life at zero load) are skipped.
    """
    found = (_load_ratio_warning(_finite(load_ratios)),
             _life_warning(_finite(lives_h)),
             _hertz_warning(_finite(hertz_MPa), hertz_limit_MPa),
             _yield_warning(disc_stress_MPa, yield_strength_MPa),
             _displacement_warning(deformation_mm, element_size_mm))
    return tuple(w for w in found if w is not None)


def _load_ratio_warning(ratios: list[tuple[str, float]]) -> ResultWarning | None:
    """The ``load_ratio`` warning of the largest P/C, if it is above :data:`LOAD_RATIO_LIMIT`."""
    if not ratios:
        return None
    where, value = max(ratios, key=lambda x: x[1])
    if not value > LOAD_RATIO_LIMIT:
        return None
    return ResultWarning(
        "load_ratio",
        f"P/C = {_sig(value)} ({where}) > {LOAD_RATIO_LIMIT:g}: outside the range of the ISO 281 rating "
        "life; the lives are not meaningful",
        value, LOAD_RATIO_LIMIT, "")


def _life_warning(lives: list[tuple[str, float]]) -> ResultWarning | None:
    """The ``life_under_1h`` warning of the shortest life, if it is under :data:`MIN_LIFE_H`."""
    if not lives:
        return None
    where, value = min(lives, key=lambda x: x[1])
    if not value < MIN_LIFE_H:
        return None
    return ResultWarning(
        "life_under_1h",
        f"life {_sig(value)} h ({where}) < {MIN_LIFE_H:g} h: a load far beyond the bearing's capacity, "
        "not a life",
        value, MIN_LIFE_H, "h")


def _hertz_warning(pressures: list[tuple[str, float]], hertz_limit_MPa: float) -> ResultWarning | None:
    """The ``hertz_pressure`` warning of the largest Hertz pressure, if it is above ``hertz_limit_MPa``
    (the message says when the limit is :data:`HERTZ_PRESSURE_LIMIT_MPA` scaled to another modulus)."""
    if not pressures:
        return None
    where, value = max(pressures, key=lambda x: x[1])
    if not value > hertz_limit_MPa:
        return None
    scaled = ("" if math.isclose(hertz_limit_MPa, HERTZ_PRESSURE_LIMIT_MPA) else
              f" ({HERTZ_PRESSURE_LIMIT_MPA:.0f} MPa on bearing steel, scaled to the case's modulus)")
    return ResultWarning(
        "hertz_pressure",
        f"Hertz pressure {value:.0f} MPa ({where}) > {hertz_limit_MPa:.0f} MPa, the static limit of roller "
        f"bearings (ISO 76){scaled}: the raceways deform plastically, elastic Hertz contact does not hold",
        value, float(hertz_limit_MPa), "MPa")


def _yield_warning(disc_stress_MPa: float | None, yield_strength_MPa: float) -> ResultWarning | None:
    """The ``disc_stress_yield`` warning, if the structural peak is above the yield strength."""
    if not (disc_stress_MPa is not None and math.isfinite(disc_stress_MPa) and disc_stress_MPa > yield_strength_MPa):
        return None
    source = ("placeholder for through-hardened bearing steel"
              if yield_strength_MPa == PLACEHOLDER_YIELD_STRENGTH_MPA else "material.yield_strength")
    return ResultWarning(
        "disc_stress_yield",
        f"structural stress peak {disc_stress_MPa:.0f} MPa von Mises > yield strength "
        f"{yield_strength_MPa:.0f} MPa ({source}): the disc yields, the linear-elastic model does not hold",
        float(disc_stress_MPa), float(yield_strength_MPa), "MPa")


def _displacement_warning(deformation_mm: float | None, element_size_mm: float | None) -> ResultWarning | None:
    """The ``large_displacement`` warning, if the deformation is above
    :data:`DISPLACEMENT_FRACTION_LIMIT` of the element size at the contacts."""
    if not (deformation_mm is not None and element_size_mm is not None and math.isfinite(deformation_mm)
            and element_size_mm > 0 and deformation_mm > DISPLACEMENT_FRACTION_LIMIT * element_size_mm):
        return None
    limit = DISPLACEMENT_FRACTION_LIMIT * element_size_mm
    return ResultWarning(
        "large_displacement",
        f"largest disc deformation {_sig(deformation_mm)} mm = {100 * deformation_mm / element_size_mm:.0f} % "
        f"of the element size at the contacts ({element_size_mm:g} mm) > "
        f"{100 * DISPLACEMENT_FRACTION_LIMIT:.0f} %: beyond the small-displacement assumption of the linear "
        "model",
        float(deformation_mm), float(limit), "mm")


def _hertz_items(label: str, inner, outer) -> list[tuple[str, float]]:
    return [(f"{label}, on the eccentric", inner.peak_pressure_MPa),
            (f"{label}, in the disc bore", outer.peak_pressure_MPa)]


def _duty_lives(duty) -> list[tuple[str, float | None]]:
    """(where, service life) of a :class:`rvfem.app.analysis.DutyCycleResult`."""
    if duty is None:
        return []
    out = [("duty-cycle service life, flexible", duty.flexible.service_life_h)]
    if duty.rigid is not None:
        out.append(("duty-cycle service life, rigid", duty.rigid.service_life_h))
    if duty.flexible_fe is not None:
        out.append(("duty-cycle service life, flexible FE at every torque", duty.flexible_fe.service_life_h))
    return out


_HERTZ_LABELS = {"fe_rollers": "largest FE roller load", "stribeck_rigid": "rigid rings, handbook loads",
                 "stribeck_flexible": "rigid rings, FE bearing loads"}


def analysis_warnings(analysis) -> tuple[ResultWarning, ...]:
    """The warnings of a complete analysis (:class:`rvfem.app.analysis.Analysis`; its ``warnings``
    field holds them once :func:`rvfem.app.analysis.analyse` has computed them).

    Checked: P/C and L10h of every bearing, rigid (handbook, where defined) and flexible; the
    duty-cycle service lives; the Hertz pressures of every evaluated roller (FE and Stribeck);
    the structural stress peak (P2 where re-solved; the contact-zone peak is mesh-dependent and
    not checked); the largest deformation of the kept fields against ``min(mesh.size_flank,
    mesh.size_bore)``.
    """
    c = analysis.comparison
    ratios, lives = [], []
    for bc in c.bearings:
        for model in ("rigid", "flexible"):
            s = getattr(bc, model)
            if s is None:
                continue
            where = f"bearing {bc.bearing + 1}, {model}"
            ratios.append((where, s.equivalent_N / c.rating_N))
            lives.append((f"{where} L10h", s.L10h))
    lives += _duty_lives(analysis.duty_cycle)
    pressures = []
    for key, rh in analysis.hertz.items():
        pressures += _hertz_items(_HERTZ_LABELS.get(key, key), rh.inner, rh.outer)
    structural = analysis.stress.structural
    snapshots = analysis.stress.snapshots
    deformation = max((float(np.max(np.hypot(*s.deformation.T), initial=0.0)) for s in snapshots), default=None)
    ms, mat = analysis.case.mesh, analysis.case.material
    found = check_limits(load_ratios=ratios, lives_h=lives, hertz_MPa=pressures,
                         hertz_limit_MPa=hertz_pressure_limit_MPa(mat.youngs_modulus, mat.poissons_ratio),
                         disc_stress_MPa=None if structural is None else structural.von_mises_MPa,
                         yield_strength_MPa=mat.yield_strength,
                         deformation_mm=deformation, element_size_mm=min(ms.size_flank, ms.size_bore))
    return found + _fatigue_warnings(analysis)


def _fatigue_warnings(analysis) -> tuple[ResultWarning, ...]:
    """The ``fatigue_safety`` warning of the hot spot with the smallest fatigue safety factor, if
    it is below 1 (:mod:`rvfem.evaluate.strength`)."""
    history = getattr(analysis.stress, "history", None)
    if history is None:
        return ()
    assessed = [(f.safety_factor, f) for f in hot_spot_fatigue(history, analysis.case.material)
                if f.safety_factor is not None]
    if not assessed:
        return ()
    factor, worst = min(assessed, key=lambda sf: sf[0])
    if not factor < FATIGUE_SAFETY_LIMIT:
        return ()
    where = f"{worst.name} hot spot at ({worst.peak.x_mm:.2f}, {worst.peak.y_mm:.2f}) mm"
    crit = worst.findley
    detail = ("" if crit is None else f"τ_a = {crit.shear_amplitude_MPa:.0f} MPa, σ_n,max = "
              f"{crit.normal_max_MPa:.0f} MPa on the critical plane, ")
    return (ResultWarning(
        "fatigue_safety",
        f"fatigue safety factor {_sig(factor)} < 1 ({where}; {detail}{FATIGUE_CRITERION}): "
        "the disc does not have infinite life there",
        float(factor), FATIGUE_SAFETY_LIMIT, ""),)


def rigid_warnings(rigid_analysis) -> tuple[ResultWarning, ...]:
    """The warnings of the rigid handbook evaluation (:class:`rvfem.app.analysis.RigidAnalysis`, what
    ``rvfem rigid`` prints): P/C and L10h of every bearing, the duty-cycle service life, the
    Hertz pressures of the rigid rings' most loaded roller and, where the slice model ran, the
    pressure along the roller and κ (:func:`bearing_depth_warnings`, the same code path as the
    run's). Nothing where the handbook is not defined."""
    ratios, lives, pressures = [], [], []
    for b in rigid_analysis.bearings:
        where = f"bearing {b.loads.bearing + 1}, rigid"
        ratios.append((where, b.loads.equivalent_N / rigid_analysis.rating_N))
        lives.append((f"{where} L10h", b.loads.L10h))
        pressures += _hertz_items(f"Stribeck roller of bearing {b.loads.bearing + 1}, rigid", b.hertz_inner,
                                  b.hertz_outer)
    if rigid_analysis.duty_cycle is not None:
        lives.append(("duty-cycle service life, rigid", rigid_analysis.duty_cycle.service_life_h))
    mat = rigid_analysis.case.material
    return check_limits(load_ratios=ratios, lives_h=lives, hertz_MPa=pressures,
                        hertz_limit_MPa=hertz_pressure_limit_MPa(mat.youngs_modulus, mat.poissons_ratio)) + \
        bearing_depth_warnings(b.depth for b in rigid_analysis.bearings if b.depth is not None)


KAPPA_RANGE = (0.1, 4.0)
"""Range of the viscosity ratio κ = ν/ν1 of ISO 281's a_ISO (9.3.2): below 0.1 the formulas are not
defined (the standard leaves such lubrication outside its scope); above 4 a_ISO is evaluated at κ = 4."""


def roller_depth_warnings(depth) -> tuple[ResultWarning, ...]:
    """The warnings of the crank bearing in depth (:class:`rvfem.evaluate.roller_life.CrankBearingDepth`,
    None: none): :func:`bearing_depth_warnings` of its rigid and flexible bearings. (P/C of the
    modified lives above :data:`LOAD_RATIO_LIMIT` is already the ``load_ratio`` warning of the
    basic lives; not repeated.)"""
    if depth is None:
        return ()
    return bearing_depth_warnings(list(depth.rigid) + list(depth.flexible))


def bearing_depth_warnings(items) -> tuple[ResultWarning, ...]:
    """The warnings of slice-model results (:class:`rvfem.evaluate.roller_life.BearingDepth` of any
    bearings and load models; one code path for the rigid and the flexible slice results): for each
    load model (rigid, flexible) whose largest slice pressure along a roller is above
    :data:`HERTZ_PRESSURE_LIMIT_MPA`, one ``roller_pressure`` warning naming the worst bearing of
    that model (the rigid model's is not hidden behind a larger flexible one); κ outside
    :data:`KAPPA_RANGE` (code ``kappa_range``, once: κ is a property of the lubricant and the
    speed, the same for every bearing and model)."""
    items = list(items)
    if not items:
        return ()
    out = []
    for model in dict.fromkeys(d.model for d in items):   # in the order given: rigid, then flexible
        worst = max((d for d in items if d.model == model), key=lambda d: d.roller_peak_pressure_MPa)
        if worst.roller_peak_pressure_MPa > HERTZ_PRESSURE_LIMIT_MPA:
            out.append(ResultWarning(
                "roller_pressure",
                f"pressure along the roller {worst.roller_peak_pressure_MPa:.0f} MPa (bearing {worst.bearing + 1}, "
                f"{worst.model}, {worst.raceway}) > {HERTZ_PRESSURE_LIMIT_MPA:.0f} MPa, the static limit of roller "
                "bearings (ISO 76): the raceway deforms plastically, the slice model and L10r do not hold",
                worst.roller_peak_pressure_MPa, HERTZ_PRESSURE_LIMIT_MPA, "MPa"))
    kappa = items[0].kappa
    low, high = KAPPA_RANGE
    if kappa < low:
        out.append(ResultWarning(
            "kappa_range", f"viscosity ratio κ = {_sig(kappa)} < {low:g}: outside ISO 281's a_ISO; L_nm is "
            f"evaluated at κ = {low:g} and is not meaningful", kappa, low, ""))
    elif kappa > high:
        out.append(ResultWarning(
            "kappa_range", f"viscosity ratio κ = {_sig(kappa)} > {high:g}: ISO 281 evaluates a_ISO at κ = {high:g} "
            "(more viscosity gives no more life)", kappa, high, ""))
    return tuple(out)


def bearing_check_warnings(checks) -> tuple[ResultWarning, ...]:
    """The warnings of :class:`rvfem.evaluate.bearing_checks.BearingChecks` (None: none): the crank
    bearing's static safety S0 below 1 (code ``static_safety``) and its smallest load under the
    minimum-load rule 0.02·C (code ``minimum_load``), the worst model of each."""
    if checks is None:
        return ()
    out = []
    if checks.static:
        model, worst = min(checks.static.items(), key=lambda kv: kv[1].s0)
        if worst.s0 < 1.0:
            out.append(ResultWarning(
                "static_safety", f"static safety S0 = C0/P0 = {_sig(worst.s0)} ({model}, P0 = {worst.p0_N:.0f} N) < 1: "
                "the most loaded roller deforms the raceway permanently (ISO 76's C0; bearing makers ask S0 ≥ 1, "
                "≥ 2 for shock loads or high running accuracy)", worst.s0, 1.0, ""))
    below = [(m, v) for m, v in checks.minimum.items() if v.below]
    if below:
        model, worst = min(below, key=lambda kv: kv[1].fraction_of_C)
        out.append(ResultWarning(
            "minimum_load", f"smallest crank-bearing load {worst.min_load_N:.0f} N = {100 * worst.fraction_of_C:.2f} % "
            f"of C ({model}) < {100 * worst.required_fraction:g} % of C, the bearing makers' minimum load of "
            "cylindrical roller bearings (SKF rule, not ISO): the rollers may skid and smear the raceways",
            100 * worst.fraction_of_C, 100 * worst.required_fraction, "% of C"))
    return tuple(out)
