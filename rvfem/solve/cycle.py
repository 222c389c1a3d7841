"""The flexible load cycle of a reducer stage: the disc model of a case, one crank angle, the
stage (one disc, or two discs on one carrier with crankshafts) and a full crank revolution.

Typical use from a notebook::

    from rvfem.case.definition import load_case
    from rvfem.mesh import mesh_case
    from rvfem.solve.cycle import OperatingPoint, build_system, solve_angle, load_cycle

    case = load_case("cases/rv40e_fanholes.toml")
    system = build_system(case, mesh_case(case))
    one = solve_angle(system, theta=0.0)             # crank angle in rad
    cycle = load_cycle(system)                       # 0…360° at the case's angle step and torque
    reverse = load_cycle(system, op=OperatingPoint(-412.0, 0.05))   # same system, reversed torque

The stiffness of the disc is assembled and factorised once (:func:`build_system`); every crank
angle and every operating point (:class:`OperatingPoint`: torque, pin friction) reuses it through
the lazily filled column compliance of :mod:`rvfem.solve.contact`. One disc is a stage with one body:
every cycle is solved by :func:`solve_stage_cycle`.

The parts, from the bottom up: the disc model (:mod:`rvfem.solve.cycle_system`), the contact sets of a
crank angle and their cache (:mod:`rvfem.solve.cycle_contacts`), one crank angle
(:mod:`rvfem.solve.cycle_angle`), the symmetries of a cycle (:mod:`rvfem.solve.cycle_symmetry`) and
the reducer stage with its cycle (:mod:`rvfem.solve.cycle_stage`, where the two-disc stage is
described) and the stage the case asks for, built by its components (:mod:`rvfem.solve.stage_parts`).
This module drives a crank revolution with them (:func:`load_cycle`), holds its results
(:class:`CycleResult`, :class:`AngleLoads`) and displacement fields, and gives all their names.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from rvfem._arrays import max_load_index, single_threaded_blas
from rvfem.case.definition import Case
from rvfem.fem import nodal_stress_operator
from rvfem.geometry import crank_centres, load_cycle_angles
# The parts of the load cycle, each in its own module; this module is their public face
# (``cycle.X`` reaches every name it reached before they were split off).
from rvfem.solve.cycle_angle import AngleResult, angle_result, solve_angle, solve_from_last
from rvfem.solve.cycle_contacts import contact_set, contact_sets, pin_contacts, pin_contacts_many
from rvfem.solve.cycle_stage import (
    SECOND_DISC_MODELS,
    PairResult,
    ReducerStage,
    _rotation,
    build_stage,
    coupling_matrix,
    half_pitch_case,
    likely_columns,
    second_disc_phase,
    single_disc_stage,
    solve_pair,
    solve_stage_cycle,
)
from rvfem.solve.cycle_symmetry import (
    _contact_map,
    _permutation_map,
    symmetry_plan,
    turn_field,
    turn_result,
    turned_nodes,
)
from rvfem.solve.cycle_system import DiscSystem, OperatingPoint, build_system, scaled_system
from rvfem.solve.models import roller_angles
from rvfem.solve.stage_parts import case_stage
from rvfem.units import arcmin_from_rad, nm_from_nmm

__all__ = [
    "SECOND_DISC_MODELS",
    "ReducerStage",
    "PairResult",
    "build_stage",
    "case_stage",
    "single_disc_stage",
    "half_pitch_case",
    "second_disc_phase",
    "solve_pair",
    "solve_stage_cycle",
    "OperatingPoint",
    "DiscSystem",
    "AngleResult",
    "CycleResult",
    "build_system",
    "scaled_system",
    "contact_set",
    "solve_angle",
    "load_cycle",
    "displacement",
    "roller_angles",
]


def displacements(system: DiscSystem, results):
    """The displacement field of each result in turn (:func:`displacement`), solving each
    distinct solved angle once (all of them in one batched back-substitution): a result obtained
    by symmetry is its origin's field, turned."""
    origins, roots = _origins(system, results)
    batches = _root_fields(system, roots)
    cache = {}
    for root, k in origins:
        if id(root) not in cache:                # the next FIELD_BATCH solved angles at once
            batch, fields = next(batches)
            cache.update({id(r): u for r, u in zip(batch, fields.T)})
        yield turn_field(system, cache[id(root)], k)


