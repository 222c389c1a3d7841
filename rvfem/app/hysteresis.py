"""``rvfem hysteresis``: the transmission-accuracy figures of a case (hysteresis loop, torsional
rigidity, lost motion, hysteresis loss, backlash, where the compliance sits and, on request, the
transmission error over a revolution), written to a directory.

The library part (:func:`accuracy_study`) computes and writes; the command line prints.
"""

from __future__ import annotations

import dataclasses
import importlib
import json
import logging
import math
import os
import time
from pathlib import Path

import numpy as np

from rvfem._child import ChildProcess, SharedWork, usable_cores
from rvfem.app.analysis import analyse_rigid, default_cache_dir
from rvfem.app.p2_model import models_in_package
from rvfem.case.definition import MAX_FRICTION, Case
from rvfem.errors import CaseError
from rvfem.evaluate.validity import ResultWarning
from rvfem.evaluate.accuracy import accuracy_figures, mean_loop
from rvfem.geometry import disc_geometry
from rvfem.mesh import mesh_case
from rvfem.outputs import accuracy as files
from rvfem.outputs.plot_worker import PlotWorker
from rvfem.outputs.summary import result_folder
from rvfem.solve import accuracy
from rvfem.solve.cycle import build_system, case_stage
from rvfem.solve.stage_parts import held_in_words, not_modelled
from rvfem.units import ARCSEC_PER_RAD

log = logging.getLogger(__name__)

__all__ = ["accuracy_study", "left_out", "loop_option_problem", "loop_warnings", "mesh_period_angles"]


def left_out() -> str:
    """What the stage model holds and leaves out, in words, for the report: the stage's components
    (:func:`rvfem.solve.stage_parts.held_in_words`) and the parts of the reducer none of them brings
    in (:func:`rvfem.solve.stage_parts.not_modelled`), then the conventions of the loop."""
    parts = [words for _, words in not_modelled()]
    leaves = (", ".join(parts[:-1]) + " and " + parts[-1]) if len(parts) > 1 else "".join(parts)
    return (f"The stage model holds {held_in_words()}. "
            + (f"It leaves out {leaves}. " if parts else "")
            + "The output rotation is the carrier's rotation about the reducer axis (the discs, stiff, turning with "
            "it), under the output torque about that axis. Pin friction is Coulomb "
            "with full sliding at every step: it vanishes with the load, so without a clearance the loop has no "
            "width at zero torque. Catalogue rigidity and lost motion are measured on the whole reducer: this "
            "model's rigidity is an upper bound and its lost motion a lower bound.")


def mesh_period_angles(case: Case, count: int = 9) -> np.ndarray:
    """``count`` crank angles spread over one tooth-mesh period 2π/Zc (rad): the disc's contact
    pattern at θ + 2π/Zc is the one at θ turned by a tooth (docs/theory.md)."""
    if count < 1:
        raise CaseError(f"angle_count needs at least 1 crank angle, got {count}")
    return np.arange(count) * 2.0 * math.pi / (count * case.cycloid.teeth)


def loop_option_problem(*, torque_Nm: float | None = None, angles_deg: tuple[float, ...] | None = None,
                        angle_count: int | None = None, steps: int = 40,
                        friction: float | None = None) -> tuple[str, str] | None:
    """The first option of :func:`accuracy_study` that cannot be used, as ``(parameter, why)``, or
    None. ``why`` follows the parameter's name, so that the library says ``torque_Nm …`` and the
    command line its own option (``--torque …``).

    Refused: a torque that is not positive (the loop goes to +T and −T); ``steps`` that are not a
    multiple of 4 of at least 8; a friction outside [0, :data:`~rvfem.case.definition.MAX_FRICTION`];
    crank angles outside [0, 360)° (given as they are reported: a crank angle of 400° is not
    silently taken as 40°); an ``angle_count`` below 1; and ``angles_deg`` together with
    ``angle_count`` (the given crank angles, or that many spread over a mesh period: one or the
    other).
    """
    if torque_Nm is not None and not float(torque_Nm) > 0:
        return "torque_Nm", f"must be positive (the loop goes to +T and −T), got {torque_Nm:g}"
    if steps < 8 or steps % 4:
        return "steps", (f"must be a multiple of 4 and at least 8 (0 → +T → 0 → −T → 0 in equal steps), "
                         f"got {steps}")
    if friction is not None and not 0.0 <= friction <= MAX_FRICTION:
        return "friction", f"must be in [0, {MAX_FRICTION:g}] (the range of analysis.friction), got {friction:g}"
    if angles_deg:
        if angle_count is not None:
            return "angles_deg", ("and angle_count exclude each other: give the crank angles, or how many to "
                                  "spread over one mesh period")
        for a in angles_deg:
            if not 0.0 <= a < 360.0:
                return "angles_deg", f"must lie in [0, 360)° (one crank revolution), got {a:g}"
    if angle_count is not None and angle_count < 1:
        return "angle_count", f"needs at least 1 crank angle, got {angle_count}"
    return None


