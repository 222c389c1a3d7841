"""The reducer stage as registered components: each part of the stage is one component, listed in one
explicit table.

A component (:class:`StageComponent`) is one series compliance of the stage. It declares

* its ``name`` (its key in the compliance shares) and the case table it owns, with that table's
  keys (``table`` and ``schema``: a dataclass of :mod:`rvfem.case.tables`, or the schema of a table
  it brings into the case format; the ``_parameters`` of a solver class in sfepy's
  ``solvers/nls.py``);
* how it builds its part of the stage from the case (:meth:`StageComponent.build`, applied by
  :func:`case_stage`) and whether the case has it at all (:meth:`StageComponent.present`);
* how it makes itself :data:`STIFFEN` times stiffer (:meth:`StageComponent.stiffen`), for the
  compliance shares (:func:`rvfem.solve.accuracy.compliance_shares`);
* the attribution step that first models it (``step``, :mod:`rvfem.evaluate.attribution`;
  ``step_label`` names a step of its own), and in words what the stage model holds of it
  (``held``) and which of the parts the stage model leaves out it brings in (``models``, keys of
  :data:`NOT_MODELLED`).

The built-in components are listed in :data:`BUILTIN_COMPONENTS`, in the order of the load path from
the pins to the carrier (as meshio lists its formats); a component written elsewhere (a notebook,
a test module, a module of its own) is added after them with one line,
``register_stage_component(MyComponent())``, which also adds its table to the case format
(:func:`rvfem.case.definition.register_component_table`). :func:`stage_components` is the table the
compliance shares, the attribution, :func:`case_stage` and the words of ``rvfem hysteresis``
iterate.

A component changes the stage only through :func:`dataclasses.replace` (or a method of
:class:`~rvfem.solve.cycle_stage.ReducerStage` that uses it), so a field of the stage that it does not
touch — another component's part included — is carried through unchanged. A part that acts in
series with the whole stage in the output's load path (a carrier's torsion, a spring to the
ground) adds a series output compliance (:meth:`~rvfem.solve.cycle_stage.ReducerStage.with_output_compliance`),
which the hysteresis loop, the rigidity, the lost motion and the TE see in the output rotation
(:attr:`~rvfem.solve.cycle_stage.PairResult.output_rotation`).
"""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np

from rvfem.case.definition import (
    Case,
    CrankBearing,
    CrankSupport,
    Material,
    Pins,
    register_component_table,
    unregister_component_table,
)
from rvfem.errors import CaseError
from rvfem.fem.crankshaft import crankshaft_influence
from rvfem.solve import models
from rvfem.solve.cycle_stage import ReducerStage, build_stage, solve_pair
from rvfem.solve.cycle_system import DiscSystem, OperatingPoint, scaled_system
from rvfem.solve.stage_carrier import Carrier
from rvfem.solve.stage_component import STIFFEN, StageComponent
from rvfem.solve.stage_main_bearings import MainBearings
from rvfem.solve.stage_pin_housing import PinHousing

__all__ = [
    "BUILTIN_COMPONENTS",
    "NOT_MODELLED",
    "STIFFEN",
    "StageComponent",
    "build_components",
    "case_stage",
    "component_names",
    "held_in_words",
    "not_modelled",
    "register_stage_component",
    "stage_component",
    "stage_components",
    "stiffened_stage",
    "unregister_stage_component",
]

# ------------------------------------------------------------------------------------------------
# The built-in components
# ------------------------------------------------------------------------------------------------


def _with_disc_system(stage: ReducerStage, system: DiscSystem) -> ReducerStage:
    """The stage with disc A's model replaced (and disc B's, which is disc A's)."""
    if stage.second is not None and stage.second is not stage.first:
        raise ValueError("stiffening a disc's part needs disc B modelled as disc A (second_disc = 'same_as_first')")
    return dataclasses.replace(stage, first=system, second=None if stage.second is None else system)


