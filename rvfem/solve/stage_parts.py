"""The parts of a reducer stage whose compliance the stage model holds, listed once.

Each part (:class:`StagePart`) names itself, says in words how the stage model holds it, names the
attribution step that brings it into the model (:mod:`rvfem.evaluate.attribution`) and knows how to
make itself :data:`STIFFEN` times stiffer. The compliance shares
(:func:`rvfem.solve.accuracy.compliance_shares`), the list of components (:data:`COMPONENTS`), the
attribution's chain of steps and the hysteresis study's note on what the model leaves out all
iterate :data:`STAGE_PARTS`; a part added here reaches all four.

A stiffened stage is the stage with the changed fields replaced (:func:`dataclasses.replace`), so a
field of :class:`rvfem.solve.cycle.ReducerStage` that no part touches is carried through unchanged.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from rvfem.case.definition import CrankSupport
from rvfem.fem.crankshaft import crankshaft_influence
from rvfem.solve import models
from rvfem.solve.cycle import DiscSystem, OperatingPoint, ReducerStage, build_system, solve_pair

__all__ = ["COMPONENTS", "STAGE_PARTS", "STIFFEN", "StagePart", "held_in_words", "stage_part", "stiffened_stage"]

STIFFEN = 1.0e3
"""The factor a part is stiffened by to remove its compliance (:func:`stiffened_stage`)."""


@dataclass(frozen=True)
class StagePart:
    """One series compliance of the reducer stage.

    Attributes
    ----------
    name : str
        The part's name in the compliance shares (``"disc body"``).
    held : str
        How the stage model holds the part, in words (a noun phrase of :func:`held_in_words`).
    step : str
        The attribution step that first models the part as compliant (``one_disc`` or
        ``crankshafts``, :data:`rvfem.evaluate.attribution.STEP_LABELS`).
    stiffen : callable
        ``stiffen(stage) → ReducerStage``: the stage with this part :data:`STIFFEN` times stiffer;
        raises ValueError where the stage has no such compliance to remove.
    body : bool
        True for the bodies the other parts connect (named first in :func:`held_in_words`).
    crank : bool
        True for the parts of the crankshaft model (the stage's crankshaft influence matrix), which
        the attribution's step adds only where the case has one.
    """

    name: str
    held: str
    step: str
    stiffen: Callable[[ReducerStage], ReducerStage]
    body: bool = False
    crank: bool = False


def _with_disc_system(stage: ReducerStage, system: DiscSystem) -> ReducerStage:
    """The stage with disc A's model replaced (and disc B's, which is disc A's)."""
    if stage.second is not None and stage.second is not stage.first:
        raise ValueError("stiffening a disc's part needs disc B modelled as disc A (second_disc = 'same_as_first')")
    return dataclasses.replace(stage, first=system, second=None if stage.second is None else system)


def _stiff_pins(stage: ReducerStage) -> ReducerStage:
    """Linear pin springs of STIFFEN × the secant stiffness of the pins' law at the mean pin load
    (the profile's gaps kept)."""
    system = stage.first
    k = STIFFEN * _secant_stiffness(system, "pins", stage)
    return _with_disc_system(stage, dataclasses.replace(system, pin_model="linear", pin_stiffness_N_per_mm=k,
                                                        pins=models.pin_model("linear")(system.case, k),
                                                        contact_sets={}))


def _stiff_disc(stage: ReducerStage) -> ReducerStage:
    """The disc's E × STIFFEN: a new factorisation of the same mesh and models."""
    s = stage.first
    system = build_system(s.case, s.mesh, bearing_model=s.bearing_model, pin_model=s.pin_model,
                          stiffness_scale=STIFFEN * s.stiffness_scale, bearing_stiffness_scale=s.bearing_stiffness_scale,
                          pin_stiffness_N_per_mm=s.pin_stiffness_N_per_mm, geometry=s.geometry)
    return _with_disc_system(stage, system)


def _stiff_rollers(stage: ReducerStage) -> ReducerStage:
    """Linear roller springs of STIFFEN × the secant of the rollers' law at the mean roller load
    (the clearance kept)."""
    system = stage.first
    if system.bearing_model != "rollers":
        raise ValueError("the roller share needs the 'rollers' bearing model")
    k = STIFFEN * _secant_stiffness(system, "rollers", stage)
    case = system.case
    stiff = case.replace(crank_bearing=dataclasses.replace(case.crank_bearing, stiffness_law="linear",
                                                           linear_stiffness_N_per_mm=k))
    return _with_disc_system(stage, dataclasses.replace(system, case=stiff, bearings=models.bearing_model("rollers")(stiff),
                                                        contact_sets={}))


def _beam_support(stage: ReducerStage, name: str) -> CrankSupport:
    cs = stage.first.case.crank_support
    if cs is None or cs.influence_mm_per_N is not None or stage.influence is None:
        raise ValueError(f"the {name} share needs the beam keys of [crank_support]")
    return cs


def _with_support(stage: ReducerStage, cs: CrankSupport) -> ReducerStage:
    # the influence of the changed beam alone (E × 10³ is outside a case's bounds on purpose)
    influence = crankshaft_influence(SimpleNamespace(crank_support=cs))
    assert influence is not None        # the beam keys are there (_beam_support)
    return dataclasses.replace(stage, influence=influence[:stage.discs, :stage.discs])


def _stiff_crankshaft(stage: ReducerStage) -> ReducerStage:
    """The crankshaft beam's E × STIFFEN (bending and shear)."""
    cs = _beam_support(stage, "crankshaft bending/shear")
    return _with_support(stage, dataclasses.replace(cs, youngs_modulus=cs.youngs_modulus * STIFFEN, bending_stiffness_Nmm2=(
        None if cs.bending_stiffness_Nmm2 is None else cs.bending_stiffness_Nmm2 * STIFFEN)))


def _stiff_support(stage: ReducerStage) -> ReducerStage:
    """The support bearings' (and the carrier's) stiffness × STIFFEN."""
    cs = _beam_support(stage, "support bearings")

    def scale(v: float | tuple[float, ...] | None) -> float | tuple[float, ...] | None:
        return None if v is None else (tuple(x * STIFFEN for x in v) if isinstance(v, tuple) else v * STIFFEN)

    return _with_support(stage, dataclasses.replace(cs, support_stiffness_N_per_mm=scale(cs.support_stiffness_N_per_mm),
                                                    carrier_stiffness_N_per_mm=scale(cs.carrier_stiffness_N_per_mm)))


STAGE_PARTS: tuple[StagePart, ...] = (
    StagePart("pin–flank contact", "the pins (Hertz contact at the gaps of the modified profile)", "one_disc",
              _stiff_pins),
    StagePart("disc body", "both discs", "one_disc", _stiff_disc, body=True),
    StagePart("crank-bearing rollers", "the crank-bearing rollers with their clearance", "one_disc", _stiff_rollers),
    StagePart("crankshaft bending/shear", "the crankshafts as beams", "crankshafts", _stiff_crankshaft, crank=True),
    StagePart("support bearings", "their support bearings", "crankshafts", _stiff_support, crank=True),
)
"""The series compliances of the stage, in the order of the load path from the pins to the carrier."""

COMPONENTS = tuple(p.name for p in STAGE_PARTS)
"""The parts' names, in the order of the load path (:data:`STAGE_PARTS`)."""


def stage_part(name: str) -> StagePart:
    """The part of :data:`STAGE_PARTS` called ``name``; ValueError naming the known ones otherwise."""
    for p in STAGE_PARTS:
        if p.name == name:
            return p
    raise ValueError(f"unknown component {name!r}; known: {', '.join(COMPONENTS)}")


def stiffened_stage(stage: ReducerStage, component: str) -> ReducerStage:
    """The stage with one component (:data:`COMPONENTS`) :data:`STIFFEN` times stiffer.

    Pins: linear springs of STIFFEN × the secant stiffness of the Hertz contact at the mean pin load
    (the gaps of the profile kept); disc: E × STIFFEN (a new factorisation); rollers: linear
    springs of STIFFEN × the secant of their law at the mean roller load (clearance kept);
    crankshaft: E × STIFFEN of the beam (bending and shear); support bearings (and carrier):
    stiffness × STIFFEN. The stage shares the disc's factorisation and compliance except for the
    disc body; every other field of the stage is carried through unchanged.
    """
    return stage_part(component).stiffen(stage)


def held_in_words() -> str:
    """What the stage model holds, in words: the bodies first, then the parts that connect them along
    the load path (``"both discs, the pins (…), … and their support bearings"``)."""
    phrases = [p.held for p in STAGE_PARTS if p.body] + [p.held for p in STAGE_PARTS if not p.body]
    return ", ".join(phrases[:-1]) + " and " + phrases[-1]


def _secant_stiffness(system: DiscSystem, which: str, stage: ReducerStage) -> float:
    """Secant stiffness (N/mm) of the pins' or the rollers' law at their mean load at the rated torque:
    a stand-in scale for 'STIFFEN times stiffer'."""
    op = OperatingPoint.of(system.case)
    pair = solve_pair(stage, 0.0, op=op)
    sol = pair.results[0].solution
    zp = system.case.pins.count
    part = slice(0, zp) if which == "pins" else slice(zp, None)
    force, approach = sol.force[part], -sol.gap[part]          # a spring's gap is −its approach
    loaded = (force > 1e-3 * force.max()) & (approach > 0)
    if not loaded.any():
        raise ValueError(f"no loaded {which} to take a secant stiffness from")
    return float(np.sum(force[loaded]) / np.sum(approach[loaded]))