def loop_warnings(case: Case, torque_Nm: float) -> tuple[ResultWarning, ...]:
    """The range warnings of the loop's torque: those ``rvfem rigid`` and ``rvfem run`` give for
    the case at ``torque_Nm`` (:func:`rvfem.evaluate.validity.rigid_warnings` of the handbook at
    that torque, without the duty cycle: P/C, L10h and the Stribeck Hertz pressures). Empty where
    the handbook is not defined (a modified tooth count)."""
    loads = dataclasses.replace(case.loads, torque_Nm=float(torque_Nm), duty_cycle=())
    try:
        rigid = analyse_rigid(case.replace(loads=loads))
    except CaseError:   # the handbook is not defined for this case: nothing to check against
        return ()
    return tuple(rigid.warnings)


def _loops(stage, thetas, torque, friction, steps):
    loops = [accuracy.hysteresis_loop(stage, float(t), torque, friction=friction, steps=steps) for t in thetas]
    per_angle = []
    for loop in loops:
        f = accuracy_figures(loop.torque_Nm, loop.rotation_rad, loop.branch, torque)
        per_angle.append({"crank_angle_deg": math.degrees(loop.theta), **f.as_dict()})
    return loops, per_angle


def accuracy_study(case: Case, out_dir: str | os.PathLike, *, torque_Nm: float | None = None,
                   angles_deg: tuple[float, ...] | None = None, angle_count: int | None = None, steps: int = 40,
                   friction: float | None = None, te: bool = False, shares: bool = True,
                   cache_dir: str | os.PathLike | None = None, overwrite: bool = False) -> dict:
    """Solve the hysteresis loop (and the shares and TE) of ``case`` and write the files to
    ``out_dir``: hysteresis.csv, plots/hysteresis.png, plots/compliance_shares.png, te.csv and
    plots/transmission_error.png (``te``), summary.json and accuracy.md. Returns the summary.

    ``torque_Nm`` defaults to ``loads.torque_Nm`` (the rated torque), ``friction`` to
    ``analysis.friction``; the loop is averaged over ``angles_deg`` (in [0, 360)°) or
    ``angle_count`` crank angles of one mesh period (:func:`mesh_period_angles`; default 9), not
    both (:func:`loop_option_problem`). The summary's ``warnings`` are those of the case at the
    loop's torque (:func:`loop_warnings`). ``out_dir`` is an atomic result folder
    (:func:`rvfem.outputs.summary.result_folder`): it appears only when complete, and an existing
    non-empty one is replaced only with ``overwrite`` and only if rvfem wrote it.

    Raises
    ------
    CaseError
        An option cannot be used (:func:`loop_option_problem`).
    OutputError
        ``out_dir`` cannot take the results.
    """
    t_start = time.perf_counter()
    problem = loop_option_problem(torque_Nm=torque_Nm, angles_deg=angles_deg, angle_count=angle_count, steps=steps,
                                  friction=friction)
    if problem is not None:
        raise CaseError(" ".join(problem))
    T = float(case.loads.torque_Nm if torque_Nm is None else torque_Nm)
    if not T > 0:
        raise CaseError(f"the loop's torque must be positive (the loop goes to +T and −T): loads.torque_Nm = {T:g}; "
                        "give a positive torque_Nm")
    mu = float(case.analysis.friction if friction is None else friction)
    thetas = (np.radians(angles_deg) if angles_deg else mesh_period_angles(case, 9 if angle_count is None else angle_count))
    warnings = loop_warnings(case, T)
    for w in warnings:   # in the summary; the command line prints them as rvfem run does
        log.debug("loop torque %g N·m: %s", T, w.message)
    with result_folder(out_dir, overwrite=overwrite, what="hysteresis") as out, \
            PlotWorker("hysteresis plots") as plots, \
            _TransmissionErrorChild(case if te else None) as te_child:   # imports while the model is built
        (out / "plots").mkdir()
        timings = {}
        t0 = time.perf_counter()
        geometry = disc_geometry(case)
        mesh = mesh_case(case, default_cache_dir() if cache_dir is None else cache_dir, geometry=geometry)
        te_child.start(mesh, geometry)      # its stage built there beside this one's
        stage = case_stage(build_system(case, mesh, geometry=geometry))
        te_child.begin(stage, te_angles(case), T, mu)    # the child's share of the TE beside the loops and shares
        timings["model_s"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        loops, per_angle = _loops(stage, thetas, T, mu, steps)
        timings["loops_s"] = time.perf_counter() - t0
        torque, branch = loops[0].torque_Nm, loops[0].branch
        rotations = np.array([lp.rotation_rad for lp in loops])
        mean = mean_loop(rotations)
        fig = accuracy_figures(torque, mean, branch, T)
        summary = {"case": case.name, "torque_Nm": T, "friction": mu, "steps": steps,
                   "angles_deg": [math.degrees(t) for t in thetas], **fig.as_dict(),
                   "per_angle": per_angle, "stage": stage.describe(), "left_out": left_out(),
                   "warnings": [w.as_dict() for w in warnings]}
        files.write_loop_csv(out / "hysteresis.csv", torque, branch, mean, np.degrees(thetas), rotations)
        plots.submit(files.hysteresis_plot, out / "plots" / "hysteresis.png", torque, branch, mean, fig, T,
                     title=f"{case.name}: hysteresis loop, input locked (mean of {len(thetas)} crank angles)")
        if shares:
            t0 = time.perf_counter()
            summary["compliance_shares"] = _shares(case, stage, float(thetas[0]), T, mu, out, plots)
            timings["shares_s"] = time.perf_counter() - t0
        if te:
            t0 = time.perf_counter()
            summary["transmission_error"] = _te(case, stage, T, mu, out, plots, te_child)
            timings["te_s"] = time.perf_counter() - t0
        plots.wait()
        timings["total_s"] = time.perf_counter() - t_start
        summary["timings"] = timings
        (out / "summary.json").write_text(json.dumps(summary, indent=2, allow_nan=False), encoding="utf-8")
        (out / "accuracy.md").write_text(files.accuracy_report(summary), encoding="utf-8")
    return summary


def _shares(case: Case, stage, theta: float, torque: float, friction: float, out: Path, plots: PlotWorker) -> dict:
    """The compliance shares at crank angle θ (rad): the plot and the summary part."""
    cs = accuracy.compliance_shares(stage, theta, torque, friction)
    plots.submit(files.shares_plot, out / "plots" / "compliance_shares.png", cs.shares,
                 title=f"{case.name}: where the compliance sits")
    return {"crank_angle_deg": math.degrees(theta), "rotation_arcmin": cs.rotation_arcmin, "shares": cs.shares,
            "total": cs.total}


def te_angles(case: Case) -> np.ndarray:
    """The crank angles of the TE over one revolution: the case's angle step, rad."""
    return np.radians(np.arange(0.0, 360.0, case.analysis.angle_step_deg))


_TE_STAGE: dict = {}
"""In the TE's child process only: the stage it solves its share of the TE on (key ``"stage"``)."""


def _te_child_stage(case: Case, mesh, geometry) -> None:
    """In the child process of :class:`_TransmissionErrorChild`: the case's stage on its own
    factorisation, kept for :func:`_te_child_angles`."""
    _TE_STAGE["stage"] = case_stage(build_system(case, mesh, geometry=geometry))


def _te_child_angles(thetas: np.ndarray, torque: float, friction: float) -> tuple[np.ndarray, np.ndarray]:
    """In the child process of :class:`_TransmissionErrorChild`: :func:`rvfem.solve.accuracy.te_at_angles`
    on its stage."""
    return accuracy.te_at_angles(_TE_STAGE["stage"], thetas, torque, friction)


def _te_child_imports() -> None:
    """In the child process of :class:`_TransmissionErrorChild`: import the solver."""
    for name in ("rvfem.solve.cycle", "rvfem.solve.accuracy"):
        importlib.import_module(name)


TE_CHILD_NICENESS = 10
"""Niceness added to the TE's child process (Unix ``nice``): where it competes for a core with
this process (the model, the loops) or the plot worker, they go first."""

TE_SHARE_ANGLES = 6
"""Crank angles of one share of the TE (:class:`_TransmissionErrorChild`): each share starts from
no contacts of its own, the angles within it each from the last one's."""


class _TransmissionErrorChild:
    """The TE over a revolution solved in shares of :data:`TE_SHARE_ANGLES` crank angles by a child
    process (:class:`rvfem._child.ChildProcess`) and by this one (:class:`rvfem._child.SharedWork`):
    the child takes shares from the first angle on as soon as its stage is built, while this
    process solves the loops and the compliance shares; then this process takes the shares left
    from the last angle backwards until the two meet.

    The child builds the same stage on its own factorisation (the model is built twice; most of
    the TE's compliance columns are its own anyway: a revolution of crank angles against the
    loops' mesh period). Measurements: benchmarks/README.md, "Hysteresis and transmission
    error". Without a child (``case`` None, a bearing or pin model registered in this process
    only, one usable core, no process could be started) the TE is solved here alone; a share the
    child does not deliver (it ended) is solved here.
    """

    def __init__(self, case: Case | None):
        self._child: ChildProcess | None = None
        self._work: SharedWork | None = None
        self._angles = np.zeros(0)
        self._case = case
        if case is None or not models_in_package(case) or usable_cores() < 2:
            return
        try:
            self._child = ChildProcess("transmission error", niceness=TE_CHILD_NICENESS, forward_logs=True)
        except OSError as exc:  # pragma: no cover - the interpreter itself cannot be started
            log.info("the transmission error is solved in this process: %s", exc)
            return
        self._child.call(_te_child_imports)

    def start(self, mesh, geometry) -> None:
        """Hand the child the case's mesh and geometry: it builds its stage."""
        if self._child is not None:
            self._child.call(_te_child_stage, self._case, mesh, geometry)

    def begin(self, stage, thetas: np.ndarray, torque: float, friction: float) -> None:
        """Let the child start on the TE at crank angles ``thetas`` (rad) of ``stage`` (this
        process's, for the angles symmetry does not give: :func:`rvfem.solve.accuracy.te_plan`),
        at the torque (N·m) and the friction."""
        if self._child is None:
            return
        solve_at, _ = accuracy.te_plan(stage, thetas)
        angles = self._angles = np.asarray(thetas, dtype=float)[solve_at]
        shares = [angles[i:i + TE_SHARE_ANGLES] for i in range(0, len(angles), TE_SHARE_ANGLES)]
        child = self._child
        self._work = SharedWork(shares, lambda share: child.call(_te_child_angles, share, float(torque),
                                                                  float(friction)))

    def solve(self, stage, torque: float, friction: float):
        """The ``solve`` of :func:`rvfem.solve.accuracy.transmission_error`: the angles shared
        with the child where :meth:`begin` gave it these, else solved here."""
        def here(angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return accuracy.te_at_angles(stage, angles, torque, friction)

        def shared(angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            if self._work is None or not np.array_equal(np.asarray(angles, dtype=float), self._angles):
                return here(angles)
            parts = self._work.finish(here)
            log.info("transmission error: %d of %d shares of %d crank angles solved in the child process",
                     self._work.child_count, len(parts), TE_SHARE_ANGLES)
            return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])

        return shared

    @property
    def shares_to_child(self) -> int:
        """Shares of the TE the child was given (0 without a child)."""
        return 0 if self._work is None else self._work.child_count

    def __enter__(self) -> "_TransmissionErrorChild":
        return self

    def __exit__(self, *exc) -> None:
        if self._child is not None:
            self._child.close()


def _te(case: Case, stage, torque: float, friction: float, out: Path, plots: PlotWorker,
        child: _TransmissionErrorChild | None = None) -> dict:
    """The TE over one crank revolution at the case's angle step: te.csv, the plot, the summary part."""
    thetas = te_angles(case)
    no_load, loaded = accuracy.transmission_error(stage, thetas, torque, friction,
                                                  solve=None if child is None else child.solve(stage, torque, friction))
    files.write_te_csv(out / "te.csv", np.degrees(thetas), no_load, loaded)
    plots.submit(files.te_plot, out / "plots" / "transmission_error.png", np.degrees(thetas), no_load, loaded, torque,
                 title=f"{case.name}: transmission error over one crank revolution")
    arcsec = ARCSEC_PER_RAD

    def orders(te):
        return [{"order": k, "amplitude_arcsec": a} for k, a in accuracy.te_orders(te * arcsec, thetas, 6)]

    return {"no_load_peak_to_peak_arcsec": float(np.ptp(no_load) * arcsec),
            "loaded_peak_to_peak_arcsec": float(np.ptp(loaded) * arcsec),
            "loaded_mean_arcsec": float(np.mean(loaded) * arcsec),
            "no_load_orders": orders(no_load), "loaded_orders": orders(loaded)}