class PinFlankContact(StageComponent):
    """The pins against the disc's flanks: the pin law of ``[pins]`` at the gaps of the modified
    profile, built with the disc's model."""

    name = "pin–flank contact"
    table, schema = "pins", Pins
    held = "the pins (Hertz contact at the gaps of the modified profile)"
    step = "one_disc"

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        """Linear pin springs of STIFFEN × the secant stiffness of the pins' law at the mean pin load
        (the profile's gaps kept)."""
        system = stage.first
        k = STIFFEN * _secant_stiffness(system, "pins", stage)
        return _with_disc_system(stage, dataclasses.replace(system, pin_model="linear", pin_stiffness_N_per_mm=k,
                                                            pins=models.pin_model("linear")(system.case, k),
                                                            contact_sets={}))


class DiscBody(StageComponent):
    """The disc's elastic body (its material, ``[material]``, on its mesh), built with the disc's
    model."""

    name = "disc body"
    table, schema = "material", Material
    held = "both discs"
    step = "one_disc"
    body = True

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        """The disc's E × STIFFEN: the same factorisation and compliance columns divided by STIFFEN
        (:func:`rvfem.solve.cycle_system.scaled_system`, exact for linear elasticity)."""
        return _with_disc_system(stage, scaled_system(stage.first, STIFFEN))


