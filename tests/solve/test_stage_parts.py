"""The stage's parts listed once (:mod:`rvfem.solve.stage_parts`): a stiffened stage carries every
other field of the stage through, and each part's compliance share is the one an independently
built stiffer model gives (the case's own tables or model options changed, a new model built)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import coarse_case

from rvfem.app.hysteresis import LEFT_OUT
from rvfem.evaluate.attribution import STEP_LABELS
from rvfem.mesh import mesh_case
from rvfem.solve import cycle
from rvfem.solve.accuracy import COMPONENTS, compliance_shares, loop_at_torques
from rvfem.solve.stage_parts import STAGE_PARTS, STIFFEN, stiffened_stage

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


@pytest.mark.parametrize("part", STAGE_PARTS, ids=lambda p: p.name)
def test_stiffening_a_part_carries_every_other_field_of_the_stage_through(linear_stage, part):
    stage = TaggedStage(**{f.name: getattr(linear_stage, f.name) for f in dataclasses.fields(linear_stage)},
                        tag="carrier spring")
    stiff = stiffened_stage(stage, part.name)
    assert type(stiff) is TaggedStage and stiff.tag == "carrier spring"
    # a disc's part changes the disc model (disc B is disc A), a crankshaft part the influence matrix
    assert _changed(stage, stiff) == ({"influence"} if part.crank else {"first", "second"})
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
    assert tuple(shares.shares) == COMPONENTS == tuple(p.name for p in STAGE_PARTS)
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
    assert LEFT_OUT.startswith("The stage model holds both discs, the pins (Hertz contact at the gaps of the "
                               "modified profile), the crank-bearing rollers with their clearance, the "
                               "crankshafts as beams and their support bearings. It leaves out")
    assert {p.step for p in STAGE_PARTS} <= set(STEP_LABELS)
    with pytest.raises(ValueError, match="unknown component 'carrier'; known: pin–flank contact"):
        stiffened_stage(None, "carrier")
