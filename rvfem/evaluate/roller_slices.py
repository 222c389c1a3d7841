"""Pressure along the crank-bearing rollers: roller profile, slice model on an elastic half-space,
subsurface shear, and the rigid-ring roller loads of the handbook model.

A roller of effective length L carrying the load Q on one raceway is cut into n slices of width
Δx along its axis. Slice j sits at x_j (from the roller centre) and its two surfaces approach by

    s_j = δ + ψ·x_j − z(x_j),

δ the approach of the roller and raceway at mid-length, ψ their relative tilt (rad) and z the
profile drop of the roller (:func:`profile_drop`). Each slice carries a uniform pressure p_j over a
rectangle Δx × 2b of the contact strip (b the Hertz half-width of the nominal line load Q/L); the
elastic displacement of both bodies at the centre of slice i is w_i = Σ_j C_ij·p_j, with C_ij the
displacement at the centre of rectangle i under a unit pressure on rectangle j of a half-space
(Love's solution for a uniformly loaded rectangle, Johnson, *Contact Mechanics*, eq. 3.25; both
bodies through the composite modulus E*). Unlike independent slice springs this couples the slices,
so a straight roller shows its edge peaks. Contact: p_j ≥ 0, w_j = s_j where p_j > 0 and w_j ≥ s_j
where p_j = 0, with Σ p_j·2b·Δx_j = Q (solved with an active set, :func:`solve_slices`). This is the
half-space slice method of the roller-bearing literature (e.g. de Mul, Kalker and Fredriksson, *The
contact between arbitrarily curved bodies of finite dimensions*, J. Tribology 1986; Reusner's
rectangle-coupled slices) with one rectangle across the strip.

The local peak pressure of slice j is the Hertz peak of its load per length q_j = p_j·2b:
p_h,j = √(q_j·E*/(π·R')), half-width b_j = √(4·q_j·R'/(π·E*)) (Johnson §4.3); the maximum shear
stress under it is 0.300·p_h,j at depth 0.786·b_j (principal shear, Tresca; the orthogonal shear
τ_yz peaks at 0.25·p_h at 0.5·b, Johnson §4.2, Fig. 4.6). Near the roller ends this plane-strain
value underestimates the true three-dimensional stress.

Sources
-------
* K. L. Johnson, *Contact Mechanics*, Cambridge University Press 1985, §3.9 (uniform pressure on a
  rectangle), §4.2-4.3 (line contact, subsurface stresses).
* Zhang, Wang, Wu, Guan, Chen, *Contact load and elastohydrodynamic lubrication analysis of
  eccentric bearings in RV reducer considering the effects of roller profile modification*,
  eqs. 8-10 (straight, arc and combined generatrix).
* H. Reusner, *Druckflächenbelastung und Oberflächenverschiebung im Wälzkontakt von Rotationskörpern*,
  Dissertation, Karlsruhe 1977 (the logarithmic profile); P. M. Johns, R. Gohar, *Roller bearings
  under radial and eccentric loads*, Tribology International 14 (1981) 131-136 (its finite form).
* T. A. Harris, M. N. Kotzalas, *Rolling Bearing Analysis* (the zero-clearance roller load
  distribution Q_j ∝ cos(ψ_j)^(10/9) of a radially loaded roller bearing).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rvfem.case.definition import ROLLER_PROFILE_KINDS, RollerProfile
from rvfem.evaluate.hertz import hertz_half_width
from rvfem.evaluate.rigid_rings import case_rigid_roller_loads, rigid_ring_roller_loads
from rvfem.evaluate.slice_solver import SliceSolver, influence_inverse, solve_slices

__all__ = [
    "PROFILE_KINDS",
    "PROFILE_DROPS",
    "register_profile_kind",
    "SHEAR_FACTOR",
    "SHEAR_DEPTH_FACTOR",
    "SliceContact",
    "profile_drop",
    "corner_extent",
    "slice_centres",
    "slice_layout",
    "rectangle_influence",
    "section_window",
    "windowed_peak",
    "solve_slices",
    "hertz_peak_from_line_load",
    "roller_contact",
    "influence_inverse",
    "SliceSolver",
    "rigid_ring_roller_loads",
    "case_rigid_roller_loads",
]

PROFILE_KINDS = tuple(ROLLER_PROFILE_KINDS)
"""The roller-profile kinds (:data:`rvfem.case.definition.ROLLER_PROFILE_KINDS`, where they are declared)."""
#: Maximum principal shear stress / p_h of a Hertz line contact (Johnson, Contact Mechanics, §4.2).
SHEAR_FACTOR = 0.300
#: Its depth / b.
SHEAR_DEPTH_FACTOR = 0.786


@dataclass(frozen=True)
class SliceContact:
    """One roller–raceway contact solved by the slice model.

    Attributes
    ----------
    x_mm : ndarray (n,)
        Slice centres along the roller, from its centre, mm.
    line_load_N_per_mm : ndarray (n,)
        Load per length q_j of every slice, N/mm.
    pressure_MPa : ndarray (n,)
        Local Hertz peak pressure p_h,j = √(q_j·E*/(π·R')), MPa.
    half_width_mm : ndarray (n,)
        Local Hertz half-width b_j, mm.
    approach_mm : float
        δ, the approach at mid-length (including the half-space's far-field part), mm.
    peak_pressure_MPa : float
        max p_h,j, MPa.
    edge_factor : float
        Peak pressure / Hertz p_h of the nominal line load Q/L.
    max_shear_MPa, max_shear_depth_mm : float
        Largest subsurface principal shear stress 0.300·p_h,j and its depth 0.786·b_j (slice of the
        peak), MPa and mm.
    """

    x_mm: np.ndarray
    line_load_N_per_mm: np.ndarray
    pressure_MPa: np.ndarray
    half_width_mm: np.ndarray
    approach_mm: float
    peak_pressure_MPa: float
    edge_factor: float
    max_shear_MPa: float
    max_shear_depth_mm: float
    peak_x_mm: float = math.nan
    widths_mm: np.ndarray | None = None


def corner_extent(profile) -> float:
    """Axial length c of each rounded corner beyond the effective length, mm: ``chamfer_length``
    where given, else ``corner_radius`` (a quarter circle reaching the end face); 0 for a sharp
    corner."""
    r = float(getattr(profile, "corner_radius", 0.0) or 0.0)
    if r <= 0.0:
        return 0.0
    c = getattr(profile, "chamfer_length", None)
    return r if c is None else min(float(c), r)


def profile_drop(profile, length_mm: float, x_mm, *, composite_modulus_MPa: float,
                 reduced_radius_mm: float) -> np.ndarray:
    """Drop z(x) of the roller surface below its straight generatrix, mm.

    Parameters
    ----------
    profile : rvfem.case.definition.RollerProfile
        ``kind`` and its parameters (crown radius R, design load Q_d, modification length a and
        drop b), and the corner: radius r (``corner_radius``) and axial length c
        (``chamfer_length``, default r).
    length_mm : float
        Effective roller length L, mm (the corners lie beyond it).
    x_mm : array_like
        Positions from the roller centre, |x| ≤ L/2 + c, mm.
    composite_modulus_MPa, reduced_radius_mm : float
        E* and R' of the contact (the logarithmic profile's design load sets its drop through them).

    Returns
    -------
    ndarray
        z(x) ≥ 0, mm.

    Notes
    -----
    Over the effective length, |x| ≤ l = L/2:

    * straight: z = 0 (Zhang et al., eq. 8);
    * arc: z = R − √(R² − x²) (eq. 9);
    * combined: z = 0 for |x| ≤ l − a, else R − √(R² − (|x| − l + a)²) with
      R = (a² + b²)/(2b), so that z(l) = b (eq. 10, its b = R − √(R² − a²));
    * logarithmic (Johns–Gohar): z = 2Q_d/(π·L·E′)·ln[1/(1 − (1 − b_d²/l²)·(x/l)²)] with
      E′ = 2E* (the plane-strain modulus E/(1 − ν²) of two equal steels), i.e.
      Q_d/(π·L·E*)·ln[…]; b_d the Hertz half-width at Q_d; Lundberg's profile (b_d → 0) with a
      finite drop at the ends. It is the sag of a uniformly loaded strip on the half-space, so
      the pressure is uniform along the roller at Q_d.

    Beyond it, on the rounded corner (Zhang et al.'s "round corners", their Fig. 5), u = |x| − l
    with 0 < u ≤ c: z = z(l) + z′(l)·u + r − √(r² − u²), the generatrix continued along its end
    tangent plus a circular arc of radius r tangent to it (exact for the straight roller, to
    first order in the end slope z′(l) for the crowned ones; z′(l) by a one-sided difference).
    The surface stays smooth (no kink) where the corner begins, so the edge pressure is finite.
    """
    try:
        drop = PROFILE_DROPS[profile.kind]
    except KeyError:
        raise ValueError(f"unknown roller profile kind {profile.kind!r}; expected one of {tuple(PROFILE_DROPS)}") from None
    x = np.abs(np.asarray(x_mm, dtype=float))
    half = 0.5 * length_mm
    contact = dict(composite_modulus_MPa=composite_modulus_MPa, reduced_radius_mm=reduced_radius_mm)
    z = drop(profile, length_mm, np.minimum(x, half), **contact)
    c = corner_extent(profile)
    u = np.clip(x - half, 0.0, c)
    if c > 0.0 and np.any(u > 0.0):
        h = 1e-7 * length_mm
        ends = drop(profile, length_mm, np.array([half - h, half]), **contact)
        slope = float(ends[1] - ends[0]) / h
        r = float(profile.corner_radius)
        z = z + slope * u + (r - np.sqrt(r * r - u * u))
    return z


def _straight_drop(profile, length_mm, x, **contact):
    """z = 0."""
    return np.zeros_like(x)


def _arc_drop(profile, length_mm, x, **contact):
    """z = R − √(R² − x²), R the crown radius."""
    r = profile.crown_radius
    return r - np.sqrt(r * r - np.minimum(x, r) ** 2)


def _combined_drop(profile, length_mm, x, **contact):
    """Straight centre, circular end segments of length a dropping by b at the ends."""
    a, b = profile.modification_length, profile.modification_drop
    if b <= 0.0:
        return np.zeros_like(x)
    r = (a * a + b * b) / (2.0 * b)
    u = np.clip(x - (0.5 * length_mm - a), 0.0, None)
    return r - np.sqrt(r * r - np.minimum(u, r) ** 2)


def _logarithmic_drop(profile, length_mm, x, *, composite_modulus_MPa, reduced_radius_mm):
    """Johns–Gohar's drop for the design load (uniform pressure along the roller at that load)."""
    half = 0.5 * length_mm
    q = profile.design_load_N
    b_d = hertz_half_width(q, length_mm, reduced_radius_mm, composite_modulus_MPa)
    frac = min(b_d / half, 1.0)
    arg = 1.0 - (1.0 - frac * frac) * np.minimum(x / half, 1.0) ** 2
    return q / (math.pi * length_mm * composite_modulus_MPa) * np.log(1.0 / arg)   # 2Q/(π·L·E′), E′ = 2E*


PROFILE_DROPS = {
    "straight": _straight_drop,
    "arc": _arc_drop,
    "logarithmic": _logarithmic_drop,
    "combined": _combined_drop,
}
"""The drop function of every roller-profile kind, ``drop(profile, length_mm, |x|, *,
composite_modulus_MPa, reduced_radius_mm) -> z`` (mm; see :func:`profile_drop`). Its kinds are
those of :data:`rvfem.case.definition.ROLLER_PROFILE_KINDS`: this module is not imported otherwise."""

if set(PROFILE_DROPS) != set(ROLLER_PROFILE_KINDS):   # a kind the case accepts but nothing can draw
    raise ImportError("rvfem.evaluate.roller_slices: the roller-profile kinds of the case format "
                      f"({', '.join(ROLLER_PROFILE_KINDS)}) and those with a drop function in PROFILE_DROPS "
                      f"({', '.join(PROFILE_DROPS)}) differ; give every kind its drop function")


def register_profile_kind(name: str, drop: Callable[..., np.ndarray], keys: tuple[str, ...] = ()) -> None:
    """Add a roller-profile kind from outside the package: the case accepts ``kind = name``
    (:data:`rvfem.case.definition.ROLLER_PROFILE_KINDS`) and its drop is ``drop`` (the signature of
    :data:`PROFILE_DROPS`), in one call, so the two lists stay one.

    Parameters
    ----------
    name : str
        The kind, as the case names it.
    drop : callable
        ``drop(profile, length_mm, |x|, *, composite_modulus_MPa, reduced_radius_mm) -> z``, mm.
    keys : tuple of str
        Keys of ``[crank_bearing.profile]`` that shape it: existing keys no other kind uses (a new
        key needs a field of :class:`rvfem.case.definition.RollerProfile`).

    Raises
    ------
    ValueError
        The kind exists, or a key is not a profile key or is another kind's.
    """
    if name in ROLLER_PROFILE_KINDS:
        raise ValueError(f"the roller-profile kind {name!r} exists already")
    fields = {f.name for f in dataclasses.fields(RollerProfile)}
    taken = {k for ks in ROLLER_PROFILE_KINDS.values() for k in ks}
    bad = [k for k in keys if k not in fields or k in taken]
    if bad:
        raise ValueError(f"roller-profile kind {name!r}: {', '.join(bad)} must be keys of [crank_bearing.profile] "
                         "that no other kind uses")
    ROLLER_PROFILE_KINDS[name] = tuple(keys)
    PROFILE_DROPS[name] = drop


def slice_centres(length_mm: float, slices: int) -> tuple[np.ndarray, np.ndarray]:
    """Slice centres x_j (mm, from the roller centre) and widths Δx (mm) of ``slices`` equal slices."""
    if slices < 1 or length_mm <= 0:
        raise ValueError("slice_centres needs a positive length and at least one slice")
    edges = np.linspace(-0.5 * length_mm, 0.5 * length_mm, slices + 1)
    return 0.5 * (edges[1:] + edges[:-1]), np.diff(edges)


END_CLUSTER_FRACTION = 0.5
"""Share of the slices that :func:`slice_layout` gathers at the ends of the effective length (where a
rounded corner begins, or a sharp roller ends) and at the profile's junctions; the rest are spread
evenly."""

END_CLUSTER_LENGTH_MM = 0.002
"""λ of :func:`slice_layout`, mm: the slices are finest within about λ of an end or junction and
widen in proportion to the distance beyond it (a geometric grading)."""

JUNCTION_WEIGHT = 0.25
"""Weight of a junction inside the effective length (the combined profile's start of the modified
segment, a curvature jump of a smooth surface) against an end (1) in :func:`slice_layout`."""


def profile_junctions(profile, length_mm: float) -> tuple[tuple[float, float], ...]:
    """(position from the centre in mm, weight) of every place along the roller where the slices
    are refined: both ends of the effective length (weight 1) and the junctions of the profile's
    pieces inside it (the combined profile's ±(L/2 − a), weight :data:`JUNCTION_WEIGHT`)."""
    half = 0.5 * length_mm
    out = [(-half, 1.0), (half, 1.0)]
    if profile.kind == "combined" and profile.modification_drop > 0.0:
        a = profile.modification_length
        out += [(-(half - a), JUNCTION_WEIGHT), (half - a, JUNCTION_WEIGHT)]
    return tuple(out)


def slice_layout(profile, length_mm: float, slices: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Slice centres x_j (mm, from the roller centre) and widths Δx_j (mm) of a roller's slice model:
    the effective length and both rounded corners beyond it, slices refined at the ends and at the
    profile's junctions.

    The edges are equally spaced in the stretched coordinate s(x) = ∫ρ, with the slice density
    ρ(x) = 1 + A·Σ_k w_k/(1 + |x − x_k|/λ) (x_k, w_k: :func:`profile_junctions`; λ =
    :data:`END_CLUSTER_LENGTH_MM`); A puts :data:`END_CLUSTER_FRACTION` of the slices into the
    clusters. Near x_k the widths are about (s_tot/n)/(1 + A·w_k) and grow in proportion to the
    distance (a geometric grading); far from them they are s_tot/n. Doubling n halves every width.

    Parameters
    ----------
    profile : rvfem.case.definition.RollerProfile
        Its kind, corner (:func:`corner_extent`) and ``slices``.
    length_mm : float
        Effective roller length L, mm.
    slices : int, optional
        Number of slices n (default: ``profile.slices``).

    Returns
    -------
    x, dx : ndarray (n,)
        Centres and widths, mm; Σ Δx = L + 2c.
    """
    n = profile.slices if slices is None else int(slices)
    if n < 1 or length_mm <= 0:
        raise ValueError("slice_layout needs a positive length and at least one slice")
    end = 0.5 * length_mm + corner_extent(profile)
    lam = END_CLUSTER_LENGTH_MM
    junctions = profile_junctions(profile, length_mm)
    pos = np.array([j[0] for j in junctions])
    wts = np.array([j[1] for j in junctions])

    def kernel(x):                                     # Σ_k w_k·∫_{x_k}^{x} dt/(1 + |t − x_k|/λ)
        d = np.asarray(x, dtype=float)[..., None] - pos
        return np.sum(wts * np.sign(d) * lam * np.log1p(np.abs(d) / lam), axis=-1)

    span = 2.0 * end
    cluster = float(kernel(end) - kernel(-end))
    frac = END_CLUSTER_FRACTION
    amp = frac / (1.0 - frac) * span / cluster

    def stretched(x):
        return (x + end) + amp * (kernel(x) - kernel(-end))

    targets = np.linspace(0.0, float(stretched(end)), n + 1)
    lo = np.full(n + 1, -end)
    hi = np.full(n + 1, end)
    for _ in range(60):                                # bisection: s is increasing
        mid = 0.5 * (lo + hi)
        below = stretched(mid) < targets
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    edges = 0.5 * (lo + hi)
    edges[0], edges[-1] = -end, end
    edges = 0.5 * (edges - edges[::-1])               # exactly symmetric
    return 0.5 * (edges[1:] + edges[:-1]), np.diff(edges)


def _love(u, v):
    """Signed ∫₀^u ∫₀^v dx dy / √(x² + y²), the corner function of Love's rectangle solution:
    sgn(u)·sgn(v)·(|u|·asinh(|v|/|u|) + |v|·asinh(|u|/|v|)) (0 where u or v is 0)."""
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    au, av = np.abs(u), np.abs(v)
    with np.errstate(divide="ignore", invalid="ignore"):
        f1 = np.where(au > 0.0, au * np.arcsinh(av / np.where(au > 0.0, au, 1.0)), 0.0)
        f2 = np.where(av > 0.0, av * np.arcsinh(au / np.where(av > 0.0, av, 1.0)), 0.0)
    return np.sign(u) * np.sign(v) * (f1 + f2)


def rectangle_influence(x_mm, widths_mm, half_width_mm: float, composite_modulus_MPa: float,
                        y_mm=None, half_heights_mm=None) -> np.ndarray:
    """Displacement (both bodies) at the centres of rectangles per unit uniform pressure on each
    rectangle of a half-space, mm/MPa.

    C_ij = 1/(π·E*)·∫∫_rect j dA/r from the centre of rectangle i (Love's solution, Johnson,
    *Contact Mechanics*, eq. 3.25), evaluated with the corner function u·asinh(v/u) + v·asinh(u/v).

    Parameters
    ----------
    x_mm, widths_mm : array_like (n,)
        Centres and widths of the rectangles along x, mm.
    half_width_mm : float
        Half-height of every rectangle across (y), mm (the strip half-width b of the slice model).
    composite_modulus_MPa : float
        E*, MPa.
    y_mm, half_heights_mm : array_like (n,), optional
        Centres and half-heights across for a two-dimensional grid of rectangles (default: all at
        y = 0 with ``half_width_mm``).

    Returns
    -------
    ndarray (n, n)
    """
    x = np.asarray(x_mm, dtype=float)
    hw = 0.5 * np.asarray(widths_mm, dtype=float)
    y = np.zeros_like(x) if y_mm is None else np.asarray(y_mm, dtype=float)
    hh = np.full_like(x, half_width_mm) if half_heights_mm is None else np.asarray(half_heights_mm, dtype=float)
    if y_mm is None:            # all on one line: the corner function is odd in v, so the ±v terms are one
        n = x.size
        # a layout symmetric about its middle (the slices' is, exactly) gives C_(n−1−i)(n−1−j) = C_ij
        # (the rectangle's displacement is even in x_i − x_j): the first half of the rows is enough
        mirrored = (n % 2 == 0 and np.array_equal(x, -x[::-1]) and np.array_equal(hw, hw[::-1])
                    and np.array_equal(hh, hh[::-1]))
        rows = slice(0, n // 2) if mirrored else slice(None)
        dx = x[rows, None] - x[None, :]
        total = np.zeros(dx.shape)
        for sx in (-1.0, 1.0):
            total += 2.0 * sx * _love(dx + sx * hw[None, :], np.broadcast_to(hh[None, :], dx.shape))
        if mirrored:
            total = np.concatenate([total, total[::-1, ::-1]])
        return total / (math.pi * composite_modulus_MPa)
    dx = x[:, None] - x[None, :]
    dy = y[:, None] - y[None, :]
    total = np.zeros(dx.shape)
    for sx in (-1.0, 1.0):
        for sy in (-1.0, 1.0):
            total += sx * sy * _love(dx + sx * hw[None, :], dy + sy * hh[None, :])
    return total / (math.pi * composite_modulus_MPa)


def hertz_peak_from_line_load(line_load_N_per_mm, reduced_radius_mm: float, composite_modulus_MPa: float):
    """Hertz peak pressure (MPa) and half-width (mm) of a line load q (N/mm):
    p_h = √(q·E*/(π·R')), b = √(4·q·R'/(π·E*)) (Johnson, Contact Mechanics, §4.3)."""
    q = np.clip(np.asarray(line_load_N_per_mm, dtype=float), 0.0, None)
    return (np.sqrt(q * composite_modulus_MPa / (math.pi * reduced_radius_mm)),
            np.sqrt(4.0 * q * reduced_radius_mm / (math.pi * composite_modulus_MPa)))


def section_window(x_mm, widths_mm, half_width_mm: float, at_mm=None) -> np.ndarray:
    """Averaging matrix W (m, n) of slice line loads over a section's own contact width: (W·q)_i is
    the mean of the piecewise constant q over [a_i − b, a_i + b], zero beyond the roller's ends.

    A section of a line contact is in plane strain only over lengths of about its half-width b
    or more: the subsurface stresses under it (the principal shear at 0.786·b) and the contact
    width are set by the load over about ±b around it. The slice model's line loads resolve much
    shorter lengths at a roller's ends (slices of a few µm where a rounded corner begins); the
    Hertz peaks, the contact widths and the lamina loads are taken from W·q. Where a slice is
    wider than 2b, W·q at its centre is its own q.

    Parameters
    ----------
    x_mm, widths_mm : array_like (n,)
        Slice centres and widths, mm.
    half_width_mm : float
        b, mm.
    at_mm : array_like (m,), optional
        Where to evaluate (default: the slice centres).
    """
    x = np.asarray(x_mm, dtype=float)
    dx = np.asarray(widths_mm, dtype=float)
    a = x if at_mm is None else np.asarray(at_mm, dtype=float)
    lo, hi = x - 0.5 * dx, x + 0.5 * dx
    overlap = np.clip(np.minimum(hi[None, :], a[:, None] + half_width_mm)
                      - np.maximum(lo[None, :], a[:, None] - half_width_mm), 0.0, None)
    return overlap / (2.0 * half_width_mm)


def windowed_peak(x_mm, widths_mm, line_load_N_per_mm, half_width_mm: float) -> tuple[float, float]:
    """Largest section line load (W·q of :func:`section_window`) along the roller and where it is
    (N/mm, mm): W·q sampled every b/8 along the whole roller, so that the maximum does not depend
    on where the slice centres fall."""
    x = np.asarray(x_mm, dtype=float)
    dx = np.asarray(widths_mm, dtype=float)
    ends = x[0] - 0.5 * dx[0], x[-1] + 0.5 * dx[-1]
    at = np.linspace(ends[0], ends[1], int(math.ceil((ends[1] - ends[0]) / (0.125 * half_width_mm))) + 1)
    qw = section_window(x, dx, half_width_mm, at) @ np.asarray(line_load_N_per_mm, dtype=float)
    k = int(np.argmax(qw))
    return float(qw[k]), float(at[k])


def roller_contact(load_N: float, length_mm: float, reduced_radius_mm: float, composite_modulus_MPa: float,
                   profile, *, tilt_rad: float = 0.0, slices: int | None = None,
                   local_width_iterations: int = 8) -> SliceContact:
    """Slice model of one roller–raceway contact (see the module docstring).

    The rectangles start at the nominal Hertz half-width of Q/L; then, up to
    ``local_width_iterations`` times, each slice's rectangle takes the Hertz half-width of its own
    load per length (a crowned roller's contact narrows towards its ends) and the contact is solved
    again, until the slice loads change by less than 0.1 % of the largest.

    Parameters
    ----------
    load_N : float
        Roller load Q on this raceway, N (> 0).
    length_mm : float
        Effective roller length L, mm.
    reduced_radius_mm, composite_modulus_MPa : float
        R' of roller and raceway (mm) and E* (MPa).
    profile : rvfem.case.definition.RollerProfile
        Roller profile (its ``slices`` unless ``slices`` is given).
    tilt_rad : float
        Relative tilt ψ of roller and raceway, rad.
    slices : int, optional
        Number of slices.
    local_width_iterations : int
        0: every rectangle keeps the nominal half-width (as in the cycle, :func:`solve_slices` with
        one influence matrix).

    Returns
    -------
    SliceContact
    """
    x, dx = slice_layout(profile, length_mm, slices)
    n = x.size
    b_nom = hertz_half_width(load_N, length_mm, reduced_radius_mm, composite_modulus_MPa)
    drop = profile_drop(profile, length_mm, x, composite_modulus_MPa=composite_modulus_MPa,
                        reduced_radius_mm=reduced_radius_mm)
    g = (tilt_rad * x - drop)[None, :]
    widths = np.full(n, b_nom)
    window = section_window(x, dx, b_nom)
    q: np.ndarray | None = None
    for _ in range(local_width_iterations + 1):
        c = rectangle_influence(x, dx, b_nom, composite_modulus_MPa, half_heights_mm=widths)
        p, delta = solve_slices(c, 2.0 * widths * dx, g, np.array([load_N]))
        q_new = p[0] * 2.0 * widths
        converged = q is not None and np.max(np.abs(q_new - q)) < 1e-3 * np.max(q_new)
        q = q_new
        if converged:
            break
        _, b_local = hertz_peak_from_line_load(window @ q, reduced_radius_mm, composite_modulus_MPa)
        widths = np.maximum(b_local, 0.2 * b_nom)
    assert q is not None   # the loop runs at least once
    ph, b = hertz_peak_from_line_load(window @ q, reduced_radius_mm, composite_modulus_MPa)
    nominal, _ = hertz_peak_from_line_load(load_N / length_mm, reduced_radius_mm, composite_modulus_MPa)
    q_peak, x_peak = windowed_peak(x, dx, q, b_nom)
    ph_max, b_max = (float(v) for v in hertz_peak_from_line_load(q_peak, reduced_radius_mm, composite_modulus_MPa))
    return SliceContact(x_mm=x, line_load_N_per_mm=q, pressure_MPa=ph, half_width_mm=b,
                        approach_mm=float(delta[0]), peak_pressure_MPa=ph_max,
                        edge_factor=ph_max / float(nominal), max_shear_MPa=SHEAR_FACTOR * ph_max,
                        max_shear_depth_mm=SHEAR_DEPTH_FACTOR * b_max, peak_x_mm=x_peak, widths_mm=dx)