def _origins(system: DiscSystem, results) -> tuple[list, list]:
    """``(solved result, turns)`` of each result (a result obtained by symmetry comes from its
    origin, turned) and the distinct solved results in the order they first come."""
    origins = [r.origin if r.origin is not None and system.node_rotation is not None else (r, 0)
               for r in results]
    return origins, list({id(root): root for root, _ in origins}.values())


def _root_fields(system: DiscSystem, roots: list):
    """``(batch, fields)`` for the solved results ``roots``, FIELD_BATCH at a time in order."""
    for lo in range(0, len(roots), FIELD_BATCH):
        batch = roots[lo:lo + FIELD_BATCH]
        yield batch, _solved_fields(system, batch)


FIELD_BATCH = 16
"""Solved angles whose displacement fields are back-substituted together (batched and threaded
like the compliance columns; bounded so that a cycle without symmetry does not hold hundreds of
fields at once)."""


def displacement(system: DiscSystem, result: AngleResult) -> np.ndarray:
    """Displacement field (n_dofs,) of the disc at a solved angle, mm (rigid motion included)."""
    if result.origin is not None and system.node_rotation is not None:
        root, k = result.origin
        return turn_field(system, displacement(system, root), k)
    return _solved_fields(system, [result])[:, 0]


def _solved_fields(system: DiscSystem, results: list[AngleResult]) -> np.ndarray:
    """Displacement fields (n_dofs, m) of solved angles, mm: the contact loads (friction
    included) back-substituted together, plus each angle's rigid motion."""
    f = system.interface.B @ np.stack([r.column_loads for r in results], axis=1)
    rigid = np.stack([r.rigid_motion for r in results], axis=1)
    return system.compliance.fields(np.asarray(f)) + system.rigid_modes @ rigid


@dataclass(frozen=True, eq=False)
class AngleLoads:
    """What the displacement field of an angle is made of (:func:`displacements` takes it as it
    takes an :class:`AngleResult`): small, and free of the contact laws, so that it can be sent to
    another process (the P2 stress recovery of :func:`rvfem.app.analysis.analyse`).

    Attributes
    ----------
    theta : float
        Crank angle, rad.
    column_loads : ndarray (n_columns,)
        ``W_load·λ``, N.
    rigid_motion : ndarray (3,)
    origin : (AngleLoads, int) or None
        As for :class:`AngleResult`.
    """

    theta: float
    column_loads: np.ndarray
    rigid_motion: np.ndarray
    origin: tuple | None = None

    @classmethod
    def of(cls, result: AngleResult, roots: dict | None = None) -> AngleLoads:
        """The loads of ``result``; ``roots`` (id of a result → its AngleLoads, filled here) makes
        results that share an origin share its AngleLoads too, so that :func:`displacements`
        solves it once."""
        roots = {} if roots is None else roots
        if id(result) not in roots:
            origin = None
            if result.origin is not None:
                root, k = result.origin
                origin = (cls.of(root, roots), k)
            roots[id(result)] = cls(float(result.theta), np.asarray(result.column_loads),
                                    np.asarray(result.rigid_motion), origin)
        return roots[id(result)]


