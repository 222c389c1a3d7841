"""The disc model of a case: everything of one disc that does not change with the crank angle.

:func:`build_system` assembles and factorises the stiffness of the disc once, builds its contact
interface (:mod:`rvfem.solve.contact_interface`) and the lazily filled column compliance
(:mod:`rvfem.solve.contact_compliance`), and finds an exact N-fold symmetry of the mesh. Every crank
angle and every operating point (:class:`OperatingPoint`: torque, pin friction) reuses the
:class:`DiscSystem` it returns. Both are reached as ``rvfem.solve.cycle.X`` (their public home).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from rvfem import fem
from rvfem.case.definition import Case
from rvfem.case.mesh_checks import footprint_half_widths
from rvfem.errors import CaseError, MeshError
from rvfem.geometry import DiscGeometry, FlankDeviation, crank_centres, disc_geometry
from rvfem.mesh import DiscMesh, rotation_permutation
from rvfem.solve import contact, models
from rvfem.solve.contact import Compliance, Interface
from rvfem.solve.models import BearingModel, PinModel
from rvfem.units import nmm_from_nm

log = logging.getLogger(__name__)


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


# its public home, as the front door (``rvfem.OperatingPoint``) names it; set after the class is made,
# so that this module imports whether or not rvfem.solve.cycle has been imported before it
OperatingPoint.__module__ = "rvfem.solve.cycle"


@dataclass(frozen=True)
class DiscSystem:
    """Everything that does not change with the crank angle.

    Attributes
    ----------
    case : Case
    mesh : rvfem.mesh.DiscMesh
        The disc's mesh (``points``, ``triangles``, ``boundaries``).
    model : rvfem.fem.FEModel
        The FE model.
    interface : contact.Interface
    compliance : contact.Compliance
        Cache of the column compliance (filled lazily; the only mutable part).
    solve : callable
        K_s⁻¹ applied to a right-hand side (:meth:`rvfem.fem.Factorization.solve`).
    rigid_modes : ndarray (n_dofs, 3)
    bearing_model, pin_model : str
        Names of the crank-bearing and pin models (:mod:`rvfem.case.registry`).
    stiffness_scale : float
        Factor on the disc's Young's modulus.
    geometry : rvfem.geometry.DiscGeometry
        The case's checked geometry.
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
        Cache of :func:`rvfem.solve.cycle_contacts.contact_set` by crank angle, pin friction and model
        (mutable, like the compliance; keyed by value,
        :func:`rvfem.solve.cycle_contacts.contact_model_key`): the cycles of the attribution and the
        operating points of a sweep revisit the same angles; also the contact maps of
        :func:`rvfem.solve.cycle_symmetry.turn_result`, by angle and turn.
    flank_deviation : rvfem.geometry.FlankDeviation or None
        A deviation of every tooth's flank gaps from the nominal profile's as a function of the pin
        phase (worn flanks and pins, :mod:`rvfem.app.wear`), added to each pin's gap at each crank
        angle; None (default): the profile's own gaps. Only the gaps change: a system with one is
        ``dataclasses.replace(system, flank_deviation=..., contact_sets={})`` on the same
        factorisation and column compliance.
    """

    case: Case
    mesh: DiscMesh
    model: fem.FEModel
    interface: Interface
    compliance: Compliance
    solve: Callable[[np.ndarray], np.ndarray]
    rigid_modes: np.ndarray
    bearing_model: str
    stiffness_scale: float
    pin_model: str
    geometry: DiscGeometry
    bearings: BearingModel
    pins: PinModel
    bearing_stiffness_scale: float = 1.0
    pin_stiffness_N_per_mm: float | None = None
    setup_seconds: dict = field(default_factory=dict)
    symmetry: int = 1
    node_rotation: np.ndarray | None = field(default=None, repr=False)
    contact_sets: dict = field(default_factory=dict, repr=False, compare=False)
    flank_deviation: FlankDeviation | None = None


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
        choice; 2 halves the back-substitutions (benchmarks/README.md, "Load cycle") at the
        price of 0.6 % of the maximum bearing load and 5 % on single pin forces.
    geometry : rvfem.geometry.DiscGeometry, optional
        The case's checked geometry (:func:`rvfem.geometry.disc_geometry`) if already built.
    """

    order = order or case.analysis.element_order
    bearing_model = bearing_model or case.crank_bearing.model
    pin_model = pin_model or case.pins.model
    try:
        pins = models.pin_model(pin_model)(case, pin_stiffness_N_per_mm)
        bearings = models.bearing_laws(bearing_model, case, bearing_stiffness_scale, stiffness_scale)
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


