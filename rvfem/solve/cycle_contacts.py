"""The contact sets of a disc model: its pins and crank-bearing rollers at a crank angle, cached.

:func:`contact_set` gives the contacts of one crank angle at an operating point in interface terms
(:class:`rvfem.solve.contact.ContactSet`); :func:`contact_sets` builds many angles at once and keeps
them in the model's cache (:attr:`rvfem.solve.cycle.DiscSystem.contact_sets`), keyed by value
(:func:`contact_model_key`), for the cycles and sweeps that revisit the same angles.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from rvfem.geometry import (
    crank_centres,
    pin_centres,
    pin_phases,
    pin_profile_contacts,
    pin_profile_contacts_many,
    profile_curvature,
)
from rvfem.solve.contact import ContactSet
from rvfem.solve.cycle_system import DiscSystem, OperatingPoint
from rvfem.solve.models import ContactGroup, bearing_contacts_many, contact_columns_many


def pin_contacts(system: DiscSystem, theta: float, friction: float, pc=None):
    """The pin contacts of crank angle θ (rad) as a :class:`rvfem.solve.models.ContactGroup`.

    Each pin pushes along the inward normal of the profile at its closest point; the gap is the
    exact one of the (modified, pitch-error) profile, plus the system's flank deviation at the
    pin's phase when it has one (:attr:`rvfem.solve.cycle.DiscSystem.flank_deviation`). With
    friction (μ = ``friction``, the operating point's) the load on the disc is λ·(d + μ·s·t) along
    the known sliding direction, while the gap is still measured along the normal d. The pin
    model's law gets the angle's contacts and the flank curvature at each pin's closest point (the
    Hertz law depends on it).
    ``pc`` passes the angle's :class:`rvfem.geometry.PinContacts` if they are already computed.
    """

    if pc is None:
        pc = pin_profile_contacts(system.geometry, theta)
    return pin_contacts_many(system, [pc], friction)[0]


def pin_contacts_many(system: DiscSystem, pcs, friction: float, slip: int = 0) -> list:
    """:func:`pin_contacts` of many crank angles from their :class:`rvfem.geometry.PinContacts`:
    the closest points of all of them located on the footprint grid at once. ``slip`` as in
    :class:`rvfem.solve.cycle.OperatingPoint` (0: the pins slide as the crank turns)."""

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
            # a load step at a held crank angle: the disc turns with the carrier about the reducer
            # axis O (at −e·u(θ) in the disc frame), so a pin moves relative to the disc by
            # −slip·ẑ × (c − O)
            c = np.concatenate([pin_centres(case, pc.theta) - reducer_axis(case, pc.theta) for pc in pcs])
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
        gap = np.asarray(pc.gap)
        if system.flank_deviation is not None:     # worn flanks: the same for every tooth, by pin phase
            gap = gap + system.flank_deviation.gap(pin_phases(case, pc.theta))
        out.append(ContactGroup(
            W=Ws[a], signorini=np.full(zp, rigid),
            gap0=gap if rigid else np.zeros(zp),
            offset=np.zeros(zp) if rigid else -gap,
            laws=[] if law is None else [(np.arange(zp), law)], names=names,
            bearing=np.full(zp, -1), W_load=W_load))
    return out


def contact_set(system: DiscSystem, theta: float, op: OperatingPoint | None = None
                ) -> tuple[ContactSet, list[str]]:
    """The contacts of crank angle θ (rad) at the operating point ``op`` (default the case's):
    every pin (the pin model's), then the bearing contacts (the bearing model's).

    Returns the contact set and a name per contact (``pin 7``, ``bearing 1 roller 3``, ...).
    Built once per angle, pin friction and system (:attr:`rvfem.solve.cycle.DiscSystem.contact_sets`).
    """
    return contact_sets(system, [theta], OperatingPoint.of(system.case) if op is None else op)[0]


def contact_sets(system: DiscSystem, thetas, op: OperatingPoint) -> list[tuple[ContactSet, list[str]]]:
    """:func:`contact_set` of many crank angles; the pin contacts of the angles not built yet
    come from one vectorised closest-point search (:func:`rvfem.geometry.pin_profile_contacts_many`).

    The cache is keyed by value: the crank angle, the pin friction (the only part of the
    operating point the contacts depend on; the torque enters the solve alone) and the models the
    contacts come from (:func:`contact_model_key`)."""

    model = contact_model_key(system)
    keys = [(round(float(theta), 12), float(op.friction)) + model + ((op.slip,) if op.slip else ())
            for theta in thetas]
    missing = {key: float(theta) for key, theta in zip(keys, thetas) if key not in system.contact_sets}
    if missing:
        angles = list(missing.values())
        pins = pin_contacts_many(system, pin_profile_contacts_many(system.geometry, angles), op.friction, op.slip)
        bearings = bearing_contacts_many(system.bearings, system.interface, crank_centres(system.case), angles)
        for (key, theta), p, b in zip(missing.items(), pins, bearings):
            system.contact_sets[key] = _contact_set(system, p, b, theta)
    return [system.contact_sets[key] for key in keys]


def contact_model_key(system: DiscSystem) -> tuple:
    """What a system's contacts depend on besides the crank angle and the friction, by value: the
    case (frozen, hashable), the bearing and pin models with their stiffness options and the flank
    deviation. Systems that share an interface and a compliance (:func:`dataclasses.replace` of
    one disc model with another case) share the cache without mixing their contacts."""
    return (system.case, system.bearing_model, system.pin_model, system.bearing_stiffness_scale,
            system.pin_stiffness_N_per_mm, system.flank_deviation)


def reducer_axis(case, theta: float) -> np.ndarray:
    """The reducer axis O (the carrier's and the pin circle's centre) in the disc frame at crank
    angle θ (rad): −e·u(θ), mm (docs/theory.md § 1)."""
    e = case.cycloid.eccentricity
    return np.array([-e * np.cos(theta), -e * np.sin(theta)])


def _contact_set(system: DiscSystem, pins, bearings, theta: float) -> tuple[ContactSet, list[str]]:
    """One angle's contact set from its pin and bearing contacts (:class:`rvfem.solve.models.ContactGroup`)
    at crank angle θ (rad). The lever of a bearing contact is the approach per unit carrier rotation
    about the reducer axis O: m_c = ((c_i − O) × d_c)·ẑ, c_i its bore centre, d_c its unit force on
    the disc (the carrier with its eccentrics turns about O, docs/theory.md § 6)."""
    centres = crank_centres(system.case) - reducer_axis(system.case, theta)
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
