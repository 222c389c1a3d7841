"""One crank angle of one disc: its solve and its result.

:func:`solve_angle` solves the contacts of one crank angle (:func:`rvfem.solve.contact.solve_contact`)
and gives an :class:`AngleResult`: the pin forces, the crank-bearing and roller loads and the carrier
rotation; :func:`solve_from_last` starts the next of equally spaced angles from the ones before it.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from rvfem.errors import ContactError
from rvfem.solve import contact
from rvfem.solve.contact import AngleSolution, ContactSet
from rvfem.solve.cycle_contacts import contact_set
from rvfem.solve.cycle_system import DiscSystem, OperatingPoint


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
        φ, rad (carrier relative to the pin housing, about the reducer axis).
    solution : contact.AngleSolution
    contacts : contact.ContactSet
    origin : (AngleResult, int) or None
        For a result obtained by symmetry (:func:`rvfem.solve.cycle_symmetry.turn_result`): the solved
        result and the number of 2π/N turns; its displacement field is the solved one's, turned.
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
        the rigid motion, all a displacement field needs (:func:`rvfem.solve.cycle.displacements`)."""
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
    ``contacts`` passes the angle's :func:`rvfem.solve.cycle_contacts.contact_set` if it is already built."""
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


def solve_from_last(solve, last: list):
    """``solve(start)`` for the next of equally spaced angles, ``last`` the results of the (up to
    two) angles before it: started from their linear extrapolation
    (:func:`rvfem.solve.contact.extrapolated_start`), or from the last result if that start does not
    settle. Results are :class:`AngleResult` or :class:`rvfem.solve.cycle_stage.PairResult` (disc by disc)."""
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
