"""The crank bearing in depth over a load cycle: tilt of the eccentrics from the crankshaft beams,
the slice model of every roller at every crank angle on both raceways, film thickness, κ, the
ISO 281 modified life L_nm and the ISO 16281 reference life L10r (lamina method).

Inputs are the roller loads of a load cycle (the FE rollers, or the rigid rings'
:func:`rvfem.evaluate.roller_slices.rigid_ring_roller_loads` under the handbook forces); the
formulas are in docs/theory.md ("The crank bearing in depth").

Sources
-------
* ISO/TS 16281:2008 (now ISO 16281:2025), *Rolling bearings - Methods for calculating the modified
  reference rating life for universally loaded bearings* (lamina ratings q_c, equivalent lamina
  loads q_e, L10r of line contact).
* ISO 281:2007 (L10, a_ISO, L_nm = a1·a_ISO·L10).
* Roark's *Formulas for Stress and Strain*, simply supported beam with an intermediate point load
  (the slope of the crankshaft at its eccentrics).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import sparse

from rvfem.evaluate import lubrication, roller_slices
from rvfem.solve.models import roller_angles
from rvfem.evaluate.bearing_checks import crank_bearing_static_rating
from rvfem.evaluate.hertz import composite_modulus, reduced_radius
from rvfem.evaluate.iso281 import ROLLER_LIFE_EXPONENT
from rvfem.fem.crankshaft import crankshaft_beam
from rvfem.units import crank_angle_deg

__all__ = [
    "beam_slope_influence",
    "crankshaft_slope_influence",
    "eccentric_slopes",
    "roller_tilts",
    "RacewayGeometry",
    "raceways",
    "cycle_slices",
    "lamina_ratings",
    "lamina_life_mrev",
    "lamina_damage_mrev",
    "DamageLocation",
    "damage_location",
    "BearingDepth",
    "bearing_depth",
    "CrankBearingDepth",
    "crank_bearing_depth",
    "rigid_bearing_depths",
    "cycle_l10r_h",
    "L10R_STEPS",
    "L10rSteps",
    "l10r_steps",
]

log = logging.getLogger(__name__)


def beam_slope_influence(span: float, positions, bending_stiffness: float,
                         support_compliance: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """Cross-section rotation at z_i per unit load at z_j of a beam on two elastic supports, rad/N.

    Bending (Roark, simply supported beam, load at b, point x): y'(x) = (L − b)(L² − (L − b)² −
    3x²)/(6·L·EI) for x ≤ b and −b(L² − b² − 3(L − x)²)/(6·L·EI) for x ≥ b; the supports'
    deflections c₁R₁, c₂R₂ turn the beam by (c₂·b/L − c₁·(L − b)/L)/L. Shear deflection does not
    turn the cross-sections (Timoshenko) and is left out.

    Parameters
    ----------
    span : float
        L, mm.
    positions : sequence of float
        z, mm from support 1.
    bending_stiffness : float
        EI, N·mm² (inf: rigid beam).
    support_compliance : (float, float)
        c₁, c₂, mm/N.

    Returns
    -------
    ndarray (n, n)
    """
    L = float(span)
    z = np.asarray(positions, dtype=float)
    x = z[:, None]
    b = z[None, :]
    g = np.zeros((len(z), len(z)))
    if np.isfinite(bending_stiffness):
        left = (L - b) * (L * L - (L - b) ** 2 - 3.0 * x * x) / (6.0 * L * bending_stiffness)
        right = -b * (L * L - b * b - 3.0 * (L - x) ** 2) / (6.0 * L * bending_stiffness)
        g += np.where(x <= b, left, right)
    c1, c2 = (float(c) for c in support_compliance)
    g += (c2 * b / L - c1 * (L - b) / L) / L + 0.0 * x
    return g


def crankshaft_slope_influence(case) -> np.ndarray | None:
    """The slope influence matrix of a case's crankshaft beam (rad/N, one row per disc); None for
    rigid support or a crankshaft given only by its deflection matrix (no slopes)."""
    cs = case.crank_support
    if cs is None or cs.influence_mm_per_N is not None:
        return None
    ei, _, compliance = crankshaft_beam(cs)   # shear turns no cross-section
    return beam_slope_influence(cs.span, cs.eccentric_positions, ei, compliance)


def eccentric_slopes(case, cycle) -> np.ndarray:
    """Slope vector of disc A's eccentrics (rad, components along the disc's x and y) at every crank
    angle, (n, N, 2): s = −Σ_k g_Ak·F_k (−F the bearing force on the eccentric of disc k). Zero
    with rigid crank support; the discs do not tilt (plane model), so this is the relative tilt
    of eccentric and bore. One-way: the roller loads are those of the untilted solve."""
    n, nb = cycle.bearing_forces.shape[:2]
    g = crankshaft_slope_influence(case)
    if g is None:
        return np.zeros((n, nb, 2))
    forces = cycle.disc_bearing_forces
    if forces is None:                                  # one disc with T/discs
        return -g[0, 0] * np.asarray(cycle.bearing_forces)
    return -np.einsum("k,nkbc->nbc", g[0], np.asarray(forces))


def roller_tilts(slopes: np.ndarray, roller_angles: np.ndarray, bearing_forces: np.ndarray,
                 misalignment_rad: float = 0.0) -> np.ndarray:
    """Tilt of every roller's contact line, rad, (..., Z): the slope vector's component along the
    roller's radial line, plus an extra misalignment in the plane of the bearing force (the worst
    orientation for the loaded rollers)."""
    er = np.stack([np.cos(roller_angles), np.sin(roller_angles)], axis=-1)
    tilt = np.einsum("...c,...zc->...z", slopes, er)
    if misalignment_rad:
        direction = np.arctan2(bearing_forces[..., 1], bearing_forces[..., 0])
        tilt = tilt + misalignment_rad * np.cos(roller_angles - direction[..., None])
    return tilt


@dataclass(frozen=True)
class RacewayGeometry:
    """One raceway of the crank bearing: name, R' (mm), E* (MPa)."""

    name: str
    reduced_radius_mm: float
    composite_modulus_MPa: float


