"""Pluggable crank-bearing and pin models.

A crank-bearing model says how a bearing's load enters the disc at a crank angle: which footprint
columns of the bore it loads, with which force law, and how the solved contact forces add up to
the bearing force (and roller loads, where the model has rollers). A pin model says how a pin acts
on the tooth flank: as a rigid body (a Signorini contact) or through a force–approach law.

Both are plain classes behind the small protocols :class:`BearingModel` and :class:`PinModel`,
registered by name in :mod:`rvfem.case.registry`; the case reader, the command line and the report take
the names and the sentences they print from there. Adding a bearing model is one class with the
methods below, decorated with :func:`rvfem.case.registry.register_bearing_model`, plus its case keys.

The contact laws are functions ``law(delta) -> (Q, dQ/dδ)`` of the approach δ (mm) returning the
force (N) and its derivative (N/mm), see :func:`rvfem.solve.contact.palmgren_law`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

import numpy as np
import scipy.sparse as sp

from rvfem._arrays import readonly as _readonly
from rvfem.case.definition import Case
from rvfem.case.mesh_checks import footprint_half_widths
from rvfem.case.registry import (
    builtin_model_names,
    register_bearing_model,
    register_pin_model,
    registered_models,
)
from rvfem.errors import CaseError
from rvfem.geometry import PinContacts
from rvfem.solve import contact
from rvfem.solve.contact_interface import Interface
from rvfem.solve.contact_laws import ForceLaw

__all__ = [
    "ContactGroup",
    "BearingModel",
    "PinModel",
    "RollerBearing",
    "RigidBoreBearing",
    "RigidPins",
    "HertzPins",
    "PalmgrenPins",
    "LinearPins",
    "hertz_pin_parameters",
    "roller_angles",
    "bearing_contacts_many",
    "bearing_laws",
    "contact_columns",
    "contact_columns_many",
]


@dataclass(frozen=True)
class ContactGroup:
    """The contacts that one model adds at one crank angle (m contacts).

    Attributes
    ----------
    W : scipy.sparse.csc_matrix (n_columns, m)
        Weights of each contact on the disc's interface columns (approach measured along them).
    signorini : ndarray bool (m,)
        True for rigid contacts (gap ≥ 0 ⟂ λ ≥ 0).
    gap0 : ndarray (m,)
        Initial gap of the Signorini contacts, mm (0 for springs).
    offset : ndarray (m,)
        Constant part of a spring's approach, mm.
    laws : list of (ndarray of local indices, law)
        Force laws of the spring contacts.
    names : list of str
        One name per contact, for messages, numbered from 1 like everything a user reads
        (``pin 7``, ``bearing 1 roller 3``).
    bearing : ndarray int (m,)
        Index of the crank bearing each contact belongs to, −1 for pins.
    W_load : scipy.sparse.csc_matrix or None
        Weights of the contact *loads* where they differ from ``W`` (pin friction).
    """

    W: sp.csc_matrix
    signorini: np.ndarray
    gap0: np.ndarray
    offset: np.ndarray
    laws: list[tuple[np.ndarray, ForceLaw]]
    names: list[str]
    bearing: np.ndarray
    W_load: sp.csc_matrix | None = None

    @property
    def size(self) -> int:
        return self.W.shape[1]


def _group(n_columns: int, rows: list[np.ndarray], cols: list[np.ndarray], vals: list[np.ndarray], m: int,
           **kw: Any) -> ContactGroup:
    W = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n_columns, m))
    return ContactGroup(W=W, **kw)


def contact_columns(n_columns: int, columns: np.ndarray, weights: np.ndarray) -> sp.csc_matrix:
    """W of m contacts that each load k distinct interface columns, built directly in CSC form.

    Parameters
    ----------
    n_columns : int
        Interface columns.
    columns, weights : ndarray (m, k)
        The columns of each contact and their weights (:meth:`rvfem.solve.contact.FootprintGrid.columns_at`).

    Returns
    -------
    scipy.sparse.csc_matrix (n_columns, m)
        With sorted indices, as built from coordinates (zero weights kept as entries).
    """
    return contact_columns_many(n_columns, np.asarray(columns)[None], np.asarray(weights)[None])[0]


def contact_columns_many(n_columns: int, columns: np.ndarray, weights: np.ndarray) -> list[sp.csc_matrix]:
    """:func:`contact_columns` of many crank angles, ``columns`` and ``weights`` (n, m, k): sorted
    all at once, each angle's W a view of the joint arrays."""
    columns = np.asarray(columns)
    n, m, k = columns.shape
    order = np.argsort(columns, axis=2, kind="stable")
    # 32-bit indices, as SciPy would choose for them anyway (it checks 64-bit ones value by value)
    rows = np.take_along_axis(columns, order, axis=2).reshape(n, m * k).astype(np.int32)
    data = np.take_along_axis(np.asarray(weights, dtype=float), order, axis=2).reshape(n, m * k)
    indptr = np.arange(0, m * k + 1, k, dtype=np.int32)
    return [sp.csc_matrix((data[a], rows[a], indptr), shape=(n_columns, m)) for a in range(n)]