@dataclass(frozen=True)
class CycleResult:
    """A full crank revolution (arrays indexed by angle first).

    Attributes
    ----------
    theta : ndarray (n,)
        Crank angles, rad.
    bearing_forces : ndarray (n, N, 2)
        Force of each bearing on the disc, N.
    roller_loads : ndarray (n, N, Z) or None
    pin_forces : ndarray (n, Zp)
    pins_in_contact : ndarray (n,)
    carrier_rotation : ndarray (n,)
        rad.
    equilibrium_residual : ndarray (n,)
        |ΣF| / Σ|λ| of the disc at each angle (dimensionless).
    iterations : ndarray (n,)
    fields : dict angle (rad) → displacement (n_dofs,)
        At the case's saved angles and the angle of the maximum bearing load.
    timings : dict
    von_mises_envelope : ndarray (n_vertices,) or None
        Largest vertex von Mises stress of every mesh vertex over all solved angles, MPa (with
        ``stress_envelope=True``); the same vertex stresses as :func:`rvfem.fem.stress_fields`.
    von_mises_envelope_theta : ndarray (n_vertices,) or None
        Crank angle at which each vertex reaches it, rad.
    signed_von_mises_max, signed_von_mises_min : ndarray (n_vertices,) or None
        Largest and smallest vertex von Mises stress with the sign of σxx + σyy over all solved
        angles, MPa (with ``stress_envelope=True``): the fatigue check's amplitude and mean
        (:func:`rvfem.evaluate.strength.fatigue_field`).
    solutions : tuple of AngleResult
        The full solution of every angle (any displacement field can be rebuilt exactly from it
        with :func:`displacement`).
    stage : str
        The reducer-stage model (:meth:`ReducerStage.describe`).
    disc_torque_Nmm : ndarray (n, discs) or None
        Each disc's share of the carrier torque (two discs sharing the carrier), N·mm; None for
        one disc with T/discs.
    disc_bearing_forces : ndarray (n, discs, N, 2) or None
        Bearing forces on disc A (at θ) and disc B (at θ + 180°), carrier frame, N.
    eccentric_displacement : ndarray (n, discs, N, 2) or None
        Eccentric displacements relative to the carrier (crankshaft deflection), mm.
    crankshaft_influence : ndarray (discs, discs) or None
        The stage's crankshaft influence matrix, mm/N (None: rigid eccentrics).
    """

    theta: np.ndarray
    bearing_forces: np.ndarray
    roller_loads: np.ndarray | None
    roller_angles: np.ndarray | None
    pin_forces: np.ndarray
    pins_in_contact: np.ndarray
    carrier_rotation: np.ndarray
    equilibrium_residual: np.ndarray
    iterations: np.ndarray
    fields: dict
    timings: dict
    von_mises_envelope: np.ndarray | None = None
    von_mises_envelope_theta: np.ndarray | None = None
    signed_von_mises_max: np.ndarray | None = None
    signed_von_mises_min: np.ndarray | None = None
    solutions: tuple = field(default=(), repr=False)
    stage: str = "one disc carrying T/discs (the handbook's equal share); crank support rigid: upper bound of the flexibility effect"
    disc_torque_Nmm: np.ndarray | None = None
    disc_bearing_forces: np.ndarray | None = None
    eccentric_displacement: np.ndarray | None = None
    crankshaft_influence: np.ndarray | None = None

    @property
    def bearing_loads(self) -> np.ndarray:
        """|F|, (n, N), N."""
        return np.linalg.norm(self.bearing_forces, axis=2)

    def torsional_stiffness_Nm_per_arcmin(self, torque_Nmm: float) -> float:
        """Mean disc torque / carrier rotation, N·m/arcmin."""
        phi = float(np.mean(np.abs(self.carrier_rotation)))
        return nm_from_nmm(abs(torque_Nmm)) / arcmin_from_rad(phi)


def cycle_angles(case: Case) -> np.ndarray:
    """Crank angles of a full revolution at the case's step (endpoint excluded), rad
    (:func:`rvfem.geometry.load_cycle_angles`)."""

    return load_cycle_angles(case.analysis.angle_step_deg)