def raceways(case) -> tuple[RacewayGeometry, RacewayGeometry]:
    """The eccentric (inner, convex) and bore (outer, concave) raceways of a case's crank bearing."""
    b = case.crank_bearing
    e_star = composite_modulus(case.material.youngs_modulus, case.material.poissons_ratio)
    r = 0.5 * b.roller_diameter
    return (RacewayGeometry("eccentric", reduced_radius(r, b.inner_raceway_radius, concave=False), e_star),
            RacewayGeometry("bore", reduced_radius(r, b.bore_radius, concave=True), e_star))


def cycle_slices(roller_loads: np.ndarray, tilts: np.ndarray, length_mm: float, raceway: RacewayGeometry,
                 profile, *, bin_ratio: float = 1.1, light_fraction: float = 0.02,
                 cache: dict | None = None) -> np.ndarray:
    """Slice loads per length of every roller contact of a cycle on one raceway, N/mm, (..., Z, n).

    The contacts are grouped by the Hertz half-width b of their nominal line load (groups a factor
    ``bin_ratio`` wide, each solved with the influence matrix of its geometric-mean width) and
    every group is solved at once (:class:`rvfem.evaluate.slice_solver.SliceSolver`, the
    interferences ψ·x − z combinations of x and the drop z). Contacts lighter than
    ``light_fraction`` of the heaviest share the group of that load (their rectangles are then a
    little too wide; they carry under 10⁻⁵ of the damage). ``cache`` keeps each group's solver
    (its influence matrix, inverse and the active sets solved) between calls (key: group, E*, L,
    slices), and its section window (:func:`rvfem.evaluate.roller_slices.section_window`).
    """
    q = np.asarray(roller_loads, dtype=float)
    shape = q.shape
    flat_q = q.reshape(-1)
    flat_t = np.broadcast_to(tilts, shape).reshape(-1)
    x, dx = roller_slices.slice_layout(profile, length_mm)
    r_red, e_star = raceway.reduced_radius_mm, raceway.composite_modulus_MPa
    drop = roller_slices.profile_drop(profile, length_mm, x, composite_modulus_MPa=e_star, reduced_radius_mm=r_red)
    out = np.zeros((flat_q.size, x.size))
    q_max = flat_q.max(initial=0.0)
    loaded = np.flatnonzero(flat_q > 1e-9 * max(q_max, 1.0))
    if loaded.size == 0:
        return out.reshape(shape + (x.size,))
    q_bin = np.maximum(flat_q[loaded], light_fraction * q_max)
    _, b = roller_slices.hertz_peak_from_line_load(q_bin / length_mm, r_red, e_star)   # Hertz half-width of Q/L
    group = np.floor(np.log(b) / math.log(bin_ratio)).astype(int)
    cache = {} if cache is None else cache
    shapes = np.stack([x, drop])                     # g = ψ·x − z: the coefficients (ψ, −1)
    for key in np.unique(group):
        idx = loaded[group == key]
        b_g = bin_ratio ** (key + 0.5)
        ckey = (int(key), bin_ratio, e_star, length_mm, x.size)
        solver = cache.get(ckey)
        if solver is None:
            solver = roller_slices.SliceSolver(roller_slices.rectangle_influence(x, dx, b_g, e_star),
                                               2.0 * b_g * dx, shapes)
        elif not np.array_equal(solver.modes[:, 1:].T, shapes):      # another profile: C and C⁻¹ kept
            solver = roller_slices.SliceSolver(solver.influence, 2.0 * b_g * dx, shapes, inverse=solver.inverse)
        cache[ckey] = solver
        coef = np.stack([flat_t[idx], np.full(idx.size, -1.0)], axis=1)
        p, _ = solver.solve(coef, flat_q[idx])
        window = cache.get(("window",) + ckey)          # the group's section window, as a sparse matrix
        if window is None:
            window = cache[("window",) + ckey] = sparse.csr_matrix(roller_slices.section_window(x, dx, b_g))
        out[idx] = window.dot((p * 2.0 * b_g).T).T
    return out.reshape(shape + (x.size,))


