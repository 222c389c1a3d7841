"""What a run hands the analyst for a check of their own, and where its time goes.

* ``stress_history.csv`` carries the fatigue check's inputs: the P2-consistent columns are the
  load cycle's columns times the hot spot's ``p2_factor`` of ``summary.json``, and the Goodman line
  (Shigley, *Mechanical Engineering Design*, eq. 6-41) through the amplitude and mean of their
  signed von Mises stress (FKM guideline) gives the summary's fatigue safety factors.
* Every stage of a run is reported (start, steps, end) and the stages are spans of the run's wall
  time one after the other: ``total = Σ stages + other``, with ``other`` small and the total the
  wall time measured around the run.
* The slice solver's answer satisfies the contact conditions (an invariant, not a printed value)
  for contacts whose active sets are solved by either of its two systems.
"""

from __future__ import annotations

import csv
import io
import math
import re
import time

import numpy as np
import pytest
from conftest import coarse_case

from rvfem.app import cli
from rvfem.app.run import STAGES, outside_stages, run_case, run_stages, summary_text
from rvfem.evaluate import roller_slices


@pytest.fixture(scope="module")
def timed_run(tmp_path_factory):
    """A coarse run of the default case without images, every progress call recorded with its
    time, and the wall time measured around it."""
    case = coarse_case("rv40e_fanholes", analysis={"angle_step_deg": 30.0, "saved_angles_deg": [0.0]})
    folder = tmp_path_factory.mktemp("fatigue")
    calls = []

    def progress(stage, done, total):
        calls.append((time.perf_counter(), stage, done, total))

    t0 = time.perf_counter()
    result = run_case(case, folder / "out", images=False, progress=progress, cache_dir=folder / "meshes")
    wall = time.perf_counter() - t0
    return result, calls, wall


