"""Rigid versus flexible: what the disc's flexibility costs in bearing load and life.

For every crank bearing, three load curves over one crank revolution are compared:

``rigid``
    The handbook model (:mod:`rvfem.evaluate.rigid`; Gao et al., eqs. 4-10) — rigid disc, rigid bearings,
    the classical pin-force resultant ΣP_y = k_y·ΣP_x.
``flexible``
    The finite-element load cycle (:mod:`rvfem.solve.cycle`).
``equal_share``
    A rigid reference built from the finite-element model's *own* pin-force resultant P: each
    bearing carries −P/N plus the torque share T_disc/(N·r0) along its tangent. The difference
    flexible − equal_share is what the disc's flexibility does to the load sharing between the
    bearings; equal_share − rigid is what the handbook's pin-force assumption (k_y) does.

Deltas are in percent of the rigid values; the life ratio is L_flex/L_rigid = (F_m,rigid/F_m,flex)^(10/3)
(ISO 281 life exponent for roller bearings), e.g. +15 % equivalent load costs about 37 % life.

For a tooth difference Zp − Zc ≠ 1 the handbook model is not defined (:func:`rvfem.evaluate.rigid.references`):
``rigid`` is None and the deltas and life ratios are against ``equal_share``, the reference that
exists for any tooth difference (:attr:`Comparison.reference` names it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rvfem.case.definition import Case
from rvfem.errors import CaseError
from rvfem.evaluate import iso281, rigid
from rvfem.evaluate.rigid import BearingLoadSummary
from rvfem.geometry import crank_centres
from rvfem.solve.cycle import CycleResult

__all__ = ["BearingComparison", "Comparison", "equal_share_forces", "rigid_vs_flexible"]


@dataclass(frozen=True)
class BearingComparison:
    """One bearing: the three models (load statistics with their L10h, N, degrees, hours) and the
    deltas (percent) of the flexible loads against the reference of :attr:`Comparison.reference`
    (the handbook ``rigid``, or ``equal_share`` where the handbook is not defined; ``rigid`` is
    then None)."""

    bearing: int
    rigid: BearingLoadSummary | None
    flexible: BearingLoadSummary
    equal_share: BearingLoadSummary
    delta_max_percent: float
    delta_min_percent: float
    delta_equivalent_percent: float
    life_ratio: float


@dataclass(frozen=True)
class Comparison:
    """Rigid-vs-flexible comparison of all crank bearings.

    Attributes
    ----------
    bearings : tuple of BearingComparison
    exponent : float
        Equivalent-load exponent p used (case.analysis.equivalent_load_exponent).
    rating_N : float
        Dynamic load rating C of the crank bearing (ISO 281), N.
    bearing_speed_rpm : float
        n_b, rpm.
    pin_resultant_ratio : float
        Mean |P_y/P_x| of the finite-element pin resultant over the cycle (the handbook's k_y).
    handbook_k_y : float or None
        None where the handbook is not defined (Zp − Zc ≠ 1).
    reference : str
        What the deltas and life ratios are against: ``"handbook"`` (the ``rigid`` statistics) or
        ``"equal_share"`` (:attr:`rvfem.evaluate.rigid.References.bearing_loads`).
    """

    bearings: tuple[BearingComparison, ...]
    exponent: float
    rating_N: float
    bearing_speed_rpm: float
    pin_resultant_ratio: float
    handbook_k_y: float | None
    reference: str = "handbook"


def equal_share_forces(case: Case, result: CycleResult) -> np.ndarray:
    """Equal-share rigid reference from the FE pin resultant, (n, N, 2), N, forces on the disc.

    F_i = −P/N + T_disc/(N·r0)·t_i with P the pin-force resultant on the disc (= −Σ bearing forces)
    and t_i the unit tangent of the crank circle at bearing i (counter-clockwise): the resultant
    is shared equally and the torque is carried by equal tangential forces. T_disc is the bearing
    forces' moment about the disc centre at each angle (the carrier torque is a moment about the
    reducer axis, docs/theory.md § 6: about the disc centre the same forces give about Zc/Zp of the
    disc's share).
    """
    c = crank_centres(case)
    n = len(c)
    t = np.stack([-c[:, 1], c[:, 0]], axis=1) / np.linalg.norm(c, axis=1)[:, None]
    f = result.bearing_forces
    minus_p = f.sum(axis=1)          # −P
    torque = (c[None, :, 0] * f[..., 1] - c[None, :, 1] * f[..., 0]).sum(axis=1)
    share = torque / (n * case.cranks.circle_radius)
    return minus_p[:, None, :] / n + share[:, None, None] * t[None, :, :]


def _stats(theta: np.ndarray, magnitude: np.ndarray, exponent: float, rating: float,
           speed: float) -> list[BearingLoadSummary]:
    return [rigid.with_rating_life(s, rating, speed) for s in rigid.summarize_loads(theta, magnitude, exponent)]


def rigid_vs_flexible(case: Case, result: CycleResult) -> Comparison:
    """Compare the FE load cycle with the handbook model and the equal-share reference.

    Parameters
    ----------
    case : Case
    result : CycleResult
        A full revolution sampled uniformly (the handbook curve is evaluated at the same angles).

    Notes
    -----
    Where the handbook is not defined (Zp − Zc ≠ 1, :func:`rvfem.evaluate.rigid.references`) the ``rigid``
    statistics are None and the deltas are against the equal share.

    Raises
    ------
    CaseError
        Unequally spaced cranks: neither the handbook nor the equal share applies.
    """
    p = case.analysis.equivalent_load_exponent
    rating = iso281.crank_bearing_rating(case.crank_bearing)
    speed = iso281.case_bearing_speed_rpm(case)
    theta = result.theta
    refs = rigid.references(case)
    hb = rigid.handbook_bearing_loads(case, theta) if refs.handbook.defined else None
    if not refs.equal_share.defined:   # unequally spaced cranks: no rigid reference at all
        raise CaseError(f"{case.source}: {refs.equal_share.why}")
    flex = result.bearing_loads.T
    eq = np.linalg.norm(equal_share_forces(case, result), axis=2).T
    fs, es = (_stats(theta, m, p, rating, speed) for m in (flex, eq))
    rs = _stats(theta, hb.magnitude, p, rating, speed) if hb is not None else [None] * len(fs)
    bearings = []
    for i, (r, f, e) in enumerate(zip(rs, fs, es)):
        ref = r if refs.bearing_loads == "handbook" else e
        assert ref is not None   # the handbook is the reference only where it is defined
        bearings.append(BearingComparison(
            bearing=i, rigid=r, flexible=f, equal_share=e,
            delta_max_percent=100.0 * (f.max_N / ref.max_N - 1.0),
            delta_min_percent=100.0 * (f.min_N / ref.min_N - 1.0),
            delta_equivalent_percent=100.0 * (f.equivalent_N / ref.equivalent_N - 1.0),
            life_ratio=iso281.life_ratio(ref.equivalent_N, f.equivalent_N),
        ))
    # pin resultant in the eccentric's frame: P_x ⟂ eccentric, P_y along it
    p_res = -result.bearing_forces.sum(axis=1)
    u = np.stack([np.cos(theta), np.sin(theta)], axis=1)
    u_perp = np.stack([-np.sin(theta), np.cos(theta)], axis=1)
    ratio = float(np.mean(np.abs(np.einsum("ij,ij->i", p_res, u) / np.einsum("ij,ij->i", p_res, u_perp))))
    return Comparison(tuple(bearings), p, rating, speed, ratio, None if hb is None else hb.components.k_y,
                      refs.bearing_loads)
