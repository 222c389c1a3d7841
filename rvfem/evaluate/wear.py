"""Archard wear of the cycloid flanks, the pins and the crank and support bearings.

Plain functions of numbers (forces N, lengths mm, wear coefficient mm²/N, depths mm); the life
loop that applies the wear to the stage is :mod:`rvfem.app.wear`. The formulas are collected in
docs/theory.md, "Transmission-accuracy life".

**Archard's law** per surface point: dh = k·p·ds, k = K/H (K the dimensionless wear coefficient,
H the hardness), p the contact pressure and ds the sliding distance relative to the other
surface (Liu et al. eqs. 22-25). A point of surface i that passes once through a line contact of
half-width b, load F and length L slides 2b·ε_i (ε_i the sliding coefficient: sliding speed over
the speed at which the contact moves over surface i) under the mean pressure F/(2bL), so one
passage wears it by k·ε_i·F/L: the half-width drops out. Here the same integral is taken over the
footprint (:func:`footprint_wear`): each sample of the engagement adds k·F·ds/L spread over the
Hertz half-width with the elliptic pressure shape, which keeps the worn volume exactly
k·Σ F·ds (the law's global form) and stays finite where the contact point stands still on a
surface (the pin's ε → ∞ at the edge of its contact arc, Liu et al. § 4.1).

**Kinematics** (:func:`mesh_kinematics`). In the frame of the turning arm (the eccentric), the pin
ring turns about the pin-circle centre O at ω_p = −Zc/Zp and the disc about its centre O_c = e·x̂
at ω_c = −1 per unit crank angle; the pitch point, where the two bodies move alike, lies at
C = e·Zp/(Zp − Zc)·x̂ and every contact normal passes through it. A pin at phase ψ (its angle from
the eccentric's direction) touches the disc at P = c + r_rp·(C − c)/|C − c|; the sliding velocity
is (ω_p − ω_c)·ẑ × (P − C), of size (Zp − Zc)/Zp·(Rp·τ − r_rp) per unit crank angle with
τ = √(1 + K1² − 2·K1·cos ψ), K1 = e·Zp/Rp (Liu et al.'s V_pc^r), zero only where P reaches C.

Sources
-------
* Liu, Shi, Yu, Liu, *Degradation law analysis and life estimation of transmission accuracy of RV
  reducer based on tooth surface and bearing wear* (Lubricants 2025): Archard's law with the
  sliding distance 2εb, the sliding coefficients of the cycloid–pin pair, the 2.5 µm update step,
  the 60 arcsec limit, the bearings' clearance growth per unit radial load.
* J. F. Archard, *Contact and rubbing of flat surfaces*, J. Appl. Phys. 24 (1953).
* K. L. Johnson, *Contact Mechanics*, § 4.3 (line-contact half-width and pressure shape).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rvfem.geometry import pin_profile_contacts_many

__all__ = [
    "MeshKinematics",
    "archard_depth",
    "bearing_clearance_rate",
    "WornProfile",
    "footprint_wear",
    "flank_pin_engagement",
    "mesh_kinematics",
    "side_force",
    "worn_profile",
]


def archard_depth(k_mm2_per_N: float, pressure_MPa: float, sliding_mm: float) -> float:
    """Archard's wear depth h = k·p·s, mm: k in mm²/N, p in MPa (N/mm²), s the sliding distance
    in mm."""
    return float(k_mm2_per_N) * float(pressure_MPa) * float(sliding_mm)


@dataclass(frozen=True)
class MeshKinematics:
    """The relative kinematics of the cycloid–pin pair at pin phases ψ (one flank, arrays (n,)).

    Speeds are per unit crank angle (mm/rad of crank rotation relative to the carrier).

    Attributes
    ----------
    psi : ndarray
        Pin phase ψ, rad (the pin's angle about the pin-circle centre from the eccentric).
    point : ndarray (n, 2)
        Contact point in the arm frame, mm.
    lever : ndarray
        Lever of the contact normal about the reducer axis O, mm (Rp·sin γ).
    sliding : ndarray
        Sliding speed |v_pin − v_disc|, mm/rad.
    rolling_disc, rolling_pin : ndarray
        Speed of the contact point over the disc and over the pin, mm/rad.
    eps_disc, eps_pin : ndarray
        Sliding coefficients ε = sliding / rolling over that surface (inf where the contact
        stands still on the surface).
    disc_arc : ndarray
        Arc length of the contact point along the disc flank from the first ψ, mm.
    disc_radius : ndarray
        Distance of the contact point from the disc centre, mm.
    pin_angle : ndarray
        Angle of the contact point on the pin from its pole facing the pin-circle centre, rad.
    relative_radius : ndarray
        Relative radius of curvature of pin and flank, mm (1/R' = 1/r_rp + κ, κ the flank's
        curvature, positive where it is convex towards the pin; inf where conformal).
    """

    psi: np.ndarray
    point: np.ndarray
    lever: np.ndarray
    sliding: np.ndarray
    rolling_disc: np.ndarray
    rolling_pin: np.ndarray
    eps_disc: np.ndarray
    eps_pin: np.ndarray
    disc_arc: np.ndarray
    disc_radius: np.ndarray
    pin_angle: np.ndarray
    relative_radius: np.ndarray


def _contact(Rp: float, r_rp: float, e: float, zp: int, zc: int, psi: np.ndarray):
    """Pin centre, unit normal (pin → disc) and contact point in the arm frame (module docstring)."""
    c = Rp * np.stack([np.cos(psi), np.sin(psi)], axis=-1)
    C = np.array([e * zp / (zp - zc), 0.0])
    d = C - c
    n = d / np.linalg.norm(d, axis=-1, keepdims=True)
    return c, n, c + r_rp * n


def mesh_kinematics(Rp: float, r_rp: float, e: float, zp: int, zc: int, psi) -> MeshKinematics:
    """Sliding and rolling of the cycloid–pin pair at pin phases ``psi`` (rad, increasing, one
    flank: 0 < ψ < π for the flank a positive torque loads; the other is its mirror image).

    Parameters
    ----------
    Rp, r_rp, e : float
        Pin-circle radius, pin radius, eccentricity, mm.
    zp, zc : int
        Pins and lobes (any tooth difference Zp − Zc ≥ 1).
    psi : array_like
        Pin phases, rad.
    """
    psi = np.asarray(psi, dtype=float)
    wp, wc = -zc / zp, -1.0                        # per unit crank angle, relative to the arm
    oc = np.array([e, 0.0])
    c, n, P = _contact(Rp, r_rp, e, zp, zc, psi)
    h = 1e-6
    dP = (_contact(Rp, r_rp, e, zp, zc, psi + h)[2] - _contact(Rp, r_rp, e, zp, zc, psi - h)[2]) / (2 * h)
    vP = dP * wp                                   # dψ/dθ = ω_p
    perp = lambda w, r: w * np.stack([-r[..., 1], r[..., 0]], axis=-1)   # noqa: E731  ω ẑ × r
    v_pin, v_disc = perp(wp, P), perp(wc, P - oc)
    sliding = np.linalg.norm(v_pin - v_disc, axis=-1)
    roll_pin = np.linalg.norm(vP - v_pin, axis=-1)
    roll_disc = np.linalg.norm(vP - v_disc, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        eps_pin = np.where(roll_pin > 0, sliding / roll_pin, np.inf)
        eps_disc = np.where(roll_disc > 0, sliding / roll_disc, np.inf)
    # the disc frame: the disc has turned by ω_c/ω_p·ψ relative to the arm since ψ = 0
    a = -(zp / zc) * psi
    rel = P - oc
    pd = np.stack([np.cos(a) * rel[:, 0] - np.sin(a) * rel[:, 1], np.sin(a) * rel[:, 0] + np.cos(a) * rel[:, 1]], -1)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pd, axis=0), axis=-1))])
    lever = np.abs(c[:, 0] * n[:, 1] - c[:, 1] * n[:, 0])
    pin_angle = np.angle(np.exp(1j * (np.arctan2(n[:, 1], n[:, 0]) - psi - math.pi)))
    return MeshKinematics(psi, P, lever, sliding, roll_disc, roll_pin, eps_disc, eps_pin, arc,
                          np.linalg.norm(rel, axis=-1), pin_angle, _relative_radius(pd, n, a, r_rp))


def _relative_radius(pd: np.ndarray, n: np.ndarray, a: np.ndarray, r_rp: float) -> np.ndarray:
    """1/R' = 1/r_rp + κ of the flank curve ``pd`` (disc frame), κ > 0 where the flank is convex
    towards the pin (its curvature vector points into the disc, along the normal n turned into the
    disc frame)."""
    if len(pd) < 3:
        return np.full(len(pd), r_rp)
    t = np.gradient(pd, axis=0)
    tt = np.gradient(t, axis=0)
    speed = np.linalg.norm(t, axis=-1)
    kvec_mag = (t[:, 0] * tt[:, 1] - t[:, 1] * tt[:, 0]) / speed**3          # signed curvature
    normal_disc = np.stack([np.cos(a) * n[:, 0] - np.sin(a) * n[:, 1], np.sin(a) * n[:, 0] + np.cos(a) * n[:, 1]], -1)
    left = np.stack([-t[:, 1], t[:, 0]], -1) / speed[:, None]                 # the curve's left normal
    kappa = kvec_mag * np.sign(np.sum(left * normal_disc, axis=-1))
    inv = 1.0 / r_rp + kappa
    with np.errstate(divide="ignore"):
        return np.where(inv > 1e-9, 1.0 / np.maximum(inv, 1e-9), np.inf)


def footprint_wear(nodes: np.ndarray, centres: np.ndarray, amounts: np.ndarray, half_widths: np.ndarray) -> np.ndarray:
    """Wear depth at ``nodes`` (mm, increasing) of contacts at ``centres`` (mm along the same
    surface), each wearing ``amounts`` (mm², the worn area per unit length: k·F·ds/L) spread over
    its Hertz footprint of ``half_widths`` (mm) with the elliptic pressure shape √(b² − x²).

    Each contact's share is normalised on the nodes (trapezoid weights), so Σ depth·weight equals
    Σ amounts exactly (the worn area is conserved); a footprint narrower than the node spacing
    falls on its two neighbouring nodes linearly.
    """
    nodes = np.asarray(nodes, dtype=float)
    wts = np.gradient(nodes) if len(nodes) > 1 else np.ones(1)
    if len(nodes) > 1:
        wts[0], wts[-1] = 0.5 * (nodes[1] - nodes[0]), 0.5 * (nodes[-1] - nodes[-2])
    depth = np.zeros(len(nodes))
    centres, amounts, half_widths = (np.asarray(x, dtype=float) for x in (centres, amounts, half_widths))
    for lo in range(0, len(centres), 256):
        sl = slice(lo, lo + 256)
        x = nodes[None, :] - centres[sl, None]
        b = np.maximum(half_widths[sl, None], 1e-12)
        shape = np.sqrt(np.clip(b * b - x * x, 0.0, None))
        norm = shape @ wts
        narrow = norm <= 0
        if np.any(narrow):                      # below the node spacing: linear share of two nodes
            hat = np.clip(1.0 - np.abs(x[narrow]) / np.maximum(wts[None, :] * 1.0, 1e-15), 0.0, None)
            shape[narrow], norm[narrow] = hat, hat @ wts
        ok = norm > 0
        depth += (amounts[sl][ok, None] * shape[ok] / norm[ok, None]).sum(axis=0)
    return depth


def side_force(psi_samples: np.ndarray, force_samples: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """The pin force as a function of the pin phase on one flank: the samples (ψ in (0, π), N) of
    every pin and crank angle of a load cycle averaged in the cells around ``grid`` (rad,
    increasing), empty cells interpolated linearly between their neighbours (zero outside the
    samples' range)."""
    grid = np.asarray(grid, dtype=float)
    edges = np.concatenate([[grid[0] - 0.5 * (grid[1] - grid[0])], 0.5 * (grid[1:] + grid[:-1]),
                            [grid[-1] + 0.5 * (grid[-1] - grid[-2])]])
    cell = np.digitize(psi_samples, edges) - 1
    ok = (cell >= 0) & (cell < len(grid))
    total = np.bincount(cell[ok], weights=force_samples[ok], minlength=len(grid))
    count = np.bincount(cell[ok], minlength=len(grid))
    have = count > 0
    if not have.any():
        return np.zeros(len(grid))
    return np.interp(grid, grid[have], total[have] / count[have], left=0.0, right=0.0)


def flank_pin_engagement(kin: MeshKinematics, force: np.ndarray, *, k_mm2_per_N: float, length_mm: float,
                         modulus_MPa: float, zp: int, zc: int, pin_radius: float,
                         pin_rolling: str = "none") -> tuple[np.ndarray, np.ndarray]:
    """Wear of one engagement of a flank with a pin: (depth along the flank at ``kin.disc_arc``,
    depth around the pin at ``kin.pin_angle``), mm.

    ``force`` is the pin force at each ψ of ``kin`` (N). The sliding distance of a step dψ is
    |v_s|·dθ with dθ = (Zp/Zc)·dψ (the crank turns Zp/Zc times faster than the pin's phase), the
    footprint the Hertz half-width of pin and flank (:func:`footprint_wear`). ``pin_rolling``:
    ``"none"`` (Liu et al.: the pin does not turn in its groove, its wear stays where the contact
    runs) or ``"free"`` (the pin turns slowly in its groove: its worn area is spread evenly over its
    circumference).
    """
    force = np.clip(np.asarray(force, dtype=float), 0.0, None)
    dpsi = np.gradient(kin.psi)
    ds = kin.sliding * (zp / zc) * np.abs(dpsi)
    amount = k_mm2_per_N * force * ds / length_mm
    R = np.where(np.isfinite(kin.relative_radius), kin.relative_radius, 1e3 * pin_radius)
    b = np.sqrt(4.0 * force * R / (math.pi * length_mm * modulus_MPa))
    disc = footprint_wear(kin.disc_arc, kin.disc_arc, amount, b)
    pin_nodes = np.linspace(-0.5 * math.pi, 0.5 * math.pi, len(kin.psi)) * pin_radius
    if pin_rolling == "free":
        pin = np.full(len(pin_nodes), amount.sum() / (2.0 * math.pi * pin_radius))
    elif pin_rolling == "none":
        pin = footprint_wear(pin_nodes, kin.pin_angle * pin_radius, amount, b)
    else:
        raise ValueError(f"pin_rolling must be 'none' or 'free', got {pin_rolling!r}")
    return disc, pin


def bearing_clearance_rate(mean_radial_load_N: float, revolutions_per_hour: float,
                           rate_um_per_N_per_Mrev: float) -> float:
    """Radial-clearance growth of a rolling bearing, mm per hour: rate·F̄·revolutions (Liu et al.
    § 4.2: the clearance grows in proportion to the mean radial load and, by Archard's law, to the
    sliding distance, i.e. to the revolutions)."""
    return 1e-3 * rate_um_per_N_per_Mrev * mean_radial_load_N * revolutions_per_hour * 1e-6


@dataclass(frozen=True)
class WornProfile:
    """One tooth space of the disc's profile, unworn and worn, along the pin phases ψ (arrays (n,)).

    Attributes
    ----------
    psi : ndarray
        Pin phase of the contact, rad, increasing over (−π, π): ψ < 0 the flank a negative torque
        loads, ψ > 0 the one a positive torque loads.
    segment, param : ndarray
        Profile segment and base-curve parameter of the contact point (:class:`rvfem.geometry.Profile`).
    point, worn : ndarray (n, 2)
        Contact point on the nominal profile and the same point on the worn one (moved by the depth
        along the inward normal), disc frame, mm.
    depth : ndarray
        Flank wear depth, mm.
    """

    psi: np.ndarray
    segment: np.ndarray
    param: np.ndarray
    point: np.ndarray
    worn: np.ndarray
    depth: np.ndarray


def worn_profile(geometry, psi: np.ndarray, depth_positive: np.ndarray, depth_negative: np.ndarray) -> WornProfile:
    """The profile points the pins touch at phases ±``psi`` (rad, increasing in (0, π)) and their
    positions after the flank wear ``depth_positive`` / ``depth_negative`` (mm, at +ψ / −ψ).

    Pin 0 has the phase ψ at the crank angle θ = −ψ·Zp/Zc (:func:`rvfem.geometry.pin_phases`), so
    its closest points over θ trace one tooth space of the disc
    (:func:`rvfem.geometry.pin_profile_contacts_many`)."""
    case = geometry.case
    psi = np.asarray(psi, dtype=float)
    phases = np.concatenate([-psi[::-1], psi])
    depth = np.concatenate([np.asarray(depth_negative, dtype=float)[::-1], np.asarray(depth_positive, dtype=float)])
    pcs = pin_profile_contacts_many(geometry, -phases * case.pins.count / case.cycloid.teeth)
    point = np.array([pc.point[0] for pc in pcs])
    normal = np.array([pc.normal[0] for pc in pcs])
    return WornProfile(phases, np.array([pc.segment[0] for pc in pcs]), np.array([pc.param[0] for pc in pcs]),
                       point, point - depth[:, None] * normal, depth)
