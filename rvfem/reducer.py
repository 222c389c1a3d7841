"""The reducer stage: two discs on one carrier, crankshafts as beams.

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

Both couplings enter the condensed contact problem of :func:`rvfem.contact.solve_bodies`: the
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

**Torque convention.** As for one disc (docs/theory.md), each disc's torque is the moment of its
pin forces about its own centre, and the carrier rotation turns each disc's eccentric centres about
the disc centre; the handbook's ΣP_x·e·Zc = T/2 per disc is the equal split of this total.

**Crankshaft influence coefficients** (:func:`beam_influence`): a beam of span L between two elastic
supports with compliances c₁, c₂ (support bearing plus carrier in series), loaded at the eccentric
positions z_k. Bending (Roark's *Formulas for Stress and Strain*, simply supported beam with an
intermediate point load), shear (Timoshenko beam, shear coefficient κ = 6(1 + ν)/(7 + 6ν) of a
solid circular section after Cowper) and the rigid-body motion of the beam on its supports add up.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from .contact import Body, solve_bodies
from .errors import CaseError

log = logging.getLogger(__name__)

__all__ = [
    "beam_influence",
    "crankshaft_influence",
    "second_disc_phase",
    "ReducerStage",
    "PairResult",
    "build_stage",
    "default_stage",
    "solve_pair",
    "solve_stage_cycle",
    "SECOND_DISC_MODELS",
    "Attribution",
    "AttributionStep",
    "attribution",
    "case_step",
]

SECOND_DISC_MODELS = ("same_as_first", "half_pitch")


# ------------------------------------------------------------------------------------------------
# Crankshaft as a beam
# ------------------------------------------------------------------------------------------------


def beam_influence(span: float, positions, bending_stiffness: float, shear_stiffness: float | None = None,
                   support_compliance: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """Influence matrix of a beam on two elastic supports: deflection at z_i per unit load at z_j.

    Parameters
    ----------
    span : float
        L, distance between the two supports, mm.
    positions : sequence of float
        Load positions z measured from support 1, each in (0, L), mm.
    bending_stiffness : float
        EI, N·mm² (``inf`` for a rigid shaft).
    shear_stiffness : float, optional
        κ·G·A, N (None or ``inf``: no shear deflection).
    support_compliance : (float, float)
        Radial compliance of support 1 and support 2, mm/N (0: rigid).

    Returns
    -------
    ndarray (n, n)
        f_ij, mm/N, symmetric (Maxwell–Betti).

    Notes
    -----
    For a unit load at b (from support 1) and a point x ≤ b, with L the span:

    * bending, simply supported (Roark's *Formulas for Stress and Strain*, beam table, simple
      supports, intermediate load): y = (L − b)·x·(L² − (L − b)² − x²) / (6·L·EI); for x ≥ b the
      mirror image (x → L − x, b → L − b). At mid-span for a central load this is L³/(48·EI).
    * shear (Timoshenko): y = (L − b)·x / (L·κGA) for x ≤ b and b·(L − x) / (L·κGA) for x ≥ b
      (L/(4·κGA) at the centre for a central load).
    * supports: the reactions R₁ = (L − b)/L, R₂ = b/L deflect the supports by c₁R₁ and c₂R₂, and
      the beam follows the line between them: y = c₁R₁·(L − x)/L + c₂R₂·x/L.
    """
    L = float(span)
    z = np.asarray(positions, dtype=float)
    if not (L > 0 and np.all((z > 0) & (z < L))):
        raise ValueError("the load positions must lie strictly between the supports")
    c1, c2 = (float(c) for c in support_compliance)
    x = z[:, None]
    b = z[None, :]
    lo = np.minimum(x, b)                      # the point nearer support 1 ...
    hi = np.maximum(x, b)                      # ... and the one nearer support 2
    f = np.zeros((len(z), len(z)))
    if np.isfinite(bending_stiffness):
        f += (L - hi) * lo * (L * L - (L - hi) ** 2 - lo * lo) / (6.0 * L * bending_stiffness)
    if shear_stiffness is not None and np.isfinite(shear_stiffness):
        f += (L - hi) * lo / (L * shear_stiffness)
    f += c1 * (L - x) * (L - b) / L**2 + c2 * x * b / L**2
    return f


def crankshaft_influence(case) -> np.ndarray | None:
    """The crankshaft influence matrix of a case (mm/N, one row per disc), None for rigid support.

    From ``[crank_support]``: the direct ``influence_mm_per_N``, or a beam of ``span`` with the
    eccentrics at ``eccentric_positions``, EI from ``bending_stiffness_Nmm2`` or from
    ``journal_diameter`` (EI = E·π·d⁴/64; shear κGA with G = E/(2(1 + ν)), A = π·d²/4 and
    κ = 6(1 + ν)/(7 + 6ν) when ``shear`` is on), on supports of compliance
    1/k_support + 1/k_carrier per side.
    """
    cs = case.crank_support
    if cs is None:
        return None
    if cs.influence_mm_per_N is not None:
        return np.asarray(cs.influence_mm_per_N, dtype=float)
    E, nu = cs.youngs_modulus, cs.poissons_ratio
    shear = None
    if cs.bending_stiffness_Nmm2 is not None:
        EI = float(cs.bending_stiffness_Nmm2)
    else:
        d = cs.journal_diameter
        EI = E * math.pi * d**4 / 64.0
        if cs.shear:
            kappa = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)
            shear = kappa * E / (2.0 * (1.0 + nu)) * math.pi * d * d / 4.0
    ks = cs.support_stiffness_pair
    kc = cs.carrier_stiffness_pair
    compliance = tuple((1.0 / ks[i] if ks[i] else 0.0) + (1.0 / kc[i] if kc[i] else 0.0) for i in range(2))
    return beam_influence(cs.span, cs.eccentric_positions, EI, shear, compliance)


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
    first : rvfem.cycle.DiscSystem
        Disc A.
    second : rvfem.cycle.DiscSystem or None
        Disc B's model; None for a single disc, ``first`` itself for ``"same_as_first"``.
    second_phase : float
        β, rad: disc B is solved at θ + π − β and its results turned by β (0 for
        ``"same_as_first"``).
    influence : ndarray (discs, discs) or None
        Crankshaft influence matrix, mm/N (None: rigid eccentrics).
    torque_Nmm : float
        Torque on the carrier from the discs modelled here, N·mm: T_out for two discs, T_out/discs
        for one disc (the handbook's equal share).
    """

    first: object
    second: object | None
    second_phase: float
    influence: np.ndarray | None
    torque_Nmm: float

    @property
    def discs(self) -> int:
        return 1 if self.second is None else 2

    @property
    def mirrored_pairs(self) -> bool:
        """True when the pair at θ + π is the pair at θ with the discs swapped (disc B is disc A
        at θ + π and the crankshaft is symmetric), so that 180° of pairs make a cycle."""
        if self.second is not self.first or self.second_phase != 0.0:
            return False
        f = self.influence
        return f is None or bool(np.isclose(f[0, 0], f[1, 1], rtol=1e-12, atol=0.0))

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
        return f"{disc}; {crank}"


