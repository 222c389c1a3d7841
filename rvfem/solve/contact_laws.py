"""The force laws of the compliant contacts: rollers and compliant pins.

Rollers are compression-only springs along their radial line with the Palmgren law for both raceways,
δ = 2·3.84e-5·Q^0.9 / L^0.8 (mm, N) (:func:`palmgren_law`), or a linear stiffness (:func:`linear_law`);
a compliant pin follows the Hertz pin–flank line contact (:func:`hertz_pin_law`). Each law maps an
approach δ (mm) to the force q (N) and its slope dq/dδ (N/mm).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.special import lambertw

ForceLaw = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
"""A force law of spring contacts, vectorised: approach δ (mm) → (force q (N), slope dq/dδ (N/mm)).
A law whose ``elementwise`` attribute is True gives each contact's force from its own approach
alone, for an array of any shape (no per-contact data): the contact problem evaluates the contacts
of every body that share it in one call (:class:`rvfem.solve.contact_newton.ContactProblem`)."""


PALMGREN_COEFFICIENT = 3.84e-5
"""Palmgren's line-contact approach coefficient, steel on steel: δ = 3.84e-5·Q^0.9/L^0.8 (mm, N;
Harris & Kotzalas, *Rolling Bearing Analysis*). The roller springs here and the Hertz evaluation
(:func:`rvfem.evaluate.hertz.palmgren_approach`) share it."""


def palmgren_law(length: float, contacts: int = 2):
    """Force–approach law of a roller line contact after Palmgren.

    δ = contacts · 3.84e-5 · Q^0.9 / L^0.8  (δ mm, Q N, L mm; Harris & Kotzalas, *Rolling Bearing
    Analysis*, line contact, one roller–raceway contact each; see
    :func:`rvfem.evaluate.hertz.palmgren_approach`), inverted to
    Q(δ) = (δ · L^0.8 / (contacts · 3.84e-5))^(1/0.9) for δ > 0, 0 otherwise.

    Returns a function ``law(delta) -> (Q, dQ/dδ)`` (arrays).
    """
    c = contacts * PALMGREN_COEFFICIENT / length**0.8
    p = 1.0 / 0.9

    def law(delta):
        d = np.maximum(delta, 0.0)
        q = (d / c) ** p
        dq = np.where(d > 0, p / c * (d / c) ** (p - 1.0), 0.0)
        return q, dq

    law.elementwise = True  # type: ignore[attr-defined]
    return law


def linear_law(stiffness: float, bilateral: bool = False, open_fraction: float = 0.0):
    """Linear spring Q = k·δ (compression only unless ``bilateral``), k in N/mm.

    ``open_fraction`` > 0 regularises a compression-only spring: at δ ≤ 0 it keeps the stiffness
    ``open_fraction``·k (a weak tension spring) instead of none. Only the first, linearised solve
    of a cycle uses it (:func:`rvfem.solve.contact.solve_bodies`).
    """

    def law(delta):
        if bilateral:
            return stiffness * delta, np.full_like(delta, stiffness)
        if open_fraction > 0:
            k = np.where(delta > 0, stiffness, open_fraction * stiffness)
            return k * delta, k
        return stiffness * np.maximum(delta, 0.0), np.where(delta > 0, stiffness, 0.0)

    law.elementwise = True  # type: ignore[attr-defined]
    return law


def hertz_pin_approach(Q, *, length: float, pin_radius: float, flank_curvature, pin_modulus: float,
                       pin_poisson: float, disc_modulus: float, disc_poisson: float,
                       footprint_half_width: float):
    """Approach δ (mm) of a pin–flank Hertz line contact at the force Q (N), and dδ/dQ (mm/N).

    Parameters
    ----------
    Q : array_like
        Contact force, N (> 0).
    length : float
        Contact length L (the disc width), mm; P = Q/L is the load per unit length.
    pin_radius : float
        R_p, mm.
    flank_curvature : array_like
        Signed curvature κ of the flank at the contact point, 1/mm: positive where the flank is
        convex (near the tips), negative where it is concave (near the roots).
    pin_modulus, pin_poisson, disc_modulus, disc_poisson : float
        E (MPa) and ν of the pin and of the disc.
    footprint_half_width : float
        Half-width w of the elliptical footprint over which the FE model spreads the pin force, mm.

    Returns
    -------
    delta, ddelta_dQ : ndarray

    Notes
    -----
    Hertz line contact (Johnson, *Contact Mechanics*, §4.2 and §5.6, plane strain): relative
    curvature 1/R = 1/R_p + κ, contact modulus 1/E* = (1 − ν_p²)/E_p + (1 − ν_d²)/E_d, half-width
    a = √(4PR/(πE*)). The approach is the sum of two parts:

    * the pin: approach of its centre to the contact, Johnson's line-contact result for a
      cylinder, δ_p = P(1 − ν_p²)/(πE_p)·(2 ln(4R_p/a) − 1);
    * the disc: the FE model already deforms the disc under the force spread elliptically over
      ±w; what it lacks is the difference between the Hertz pressure of half-width a and that
      footprint. On a half-plane (plane strain) the approach of the surface point above depth z
      under an elliptical pressure of half-width c is, integrating the strain of the Hertz
      subsurface stresses along the axis,
      2P/(πE)·[(1 − ν²)·asinh(z/c) − ν(1 + ν)·(z√(c² + z²) − z²)/c²]
      → 2P(1 − ν²)/(πE)·[ln(2z/c) − ν/(2(1 − ν))] for z ≫ c; in the difference of c = a and c = w
      the depth and the Poisson term cancel: δ_d = 2P(1 − ν_d²)/(πE_d)·ln(w/a).

    The "depth" convention is therefore: the pin's centre, and for the disc the far field the FE
    model resolves (the sum pin law + FE does not depend on w as long as a and w are small
    against the flank radius). δ(Q) increases up to a half-width a0 where dδ/dP would vanish
    (≈1.2 mm for steel, r_rp = 3 mm, w = 0.5 mm: far beyond any pin load, but a trial approach
    of the solver may get there); beyond a0/√e it is continued linearly with its tangent.
    """
    Q = np.maximum(np.asarray(Q, dtype=float), 1e-300)
    kappa = np.asarray(flank_curvature, dtype=float)
    # a concave flank tighter than the pin (a negative equidistant modification at the root) is
    # not a Hertz contact: the relative radius is capped at 1000 r_rp (conforming)
    inv_r = np.maximum(1.0 / pin_radius + kappa, 1e-3 / pin_radius)
    cp = (1.0 - pin_poisson**2) / (np.pi * pin_modulus)
    cd = (1.0 - disc_poisson**2) / (np.pi * disc_modulus)
    e_star = 1.0 / (np.pi * (cp + cd))
    # dδ/dP = cp·(2 ln(4R_p/a) − 2) + 2cd·(ln(w/a) − ½) vanishes at a0; beyond a_lim = a0/√e
    # (where it is still cp + cd) the law is continued with its tangent, so that it stays monotone
    # for any trial approach of the solver (a_lim ≈ 0.7 mm for steel, r_rp = 3, w = 0.5 mm:
    # thousands of newtons per pin even at the conforming roots)
    ln_a0 = (cp * (2.0 * np.log(4.0 * pin_radius) - 2.0) + cd * (2.0 * np.log(footprint_half_width) - 1.0)) / (2.0 * (cp + cd))
    a_lim = np.exp(ln_a0 - 0.5)
    P_lim = a_lim**2 * np.pi * e_star * inv_r / 4.0

    def parts(P):
        a = np.sqrt(4.0 * P / (inv_r * np.pi * e_star))
        d = P * (cp * (2.0 * np.log(4.0 * pin_radius / a) - 1.0) + 2.0 * cd * np.log(footprint_half_width / a))
        # d ln a / dP = 1/(2P)
        dd = cp * (2.0 * np.log(4.0 * pin_radius / a) - 2.0) + 2.0 * cd * (np.log(footprint_half_width / a) - 0.5)
        return d, dd

    P = Q / length
    beyond = P > P_lim
    d, dd = parts(np.where(beyond, P_lim, P))
    delta = np.where(beyond, d + dd * (P - P_lim), d)
    return delta, dd / length


def hertz_pin_law(**params):
    """Force–approach law of the pin–flank Hertz line contact (:func:`hertz_pin_approach`),
    inverted: ``law(delta) -> (Q, dQ/dδ)`` per pin (arrays broadcast against the pins' curvatures).

    The inversion is closed-form. Below the tangent continuation the approach of
    :func:`hertz_pin_approach` is δ = P·(α − β ln P) with P = Q/L, β = c_p + c_d and
    α = c_p(2 ln 4R_p − 1) + 2c_d ln w − β ln(4R/(πE*)) (ln a = ½ ln(4PR/(πE*)) substituted).
    With P = e^(α/β − t) this is t·e^(−t) = δ·e^(−α/β)/β, whose root on the rising branch
    (dδ/dP = β(t − 1) > 0, t ≥ 2 below the continuation point) is t = −W₋₁(−δ·e^(−α/β)/β), W₋₁
    the lower real branch of Lambert's W function (Corless et al., "On the Lambert W function",
    Adv. Comput. Math. 5, 1996). Beyond the continuation point the law is linear. One Newton step
    on ln P polishes the result to round-off. δ ≤ 0 gives Q = 0 and dQ/dδ = 0 (compression
    only, as Palmgren's law).
    """

    curvature = np.asarray(params["flank_curvature"], dtype=float)
    length = float(params["length"])
    pin_radius, w = float(params["pin_radius"]), float(params["footprint_half_width"])
    cp = (1.0 - params["pin_poisson"] ** 2) / (np.pi * params["pin_modulus"])
    cd = (1.0 - params["disc_poisson"] ** 2) / (np.pi * params["disc_modulus"])
    beta = cp + cd
    e_star = 1.0 / (np.pi * beta)
    inv_r = np.maximum(1.0 / pin_radius + curvature, 1e-3 / pin_radius)   # as hertz_pin_approach
    alpha = (cp * (2.0 * np.log(4.0 * pin_radius) - 1.0) + 2.0 * cd * np.log(w)
             - beta * np.log(4.0 / (inv_r * np.pi * e_star)))
    # the continuation point of hertz_pin_approach: dδ/dP = β there, i.e. t = 2
    P_lim = np.exp(alpha / beta - 2.0)
    d_lim = 2.0 * beta * P_lim

    def law(delta):
        delta = np.asarray(delta, dtype=float)
        if curvature.ndim and delta.shape == curvature.shape:    # one approach per pin: no broadcasting
            d, a_, b_, dl = delta, alpha, P_lim, d_lim
        else:
            shape = np.broadcast(delta, curvature).shape
            d = np.broadcast_to(delta, shape)
            a_, b_ = np.broadcast_to(alpha, shape), np.broadcast_to(P_lim, shape)
            dl = np.broadcast_to(d_lim, shape)
        q = np.zeros(d.shape)
        dq = np.zeros(d.shape)
        pos = d > 0
        if not pos.any():
            return q, dq
        dp, ap, Pl, dlp = d[pos], a_[pos], b_[pos], dl[pos]
        linear = dp > dlp
        P = Pl + (dp - dlp) / beta                                   # tangent continuation
        rising = ~linear
        if np.any(rising):
            z = dp[rising] / beta * np.exp(-ap[rising] / beta)
            t = -np.real(lambertw(-z, k=-1))
            lnP = ap[rising] / beta - t
            # one Newton step on ln P: f = ln δ(P) − ln δ, f' = 1 − 1/t (δ = βtP)
            t1 = ap[rising] / beta - lnP
            f = np.log(beta * t1) + lnP - np.log(dp[rising])
            lnP = lnP - f / (1.0 - 1.0 / t1)
            P = P.copy()
            P[rising] = np.exp(lnP)
        # dδ/dP = β(t − 1) on the rising branch (t ≥ 2), β on the continuation
        slope = beta * (np.maximum(ap / beta - np.log(P), 2.0) - 1.0)
        q[pos] = P * length
        dq[pos] = length / slope                                     # dQ/dδ = L·dP/dδ
        return q, dq

    return law


def roller_bore_approach(Q, *, length: float, reduced_radius_bore: float, disc_modulus: float,
                         disc_poisson: float, footprint_half_width: float, disc_stiffness_scale: float = 1.0):
    """Approach δ (mm) of a crank-bearing roller between eccentric and bore at the force Q (N), and
    dδ/dQ (mm/N): Palmgren's two line contacts less the bore's local contact compliance that the FE
    bore footprint already holds (:func:`roller_bore_law`).

    Parameters
    ----------
    Q : array_like
        Roller force, N (≥ 0).
    length : float
        Effective roller length L, mm.
    reduced_radius_bore : float
        R' of roller and bore (1/R' = 1/R_roller − 1/R_bore), mm.
    disc_modulus, disc_poisson : float
        E (MPa) and ν of the disc (the bore's body; the roller and the eccentric of the same steel
        in Palmgren's law).
    footprint_half_width : float
        Half-width w of the elliptical footprint over which the FE model spreads a roller's force
        on the bore, mm.
    disc_stiffness_scale : float
        The factor on the disc's Young's modulus in the FE model (1; 10³ in the rigid-limit checks):
        the FE bore then holds 1/scale of the local compliance, and the law gives back the rest.

    Returns
    -------
    delta, ddelta_dQ : ndarray

    Notes
    -----
    Palmgren's law, δ_P = 2·c₁·Q^0.9 with c₁ = 3.84·10⁻⁵/L^0.8 ([HK]), is the approach of the
    roller between two rigid ring bodies: each of its two contacts holds the local compliance of the
    roller's side and of the ring's. On the FE disc the bore is the ring, and its footprint (an
    elliptical pressure of half-width w, Bᵀu the pressure-weighted mean displacement) already
    deforms the bore locally. On a half-plane (plane strain) the approach of a surface under an
    elliptical pressure of half-width c, referred to a point at depth z ≫ c, is
    K·Q·[ln(2z/c) + const] with K = 2(1 − ν²)/(π·E·L) (Johnson, *Contact Mechanics*, § 2.8 and
    § 4.2); the constant is the same for every c. With the bore's half of one Palmgren contact,
    c₁·Q^0.9/2 (two steel bodies of the same law), as its Hertz part (c = a, the Hertz
    half-width a = √(4·Q·R'/(π·E*·L))), the part the footprint holds at the same depth is

        δ_loc = c₁·Q^0.9/2 − K·Q·ln(w/a),

    the depth cancels (as in the pin law, :func:`hertz_pin_approach`). The roller's spring is
    δ = δ_P − δ_loc/s (s the disc's stiffness scale), so that spring + FE footprint = Palmgren's
    law for a disc that deforms only locally: the bore's local compliance counted once. s → ∞ (a
    rigid disc) gives Palmgren's law; w → a (a footprint as narrow as the contact) gives
    1.5·c₁·Q^0.9 (the eccentric's contact and the roller's side of the bore's). Where a would
    pass w (a footprint narrower than the contact; some 10⁴ N per mm of roller for the shipped
    bearings, far beyond any roller load, but a trial approach of the solver may get there) δ is
    continued linearly with its tangent (dδ/dQ > 0 there for s ≥ 1).
    """
    return _roller_bore_approach_of(length, reduced_radius_bore, disc_modulus, disc_poisson,
                                    footprint_half_width, disc_stiffness_scale)(Q)


def _roller_bore_approach_of(length: float, reduced_radius_bore: float, disc_modulus: float, disc_poisson: float,
                             footprint_half_width: float, disc_stiffness_scale: float = 1.0):
    """:func:`roller_bore_approach` of one bearing as a function of Q alone (N → (δ mm, dδ/dQ
    mm/N)), its constants computed once: the roller law evaluates it at every Newton iterate."""
    c1 = PALMGREN_COEFFICIENT / length**0.8
    k = 2.0 * (1.0 - disc_poisson**2) / (np.pi * disc_modulus * length)
    e_star = disc_modulus / (2.0 * (1.0 - disc_poisson**2))             # two bodies of the disc's steel
    w, s = float(footprint_half_width), float(disc_stiffness_scale)
    q_lim = np.pi * e_star * length * w * w / (4.0 * reduced_radius_bore)   # a = w
    ln_w = np.log(w)
    a_denominator = np.pi * e_star * length                          # a² = 4QR'/(πE*L)

    def approach(Q, slope_only: bool = False):
        Q = np.maximum(np.asarray(Q, dtype=float), 0.0)
        beyond = Q > q_lim
        q = np.maximum(np.where(beyond, q_lim, Q), 1e-300)
        ln_wa = ln_w - 0.5 * np.log(4.0 * q * reduced_radius_bore / a_denominator)
        q01 = q**-0.1
        dd = 1.8 * c1 * q01 - (0.45 * c1 * q01 - k * (ln_wa - 0.5)) / s
        if slope_only:
            return None, dd
        q09 = q**0.9
        d = 2.0 * c1 * q09 - (0.5 * c1 * q09 - k * q * ln_wa) / s
        if beyond.any():
            d = np.where(beyond, d + dd * (Q - q_lim), d)
        return np.where(Q > 0.0, d, 0.0), dd

    return approach


def roller_bore_law(*, length: float, reduced_radius_bore: float, disc_modulus: float, disc_poisson: float,
                    footprint_half_width: float, disc_stiffness_scale: float = 1.0):
    """Force–approach law of a crank-bearing roller on the FE bore: Palmgren's two line contacts with
    the bore's local contact compliance counted once (:func:`roller_bore_approach`), inverted:
    ``law(delta) -> (Q, dQ/dδ)``. δ ≤ 0 gives Q = 0 and dQ/dδ = 0 (compression only).

    The inversion interpolates ln Q against ln δ on a table of δ(Q) (ln δ is increasing in ln Q,
    400 points from 10⁻⁶ N to the continuation point) and polishes the result with one Newton step
    on ln Q (to about 10⁻¹⁰ relative); beyond the tangent continuation of
    :func:`roller_bore_approach` it is linear.
    """
    approach = _roller_bore_approach_of(length, reduced_radius_bore, disc_modulus, disc_poisson,
                                        footprint_half_width, disc_stiffness_scale)
    e_star = disc_modulus / (2.0 * (1.0 - disc_poisson**2))
    w = float(footprint_half_width)
    q_lim = np.pi * e_star * length * w * w / (4.0 * reduced_radius_bore)
    d_lim, slope_lim = (float(v) for v in approach(q_lim))
    table_q = np.geomspace(1e-6, q_lim, 400)
    table_ln_d = np.log(approach(table_q)[0])
    table_ln_q = np.log(table_q)
    ln_d0, ln_q0 = table_ln_d[0], table_ln_q[0]

    def law(delta):
        d = np.asarray(delta, dtype=float)
        q = np.zeros(d.shape)
        dq = np.zeros(d.shape)
        pos = d > 0.0
        if not pos.any():
            return q, dq
        dp = d[pos]
        lin = dp > d_lim
        target = np.log(np.minimum(dp, d_lim))
        # below the table: δ ∝ Q^0.9 to within the ln term's change, extrapolated so
        ln_q = np.interp(target, table_ln_d, table_ln_q)
        below = target < ln_d0
        if below.any():
            ln_q = np.where(below, ln_q0 + (target - ln_d0) / 0.9, ln_q)
        q_ = np.exp(ln_q)
        d_, dd_ = approach(q_)
        ln_q = ln_q - (np.log(d_) - target) * d_ / (q_ * dd_)     # f = ln δ(Q) − ln δ*
        qp = np.exp(ln_q)
        if lin.any():
            qp = np.where(lin, q_lim + (dp - d_lim) / slope_lim, qp)
        _, slope = approach(qp, slope_only=True)
        q[pos] = qp
        dq[pos] = 1.0 / slope
        return q, dq

    law.elementwise = True  # type: ignore[attr-defined]
    return law
