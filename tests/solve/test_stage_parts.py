"""The stage's components listed once (:mod:`rvfem.solve.stage_parts`): the stage they build is the
one the case's tables describe, a stiffened stage carries every other field of the stage through,
and each part's compliance share is the one an independently built stiffer model gives (the case's
own tables or model options changed, a new model built)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import coarse_case

from rvfem.app.hysteresis import left_out
from rvfem.evaluate.attribution import STEP_LABELS, chain
from rvfem.fem.crankshaft import crankshaft_influence
from rvfem.mesh import mesh_case
from rvfem.solve import cycle
from rvfem.solve.accuracy import compliance_shares, loop_at_torques
from rvfem.solve.stage_carrier import carrier_output_compliance
from rvfem.solve.stage_pin_housing import ring_output_compliance
from rvfem.solve.stage_parts import (
    BUILTIN_COMPONENTS,
    STIFFEN,
    StageComponent,
    component_names,
    register_stage_component,
    stiffened_stage,
)

T_R = 412.0
LINEAR = dict(pins={"model": "linear", "linear_stiffness_N_per_mm": 2e5},
              crank_bearing={"stiffness_law": "linear", "linear_stiffness_N_per_mm": 3e5})


@pytest.fixture(scope="module")
def linear_stage(tmp_path_factory):
    case = coarse_case("rv40e", **LINEAR)
    mesh = mesh_case(case, tmp_path_factory.mktemp("meshes"))
    return cycle.case_stage(cycle.build_system(case, mesh))


@dataclasses.dataclass(frozen=True)
class TaggedStage(cycle.ReducerStage):
    """A stage with one more field, as a new part of the stage would add."""

    tag: str = "untouched"


def _changed(before, after) -> set[str]:
    return {f.name for f in dataclasses.fields(before) if getattr(before, f.name) is not getattr(after, f.name)}


def test_the_components_build_the_stage_the_cases_tables_describe(linear_stage):
    """Both discs on one carrier (disc B as disc A) on the crankshaft influence of [crank_support],
    with the series output compliances of the housing ring, the carrier and the main bearings (zero)
    of their tables' defaults: the stage built directly from the case's keys. (Linear pins: the pins'
    seats are not added to a given pin stiffness, so disc A's model is the system itself.)"""
    system = linear_stage.first
    direct = cycle.build_stage(system, discs=2, influence=crankshaft_influence(system.case))
    assert linear_stage.second is linear_stage.first is direct.first
    np.testing.assert_array_equal(linear_stage.influence, direct.influence)
    case = system.case
    assert (linear_stage.second_phase, direct.second_phase, direct.output_compliances) == (0.0, 0.0, ())
    assert linear_stage.output_compliances == (
        ("pin_housing", ring_output_compliance(case, case.component_table("pin_housing"))),
        ("carrier", carrier_output_compliance(case, case.component_table("carrier"))),
        ("main_bearings", 0.0))
    for name, c in linear_stage.output_compliances:
        direct = direct.with_output_compliance(name, c)
    assert linear_stage.describe() == direct.describe()


@pytest.mark.parametrize("part", BUILTIN_COMPONENTS, ids=lambda p: p.name)
def test_stiffening_a_part_carries_every_other_field_of_the_stage_through(linear_stage, part):
    stage = TaggedStage(**{f.name: getattr(linear_stage, f.name) for f in dataclasses.fields(linear_stage)},
                        tag="carrier spring").with_output_compliance("a spring", 1e-9)
    stiff = stiffened_stage(stage, part.name)
    assert type(stiff) is TaggedStage and stiff.tag == "carrier spring"
    own = dict(stage.output_compliances)
    if part.name in own and own[part.name] > 0:          # a series part: its own compliance / STIFFEN
        own[part.name] /= STIFFEN
    assert stiff.output_compliances == tuple(own.items()) and ("a spring", 1e-9) in stiff.output_compliances
    # a disc's part changes the disc model (disc B is disc A), a crankshaft part the influence matrix,
    # a series part its output compliance (the pins' seats are not added to linear pins); the main
    # bearings pass no torque and have nothing to stiffen
    expected = ({"influence"} if part.step == "crankshafts" else
                {"output_compliances"} if part.name in ("pin_housing", "carrier") else
                set() if part.name == "main_bearings" else {"first", "second"})
    assert _changed(stage, stiff) == expected
    assert stiff.second is stiff.first


def _rotation_arcmin(stage) -> float:
    r, _, _ = loop_at_torques(stage, 0.0, np.array([T_R, 0.03 * T_R]), 0.0, np.ones(2, dtype=int))
    return float(r[0] - r[1]) * 180.0 * 60.0 / np.pi


def test_compliance_shares_equal_those_of_independently_built_stiffer_models(linear_stage, tmp_path):
    """Each share (a − a_stiff)/a against a stiff model built from the case's own keys: the disc's
    E × STIFFEN through ``stiffness_scale``, linear pins and rollers of STIFFEN × their stiffness
    (the secant of a linear spring without a gap is its stiffness), the support bearings' and the
    carrier's stiffness × STIFFEN in ``[crank_support]``."""
    shares = compliance_shares(linear_stage, 0.0, T_R)
    assert tuple(shares.shares) == component_names() == tuple(p.name for p in BUILTIN_COMPONENTS)
    a = _rotation_arcmin(linear_stage)
    assert shares.rotation_arcmin == pytest.approx(a, rel=1e-12)
    case, mesh = linear_stage.first.case, linear_stage.first.mesh
    cs = case.crank_support

    def stiff(changes=None, **options):
        c = case if changes is None else case.replace(**changes)
        return cycle.case_stage(cycle.build_system(c, mesh, **options))

    scale = (lambda v: None if v is None else (v * STIFFEN if np.isscalar(v) else tuple(x * STIFFEN for x in v)))
    independent = {
        "disc body": stiff(stiffness_scale=STIFFEN),
        "pin–flank contact": stiff(pin_stiffness_N_per_mm=STIFFEN * 2e5),
        "crank-bearing rollers": stiff(dict(crank_bearing=dataclasses.replace(
            case.crank_bearing, linear_stiffness_N_per_mm=STIFFEN * 3e5))),
        "support bearings": stiff(dict(crank_support=dataclasses.replace(
            cs, support_stiffness_N_per_mm=scale(cs.support_stiffness_N_per_mm),
            carrier_stiffness_N_per_mm=scale(cs.carrier_stiffness_N_per_mm)))),
    }
    for name, stage in independent.items():
        assert shares.shares[name] == pytest.approx((a - _rotation_arcmin(stage)) / a, rel=1e-6), name


def test_the_parts_are_what_the_left_out_note_and_the_attribution_name():
    assert left_out().startswith("The stage model holds both discs, the pins (Hertz contact at the gaps of the "
                                 "modified profile), the crank-bearing rollers with their clearance, the "
                                 "crankshafts as beams, their support bearings, the pins' seats in their housing "
                                 "grooves (Hertz, in series with each pin) and the housing ring, the carrier's "
                                 "pillars between its end plates and the main bearings (which pass no torque). It "
                                 "leaves out the input spur stage")
    assert {p.step for p in BUILTIN_COMPONENTS} - {None} <= set(STEP_LABELS)
    with pytest.raises(ValueError, match="unknown component 'a carrier'; known: pin–flank contact"):
        stiffened_stage(None, "a carrier")


class _Housing(StageComponent):
    """A component that brings in a part left out and an attribution step of its own (no table)."""

    name = "pin housing"
    held = "the pin housing"
    step = "housing"
    step_label = "with the pin housing"
    models = ("pin housing",)


def test_a_registered_component_reaches_the_words_and_the_attribution_chain(registries, linear_stage):
    register_stage_component(_Housing())
    words = left_out()
    assert "the main bearings (which pass no torque) and the pin housing. It leaves out the input spur stage" in words
    assert chain(linear_stage.first.case) == ["one_disc", "two_discs", "crankshafts", "housing"]
    with pytest.raises(ValueError, match="'pin housing' is registered already"):
        register_stage_component(type("Other", (_Housing,), {})())
    with pytest.raises(ValueError, match="brings in carrier, which are not among the parts left out"):
        register_stage_component(type("Carrier", (StageComponent,), {"name": "c", "held": "c", "models": ("carrier",)})())
