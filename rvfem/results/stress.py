"""The disc stresses: the structural peak (P2 re-solved), the P1 envelope away from contacts, the
contact-zone peak, the kept field angles and the hot spots' histories."""

from __future__ import annotations

import math
from typing import Any

from rvfem.evaluate import postprocess
from rvfem.results.analysis import StressResult

from rvfem.results.format import angle, peak_dict

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'compute', 'summary']

def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    s = a.stress
    away, rec = s.away_from_contacts, s.recovered
    structural = s.structural
    return {
        "peak_von_mises_MPa": None if structural is None else structural.von_mises_MPa,
        "peak_von_mises_at": None if structural is None else peak_dict(structural),
        "stress": {
            "structural_peak": None if rec is None else {
                "von_mises_MPa": rec.peak.von_mises_MPa,
                "at": peak_dict(rec.peak),
                "method": rec.method,
                "element_order": 2,
                "estimated_error_MPa": rec.estimated_error_MPa,
                "estimated_error_percent": rec.estimated_error_percent,
                "p1_MPa": rec.p1_MPa,
                "p1_at_peak_MPa": rec.p1_at_peak_MPa,
                "p1_error_percent": rec.p1_error_percent,
                "angles_deg": [angle(x) for x in rec.angles_deg],
                "seconds": rec.seconds,
            },
            "away_from_contacts": None if away is None else {
                "peak_von_mises_MPa": away.von_mises_MPa,
                "element_order": a.system.model.order,
                "at": peak_dict(away),
                "profile_band_mm": s.band_mm["profile"],
                "bore_band_mm": s.band_mm.get("bore_0"),
            },
            "contact_zone": {
                "peak_von_mises_MPa": s.peak.von_mises_MPa,
                "at": peak_dict(s.peak),
                "mesh_dependent": True,
            },
            "field_angles_deg": [angle(snap.theta_deg) for snap in s.snapshots],
            "hot_spots": [] if s.history is None else [_hot_spot_dict(s.history, j)
                                                       for j in range(len(s.history.names))],
        },
    }


def _hot_spot_dict(h: Any, j: int) -> dict[str, Any]:
    vm, sd = h.von_mises[:, j], h.dominant[:, j]
    return {
        "name": h.names[j],
        "at": peak_dict(h.peaks[j]),
        "von_mises_max_MPa": float(vm.max()),
        "von_mises_min_MPa": float(vm.min()),
        "dominant_principal_max_MPa": float(sd.max()),
        "dominant_principal_min_MPa": float(sd.min()),
        "dominant_principal_range_MPa": float(sd.max() - sd.min()),
        "dominant_principal_mean_MPa": float(0.5 * (sd.max() + sd.min())),
        "p2_factor": h.p2_factor[j],
    }


def compute(inputs: Any) -> StressResult:
    """The disc stresses of the cycle: the structural peak re-solved on P2 where ``inputs["p2"]``
    (``recover(system, cycle, mesh, band, away) -> RecoveredPeak``, the analysis's executor choice:
    a child process or this one) is given, and the hot spots' histories over the cycle."""
    system, cycle, mesh = inputs["system"], inputs["cycle"], inputs["mesh"]
    env = inputs["stress_envelope"]
    peak, away, band, snapshots = env.peak, env.away_from_contacts, env.band_mm, env.snapshots
    recovered = None
    if inputs["p2"] is not None and away is not None:
        recovered = inputs["p2"](system, cycle, mesh, band, away)
        if not any(math.isclose(s.theta_deg, recovered.peak.theta_deg, abs_tol=1e-9) for s in snapshots):
            snapshots = postprocess.field_snapshots(system, cycle, extra_angles=[
                math.radians(x) for x in (peak.theta_deg, away.theta_deg, recovered.peak.theta_deg)])
    spots = {"structural": recovered.peak if recovered is not None else away, "contact_zone": peak}
    spots = {k: v for k, v in spots.items() if v is not None}
    factors = {}
    if recovered is not None and recovered.p1_at_peak_MPa > 0:
        factors["structural"] = recovered.peak.von_mises_MPa / recovered.p1_at_peak_MPa
    history = postprocess.hot_spot_history(system, cycle, spots, factors)
    return StressResult(peak=peak, away_from_contacts=away, band_mm=band, snapshots=snapshots,
                        recovered=recovered, history=history)