def _rotation(beta: float) -> np.ndarray:
    c, s = math.cos(beta), math.sin(beta)
    return np.array([[c, -s], [s, c]])


def build_stage(system, *, discs: int | None = None, second=None, second_disc: str = "same_as_first",
                influence: np.ndarray | None | str = "case") -> ReducerStage:
    """The reducer stage of a disc model.

    Parameters
    ----------
    system : rvfem.cycle.DiscSystem
        Disc A.
    discs : {1, 2}, optional
        1: one disc with the equal torque share T_out/discs; 2: both discs on one carrier.
        Default from the case (``loads.discs`` and ``loads.torque_split``): with
        ``torque_split = "equal"`` one disc on rigid eccentrics (``[crank_support]`` unused).
    second : rvfem.cycle.DiscSystem, optional
        Disc B's model for ``second_disc = "half_pitch"``: the case with its cranks and holes turned
        by −β (:func:`half_pitch_case`), meshed and built like disc A.
    second_disc : {"same_as_first", "half_pitch"}
    influence : ndarray, None or "case"
        Crankshaft influence matrix (mm/N); None for rigid eccentrics; "case" from
        ``[crank_support]``.
    """
    case = system.case
    equal_split = case.loads.discs > 1 and case.loads.torque_split == "equal"
    if discs is None:
        discs = 1 if equal_split or case.loads.discs == 1 else 2
    if isinstance(influence, str):
        # the equal split is rvfem 0.1's and the handbook's model: one disc with T/discs on rigid
        # eccentrics; [crank_support] belongs to the two-disc stage
        influence = None if (discs == 1 and equal_split) else crankshaft_influence(case)
    torque = case.loads.torque_Nm * 1000.0
    if discs == 1:
        f = None if influence is None else np.asarray(influence, dtype=float)[:1, :1]
        return ReducerStage(system, None, 0.0, f, torque / case.loads.discs)
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
        return ReducerStage(system, system, 0.0, f, torque)
    if second is None:
        raise CaseError("second_disc = 'half_pitch' needs the second disc's model (see half_pitch_case)")
    return ReducerStage(system, second, second_disc_phase(case), f, torque)


