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

**The reducer stage.** A two-disc RV reducer is not one disc on rigid eccentrics with half the torque. Disc B runs 180°
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

**Torque convention.** As for one disc (docs/theory.md), each disc's torque is the moment of its
pin forces about its own centre, and the carrier rotation turns each disc's eccentric centres about
the disc centre; the handbook's ΣP_x·e·Zc = T/2 per disc is the equal split of this total.

The crankshaft influence matrix comes from :func:`rvfem.fem.crankshaft.crankshaft_influence`.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from threadpoolctl import threadpool_limits

from rvfem import fem
from rvfem._arrays import max_load_index
from rvfem.case.definition import FOOTPRINT_ELEMENTS, Case
from rvfem.errors import CaseError, ContactError, MeshError
from rvfem.fem import nodal_stress_operator
from rvfem.fem.crankshaft import crankshaft_influence
from rvfem.geometry import (
    crank_centres,
    disc_geometry,
    load_cycle_angles,
    pin_centres,
    pin_profile_contacts,
    pin_profile_contacts_many,
    profile_curvature,
)
from rvfem.mesh import rotation_permutation
from rvfem.solve import contact, models
from rvfem.solve.contact import AngleSolution, Compliance, ContactSet, Interface
from rvfem.solve.models import (
    ContactGroup,
    bearing_contacts_many,
    contact_columns_many,
    roller_angles,
)
from rvfem.units import arcmin_from_rad, nm_from_nmm, nmm_from_nm

log = logging.getLogger(__name__)

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
    "contact_set",
    "solve_angle",
    "load_cycle",
    "displacement",
    "roller_angles",
]


@dataclass(frozen=True)
class OperatingPoint:
    """What varies between solves of one disc model: the output torque and the pin friction.

    A torque sweep, a duty cycle or a hysteresis loop is a loop over operating points on one
    :class:`DiscSystem` (one factorisation, one column compliance).

    Attributes
    ----------
    torque_Nm : float
        Output torque T_out of the stage, N·m, signed (negative: the reversed direction). One disc
        modelled alone carries T_out/discs.
    friction : float
        Coulomb coefficient μ at the pins (0: frictionless).
    slip : int
        Which way the pins slide on the flanks. 0 (default): as the crank turns (the running
        reducer). +1 / −1: as the disc turns with the carrier in the positive / negative sense at a
        held crank angle (a load step of the hysteresis loop with the input locked,
        :mod:`rvfem.solve.accuracy`).
    """

    torque_Nm: float
    friction: float = 0.0
    slip: int = 0

    @classmethod
    def of(cls, case: Case) -> "OperatingPoint":
        """The case's own operating point: ``loads.torque_Nm`` and ``analysis.friction``."""
        return cls(float(case.loads.torque_Nm), float(case.analysis.friction))

    def disc_torque_Nmm(self, case: Case) -> float:
        """The torque of one disc with the equal share T_out/discs, N·mm."""
        return nmm_from_nm(self.torque_Nm) / case.loads.discs


@dataclass(frozen=True)
class DiscSystem:
    """Everything that does not change with the crank angle.

    Attributes
    ----------
    case : Case
    mesh : mesh object with ``points``, ``triangles``, ``boundaries``
    model : the FE model (:mod:`rvfem.fem`)
    interface : contact.Interface
    compliance : contact.Compliance
        Cache of the column compliance (filled lazily; the only mutable part).
    solve : callable
        K_s⁻¹ applied to a right-hand side.
    rigid_modes : ndarray (n_dofs, 3)
    bearing_model, pin_model : str
        Names of the crank-bearing and pin models (:mod:`rvfem.case.registry`).
    bearings, pins : rvfem.solve.models.BearingModel, rvfem.solve.models.PinModel
        The model objects.
    setup_seconds : dict
        Wall times of assembly, factorisation and interface build.
    symmetry : int
        N when the mesh is exactly N-fold symmetric (built from one 360°/N sector) and the
        compliance maps columns by rotation; 1 otherwise.
    node_rotation : ndarray of int or None
        The FE node that each node turns into by 2π/N (symmetric meshes).
    contact_sets : dict
        Cache of :func:`contact_set` by crank angle, pin friction and model (mutable, like the
        compliance; keyed by value, :func:`_contact_model_key`): the cycles of the attribution and
        the operating points of a sweep revisit the same angles; also the contact maps of
        :func:`turn_result`, by angle and turn.
    """

    case: Case
    mesh: object
    model: object
    interface: Interface
    compliance: Compliance
    solve: object
    rigid_modes: np.ndarray
    bearing_model: str
    stiffness_scale: float
    pin_model: str
    geometry: object
    bearing_stiffness_scale: float = 1.0
    pin_stiffness_N_per_mm: float | None = None
    setup_seconds: dict = field(default_factory=dict)
    bearings: object = None
    pins: object = None
    symmetry: int = 1
    node_rotation: np.ndarray | None = field(default=None, repr=False)
    contact_sets: dict = field(default_factory=dict, repr=False, compare=False)