class BearingModel(Protocol):
    """What a crank-bearing model provides (one instance per analysed case).

    ``name`` is the value of ``crank_bearing.model``; the constructor takes the case and the
    stiffness scale of the rigid-limit checks (1 in an ordinary analysis).
    """

    name: ClassVar[str]

    def __init__(self, case: Case, stiffness_scale: float = 1.0) -> None: ...

    def describe(self) -> str:
        """One sentence for the report's assumptions."""

    def contacts(self, interface: Interface, centres: np.ndarray, theta: float) -> ContactGroup:
        """The bearing contacts at crank angle θ (rad); ``centres`` are the bore centres (N, 2).

        A model may also provide ``contacts_many(interface, centres, thetas)``, the list of the
        contacts of many angles at once (faster, same result); :func:`bearing_contacts_many`
        uses it when it is there."""

    def bearing_forces(self, vectors: np.ndarray, forces: np.ndarray, theta: float
                       ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
        """Bearing forces on the disc (N, 2), roller loads (N, Z) and roller angles (N, Z), rad
        (None without rollers), from the solved forces of this group's contacts."""


class PinModel(Protocol):
    """What a pin model provides: rigid (Signorini) or a force–approach law per pin."""

    name: ClassVar[str]
    rigid: ClassVar[bool]

    def __init__(self, case: Case, stiffness_N_per_mm: float | None = None) -> None: ...

    def describe(self) -> str:
        """One sentence for the report's assumptions."""

    def law(self, contacts: PinContacts | None = None, curvature: np.ndarray | None = None) -> ForceLaw | None:
        """The pins' force–approach law at one crank angle (None for rigid pins).

        ``contacts`` is the angle's :class:`rvfem.geometry.PinContacts` and ``curvature`` (Zp,)
        the flank curvature at each pin's contact point, 1/mm; a law may use them (the Hertz law
        does: its compliance depends on the local curvature) or not. The law is vectorised over
        the pins: ``law(delta) -> (Q, dQ/dδ)``.
        """


def bearing_contacts_many(bearings: BearingModel, interface: Interface, centres: np.ndarray, thetas: Sequence[float] | np.ndarray
                          ) -> list[ContactGroup]:
    """The contacts of a bearing model at many crank angles: its ``contacts_many`` where it has
    one, else its ``contacts`` angle by angle."""
    many = getattr(bearings, "contacts_many", None)
    if many is not None:
        return many(interface, centres, thetas)
    return [bearings.contacts(interface, centres, float(theta)) for theta in thetas]


def roller_angles(case: Case, theta: float | np.ndarray) -> np.ndarray:
    """Angular positions of the rollers of every bearing at crank angle θ, (N, Z), rad; for an
    array of angles (n,), (n, N, Z).

    Measured about each bore centre from the disc's x axis. The eccentric turns by θ relative to
    the disc (the disc only translates relative to the carrier), so the cage turns by
    θ·(1 − γ)/2 with γ = D_we/D_m (outer ring fixed). The cage of the bearing of a crank at Δ_i
    from the first is where the first bearing's cage is at θ − Δ_i, turned by Δ_i, with that
    crank angle taken modulo one revolution: ψ_i = ((θ − Δ_i) mod 2π)·(1 − γ)/2 + Δ_i. A cage
    does not return to its place after one crank revolution (it has turned by π(1 − γ)), so a
    load cycle is one revolution's sample of the cage phases; taking that revolution the same
    way for every bearing makes the cycle 2π-periodic and, on an N-fold symmetric disc, the
    state at θ + 2π/N exactly the state at θ turned, with bearing i + 1 in the place of bearing
    i (:func:`rvfem.solve.cycle.turn_result`). Rollers of one bearing are 2π/Z apart.
    """
    b = case.crank_bearing
    gamma = b.roller_diameter / b.pitch_diameter
    alpha = np.radians(case.cranks.angles_deg)
    shift = alpha - alpha[0]
    # the revolution starts 1e-9 rad before θ = Δ_i, so that crank angles that are Δ_i up to
    # round-off (θ = 120° as 12·10° or as 210° − 90°) all fall on the same side of it
    theta_col = np.asarray(theta, dtype=float)[..., None]
    cage = (np.mod(theta_col - shift + 1e-9, 2.0 * np.pi) - 1e-9) * (1.0 - gamma) / 2.0 + shift
    return cage[..., None] + 2.0 * np.pi * np.arange(b.rollers) / b.rollers


@register_bearing_model
class RollerBearing:
    """Discrete rollers: each a compression-only spring along its radial line.

    The approach of a roller is the radial relative displacement of eccentric and bore minus half
    the radial clearance; its law is Palmgren's line contact for both raceways (Harris & Kotzalas,
    *Rolling Bearing Analysis*) less the bore's local contact compliance that the FE bore footprint
    already holds (:func:`rvfem.solve.contact_laws.roller_bore_law`: the bore's compliance counted
    once, as the Hertz pin law does for the flank), or a linear stiffness. Rollers sit at their cage
    positions (:func:`roller_angles`); each roller's force is shared by the two nearest bore columns.

    ``disc_stiffness_scale`` is the factor on the disc's Young's modulus of the FE model it loads
    (:func:`rvfem.solve.cycle_system.build_system` passes it, :attr:`takes_disc_stiffness_scale`):
    a stiffened disc holds that much less of the bore's local compliance, and the law gives it back
    (Palmgren's law in the rigid-disc limit).
    """

    name = "rollers"
    takes_disc_stiffness_scale: ClassVar[bool] = True

    def __init__(self, case: Case, stiffness_scale: float = 1.0, *, disc_stiffness_scale: float = 1.0) -> None:
        self.case = case
        b = case.crank_bearing
        if b.stiffness_law == "palmgren":
            r = 0.5 * b.roller_diameter
            self._law = contact.roller_bore_law(
                length=b.roller_length, reduced_radius_bore=r * b.bore_radius / (b.bore_radius - r),
                disc_modulus=case.material.youngs_modulus, disc_poisson=case.material.poissons_ratio,
                footprint_half_width=footprint_half_widths(case)["bore"],
                disc_stiffness_scale=disc_stiffness_scale)
        else:
            assert b.linear_stiffness_N_per_mm is not None      # the case requires it with the linear law
            self._law = contact.linear_law(b.linear_stiffness_N_per_mm)

    def describe(self) -> str:
        b = self.case.crank_bearing
        law = ("Palmgren line contact on both raceways, the bore's local compliance left to the FE bore"
               if b.stiffness_law == "palmgren"
               else f"a linear stiffness of {b.linear_stiffness_N_per_mm:g} N/mm")
        return (f"crank bearings: {b.rollers} discrete rollers per bearing at their cage positions, "
                f"each a compression-only spring ({law}), radial clearance {b.radial_clearance:g} mm")

    def contacts(self, interface: Interface, centres: np.ndarray, theta: float) -> ContactGroup:
        return self.contacts_many(interface, centres, [theta])[0]

    def contacts_many(self, interface: Interface, centres: np.ndarray, thetas: Sequence[float] | np.ndarray) -> list[ContactGroup]:
        """:meth:`contacts` of many crank angles: the rollers of all of them located on each bore
        at once."""
        b = self.case.crank_bearing
        psi = roller_angles(self.case, np.asarray(thetas, dtype=float))       # (n, N, Z)
        n_angles, n_bearings, z = psi.shape
        bore_cols, bore_wts = [], []
        for i, c in enumerate(centres):
            grid = interface.grids[f"bore_{i}"]
            pts = c + b.bore_radius * np.stack([np.cos(psi[:, i]), np.sin(psi[:, i])], axis=-1)
            cc, ww = grid.columns_at(grid.arc_of(pts.reshape(-1, 2)))
            bore_cols.append(cc.reshape(n_angles, z, 2))
            bore_wts.append(ww.reshape(n_angles, z, 2))
        cols, wts = np.concatenate(bore_cols, axis=1), np.concatenate(bore_wts, axis=1)   # bearing after bearing
        n = n_bearings * z
        names = [f"bearing {i + 1} roller {k + 1}" for i in range(n_bearings) for k in range(z)]
        bearing = np.repeat(np.arange(n_bearings), z)
        laws = [(np.arange(n), self._law)]
        # shared by the groups of all angles, hence read-only
        signorini, gap0, offset = (_readonly(a) for a in (np.zeros(n, dtype=bool), np.zeros(n),
                                                          np.full(n, -0.5 * b.radial_clearance)))
        return [ContactGroup(W=W, signorini=signorini, gap0=gap0, offset=offset, laws=laws, names=names,
                             bearing=bearing)
                for W in contact_columns_many(interface.n_columns, cols, wts)]

    def bearing_forces(self, vectors: np.ndarray, forces: np.ndarray, theta: float
                       ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
        n, z = self.case.cranks.count, self.case.crank_bearing.rollers
        return (vectors.reshape(n, z, 2).sum(axis=1), forces.reshape(n, z),
                roller_angles(self.case, theta))


@register_bearing_model
class RigidBoreBearing:
    """The bore tied to a rigid ring by a radial pressure ∝ cos, with one isotropic spring.

    Each bearing is two bilateral springs (x and y) of stiffness
    ``crank_bearing.rigid_bore_stiffness_N_per_mm``; the force enters the bore as a radial
    pressure proportional to the cosine of the angle to the force (a deformable remote point that
    does not stiffen the bore).
    """

    name = "rigid_bore"

    def __init__(self, case: Case, stiffness_scale: float = 1.0) -> None:
        self.case = case
        self.stiffness = case.crank_bearing.rigid_bore_stiffness_N_per_mm * stiffness_scale

    def describe(self) -> str:
        return ("crank bearings: each bore tied to a rigid ring by a radial pressure ∝ cos, with one "
                f"isotropic bearing spring of {self.stiffness:.3g} N/mm")

    def contacts(self, interface: Interface, centres: np.ndarray, theta: float) -> ContactGroup:
        rows: list[np.ndarray] = []
        cols: list[np.ndarray] = []
        vals: list[np.ndarray] = []
        names: list[str] = []
        bearing: list[int] = []
        n = 0
        for i, c in enumerate(centres):
            grid = interface.grids[f"bore_{i}"]
            ang = np.arctan2(*(interface.points[grid.offset:grid.offset + grid.count] - c).T[::-1])
            colsb = grid.offset + np.arange(grid.count)
            for comp, w in (("x", np.cos(ang)), ("y", np.sin(ang))):
                rows.append(colsb)
                cols.append(np.full(grid.count, n))
                vals.append(2.0 / grid.count * w)
                names.append(f"bearing {i + 1} {comp}")
                bearing.append(i)
                n += 1
        return _group(interface.n_columns, rows, cols, vals, n, signorini=np.zeros(n, dtype=bool),
                      gap0=np.zeros(n), offset=np.zeros(n),
                      laws=[(np.arange(n), contact.linear_law(self.stiffness, bilateral=True))],
                      names=names, bearing=np.asarray(bearing))

    def bearing_forces(self, vectors: np.ndarray, forces: np.ndarray, theta: float
                       ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
        n = self.case.cranks.count
        return vectors.reshape(n, 2, 2).sum(axis=1), None, None


@register_pin_model
class RigidPins:
    """Rigid pins: Signorini contact (gap ≥ 0, force ≥ 0, no force across a gap) with the flank.

    For: the limit of infinitely stiff pin contacts. On an elastic disc the local contact
    compliance is then whatever the FE footprint makes it (a mesh parameter, not physics), and the
    load concentrates on few pins; use it for comparisons, not as the model of a reducer.
    """

    name = "rigid"
    rigid = True

    def __init__(self, case: Case, stiffness_N_per_mm: float | None = None) -> None:
        self.case = case

    def describe(self) -> str:
        return "rigid pins (Signorini contact: gap ≥ 0, force ≥ 0)"

    def law(self, contacts: PinContacts | None = None, curvature: np.ndarray | None = None) -> ForceLaw | None:
        return None


def _footprint_half_width(case: Case) -> float:
    """Half-width of the FE pin-load footprint, mm (``FOOTPRINT_ELEMENTS`` spacings of the contact
    grid, :func:`rvfem.case.mesh_checks.footprint_half_widths`)."""

    return footprint_half_widths(case)["profile"]


@register_pin_model
class HertzPins:
    """Compliant pins: the Hertz line contact of the pin (radius r_rp) with the flank, at the flank's
    own radius of curvature at each contact point, with the elastic constants of pin and disc.

    The approach is the pin centre's (Johnson, *Contact Mechanics*) plus the local disc
    compression that the FE footprint does not resolve (:func:`rvfem.solve.contact.hertz_pin_approach`).
    For: the default model of a reducer — the compliance the physics of the contact gives, which
    makes the load sharing among the pins independent of the mesh.
    """

    name = "hertz"
    rigid = False

    def __init__(self, case: Case, stiffness_N_per_mm: float | None = None) -> None:
        self.case = case

    def describe(self) -> str:
        p, m = self.case.pins, self.case.material
        return (f"compliant pins: Hertz line contact of each pin (r_rp = {p.radius:g} mm, E = "
                f"{p.youngs_modulus:g} MPa, ν = {p.poissons_ratio:g}) with the flank at its local "
                f"curvature (disc E = {m.youngs_modulus:g} MPa, ν = {m.poissons_ratio:g}), over the "
                f"disc width {self.case.cycloid.thickness:g} mm")

    def law(self, contacts: PinContacts | None = None, curvature: np.ndarray | None = None) -> ForceLaw | None:
        """The law of the pins of one crank angle; ``curvature`` (Zp,) is the flank curvature at
        each pin's contact point, 1/mm (:func:`rvfem.geometry.profile_curvature`)."""
        if curvature is None:
            raise ValueError("the Hertz pin law needs the flank curvature at each contact point")
        return contact.hertz_pin_law(**hertz_pin_parameters(self.case, np.asarray(curvature, dtype=float)))


def hertz_pin_parameters(case: Case, curvature: np.ndarray) -> dict[str, Any]:
    """The parameters of the Hertz pin law (:func:`rvfem.solve.contact.hertz_pin_law`) and of its
    inverse (:func:`rvfem.solve.contact.hertz_pin_approach`) for ``case`` at the flank curvatures
    ``curvature`` (1/mm), as :class:`HertzPins` uses them."""
    return dict(length=case.cycloid.thickness, pin_radius=case.pins.radius, flank_curvature=curvature,
                pin_modulus=case.pins.youngs_modulus, pin_poisson=case.pins.poissons_ratio,
                disc_modulus=case.material.youngs_modulus, disc_poisson=case.material.poissons_ratio,
                footprint_half_width=_footprint_half_width(case))


@register_pin_model
class PalmgrenPins:
    """Compliant pins: Palmgren's line-contact approach of one steel roller–raceway contact over the
    disc width, δ = 3.84e-5·Q^0.9/b^0.8 (Harris & Kotzalas, *Rolling Bearing Analysis*).

    For: comparison with rvfem before the Hertz pin law (this was ``"hertz"`` then) and with tools
    that use Palmgren's formula. It ignores the pin radius, the flank curvature and the materials.
    """

    name = "palmgren"
    rigid = False

    def __init__(self, case: Case, stiffness_N_per_mm: float | None = None) -> None:
        self.case = case

    def describe(self) -> str:
        return ("compliant pins: Palmgren's steel line-contact approach of each pin–flank contact "
                "(independent of pin radius, flank curvature and materials)")

    def law(self, contacts: PinContacts | None = None, curvature: np.ndarray | None = None) -> ForceLaw | None:
        return contact.palmgren_law(self.case.cycloid.thickness, contacts=1)


@register_pin_model
class LinearPins:
    """Linear pin springs Q = k·δ (compression only): the classical textbook assumption that the
    pin deflections are proportional to the forces.

    For: the classical pin-force distribution. On a (nearly) rigid disc held at its centre with a
    stiffness k far below the disc's, the pins' forces are the textbook
    F_i = F_max·sin φ_i/√(1 + K1² − 2K1·cos φ_i). The stiffness is ``pins.linear_stiffness_N_per_mm``
    (or passed explicitly for the validation checks).
    """

    name = "linear"
    rigid = False

    def __init__(self, case: Case, stiffness_N_per_mm: float | None = None) -> None:
        if stiffness_N_per_mm is None:
            stiffness_N_per_mm = getattr(case.pins, "linear_stiffness_N_per_mm", None)
        if not (stiffness_N_per_mm and stiffness_N_per_mm > 0):
            raise CaseError("pin model 'linear' needs a positive pin stiffness "
                            "(pins.linear_stiffness_N_per_mm, N/mm)")
        self.case = case
        self.stiffness = float(stiffness_N_per_mm)

    def describe(self) -> str:
        return f"linear pin springs of {self.stiffness:g} N/mm (the classical pin-force assumption)"

    def law(self, contacts: PinContacts | None = None, curvature: np.ndarray | None = None) -> ForceLaw | None:
        return contact.linear_law(self.stiffness)


def _model(kind: str, name: str) -> type:
    registered = registered_models(kind)
    try:
        return registered[name]
    except KeyError:
        known = ", ".join(dict.fromkeys([*builtin_model_names(kind), *registered]))
        raise KeyError(f"unknown {kind} model {name!r}; known: {known}") from None


def bearing_model(name: str) -> type:
    """The class of the crank-bearing model ``name`` (built in or registered,
    :func:`rvfem.case.registry.register_bearing_model`)."""
    return _model("bearing", name)


def pin_model(name: str) -> type:
    """The class of the pin model ``name`` (built in or registered,
    :func:`rvfem.case.registry.register_pin_model`)."""
    return _model("pin", name)


def bearing_laws(name: str, case: Case, stiffness_scale: float = 1.0, disc_stiffness_scale: float = 1.0) -> BearingModel:
    """The crank-bearing model ``name`` of ``case`` (:func:`bearing_model`), built with its stiffness
    scale and, for a model whose law complements the FE bore's own compliance
    (:attr:`RollerBearing.takes_disc_stiffness_scale`), the factor on the disc's Young's modulus of the
    FE model it loads.

    Raises
    ------
    KeyError
        ``name`` is not a known bearing model.
    """
    model = bearing_model(name)
    if getattr(model, "takes_disc_stiffness_scale", False):
        return model(case, stiffness_scale, disc_stiffness_scale=disc_stiffness_scale)
    return model(case, stiffness_scale)