def lamina_ratings(case, slices):
    """Basic dynamic load ratings of the laminae on the inner and outer raceway, N (ISO/TS 16281,
    line contact): q_c = 552·b_m·γ^(2/9)·(1 ∓ γ)^(29/27)/(1 ± γ)^(1/4)·D_we^(29/27)·w^(7/9)·Z^(−1/4),
    upper signs for the inner raceway, w the lamina width (L_we/n_s for n_s equal laminae).

    b_m as in the case's basic rating C (ISO 281). λν is **not** in the lamina ratings: ISO/TS
    16281 derives the rolling-element ratings of the raceways from C divided by λν (Q_c =
    C/(λν·0.378·Z·cos α·i^(7/9))·[1 + (1.038·((1 ∓ γ)/(1 ± γ))^(143/108))^(±9/2)]^(2/9), λν = 0.83
    for radial roller bearings; q_c = Q_c·(1/n_s)^(7/9)), because λν stands in ISO 281 for the
    edge stresses and the non-uniform stress along a real roller (ISO/TR 1281-1), which the lamina
    loads compute explicitly — here the half-space slice model with the roller's profile and
    tilt. 552 ≈ 208/0.378. So at P = C on rigid rings L10r = λν^(−4)·10⁶ revolutions (line
    contact); with λν = 1 it is C's 10⁶.

    ``slices`` is the number n_s of equal laminae over L_we (two floats returned), or the widths of
    unequal laminae in mm (two arrays): the rating of a lamina scales with its width^(7/9), so
    that Σ_k (q_k/q_c,k)^(9/2) over laminae of a uniform load per length is the same however the
    length is cut (the slice model's laminae are refined at the roller ends,
    :func:`rvfem.evaluate.roller_slices.slice_layout`)."""
    b = case.crank_bearing
    g = b.roller_diameter / b.pitch_diameter
    width = b.roller_length / slices if np.isscalar(slices) else np.asarray(slices, dtype=float)
    common = (552.0 * b.b_m * g ** (2.0 / 9.0) * b.roller_diameter ** (29.0 / 27.0)
              * width ** (7.0 / 9.0) * b.rollers ** -0.25)
    inner = common * (1.0 - g) ** (29.0 / 27.0) / (1.0 + g) ** 0.25
    outer = common * (1.0 + g) ** (29.0 / 27.0) / (1.0 - g) ** 0.25
    return inner, outer


def _equivalent_lamina_loads(inner: np.ndarray, outer: np.ndarray, inner_rotates: bool) -> tuple[np.ndarray, np.ndarray]:
    """q_e,k = (Σ_j q_jk^w / Z)^(1/w) over the Z rollers (axis −2) of the inner and the outer
    raceway, w = 4 on the ring that turns relative to the load and 4.5 on the one that stands
    (ISO/TS 16281). The powers of the (…, Z, n_s) loads as products (q²)² and (q²)²·√q: a
    third of the time of ``q**w`` on these arrays, equal to round-off."""
    def power(q: np.ndarray, w: float) -> np.ndarray:
        out = np.square(q)
        np.square(out, out=out)
        if w == 4.5:
            out *= np.sqrt(q)
        return out

    wi, we = (4.0, 4.5) if inner_rotates else (4.5, 4.0)
    z = inner.shape[-2]
    qei = (np.sum(power(inner, wi), axis=-2) / z) ** (1.0 / wi)
    qee = (np.sum(power(outer, we), axis=-2) / z) ** (1.0 / we)
    return qei, qee


def lamina_life_mrev(lamina_loads_inner: np.ndarray, lamina_loads_outer: np.ndarray, q_ci: float, q_ce: float,
                     *, inner_rotates: bool = False) -> np.ndarray:
    """L10r of each load state (million revolutions) from the lamina loads (ISO/TS 16281, line contact).

    q_e,k = (Σ_j q_jk^w / Z)^(1/w) per lamina k over the Z rollers, w = 4 on the ring that turns
    relative to the load and 4.5 on the one that stands; L10r = [Σ_k (q_ci/q_ei,k)^(−9/2) +
    (q_ce/q_ee,k)^(−9/2)]^(−8/9).

    Parameters
    ----------
    lamina_loads_inner, lamina_loads_outer : ndarray (..., Z, n_s)
        Load of every lamina (slice) of every roller, N.
    q_ci, q_ce : float or ndarray (n_s,)
        Lamina ratings (:func:`lamina_ratings`), N.
    inner_rotates : bool
        True if the inner raceway turns relative to the load direction.

    Returns
    -------
    ndarray (...)
        L10r, 10⁶ revolutions (inf without load).
    """
    qei, qee = _equivalent_lamina_loads(lamina_loads_inner, lamina_loads_outer, inner_rotates)
    damage = np.sum((qei / q_ci) ** 4.5 + (qee / q_ce) ** 4.5, axis=-1)
    with np.errstate(divide="ignore"):
        return np.where(damage > 0, damage ** (-8.0 / 9.0), np.inf)