def build_system(case: Case, mesh, *, order: int | None = None, bearing_model: str | None = None,
                 stiffness_scale: float = 1.0, pin_model: str | None = None,
                 bearing_stiffness_scale: float = 1.0,
                 pin_stiffness_N_per_mm: float | None = None, column_stride: int = 1,
                 geometry=None) -> DiscSystem:
    """Assemble and factorise the disc and build its footprint interface.

    Parameters
    ----------
    case : Case
    mesh : DiscMesh
        From :func:`rvfem.mesh.mesh_case`.
    order : {1, 2}, optional
        Element order; default ``case.analysis.element_order``.
    bearing_model : {"rollers", "rigid_bore"}, optional
        Default ``case.crank_bearing.model``.
    stiffness_scale : float
        Multiplies the disc's Young's modulus (1000 gives the "rigid disc" limit of the design
        notes' validation ladder).
    pin_model : {"rigid", "hertz", "palmgren", "linear"}, optional
        Default ``case.pins.model`` (:mod:`rvfem.solve.models`). ``"linear"`` (the classical pin-force
        distribution assumes pin deflections proportional to the forces) takes its stiffness from
        ``pin_stiffness_N_per_mm`` or else ``pins.linear_stiffness_N_per_mm``.
    bearing_stiffness_scale : float
        Multiplies the ``rigid_bore`` bearing stiffness (for the rigid-limit checks).
    pin_stiffness_N_per_mm : float, optional
        Stiffness of the ``"linear"`` pin model, N/mm (overrides the case's).
    column_stride : int
        Interface columns at every stride-th boundary vertex. 1 (default) is the accurate
        choice; 2 halves the back-substitutions (default fan-hole case: cycle 8.5 → 6.0 s) at the
        price of 0.6 % of the maximum bearing load and 5 % on single pin forces.
    geometry : rvfem.geometry.DiscGeometry, optional
        The case's checked geometry (:func:`rvfem.geometry.disc_geometry`) if already built.
    """

    order = order or case.analysis.element_order
    bearing_model = bearing_model or case.crank_bearing.model
    pin_model = pin_model or case.pins.model
    try:
        pins = models.pin_model(pin_model)(case, pin_stiffness_N_per_mm)
        bearings = models.bearing_model(bearing_model)(case, bearing_stiffness_scale)
    except KeyError as exc:
        raise CaseError(exc.args[0]) from None
    times = {}
    if geometry is None or geometry.case is not case:
        geometry = disc_geometry(case)
    t0 = time.perf_counter()
    model = fem.build_model(mesh.points, mesh.triangles,
                            youngs_modulus=case.material.youngs_modulus * stiffness_scale,
                            poissons_ratio=case.material.poissons_ratio,
                            thickness=case.cycloid.thickness, order=order)
    times["assembly"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    factor = fem.factorize(model)
    times["factorization"] = time.perf_counter() - t0
    rigid = fem.rigid_body_modes(model)  # about the disc centre (the origin)

    t0 = time.perf_counter()
    iface = _footprint_interface(case, mesh, model, rigid, column_stride)
    rotation, node_rotation, symmetry = _interface_symmetry(iface, model, int(getattr(mesh, "symmetry", 1)))
    times["interface"] = time.perf_counter() - t0
    compliance = Compliance(factor.solve, iface.B, factor.batch, None if factor.concurrent else 1, rigid_modes=rigid,
                            vertex_dofs=model.node_dofs[:model.n_vertices].ravel(),
                            rotation=rotation, order=symmetry, free=(factor.free_dofs, factor.solve_free))
    return DiscSystem(case=case, mesh=mesh, model=model, interface=iface, compliance=compliance, solve=factor.solve,
                      rigid_modes=rigid, bearing_model=bearing_model, stiffness_scale=stiffness_scale,
                      pin_model=pin_model, geometry=geometry, bearing_stiffness_scale=bearing_stiffness_scale,
                      pin_stiffness_N_per_mm=pin_stiffness_N_per_mm, setup_seconds=times, bearings=bearings,
                      pins=pins, symmetry=symmetry, node_rotation=node_rotation)


def _footprint_interface(case: Case, mesh, model, rigid: np.ndarray, column_stride: int) -> Interface:
    """The contact interface of the profile and the bores: load footprints of ±FOOTPRINT_ELEMENTS
    element sizes (:func:`rvfem.solve.contact.build_interface`), columns at every ``column_stride``-th
    boundary vertex."""
    centres = crank_centres(case)
    names = ["profile"] + [f"bore_{i}" for i in range(case.cranks.count)]
    boundaries = {n: mesh.boundaries[n] for n in names}
    half = {"profile": FOOTPRINT_ELEMENTS * case.mesh.size_flank}
    for i in range(case.cranks.count):
        half[f"bore_{i}"] = FOOTPRINT_ELEMENTS * case.mesh.size_bore
    return contact.build_interface(model, boundaries, rigid,
                                   {f"bore_{i}": centres[i] for i in range(len(centres))}, half,
                                   {name: column_stride for name in boundaries})


def _interface_symmetry(iface: Interface, model, symmetry: int) -> tuple:
    """(column rotation, node rotation, N) of a mesh marked N-fold symmetric; (None, None, 1) when
    it is not, or when its interface turns out not to be (logged: the full disc is solved)."""
    if symmetry <= 1:
        return None, None, 1

    rotation = contact.column_rotation(iface, symmetry)
    node_rotation = None
    try:
        node_rotation = rotation_permutation(model.node_coords, symmetry)
    except MeshError:
        rotation = None
    if rotation is None:
        log.warning("the mesh is marked %d-fold symmetric but its interface is not; solving the "
                    "full disc", symmetry)
        return None, None, 1
    return rotation, node_rotation, symmetry


def pin_contacts(system: DiscSystem, theta: float, friction: float, pc=None):
    """The pin contacts of crank angle θ (rad) as a :class:`rvfem.solve.models.ContactGroup`.

    Each pin pushes along the inward normal of the profile at its closest point; the gap is the
    exact one of the (modified, pitch-error) profile. With friction (μ = ``friction``, the
    operating point's) the load on the disc is λ·(d + μ·s·t) along the known sliding direction,
    while the gap is still measured along the normal d. The pin model's law gets the angle's
    contacts and the flank curvature at each pin's closest point (the Hertz law depends on it).
    ``pc`` passes the angle's :class:`rvfem.geometry.PinContacts` if they are already computed.
    """

    if pc is None:
        pc = pin_profile_contacts(system.geometry, theta)
    return pin_contacts_many(system, [pc], friction)[0]


def pin_contacts_many(system: DiscSystem, pcs, friction: float, slip: int = 0) -> list:
    """:func:`pin_contacts` of many crank angles from their :class:`rvfem.geometry.PinContacts`:
    the closest points of all of them located on the footprint grid at once. ``slip`` as in
    :class:`OperatingPoint` (0: the pins slide as the crank turns)."""

    case = system.case
    prof = system.interface.grids["profile"]
    n_columns = system.interface.n_columns
    zp = case.pins.count
    if not pcs:
        return []
    s = prof.arc_of(np.concatenate([pc.point for pc in pcs]))
    inward = -np.concatenate([pc.normal for pc in pcs])
    cols, wts = prof.columns_at(s, inward)   # pins push along the inward normal
    curvature = profile_curvature(system.geometry.profile, np.concatenate([pc.segment for pc in pcs]),
                                  np.concatenate([pc.param for pc in pcs]))
    mu = friction
    if mu > 0:
        # Coulomb friction along the known sliding direction: the pin centre's velocity relative
        # to the disc (the pins are taken as not rolling in their grooves); the friction force on
        # the disc drags its surface along with the pin: μ·λ·sign(v·t)·t, t the profile tangent
        h = 1e-6
        if slip:
            # a load step at a held crank angle: the disc turns with the carrier about its centre
            # (the torque convention), so a pin moves relative to the disc by −slip·ẑ × c
            c = np.concatenate([pin_centres(case, pc.theta) for pc in pcs])
            vel = -float(np.sign(slip)) * np.stack([-c[:, 1], c[:, 0]], axis=1)
        else:
            vel = np.concatenate([(pin_centres(case, pc.theta + h) - pin_centres(case, pc.theta - h)) / (2 * h)
                                  for pc in pcs])
        tangent = np.stack([-inward[:, 1], inward[:, 0]], axis=1)
        slide = np.sign(np.einsum("ij,ij->i", vel, tangent))
        load_cols, pin_load = prof.columns_at(s, inward + mu * slide[:, None] * tangent)
    names = [f"pin {j + 1}" for j in range(zp)]
    n = len(pcs)
    Ws = contact_columns_many(n_columns, cols.reshape(n, zp, -1), wts.reshape(n, zp, -1))
    W_loads = [None] * n if mu == 0 else contact_columns_many(n_columns, load_cols.reshape(n, zp, -1),
                                                               pin_load.reshape(n, zp, -1))
    out = []
    for a, pc in enumerate(pcs):
        rows = slice(a * zp, (a + 1) * zp)
        W_load = W_loads[a]
        law = system.pins.law(pc, curvature[rows])
        rigid = law is None
        out.append(ContactGroup(
            W=Ws[a], signorini=np.full(zp, rigid),
            gap0=np.asarray(pc.gap) if rigid else np.zeros(zp),
            offset=np.zeros(zp) if rigid else -np.asarray(pc.gap),
            laws=[] if rigid else [(np.arange(zp), law)], names=names,
            bearing=np.full(zp, -1), W_load=W_load))
    return out


def contact_set(system: DiscSystem, theta: float, op: OperatingPoint | None = None
                ) -> tuple[ContactSet, list[str]]:
    """The contacts of crank angle θ (rad) at the operating point ``op`` (default the case's):
    every pin (the pin model's), then the bearing contacts (the bearing model's).

    Returns the contact set and a name per contact (``pin 7``, ``bearing 1 roller 3``, ...).
    Built once per angle, pin friction and system (:attr:`DiscSystem.contact_sets`).
    """
    return contact_sets(system, [theta], OperatingPoint.of(system.case) if op is None else op)[0]


def contact_sets(system: DiscSystem, thetas, op: OperatingPoint) -> list[tuple[ContactSet, list[str]]]:
    """:func:`contact_set` of many crank angles; the pin contacts of the angles not built yet
    come from one vectorised closest-point search (:func:`rvfem.geometry.pin_profile_contacts_many`).

    The cache is keyed by value: the crank angle, the pin friction (the only part of the
    operating point the contacts depend on; the torque enters the solve alone) and the models the
    contacts come from (:func:`_contact_model_key`)."""

    model = _contact_model_key(system)
    keys = [(round(float(theta), 12), float(op.friction)) + model + ((op.slip,) if op.slip else ())
            for theta in thetas]
    missing = {key: float(theta) for key, theta in zip(keys, thetas) if key not in system.contact_sets}
    if missing:
        angles = list(missing.values())
        pins = pin_contacts_many(system, pin_profile_contacts_many(system.geometry, angles), op.friction, op.slip)
        bearings = bearing_contacts_many(system.bearings, system.interface, crank_centres(system.case), angles)
        for key, p, b in zip(missing, pins, bearings):
            system.contact_sets[key] = _contact_set(system, p, b)
    return [system.contact_sets[key] for key in keys]


def _contact_model_key(system: DiscSystem) -> tuple:
    """What a system's contacts depend on besides the crank angle and the friction, by value: the
    case (frozen, hashable) and the bearing and pin models with their stiffness options. Systems
    that share an interface and a compliance (:func:`dataclasses.replace` of one disc model with
    another case) share the cache without mixing their contacts."""
    return (system.case, system.bearing_model, system.pin_model, system.bearing_stiffness_scale,
            system.pin_stiffness_N_per_mm)


def _contact_set(system: DiscSystem, pins, bearings) -> tuple[ContactSet, list[str]]:
    """One angle's contact set from its pin and bearing contacts (:class:`rvfem.solve.models.ContactGroup`)."""
    centres = crank_centres(system.case)
    zp = pins.size
    W = _hstack_csc(pins.W, bearings.W)
    W_load = None
    if pins.W_load is not None:
        W_load = _hstack_csc(pins.W_load, bearings.W)
    laws = [(idx, law) for idx, law in pins.laws] + [(zp + idx, law) for idx, law in bearings.laws]
    F = np.asarray(bearings.W.T @ system.interface.resultants[:, :2])     # force on the disc per unit λ
    cb = centres[bearings.bearing]
    lever = np.concatenate([np.zeros(zp), cb[:, 0] * F[:, 1] - cb[:, 1] * F[:, 0]])
    cset = ContactSet(W, np.concatenate([pins.signorini, bearings.signorini]),
                      np.concatenate([pins.gap0, bearings.gap0]),
                      np.concatenate([pins.offset, bearings.offset]), lever, laws, W_load,
                      np.concatenate([pins.bearing, bearings.bearing]))
    return cset, pins.names + bearings.names


def _hstack_csc(a: sp.spmatrix, b: sp.spmatrix) -> sp.csc_matrix:
    """[a b] of two CSC matrices with the same rows, by joining their arrays."""
    a, b = (m if sp.isspmatrix_csc(m) else sp.csc_matrix(m) for m in (a, b))
    return sp.csc_matrix((np.concatenate([a.data, b.data]), np.concatenate([a.indices, b.indices]),
                          np.concatenate([a.indptr, b.indptr[1:] + a.indptr[-1]])),
                         shape=(a.shape[0], a.shape[1] + b.shape[1]))


@dataclass(frozen=True)
class AngleResult:
    """Loads at one crank angle (all forces act on the disc, N; disc frame).

    Attributes
    ----------
    theta : float
        Crank angle, rad.
    bearing_forces : ndarray (N, 2)
        Force of each crank bearing on the disc.
    roller_loads : ndarray (N, Z) or None
        Roller loads (``rollers`` model), N.
    roller_angles : ndarray (N, Z) or None
        Roller positions about each bore centre, rad.
    pin_forces : ndarray (Zp,)
        Pin force magnitudes, N.
    pin_vectors : ndarray (Zp, 2)
    pin_gaps : ndarray (Zp,)
        Final pin gaps (rigid pins) or −approach (compliant pins), mm.
    carrier_rotation : float
        φ, rad (carrier relative to the pin housing, about the disc centre).
    solution : contact.AngleSolution
    contacts : contact.ContactSet
    origin : (AngleResult, int) or None
        For a result obtained by symmetry (:func:`turn_result`): the solved result and the number
        of 2π/N turns; its displacement field is the solved one's, turned.
    """

    theta: float
    bearing_forces: np.ndarray
    roller_loads: np.ndarray | None
    roller_angles: np.ndarray | None
    pin_forces: np.ndarray
    pin_vectors: np.ndarray
    pin_gaps: np.ndarray
    carrier_rotation: float
    solution: AngleSolution
    contacts: ContactSet
    origin: tuple | None = field(default=None, repr=False, compare=False)

    @property
    def bearing_loads(self) -> np.ndarray:
        """|F| of each bearing, N."""
        return np.linalg.norm(self.bearing_forces, axis=1)

    @property
    def column_loads(self) -> np.ndarray:
        """The contact loads on the interface columns, ``W_load·λ`` (friction included), N: with
        the rigid motion, all a displacement field needs (:func:`displacements`)."""
        return self.contacts.load_weights @ self.solution.force

    @property
    def rigid_motion(self) -> np.ndarray:
        """The disc's rigid motion (x, y in mm, rotation in rad) of the solve."""
        return self.solution.rigid

    @property
    def pins_in_contact(self) -> int:
        return int(np.count_nonzero(self.pin_forces > 1e-9 * max(self.pin_forces.max(), 1.0)))


def solve_angle(system: DiscSystem, theta: float, start: AngleResult | None = None, *,
                op: OperatingPoint | None = None,
                contacts: tuple[ContactSet, list[str]] | None = None) -> AngleResult:
    """Solve one crank angle θ (rad) of one disc with the equal torque share T_out/discs at the
    operating point ``op`` (default the case's). ``start`` warm-starts from a neighbouring angle;
    ``contacts`` passes the angle's :func:`contact_set` if it is already built."""
    case = system.case
    op = OperatingPoint.of(case) if op is None else op
    cset, names = contact_set(system, theta, op) if contacts is None else contacts
    sol = contact.solve_contact(
        cset, system.interface, system.compliance, op.disc_torque_Nmm(case),
        start=None if start is None else start.solution,
        max_iterations=case.analysis.max_active_set_iterations,
        label=f"at crank angle {math.degrees(theta):.2f}° ", names=names,
    )
    return angle_result(system, theta, sol, cset)


def angle_result(system: DiscSystem, theta: float, sol: AngleSolution, cset: ContactSet,
                 origin: tuple | None = None) -> AngleResult:
    """Unpack a solved contact problem into pin and bearing loads (the bearing model's);
    ``origin`` as in :class:`AngleResult`."""
    zp = system.case.pins.count
    bearing, rollers, angles = system.bearings.bearing_forces(sol.vectors[zp:], sol.force[zp:], theta)
    return AngleResult(theta, bearing, rollers, angles, sol.force[:zp], sol.vectors[:zp],
                       sol.gap[:zp], sol.carrier_rotation, sol, cset, origin)


def turn_result(system: DiscSystem, result: AngleResult, k: int,
                contacts: ContactSet | None = None, op: OperatingPoint | None = None) -> AngleResult:
    """The solution at θ + k·2π/N from the one at θ, by the disc's exact N-fold symmetry.

    Turning the whole configuration by 2π/N maps the disc (and its mesh) onto itself, the
    eccentric of crank i onto that of crank i + 1, the pin ring onto itself (pin j onto pin
    j + Zp/N·…, whatever the turned positions say) and each roller cage onto the next bearing's:
    the state at θ + 2π/N is the state at θ turned (:func:`roller_angles` phases the cages for
    this). The contacts of the turned angle are mapped onto the solved ones through the
    interface: M with W(θ')·M = Qᵏ·W(θ) (a permutation of pins and rollers, a rotation of x/y
    spring pairs), λ' = M·λ; the rigid motion turns with the disc, φ is unchanged.

    Parameters
    ----------
    system : DiscSystem
        With ``system.symmetry = N > 1``.
    result : AngleResult
        Solved at θ.
    k : int
        Number of 2π/N steps.
    contacts : ContactSet, optional
        The contact set at θ + k·2π/N (built here otherwise, at the operating point ``op``).
    op : OperatingPoint, optional
        The operating point ``result`` was solved at; default the case's.

    Raises
    ------
    ValueError
        If the turned contacts do not match the solved ones (the configuration is not
        symmetric, e.g. a pin count or a model that breaks the symmetry): solve that angle
        directly instead.
    """
    k = int(k)
    if k == 0:
        return result
    beta = 2.0 * math.pi * k / system.symmetry      # signed: the result is labelled θ + β
    theta = result.theta + beta
    cset = contacts if contacts is not None else contact_set(system, theta, op)[0]
    old = result.contacts
    # the map depends only on the two contact sets and the turn, which the solved angle, the turn
    # and whether the pins carry friction loads determine (contact sets are built once per angle
    # and friction, :func:`contact_sets`): found once per system (the attribution's cycles and the
    # operating points of a sweep turn the same solved angles)
    key = ("map", round(float(result.theta), 12), k, old.W_load is not None) + _contact_model_key(system)
    M = system.contact_sets.get(key)
    if M is None:
        pairs = [(old.W, cset.W)]
        if old.W_load is not None or cset.W_load is not None:      # friction: the load weights map too
            pairs.append((old.load_weights, cset.load_weights))
        M = _permutation_map(system.compliance.rotation_power(k), *pairs, turned=_turned_probes(system, k))
        if M is None:
            M = _contact_map(system.compliance.rotation_power(k), *pairs)
        system.contact_sets[key] = M
    # gaps, offsets and levers (mm; 1e-9 mm absolute, 1e-8 relative)
    mapped = M @ np.stack([old.gap0, old.offset, old.lever], axis=1)
    direct = np.stack([cset.gap0, cset.offset, cset.lever], axis=1)
    if np.any(np.abs(mapped - direct) > 1e-9 + 1e-8 * np.abs(direct)):
        raise ValueError(f"the contacts at {math.degrees(theta):.3f}° are not the turned contacts of "
                         f"{math.degrees(result.theta):.3f}°")
    sol = result.solution
    lam = M @ sol.force
    WL = cset.load_weights
    vectors = np.asarray(WL.T @ system.interface.resultants[:, :2]) * lam[:, None]
    c, s_ = math.cos(beta), math.sin(beta)
    a = sol.rigid
    rigid = np.array([c * a[0] - s_ * a[1], s_ * a[0] + c * a[1], a[2]])
    turned = dataclasses.replace(sol, force=lam, vectors=vectors, gap=M @ sol.gap, rigid=rigid,
                                 residual=dict(sol.residual))
    root, k0 = result.origin if result.origin is not None else (result, 0)
    return angle_result(system, theta, turned, cset, origin=(root, k0 + k))


def solve_from_last(solve, last: list):
    """``solve(start)`` for the next of equally spaced angles, ``last`` the results of the (up to
    two) angles before it: started from their linear extrapolation
    (:func:`rvfem.solve.contact.extrapolated_start`), or from the last result if that start does not
    settle. Results are :class:`AngleResult` or :class:`PairResult` (disc by disc)."""
    if len(last) < 2:
        return solve(last[-1] if last else None)

    def extrapolated(before, after):
        if isinstance(after, AngleResult):
            return dataclasses.replace(after, solution=contact.extrapolated_start(before.solution, after.solution))
        return dataclasses.replace(after, results=tuple(extrapolated(b, a) for b, a in zip(before.results, after.results)))

    try:
        return solve(extrapolated(*last))
    except ContactError:
        return solve(last[-1])


@functools.lru_cache(maxsize=8)
def _probes(n_columns: int) -> np.ndarray:
    """Two fixed random vectors over the interface columns (n_columns, 2), read-only."""
    z = np.random.default_rng(0).standard_normal((n_columns, 2))
    z.flags.writeable = False
    return z


def _turned_probes(system: DiscSystem, k: int) -> np.ndarray:
    """Qᵏᵀ·z of the probes z (:func:`_probes`), once per system and k (kept with the contact sets)."""
    compliance = system.compliance
    key = ("probes", int(k) % compliance.order, id(compliance))
    hit = system.contact_sets.get(key)
    if hit is None or hit[0] is not compliance:
        Qk = compliance.rotation_power(k)
        hit = system.contact_sets[key] = (compliance, np.asarray(Qk.T @ _probes(Qk.shape[0])))
    return hit[1]


def _permutation_map(Qk: sp.spmatrix, *pairs: tuple[sp.spmatrix, sp.spmatrix],
                     turned: np.ndarray | None = None) -> np.ndarray | None:
    """M of :func:`_contact_map` when it is a permutation (pins and rollers turn into pins and
    rollers), else None; ``turned`` is Qkᵀ·z of the probes z, when known (:func:`_turned_probes`).

    Found and checked with two random probes z over the columns: the turned weights of contact j
    and the weights of its image σ(j) are the same column, Qk·W0[:, j] = W1[:, σ(j)], so
    (W0ᵀ·Qkᵀ·z)[j] = (W1ᵀ·z)[σ(j)] for both probes, within 1e-8 of the weights' scale; σ pairs
    each value with the nearest one. Two different columns give the same two values with
    probability zero, so the check is that of the columns themselves (on every pair: the gap
    weights and, with friction, the load weights), at the cost of a few sparse products.
    """
    def weighted(W, z):                                       # Wᵀ·z from the CSC arrays
        contact = np.repeat(np.arange(W.shape[1]), np.diff(W.indptr))
        values = W.data[:, None] * z[W.indices]
        return np.stack([np.bincount(contact, values[:, i], W.shape[1]) for i in range(z.shape[1])], axis=1)

    sigma = None
    for W0, W1 in pairs:
        W0, W1 = (W if sp.isspmatrix_csc(W) else sp.csc_matrix(W) for W in (W0, W1))
        if W1.shape != W0.shape or W0.nnz == 0:
            return None
        z = _probes(W0.shape[0])
        Qz = turned if turned is not None else np.asarray(Qk.T @ z)
        mapped = weighted(W0, Qz)                             # (n_contacts, 2)
        direct = weighted(W1, z)
        tol = 1e-8 * float(np.abs(W0.data).max()) * float(np.abs(z).max()) * max(int(np.diff(W0.indptr).max()), 1)
        if sigma is None and len(direct) == 1:
            sigma = np.zeros(1, dtype=int)
        elif sigma is None:
            order = np.argsort(direct[:, 0], kind="stable")
            ranked = direct[order, 0]
            pos = np.clip(np.searchsorted(ranked, mapped[:, 0]), 1, len(ranked) - 1)
            nearer = np.where(np.abs(ranked[pos - 1] - mapped[:, 0]) <= np.abs(ranked[pos] - mapped[:, 0]), pos - 1, pos)
            sigma = order[nearer]
            if len(np.unique(sigma)) != len(sigma):
                return None
        if np.abs(direct[sigma] - mapped).max() > tol:
            return None
    M = np.zeros((len(sigma), len(sigma)))
    M[sigma, np.arange(len(sigma))] = 1.0
    return M


def _contact_map(Qk: sp.spmatrix, *pairs: tuple[sp.spmatrix, sp.spmatrix]) -> np.ndarray:
    """M (n_contacts × n_contacts) with W1·M = Qk·W0 for the first pair (W0, W1) of contact
    weights, checked on every pair (the gap weights and, with friction, the load weights);
    ValueError if there is none.

    For contacts that do not turn one into one (a rigid bore's x and y springs turn into
    combinations of the next bore's); pins and rollers are matched by :func:`_permutation_map`.
    The weights touch a few hundred of the interface columns: M is found on the dense rows of
    those columns only, (W1ᵀW1)·M = W1ᵀ(Qk·W0) in the least-squares sense, and each pair is
    checked to 1e-8 of its largest weight.
    """
    blocks = []
    for W0, W1 in pairs:
        W0, W1 = sp.csc_matrix(W0), sp.csc_matrix(W1)
        if W1.shape != W0.shape:
            raise ValueError("the turned angle has a different number of contacts")
        blocks.append((W0, sp.csc_matrix(Qk @ W0), W1))
    rows = np.unique(np.concatenate([m.indices for _, T, W1 in blocks for m in (T, W1)]))
    dense_blocks = [(W0, T[rows].toarray(), W1[rows].toarray()) for W0, T, W1 in blocks]
    _, T, A = dense_blocks[0]
    try:
        M = np.linalg.solve(A.T @ A, A.T @ T)
    except np.linalg.LinAlgError:
        raise ValueError("the turned contacts are not the solved ones (a contact without weights)") from None
    M[np.abs(M) < 1e-12] = 0.0
    for W0, T, A in dense_blocks:
        scale = max(float(np.abs(W0.data).max()) if W0.nnz else 0.0, 1e-30)
        if T.size and np.abs(A @ M - T).max() > 1e-8 * scale:
            raise ValueError("the turned contacts are not the solved ones")
    return M


def symmetry_plan(thetas: np.ndarray, order: int = 1, mirror: bool = False):
    """Which crank angles to solve and how to obtain the others by symmetry.

    The angles must be a uniform full revolution (θ_j = θ_0 + j·2π/n). The load cycle of an
    N-fold symmetric disc repeats, turned, every 2π/N (``order`` = N); a mirrored pair of discs
    repeats, with the discs swapped, every π (``mirror``). Together the angle indices repeat
    every g = gcd(n, n/N, n/2) and only the first g angles are solved.

    Returns
    -------
    solve : ndarray of int
        Indices of the angles to solve (0 … g − 1), or all of them when nothing applies.
    source : list of (i, swap, k)
        For every angle j: the solved index i, whether the discs are swapped (0/1) and the
        number k of 2π/N turns (of either sign, so that θ_i + swap·π + k·2π/N is θ_j itself).
    """
    thetas = np.asarray(thetas, dtype=float)
    n = len(thetas)
    steps = np.mod(np.diff(np.append(thetas, thetas[0] + 2 * math.pi)), 2 * math.pi) if n else np.zeros(0)
    uniform = n > 1 and np.allclose(steps, 2 * math.pi / n, rtol=0, atol=1e-9)
    shifts = []
    if uniform and order > 1 and n % order == 0:
        shifts.append((n // order, "turn"))
    if uniform and mirror and n % 2 == 0:
        shifts.append((n // 2, "swap"))
    if not shifts:
        return np.arange(n), [(j, 0, 0) for j in range(n)]
    g = n
    for sh, _ in shifts:
        g = math.gcd(g, sh)
    turn = n // order if (uniform and order > 1 and n % order == 0) else 0
    half = n // 2 if (uniform and mirror and n % 2 == 0) else 0
    # every offset d = j − i is reached exactly, with turns of either sign and no wrap past 2π,
    # so that each result obtained carries the angle θ_j itself
    options = sorted(((swap * half + k * turn, swap, k) for swap in ((0, 1) if half else (0,))
                      for k in (range(-order + 1, order) if turn else (0,))), key=lambda o: abs(o[2]))
    source = []
    for j in range(n):
        i, d = j % g, j - j % g
        swap, k = next((sw, k) for off, sw, k in options if off == d)
        source.append((i, swap, k))
    return np.arange(g), source


def turned_nodes(system: DiscSystem, k: int) -> np.ndarray:
    """The FE node that each node turns into by k·2π/N (k of either sign); vertices come first
    and turn into vertices."""
    perm = system.node_rotation
    if perm is None:
        raise ValueError("the disc model has no node rotation (its mesh is not symmetric)")
    target = np.arange(len(perm))
    step = perm if k > 0 else np.argsort(perm)
    for _ in range(abs(int(k))):
        target = step[target]
    return target


def turn_field(system: DiscSystem, u: np.ndarray, k: int) -> np.ndarray:
    """A displacement field (n_dofs,) turned by k·2π/N with the disc: the vector of node n
    turned by k·2π/N moves to the node n turns into (exact on the symmetric mesh)."""
    k = int(k)
    if k == 0:
        return u
    target = turned_nodes(system, k)
    a = 2.0 * math.pi * k / system.symmetry
    c, s_ = math.cos(a), math.sin(a)
    dofs = system.model.node_dofs
    ux, uy = u[dofs[:, 0]], u[dofs[:, 1]]
    out = np.empty_like(u)
    out[dofs[target, 0]] = c * ux - s_ * uy
    out[dofs[target, 1]] = s_ * ux + c * uy
    return out


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


# ------------------------------------------------------------------------------------------------
# The reducer stage: one disc, or two discs on one carrier and crankshafts
# ------------------------------------------------------------------------------------------------

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
    """

    first: object
    second: object | None
    second_phase: float
    influence: np.ndarray | None

    @property
    def discs(self) -> int:
        return 1 if self.second is None else 2

    def carrier_torque_Nmm(self, op: OperatingPoint) -> float:
        """Torque on the carrier from the discs modelled here at the operating point, N·mm: T_out
        for two discs, T_out/discs for one disc (the handbook's equal share)."""
        return nmm_from_nm(op.torque_Nm) * self.discs / self.first.case.loads.discs

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


def build_stage(system, *, discs: int, influence: np.ndarray | None, second=None,
                second_disc: str = "same_as_first") -> ReducerStage:
    """A reducer stage of a disc model (:func:`case_stage` builds the one the case asks for).

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


def case_stage(system, second=None, second_disc: str = "same_as_first") -> ReducerStage:
    """The reducer stage the case asks for: both discs on one carrier for ``loads.discs = 2`` with
    the crankshafts of ``[crank_support]`` (rigid eccentrics without it), or, with
    ``loads.torque_split = "equal"`` or one disc, one disc carrying T_out/discs. The equal split is
    rvfem 0.1's and the handbook's model, on rigid eccentrics ([crank_support] belongs to the
    two-disc stage). ``second``, ``second_disc`` as in :func:`build_stage`."""
    case = system.case
    equal_split = case.loads.discs > 1 and case.loads.torque_split == "equal"
    discs = 1 if equal_split or case.loads.discs == 1 else 2
    influence = None if (discs == 1 and equal_split) else crankshaft_influence(case)
    return build_stage(system, discs=discs, influence=influence, second=second, second_disc=second_disc)


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
    """

    results: tuple
    bearing_forces: np.ndarray
    torque_Nmm: np.ndarray
    eccentric_displacement: np.ndarray


def _disc_angles(stage: ReducerStage, theta: float) -> list[float]:
    """The crank angle of each disc's own frame at the stage's crank angle θ (rad): disc A at θ,
    disc B at θ + π − its phase."""
    return [theta] if stage.second is None else [theta, theta + math.pi - stage.second_phase]


def _bodies(stage: ReducerStage, theta: float, op: OperatingPoint):
    systems = [stage.first] if stage.second is None else [stage.first, stage.second]
    thetas = _disc_angles(stage, theta)
    phases = [0.0, stage.second_phase][:len(systems)]
    sets = [contact_set(s, th, op) for s, th in zip(systems, thetas)]
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


def solve_pair(stage: ReducerStage, theta: float, start: PairResult | None = None, *,
               op: OperatingPoint | None = None, g_cache: dict | None = None) -> PairResult:
    """Solve the stage at crank angle θ (rad) and the operating point ``op`` (default the case's):
    disc A at θ with disc B at θ + 180°. ``g_cache`` keeps the contact compliance between solves
    of the same crank angle (:func:`rvfem.solve.contact.solve_bodies`)."""
    op = OperatingPoint.of(stage.first.case) if op is None else op
    systems, thetas, phases, sets = _bodies(stage, theta, op)
    case = stage.first.case
    names = [f"disc {'AB'[k]} {n}" if len(sets) > 1 else n for k, (_, ns) in enumerate(sets) for n in ns]
    H = coupling_matrix(stage, systems, phases, sets)
    sols = contact.solve_bodies(
        [contact.Body(c, s.interface, s.compliance) for s, (c, _) in zip(systems, sets)], stage.carrier_torque_Nmm(op),
        coupling=H, start=None if start is None else [r.solution for r in start.results],
        max_iterations=case.analysis.max_active_set_iterations,
        label=f"at crank angle {math.degrees(theta):.2f}° ", names=names, g_cache=g_cache)
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
    wanted = [[] for _ in systems]
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
        first = turn_result(system, src[0], k, contact_set(system, turned_theta, op)[0], op)
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
    the ones before it (:func:`solve_from_last`). One disc is a stage with one body.

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
    systems = [stage.first] if stage.second is None else [stage.first, stage.second]
    order = min(s.symmetry for s in systems)
    mirrored = stage.discs == 2 and stage.mirrored_pairs
    solve_at, source = symmetry_plan(thetas, order, mirrored)
    step = 2.0 * math.pi / order

    t0 = time.perf_counter()
    _prefetch_stage(stage, systems, thetas, solve_at, source, step, op)
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
        sparse product per batch (0.5 s on the default case); turned angles reuse them.
    """
    case = system.case
    thetas = cycle_angles(case) if thetas is None else np.asarray(thetas, dtype=float)
    op = OperatingPoint.of(case) if op is None else op
    stage = case_stage(system) if stage is None else stage
    t0 = time.perf_counter()
    # the per-angle systems are small (~100 unknowns): threaded BLAS only adds overhead there
    # (measured 7x slower on two cores), so the cycle runs BLAS single-threaded
    with threadpool_limits(limits=1, user_api="blas"):
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
