"""The pins' seats in the housing: ``[pin_housing]``, a stage component (:mod:`rvfem.solve.stage_parts`).

Between a pin–flank contact and the ground the pin force passes through

1. the **pin–groove contact**: the pin lies in a groove of the housing of radius R_g a little
   larger than the pin's r_p, a second Hertz line contact (concave–convex) in series with the
   pin–flank one (:func:`groove_approach`);
2. the **pin's bending** between its supports, where the pin is held at its ends over a free span
   (:func:`pin_bending_compliance`); a pin seated in its groove along its whole length (the RV-E
   construction, the default) has no free span and no bending compliance of its own: the groove
   contact carries it;
3. the **housing ring**: the ring of the housing around the pin circle bends and stretches under
   all the pin forces together (:func:`ring_influence`).

**How they enter.** (1) and (2) act on one pin each and only on its own force: they are springs in
series with each pin–flank contact. They change the pin law (:class:`SeriesPins`: the approach of a
pin is the flank's plus the seat's at the same force) and so the load sharing among the pins, the
bearing loads and the output rotation. (3) couples the pins (the ring's deflection at one pin
depends on the forces at all of them) and has no singular local part (the local deformation under a
pin is the groove contact's, counted in (1) down to the depth ``contact_depth``); it is a
curved-beam deflection three orders of magnitude below the contacts'. It enters as a series output
compliance: the output rotation it adds is its complementary energy, Δφ = Σ_j F_j·w_j / T =
T·q̂ᵀ G q̂ (q̂ the pin forces of both discs per unit output torque, the classical distribution of
:func:`classical_pin_forces`, G the ring's influence matrix). By the theorem of minimum
complementary energy this is exact to first order in G and an upper bound (the contacts would
redistribute a little to soften it), which is ample for a part this stiff.

Sources: Johnson, *Contact Mechanics* (1985), §4.2 and §5.6 (line contact, approach of a
cylinder's centre, the half-plane under a Hertz pressure), as the pin–flank law of
:func:`rvfem.solve.contact_laws.hertz_pin_approach`; Roark's *Formulas for Stress and Strain*
(Young & Budynas, 7th ed.), Table 8.1 (simply supported beam) and § 9.3 / Table 9.2 (thick curved
rings: hoop stress and radial shear, the constants α and β); Timoshenko & Goodier for the ring's
Fourier modes; Cowper (1966) for the shear coefficient of a circular section.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.special import lambertw

from rvfem.case.definition import Case, register_component_table
from rvfem.case.schema import param
from rvfem.solve.contact_laws import ForceLaw, hertz_pin_approach
from rvfem.solve.cycle_stage import ReducerStage
from rvfem.solve.models import hertz_pin_parameters
from rvfem.solve.stage_component import STIFFEN, StageComponent

__all__ = [
    "PinHousing",
    "PinHousingTable",
    "SeriesPins",
    "classical_pin_forces",
    "groove_approach",
    "pin_bending_compliance",
    "ring_influence",
    "ring_output_compliance",
    "series_law",
]

NAME = "pin_housing"
"""The component's name, its key in the compliance shares and its table."""

RING_MODES = 400
"""Fourier modes of the ring's influence matrix (its terms fall as 1/n², the tail past 400 is below
1e-3 of the sum at a load point and far less in the energy)."""