def half_pitch_case(case):
    """Disc B's case for the exact model: cranks (and the holes that follow them) turned by −β.

    Holes placed by an explicit ``angle_offset_deg`` are turned too; everything else is unchanged.
    Solved at θ + π − β and turned back by β, this is disc B with its teeth half a tooth pitch from
    disc A's against the bores and holes.
    """
    import dataclasses

    beta = math.degrees(second_disc_phase(case))
    cranks = dataclasses.replace(case.cranks, angles_deg=tuple(a - beta for a in case.cranks.angles_deg))
    changes = {"cranks": cranks}
    for table in ("fan_holes", "round_holes"):
        holes = getattr(case, table)
        if holes is not None and holes.angle_offset_deg is not None:
            changes[table] = dataclasses.replace(holes, angle_offset_deg=holes.angle_offset_deg - beta)
    return dataclasses.replace(case, **changes)


@dataclass(frozen=True)
class PairResult:
    """One crank angle of the stage.

    Attributes
    ----------
    results : tuple of rvfem.cycle.AngleResult
        Disc A at θ (and disc B, in its own model's frame and crank angle).
    bearing_forces : ndarray (discs, N, 2)
        Bearing forces on each disc in the carrier frame, N.
    torque_Nmm : ndarray (discs,)
        Each disc's share of the carrier torque, N·mm.
    eccentric_displacement : ndarray (discs, N, 2)
        Displacement of each eccentric relative to the carrier (crankshaft deflection), mm.
    """

    results: tuple
    bearing_forces: np.ndarray
    torque_Nmm: np.ndarray
    eccentric_displacement: np.ndarray


def _disc_angles(stage: ReducerStage, theta: float) -> list[float]:
    """The crank angle of each disc's own frame at the stage's crank angle θ (rad): disc A at θ,
    disc B at θ + π − its phase."""
    return [theta] if stage.second is None else [theta, theta + math.pi - stage.second_phase]


def _bodies(stage: ReducerStage, theta: float):
    from .cycle import contact_set

    systems = [stage.first] if stage.second is None else [stage.first, stage.second]
    thetas = _disc_angles(stage, theta)
    phases = [0.0, stage.second_phase][:len(systems)]
    sets = [contact_set(s, th) for s, th in zip(systems, thetas)]
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
    crank = np.concatenate(crank)
    disc = np.concatenate(disc)
    same = (crank[:, None] == crank[None, :]) & (crank[:, None] >= 0)
    f = stage.influence[disc[:, None], disc[None, :]]
    return np.where(same, f * (d @ d.T), 0.0)