def lamina_damage_mrev(lamina_loads_inner: np.ndarray, lamina_loads_outer: np.ndarray, q_ci, q_ce, *,
                       inner_rotates: bool = False) -> np.ndarray:
    """Damage per million revolutions of every lamina on each raceway, (..., 2, n_s): the load
    state's 1/L10r (:func:`lamina_life_mrev`) shared among the laminae of both raceways in
    proportion to their terms (q_e,k/q_c,k)^(9/2).

    The share is Lundberg and Palmgren's: ISO/TS 16281 combines the laminae as independent
    Weibull survivals, ln(1/S) = Σ_k ln(1/S_k) with ln(1/S_k) ∝ (L/L_k)^e, e = 9/8 and
    L_k = (q_c,k/q_e,k)^4 (line contact), which gives L10r = [Σ_k (q_c,k/q_e,k)^(−9/2)]^(−8/9);
    lamina k's share of ln(1/S) at any life, the chance that the first spall starts there, is
    (q_e,k/q_c,k)^(9/2) / Σ. So the laminae's damage sums to 1/L10r, and over a cycle (Palmgren–
    Miner) to the cycle's damage.

    Parameters and conventions as :func:`lamina_life_mrev`; index 0 of the axis −2 is the inner
    raceway, 1 the outer.
    """
    qei, qee = _equivalent_lamina_loads(lamina_loads_inner, lamina_loads_outer, inner_rotates)
    terms = np.stack([np.broadcast_to((qei / q_ci) ** 4.5, qei.shape),
                      np.broadcast_to((qee / q_ce) ** 4.5, qee.shape)], axis=-2)
    total = np.sum(terms, axis=(-2, -1), keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, terms * total ** (-1.0 / 9.0), 0.0)   # terms/Σ · Σ^(8/9)


@dataclass(frozen=True)
class DamageLocation:
    """Where the lamina damage of a bearing concentrates (:func:`damage_location`).

    Attributes
    ----------
    raceway : str
        ``"eccentric"`` or ``"bore"``: the raceway of the largest damage per length.
    x_mm : float
        Centre of the lamina of the largest damage per length, mm from the roller's centre (the
        sign is the side; the profiles are symmetric).
    peak_over_mean : float
        That largest damage per length over the raceway's mean over the effective length L_we
        (1 for a damage spread evenly).
    spread_mm : float
        Length of roller over which that raceway's damage per length is at least half its
        largest, mm (L_we for an evenly spread damage, short for a peak).
    middle_share : float
        Share of the bearing's damage (both raceways) in the middle half of the roller,
        |x| ≤ L_we/4, the damage taken as uniform within each lamina (0.5 for an evenly spread
        damage).
    """

    raceway: str
    x_mm: float
    peak_over_mean: float
    spread_mm: float
    middle_share: float


def damage_location(x_mm, widths_mm, lamina_damage, length_mm: float,
                    names: tuple[str, str] = ("eccentric", "bore")) -> DamageLocation | None:
    """Where the damage of :func:`lamina_damage_mrev` (summed over a cycle, (2, n_s)) concentrates:
    the raceway and lamina of the largest damage per length, how far it spreads and the middle
    half's share (:class:`DamageLocation`); None without damage.

    Parameters
    ----------
    x_mm, widths_mm : array_like (n_s,)
        Lamina centres and widths, mm.
    lamina_damage : array_like (2, n_s)
        Damage of every lamina of the inner and the outer raceway (any unit).
    length_mm : float
        Effective roller length L_we, mm.
    """
    x = np.asarray(x_mm, dtype=float)
    dx = np.asarray(widths_mm, dtype=float)
    d = np.asarray(lamina_damage, dtype=float)
    total = float(np.sum(d))
    if not total > 0:
        return None
    density = d / dx
    # the first of the laminae within round-off of the largest (a symmetric roller's two ends
    # carry the same damage; which end is reported must not depend on the last bit)
    top = float(np.max(density))
    r, k = np.unravel_index(int(np.argmax(density >= top * (1.0 - 1e-12))), density.shape)
    peak = float(density[r, k])
    mean = float(np.sum(d[r])) / length_mm
    spread = float(np.sum(dx[density[r] >= 0.5 * peak]))
    quarter = 0.25 * length_mm                          # each lamina's part in |x| ≤ L/4 (uniform within it)
    inside = np.clip(np.minimum(x + 0.5 * dx, quarter) - np.maximum(x - 0.5 * dx, -quarter), 0.0, None) / dx
    middle = float(np.sum(d * inside)) / total
    return DamageLocation(raceway=names[r], x_mm=float(x[k]), peak_over_mean=peak / mean if mean > 0 else math.inf,
                          spread_mm=spread, middle_share=middle)


