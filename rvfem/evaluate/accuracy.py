"""The catalogue's accuracy figures read off a hysteresis loop (:mod:`rvfem.solve.accuracy`).

Definitions (docs/theory.md, "Transmission accuracy"): the hysteresis loop is the output rotation
with the input locked while the output torque goes 0 → +T_R → 0 → −T_R → 0 (Liu et al.,
*Degradation law analysis and life estimation of transmission accuracy of RV reducer based on
tooth surface and bearing wear*, section 4.4; the RV catalogues' hysteresis curve).

* torsional rigidity: b/a, the secant slope of the loading branch between the lost-motion torque
  3 % T_R and T_R (b = 0.97·T_R, a the rotation between them), the mean of the + and − sides;
* lost motion: the rotation between the midpoints of the loop's width at +3 % and −3 % T_R (the
  width of the loop's centreline between ±3 % T_R);
* hysteresis loss: the width of the loop at zero torque;
* backlash: the jump of the rotation at a zero crossing (the free play: the stage is a mechanism at
  zero torque), the mean of the two crossings.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rvfem.solve.accuracy import LOST_MOTION_FRACTION, loop_at_torques
from rvfem.units import ARCMIN_PER_RAD

__all__ = [
    "ARCMIN_PER_RAD",
    "LOST_MOTION_FRACTION",
    "AccuracyFigures",
    "accuracy_figures",
    "branch_at",
    "mean_loop",
    "quick_figures",
]

"""arcmin per rad."""



@dataclass(frozen=True)
class AccuracyFigures:
    """The catalogue figures of one loop (or of the loop averaged over crank angles).

    Attributes
    ----------
    torsional_rigidity_Nm_per_arcmin : float
        b/a between 3 % and 100 % of the loop's torque on the loading branches, N·m/arcmin.
    lost_motion_arcmin : float
        Width of the loop's centreline between ±3 % of the loop's torque, arcmin.
    hysteresis_loss_arcmin : float
        Width of the loop at zero torque, arcmin.
    backlash_arcmin : float
        Jump of the rotation at zero torque (free play), arcmin.
    rigidity_points : tuple
        ((T_low, φ_low), (T_R, φ_R)) of the + side's b/a construction, N·m and arcmin.
    lost_motion_points : tuple
        ((+T_lm, φ_mid+), (−T_lm, φ_mid−)), N·m and arcmin: the centreline's points.
    """

    torsional_rigidity_Nm_per_arcmin: float
    lost_motion_arcmin: float
    hysteresis_loss_arcmin: float
    backlash_arcmin: float
    rigidity_points: tuple[tuple[float, float], tuple[float, float]]
    lost_motion_points: tuple[tuple[float, float], tuple[float, float]]

    def as_dict(self) -> dict:
        """The four figures under their summary keys."""
        return {"torsional_rigidity_Nm_per_arcmin": self.torsional_rigidity_Nm_per_arcmin,
                "lost_motion_arcmin": self.lost_motion_arcmin,
                "hysteresis_loss_arcmin": self.hysteresis_loss_arcmin,
                "backlash_arcmin": self.backlash_arcmin}


def branch_at(torque: np.ndarray, rotation: np.ndarray, branch: np.ndarray, k: int, at: float) -> float:
    """Rotation of branch ``k`` at torque ``at`` (linear interpolation between its load steps)."""
    sel = branch == k
    t, r = torque[sel], rotation[sel]
    order = np.argsort(t)
    return float(np.interp(at, t[order], r[order]))


def accuracy_figures(torque_Nm: np.ndarray, rotation_rad: np.ndarray, branch: np.ndarray,
                     rated_torque_Nm: float) -> AccuracyFigures:
    """The catalogue figures (module docstring) of a loop: its torques (N·m), rotations (rad) and
    branches (0 loading +, 1 unloading +, 2 loading −, 3 unloading −, as
    :func:`rvfem.solve.accuracy.loop_torques` orders them)."""
    T = abs(float(rated_torque_Nm))
    phi = np.asarray(rotation_rad, dtype=float) * ARCMIN_PER_RAD
    tq = np.asarray(torque_Nm, dtype=float)
    br = np.asarray(branch)
    lm = LOST_MOTION_FRACTION * T
    at = lambda k, t: branch_at(tq, phi, br, k, t)
    low_p, top_p = at(0, lm), at(0, T)
    low_m, top_m = at(2, -lm), at(2, -T)
    rigidity = 0.5 * ((T - lm) / (top_p - low_p) + (T - lm) / (low_m - top_m))
    mid_p = 0.5 * (at(0, lm) + at(1, lm))
    mid_m = 0.5 * (at(2, -lm) + at(3, -lm))
    zero_p, zero_m = _zero_end(tq, phi, br, 1), _zero_end(tq, phi, br, 3)
    start_m, start_p = _zero_start(tq, phi, br, 2), _zero_start(tq, phi, br, 0)
    backlash = 0.5 * ((zero_p - start_m) + (start_p - zero_m))
    return AccuracyFigures(float(rigidity), float(mid_p - mid_m), float(zero_p - zero_m), float(backlash),
                           ((lm, low_p), (T, top_p)), ((lm, mid_p), (-lm, mid_m)))


def _zero_end(tq, phi, br, k) -> float:
    """The rotation at the end (zero torque) of unloading branch k."""
    sel = np.flatnonzero(br == k)
    return float(phi[sel[np.argmin(np.abs(tq[sel]))]])


_zero_start = _zero_end


def mean_loop(rotations: np.ndarray) -> np.ndarray:
    """The loop averaged over crank angles: the mean rotation of each load step over the loops
    (``rotations`` (angles, steps), the same torques at every angle)."""
    return np.asarray(rotations, dtype=float).mean(axis=0)


def quick_figures(stage, torque_Nm: float, friction: float = 0.0, theta: float = 0.0) -> dict:
    """Torsional rigidity and lost motion of the stage at crank angle θ (rad) from six solves:
    the loading and unloading branches at ±3 % and ±100 % of ``torque_Nm`` (N·m) only, on the
    stage's factorised discs (``rvfem run``'s screen line). Returns the two summary keys."""
    T = abs(float(torque_Nm))
    lm = LOST_MOTION_FRACTION * T
    plus, _, _ = loop_at_torques(stage, theta, [T, lm, lm], friction, [1, 1, -1])
    minus, _, _ = loop_at_torques(stage, theta, [-T, -lm, -lm], friction, [-1, -1, 1])
    a = (plus[0] - plus[1] + minus[1] - minus[0]) * 0.5 * ARCMIN_PER_RAD
    return {"torsional_rigidity_Nm_per_arcmin": float((T - lm) / a),
            "lost_motion_arcmin": float(0.5 * (plus[1] + plus[2] - minus[1] - minus[2]) * ARCMIN_PER_RAD)}