KEYS = (
    KeyRow('`peak_von_mises_MPa`',
           'float or null',
           "**the structural stress peak away from contacts**: `stress.structural_peak.von_mises_MPa` (P2 re-solve), or the P1 envelope's `stress.away_from_contacts` value when the re-solve was not done"),
    KeyRow('`peak_von_mises_at`',
           'object or null',
           'where it is (keys below)'),
    KeyRow('`peak_von_mises_at`, `stress.structural_peak.at`, `stress.away_from_contacts.at`, `stress.contact_zone.at`, `stress.hot_spots[].at`',
           'object',
           'where a stress peak is'),
    KeyRow('&nbsp;&nbsp;`.x_mm`, `.y_mm`, `.radius_mm`',
           'float',
           'position in the disc frame and distance from the disc centre'),
    KeyRow('&nbsp;&nbsp;`.theta_deg`',
           'float',
           'crank angle'),
    KeyRow('&nbsp;&nbsp;`.feature`, `.feature_label`',
           'str',
           'nearest mesh boundary, numbered from 1 (`profile`, `bore_1`…, `hole_1`…, `central_hole`) and the same in words, as everything rvfem prints names it (`bore 1`, `hole 1`, `tooth profile`, `central hole`)'),
    KeyRow('&nbsp;&nbsp;`.distance_to_feature_mm`',
           'float',
           'distance to that boundary'),
    KeyRow('`stress`',
           'object',
           'more on the disc stresses'),
    KeyRow('`stress.structural_peak`',
           'object or null',
           'the structural peak re-solved on P2 (see "The structural stress peak" below); null if no vertex lies outside the contact bands'),
    KeyRow('`stress.structural_peak.von_mises_MPa`',
           'float',
           'its value (P2 vertex von Mises, area-averaged element values)'),
    KeyRow('`stress.structural_peak.method`, `stress.structural_peak.element_order`',
           'str, int',
           'the method in words; 2'),
    KeyRow('`stress.structural_peak.estimated_error_MPa`, `stress.structural_peak.estimated_error_percent`',
           'float',
           'estimated error: the largest difference between the P2 element stresses at the peak vertex and their average (von Mises)'),
    KeyRow('`stress.structural_peak.p1_MPa`, `stress.structural_peak.p1_at_peak_MPa`, `stress.structural_peak.p1_error_percent`',
           'float',
           "the P1 cycle's structural peak, the P1 value at the same vertex and angle, and (P1 − P2)/P2 in % (null/NaN for a P2 case)"),
    KeyRow('`stress.structural_peak.angles_deg`, `stress.structural_peak.seconds`',
           'array, float',
           'crank angles re-solved on P2 and the wall time of the re-solve (P2 assembly and factorisation included)'),
    KeyRow('`stress.away_from_contacts`',
           'object or null',
           "the structural peak of the cycle's own stress envelope (spokes, ligaments, hole fillets) over every solved angle, ignoring a band along the tooth profile and the bores (6 element sizes)"),
    KeyRow('`stress.away_from_contacts.peak_von_mises_MPa`, `stress.away_from_contacts.element_order`',
           'float, int',
           'its value and the element order of the cycle'),
    KeyRow('`stress.away_from_contacts.profile_band_mm`, `stress.away_from_contacts.bore_band_mm`',
           'float',
           'widths of the ignored bands'),
    KeyRow('`stress.contact_zone`',
           'object',
           'the largest vertex von Mises over every solved crank angle, anywhere: in practice right under a pin or roller footprint; it depends on the footprint width and the mesh and is not a Hertz stress'),
    KeyRow('`stress.contact_zone.peak_von_mises_MPa`, `stress.contact_zone.mesh_dependent`',
           'float, bool',
           'its value; always true'),
    KeyRow('`stress.field_angles_deg`',
           'array',
           'crank angles of the kept fields (saved angles, the angle of the largest bearing load, the angles of the stress peaks, `--field-step`)'),
    KeyRow('`stress.hot_spots[]`',
           'array',
           "stress over every solved crank angle at the hot spots, for a fatigue check (the full history is `stress_history.csv`): `structural` (the structural peak's vertex) and `contact_zone`"),
    KeyRow('`stress.hot_spots[].name`, `stress.hot_spots[].at`',
           'str, object',
           'which hot spot and where (keys as `peak_von_mises_at`)'),
    KeyRow('`stress.hot_spots[].von_mises_max_MPa`, `stress.hot_spots[].von_mises_min_MPa`',
           'float',
           "von Mises over the cycle, the cycle's element order"),
    KeyRow('`stress.hot_spots[].dominant_principal_max_MPa`, `stress.hot_spots[].dominant_principal_min_MPa`, `stress.hot_spots[].dominant_principal_range_MPa`, `stress.hot_spots[].dominant_principal_mean_MPa`',
           'float',
           'the in-plane principal stress of larger magnitude (signed; at a free edge the tangential stress): largest, smallest, range and mean (max + min)/2 over the cycle'),
    KeyRow('`stress.hot_spots[].p2_factor`',
           'float',
           "P2/P1 von Mises at the hot spot at the recovery's angle (1 if not re-solved): the P1 history times it estimates the P2 values (both are in `stress_history.csv`)"),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("stress", summary, KEYS, requires=("system", "cycle", "mesh", "stress_envelope", "p2"),
                  compute=compute, stage="stress",
                  screen=lambda s: ["", *screen_lines.stress_lines(s["stress"])], screen_rank=30)