def solve_pair(stage: ReducerStage, theta: float, start: PairResult | None = None) -> PairResult:
    """Solve the stage at crank angle θ (rad): disc A at θ with disc B at θ + 180°."""
    from .cycle import angle_result

    systems, thetas, phases, sets = _bodies(stage, theta)
    case = stage.first.case
    names = [f"disc {'AB'[k]} {n}" if len(sets) > 1 else n for k, (_, ns) in enumerate(sets) for n in ns]
    H = coupling_matrix(stage, systems, phases, sets)
    sols = solve_bodies(
        [Body(c, s.interface, s.compliance) for s, (c, _) in zip(systems, sets)], stage.torque_Nmm,
        coupling=H, start=None if start is None else [r.solution for r in start.results],
        max_iterations=case.analysis.max_active_set_iterations,
        label=f"at crank angle {math.degrees(theta):.2f}° ", names=names)
    return _pair(stage, tuple(angle_result(s, th, sol, c)
                              for s, th, sol, (c, _) in zip(systems, thetas, sols, sets)))


def _pair(stage: ReducerStage, results: tuple) -> PairResult:
    """A PairResult from each disc's solution (disc A first)."""
    return PairResult(results, *_stage_loads(stage, [r.bearing_forces for r in results],
                                             [r.solution.residual["torque_Nmm"] for r in results]))


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
    bearing i + k's (the same as :func:`rvfem.cycle.turn_result` gives, to round-off)."""
    return np.roll(result.bearing_forces @ _rotation(2.0 * math.pi * k / order).T, k, axis=0)


def default_stage(system) -> ReducerStage | None:
    """The stage the case asks for, or None when it is rvfem 0.1's single disc on rigid
    eccentrics with T/discs (solved by :func:`rvfem.cycle.load_cycle` directly)."""
    stage = build_stage(system)
    if stage.discs == 1 and stage.influence is None:
        return None
    return stage


# ------------------------------------------------------------------------------------------------
# A full cycle
# ------------------------------------------------------------------------------------------------


def solve_stage_cycle(stage: ReducerStage, thetas: np.ndarray, progress=None):
    """Solve the stage at every crank angle, each pair started from the ones before it
    (:func:`rvfem.cycle.solve_from_last`).

    Only the angles that symmetry does not give are solved (:func:`rvfem.cycle.symmetry_plan`):
    with :attr:`ReducerStage.mirrored_pairs` the pair at θ + 180° is the pair at θ with the discs
    swapped; with N-fold symmetric discs the pair at θ + 360°/N is the pair at θ turned
    (:func:`rvfem.cycle.turn_result`). ``progress(done, n)`` counts the crank angles of disc A
    obtained so far.

    Returns
    -------
    results : list of rvfem.cycle.AngleResult
        Disc A at every θ.
    extras : dict
        ``disc_torque_Nmm`` (n, discs), ``disc_bearing_forces`` (n, discs, N, 2) in the carrier
        frame, ``eccentric_displacement`` (n, discs, N, 2), ``pair_solves`` (int), ``stage`` (the
        stage's description).
    """
    from .cycle import contact_set, contact_sets, likely_columns, solve_from_last, symmetry_plan, turn_result

    thetas = np.asarray(thetas, dtype=float)
    n = len(thetas)
    systems = [stage.first] if stage.second is None else [stage.first, stage.second]
    order = min(s.symmetry for s in systems)
    mirrored = stage.discs == 2 and stage.mirrored_pairs
    solve_at, source = symmetry_plan(thetas, order, mirrored)
    step = 2.0 * math.pi / order

    t0 = time.perf_counter()

    def cset(k, theta):
        return contact_set(systems[k], theta)[0]

    # the contacts of every angle a disc is solved at and of every angle disc A is turned to,
    # built in one sweep per system
    wanted = [[] for _ in systems]
    for j, (i, swap, k) in enumerate(source):
        own = _disc_angles(stage, float(thetas[i]))
        if (swap, k) == (0, 0):
            for d in range(len(systems)):
                wanted[d].append(own[d])
        else:
            wanted[0].append(own[swap] + k * step)
    for d, s in enumerate(systems):
        contact_sets(s, wanted[d])               # the solved angles are among them (source[i] = i)
    for s in {id(s): s for s in systems}.values():
        ks = [k for k, t in enumerate(systems) if t is s]
        s.compliance.ensure(likely_columns(s, [cset(k, _disc_angles(stage, float(thetas[i]))[k])
                                               for i in solve_at for k in ks]))
    log.info("stage compliance prefetch %.2f s", time.perf_counter() - t0)
    pairs: list[PairResult] = []
    for i in solve_at:
        pairs.append(solve_from_last(lambda start: solve_pair(stage, float(thetas[i]), start), pairs[-2:]))
        if progress is not None:
            progress(len(pairs) * n // len(solve_at), n)
    results, torque, forces, w = [], [], [], []
    for j, (i, swap, k) in enumerate(source):
        src = pairs[i].results
        if swap:
            src = src[::-1]                      # mirrored pair: disc B is disc A at θ + π
        if (swap, k) == (0, 0):
            first, loads = _first_and_loads(pairs[i])
        else:
            # disc A's solution turned by k steps (its contacts checked against the turned ones);
            # disc B, which may land at θ_j + π − 2π when the discs are swapped (the same state,
            # the cycle being 2π-periodic: roller_angles), enters only through its bearing forces
            # and torque, turned and unchanged
            try:
                first = turn_result(systems[0], src[0], k, cset(0, src[0].theta + k * step))
                loads = _stage_loads(stage, [first.bearing_forces] + [_turned_bearing_forces(r, k, order) for r in src[1:]],
                                     [r.solution.residual["torque_Nmm"] for r in src])     # turning keeps torques
            except ValueError as exc:
                log.warning("%s; solving the pair at %.2f° directly", exc, math.degrees(thetas[j]))
                first, loads = _first_and_loads(solve_pair(stage, float(thetas[j]), pairs[i]))
            if abs(first.theta - thetas[j]) > 1e-9:
                raise RuntimeError(f"symmetry plan lands at {first.theta} instead of {thetas[j]}")
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
    }
    return results, extras