def load_cycle(system: DiscSystem, thetas: np.ndarray | None = None, *, op: OperatingPoint | None = None,
               stage: ReducerStage | None = None, progress=None,
               saved_angles_deg: tuple[float, ...] | None = None,
               stress_envelope: bool = False) -> CycleResult:
    """Solve every crank angle of a revolution, each started from the ones before it
    (:func:`solve_from_last`).

    Parameters
    ----------
    system : DiscSystem
    thetas : ndarray, optional
        Crank angles, rad; default a full revolution at ``case.analysis.angle_step_deg``.
    op : OperatingPoint, optional
        Output torque and pin friction; default the case's (:meth:`OperatingPoint.of`). Cycles at
        other operating points reuse the system's factorisation, compliance columns and contact
        sets.
    stage : ReducerStage, optional
        The reducer-stage model (:func:`build_stage`); default the case's (:func:`case_stage`: two
        discs sharing the carrier for ``loads.discs = 2`` unless ``loads.torque_split = "equal"``,
        crankshafts from ``[crank_support]``). One disc with T/discs on rigid eccentrics is
        :func:`single_disc_stage`.
    progress : callable, optional
        Called as ``progress(i, n)`` after each solve (the CLI draws its progress bar with it).
    saved_angles_deg : tuple, optional
        Angles whose displacement fields are kept; default ``case.analysis.saved_angles_deg``
        (the nearest solved angle is used) plus the angle of the maximum bearing load.
    stress_envelope : bool
        Also track the largest vertex von Mises stress of every vertex over all angles: the
        fields of the distinct solved angles, back-substituted FIELD_BATCH at a time, and one
        sparse product per batch; turned angles reuse them.
    """
    case = system.case
    thetas = cycle_angles(case) if thetas is None else np.asarray(thetas, dtype=float)
    op = OperatingPoint.of(case) if op is None else op
    stage = case_stage(system) if stage is None else stage
    t0 = time.perf_counter()
    # the per-angle systems are small (~100 unknowns): threaded BLAS only adds overhead there
    # (benchmarks/README.md, "Load cycle"), so the cycle runs BLAS single-threaded
    with single_threaded_blas():
        results, extras = solve_stage_cycle(stage, thetas, op, progress)
        t_prefetch = extras.pop("prefetch_seconds")
        t_cycle = time.perf_counter() - t0
        t1 = time.perf_counter()
        envelope = envelope_theta = sv_max = sv_min = None
        if stress_envelope:
            envelope, envelope_theta, sv_max, sv_min = _von_mises_envelope(system, results)
        t_envelope = time.perf_counter() - t1

    bf = np.stack([r.bearing_forces for r in results])
    saved = case.analysis.saved_angles_deg if saved_angles_deg is None else saved_angles_deg
    keep = {int(np.argmin(np.abs(np.angle(np.exp(1j * (thetas - math.radians(a))))))) for a in saved}
    keep.add(max_load_index(bf)[0])
    t1 = time.perf_counter()
    fields = {float(thetas[k]): displacement(system, results[k]) for k in sorted(keep)}
    t_fields = time.perf_counter() - t1
    rollers = None if results[0].roller_loads is None else np.stack([r.roller_loads for r in results])
    rangles = None if results[0].roller_angles is None else np.stack([r.roller_angles for r in results])
    return CycleResult(
        theta=thetas,
        bearing_forces=bf,
        roller_loads=rollers,
        roller_angles=rangles,
        pin_forces=np.stack([r.pin_forces for r in results]),
        pins_in_contact=np.array([r.pins_in_contact for r in results]),
        carrier_rotation=np.array([r.carrier_rotation for r in results]),
        equilibrium_residual=np.array([r.solution.residual["relative"] for r in results]),
        iterations=np.array([r.solution.iterations for r in results]),
        fields=fields,
        timings={"cycle": t_cycle, "prefetch": t_prefetch, "fields": t_fields,
                 "stress_envelope": t_envelope,
                 "columns_solved": system.compliance.columns_solved,
                 "column_solve": system.compliance.solve_seconds,
                 "pair_solves": extras.pop("pair_solves", len(thetas))},
        von_mises_envelope=envelope,
        von_mises_envelope_theta=envelope_theta,
        signed_von_mises_max=sv_max,
        signed_von_mises_min=sv_min,
        solutions=tuple(results),
        **extras,
    )


def _von_mises_envelope(system: DiscSystem, results: list[AngleResult]) -> tuple[np.ndarray, ...]:
    """Largest vertex von Mises stress of every vertex over the solved angles (MPa), the angle
    at which it occurs (rad), and the largest and smallest signed von Mises stress (the von Mises
    stress with the sign of σxx + σyy, for the fatigue check of :mod:`rvfem.evaluate.strength`), MPa."""

    stress_op = nodal_stress_operator(system.model)
    nv = system.model.n_vertices
    envelope = np.full(nv, -np.inf)
    envelope_theta = np.zeros(nv)
    sv_max, sv_min = np.full(nv, -np.inf), np.full(nv, np.inf)
    origins, roots = _origins(system, results)
    solved = {}
    for batch, fields in _root_fields(system, roots):      # vertex von Mises of the solved angles
        sxx, syy, sxy = (stress_op @ fields).reshape(3, nv, len(batch))
        vm = np.sqrt(sxx * sxx - sxx * syy + syy * syy + 3.0 * sxy * sxy)
        sign = np.where(sxx + syy >= 0.0, 1.0, -1.0)
        solved.update({id(r): (vm[:, j].copy(), sign[:, j].copy()) for j, r in enumerate(batch)})
    turns = {}
    for r, (root, k) in zip(results, origins):
        vm, sign = solved[id(root)]
        if k:                              # von Mises is invariant: the values move with the disc
            if k not in turns:
                turns[k] = turned_nodes(system, k)[:nv]
            turned, turned_sign = np.empty(nv), np.empty(nv)
            turned[turns[k]] = vm
            turned_sign[turns[k]] = sign
            vm, sign = turned, turned_sign
        higher = vm > envelope
        envelope[higher] = vm[higher]
        envelope_theta[higher] = r.theta
        np.maximum(sv_max, sign * vm, out=sv_max)
        np.minimum(sv_min, sign * vm, out=sv_min)
    return envelope, envelope_theta, sv_max, sv_min