@dataclass(frozen=True)
class PinHousingTable:
    """The keys of ``[pin_housing]``. Defaults: the RV-40E class, estimated (the catalogue gives none
    of these dimensions): a pin seated along its length in a groove with a sliding fit, in a steel
    housing of about 190 mm outside diameter."""

    enabled: bool = param(True, doc="model the pins' seats and the housing ring (false: rigid seats, as before)")
    groove_clearance: float = param(0.01, unit="mm", low=0.0, low_open=True, high=1.0,
                                    doc="groove radius − pin radius, R_g − r_p (estimated: a sliding fit of a 6 mm pin)")
    groove_length: float | None = param(None, unit="mm", low=0.1, high=1000.0,
                                        default_doc="the disc width",
                                        doc="length of groove that carries one disc's pin force")
    contact_depth: float | None = param(None, unit="mm", low=0.1, high=1000.0,
                                        default_doc="half the ring's wall under the groove",
                                        doc="depth below the groove down to which the groove contact's approach is "
                                            "counted (the ring model takes over there)")
    pin_span: float = param(0.0, unit="mm", low=0.0, high=1000.0,
                            doc="free span of a pin held at its ends (0: seated in its groove along its length, "
                                "the RV-E construction: no bending compliance)")
    load_position: float | None = param(None, unit="mm", low=0.0, high=1000.0, default_doc="mid-span",
                                        doc="distance of a disc's pin load from a pin support, for `pin_span` > 0")
    ring_outer_radius: float = param(95.0, unit="mm", low=1.0, high=5000.0,
                                     doc="outer radius of the housing ring (estimated, RV-40E class)")
    ring_width: float | None = param(None, unit="mm", low=0.1, high=5000.0,
                                     default_doc="two disc widths + 2 mm",
                                     doc="axial width of the housing ring that carries the pins")
    youngs_modulus: float = param(206000.0, unit="MPa", low=1.0e3, high=1.2e6, doc="housing E (steel, estimated)")
    poissons_ratio: float = param(0.3, low=0.0, high=0.5, high_open=True, doc="housing ν")

    def check(self, fail: Any) -> None:
        if self.pin_span > 0 and self.load_position is not None and self.load_position > self.pin_span:
            raise fail("load_position", f"must be within the pin span ({self.pin_span:g} mm)")


# ------------------------------------------------------------------------------------------------
# (1) The pin in its groove
# ------------------------------------------------------------------------------------------------


