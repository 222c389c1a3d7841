"""What one crank angle's contact problem is made of: its contact set, its solution and a body.

A :class:`ContactSet` holds the contacts of one crank angle in interface terms, an
:class:`AngleSolution` the solved forces, gaps, rigid motion and carrier rotation, and a
:class:`Body` one disc's contacts with its interface and compliance (the unit of
:func:`rvfem.solve.contact.solve_bodies`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from rvfem.solve.contact_compliance import Compliance
from rvfem.solve.contact_interface import Interface


@dataclass(frozen=True)
class ContactSet:
    """The contacts of one crank angle, in interface terms.

    Attributes
    ----------
    W : sparse (n_cols, n_contacts)
        Weights of each contact on the interface columns.
    signorini : ndarray bool (n_contacts,)
        True for rigid pins (gap ≥ 0 ⟂ λ ≥ 0); False for springs.
    gap0 : ndarray (n_contacts,)
        Initial gap of Signorini contacts (mm, negative = overlap), 0 for springs.
    offset : ndarray (n_contacts,)
        Constant part of a spring's approach (mm): −gap for compliant pins, −clearance/2 for rollers.
    lever : ndarray (n_contacts,)
        m_c: approach per unit carrier rotation (mm/rad) = c_i × F̂_c for bearing contacts.
    laws : list of (slice, law)
        Force laws of the spring contacts.
    W_load : sparse (n_cols, n_contacts) or None
        Weights of the *load* of each contact if it differs from ``W`` (Coulomb friction at the
        pins: the force on the disc is λ·(d + μ·s·t), normal plus friction along the known sliding
        direction, while the gap is still measured along the normal d). None: same as ``W``.
    """

    W: sp.csc_matrix
    signorini: np.ndarray
    gap0: np.ndarray
    offset: np.ndarray
    lever: np.ndarray
    laws: list
    W_load: sp.csc_matrix | None = None
    bearing: np.ndarray | None = None

    @property
    def load_weights(self) -> sp.csc_matrix:
        """The weights the contact forces load the disc along: ``W_load``, or ``W`` without one."""
        return self.W if self.W_load is None else self.W_load


@dataclass(frozen=True)
class AngleSolution:
    """Solution of one crank angle.

    Attributes
    ----------
    force : ndarray (n_contacts,)
        Contact force magnitudes λ (N), on the disc along each contact's direction.
    vectors : ndarray (n_contacts, 2)
        Force vectors on the disc, N.
    gap : ndarray (n_contacts,)
        Final gap of Signorini contacts / −approach of springs, mm.
    rigid : ndarray (3,)
        Rigid-body motion of the disc relative to the K_s support: ux, uy (mm), rotation (rad).
    carrier_rotation : float
        φ, rad.
    iterations : int
    residual : dict
        Equilibrium residuals: ``force_N`` (|ΣF|), ``moment_Nmm`` (|ΣM| about the disc centre),
        ``carrier_Nmm`` (|Σ m λ − T|), ``relative`` (force residual / total contact force).
    """

    force: np.ndarray
    vectors: np.ndarray
    gap: np.ndarray
    rigid: np.ndarray
    carrier_rotation: float
    iterations: int
    residual: dict = field(default_factory=dict)


def extrapolated_start(before: AngleSolution, last: AngleSolution) -> AngleSolution:
    """A warm start for the next of equally spaced crank angles: the contact forces (kept ≥ 0),
    the rigid motion and the carrier rotation extrapolated linearly from the last two solutions.

    On the default fan-hole case the Newton iterations per angle fall from 4.5 (the last
    solution as the start) to 2.4; the solutions agree within the iteration's tolerance
    (bearing loads to 3e-9 of the peak)."""
    return dataclasses.replace(last, force=np.maximum(2.0 * last.force - before.force, 0.0),
                               rigid=2.0 * last.rigid - before.rigid,
                               carrier_rotation=2.0 * last.carrier_rotation - before.carrier_rotation)


@dataclass(frozen=True)
class Body:
    """One elastic body of a contact solve: its contacts at this crank angle, its footprint
    interface and its (lazily filled) column compliance. Two discs of the same mesh may share one
    :class:`rvfem.solve.contact_compliance.Compliance`."""

    cset: ContactSet
    interface: Interface
    compliance: Compliance

    def moments(self) -> np.ndarray:
        """Moment about the disc centre of each contact's load per unit force, N·mm/N."""
        return np.asarray(self.cset.load_weights.T @ self.interface.resultants[:, 2])