@dataclass(frozen=True)
class BearingDepth:
    """The crank bearing in depth for one bearing and one load model (rigid or flexible).

    Attributes
    ----------
    bearing : int
        0-based bearing.
    model : str
        ``"rigid"`` or ``"flexible"``.
    roller_peak_pressure_MPa : float
        Largest slice pressure over the cycle, both raceways, MPa (the roller of the largest
        pressure of the cycle's slices, solved again with each slice's own strip width).
    roller_edge_factor : float
        That peak / the Hertz p_h of the same roller's nominal line load Q/L.
    raceway : str
        Raceway of the peak (``"eccentric"`` or ``"bore"``).
    theta_deg : float
        Crank angle of the peak, degrees.
    roller : int
        0-based roller of the peak.
    roller_load_N : float
        Its load Q, N.
    tilt_mrad : float
        Its tilt, mrad.
    x_mm, pressure_MPa : ndarray (n_s,)
        p(x) of that roller on that raceway, MPa.
    max_shear_MPa, max_shear_depth_mm : float
        Subsurface principal shear 0.300·p and its depth 0.786·b at the peak, MPa and mm.
    film_thickness_min_um, film_thickness_central_um : float
        EHL film (Pan & Hamrock) of the most loaded roller at the eccentric, µm.
    film_parameter : float
        Λ = h_min/σ.
    kappa : float
        ν/ν1.
    a_iso : float
        ISO 281 a_ISO at κ and e_C·C_u/P (P = equivalent bearing load).
    L10h : float
        Basic rating life (ISO 281), h.
    L_nm_h : float
        a1·a_ISO·L10h (a1 = 1, 10 % failure probability), h.
    L10r_h : float
        ISO/TS 16281 reference rating life from the lamina loads (Palmgren–Miner over the cycle), h.
    max_roller_load_N : float
        The most loaded roller: the largest roller load over the cycle, N (the quantity of
        ``hertz.fe_rollers`` / ``hertz.stribeck_rigid``, not the roller of the pressure peak).
    max_roller_theta_deg : float
        Its crank angle, degrees.
    max_roller : int
        Its 0-based roller.
    slice_width_mm : ndarray (n_s,) or None
        Widths Δx of the laminae centred at ``x_mm``, mm.
    damage_per_h : ndarray (2, n_s) or None
        Lamina damage per hour of operation on the eccentric (row 0) and the bore (row 1)
        (:func:`lamina_damage_mrev`, Palmgren–Miner over the cycle): where spalling starts; its
        sum is 1/``L10r_h``.
    damage : DamageLocation or None
        Where that damage concentrates (:func:`damage_location`).
    """

    bearing: int
    model: str
    roller_peak_pressure_MPa: float
    roller_edge_factor: float
    raceway: str
    theta_deg: float
    roller: int
    roller_load_N: float
    tilt_mrad: float
    x_mm: np.ndarray
    pressure_MPa: np.ndarray
    max_shear_MPa: float
    max_shear_depth_mm: float
    film_thickness_min_um: float
    film_thickness_central_um: float
    film_parameter: float
    kappa: float
    a_iso: float
    L10h: float
    L_nm_h: float
    L10r_h: float
    max_roller_load_N: float = math.nan
    max_roller_theta_deg: float = math.nan
    max_roller: int = -1
    slice_width_mm: np.ndarray | None = None
    damage_per_h: np.ndarray | None = None
    damage: DamageLocation | None = None


def _cycle_damage(case, slice_loads, dx) -> float:
    """Palmgren–Miner damage per million revolutions over a cycle, mean_θ 1/L10r(θ), from the slice
    loads per length of both raceways (N/mm, (n, Z, n_s) each) and the slice widths dx (mm)."""
    q_ci, q_ce = lamina_ratings(case, dx)
    # the eccentric turns relative to the load (whose direction swings by about 100° in the disc
    # frame but does not follow the crank); the bore stands relative to it
    per_angle = lamina_life_mrev(slice_loads[0] * dx, slice_loads[1] * dx, q_ci, q_ce, inner_rotates=True)
    return float(np.mean(1.0 / per_angle))


def _cycle_lamina_damage(case, slice_loads, dx) -> np.ndarray:
    """Palmgren–Miner damage per million revolutions of every lamina over a cycle, (2, n_s) (the
    eccentric, the bore): mean_θ of :func:`lamina_damage_mrev`; sums to :func:`_cycle_damage`."""
    q_ci, q_ce = lamina_ratings(case, dx)
    per_angle = lamina_damage_mrev(slice_loads[0] * dx, slice_loads[1] * dx, q_ci, q_ce, inner_rotates=True)
    return np.mean(per_angle, axis=0)


def cycle_l10r_h(case, roller_loads: np.ndarray, tilts: np.ndarray, bearing_speed_rpm: float,
                 cache: dict | None = None) -> float:
    """ISO/TS 16281 L10r (h) of one bearing over a load cycle from its roller loads and tilts,
    (n, Z) each: the slices of both raceways (:func:`cycle_slices`) and Palmgren–Miner over the
    cycle, exactly as :func:`bearing_depth` computes its ``L10r_h``."""
    b = case.crank_bearing
    slice_loads = [cycle_slices(roller_loads, tilts, b.roller_length, g, b.profile, cache=cache) for g in raceways(case)]
    _, dx = roller_slices.slice_layout(b.profile, b.roller_length)
    damage = _cycle_damage(case, slice_loads, dx)
    return math.inf if damage == 0 else 1.0e6 / (60.0 * bearing_speed_rpm) / damage


def _peak(case, theta, loads, tilts, slice_loads, geoms):
    """(raceway index, angle, roller, p(x) array) of the largest slice pressure of one bearing."""
    best = None
    for r, (geom, q) in enumerate(zip(geoms, slice_loads)):
        k, j, s = np.unravel_index(int(np.argmax(q)), q.shape)       # p_h grows with q
        ph, _ = roller_slices.hertz_peak_from_line_load(q[k, j], geom.reduced_radius_mm, geom.composite_modulus_MPa)
        if best is None or ph[s] > best[0]:
            best = (float(ph[s]), r, int(k), int(j), ph)
    return best


