"""The hysteresis loop of a reducer stage: the input locked, the output loaded 0 → +T → 0 → −T → 0.

With the input locked the crankshafts do not turn relative to the carrier (the spur stage would
let them turn by z_sun/z_planet of the output angle, a small part of the cycloid stage's effect,
left out): the stage is held at one crank angle θ and only the torque on the carrier changes. Each
load step is one contact solve of the stage (:func:`rvfem.solve.cycle.solve_pair`) on the same
factorised discs and lazily filled column compliance, started from the step before it. The
output rotation is the carrier rotation φ of that solve (plus the rotation of the stage's series
output compliances under the output torque, where a component adds one): the carrier turning about
the reducer axis, conjugate to the output torque as a moment about that axis
(:mod:`rvfem.solve.cycle_stage`), so every figure is in the output's arcmin.

**Friction.** A pin's friction opposes its sliding in the load step. At a held crank angle the
disc turns with the carrier about the reducer axis, so a pin slides along the flank by the rotation increment: loading
towards +T and unloading from −T slide one way (``slip = +1`` of
:class:`rvfem.solve.cycle.OperatingPoint`), unloading from +T and loading towards −T the other way
(``slip = −1``). Full sliding is assumed at every step (Coulomb, no sticking phase): at a reversal
the loop crosses at once to the other friction branch, which is what a stick phase does over a
torque interval of 2μ times the load (drawn as the vertical segment at the loop's tips).

**Zero torque.** With a clearance (a profile modification, a bearing clearance) the stage is a
mechanism at zero torque: its rotation is anywhere in the backlash. The loop's zeros are therefore
solved at ±``ZERO_FRACTION``·T on the side the branch comes from (unloading from +T ends at +0,
loading towards −T starts at −0), so each zero crossing shows the backlash as the jump between
the two.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass
from collections.abc import Callable, Sequence

import numpy as np

from rvfem.errors import ContactError
from rvfem.geometry import pin_profile_contacts
from rvfem.solve.cycle import (
    OperatingPoint,
    PairResult,
    ReducerStage,
    solve_pair,
    symmetry_plan,
)
from rvfem.solve.cycle_stage import prefetch_columns, stage_symmetry
from rvfem.solve.stage_parts import STIFFEN, component_names, stiffened_stage
from rvfem.units import arcmin_from_rad, nm_from_nmm

log = logging.getLogger(__name__)

__all__ = [
    "LOST_MOTION_FRACTION",
    "STIFFEN",
    "ZERO_FRACTION",
    "ComplianceShares",
    "HysteresisLoop",
    "component_names",
    "compliance_shares",
    "hysteresis_loop",
    "loop_at_torques",
    "loop_torques",
    "rigid_kinematic_te",
    "stiffened_stage",
    "te_at_angles",
    "te_orders",
    "te_plan",
    "transmission_error",
]

LOST_MOTION_FRACTION = 0.03
"""The lost-motion torque as a fraction of the rated torque (±3 % T_R, the catalogues' and Liu et
al.'s, section 4.4)."""

ZERO_FRACTION = 1e-4
"""The loop's zero torque, as a fraction of the loop's torque, solved on the side the branch comes
from (module docstring)."""

BRANCHES = ("loading +", "unloading +", "loading -", "unloading -")
"""The four branches of the loop, in order."""

BRANCH_SLIP = np.array([1, -1, -1, 1])
"""Which way the carrier turns on each branch (the pins' sliding, :class:`OperatingPoint` ``slip``)."""


@dataclass(frozen=True)
class HysteresisLoop:
    """The hysteresis loop of the stage at one crank angle.

    Attributes
    ----------
    theta : float
        Crank angle held, rad.
    torque_Nm : ndarray (n,)
        Output torque of each load step, N·m (the zeros at ±ZERO_FRACTION·T).
    rotation_rad : ndarray (n,)
        Output (carrier) rotation of each step, rad.
    branch : ndarray (n,) of int
        Index into :data:`BRANCHES` of each step.
    rated_torque_Nm : float
        The loop's torque T, N·m.
    friction : float
        Coulomb coefficient at the pins.
    iterations : ndarray (n,) of int
        Newton iterations of each step.
    """

    theta: float
    torque_Nm: np.ndarray
    rotation_rad: np.ndarray
    branch: np.ndarray
    rated_torque_Nm: float
    friction: float
    iterations: np.ndarray

    def branch_curve(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """(torque, rotation) of branch ``k`` (:data:`BRANCHES`), in load-step order."""
        sel = self.branch == k
        return self.torque_Nm[sel], self.rotation_rad[sel]


def loop_torques(torque_Nm: float, steps: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """The torques of a loop of ``steps`` load steps (a multiple of 4, at least 8) and the branch
    of each: 0 → +T, +T → 0, 0 → −T, −T → 0, each branch steps/4 equal steps, its zero end at
    ±ZERO_FRACTION·T on the side it comes from.

    Returns
    -------
    torques : ndarray (steps + 8,)
        N·m, the ±3 % of T (the lost-motion torque) among them; every branch starts at its own first point (a branch's start is the previous branch's
        end except at the zeros, which are solved on both sides).
    branch : ndarray (steps + 8,) of int
    """
    if steps < 8 or steps % 4:
        raise ValueError(f"a hysteresis loop needs a multiple of 4 load steps, at least 8; got {steps}")
    m = steps // 4
    T = float(torque_Nm)
    eps = ZERO_FRACTION * T
    up = np.linspace(0.0, T, m + 1)
    up[0] = eps
    up = np.unique(np.concatenate([up, [LOST_MOTION_FRACTION * T]]))   # the lost-motion torque solved, not interpolated
    if T < 0:
        up = up[::-1]
    torques = [up, up[::-1], -up, -up[::-1]]
    branch = [np.full(len(up), k) for k in range(4)]
    return np.concatenate(torques), np.concatenate(branch)


def _slip(torque_from: float, torque_to: float) -> int:
    """+1 when the step turns the carrier in the positive sense (the torque increases), −1 else."""
    return 1 if torque_to >= torque_from else -1


def loop_at_torques(stage: ReducerStage, theta: float, torques: Sequence[float] | np.ndarray, friction: float,
                    slips: Sequence[int] | np.ndarray | None = None, start: PairResult | None = None, start_torque=...,
                    g_cache: dict | None = None) -> tuple[np.ndarray, np.ndarray, list[PairResult]]:
    """Solve the stage at crank angle θ (rad) at each torque in turn (N·m), each step started from
    the step before it (the first from ``start``, if given), with the pins' friction ``friction``
    sliding as ``slips`` says (+1/−1 per step; default: the way the torque moves from the step
    before, the first step as a loading one). ``start_torque``: the torque ``start`` was solved at
    (default: the torque it carries); None when ``start`` comes from another crank angle (a step
    that does not settle from it is then solved cold). ``g_cache``: the contact compliance kept
    between the steps (one per crank angle; a new one by default), so that the steps after the
    first do not build it again (:func:`rvfem.solve.contact.solve_bodies`).

    Returns the output rotation of each step (rad: the carrier rotation and the stage's series
    output compliances, :attr:`rvfem.solve.cycle.PairResult.output_rotation`), the Newton
    iterations and the pair results.
    """
    torques = np.asarray(torques, dtype=float)
    if slips is None:
        loading = [_slip(a, b) for a, b in zip(np.concatenate([[0.0], torques[:-1]]), torques)]
        loading[0] = 1 if torques[0] >= 0 else -1
        slips = loading
    cache = {} if g_cache is None else g_cache
    pairs: list[PairResult] = []
    before = None if start is None else (_pair_torque_Nm(stage, start) if start_torque is ... else start_torque)
    for T, slip in zip(torques, slips):
        op = OperatingPoint(float(T), float(friction), int(slip) if friction > 0 else 0)
        pairs.append(_step(stage, theta, op, pairs[-1] if pairs else start, before, cache))
        before = float(T)
    rotation = np.array([p.output_rotation for p in pairs])
    iterations = np.array([p.results[0].solution.iterations for p in pairs])
    return rotation, iterations, pairs


MAX_SUBSTEPS = 6
"""How many times a load step whose active set does not settle is halved (:func:`_step`)."""


def _pair_torque_Nm(stage: ReducerStage, pair: PairResult) -> float:
    """The output torque a solved pair carries, N·m."""
    return nm_from_nmm(float(np.sum(pair.torque_Nmm))) * stage.first.case.loads.discs / stage.discs


def _step(stage: ReducerStage, theta: float, op: OperatingPoint, start: PairResult | None,
          before: float | None, cache: dict, depth: int = 0) -> PairResult:
    """One load step from ``start`` (solved at the torque ``before``, N·m). A step whose active
    set does not settle (a clearance that closes within the step can make the iteration cycle)
    is solved cold if ``start`` is another crank angle's, else reached through the torque halfway (the geometric mean towards
    zero torque), up to :data:`MAX_SUBSTEPS` times."""
    try:
        return solve_pair(stage, theta, start, op=op, g_cache=cache)
    except ContactError:
        if start is None or depth >= MAX_SUBSTEPS:
            raise
        if before is None or abs(before - op.torque_Nm) <= 1e-12 * abs(op.torque_Nm):
            return solve_pair(stage, theta, None, op=op, g_cache=cache)   # a start from another angle: cold
    a, b = before, op.torque_Nm
    # towards the zero end the stage softens (a clearance opens): halve geometrically there
    mid = math.copysign(math.sqrt(a * b), b) if a * b > 0 and max(a / b, b / a) > 4.0 else 0.5 * (a + b)
    half = dataclasses.replace(op, torque_Nm=mid)
    log.debug("load step to %.4g N·m halved at %.2f°", op.torque_Nm, math.degrees(theta))
    mid_pair = _step(stage, theta, half, start, before, cache, depth + 1)
    return _step(stage, theta, op, mid_pair, half.torque_Nm, cache, depth + 1)


def hysteresis_loop(stage: ReducerStage, theta: float, torque_Nm: float, *, friction: float = 0.0,
                    steps: int = 40) -> HysteresisLoop:
    """The quasi-static hysteresis loop of the stage at crank angle θ (rad), the input locked.

    Parameters
    ----------
    stage : ReducerStage
        :func:`rvfem.solve.cycle.case_stage` of the case (both discs, crankshafts, support bearings).
    theta : float
        Crank angle held, rad.
    torque_Nm : float
        The loop's torque T (the rated torque), N·m.
    friction : float
        Coulomb coefficient at the pins; each step's friction opposes that step's sliding.
    steps : int
        Load steps (multiple of 4, ≥ 8): steps/4 per branch.
    """
    torques, branch = loop_torques(torque_Nm, steps)
    rotation = np.zeros(len(torques))
    iterations = np.zeros(len(torques), dtype=int)
    start = None
    cache: dict = {}
    for k in range(len(BRANCHES)):
        # each branch from its loaded end to its zero (the state of a step depends only on its
        # torque and its sliding direction, so the order is free): every step near zero torque,
        # where a clearance leaves the stage nearly a mechanism, starts from a loaded neighbour
        sel = np.flatnonzero(branch == k)
        sel = sel[np.argsort(-np.abs(torques[sel]), kind="stable")]
        r, it, pairs = loop_at_torques(stage, theta, torques[sel], friction,
                                       np.full(len(sel), BRANCH_SLIP[k]), start=start, g_cache=cache)
        rotation[sel], iterations[sel] = r, it
        start = pairs[0] if k % 2 == 0 else None
    log.info("hysteresis loop at %.2f°: %d steps, %d Newton iterations", math.degrees(theta),
             len(torques), int(iterations.sum()))
    return HysteresisLoop(float(theta), torques, rotation, branch, float(torque_Nm), float(friction), iterations)


# ------------------------------------------------------------------------------------------------
# Where the compliance sits
# ------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class ComplianceShares:
    """The share of the loop's elastic rotation each component carries.

    Attributes
    ----------
    rotation_arcmin : float
        a: the rotation between 3 % and 100 % of the torque on the loading branch (the rigidity's
        construction), arcmin.
    shares : dict
        component → (a − a_stiffened)/a.
    total : float
        Σ shares (1 for compliances in series; the rest is the components' interaction).
    """

    rotation_arcmin: float
    shares: dict
    total: float


def compliance_shares(stage: ReducerStage, theta: float, torque_Nm: float, friction: float = 0.0,
                      components: tuple[str, ...] | None = None) -> ComplianceShares:
    """Where the compliance sits (stiffen one component at a time, :func:`stiffened_stage`): the
    rotation a between 3 % and 100 % of ``torque_Nm`` (N·m) at crank angle θ (rad) with each
    component :data:`STIFFEN` times stiffer, against the stage's own. ``components``: their names,
    default every component of the stage (:func:`rvfem.solve.stage_parts.component_names`); one the
    stage does not have is left out (logged)."""
    torques = np.array([torque_Nm, 0.03 * torque_Nm])
    slips = np.ones(2, dtype=int)

    def rotation(s: ReducerStage) -> float:
        r, _, _ = loop_at_torques(s, theta, torques, friction, slips)
        return arcmin_from_rad(float(r[0] - r[1]))

    a = rotation(stage)
    shares = {}
    for c in component_names() if components is None else components:
        try:
            shares[c] = (a - rotation(stiffened_stage(stage, c))) / a
        except ValueError as exc:
            log.info("compliance share of %s left out: %s", c, exc)
    return ComplianceShares(a, shares, float(sum(shares.values())))


# ------------------------------------------------------------------------------------------------
# Transmission error over a revolution
# ------------------------------------------------------------------------------------------------


TE_LADDER = (1.0, 0.1, 0.01)
"""The torques (fractions of the loaded torque) a no-load TE solve steps down through before
ZERO_FRACTION (:func:`transmission_error`)."""


def transmission_error(stage: ReducerStage, thetas: np.ndarray, torque_Nm: float, friction: float = 0.0, *,
                       solve: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """The output's deviation from the ideal ratio at each crank angle (rad), at no load and at
    ``torque_Nm`` (N·m), rad.

    TE = θ_out − θ_in/i (Liu et al., *Degradation law analysis and life estimation of transmission
    accuracy of RV reducer based on tooth surface and bearing wear*, section 4): in the stage's frame
    the ideal output position at crank angle θ is the kinematic one of the nominal profile, so TE is
    the carrier rotation φ(θ) of the solve at that crank angle (:func:`te_at_angles`). Only the
    crank angles symmetry does not give are solved (:func:`te_plan`: the carrier rotation is
    unchanged by the turn and by the swap of the discs).

    Parameters
    ----------
    solve : callable, optional
        ``solve(angles)`` → (no load, loaded) at those crank angles, rad: how the angles of
        :func:`te_plan` are solved (default :func:`te_at_angles` on ``stage``; ``rvfem hysteresis
        --te`` shares them with a child process).

    Returns
    -------
    no_load, loaded : ndarray (n,)
        rad.
    """
    thetas = np.asarray(thetas, dtype=float)
    solve_at, source = te_plan(stage, thetas)
    if solve is None:
        no_load, loaded = te_at_angles(stage, thetas[solve_at], torque_Nm, friction)
    else:
        no_load, loaded = solve(thetas[solve_at])
    # the solved angles are the first len(solve_at) of thetas (symmetry_plan): index i is its own
    return np.array([no_load[i] for i, _, _ in source]), np.array([loaded[i] for i, _, _ in source])


def te_plan(stage: ReducerStage, thetas: np.ndarray) -> tuple[np.ndarray, list]:
    """The crank angles (indices into ``thetas``, rad) whose TE :func:`transmission_error` solves,
    and for every angle the solved one it repeats (:func:`rvfem.solve.cycle.symmetry_plan`: the
    carrier rotation repeats where the stage does, a turn by 2π/N and the pair swapped at π)."""
    return symmetry_plan(np.asarray(thetas, dtype=float), *stage_symmetry(stage))


def te_at_angles(stage: ReducerStage, thetas: np.ndarray, torque_Nm: float, friction: float = 0.0
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The carrier rotation at no load and at ``torque_Nm`` (N·m) at each crank angle (rad), rad:
    the angles one after the other, each solve started from the last one's contacts.

    No load: the stage solved at +ZERO_FRACTION·T (the profile's gaps, modification and pitch
    error, closed on the driving side: the kinematic TE), reached from the loaded solve through
    :data:`TE_LADDER` (a nearly unloaded stage is nearly a mechanism; from a loaded start its
    active set settles). The running stage's pins slide as the crank turns (``slip`` 0)."""
    T = float(torque_Nm)
    ladder = [T * f for f in TE_LADDER] + [ZERO_FRACTION * T]
    thetas = np.asarray(thetas, dtype=float)
    prefetch_columns(stage, thetas, OperatingPoint(T, float(friction), 0))
    no_load, loaded = np.zeros(len(thetas)), np.zeros(len(thetas))
    start = None
    for i, theta in enumerate(thetas):
        r, _, pairs = loop_at_torques(stage, float(theta), ladder, friction, np.zeros(len(ladder), dtype=int),
                                      start=start, start_torque=None)
        loaded[i], no_load[i] = r[0], r[-1]
        start = pairs[0]
    return no_load, loaded


def rigid_kinematic_te(geometry, thetas: np.ndarray) -> np.ndarray:
    """The kinematic TE of a rigid stage (rad): the carrier rotation, positive, at which the first
    pin gap closes with the disc turning rigidly with the carrier about the reducer axis O (at
    −e·u(θ) in the disc frame; the eccentrics held): min over the pins with a positive lever of
    gap_j / ((ẑ × (x_j − O))·n_j), x_j the contact point, n_j the flank's outward normal. The
    independent reference of :func:`transmission_error` at no load in the stiff limit (no clearance
    in the bearings)."""
    e = geometry.case.cycloid.eccentricity
    out = []
    for theta in np.asarray(thetas, dtype=float):
        pc = pin_profile_contacts(geometry, float(theta))
        axis = -e * np.array([math.cos(theta), math.sin(theta)])
        x, n = np.asarray(pc.point) - axis, np.asarray(pc.normal)
        lever = x[:, 0] * n[:, 1] - x[:, 1] * n[:, 0]
        ok = lever > 1e-9 * np.abs(lever).max()
        out.append(float(np.min(np.asarray(pc.gap)[ok] / lever[ok])))
    return np.array(out)


def te_orders(te: np.ndarray, thetas: np.ndarray, count: int = 8) -> list[tuple[int, float]]:
    """The largest orders of a TE sampled at equally spaced crank angles over one revolution: (order
    per crank revolution, amplitude in the units of ``te``), largest first, the mean left out."""
    te = np.asarray(te, dtype=float)
    n = te.size
    amp = np.abs(np.fft.rfft(te - te.mean())) * 2.0 / n
    if n % 2 == 0:
        amp[-1] /= 2.0
    span = float(thetas[-1] - thetas[0]) * n / max(n - 1, 1)
    per_rev = 2.0 * math.pi / span if span > 0 else 1.0
    order = np.argsort(-amp[1:])[:count] + 1
    return [(int(round(k * per_rev)), float(amp[k])) for k in order]