def scaled_system(system: DiscSystem, factor: float) -> DiscSystem:
    """The disc of ``system`` with its Young's modulus × ``factor``, without a new assembly,
    factorisation or back-substitution.

    Linear plane-stress elasticity is homogeneous in E: the stiffness is K·factor, every
    displacement of the same loads, the floating compliance C = Bᵀ K⁺ B included, is divided by
    ``factor``, and the stresses of the same loads are unchanged. The columns already
    back-substituted are carried over (divided by ``factor``); the laws that depend on the disc's
    stiffness (the roller law that complements the FE bore, :func:`rvfem.solve.models.bearing_laws`)
    are built for the new modulus; the contact-set cache starts empty. Equal to
    :func:`build_system` with ``stiffness_scale`` × ``factor`` to round-off
    (tests/solve/test_scaled_system.py), at none of its cost: the disc-body share of the compliance
    (:class:`rvfem.solve.stage_parts.DiscBody`) stiffens the disc 1000× this way.

    Parameters
    ----------
    system : DiscSystem
    factor : float
        > 0, dimensionless.

    Returns
    -------
    DiscSystem
    """
    factor = float(factor)
    if not factor > 0.0:
        raise ValueError(f"the factor on the disc's Young's modulus must be positive, got {factor!r}")
    model = replace(system.model, youngs_modulus=system.model.youngs_modulus * factor,
                     stiffness=system.model.stiffness * factor)
    scale = system.stiffness_scale * factor
    bearings = models.bearing_laws(system.bearing_model, system.case, system.bearing_stiffness_scale, scale)

    def solve(rhs, _solve=system.solve):
        return _solve(rhs) / factor

    return replace(system, model=model, compliance=system.compliance.scaled(factor), solve=solve,
                   stiffness_scale=scale, bearings=bearings, setup_seconds={}, contact_sets={})


def _footprint_interface(case: Case, mesh, model, rigid: np.ndarray, column_stride: int) -> Interface:
    """The contact interface of the profile and the bores: load footprints of ±FOOTPRINT_ELEMENTS
    spacings of the contact grid (:func:`rvfem.case.mesh_checks.footprint_half_widths`;
    :func:`rvfem.solve.contact.build_interface`). Columns sit at every ``column_stride``-th boundary
    vertex, or, where ``mesh.contact_grid_flank`` / ``mesh.contact_grid_bore`` is given, at that
    spacing along the boundary whatever the mesh (their count a multiple of the mesh's rotation
    symmetry, so that the grid turns into itself)."""
    centres = crank_centres(case)
    names = ["profile"] + [f"bore_{i}" for i in range(case.cranks.count)]
    boundaries = {n: mesh.boundaries[n] for n in names}
    widths = footprint_half_widths(case)
    given = {"profile": case.mesh.contact_grid_flank, "bore": case.mesh.contact_grid_bore}
    half, spacing = {}, {}
    for name in names:
        kind = "profile" if name == "profile" else "bore"
        half[name] = widths[kind]
        step = given[kind]
        if step is not None:
            spacing[name] = float(step)
    return contact.build_interface(model, boundaries, rigid,
                                   {f"bore_{i}": centres[i] for i in range(len(centres))}, half,
                                   {name: column_stride for name in boundaries}, spacing=spacing,
                                   multiple=max(1, int(getattr(mesh, "symmetry", 1))))


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
