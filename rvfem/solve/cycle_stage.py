"""The reducer stage: one disc, or two discs on one carrier and crankshafts, and its cycle.

A two-disc RV reducer is not one disc on rigid eccentrics with half the torque. Disc B runs 180°
behind disc A and the two discs share

1. the **carrier**: one rotation φ, so the output torque divides between the discs by their
   stiffness at each crank angle (T_A + T_B = T_out, not T_out/2 each), and
2. every **crankshaft**: a beam on two support bearings in the carrier's end plates carrying both
   discs' eccentrics. The eccentric of crank i under disc k moves by
   w_k,i = −Σ_k' f_kk' · F_k',i (F the bearing force on disc k', so −F acts on the eccentric),
   the same 2×2 influence matrix f (mm/N) in x and y (a round shaft on radially isotropic
   bearings). The part of the two discs' forces that is common on a crank (the torque-carrying
   tangential force) sees the soft path through the support bearings; the part that is opposite
   (the rotating pin-force components, ≈ 180° apart) sees the much stiffer bending between them.

Both couplings enter the condensed contact problem of :func:`rvfem.solve.contact.solve_bodies`: the
discs are two bodies with their own contacts and rigid motions, one carrier unknown, and the
crankshafts add the compliance H[c, c'] = f_kk' · (d_c · d_c') between bearing contacts c, c' of
the same crank (d the unit force direction on the disc, in the carrier frame).

**Disc B.** Disc B is the same part and mesh as disc A, but it cannot sit in the same orientation:
seen from disc B the pin ring is the one disc A would see at θ + 180° turned by half a pin pitch,
which is disc A's view at θ + 180° − β turned as a whole by β = π/Zc (for a one-tooth difference;
β = (2π − π·(Zp − Zc))/Zc in general, 0 for an even tooth difference). So disc B's teeth sit half a
tooth pitch from disc A's against the bores and holes. Two ways to model it:

* ``"same_as_first"`` (default): disc B is disc A at θ + 180° (same mesh, same compliance). This
  misplaces disc B's teeth by β against its bores and holes; in exchange one pair solve gives
  both discs' states (disc A at θ and at θ + 180°), so 180° of pair solves make the full cycle.
* ``"half_pitch"``: disc B is a second model whose bores and holes are turned by −β against the
  teeth, solved at θ + 180° − β and turned back by β: the exact geometry, at the price of a second
  mesh, factorisation and compliance and 360° of pair solves.

The difference between the two on the shipped RV-40E pair is measured in
``benchmarks/bench_reducer.py`` (see docs/theory.md).

**Torque convention.** The carrier with its eccentrics (and, with the input locked, the discs in
the stiff limit) turns about the **reducer axis** O, which sits at −e·u(θ) in the disc frame: its
rotation φ moves eccentric i by φ·ẑ×(c_i − O), and its conjugate load is the output torque as a
moment about O (T_out for two discs, T_out/discs for one). Every pin normal passes through the
pitch point, e·Zp from O and e·Zc from the disc centre, so the pins' moment about each disc's own
centre is Zc/Zp of that disc's share of T_out (each disc's ``torque_Nmm``, a moment about O): the
pin and bearing forces are Zc/Zp of the handbook's, which takes T/2 about the disc centre
(docs/theory.md § 6).

**Support-bearing clearance.** ``eccentric_play_mm`` (half of ``crank_support.radial_clearance``)
lets each crankshaft translate in its support bearings before they carry: in the stiff limit each
eccentric may move by that much more relative to the carrier, which the stage adds to every
roller's clearance (:func:`stage_contact_set`).

The crankshaft influence matrix comes from :func:`rvfem.fem.crankshaft.crankshaft_influence`.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from rvfem._arrays import single_threaded_blas
from rvfem.errors import CaseError
from rvfem.solve import contact
from rvfem.solve.contact import ContactSet
from rvfem.solve.cycle_angle import angle_result, solve_from_last
from rvfem.solve.cycle_contacts import contact_set, contact_sets
from rvfem.solve.cycle_symmetry import symmetry_plan, turn_result
from rvfem.solve.cycle_system import DiscSystem, OperatingPoint
from rvfem.units import nmm_from_nm

log = logging.getLogger(__name__)


SECOND_DISC_MODELS = ("same_as_first", "half_pitch")


def second_disc_phase(case) -> float:
    """β, rad: disc B seen from its bores is disc A at θ + π − β turned by β (module docstring).

    From Rp·u(2πj/Zp + θ·d/Zp) − e·u(θ) (d = Zp − Zc): disc B at crank angle θ sees the pins of
    crank angle θ + π with the ring turned back by π·d/Zp; a rotation β of the whole picture with
    β·Zc ≡ −π·d (mod 2π) absorbs it. The smallest non-negative solution is returned.
    """
    zp, zc = case.pins.count, case.cycloid.teeth
    d = zp - zc
    return float(np.mod((2.0 * math.pi - math.pi * d) / zc, 2.0 * math.pi / zc))


# ------------------------------------------------------------------------------------------------
# The stage and one pair of discs
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ReducerStage:
    """Everything of a reducer stage that does not change with the crank angle.

    Attributes
    ----------
    first : rvfem.solve.cycle.DiscSystem
        Disc A.
    second : rvfem.solve.cycle.DiscSystem or None
        Disc B's model; None for a single disc, ``first`` itself for ``"same_as_first"``.
    second_phase : float
        β, rad: disc B is solved at θ + π − β and its results turned by β (0 for
        ``"same_as_first"``).
    influence : ndarray (discs, discs) or None
        Crankshaft influence matrix, mm/N (None: rigid eccentrics).
    output_compliances : tuple of (str, float)
        Torsional compliances in series with the stage in the output's load path, each as
        ``(component name, compliance in rad/(N·mm))``: a part of the reducer outside the discs'
        contact problem (a stage component, :mod:`rvfem.solve.stage_parts`) whose rotation under
        the output torque adds to the carrier rotation (:attr:`PairResult.output_rotation`). They
        change no contact force: the output torque passes through them whole. Empty by default.
    eccentric_play_mm : float
        Radial play of each crankshaft in its support bearings, mm (half their radial clearance,
        ``crank_support.radial_clearance``): added to the clearance of every roller of the crank
        bearings (:func:`stage_contact_set`), so that in the stiff limit each eccentric moves that
        much relative to the carrier before the load path closes. 0 by default.

    A new part of the stage is a new field with a default: the stage is changed by
    :func:`dataclasses.replace` (never rebuilt positionally), so every other field is carried
    through.
    """

    first: DiscSystem
    second: DiscSystem | None
    second_phase: float
    influence: np.ndarray | None
    output_compliances: tuple[tuple[str, float], ...] = ()
    eccentric_play_mm: float = 0.0

    @property
    def discs(self) -> int:
        return 1 if self.second is None else 2

    @property
    def systems(self) -> list[DiscSystem]:
        """The disc models: disc A's, and disc B's (which may be disc A's itself)."""
        return [self.first] if self.second is None else [self.first, self.second]

    def carrier_torque_Nmm(self, op: OperatingPoint) -> float:
        """Torque on the carrier from the discs modelled here at the operating point, a moment about
        the reducer axis, N·mm: T_out for two discs, T_out/discs for one disc (the handbook's equal
        share)."""
        return nmm_from_nm(op.torque_Nm) * self.discs / self.first.case.loads.discs

    @property
    def mirrored_pairs(self) -> bool:
        """True when the pair at θ + π is the pair at θ with the discs swapped (disc B is disc A
        at θ + π and the crankshaft is symmetric), so that 180° of pairs make a cycle."""
        if self.second is not self.first or self.second_phase != 0.0:
            return False
        f = self.influence
        return f is None or bool(np.isclose(f[0, 0], f[1, 1], rtol=1e-12, atol=0.0))

    @property
    def output_compliance_rad_per_Nmm(self) -> float:
        """The series output compliances together, rad/(N·mm) (0 without any)."""
        return float(sum(c for _, c in self.output_compliances))

    def output_compliance(self, name: str) -> float | None:
        """The series output compliance of the component ``name``, rad/(N·mm), or None if the stage
        has none of it."""
        return dict(self.output_compliances).get(name)

    def with_output_compliance(self, name: str, rad_per_Nmm: float) -> "ReducerStage":
        """The stage with the component ``name``'s series output compliance set to ``rad_per_Nmm``
        (rad/(N·mm), ≥ 0; added after the others, or replacing its own), every other field carried
        through."""
        c = float(rad_per_Nmm)
        if not (math.isfinite(c) and c >= 0.0):
            raise ValueError(f"the output compliance of {name!r} must be finite and non-negative, got {rad_per_Nmm!r}")
        others = tuple((n, v) for n, v in self.output_compliances if n != name)
        if len(others) == len(self.output_compliances):
            return dataclasses.replace(self, output_compliances=others + ((name, c),))
        return dataclasses.replace(self, output_compliances=tuple((n, c if n == name else v)
                                                                  for n, v in self.output_compliances))

    def describe(self) -> str:
        """What the stage model is, for the report and the screen."""
        if self.discs == 1:
            disc = "one disc carrying T/discs (the handbook's equal share)"
        else:
            disc = ("two discs sharing one carrier (the torque divides by their stiffness); disc B "
                    + ("modelled as disc A at θ + 180°" if self.second is self.first and self.second_phase == 0
                       else "with its teeth half a pitch from disc A's against the bores and holes"))
        crank = ("crank support rigid: upper bound of the flexibility effect" if self.influence is None
                 else "crankshafts as beams on elastic support bearings")
        if self.eccentric_play_mm > 0:
            crank += f" with {1e3 * self.eccentric_play_mm:.3g} µm radial play in the support bearings"
        springs = "".join(f"; {name} in series with the output ({1.0 / c:.4g} N·mm/rad)" if c > 0
                          else f"; {name} without compliance under the output torque"
                          for name, c in self.output_compliances)
        return f"{disc}; {crank}{springs}"


def _rotation(beta: float) -> np.ndarray:
    c, s = math.cos(beta), math.sin(beta)
    return np.array([[c, -s], [s, c]])


def build_stage(system, *, discs: int, influence: np.ndarray | None, second=None,
                second_disc: str = "same_as_first") -> ReducerStage:
    """A reducer stage of a disc model (:func:`rvfem.solve.stage_parts.case_stage` builds the one the case
    asks for).

    Parameters
    ----------
    system : DiscSystem
        Disc A.
    discs : {1, 2}
        1: one disc with the equal torque share T_out/discs; 2: both discs on one carrier.
    influence : ndarray or None
        Crankshaft influence matrix (mm/N, :func:`rvfem.fem.crankshaft.crankshaft_influence`); None for
        rigid eccentrics.
    second : DiscSystem, optional
        Disc B's model for ``second_disc = "half_pitch"``: the case with its cranks and holes turned
        by −β (:func:`half_pitch_case`), meshed and built like disc A.
    second_disc : {"same_as_first", "half_pitch"}
    """
    case = system.case
    if discs == 1:
        f = None if influence is None else np.asarray(influence, dtype=float)[:1, :1]
        return ReducerStage(first=system, second=None, second_phase=0.0, influence=f)
    if discs != 2:
        raise CaseError(f"a reducer stage has one or two discs, got {discs}")
    if case.loads.discs != 2:
        raise CaseError("two discs sharing the carrier need loads.discs = 2")
    if second_disc not in SECOND_DISC_MODELS:
        raise CaseError(f"second disc model must be one of {', '.join(SECOND_DISC_MODELS)}, got {second_disc!r}")
    f = None if influence is None else np.asarray(influence, dtype=float)
    if f is not None and f.shape != (2, 2):
        raise CaseError("the crankshaft influence matrix of two discs must be 2×2")
    if second_disc == "same_as_first":
        return ReducerStage(first=system, second=system, second_phase=0.0, influence=f)
    if second is None:
        raise CaseError("second_disc = 'half_pitch' needs the second disc's model (see half_pitch_case)")
    return ReducerStage(first=system, second=second, second_phase=second_disc_phase(case), influence=f)


def single_disc_stage(system) -> ReducerStage:
    """One disc carrying T_out/discs on rigid eccentrics: the handbook's model and rvfem 0.1's."""
    return build_stage(system, discs=1, influence=None)


def half_pitch_case(case):
    """Disc B's case for the exact model: cranks (and the holes that follow them) turned by −β.

    Every hole table is turned by its hole shape (:meth:`rvfem.geometry.HoleShape.turned`: holes
    placed by an explicit ``angle_offset_deg`` are turned too); everything else is unchanged.
    Solved at θ + π − β and turned back by β, this is disc B with its teeth half a tooth pitch from
    disc A's against the bores and holes.
    """
    beta = math.degrees(second_disc_phase(case))
    cranks = dataclasses.replace(case.cranks, angles_deg=tuple(a - beta for a in case.cranks.angles_deg))
    changes = {"cranks": cranks}
    for shape, table in case.hole_shapes():
        changes[shape.name] = shape.turned(table, beta)
    return case.replace(**changes)


@dataclass(frozen=True)
class PairResult:
    """One crank angle of the stage.

    Attributes
    ----------
    results : tuple of rvfem.solve.cycle.AngleResult
        Disc A at θ (and disc B, in its own model's frame and crank angle).
    bearing_forces : ndarray (discs, N, 2)
        Bearing forces on each disc in the carrier frame, N.
    torque_Nmm : ndarray (discs,)
        Each disc's share of the carrier torque, N·mm.
    eccentric_displacement : ndarray (discs, N, 2)
        Displacement of each eccentric relative to the carrier (crankshaft deflection), mm.
    output_rotation : float
        The output's rotation, rad: the carrier rotation of disc A's solve plus the rotation of the
        stage's series output compliances under the output torque
        (:attr:`ReducerStage.output_compliances`); the carrier rotation itself without them.
    """

    results: tuple
    bearing_forces: np.ndarray
    torque_Nmm: np.ndarray
    eccentric_displacement: np.ndarray
    output_rotation: float


def _disc_angles(stage: ReducerStage, theta: float) -> list[float]:
    """The crank angle of each disc's own frame at the stage's crank angle θ (rad): disc A at θ,
    disc B at θ + π − its phase."""
    return [theta] if stage.second is None else [theta, theta + math.pi - stage.second_phase]


def stage_contact_set(stage: ReducerStage, system, theta: float, op: OperatingPoint
                      ) -> tuple[ContactSet, list[str]]:
    """The contacts of ``system`` (one of the stage's discs) at crank angle θ (rad) as the stage
    solves them: :func:`rvfem.solve.cycle_contacts.contact_set` with the stage's support-bearing
    play (:attr:`ReducerStage.eccentric_play_mm`) added to every roller's clearance. The play of
    a crankshaft in its supports and that of a bore on its eccentric add up (the set of positions
    of each is a disc of its radius, their sum a disc of the sum of the radii)."""
    cset, names = contact_set(system, theta, op)
    play = stage.eccentric_play_mm
    if play == 0.0:
        return cset, names
    zp = system.case.pins.count
    offset = np.array(cset.offset, dtype=float)
    offset[zp:] -= play
    return dataclasses.replace(cset, offset=offset), names


def _bodies(stage: ReducerStage, theta: float, op: OperatingPoint):
    systems = stage.systems
    thetas = _disc_angles(stage, theta)
    phases = [0.0, stage.second_phase][:len(systems)]
    sets = [stage_contact_set(stage, s, th, op) for s, th in zip(systems, thetas)]
    return systems, thetas, phases, sets


def _directions(system, cset) -> np.ndarray:
    """Unit force on the disc per unit λ of each contact, (n_contacts, 2), disc frame."""
    WL = cset.load_weights
    return np.asarray(WL.T @ system.interface.resultants[:, :2])


def coupling_matrix(stage: ReducerStage, systems, phases, sets) -> np.ndarray | None:
    """H[c, c'] = f_kk' · (d_c · d_c') for the bearing contacts c (disc k), c' (disc k') of the
    same crank, d in the carrier frame (mm/N); None for rigid eccentrics."""
    if stage.influence is None:
        return None
    zp = stage.first.case.pins.count
    dirs, crank, disc = [], [], []
    for k, (s, beta, (cset, names)) in enumerate(zip(systems, phases, sets)):
        d = _directions(s, cset) @ _rotation(beta).T
        b = np.full(len(names), -1)
        b[zp:] = cset.bearing[zp:]
        dirs.append(d)
        crank.append(b)
        disc.append(np.full(len(names), k))
    d = np.vstack(dirs)
    crank_of = np.concatenate(crank)
    disc_of = np.concatenate(disc)
    same = (crank_of[:, None] == crank_of[None, :]) & (crank_of[:, None] >= 0)
    f = stage.influence[disc_of[:, None], disc_of[None, :]]
    return np.where(same, f * (d @ d.T), 0.0)


def _pair_contacts(stage: ReducerStage, systems, phases, sets, cache: dict | None) -> tuple:
    """The contact names of a pair solve and its crankshaft coupling (:func:`coupling_matrix`),
    kept in ``cache`` (a solve's ``g_cache``) for the same contact sets (by identity) of the same
    stage: the load steps of a hysteresis loop solve one crank angle's contacts again and again."""
    key = ("pair contacts", id(stage)) + tuple(id(c) for c, _ in sets)
    entry = None if cache is None else cache.get(key)
    if entry is not None and entry[0] is stage and all(a is c for a, (c, _) in zip(entry[1], sets)):
        return entry[2], entry[3]
    names = [f"disc {'AB'[k]} {n}" if len(sets) > 1 else n for k, (_, ns) in enumerate(sets) for n in ns]
    H = coupling_matrix(stage, systems, phases, sets)
    if cache is not None:
        cache[key] = (stage, [c for c, _ in sets], names, H)
    return names, H


def solve_pair(stage: ReducerStage, theta: float, start: PairResult | None = None, *,
               op: OperatingPoint | None = None, g_cache: dict | None = None) -> PairResult:
    """Solve the stage at crank angle θ (rad) and the operating point ``op`` (default the case's):
    disc A at θ with disc B at θ + 180°. ``g_cache`` keeps the contact compliance between solves
    of the same crank angle (:func:`rvfem.solve.contact.solve_bodies`). BLAS runs single-threaded
    in it (:func:`rvfem._arrays.single_threaded_blas`: its dense systems are small), also when it is
    called outside a load cycle (hysteresis loops, TE, operating points)."""
    with single_threaded_blas():
        return _solve_pair(stage, theta, start, op, g_cache)


def _solve_pair(stage: ReducerStage, theta: float, start: PairResult | None, op: OperatingPoint | None,
                g_cache: dict | None) -> PairResult:
    op = OperatingPoint.of(stage.first.case) if op is None else op
    systems, thetas, phases, sets = _bodies(stage, theta, op)
    case = stage.first.case
    names, H = _pair_contacts(stage, systems, phases, sets, g_cache)
    sols = contact.solve_bodies(
        [contact.Body(c, s.interface, s.compliance) for s, (c, _) in zip(systems, sets)], stage.carrier_torque_Nmm(op),
        coupling=H, start=None if start is None else [r.solution for r in start.results],
        max_iterations=case.analysis.max_active_set_iterations,
        label=f"at crank angle {math.degrees(theta):.2f}° ", names=names, g_cache=g_cache)
    return _pair(stage, tuple(angle_result(s, th, sol, c)
                              for s, th, sol, (c, _) in zip(systems, thetas, sols, sets)), op)


def _pair(stage: ReducerStage, results: tuple, op: OperatingPoint) -> PairResult:
    """A PairResult from each disc's solution (disc A first) at the operating point ``op``: the
    series output compliances turn the output by their compliance times the whole output torque
    (which passes through them; the discs modelled may carry only their share of it)."""
    forces, torques, w = _stage_loads(stage, [r.bearing_forces for r in results],
                                      [r.solution.residual["torque_Nmm"] for r in results])
    rotation = results[0].carrier_rotation
    if stage.output_compliances:
        rotation = rotation + stage.output_compliance_rad_per_Nmm * nmm_from_nm(op.torque_Nm)
    return PairResult(results, forces, torques, w, output_rotation=float(rotation))


def _stage_loads(stage: ReducerStage, bearing_forces: list, torques: list):
    """The bearing forces of each disc in the carrier frame (discs, N, 2), the discs' torques and
    the eccentric displacements, from each disc's bearing forces in its own frame (disc A first)."""
    phases = [0.0, stage.second_phase][:len(bearing_forces)]
    forces = np.stack([f @ _rotation(beta).T for f, beta in zip(bearing_forces, phases)])
    w = np.zeros_like(forces)
    if stage.influence is not None:
        w = -np.einsum("kl,lnj->knj", stage.influence, forces)
    return forces, np.array(torques), w


def _first_and_loads(pair: PairResult) -> tuple:
    """Disc A's result and (bearing forces, torques, eccentric displacements) of a pair."""
    return pair.results[0], (pair.bearing_forces, pair.torque_Nmm, pair.eccentric_displacement)


def _turned_bearing_forces(result, k: int, order: int) -> np.ndarray:
    """The bearing forces (N, 2) of ``result`` turned by k·2π/N: bearing i's force, turned, is
    bearing i + k's (the same as :func:`rvfem.solve.cycle.turn_result` gives, to round-off)."""
    return np.roll(result.bearing_forces @ _rotation(2.0 * math.pi * k / order).T, k, axis=0)


# ------------------------------------------------------------------------------------------------
# A full cycle
# ------------------------------------------------------------------------------------------------


def _prefetch_stage(stage: ReducerStage, systems: list, thetas: np.ndarray, solve_at, source, step: float,
                    op: OperatingPoint) -> None:
    """Build the contacts of every angle a disc is solved at and of every angle disc A is turned to,
    in one sweep per system, and compute the compliance columns the cycle will likely need
    (:func:`likely_columns`) in one parallel sweep per system."""
    wanted: list[list[float]] = [[] for _ in systems]
    for i, swap, k in source:
        own = _disc_angles(stage, float(thetas[i]))
        if (swap, k) == (0, 0):
            for d in range(len(systems)):
                wanted[d].append(own[d])
        else:
            wanted[0].append(own[swap] + k * step)
    for d, s in enumerate(systems):
        contact_sets(s, wanted[d], op)           # the solved angles are among them (source[i] = i)
    for s in {id(s): s for s in systems}.values():
        ks = [k for k, t in enumerate(systems) if t is s]
        sets = [contact_set(systems[k], _disc_angles(stage, float(thetas[i]))[k], op)[0]
                for i in solve_at for k in ks]
        s.compliance.ensure(likely_columns(s, sets, stage.carrier_torque_Nmm(op)))


def stage_symmetry(stage: ReducerStage) -> tuple[int, bool]:
    """(N, mirrored) of a stage for :func:`rvfem.solve.cycle.symmetry_plan`: its results repeat,
    turned, every 2π/N (N the smaller rotation symmetry of its discs) and, with two discs mirrored
    at π, with the discs swapped every π."""
    return min(s.symmetry for s in stage.systems), stage.discs == 2 and stage.mirrored_pairs


def prefetch_columns(stage: ReducerStage, thetas, op: OperatingPoint, torques_Nmm=None) -> None:
    """Build the contacts of both discs at the stage's crank angles ``thetas`` (rad) in one sweep
    per disc model, and compute the compliance columns solves there will likely need
    (:func:`likely_columns`, for each carrier torque in ``torques_Nmm``, N·mm; default the
    operating point's) in one parallel sweep per model, instead of a few at a time as each solve
    first needs them. For solves outside a load cycle at many crank angles (the transmission
    error over a revolution); columns missed here are still computed when first needed."""
    systems = stage.systems
    angles = [_disc_angles(stage, float(t)) for t in np.atleast_1d(thetas)]
    torques = [stage.carrier_torque_Nmm(op)] if torques_Nmm is None else list(torques_Nmm)
    for d, s in enumerate(systems):
        contact_sets(s, [a[d] for a in angles], op)
    for s in {id(s): s for s in systems}.values():
        ks = [k for k, t in enumerate(systems) if t is s]
        sets = [stage_contact_set(stage, systems[k], a[k], op)[0] for a in angles for k in ks]
        s.compliance.ensure(np.unique(np.concatenate([likely_columns(s, sets, T) for T in torques])))


def _stage_angle(stage: ReducerStage, pair: PairResult, swap: int, k: int, theta: float, order: int,
                 op: OperatingPoint) -> tuple:
    """Disc A's result at θ and (bearing forces, torques, eccentric displacements) of the stage,
    from the solved ``pair`` that symmetry maps onto θ: itself, its discs swapped (``swap``: the
    mirrored pair at θ + π) and/or turned by ``k`` steps of 2π/N."""
    src = pair.results[::-1] if swap else pair.results      # mirrored pair: disc B is disc A at θ + π
    if (swap, k) == (0, 0):
        return _first_and_loads(pair)
    # disc A's solution turned by k steps (its contacts checked against the turned ones); disc B,
    # which may land at θ + π − 2π when the discs are swapped (the same state, the cycle being
    # 2π-periodic: roller_angles), enters only through its bearing forces and torque, turned and
    # unchanged
    system = stage.first
    try:
        step = 2.0 * math.pi / order
        turned_theta = src[0].theta + k * step
        first = turn_result(system, src[0], k, stage_contact_set(stage, system, turned_theta, op)[0], op)
        loads = _stage_loads(stage, [first.bearing_forces] + [_turned_bearing_forces(r, k, order) for r in src[1:]],
                             [r.solution.residual["torque_Nmm"] for r in src])     # turning keeps torques
    except ValueError as exc:
        log.warning("%s; solving the pair at %.2f° directly", exc, math.degrees(theta))
        first, loads = _first_and_loads(solve_pair(stage, theta, pair, op=op))
    if abs(first.theta - theta) > 1e-9:
        raise RuntimeError(f"symmetry plan lands at {first.theta} instead of {theta}")
    return first, loads


def solve_stage_cycle(stage: ReducerStage, thetas: np.ndarray, op: OperatingPoint, progress=None):
    """Solve the stage at every crank angle at the operating point ``op``, each pair started from
    the ones before it (:func:`rvfem.solve.cycle_angle.solve_from_last`). One disc is a stage with one body.

    Only the angles that symmetry does not give are solved (:func:`rvfem.solve.cycle.symmetry_plan`):
    with :attr:`ReducerStage.mirrored_pairs` the pair at θ + 180° is the pair at θ with the discs
    swapped; with N-fold symmetric discs the pair at θ + 360°/N is the pair at θ turned
    (:func:`rvfem.solve.cycle.turn_result`). ``progress(done, n)`` counts the crank angles of disc A
    obtained so far.

    Returns
    -------
    results : list of rvfem.solve.cycle.AngleResult
        Disc A at every θ.
    extras : dict
        ``disc_torque_Nmm`` (n, discs), ``disc_bearing_forces`` (n, discs, N, 2) in the carrier
        frame, ``eccentric_displacement`` (n, discs, N, 2), ``pair_solves`` (int), ``stage`` (the
        stage's description), ``prefetch_seconds`` (the compliance columns computed before).
    """
    thetas = np.asarray(thetas, dtype=float)
    n = len(thetas)
    order, mirrored = stage_symmetry(stage)
    solve_at, source = symmetry_plan(thetas, order, mirrored)
    step = 2.0 * math.pi / order

    t0 = time.perf_counter()
    _prefetch_stage(stage, stage.systems, thetas, solve_at, source, step, op)
    t_prefetch = time.perf_counter() - t0
    log.info("stage compliance prefetch %.2f s", t_prefetch)
    pairs: list[PairResult] = []
    for i in solve_at:
        pairs.append(solve_from_last(lambda start: solve_pair(stage, float(thetas[i]), start, op=op), pairs[-2:]))
        if progress is not None:
            progress(len(pairs) * n // len(solve_at), n)
    results, torque, forces, w = [], [], [], []
    for j, (i, swap, k) in enumerate(source):
        first, loads = _stage_angle(stage, pairs[i], swap, k, float(thetas[j]), order, op)
        results.append(first)
        forces.append(loads[0])
        torque.append(loads[1])
        w.append(loads[2])
    extras = {
        "disc_torque_Nmm": np.array(torque),
        "disc_bearing_forces": np.array(forces),
        "eccentric_displacement": np.array(w),
        "pair_solves": len(solve_at),
        "stage": stage.describe(),
        "crankshaft_influence": stage.influence,
        "prefetch_seconds": t_prefetch,
    }
    return results, extras


def likely_columns(system: DiscSystem, sets: list[ContactSet], torque: float) -> np.ndarray:
    """Interface columns the load cycle will need, to compute them in one parallel sweep.

    Every roller and bearing column, and those of the pins that touch (gap ≤ 1 µm) on the side
    that resists the torque (its sign; N·mm) with a margin. Columns missed here are computed
    when first needed, at a higher cost per column (small batches, one thread).
    """
    T = torque
    zp = system.case.pins.count
    cols = []
    for cset in sets:
        W = cset.W.tocsc()
        moment = np.asarray(W.T @ system.interface.resultants[:, 2])[:zp]
        gap = np.where(cset.signorini[:zp], cset.gap0[:zp], -cset.offset[:zp])
        likely = np.ones(W.shape[1], dtype=bool)
        # a flexible disc also loads pins past the ends of the classical loaded arc, whose lever
        # arms are small or of the other sign (default fan-hole case: loaded pins up to 0.68 of
        # the largest arm on that side): keep those within half the largest arm, which leaves
        # about 8 % of the columns to be computed when first needed
        likely[:zp] = (gap <= 1e-3) & (moment * np.sign(T) <= 0.5 * np.abs(moment).max())
        cols.append(W[:, np.flatnonzero(likely)].indices)
    return np.unique(np.concatenate(cols))