def bearing_depth(case, theta: np.ndarray, roller_loads: np.ndarray, tilts: np.ndarray, equivalent_load_N: float,
                  bearing_speed_rpm: float, rating_N: float, bearing: int, model: str,
                  cache: dict | None = None, progress: Callable[[], None] | None = None) -> BearingDepth:
    """Slice model, lubrication and lives of one bearing over a load cycle.

    Parameters
    ----------
    case : Case
    theta : ndarray (n,)
        Crank angles, rad (equally spaced over one revolution).
    roller_loads, tilts : ndarray (n, Z)
        Roller loads (N) and tilts (rad) of this bearing.
    equivalent_load_N : float
        P = F_m of the bearing (ISO 281), N.
    bearing_speed_rpm, rating_N : float
        n_b (rpm) and C (N).
    bearing : int
    model : str
    cache : dict, optional
        Influence matrices kept between calls (:func:`cycle_slices`).
    progress : callable, optional
        ``progress()`` after the slices of each raceway.

    Returns
    -------
    BearingDepth
    """
    b = case.crank_bearing
    prof = b.profile
    geoms = raceways(case)
    slice_loads = []
    for g in geoms:
        slice_loads.append(cycle_slices(roller_loads, tilts, b.roller_length, g, prof, cache=cache))
        if progress is not None:
            progress()
    x, dx = roller_slices.slice_layout(prof, b.roller_length)
    _, r, k, j, _ = _peak(case, theta, roller_loads, tilts, slice_loads, geoms)
    g = geoms[r]
    q_roller = float(roller_loads[k, j])
    tilt = float(np.broadcast_to(tilts, roller_loads.shape)[k, j])
    # the worst roller again with each slice's own strip width (roller_slices.roller_contact)
    worst = roller_slices.roller_contact(q_roller, b.roller_length, g.reduced_radius_mm, g.composite_modulus_MPa,
                                         prof, tilt_rad=tilt)
    # lubrication at the most loaded roller, on the eccentric (the smaller R', the thinner film)
    lub = case.lubricant
    _, _, nu = lubrication.lubricant_viscosity(lub)
    u = lubrication.entrainment_speed(bearing_speed_rpm, b.pitch_diameter, b.roller_diameter)
    q_max = float(np.max(roller_loads))
    film = lubrication.pan_hamrock_film(q_max / b.roller_length, geoms[0].reduced_radius_mm,
                                        geoms[0].composite_modulus_MPa, nu * lub.density * 1e-6, u,
                                        lub.pressure_viscosity_per_GPa)
    kappa = nu / lubrication.reference_viscosity(bearing_speed_rpm, b.pitch_diameter)
    c0 = crank_bearing_static_rating(b)
    cu = b.fatigue_load_limit_N or lubrication.fatigue_load_limit(c0, b.pitch_diameter)
    a_iso = lubrication.a_iso_roller(kappa, lubrication.contamination_factor(lub) * cu / equivalent_load_N)
    to_hours = 1.0e6 / (60.0 * bearing_speed_rpm)
    l10h = to_hours * (rating_N / equivalent_load_N) ** ROLLER_LIFE_EXPONENT
    lamina_damage_mrev = _cycle_lamina_damage(case, slice_loads, dx)
    damage = float(np.sum(lamina_damage_mrev))     # the laminae's damage sums to the cycle's (_cycle_damage)
    lamina_damage = lamina_damage_mrev / to_hours   # per hour
    k_max, j_max = np.unravel_index(int(np.argmax(roller_loads)), roller_loads.shape)
    return BearingDepth(
        bearing=bearing, model=model, roller_peak_pressure_MPa=worst.peak_pressure_MPa,
        roller_edge_factor=worst.edge_factor, raceway=g.name, theta_deg=crank_angle_deg(theta[k]), roller=j,
        roller_load_N=q_roller, tilt_mrad=1e3 * tilt, x_mm=x, pressure_MPa=worst.pressure_MPa,
        max_shear_MPa=worst.max_shear_MPa, max_shear_depth_mm=worst.max_shear_depth_mm,
        film_thickness_min_um=film.minimum_um, film_thickness_central_um=film.central_um,
        film_parameter=film.minimum_um / lubrication.composite_roughness_um(lub.roughness_Ra_um),
        kappa=kappa, a_iso=a_iso, L10h=l10h, L_nm_h=a_iso * l10h,
        L10r_h=math.inf if damage == 0 else to_hours / damage, max_roller_load_N=float(roller_loads[k_max, j_max]),
        max_roller_theta_deg=crank_angle_deg(theta[k_max]), max_roller=int(j_max), slice_width_mm=dx,
        damage_per_h=lamina_damage, damage=damage_location(x, dx, lamina_damage, b.roller_length))