# ------------------------------------------------------------------------------------------------
# What the flexibility effect is made of
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class AttributionStep:
    """One modelling step of the attribution: the bearing-load curves it gives.

    Attributes
    ----------
    key : str
        ``handbook``, ``equal_share``, ``one_disc``, ``two_discs`` or ``crankshafts``.
    label : str
        What the step adds, in words.
    loads : ndarray (N, n)
        Load magnitude of each bearing over the crank angles, N.
    """

    key: str
    label: str
    loads: np.ndarray


@dataclass(frozen=True)
class Attribution:
    """The chain handbook → equal share of the FE pin resultant → one flexible disc with T/discs
    → two discs sharing the carrier → crankshaft compliance, on the same crank angles.

    ``final`` names the step that is the case's own model (the full FE answer).
    """

    theta: np.ndarray
    steps: tuple[AttributionStep, ...]
    final: str

    def step(self, key: str) -> AttributionStep:
        return next(s for s in self.steps if s.key == key)

    def table(self, exponent: float) -> list[dict]:
        """Per step and bearing: max, min and equivalent load (N) and their deltas against the
        first step (%), and the life ratio (F_ref,m/F_m)^(10/3). The first step is the handbook, or
        the equal share where the handbook is not defined (Zp − Zc ≠ 1)."""
        from .evaluation import life_ratio
        from .rigid import equivalent_load

        ref = self.steps[0].loads
        rows = []
        for s in self.steps:
            for i in range(s.loads.shape[0]):
                mx, mn = float(s.loads[i].max()), float(s.loads[i].min())
                fm = float(equivalent_load(s.loads[i], exponent))
                rmx, rmn = float(ref[i].max()), float(ref[i].min())
                rfm = float(equivalent_load(ref[i], exponent))
                rows.append({
                    "step": s.key, "label": s.label, "bearing": i + 1,
                    "max_N": mx, "min_N": mn, "equivalent_N": fm,
                    "delta_max_percent": 100.0 * (mx / rmx - 1.0),
                    "delta_min_percent": 100.0 * (mn / rmn - 1.0),
                    "delta_equivalent_percent": 100.0 * (fm / rfm - 1.0),
                    "life_ratio": life_ratio(rfm, fm),
                })
        return rows


