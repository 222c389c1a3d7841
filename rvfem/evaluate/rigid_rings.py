"""Rigid rings under a radial force: the one rigid model of the crank bearing's rollers (the rigid
most loaded roller of every output, :data:`rvfem.evaluate.hertz.RIGID_ROLLER_MODEL`, and the rigid
column of the crank bearing in depth). The rollers sit at their cage positions, with the bearing's
radial clearance or preload, and Palmgren's line contact on both raceways."""

from __future__ import annotations

import numpy as np

from rvfem.evaluate.hertz import PALMGREN_COEFFICIENT
from rvfem.solve.models import roller_angles

__all__ = ["case_rigid_roller_loads", "rigid_ring_roller_loads"]


def rigid_ring_roller_loads(bearing_forces: np.ndarray, roller_angles: np.ndarray, iterations: int = 40, *,
                            radial_clearance_mm: float = 0.0, roller_length_mm: float | None = None) -> np.ndarray:
    """Roller loads of rigid rings under a radial force, N: the rigid-ring (Stribeck) distribution
    at the rollers' actual angles, with the bearing's radial clearance.

    The rings move by d relative to each other; roller j along e_j = (cos ψ_j, sin ψ_j) is
    compressed by s_j = (d·e_j − c/2)₊ (c the radial clearance, negative for a preload) and carries
    Q_j = K·s_j^(10/9), K = (L^0.8/(2·3.84·10⁻⁵))^(10/9) (Palmgren's line contact on both
    raceways, Harris & Kotzalas, the law of the FE rollers); d solves Σ_j Q_j·e_j = F (Newton,
    from the zero-clearance solution Q_j = F·c_j^(10/9)/Σ c_k^(19/9), c = cos(ψ − φ_F)₊, each step
halved until it lowers the convex potential Σ K·s_j^(19/9)/(19/9) − F·d). Without
    clearance K drops out and Q_max → 4.08·F/Z for many rollers with one on the load line
    (:func:`rvfem.evaluate.hertz.rigid_ring_factor` gives the exact discrete value).

    Parameters
    ----------
    bearing_forces : ndarray (..., 2)
        Force of the bearing on the disc, N (the rollers are pressed on the side it points to).
    roller_angles : ndarray (..., Z)
        Angular positions of the rollers, rad, same frame.
    iterations : int
        Most Newton iterations (they stop once every step is below round-off of the largest
        approach, in about ten; a light force within a wide clearance may need the damped steps
        of more).
    radial_clearance_mm : float
        c, mm (0: zero clearance; negative: preload).
    roller_length_mm : float, optional
        L_we, mm (needed for a non-zero clearance, which makes the distribution depend on K).

    Returns
    -------
    ndarray (..., Z)
    """
    f = np.asarray(bearing_forces, dtype=float)
    psi = np.asarray(roller_angles, dtype=float)
    half_c = 0.5 * float(radial_clearance_mm)
    if half_c != 0.0:
        if roller_length_mm is None:
            raise ValueError("rigid_ring_roller_loads needs roller_length_mm with a radial clearance")
        k = (roller_length_mm ** 0.8 / (2.0 * PALMGREN_COEFFICIENT)) ** (10.0 / 9.0)
    else:
        k = 1.0                                                                # drops out
    e = np.stack([np.cos(psi), np.sin(psi)], axis=-1)                       # (..., Z, 2)
    mag = np.linalg.norm(f, axis=-1)
    unit = f / np.where(mag > 0, mag, 1.0)[..., None]
    c = np.clip(np.einsum("...zc,...c->...z", e, unit), 0.0, None)
    denom = np.sum(c ** (19.0 / 9.0), axis=-1)
    scale = np.where(denom > 0, mag / np.where(denom > 0, denom, 1.0), 0.0)
    d = unit * ((scale / k) ** 0.9 + max(half_c, 0.0))[..., None]           # Q = K·(d·e − c/2)^(10/9)

    def potential(dd):       # Π(d) = Σ K·s^(19/9)/(19/9) − F·d: convex, its gradient the residual
        ss = np.clip(np.einsum("...zc,...c->...z", e, dd) - half_c, 0.0, None)
        return np.sum(k * 9.0 / 19.0 * ss ** (19.0 / 9.0), axis=-1) - np.einsum("...c,...c->...", f, dd)

    for _ in range(iterations):
        s = np.clip(np.einsum("...zc,...c->...z", e, d) - half_c, 0.0, None)
        q = k * s ** (10.0 / 9.0)
        res = np.einsum("...z,...zc->...c", q, e) - f
        jac = np.einsum("...z,...zc,...zd->...cd", k * (10.0 / 9.0) * s ** (1.0 / 9.0), e, e)
        jac = jac + 1e-12 * np.max(np.abs(jac), initial=1.0) * np.eye(2)
        step = -np.linalg.solve(jac, res[..., None])[..., 0]
        if np.all(np.abs(step) <= 1e-15 * np.max(np.abs(d), initial=1e-300)):
            break               # converged to round-off: the remaining iterations would not move d
        # Newton's step, halved until it lowers the potential (with a clearance, a light force
        # near the edge of the play would otherwise overshoot without bound)
        base = potential(d)
        alpha = np.ones(base.shape)
        pending = np.ones(base.shape, dtype=bool)
        for _ in range(60):
            trial = potential(d + alpha[..., None] * step)
            pending = pending & ~(trial <= base + 1e-12 * np.abs(base))   # round-off near the minimum
            if not pending.any():
                break
            alpha = np.where(pending, 0.5 * alpha, alpha)
        d = d + np.where(pending, 0.0, alpha)[..., None] * step
    s = np.clip(np.einsum("...zc,...c->...z", e, d) - half_c, 0.0, None)
    if half_c < 0.0:                                     # a preload loads the rollers without a force
        return k * s ** (10.0 / 9.0)
    return np.where(mag[..., None] > 0, k * s ** (10.0 / 9.0), 0.0)


def case_rigid_roller_loads(case, theta: np.ndarray, bearing_forces: np.ndarray) -> np.ndarray:
    """The rigid-ring roller loads of a case's crank bearings over a cycle, N, (n, N, Z): every
    bearing's force on rigid rings (:func:`rigid_ring_roller_loads`) with the rollers at their cage
    positions (:func:`rvfem.solve.models.roller_angles`, as in the FE) and the case's radial
    clearance. Its largest value is the rigid most loaded roller of every output
    (:data:`rvfem.evaluate.hertz.RIGID_ROLLER_MODEL`).

    Parameters
    ----------
    case : Case
    theta : ndarray (n,)
        Crank angles, rad.
    bearing_forces : ndarray (n, N, 2)
        Force of every bearing on the disc, N (handbook or FE).
    """
    b = case.crank_bearing
    return rigid_ring_roller_loads(bearing_forces, roller_angles(case, np.asarray(theta, dtype=float)),
                                   radial_clearance_mm=b.radial_clearance, roller_length_mm=b.roller_length)
