"""Contact solve on the condensed disc: pins, crank-bearing rollers and the carrier rotation.

The model (docs/theory.md) in the disc's body frame:

* The disc is a 2D plane-stress body; its stiffness K never changes with the crank angle θ.
* Every load that can act on the disc enters through a fixed **footprint grid** on its boundary:
  column k is a unit force (1 N) in direction d_k, spread over the boundary arc around the grid
  point x_k with an elliptical (Hertz-like) density of half-width a. Pin contacts use the profile
  grid (direction: inward normal of the profile), rollers use a grid on each bore (direction:
  radially outward from the bore centre, i.e. into the disc material). A contact between grid points
  shares its force between the two neighbouring columns (linear interpolation), so its load and
  its displacement are work-conjugate.
* **Condensation** (docs/theory.md § 6): the compliance of the floating disc between grid columns,
  C = Bᵀ Π K_s⁻¹ Πᵀ B, is computed lazily, column by column, the first time a column carries load,
  and reused for every later crank angle (K_s is K with a statically determinate 3-DOF support, Π
  removes the rigid motion; see :class:`Compliance`). The disc's rigid-body motion ``a``
  (2 translations, 1 rotation) is an unknown of the small system. On an exactly N-fold symmetric
  mesh only one sector's columns are back-substituted (:func:`column_rotation`, § 9a).
* Pins are rigid (Signorini: gap ≥ 0, force ≥ 0, force·gap = 0, primal–dual active set) or
  compliant: the Hertz pin–flank line contact (:func:`hertz_pin_law`), Palmgren's roller formula
  or a linear spring (:mod:`rvfem.solve.models`). Rollers are compression-only springs along their
  radial line with the Palmgren law for both raceways, δ = 2·3.84e-5·Q^0.9 / L^0.8 (mm, N), or a
  linear stiffness; the approach is the radial relative displacement of eccentric and bore minus
  half the radial clearance.
* The carrier with its eccentrics is one rigid body that can only rotate. **Torque convention**:
  its rotation φ turns the eccentric centres c_i about the *reducer axis* O (eccentric
  displacement φ·ẑ×(c_i − O), O at −e·u(θ) in the disc frame: the contact set's levers) and its
  conjugate load is the carrier torque as a moment about O (T_out/discs for one disc). Every pin
  normal passes through the pitch point, e·Zp from O and e·Zc from the disc centre, so the same pin
  forces have a moment about the disc centre smaller by Zc/Zp: the handbook's ΣP_x·e·Zc = T/2
  (Gao et al. eq. 4) takes T/2 about the disc centre.

Per crank angle the unknowns are the contact forces λ (pins and rollers), the rigid motion ``a``
and φ; the equations are the contact laws, the disc's equilibrium Rᵀλ = 0 and the carrier's
Σ m_c λ_c = T_disc. They are solved by a semismooth Newton method (the primal–dual active set for
the rigid pins) on this small dense system.

The parts, from the bottom up: the footprint grids and B (:mod:`rvfem.solve.contact_interface`), the
column map of a symmetric disc (:mod:`rvfem.solve.contact_rotation`), the column compliance
(:mod:`rvfem.solve.contact_compliance`), the force laws (:mod:`rvfem.solve.contact_laws`), one angle's
contact set, solution and bodies (:mod:`rvfem.solve.contact_state`) and the Newton method
(:mod:`rvfem.solve.contact_newton`). This module solves one crank angle with them
(:func:`solve_contact`, :func:`solve_bodies`) and gives all their names.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from rvfem.errors import ContactError
# The parts of the contact solve, each in its own module; this module is their public face
# (``contact.X`` reaches every name it reached before they were split off).
from rvfem.solve.contact_compliance import MAP_CHUNK, Compliance
from rvfem.solve.contact_interface import FootprintGrid, Interface, build_interface
from rvfem.solve.contact_laws import (
    PALMGREN_COEFFICIENT,
    hertz_pin_approach,
    hertz_pin_law,
    linear_law,
    palmgren_law,
    roller_bore_approach,
    roller_bore_law,
)
from rvfem.solve.contact_newton import (
    OPEN_SPRING_FRACTION,
    ContactProblem,
    NewtonIterate,
    NewtonOptions,
    _newton,
    _reduced_step,
    _secant_stiffnesses,
    _torque_side,
    first_to_close,
    initial_iterate,
    known_rows,
    linearised_start_laws,
    newton_matrix,
    newton_step,
    penalty_scale,
)
from rvfem.solve.contact_rotation import column_rotation
from rvfem.solve.contact_state import AngleSolution, Body, ContactSet, extrapolated_start

__all__ = [
    "FootprintGrid",
    "Interface",
    "Compliance",
    "column_rotation",
    "ContactSet",
    "AngleSolution",
    "build_interface",
    "palmgren_law",
    "roller_bore_approach",
    "roller_bore_law",
    "linear_law",
    "hertz_pin_approach",
    "hertz_pin_law",
    "solve_contact",
    "solve_bodies",
    "Body",
]


def solve_contact(cset: ContactSet, iface: Interface, compliance: Compliance, torque: float | None, *,
                  start: AngleSolution | None = None, max_iterations: int = 50, label: str = "",
                  tol_gap: float = 1e-9, names: list[str] | None = None,
                  rigid_dofs: tuple[int, ...] = (0, 1, 2)) -> AngleSolution:
    """Solve the contact problem of one body at one crank angle (semismooth Newton / primal–dual
    active set).

    Parameters
    ----------
    cset : ContactSet
    iface : Interface
    compliance : Compliance
        Lazily filled column compliance C (filled further as contacts become active).
    torque : float or None
        Carrier torque, N·mm (moment about the reducer axis, see module docstring). None: no
        carrier (the body is loaded by the contacts' prescribed gaps alone).
    start : AngleSolution, optional
        Warm start (usually the previous crank angle). Without one, a first solve with secant
        linear springs provides the start (Palmgren's law has zero stiffness at zero load).
    max_iterations : int
        Bound of the Newton / active-set loop.
    label : str
        Names the crank angle in error messages.
    tol_gap : float
        Gap tolerance of the rigid pins, mm.
    names : list of str, optional
        Contact names for error messages.
    rigid_dofs : tuple of int
        Rigid-body motions of the body that are unknowns (0: x, 1: y, 2: rotation). A motion left
        out is held by the support of K_s; use this only for a mode no contact can resist (e.g.
        the rotation of a round body under frictionless radial contacts), whose load is zero.

    Raises
    ------
    ContactError
        If the active set does not settle within ``max_iterations``; names the contacts that keep
        flipping.
    """
    return solve_bodies([Body(cset, iface, compliance)], torque,
                        start=None if start is None else [start], max_iterations=max_iterations,
                        label=label, tol_gap=tol_gap, names=names, rigid_dofs=rigid_dofs)[0]


def solve_bodies(bodies: list[Body], torque: float | None, *, coupling: np.ndarray | None = None,
                 start: list[AngleSolution] | None = None, max_iterations: int = 50, label: str = "",
                 tol_gap: float = 1e-9, names: list[str] | None = None,
                 rigid_dofs: tuple[int, ...] = (0, 1, 2), g_cache: dict | None = None) -> list[AngleSolution]:
    """Solve the contacts of several bodies that share one carrier rotation.

    Each body has its own contacts and rigid-body motion (and is in equilibrium on its own); the
    carrier rotation φ is common and its equation is Σ_bodies Σ_c m_c·λ_c = ``torque`` (the total
    torque: for the two discs of a reducer stage, T_out; each disc's share is an output). The
    optional ``coupling`` matrix H adds an approach −H·λ to every contact: the eccentrics of a
    crankshaft move under the forces of all the discs it carries (see :mod:`rvfem.solve.cycle`).

    Parameters
    ----------
    bodies : list of Body
    torque : float or None
        Total torque on the carrier, N·mm (None: no carrier unknown).
    coupling : ndarray (n_contacts, n_contacts), optional
        Symmetric positive semidefinite compliance added between the contacts of all bodies
        (contacts numbered body after body), mm/N.
    start : list of AngleSolution, optional
        Warm start, one per body.
    max_iterations, label, tol_gap, names, rigid_dofs
        As in :func:`solve_contact` (``names`` lists the contacts of all bodies in order).
    g_cache : dict, optional
        Keeps the contact compliance between solves of the same contacts (:class:`NewtonOptions`).

    Returns
    -------
    list of AngleSolution
        One per body; ``residual["torque_Nmm"]`` is the body's share of the torque.
    """
    options = NewtonOptions(max_iterations, label, tol_gap, names, tuple(rigid_dofs), g_cache)
    sizes = [b.cset.W.shape[1] for b in bodies]
    if start is not None and [s.force.shape for s in start] != [(n,) for n in sizes]:
        start = None
    if start is None and torque is not None and any(b.cset.laws for b in bodies):
        # the secant springs keep the tension side of their laws: a bilateral spring (the
        # rigid_bore bearings' x and y springs) made compression-only would be a different problem,
        # one whose disc may be nearly a mechanism once such a spring opens (with pin friction its
        # active-set iteration then cycles without end)
        secants = [_secant_stiffnesses(b, torque / len(bodies)) for b in bodies]

        def linearised(open_fraction):
            return [dataclasses.replace(b, cset=dataclasses.replace(b.cset, laws=[
                (idx, linear_law(ks, bilateral=bilateral, open_fraction=open_fraction))
                for idx, ks, bilateral in secant])) for b, secant in zip(bodies, secants)]

        # the first linear solve engages the springs that can carry the torque: the bearings' and
        # the pins whose force on the disc opposes the bearings' torque (or that overlap). The pins
        # of the other side stay open, so their compliance columns, which the cycle never needs
        # again, are not computed (about 50 of the default disc's). If that start does not
        # settle, every spring is engaged. And if that does not settle either: a step that opens
        # every pin spring of a disc (a clearance all round, e.g. an equidistant modification,
        # wider than the approaches of the first step, with stiff bearings) leaves the disc's and
        # the carrier's rotation free, the next Newton matrix is singular and the iteration
        # cycles. Open springs that keep a weak stiffness never leave a mechanism; their small
        # tensile forces are only a start, which the solve below removes
        # A start that settles but from which the solve itself does not (a radial clearance larger
        # than the first step's approaches can leave every roller open at the start) is followed
        # by the next way of starting.
        torque_side = np.concatenate([_torque_side(b, torque) for b in bodies])
        everything = np.ones(torque_side.size, dtype=bool)
        attempts = [(0.0, everything), (OPEN_SPRING_FRACTION, everything)]
        if not torque_side.all():
            attempts.insert(0, (0.0, torque_side))
        for i, (open_fraction, engaged) in enumerate(attempts):
            try:
                first = _newton(linearised(open_fraction), torque, coupling, None, options, engaged=engaged)
                return _newton(bodies, torque, coupling, first, options)
            except ContactError:
                if i == len(attempts) - 1:
                    raise
    return _newton(bodies, torque, coupling, start, options)