@dataclass(frozen=True)
class CrankBearingDepth:
    """The crank bearing in depth for every bearing of a case (:func:`crank_bearing_depth`).

    Attributes
    ----------
    flexible : tuple of BearingDepth
        From the FE roller loads, the crankshaft's tilt and the extra misalignment.
    rigid : tuple of BearingDepth
        From the handbook bearing forces on rigid rings with the case's clearance or preload and
        the same roller law as the FE's rigid-disc limit (Palmgren's two contacts), rollers
        untilted but for the extra misalignment (:func:`rigid_bearing_depths`; empty where the
        handbook is not defined).
    max_slope_mrad : float
        Largest crankshaft slope at an eccentric over the cycle, mrad (0 with rigid support).
    seconds : float
        Wall time of the evaluation, s.
    """

    flexible: tuple[BearingDepth, ...]
    rigid: tuple[BearingDepth, ...]
    max_slope_mrad: float
    seconds: float = 0.0


def crank_bearing_depth(case, theta: np.ndarray, cycle, rigid_forces, comparison, rating_N: float,
                        speed_rpm: float, rigid_depths: tuple | None = None,
                        progress: Callable[[int, int], None] | None = None) -> CrankBearingDepth | None:
    """The crank bearing in depth over a load cycle, rigid and flexible (None without FE rollers).

    Parameters
    ----------
    case : Case
    theta : ndarray (n,)
        Crank angles, rad.
    cycle : rvfem.solve.cycle.CycleResult
        With ``roller_loads`` and ``roller_angles`` (bearing model ``rollers``).
    rigid_forces : ndarray (n, N, 2) or None
        Handbook bearing forces (None or not an array where the handbook is not defined).
    comparison : rvfem.evaluate.compare.Comparison
        Equivalent loads P = F_m per bearing (rigid and flexible).
    rating_N, speed_rpm : float
        C and n_b.
    rigid_depths : tuple of BearingDepth, optional
        The rigid column already computed at the same angles (:func:`rigid_bearing_depths`, as the
        rigid handbook evaluation has it); computed here when not given.
    progress : callable, optional
        ``progress(done, total)`` after the flexible slices of each raceway of each bearing and after
        the rigid column (when computed here).
    """
    if cycle.roller_loads is None or cycle.roller_angles is None:
        return None
    t0 = time.perf_counter()
    slopes = eccentric_slopes(case, cycle)
    misalignment = 1e-3 * case.crank_bearing.profile.misalignment_mrad
    tilts = roller_tilts(slopes, cycle.roller_angles, cycle.bearing_forces, misalignment)
    flexible: list[BearingDepth] = []
    cache: dict = {}
    have_rigid = isinstance(rigid_forces, np.ndarray) and np.all(np.isfinite(rigid_forces))
    steps = 2 * len(comparison.bearings) + int(have_rigid and rigid_depths is None)
    done = 0

    def step() -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, steps)

    for bc in comparison.bearings:
        i = bc.bearing
        flexible.append(bearing_depth(case, theta, cycle.roller_loads[:, i], tilts[:, i], bc.flexible.equivalent_N,
                                      speed_rpm, rating_N, i, "flexible", cache, progress=step))
    rigid = () if rigid_depths is None else rigid_depths
    if have_rigid and rigid_depths is None:
        equivalent = {bc.bearing: bc.rigid.equivalent_N for bc in comparison.bearings if bc.rigid is not None}
        rigid = rigid_bearing_depths(case, theta, rigid_forces, equivalent, rating_N, speed_rpm, cache)
        if progress is not None:
            progress(steps, steps)
    return CrankBearingDepth(flexible=tuple(flexible), rigid=tuple(rigid),
                             max_slope_mrad=1e3 * float(np.max(np.hypot(slopes[..., 0], slopes[..., 1]),
                                                                initial=0.0)),
                             seconds=time.perf_counter() - t0)


def rigid_bearing_depths(case, theta: np.ndarray, rigid_forces: np.ndarray, equivalent_loads_N: dict,
                         rating_N: float, speed_rpm: float, cache: dict | None = None,
                         progress: Callable[[int, int], None] | None = None) -> tuple[BearingDepth, ...]:
    """The crank bearing in depth under the handbook forces: rigid rings with the case's clearance,
    rollers at their cage positions (:func:`rvfem.evaluate.roller_slices.case_rigid_roller_loads`),
    untilted but for the case's extra misalignment; one :func:`bearing_depth` per bearing. Used by
    the run's rigid column and by the rigid handbook evaluation alone (``rvfem rigid``).

    Parameters
    ----------
    case : Case
    theta : ndarray (n,)
        Crank angles, rad (equally spaced over one revolution).
    rigid_forces : ndarray (n, N, 2)
        Handbook force of every bearing on the disc, N.
    equivalent_loads_N : dict of int to float
        P = F_m of each 0-based bearing to evaluate, N.
    rating_N, speed_rpm : float
        C (N) and n_b (rpm).
    cache : dict, optional
        Influence matrices kept between calls (:func:`cycle_slices`).
    progress : callable, optional
        ``progress(done, total)`` after the slices of each raceway of each bearing.
    """
    loads = roller_slices.case_rigid_roller_loads(case, theta, rigid_forces)
    angles = roller_angles(case, np.asarray(theta, dtype=float))
    tilts = roller_tilts(np.zeros(np.shape(rigid_forces)), angles, rigid_forces,
                         1e-3 * case.crank_bearing.profile.misalignment_mrad)
    cache = {} if cache is None else cache
    depths = []
    done, steps = 0, 2 * len(equivalent_loads_N)

    def step() -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, steps)

    for i, p in sorted(equivalent_loads_N.items()):
        depths.append(bearing_depth(case, theta, loads[:, i], tilts[:, i], p, speed_rpm, rating_N, i, "rigid", cache,
                                    progress=step))
    return tuple(depths)