class CrankBearingRollers(StageComponent):
    """The crank bearings' rollers with their clearance (``[crank_bearing]``), built with the disc's
    model."""

    name = "crank-bearing rollers"
    table, schema = "crank_bearing", CrankBearing
    held = "the crank-bearing rollers with their clearance"
    step = "one_disc"

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        """Linear roller springs of STIFFEN × the secant of the rollers' law at the mean roller load
        (the clearance kept)."""
        system = stage.first
        if system.bearing_model != "rollers":
            raise ValueError("the roller share needs the 'rollers' bearing model")
        k = STIFFEN * _secant_stiffness(system, "rollers", stage)
        case = system.case
        stiff = case.replace(crank_bearing=dataclasses.replace(case.crank_bearing, stiffness_law="linear",
                                                               linear_stiffness_N_per_mm=k))
        return _with_disc_system(stage, dataclasses.replace(system, case=stiff,
                                                            bearings=models.bearing_model("rollers")(stiff),
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


class Crankshafts(StageComponent):
    """The crankshafts as beams on their support bearings (``[crank_support]``): the stage's
    crankshaft influence matrix (:func:`rvfem.fem.crankshaft.crankshaft_influence`, which holds the
    support bearings' compliance too)."""

    name = "crankshaft bending/shear"
    table, schema = "crank_support", CrankSupport
    held = "the crankshafts as beams"
    step = "crankshafts"

    def build(self, stage: ReducerStage) -> ReducerStage:
        """The stage on the crankshafts of ``[crank_support]`` (the influence matrix of the discs it
        has), except for one disc carrying T/discs with ``loads.torque_split = "equal"``: the
        handbook's model, on rigid eccentrics."""
        case = stage.first.case
        if stage.discs == 1 and case.loads.discs > 1 and case.loads.torque_split == "equal":
            return stage
        influence = crankshaft_influence(case)
        if influence is None:
            return stage
        f = np.asarray(influence, dtype=float)
        if stage.discs == 2 and f.shape != (2, 2):
            raise CaseError("the crankshaft influence matrix of two discs must be 2×2")
        return dataclasses.replace(stage, influence=f[:stage.discs, :stage.discs])

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        """The crankshaft beam's E × STIFFEN (bending and shear)."""
        cs = _beam_support(stage, self.name)
        return _with_support(stage, dataclasses.replace(cs, youngs_modulus=cs.youngs_modulus * STIFFEN,
                                                        bending_stiffness_Nmm2=(None if cs.bending_stiffness_Nmm2 is None
                                                                                else cs.bending_stiffness_Nmm2 * STIFFEN)))


class SupportBearings(StageComponent):
    """The crankshafts' support bearings (and the carrier's seats of them), ``[crank_support]``:
    the supports of the crankshaft beam, built into its influence matrix by :class:`Crankshafts`."""

    name = "support bearings"
    table, schema = "crank_support", CrankSupport
    held = "their support bearings"
    step = "crankshafts"

    def build(self, stage: ReducerStage) -> ReducerStage:
        """The support bearings' radial clearance (``crank_support.radial_clearance``): each
        crankshaft's radial play in them, half the clearance, as the stage's eccentric play
        (:attr:`~rvfem.solve.cycle_stage.ReducerStage.eccentric_play_mm`; their stiffness is in the
        crankshaft influence matrix, :class:`Crankshafts`). Not for one disc carrying T/discs with
        ``loads.torque_split = "equal"`` (the handbook's model, on rigid eccentrics)."""
        case = stage.first.case
        cs = case.crank_support
        if cs is None or cs.radial_clearance == 0.0:
            return stage
        if stage.discs == 1 and case.loads.discs > 1 and case.loads.torque_split == "equal":
            return stage
        if stage.first.bearing_model != "rollers":
            raise CaseError("crank_support.radial_clearance needs the 'rollers' crank-bearing model (the "
                            "'rigid_bore' bore has no clearance to add it to): set crank_bearing.model = \"rollers\" "
                            "or crank_support.radial_clearance = 0")
        return dataclasses.replace(stage, eccentric_play_mm=0.5 * float(cs.radial_clearance))

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        """The support bearings' (and the carrier's) stiffness × STIFFEN (their clearance kept)."""
        cs = _beam_support(stage, self.name)

        def scale(v: float | tuple[float, ...] | None) -> float | tuple[float, ...] | None:
            return None if v is None else (tuple(x * STIFFEN for x in v) if isinstance(v, tuple) else v * STIFFEN)

        return _with_support(stage, dataclasses.replace(cs, support_stiffness_N_per_mm=scale(cs.support_stiffness_N_per_mm),
                                                        carrier_stiffness_N_per_mm=scale(cs.carrier_stiffness_N_per_mm)))


BUILTIN_COMPONENTS: tuple[StageComponent, ...] = (
    PinFlankContact(),
    DiscBody(),
    CrankBearingRollers(),
    Crankshafts(),
    SupportBearings(),
    PinHousing(),
    Carrier(),
    MainBearings(),
)
"""The stage's built-in components, in the order of the load path from the pins to the carrier: the
one place they are listed."""

_REGISTERED: dict[str, StageComponent] = {}
"""The components registered since (:func:`register_stage_component`), in the order registered."""


NOT_MODELLED: tuple[tuple[str, str], ...] = (
    ("main bearings", "the main (output) bearings"),
    ("carrier end plates", "the carrier's end plates and pins (the carrier is rigid)"),
    ("pin housing", "the pin housing (the pins' seats are rigid)"),
    ("input spur stage", "the input spur stage (with the input locked the crankshafts do not turn relative to "
                         "the carrier)"),
    ("pin rotation", "the rotation of the pins in their grooves"),
)
"""The parts of the reducer the built-in stage model leaves out, as (short name, words); a component
that brings one in names its short name in ``models``."""


def register_stage_component(component: StageComponent) -> StageComponent:
    """Add ``component`` to the stage's components, after the built-in ones (and its table, if it
    brings one, to the case format: :func:`rvfem.case.definition.register_component_table`).
    Returns it.

    Raises
    ------
    ValueError
        Its name is another component's, or its table cannot be registered.
    TypeError
        It is not a :class:`StageComponent`.
    """
    if not isinstance(component, StageComponent):
        raise TypeError(f"a stage component must be a StageComponent, got {component!r}")
    name = getattr(component, "name", None)
    if not isinstance(name, str) or not name:
        raise ValueError(f"a stage component needs a name, got {name!r}")
    if name in {c.name for c in BUILTIN_COMPONENTS} or (name in _REGISTERED and _REGISTERED[name] is not component):
        raise ValueError(f"a stage component called {name!r} is registered already")
    unknown = set(component.models) - {key for key, _ in NOT_MODELLED}
    if unknown:
        raise ValueError(f"the component {name!r} brings in {', '.join(sorted(unknown))}, which are not among the "
                         f"parts left out ({', '.join(key for key, _ in NOT_MODELLED)})")
    table = component.table
    if table is not None and table not in {f.name for f in dataclasses.fields(Case)}:
        if component.schema is None:
            raise ValueError(f"the component {name!r} owns the table {table!r} but declares no schema for it")
        register_component_table(table, component.schema, by_default=component.table_by_default, owner=name)
    _REGISTERED[name] = component
    return component


def unregister_stage_component(name: str) -> None:
    """Remove the registered component ``name`` (and its table); a built-in component cannot be
    removed, an unknown name is ignored."""
    if name in {c.name for c in BUILTIN_COMPONENTS}:
        raise ValueError(f"the built-in stage component {name!r} cannot be unregistered")
    component = _REGISTERED.pop(name, None)
    if component is not None and component.table is not None:
        unregister_component_table(component.table)


def stage_components() -> tuple[StageComponent, ...]:
    """The stage's components: the built-in ones (:data:`BUILTIN_COMPONENTS`), then those registered
    since, in the order registered."""
    return BUILTIN_COMPONENTS + tuple(_REGISTERED.values())


def component_names() -> tuple[str, ...]:
    """The components' names, in the order of :func:`stage_components`."""
    return tuple(c.name for c in stage_components())


def stage_component(name: str) -> StageComponent:
    """The component called ``name``; ValueError naming the known ones otherwise."""
    for c in stage_components():
        if c.name == name:
            return c
    raise ValueError(f"unknown component {name!r}; known: {', '.join(component_names())}")


def stiffened_stage(stage: ReducerStage, component: str) -> ReducerStage:
    """The stage with one component (:func:`component_names`) :data:`STIFFEN` times stiffer
    (:meth:`StageComponent.stiffen`).

    Pins: linear springs of STIFFEN × the secant stiffness of the Hertz contact at the mean pin load
    (the gaps of the profile kept); disc: E × STIFFEN (a new factorisation); rollers: linear
    springs of STIFFEN × the secant of their law at the mean roller load (clearance kept);
    crankshaft: E × STIFFEN of the beam (bending and shear); support bearings (and carrier):
    stiffness × STIFFEN; a registered component as it says. The stage shares the disc's
    factorisation and compliance except for the disc body; every other field of the stage is
    carried through unchanged.
    """
    stiff = stage_component(component).stiffen(stage)
    for c in stage_components():
        if c.name != component:
            stiff = c.carry(stage, stiff)
    return stiff


def build_components(stage: ReducerStage, steps: tuple[str, ...] | None = None) -> ReducerStage:
    """``stage`` with the part of every component its case has (:meth:`StageComponent.present`)
    built in, in the order of :func:`stage_components`; only the components first modelled at one
    of ``steps`` (attribution step keys) if given — those without a step are then left out."""
    case = stage.first.case
    for c in stage_components():
        if c.present(case) and (steps is None or c.step in steps):
            stage = c.build(stage)
    return stage


def case_stage(system: DiscSystem, second: DiscSystem | None = None, second_disc: str = "same_as_first") -> ReducerStage:
    """The reducer stage the case asks for: both discs on one carrier for ``loads.discs = 2`` or,
    with ``loads.torque_split = "equal"`` or one disc, one disc carrying T_out/discs, with the part
    of every component the case has built in (:func:`build_components`): the crankshafts of
    ``[crank_support]`` (rigid eccentrics without it, and for the equal split, rvfem 0.1's and the
    handbook's model) and whatever the registered components add. ``second``, ``second_disc`` as
    in :func:`rvfem.solve.cycle_stage.build_stage`."""
    case = system.case
    equal_split = case.loads.discs > 1 and case.loads.torque_split == "equal"
    discs = 1 if equal_split or case.loads.discs == 1 else 2
    stage = build_stage(system, discs=discs, influence=None, second=second, second_disc=second_disc)
    return build_components(stage)


def held_in_words() -> str:
    """What the stage model holds, in words: the bodies first, then the parts that connect them along
    the load path (``"both discs, the pins (…), … and their support bearings"``)."""
    components = stage_components()
    phrases = [c.held for c in components if c.body] + [c.held for c in components if not c.body]
    return ", ".join(phrases[:-1]) + " and " + phrases[-1]


def not_modelled() -> tuple[tuple[str, str], ...]:
    """The parts of :data:`NOT_MODELLED` that no component brings in, as (short name, words)."""
    brought = {key for c in stage_components() for key in c.models}
    return tuple((key, words) for key, words in NOT_MODELLED if key not in brought)


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