STEP_LABELS = {
    "handbook": "handbook (rigid disc, classical pin forces, T/2 per disc)",
    "equal_share": "equal share of the FE pin resultant (pin-force distribution of the flexible disc)",
    "equal_share_reference": "equal share of this run's FE pin resultant (the reference: handbook not defined "
                             "for Zp − Zc ≠ 1)",
    "one_disc": "one flexible disc with T/2 on rigid eccentrics (bearing load sharing)",
    "two_discs": "two discs sharing the carrier, rigid crank support",
    "crankshafts": "two discs sharing the carrier, crankshafts as beams",
}


def attribution(system, thetas: np.ndarray, cycles: dict | None = None) -> Attribution:
    """Solve the modelling steps the case does not already have and collect their load curves.

    Parameters
    ----------
    system : rvfem.cycle.DiscSystem
    thetas : ndarray
        Crank angles, rad (a uniformly sampled turn).
    cycles : dict, optional
        Already solved cycles by step key (``one_disc``, ``two_discs``, ``crankshafts``), e.g. the
        run's own cycle, so that it is not solved twice. All steps share the disc's compliance.

    Notes
    -----
    The equal share is built from the one-disc cycle's pin resultant (the handbook's load sharing
    applied to the flexible disc's pin forces): F_i = −P/N + T_disc/(N·r0)·t_i. Where the handbook
    is not defined (Zp − Zc ≠ 1, :func:`rvfem.rigid.handbook_applicable`) the chain starts at the
    reference the run's bearing loads are compared with instead, the equal share of the case's own
    cycle's pin resultant (:func:`rvfem.compare.rigid_vs_flexible`), so that the last row's deltas
    are the run's.
    """
    from .cycle import load_cycle
    from .compare import equal_share_forces
    from .rigid import handbook_applicable, handbook_bearing_loads

    case = system.case
    cycles = dict(cycles or {})
    need = ["one_disc"]
    discs = 2 if case.loads.discs == 2 else 1
    if discs == 2:
        need.append("two_discs")
    f = crankshaft_influence(case)
    if f is not None:
        need.append("crankshafts")
    for key in need:
        if key in cycles:
            continue
        if key == "one_disc":
            stage = None
        else:
            stage = build_stage(system, discs=discs, influence=f if key == "crankshafts" else None)
        cycles[key] = load_cycle(system, thetas, saved_angles_deg=(), stage=stage)
    if handbook_applicable(case)[0]:
        steps = [AttributionStep("handbook", STEP_LABELS["handbook"], handbook_bearing_loads(case, thetas).magnitude)]
        base, label = cycles["one_disc"], STEP_LABELS["equal_share"]
    else:   # Zp − Zc ≠ 1: start at the run's own reference
        steps, base, label = [], cycles[case_step(case)], STEP_LABELS["equal_share_reference"]
    share = np.linalg.norm(equal_share_forces(case, base), axis=2).T
    steps.append(AttributionStep("equal_share", label, share))
    for key in need:
        steps.append(AttributionStep(key, STEP_LABELS[key], cycles[key].bearing_loads.T))
    return Attribution(np.asarray(thetas), tuple(steps), case_step(case))


def case_step(case) -> str:
    """The attribution step that is the case's own model: ``one_disc`` (one disc with T/discs on
    rigid eccentrics: ``torque_split = "equal"``, or one disc without ``[crank_support]``),
    ``two_discs`` (two discs on rigid eccentrics) or ``crankshafts``."""
    if case.loads.discs > 1 and case.loads.torque_split == "equal":
        return "one_disc"
    if case.crank_support is not None:
        return "crankshafts"
    return "two_discs" if case.loads.discs == 2 else "one_disc"