def _columns(path) -> dict[str, np.ndarray]:
    with path.open(newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


# --------------------------------------------------------------------------------------------
# stress_history.csv: the fatigue check's inputs
# --------------------------------------------------------------------------------------------


def test_stress_history_holds_the_p2_consistent_stresses_the_fatigue_check_uses(timed_run):
    result, _, _ = timed_run
    summary = result.summary
    col = _columns(result.out_dir / "stress_history.csv")
    assert col["theta_deg"] == pytest.approx(np.arange(0.0, 360.0, 30.0))
    spots = {h["name"]: h for h in summary["stress"]["hot_spots"]}
    fatigue = {f["name"]: f for f in summary["mass_strength"]["fatigue_hot_spots"]}
    sigma_w = summary["mass_strength"]["fatigue_limit_MPa"]
    r_m = summary["mass_strength"]["ultimate_strength_MPa"]
    assert set(spots) == {"structural", "contact_zone"} == set(fatigue)
    # the structural peak is re-solved on P2 and P1 is low there: the factor is a real correction
    assert spots["structural"]["p2_factor"] > 1.02
    factors = []
    for name, spot in spots.items():
        f = spot["p2_factor"]
        np.testing.assert_allclose(col[f"{name}_p2_factor"], f, rtol=1e-9)
        for q in ("von_mises", "s1", "s2", "dominant"):
            p1, p2 = col[f"{name}_cycle_{q}_MPa"], col[f"{name}_{q}_MPa"]
            np.testing.assert_allclose(p2, f * p1, rtol=1e-8, atol=1e-9 * np.max(np.abs(p1)))
        # the history as the cycle gives it is the summary's (P1) von Mises range
        assert col[f"{name}_cycle_von_mises_MPa"].max() == pytest.approx(spot["von_mises_max_MPa"], rel=1e-9)

        # the fatigue check redone from the CSV alone: FKM signed von Mises of the P2 columns ...
        s1, s2 = col[f"{name}_s1_MPa"], col[f"{name}_s2_MPa"]
        vm = np.sqrt(s1 ** 2 - s1 * s2 + s2 ** 2)
        np.testing.assert_allclose(col[f"{name}_von_mises_MPa"], vm, rtol=1e-7, atol=1e-6)
        signed = np.where(s1 + s2 >= 0.0, vm, -vm)
        np.testing.assert_allclose(col[f"{name}_signed_von_mises_MPa"], signed, rtol=1e-7, atol=1e-6)
        # ... its amplitude and mean on the Goodman line: 1/n = σa/σW + σm/Rm (no credit for σm < 0)
        amplitude, mean = 0.5 * (signed.max() - signed.min()), 0.5 * (signed.max() + signed.min())
        n = 1.0 / (amplitude / sigma_w + max(mean, 0.0) / r_m)
        assert amplitude == pytest.approx(fatigue[name]["amplitude_MPa"], rel=1e-7)
        assert mean == pytest.approx(fatigue[name]["mean_MPa"], rel=1e-7, abs=1e-6)
        assert n == pytest.approx(fatigue[name]["goodman_safety_factor"], rel=1e-7)
        factors.append(n)
    # the verdict is Findley's at the structural hot spot; the contact zone is assessed as what it is
    assert summary["fatigue_safety_factor"] == pytest.approx(fatigue["structural"]["safety_factor"], rel=1e-12)
    assert summary["fatigue_safety_factor_at"]["hot_spot"] == "structural"
    fin = fatigue["structural"]["findley"]
    ms = summary["mass_strength"]
    assert fatigue["structural"]["safety_factor"] == pytest.approx(
        ms["findley_f_MPa"] / (fin["shear_amplitude_MPa"] + ms["findley_k"] * fin["normal_stress_max_MPa"]), rel=1e-12)
    assert fatigue["contact_zone"]["safety_factor"] is None and fatigue["contact_zone"]["assessed_as"]


# --------------------------------------------------------------------------------------------
# Stages: progress on each, and the time line adds up to the wall time
# --------------------------------------------------------------------------------------------


def test_every_stage_of_the_run_reports_and_the_slices_report_their_steps(timed_run):
    result, calls, _ = timed_run
    started = [stage for _, stage, done, _ in calls if done == 0]
    assert started == list(run_stages(result.case, images=False))     # each once, in the announced order
    assert {"accuracy", "roller_slices"} <= set(started)
    steps = [(done, total) for _, stage, done, total in calls if stage == "roller_slices"]
    inner = [(d, t) for d, t in steps[1:-1]]
    # one step per bearing's flexible slices (the rigid column comes with the rigid model)
    assert inner and all(0 < d < t for d, t in inner)
    assert [d for d, _ in inner] == list(range(1, len(inner) + 1))
    assert steps[-1][0] == steps[-1][1]                                 # and the end


def test_the_stages_follow_each_other_and_account_for_the_wall_time(timed_run):
    result, calls, wall = timed_run
    t = result.summary["timings_s"]
    spans = {}
    for when, stage, done, total in calls:
        if done == 0:
            spans[stage] = [when, None]
        elif done >= total:
            spans[stage][1] = when
    order = sorted(spans.values())
    for (a0, a1), (b0, _) in zip(order, order[1:]):
        assert a1 <= b0                                                # one after the other
    for stage, (a, b) in spans.items():                                # each stage's time is its span
        if stage == "evaluation":      # and the evaluation's rest after the stress stage (hot spots, Hertz)
            assert t[stage] >= b - a - 2e-3
        else:
            assert t[stage] == pytest.approx(b - a, abs=2e-3), stage
    # total = Σ stages + other, other ≥ 0 and a small part; the total is the run's wall time (less
    # the summary.json written after it and the move of the folder)
    assert t["total"] == pytest.approx(sum(t[s] for s in STAGES if s in t) + t["other"], abs=1e-9)
    assert t["other"] == pytest.approx(outside_stages(t))
    assert 0.0 <= t["other"] < 0.1 * t["total"]
    assert t["total"] <= wall <= t["total"] + 0.5


def test_screen_time_line_adds_up_to_the_wall_time(timed_run):
    result, _, _ = timed_run
    t = result.summary["timings_s"]
    (line,) = [x for x in summary_text(result.summary).splitlines() if x.startswith("  time ")]
    total, parts = re.fullmatch(r"  time ([\d.]+) s = (.*) s", line).groups()
    numbers = [float(p.rsplit(" ", 1)[1]) for p in parts.split(" + ")]
    assert float(total) == pytest.approx(t["total"], abs=0.05)
    assert sum(numbers) == pytest.approx(t["total"], abs=0.05 * len(numbers) + 1e-9)
    assert "between the stages" in parts and ("roller_slices" in line or "shorter stages" in line)


@pytest.mark.parametrize("tty", [True, False])
def test_a_stage_that_learns_its_steps_while_running_shows_them(tty, monkeypatch):
    """The roller slices know their number of steps only once they run: on a terminal the status
    line becomes a bar, otherwise a line every tenth once the stage has taken a second (a quick
    stage stays one line)."""

    def run(progress):
        progress("roller_slices", 0, 1)
        for done in range(1, 4):
            progress("roller_slices", done, 4)
        progress("roller_slices", 4, 4)
        progress.close()

    stream = io.StringIO()
    run(cli._RunProgress(stream, tty, ("roller_slices",)))
    text = stream.getvalue()
    assert text.count("done in") == 1
    if tty:
        assert "0/4" in text and "step/s" in text and "…" in text    # the status line became a bar
    else:
        assert "steps" not in text                                   # quick: no step lines
        monkeypatch.setattr(cli._RunProgress, "QUIET_SECONDS", 0.0)  # as if each step took long
        stream = io.StringIO()
        run(cli._RunProgress(stream, tty, ("roller_slices",)))
        assert "rvfem run: roller_slices 2/4 steps (50 %)" in stream.getvalue()


# --------------------------------------------------------------------------------------------
# The slice solver: the contact conditions hold, whichever system solves an active set
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("slices", [30, 400])
def test_slice_contacts_satisfy_the_contact_conditions(slices):
    """Crowned rollers (logarithmic drop, tilted or not) from a very light load (a few slices in
    contact: solved with C_SS) to a heavy one (a few out of contact: solved through C⁻¹): p ≥ 0,
    no penetration, no pressure where the surfaces part, and Σ p·A = Q."""
    length, e_star, r_red = 20.0, 1.15e5, 5.0
    x, dx = roller_slices.slice_centres(length, slices)
    b = 0.15
    c = roller_slices.rectangle_influence(x, dx, b, e_star)
    area = 2.0 * b * dx
    drop = 2e-3 * np.log(1.0 / (1.0 - 0.99 * (2.0 * x / length) ** 2))            # ≈ 9 µm at the ends
    loads = np.array([5.0, 200.0, 2000.0, 8000.0, 30000.0])
    tilts = np.array([0.0, 2e-4, -1e-4, 5e-4, 0.0])
    g = tilts[:, None] * x[None, :] - drop[None, :]
    p, delta = roller_slices.solve_slices(c, area, g, loads)
    w = p @ c.T                                                                     # displacement, mm
    s = delta[:, None] + g                                                          # approach of the surfaces
    scale = np.max(np.abs(s), axis=1, keepdims=True)
    assert np.all(p >= 0.0)
    assert np.all(w - s >= -1e-9 * scale)                                           # no penetration
    contact = p > 1e-9 * p.max(axis=1, keepdims=True)
    np.testing.assert_allclose(np.where(contact, w - s, 0.0), 0.0, atol=1e-9 * scale.max())
    np.testing.assert_allclose(p @ area, loads, rtol=1e-10)
    inside = contact.sum(axis=1)
    assert inside[0] < slices / 2 < inside[-2]          # both kinds of active set occur
    assert math.isclose(float(inside[-1]), slices) or inside[-1] > inside[-2]