L10R_STEPS = ("handbook", "flexible_forces_frictionless", "flexible_forces", "flexible_rollers_untilted", "flexible")
"""The load models of :func:`l10r_steps`, from the rigid reference to the flexible column."""


@dataclass(frozen=True)
class L10rSteps:
    """The flexible/rigid L10r ratio of one bearing as a product of factors (:func:`l10r_steps`).

    Attributes
    ----------
    bearing : int
        0-based bearing.
    L10r_h : dict of str to float
        L10r (h) of every load model of :data:`L10R_STEPS`: ``handbook`` the handbook forces on
        rigid rings (the in-depth rigid column); ``flexible_forces_frictionless`` and
        ``flexible_forces`` the FE bearing forces without and with the pin friction on the same
        rigid rings; ``flexible_rollers_untilted`` the FE roller loads, rollers untilted;
        ``flexible`` the FE roller loads with the crankshaft's tilt (the flexible column). Every
        model has the case's clearance or preload and its extra misalignment.
    factors : dict of str to float
        ``pin_friction`` = flexible_forces / flexible_forces_frictionless, ``bearing_forces`` =
        flexible_forces_frictionless / handbook, ``load_sharing`` = flexible_rollers_untilted /
        flexible_forces, ``tilt`` = flexible / flexible_rollers_untilted.
    ratio : float
        flexible / handbook, the product of the factors.
    """

    bearing: int
    L10r_h: dict
    factors: dict
    ratio: float


def l10r_steps(case, theta: np.ndarray, cycle, handbook_forces: np.ndarray, frictionless_forces: np.ndarray,
               bearing_speed_rpm: float, bearings=None) -> tuple[L10rSteps, ...]:
    """The flexible/rigid L10r ratio of every bearing taken apart in steps: handbook → pin friction →
    flexible bearing forces → load sharing → tilt, each a factor, their product the ratio.

    Every step is one load model of :data:`L10R_STEPS` through the same slices and lamina life
    (:func:`cycle_l10r_h`); the rigid rings are those of the rigid column (the case's clearance or
    preload, Palmgren's two contacts, :func:`rvfem.evaluate.roller_slices.case_rigid_roller_loads`).
    The handbook has no pin friction, so the friction's factor is measured on the flexible disc:
    its bearing forces with the case's μ against the same cycle solved with μ = 0.

    Parameters
    ----------
    case : Case
    theta : ndarray (n,)
        Crank angles, rad.
    cycle : rvfem.solve.cycle.CycleResult
        The case's flexible cycle (bearing model ``rollers``).
    handbook_forces, frictionless_forces : ndarray (n, N, 2)
        The handbook bearing forces and the flexible ones with μ = 0 (the cycle's own where the case
        has no friction), N.
    bearing_speed_rpm : float
    bearings : iterable of int, optional
        0-based bearings (default all).
    """
    theta = np.asarray(theta, dtype=float)
    misalignment = 1e-3 * case.crank_bearing.profile.misalignment_mrad
    angles = roller_angles(case, theta)
    slopes = eccentric_slopes(case, cycle)
    tilted = roller_tilts(slopes, cycle.roller_angles, cycle.bearing_forces, misalignment)
    untilted = roller_tilts(np.zeros_like(slopes), cycle.roller_angles, cycle.bearing_forces, misalignment)
    rings = {}
    for key, forces in (("handbook", handbook_forces), ("flexible_forces_frictionless", frictionless_forces),
                        ("flexible_forces", cycle.bearing_forces)):
        forces = np.asarray(forces, dtype=float)
        rings[key] = (roller_slices.case_rigid_roller_loads(case, theta, forces),
                      roller_tilts(np.zeros(forces.shape), angles, forces, misalignment))
    models = {**rings, "flexible_rollers_untilted": (cycle.roller_loads, untilted),
              "flexible": (cycle.roller_loads, tilted)}
    cache: dict = {}
    out = []
    for i in (range(cycle.bearing_forces.shape[1]) if bearings is None else bearings):
        life = {key: cycle_l10r_h(case, models[key][0][:, i], models[key][1][:, i], bearing_speed_rpm, cache)
                for key in L10R_STEPS}

        def ratio(a, b):
            return life[a] / life[b] if life[b] and math.isfinite(life[b]) else math.nan

        factors = {"pin_friction": ratio("flexible_forces", "flexible_forces_frictionless"),
                   "bearing_forces": ratio("flexible_forces_frictionless", "handbook"),
                   "load_sharing": ratio("flexible_rollers_untilted", "flexible_forces"),
                   "tilt": ratio("flexible", "flexible_rollers_untilted")}
        out.append(L10rSteps(bearing=i, L10r_h=life, factors=factors, ratio=ratio("flexible", "handbook")))
    return tuple(out)
