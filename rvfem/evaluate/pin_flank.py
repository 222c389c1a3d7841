"""The pin–flank contact of a load cycle: the Hertz line contact of each pin on the cycloid flank,
its peak pressure over the cycle and where, the subsurface shear, and a contact-fatigue safety.

Each loaded pin is a cylinder of radius r_rp pressed on the flank, whose local radius of curvature
at the contact point is ρ = 1/|κ| (κ the profile's signed curvature,
:func:`rvfem.geometry.profile_curvature`: positive where the flank is convex near the tips,
negative where it is concave near the roots). Line contact over the disc width L (Johnson,
*Contact Mechanics*, Cambridge 1985, §4.3):

    1/R' = 1/r_rp + κ                 (convex flank: 1/r_rp + 1/ρ; concave: 1/r_rp − 1/ρ)
    b = √(4·Q·R'/(π·L·E*)),   p_H = 2Q/(π·L·b) = √(Q·E*/(π·L·R'))

with 1/E* = (1 − ν_disc²)/E_disc + (1 − ν_pin²)/E_pin and Q the pin's normal load (the cycle's pin
force without its friction part: |F| = Q·√(1 + μ²) for a sliding pin). Below the surface the
largest principal shear stress is τ_max = 0.300·p_H at the depth z = 0.786·b, the largest
orthogonal shear τ_zx = 0.250·p_H at z = 0.5·b (Johnson, §4.3, Fig. 4.6; frictionless, ν = 0.3).

Contact-fatigue safety. The allowable is the fatigue-limit contact pressure of through-hardened
bearing steel, 1500 MPa: ISO 281:2007 defines the fatigue load limit C_u as the load at which the
Hertz contact pressure at the most heavily loaded raceway contact reaches 1500 MPa (for
bearing steel of usual quality; ISO/TR 1281-2:2008 explains it). The safety factor on pressure is
S_H = p_lim / p_H,max (on load it is S_H² for a line contact). The pin and the flank are both of
bearing steel in an RV reducer; for another disc material the allowable has to be checked.

The contact points and curvatures are those of the rigid kinematics at each crank angle
(:func:`rvfem.geometry.pin_profile_contacts_many`), the ones the pin law of the load cycle uses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rvfem.evaluate.hertz import composite_modulus
from rvfem.geometry import pin_profile_contacts_many, profile_curvature

__all__ = ["CONTACT_FATIGUE_PRESSURE_MPa", "SUBSURFACE_SHEAR", "PinFlankHertz", "pin_flank_pressure",
           "pin_flank_hertz"]

CONTACT_FATIGUE_PRESSURE_MPa = 1500.0
"""Fatigue-limit Hertz contact pressure of through-hardened bearing steel, MPa (ISO 281:2007, the
contact pressure that defines the fatigue load limit C_u)."""

SUBSURFACE_SHEAR = (0.300, 0.786, 0.250, 0.500)
"""Line contact (Johnson, Contact Mechanics, §4.3): τ_max/p_H, its depth/b, τ_zx,max/p_H, its depth/b."""


def pin_flank_pressure(load_N: np.ndarray | float, length_mm: float, pin_radius_mm: float,
                       curvature_per_mm: np.ndarray | float, composite_modulus_MPa: float
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Peak pressure, half-width and relative radius of pin-on-flank line contacts.

    Parameters
    ----------
    load_N : float or ndarray
        Normal load Q ≥ 0, N.
    length_mm : float
        Contact length L (the disc width), mm.
    pin_radius_mm : float
        r_rp, mm.
    curvature_per_mm : float or ndarray
        Signed curvature κ of the flank at the contact, 1/mm (> 0 convex).
    composite_modulus_MPa : float
        E*, MPa.

    Returns
    -------
    p_H (MPa), b (mm), R' (mm) : ndarray
        NaN where 1/r_rp + κ ≤ 0 (a concave flank tighter than the pin: no Hertz contact).
    """
    q = np.asarray(load_N, dtype=float)
    inv = 1.0 / pin_radius_mm + np.asarray(curvature_per_mm, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(inv > 0.0, 1.0 / np.where(inv > 0.0, inv, 1.0), np.nan)
        b = np.sqrt(4.0 * np.maximum(q, 0.0) * r / (math.pi * length_mm * composite_modulus_MPa))
        p = np.sqrt(np.maximum(q, 0.0) * composite_modulus_MPa / (math.pi * length_mm * r))
    return p, b, r


@dataclass(frozen=True)
class PinFlankHertz:
    """The most loaded pin–flank contact of a load cycle (by Hertz pressure).

    Attributes
    ----------
    peak_pressure_MPa : float
        Largest Hertz pressure p_H over the cycle and the pins, MPa.
    load_N : float
        That contact's normal load Q, N.
    pin : int
        0-based pin.
    theta_deg : float
        Crank angle, degrees.
    x_mm, y_mm : float
        Contact point in the disc frame, mm.
    radius_mm : float
        Its distance from the disc centre, mm (the position on the tooth profile: between the root
        and tip radii).
    flank_radius_mm : float
        Signed radius of curvature of the flank there, 1/κ, mm (> 0 convex, < 0 concave).
    relative_radius_mm, half_width_mm : float
        R' and b, mm.
    max_load_N : float
        Largest pin load over the cycle (not necessarily at the pressure peak), N.
    max_shear_MPa, max_shear_depth_mm : float
        τ_max = 0.300·p_H and its depth 0.786·b.
    orthogonal_shear_MPa, orthogonal_shear_depth_mm : float
        τ_zx,max = 0.250·p_H and its depth 0.5·b.
    allowable_MPa : float
        The contact-fatigue allowable (:data:`CONTACT_FATIGUE_PRESSURE_MPa`).
    safety_factor : float
        allowable / p_H on pressure.
    length_mm : float
        L, the disc width.
    pressure_per_angle_MPa : ndarray (n,)
        The largest p_H over the pins at every crank angle, MPa.
    """

    peak_pressure_MPa: float
    load_N: float
    pin: int
    theta_deg: float
    x_mm: float
    y_mm: float
    radius_mm: float
    flank_radius_mm: float
    relative_radius_mm: float
    half_width_mm: float
    max_load_N: float
    max_shear_MPa: float
    max_shear_depth_mm: float
    orthogonal_shear_MPa: float
    orthogonal_shear_depth_mm: float
    allowable_MPa: float
    safety_factor: float
    length_mm: float
    pressure_per_angle_MPa: np.ndarray


def pin_flank_hertz(case, geometry, theta: np.ndarray, pin_forces: np.ndarray, friction: float | None = None,
                    allowable_MPa: float = CONTACT_FATIGUE_PRESSURE_MPa) -> PinFlankHertz:
    """The pin–flank Hertz contact over a load cycle (module docstring).

    Parameters
    ----------
    case : rvfem.case.definition.Case
    geometry : rvfem.geometry.DiscGeometry
        The disc (its profile gives the contact points and the flank curvature).
    theta : ndarray (n,)
        Crank angles, rad.
    pin_forces : ndarray (n, Zp)
        Pin force magnitudes of the cycle, N (:attr:`rvfem.solve.cycle.CycleResult.pin_forces`).
    friction : float, optional
        Pin friction μ of the cycle (default the case's ``analysis.friction``): the normal load is
        |F|/√(1 + μ²).
    allowable_MPa : float
        Contact-fatigue allowable, MPa.
    """
    mu = case.analysis.friction if friction is None else friction
    q_all = np.asarray(pin_forces, dtype=float) / math.sqrt(1.0 + mu * mu)
    e_star = composite_modulus(case.material.youngs_modulus, case.material.poissons_ratio,
                               case.pins.youngs_modulus, case.pins.poissons_ratio)
    L, rp = case.cycloid.thickness, case.pins.radius
    n = len(theta)
    per_angle = np.zeros(n)
    best: tuple | None = None
    contacts = pin_profile_contacts_many(geometry, np.asarray(theta, dtype=float))   # one vectorised search
    for k in range(n):
        q = q_all[k]
        loaded = np.flatnonzero(q > 0.0)
        if loaded.size == 0:
            continue
        pc = contacts[k]
        kappa = profile_curvature(geometry.profile, pc.segment[loaded], pc.param[loaded])
        p, b, r = pin_flank_pressure(q[loaded], L, rp, kappa, e_star)
        p = np.where(np.isnan(p), -np.inf, p)
        j = int(np.argmax(p))
        per_angle[k] = max(float(p[j]), 0.0)
        if best is None or p[j] > best[0]:
            pin = int(loaded[j])
            best = (float(p[j]), float(q[pin]), pin, k, pc.point[pin], float(kappa[j]), float(r[j]), float(b[j]))
    if best is None:
        raise ValueError("no pin carries load over the cycle")
    p, q, pin, k, xy, kappa, r, b = best
    t1, z1, t2, z2 = SUBSURFACE_SHEAR
    return PinFlankHertz(
        peak_pressure_MPa=p, load_N=q, pin=pin, theta_deg=round(math.degrees(float(theta[k])), 9),
        x_mm=float(xy[0]), y_mm=float(xy[1]), radius_mm=float(math.hypot(*xy)),
        flank_radius_mm=math.inf if kappa == 0.0 else 1.0 / kappa, relative_radius_mm=r, half_width_mm=b,
        max_load_N=float(q_all.max()), max_shear_MPa=t1 * p, max_shear_depth_mm=z1 * b,
        orthogonal_shear_MPa=t2 * p, orthogonal_shear_depth_mm=z2 * b, allowable_MPa=allowable_MPa,
        safety_factor=allowable_MPa / p if p > 0 else math.inf, length_mm=L, pressure_per_angle_MPa=per_angle)