def groove_approach(Q: Any, *, length: float, pin_radius: float, groove_radius: float, pin_modulus: float,
                    pin_poisson: float, housing_modulus: float, housing_poisson: float, depth: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Approach δ (mm) of a pin's centre towards the housing at the depth ``depth`` under the groove
    at the force Q (N), and dδ/dQ (mm/N).

    Hertz line contact of the pin (radius r_p) in the concave groove (R_g > r_p): relative radius
    R = r_p·R_g/(R_g − r_p), contact modulus 1/E* = (1 − ν_p²)/E_p + (1 − ν_h²)/E_h, half-width
    a = √(4PR/(πE*)), P = Q/L (Johnson, §4.2). The approach is the pin's, from its centre to the
    contact, δ_p = P(1 − ν_p²)/(πE_p)·(2 ln(4r_p/a) − 1) (Johnson §5.6), plus the housing's, a
    half-plane's surface approach to the depth d under the Hertz pressure,
    δ_h = 2P(1 − ν_h²)/(πE_h)·(ln(2d/a) − ν_h/(2(1 − ν_h))) (the form of
    :func:`rvfem.solve.contact_laws.hertz_pin_approach` for the disc). Beyond the half-width where
    dδ/dP falls to (1 − ν_p²)/(πE_p) + (1 − ν_h²)/(πE_h) the law is continued with that slope
    (monotone for any trial force; far beyond a pin's load).
    """
    Q = np.maximum(np.asarray(Q, dtype=float), 1e-300)
    cp = (1.0 - pin_poisson ** 2) / (math.pi * pin_modulus)
    ch = (1.0 - housing_poisson ** 2) / (math.pi * housing_modulus)
    e_star = 1.0 / (math.pi * (cp + ch))
    R = pin_radius * groove_radius / (groove_radius - pin_radius)
    k = housing_poisson / (2.0 * (1.0 - housing_poisson))
    # dδ/dP = cp(2 ln 4r_p − 2 ln a − 2) + 2ch(ln 2d − ln a − k − ½) = cp + ch at ln a_lim
    ln_a_lim = (cp * (2.0 * math.log(4.0 * pin_radius) - 3.0) + ch * (2.0 * math.log(2.0 * depth) - 2.0 * k - 2.0)
                ) / (2.0 * (cp + ch))
    P_lim = math.exp(2.0 * ln_a_lim) * math.pi * e_star / (4.0 * R)

    def parts(P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ln_a = 0.5 * np.log(4.0 * P * R / (math.pi * e_star))
        d = P * (cp * (2.0 * (math.log(4.0 * pin_radius) - ln_a) - 1.0) + 2.0 * ch * (math.log(2.0 * depth) - ln_a - k))
        dd = cp * (2.0 * (math.log(4.0 * pin_radius) - ln_a) - 2.0) + 2.0 * ch * (math.log(2.0 * depth) - ln_a - k - 0.5)
        return d, dd

    P = Q / length
    beyond = P > P_lim
    d, dd = parts(np.where(beyond, P_lim, P))
    return np.where(beyond, d + dd * (P - P_lim), d), dd / length


# ------------------------------------------------------------------------------------------------
# (2) The pin between its supports
# ------------------------------------------------------------------------------------------------


def pin_bending_compliance(span: float, position: float, diameter: float, youngs_modulus: float,
                           poissons_ratio: float) -> float:
    """Deflection per unit load (mm/N) at the load point of a round pin simply supported over
    ``span`` (mm) under a load at ``position`` (mm) from one support: bending
    a²b²/(3EIL) (Roark, Table 8.1, case 1e) plus Timoshenko shear a·b/(κGAL), κ = 6(1 + ν)/(7 + 6ν)
    for a circular section (Cowper); a = position, b = span − position. 0 for a span of 0 (a pin
    seated along its length)."""
    if span <= 0.0:
        return 0.0
    a, b = float(position), float(span) - float(position)
    I = math.pi * diameter ** 4 / 64.0
    A = math.pi * diameter ** 2 / 4.0
    G = youngs_modulus / (2.0 * (1.0 + poissons_ratio))
    kappa = 6.0 * (1.0 + poissons_ratio) / (7.0 + 6.0 * poissons_ratio)
    return a * a * b * b / (3.0 * youngs_modulus * I * span) + a * b / (kappa * G * A * span)


# ------------------------------------------------------------------------------------------------
# The pin law with its seat in series
# ------------------------------------------------------------------------------------------------


SeatApproach = Any
"""``seat(Q) -> (δ, dδ/dQ)``: the approach of a pin's seat at the force Q, vectorised (mm, mm/N)."""


def series_law(flank: ForceLaw, seat: SeatApproach, tolerance: float = 1e-12, iterations: int = 60,
               flank_approach: SeatApproach | None = None) -> ForceLaw:
    """The law of a pin–flank contact ``flank`` (δ_f → Q) in series with the seat ``seat``
    (Q → δ_s): the force Q at which δ_f(Q) + δ_s(Q) = δ, and dQ/dδ = 1/(1/k_f + 1/k_s).

    With the flank's approach ``flank_approach`` (Q → (δ_f, dδ_f/dQ), the inverse of ``flank``):
    Newton's method on Q from Q_f(δ), the flank's force at the whole approach (an upper bound; δ(Q)
    rises and is concave, so the iterates settle from below after the first step), to
    ``tolerance``·δ. Without it: solved for δ_f in [0, δ] (g(δ_f) = δ_f + δ_s(Q(δ_f)) − δ rises
    from −δ to ≥ 0) by Newton's method kept inside the bracket (bisection where a step leaves it)."""

    def explicit(delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        assert flank_approach is not None
        delta = np.asarray(delta, dtype=float)
        q0, _ = flank(delta)
        pos = q0 > 0
        if not np.any(pos):
            return np.zeros_like(q0), np.zeros_like(q0)
        d = np.where(pos, np.broadcast_to(delta, q0.shape), 1.0)
        Q = np.where(pos, q0, 1.0)              # the pins without force are carried along at 1 N
        for _ in range(iterations):
            df, ddf = flank_approach(Q)
            ds, dds = seat(Q)
            g = np.where(pos, df + ds - d, 0.0)
            Q = np.maximum(Q - g / (ddf + dds), 1e-12 * Q)
            if np.all(np.abs(g) <= tolerance * d):
                break
        _, ddf = flank_approach(Q)
        _, dds = seat(Q)
        return np.where(pos, Q, 0.0), np.where(pos, 1.0 / (ddf + dds), 0.0)

    if flank_approach is not None:
        return explicit

    def law(delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        delta = np.asarray(delta, dtype=float)
        q0, dq0 = flank(delta)
        q = np.zeros_like(q0)
        dq = np.zeros_like(dq0)
        pos = np.broadcast_to(delta, q0.shape) > 0
        if not np.any(pos):
            return q, dq
        d = np.broadcast_to(delta, q0.shape)
        lo, hi = np.zeros(q0.shape), np.where(pos, d, 0.0)
        # start: split δ by the two compliances at the flank's force at δ (a lower bound on Q)
        ds, dds = seat(q0)
        kf = np.where(dq0 > 0, dq0, 1.0)
        x = np.where(pos, d / (1.0 + dds * kf), 0.0)
        for _ in range(iterations):
            qx, dqx = flank(x)
            sx, dsx = seat(qx)
            g = np.where(pos, x + np.where(qx > 0, sx, 0.0) - d, 0.0)
            lo = np.where(g < 0, x, lo)
            hi = np.where(g > 0, x, hi)
            if np.all(np.abs(g) <= tolerance * np.maximum(d, 1e-300)):
                break
            step = x - g / (1.0 + dsx * dqx)
            x = np.where((step > lo) & (step < hi), step, 0.5 * (lo + hi))
        qx, dqx = flank(x)
        _, dsx = seat(qx)
        q = np.where(pos, qx, 0.0)
        dq = np.where(pos, dqx / (1.0 + dsx * dqx), 0.0)
        return q, dq

    return law


class SeriesPins:
    """A pin model (:class:`rvfem.solve.models.PinModel`) with each pin's seat in series with its
    flank contact: the law of ``base`` at the approach left after the seat's (:func:`series_law`).
    ``scale`` multiplies the seat's compliance (1/STIFFEN for the compliance shares). A rigid base
    (Signorini pins) is left rigid."""

    def __init__(self, base: Any, seat: SeatApproach, scale: float = 1.0) -> None:
        self.base = base
        self.seat = seat
        self.scale = float(scale)
        self.name = base.name
        self.rigid = base.rigid
        self.case = base.case

    def with_base(self, base: Any) -> "SeriesPins":
        """The same seats in series with another flank model."""
        return SeriesPins(base, self.seat, self.scale)

    def describe(self) -> str:
        return f"{self.base.describe()}; in series with each pin's seat in its housing groove"

    def _seat(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d, dd = self.seat(Q)
        return self.scale * d, self.scale * dd

    def law(self, contacts: Any = None, curvature: np.ndarray | None = None) -> ForceLaw | None:
        flank = self.base.law(contacts, curvature)
        if flank is None:
            return None
        approach = None
        if self.base.name == "hertz" and curvature is not None:
            params = hertz_pin_parameters(self.base.case, np.asarray(curvature, dtype=float))

            def approach(Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
                return hertz_pin_approach(Q, **params)    # the Hertz law's own inverse, explicit

            closed = getattr(self.seat, "log_form", None)
            if closed is not None:
                return _closed_form_law(params, closed, self.scale, series_law(flank, self._seat,
                                                                               flank_approach=approach))
        return series_law(flank, self._seat, flank_approach=approach)


def seat_approach(case: Case, table: PinHousingTable) -> SeatApproach:
    """The approach of one pin's seat (groove contact and bending) at its force, for ``case``."""
    p = case.pins
    length = table.groove_length if table.groove_length is not None else case.cycloid.thickness
    depth = table.contact_depth if table.contact_depth is not None else _wall(case, table) / 2.0
    c_bend = pin_bending_compliance(table.pin_span, table.pin_span / 2.0 if table.load_position is None
                                    else table.load_position, 2.0 * p.radius, p.youngs_modulus, p.poissons_ratio)
    params = dict(length=length, pin_radius=p.radius, groove_radius=p.radius + table.groove_clearance,
                  pin_modulus=p.youngs_modulus, pin_poisson=p.poissons_ratio, housing_modulus=table.youngs_modulus,
                  housing_poisson=table.poissons_ratio, depth=depth)

    def seat(Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d, dd = groove_approach(Q, **params)
        return d + c_bend * np.asarray(Q, dtype=float), dd + c_bend

    # δ_s = Q·(A − B ln Q) below the groove law's continuation point (groove_approach with ln a
    # substituted), for the closed-form series law of the Hertz pins (_closed_form_law)
    cp = (1.0 - p.poissons_ratio ** 2) / (math.pi * p.youngs_modulus)
    ch = (1.0 - table.poissons_ratio ** 2) / (math.pi * table.youngs_modulus)
    rg = p.radius + table.groove_clearance
    R = p.radius * rg / (rg - p.radius)
    k = table.poissons_ratio / (2.0 * (1.0 - table.poissons_ratio))
    beta = cp + ch
    alpha = (cp * (2.0 * math.log(4.0 * p.radius) - 1.0) + 2.0 * ch * (math.log(2.0 * depth) - k)
             - beta * math.log(4.0 * R * (cp + ch)))          # 4R/(πE*), E* = 1/(πβ)
    # the continuation point: dδ/dP = β(t − 1) = β at t = α/β − ln P = 2
    q_lim = length * math.exp(alpha / beta - 2.0)
    seat.log_form = ((alpha + beta * math.log(length)) / length + c_bend, beta / length, q_lim)  # type: ignore[attr-defined]
    return seat


def _closed_form_law(params: dict[str, Any], seat_form: tuple[float, float, float], scale: float,
                     fallback: ForceLaw) -> ForceLaw:
    """The Hertz pin law in series with its seat, inverted in closed form.

    Below both laws' continuation points the flank's approach is δ_f = P(α_f − β_f ln P), P = Q/L
    (:func:`rvfem.solve.contact_laws.hertz_pin_law`), and the seat's δ_s = Q(A_s − B_s ln Q)
    (``seat_form`` = (A_s, B_s, Q_lim), times ``scale``), so together δ = Q(A − B ln Q) with
    A = (α_f + β_f ln L)/L + A_s, B = β_f/L + B_s; with Q = e^(A/B − t), t·e^(−t) = δ·e^(−A/B)/B,
    whose root on the rising branch is t = −W₋₁(−δ·e^(−A/B)/B) (Lambert's W, as the flank law
    alone), dQ/dδ = 1/(B(t − 1)). A force past either continuation point (far beyond a pin's load;
    a trial approach of the solver) goes to ``fallback``, the iterative series law."""
    L = float(params["length"])
    rp, w = float(params["pin_radius"]), float(params["footprint_half_width"])
    cp = (1.0 - params["pin_poisson"] ** 2) / (math.pi * params["pin_modulus"])
    cd = (1.0 - params["disc_poisson"] ** 2) / (math.pi * params["disc_modulus"])
    beta_f = cp + cd
    inv_r = np.maximum(1.0 / rp + np.asarray(params["flank_curvature"], dtype=float), 1e-3 / rp)
    alpha_f = (cp * (2.0 * np.log(4.0 * rp) - 1.0) + 2.0 * cd * np.log(w)
               - beta_f * np.log(4.0 * beta_f / inv_r))          # 4/(κπE*), E* = 1/(πβ)
    q_lim_f = L * np.exp(alpha_f / beta_f - 2.0)
    a_s, b_s, q_lim_s = seat_form
    A = (alpha_f + beta_f * math.log(L)) / L + scale * a_s
    B = beta_f / L + scale * b_s
    q_lim = np.minimum(q_lim_f, q_lim_s)
    d_lim = q_lim * (A - B * np.log(q_lim))

    A_over_B = A / B
    B_pins = np.broadcast_to(B, np.shape(A))     # B is one value for every pin, A one per pin
    d_lim_pins = np.broadcast_to(d_lim, np.shape(A))

    def law(delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        delta = np.asarray(delta, dtype=float)
        if isinstance(A, np.ndarray) and (delta.shape == A.shape or (delta.size == 1 and delta.ndim <= A.ndim)):
            # one approach per pin, or one for every pin: no broadcasting needed
            d = delta if delta.shape == A.shape else np.full(A.shape, delta.reshape(()))
            b_all, ab_all, dl = B_pins, A_over_B, d_lim_pins
        else:
            shape = np.broadcast(delta, A).shape
            d = np.broadcast_to(delta, shape)
            b_all, ab_all, dl = (np.broadcast_to(v, shape) for v in (B, A_over_B, d_lim))
        if (d > dl).any():
            return fallback(delta)
        q = np.zeros(d.shape)
        dq = np.zeros(d.shape)
        pos = d > 0
        if not pos.any():
            return q, dq
        b_, ab, dp = b_all[pos], ab_all[pos], d[pos]
        t = -np.real(lambertw(-dp / b_ * np.exp(-ab), k=-1))
        lnq = ab - t
        # one Newton step on ln Q polishes the root: f = ln(Q(A − B ln Q)) − ln δ, f' = 1 − 1/t
        t1 = ab - lnq
        lnq = lnq - (np.log(b_ * t1) + lnq - np.log(dp)) / (1.0 - 1.0 / t1)
        q[pos] = np.exp(lnq)
        dq[pos] = 1.0 / (b_ * (ab - lnq - 1.0))
        return q, dq

    return law


def _wall(case: Case, table: PinHousingTable) -> float:
    """The ring's wall under a groove bottom, mm."""
    return table.ring_outer_radius - case.pins.circle_radius - case.pins.radius


# ------------------------------------------------------------------------------------------------
# (3) The housing ring
# ------------------------------------------------------------------------------------------------


def _mode_compliance(n: int, R: float, E: float, G: float, A: float, I: float, shear_factor: float) -> np.ndarray:
    """S_n (2×2): the amplitudes (w_n, v_n) of the radial and tangential displacement
    w = w_n cos nθ, v = v_n sin nθ of a ring under the line loads q_r = a cos nθ, q_t = b sin nθ
    (N/mm of centre line), n ≥ 2: (w_n, v_n) = S_n·(a, b).

    Equilibrium of the curved beam (dN/ds + V/R + q_t = 0, dV/ds − N/R + q_r = 0, dM/ds = V)
    gives the mode's stress resultants N = N_n cos, V = V_n sin, M = M_n cos, statically
    determinate for n ≥ 2; Castigliano on the curved beam's complementary energy
    ∫(M²/2EI + N²/2EA + MN/(EAR) + F·V²/2GA) ds (Roark § 9.3) gives S_n = Aᵀ D A."""
    Amat = np.array([[-R * R / (n * n - 1.0), R * R / (n * (n * n - 1.0))],     # M_n per (a, b)
                     [-R / (n * n - 1.0), n * R / (n * n - 1.0)],               # N_n
                     [-n * R / (n * n - 1.0), R / (n * n - 1.0)]])              # V_n
    D = np.array([[1.0 / (E * I), -1.0 / (E * A * R), 0.0],
                  [-1.0 / (E * A * R), 1.0 / (E * A), 0.0],
                  [0.0, 0.0, shear_factor / (G * A)]])
    return np.asarray(Amat.T @ D @ Amat)


def ring_influence(angles: np.ndarray, radius: float, youngs_modulus: float, poissons_ratio: float, area: float,
                   second_moment: float, shear_factor: float = 1.2, modes: int = RING_MODES) -> np.ndarray:
    """The influence matrix G (2m × 2m, mm/N) of a free ring of centre-line radius ``radius`` (mm)
    between point forces at the m ``angles`` (rad): rows and columns (radial, tangential) of each
    point in turn, outward and counter-clockwise positive.

    Fourier modes n = 0 (radial: uniform stretching, w₀ = q₀R²/(EA)) and 2 … ``modes``
    (:func:`_mode_compliance`); the force's n = 1 part and its uniform tangential part (its net
    force and torque) are taken by the ring's mounting, spread as those modes (a housing bolted all
    round): they deform nothing. A point force P at ψ is the line load P/(πR)·Σ cos n(θ − ψ)
    (P/(2πR) for n = 0)."""
    angles = np.asarray(angles, dtype=float)
    E, R = youngs_modulus, radius
    G = E / (2.0 * (1.0 + poissons_ratio))
    m = angles.size
    dpsi = angles[:, None] - angles[None, :]
    out = np.zeros((2 * m, 2 * m))
    # n = 0: radial uniform stretching
    out[0::2, 0::2] += R * R / (E * area) / (2.0 * math.pi * R)
    for n in range(2, modes + 1):
        S = _mode_compliance(n, R, E, G, area, second_moment, shear_factor) / (math.pi * R)
        c, s = np.cos(n * dpsi), np.sin(n * dpsi)
        # radial force at ψ: (a, b) = (1, 0) in cos/sin about ψ; tangential force at ψ: the mode
        # turned by a quarter wave, q_t = cos n(θ − ψ) → (a, b) = (0, −1) in sin/−cos
        out[0::2, 0::2] += S[0, 0] * c
        out[1::2, 0::2] += S[1, 0] * s
        out[0::2, 1::2] += -S[0, 1] * s
        out[1::2, 1::2] += S[1, 1] * c
    return out


def classical_pin_forces(case: Case, torque_Nm: float, theta: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The forces of one disc's pins on the housing at crank angle θ (rad) under the output torque
    ``torque_Nm`` shared equally by ``loads.discs`` discs: the classical distribution
    F_j ∝ sin φ_j/√(1 + K1² − 2K1·cos φ_j) on the pins with sin φ_j > 0, along the line from the
    pitch point (e·Zp from the axis, on the line of centres) to the pin centre, scaled so that their
    moment about the disc's centre is the disc's torque T/discs (the handbook's).

    Returns the pins' angles (rad, (Zp,)) and the forces (Zp, 2), N, in x, y.
    """
    zp, e, rp = case.pins.count, case.cycloid.eccentricity, case.pins.circle_radius
    psi = 2.0 * math.pi * np.arange(zp) / zp
    centres = rp * np.column_stack([np.cos(psi), np.sin(psi)])
    u = np.array([math.cos(theta), math.sin(theta)])
    pitch = e * zp * u
    phi = psi - theta
    sin_phi = np.sin(phi)
    vec = centres - pitch
    dist = np.linalg.norm(vec, axis=1)
    n = vec / dist[:, None]
    mag = np.where(sin_phi > 0, sin_phi * rp / dist, 0.0)
    disc = e * u
    arm = (centres - disc)[:, 0] * n[:, 1] - (centres - disc)[:, 1] * n[:, 0]
    scale = torque_Nm * 1e3 / case.loads.discs / float(np.sum(mag * np.abs(arm)))
    return psi, (mag * scale)[:, None] * n


def ring_output_compliance(case: Case, table: PinHousingTable, theta: float = 0.0) -> float:
    """The housing ring's series output compliance, rad/(N·mm): q̂ᵀGq̂ (module docstring) with the
    classical pin forces of every disc (disc k at θ + k·360°/discs) per unit output torque, G the
    ring of :func:`ring_influence` (rectangular section between the pin circle and
    ``ring_outer_radius``, ``ring_width`` wide, radial shear factor 6/5)."""
    r_in, r_out = case.pins.circle_radius, table.ring_outer_radius
    width = table.ring_width if table.ring_width is not None else 2.0 * case.cycloid.thickness + 2.0
    h = r_out - r_in
    if h <= 0.0:
        raise ValueError("the housing ring's outer radius must exceed the pin circle radius")
    R = 0.5 * (r_in + r_out)
    psi, _ = classical_pin_forces(case, 1.0, theta)
    load = np.zeros((psi.size, 2))
    for k in range(case.loads.discs):
        _, f = classical_pin_forces(case, 1e-3, theta + 2.0 * math.pi * k / case.loads.discs)   # per N·mm
        load += f
    radial = load[:, 0] * np.cos(psi) + load[:, 1] * np.sin(psi)
    tangential = -load[:, 0] * np.sin(psi) + load[:, 1] * np.cos(psi)
    q = np.column_stack([radial, tangential]).ravel()
    G = ring_influence(psi, R, table.youngs_modulus, table.poissons_ratio, width * h, width * h ** 3 / 12.0)
    return float(q @ G @ q)


# ------------------------------------------------------------------------------------------------
# The component
# ------------------------------------------------------------------------------------------------


SEATED_MODELS = ("hertz", "palmgren")
"""The pin models whose law is the pin–flank contact alone, to which the seat is added in series;
``linear`` is a given stiffness of the whole pin path and ``rigid`` the rigid limit: left as they are."""


class PinHousing(StageComponent):
    """The pins' seats in the housing grooves and the housing ring (module docstring)."""

    name = NAME
    table, schema = NAME, PinHousingTable
    table_by_default = True
    held = "the pins' seats in their housing grooves (Hertz, in series with each pin) and the housing ring"
    step = "one_disc"
    models = ("pin housing",)

    def present(self, case: Case) -> bool:
        t = self.parameters(case)
        return t is not None and bool(t.enabled)

    def build(self, stage: ReducerStage) -> ReducerStage:
        """Each pin's seat in series with its flank contact (for the Hertz and Palmgren pin
        models), and the ring as a series output compliance."""
        case = stage.first.case
        table = self.parameters(case)
        if stage.first.pin_model in SEATED_MODELS and not isinstance(stage.first.pins, SeriesPins):
            stage = _with_pins(stage, SeriesPins(stage.first.pins, seat_approach(case, table)))
        return stage.with_output_compliance(self.name, ring_output_compliance(case, table))

    def stiffen(self, stage: ReducerStage) -> ReducerStage:
        """The seats' compliance and the ring's / STIFFEN."""
        c = stage.output_compliance(self.name)
        if c is None:
            raise ValueError("the stage has no pin housing")
        pins = stage.first.pins
        if isinstance(pins, SeriesPins):
            stage = _with_pins(stage, SeriesPins(pins.base, pins.seat, pins.scale / STIFFEN))
        return stage.with_output_compliance(self.name, c / STIFFEN)

    def carry(self, before: ReducerStage, after: ReducerStage) -> ReducerStage:
        """Another component stiffened by replacing the pins' model (the flank's linear springs) or
        the disc's model (a new factorisation) keeps the seats of ``before``."""
        pins = before.first.pins
        if isinstance(pins, SeriesPins) and not isinstance(after.first.pins, SeriesPins):
            return _with_pins(after, pins.with_base(after.first.pins))
        return after


def _with_pins(stage: ReducerStage, pins: Any) -> ReducerStage:
    """The stage with disc A's (and disc B's) pin model replaced, with contact caches of their own
    (kept on the disc model's cache under the seats' key, so that every stage built from one disc
    model shares them)."""

    def swap(system: Any) -> Any:
        base = system.pins.base if isinstance(system.pins, SeriesPins) else system.pins
        cache = system.contact_sets.setdefault(("pin seats", pins.scale), {})
        return dataclasses.replace(system, pins=pins.with_base(base), contact_sets=cache)

    first = swap(stage.first)
    second = None if stage.second is None else (first if stage.second is stage.first else swap(stage.second))
    return dataclasses.replace(stage, first=first, second=second)


register_component_table(NAME, PinHousingTable, by_default=True, owner=NAME)
