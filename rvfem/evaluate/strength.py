"""Strength of the disc: a static safety factor against yield and a fatigue safety factor at
the structural hot spot from its stress-tensor history over the load cycle.

Static
    S_static = R_p0.2 / σ_vM,max at the structural peak (P2, away from the contact bands; the
    contact-zone peak is mesh-dependent and a matter of the bearing and the pin contact).

Fatigue: Findley's critical-plane criterion
    On every material plane (unit normal n) the shear stress vector τ(θ) traced over the crank
    angle θ has an amplitude τ_a (half the longest chord of its path: for a proportional history
    the usual (max − min)/2) and the plane's normal stress has a largest value σ_n,max. Findley's
    parameter is the largest over the planes of

        F = τ_a + k·σ_n,max                                                     (1)

    and the fatigue limit is reached where F = f (W. N. Findley, "A theory for the effect of mean
    stress on fatigue of metals under combined torsion and axial load or bending", Journal of
    Engineering for Industry 81 (1959) 301–306; D. F. Socie, G. B. Marquis, *Multiaxial Fatigue*,
    SAE 2000, ch. 4). The two constants follow from the fully reversed fatigue limits in bending
    σ_W and in torsion τ_W: under torsion the critical plane gives F = τ_W·√(1 + k²), under
    reversed uniaxial stress F = (σ_W/2)(k + √(1 + k²)), so with q = 2τ_W/σ_W − 1

        k = q/√(1 − q²),   f = τ_W·√(1 + k²)                                    (2)

    τ_W = f_W,τ·σ_W with the FKM guideline's shear fatigue-strength factor for steel
    f_W,τ = 0.577 (= 1/√3; FKM guideline "Analytical strength assessment of components", 6th ed.
    2012, the material table of chapter 2/4): k = 0.157, f = 0.585·σ_W; for σ_W = 960 MPa (the
    default 100Cr6) τ_W = 554 MPa, f = 561 MPa. The parameter scales with a proportional load
    factor, so the safety factor is S = f / F. Planes are searched over the hemisphere of normals
    (σ_zz = 0: the planes tilted out of the disc plane count), on a 6° grid refined six times
    around its best plane (7 × 7 planes, each grid three times finer); only the vertices of the convex hull of the stress history enter (the amplitude and
    σ_n,max are linear functionals of the stress, so their extremes over the cycle lie there).

    Unlike the FKM signed von Mises stress, F does not change sign near pure shear (the sign of
    σ1 + σ2 flips while the stress hardly changes). It is a high-cycle criterion: a large static
    stress is the static check's business. The former criterion — the signed von Mises stress on
    a Goodman line of σ_W and R_m (FKM guideline, proportional multiaxial stress) — is kept for
    comparison and for the envelope's fatigue field (:func:`fatigue_field`)::

        σ_sv(θ) = sign(σ1 + σ2) · sqrt(σ1² − σ1 σ2 + σ2²)
        S_Goodman = 1 / (σ_a/σ_W + σ_m/R_m)   (σ_m ≥ 0),   σ_W/σ_a   (σ_m < 0)

    (Shigley's Mechanical Engineering Design, 10th ed., eq. 6-41).

Which hot spot is assessed
    The structural hot spot (the P2 structural peak's vertex, away from the contacts; its P1
    history times the P2/P1 factor there). The contact zones are assessed as what they are: the
    bore is the crank bearing's outer raceway (its rolling-contact fatigue is in the lamina life
    L10r), the flank is a Hertz contact (:mod:`rvfem.evaluate.pin_flank`, the contact pressure
    over the cycle against a contact-fatigue allowable). The contact-zone vertex stress under a
    footprint is mesh-dependent and gets no fatigue factor.

The material data are the case's ``[material]`` (yield_strength, ultimate_strength,
fatigue_limit); σ_W is the material's polished-specimen limit: surface, size and notch-support
factors are not applied (docs/theory.md, "Mass and strength").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, overload

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from rvfem.case.definition import Material

if TYPE_CHECKING:   # for the annotations only: postprocess is a heavier module of the same layer
    from rvfem.evaluate.postprocess import HotSpotHistory, PeakStress

__all__ = [
    "signed_von_mises",
    "amplitude_mean",
    "goodman_safety_factor",
    "static_safety_factor",
    "HotSpotFatigue",
    "hot_spot_fatigue",
    "fatigue_field",
    "FATIGUE_CRITERION",
    "GOODMAN_CRITERION",
    "SHEAR_FATIGUE_FACTOR",
    "findley_constants",
    "FindleyResult",
    "findley",
    "ASSESSED_AS",
]

FATIGUE_CRITERION = "Findley critical plane, k and f from σ_W and τ_W = 0.577·σ_W"
"""Name of the fatigue criterion, for outputs."""

GOODMAN_CRITERION = "FKM signed von Mises, Goodman line (σ_W, R_m)"
"""Name of the former criterion (kept for comparison and the envelope's fatigue field)."""

SHEAR_FATIGUE_FACTOR = 1.0 / math.sqrt(3.0)
"""f_W,τ = τ_W/σ_W of steel, 0.577 (FKM guideline, 6th ed. 2012; the von Mises ratio)."""

ASSESSED_AS = {
    "bore": "the crank bearing's outer raceway: its rolling-contact fatigue is in the lamina life L10r "
            "(crank_bearing_depth), no fatigue factor here",
    "profile": "the pin–flank Hertz contact: contact pressure against the contact-fatigue allowable (pin_flank)",
}
"""How a contact-zone hot spot is assessed instead of a fatigue factor, by the kind of its feature."""


def signed_von_mises(s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
    """σ_sv = sign(σ1 + σ2)·sqrt(σ1² − σ1σ2 + σ2²) of plane stress (FKM guideline), MPa.
    A zero first invariant counts as positive."""
    s1, s2 = np.asarray(s1, dtype=float), np.asarray(s2, dtype=float)
    vm = np.sqrt(np.maximum(s1 * s1 - s1 * s2 + s2 * s2, 0.0))
    return np.where(s1 + s2 >= 0.0, vm, -vm)


def amplitude_mean(history: np.ndarray, axis: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Amplitude (max − min)/2 and mean (max + min)/2 of a stress history along ``axis``, MPa."""
    h = np.asarray(history, dtype=float)
    hi, lo = np.max(h, axis=axis), np.min(h, axis=axis)
    return 0.5 * (hi - lo), 0.5 * (hi + lo)


@overload
def goodman_safety_factor(amplitude: float, mean: float, fatigue_limit: float,
                          ultimate_strength: float) -> float: ...
@overload
def goodman_safety_factor(amplitude: np.ndarray, mean: np.ndarray, fatigue_limit: float,
                          ultimate_strength: float) -> np.ndarray: ...
def goodman_safety_factor(amplitude: np.ndarray | float, mean: np.ndarray | float, fatigue_limit: float,
                          ultimate_strength: float) -> np.ndarray | float:
    """Fatigue safety factor on the Goodman line (module docstring): 1/(σ_a/σ_W + σ_m/R_m) for
    σ_m ≥ 0, σ_W/σ_a for σ_m < 0; inf where nothing alternates and the mean is not tensile.

    Parameters
    ----------
    amplitude, mean : float or ndarray
        σ_a ≥ 0 and σ_m, MPa.
    fatigue_limit, ultimate_strength : float
        σ_W and R_m, MPa.
    """
    a = np.asarray(amplitude, dtype=float)
    m = np.asarray(mean, dtype=float)
    load = a / fatigue_limit + np.maximum(m, 0.0) / ultimate_strength
    with np.errstate(divide="ignore"):
        s = np.where(load > 0.0, 1.0 / np.where(load > 0.0, load, 1.0), np.inf)
    return float(s) if s.ndim == 0 else s


def findley_constants(fatigue_limit: float, shear_fatigue_limit: float) -> tuple[float, float]:
    """Findley's k and f (MPa) from the fully reversed limits σ_W and τ_W (module docstring, eq. 2).

    Raises
    ------
    ValueError
        Unless σ_W/2 < τ_W < σ_W (k would be zero, negative or undefined).
    """
    q = 2.0 * shear_fatigue_limit / fatigue_limit - 1.0
    if not 0.0 < q < 1.0:
        raise ValueError(f"Findley's constants need σ_W/2 < τ_W < σ_W, got τ_W/σ_W = "
                         f"{shear_fatigue_limit / fatigue_limit:.4g}")
    k = q / math.sqrt(1.0 - q * q)
    return k, shear_fatigue_limit * math.sqrt(1.0 + k * k)


@dataclass(frozen=True)
class FindleyResult:
    """Findley's criterion at one point.

    Attributes
    ----------
    safety_factor : float
        f/F (inf where nothing alternates and no plane is in tension).
    parameter_MPa : float
        F = τ_a + k·σ_n,max on the critical plane, MPa.
    shear_amplitude_MPa, normal_max_MPa : float
        τ_a and σ_n,max on the critical plane, MPa.
    normal : tuple of float
        Unit normal of the critical plane (x, y, z; z the disc axis).
    k, f_MPa : float
        The constants.
    """

    safety_factor: float
    parameter_MPa: float
    shear_amplitude_MPa: float
    normal_max_MPa: float
    normal: tuple[float, float, float]
    k: float
    f_MPa: float


def _hull_vertices(points: np.ndarray) -> np.ndarray:
    """The vertices of the convex hull of stress points (n, 3), in the affine hull of the points:
    a flat (biaxial-proportional) history gives its 2D hull, a proportional one its two ends."""
    centre = points.mean(axis=0)
    _, sv, vt = np.linalg.svd(points - centre, full_matrices=False)
    rank = int(np.count_nonzero(sv > 1e-9 * max(float(sv[0]), 1e-300))) if sv.size else 0
    if rank == 0:
        return points[:1]
    coords = (points - centre) @ vt[:rank].T
    if rank == 1:
        return points[[int(np.argmin(coords[:, 0])), int(np.argmax(coords[:, 0]))]]
    try:
        return points[ConvexHull(coords).vertices]
    except (QhullError, ValueError):   # nearly degenerate: all points are still exact
        return points


def _planes(psi: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Normals n and two in-plane unit vectors a, b of the planes (ψ from the disc axis, φ in the
    disc plane); each (m, 3)."""
    P, F = np.meshgrid(psi, phi, indexing="ij")
    P, F = P.ravel(), F.ravel()
    sp, cp, sf, cf = np.sin(P), np.cos(P), np.sin(F), np.cos(F)
    n = np.stack([sp * cf, sp * sf, cp], axis=1)
    a = np.stack([-sf, cf, np.zeros_like(sf)], axis=1)
    b = np.stack([-cp * cf, -cp * sf, sp], axis=1)
    return n, a, b


_COARSE_DIRECTIONS = np.linspace(0.0, math.pi, 36, endpoint=False)
"""Directions within a plane on which the coarse plane grid measures the shear path's width (5°:
the largest width is the longest chord to within 1 − cos 2.5° = 10⁻³; it only locates the plane)."""


def _findley_planes(v: np.ndarray, n: np.ndarray, a: np.ndarray, b: np.ndarray,
                    k: float, exact: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """F, τ_a, σ_n,max of every plane for the hull vertices v (m_v, 3: σxx, σyy, τxy); τ_a exactly
    (the longest chord over pairs of vertices) or, with ``exact=False``, as the largest width of
    the shear path over :data:`_COARSE_DIRECTIONS` (for the coarse grid)."""
    def traction_dot(u: np.ndarray, w: np.ndarray) -> np.ndarray:   # u·σ·w for plane stress, (planes, m_v)
        c = np.stack([u[:, 0] * w[:, 0], u[:, 1] * w[:, 1], u[:, 0] * w[:, 1] + u[:, 1] * w[:, 0]], axis=1)
        return c @ v.T
    sn = traction_dot(n, n)
    ta, tb = traction_dot(n, a), traction_dot(n, b)
    if exact:   # half the longest chord of the shear path (its diameter), over pairs of hull vertices
        da = ta[:, :, None] - ta[:, None, :]
        db = tb[:, :, None] - tb[:, None, :]
        amp = 0.5 * np.sqrt(np.max(da * da + db * db, axis=(1, 2)))
    else:       # half the largest width over a fan of directions
        proj = (ta[:, None, :] * np.cos(_COARSE_DIRECTIONS)[None, :, None]
                + tb[:, None, :] * np.sin(_COARSE_DIRECTIONS)[None, :, None])
        amp = 0.5 * np.max(proj.max(axis=2) - proj.min(axis=2), axis=1)
    smax = np.max(sn, axis=1)
    return amp + k * smax, amp, smax


def findley(sxx: np.ndarray, syy: np.ndarray, sxy: np.ndarray, fatigue_limit: float,
            shear_fatigue_limit: float | None = None) -> FindleyResult:
    """Findley's critical-plane safety factor of a plane-stress history (module docstring).

    Parameters
    ----------
    sxx, syy, sxy : ndarray (n,)
        The stress components over the cycle, MPa (σ_zz = τ_xz = τ_yz = 0).
    fatigue_limit : float
        σ_W, MPa.
    shear_fatigue_limit : float, optional
        τ_W, MPa; default :data:`SHEAR_FATIGUE_FACTOR`·σ_W.

    Returns
    -------
    FindleyResult
    """
    tau_w = SHEAR_FATIGUE_FACTOR * fatigue_limit if shear_fatigue_limit is None else shear_fatigue_limit
    k, f = findley_constants(fatigue_limit, tau_w)
    pts = np.stack([np.ravel(sxx), np.ravel(syy), np.ravel(sxy)], axis=1).astype(float)
    v = _hull_vertices(pts)
    step = math.radians(6.0)
    psi = np.linspace(0.0, 0.5 * math.pi, 16)
    phi = np.arange(0.0, math.pi, step)
    best: tuple[float, float, float, tuple[float, float, float]] | None = None
    for stage in range(7):   # a 6° grid, then six grids of 7 × 7 planes around its best plane, each 3× finer
        n, a, b = _planes(psi, phi)
        F, amp, smax = _findley_planes(v, n, a, b, k, exact=stage > 0)
        j = int(np.argmax(F))
        if stage == 0:   # the coarse grid only locates the plane (its widths are a hair short)
            n, a, b = n[j:j + 1], a[j:j + 1], b[j:j + 1]
            F, amp, smax = _findley_planes(v, n, a, b, k)
            j = 0
        if best is None or F[j] > best[0]:
            best = (float(F[j]), float(amp[j]), float(smax[j]), (float(n[j, 0]), float(n[j, 1]), float(n[j, 2])))
        p0, f0 = math.acos(min(1.0, abs(best[3][2]))), math.atan2(best[3][1], best[3][0])
        psi = np.clip(p0 + np.linspace(-step, step, 7), 0.0, 0.5 * math.pi)
        phi = f0 + np.linspace(-step, step, 7)
        step /= 3.0
    assert best is not None
    F_max, amp_max, smax_max, normal = best
    safety = math.inf if F_max <= 0.0 else f / F_max
    return FindleyResult(safety_factor=safety, parameter_MPa=F_max, shear_amplitude_MPa=amp_max,
                         normal_max_MPa=smax_max, normal=normal, k=k, f_MPa=f)


def static_safety_factor(von_mises_MPa: float | None, yield_strength: float) -> float | None:
    """R_p0.2/σ_vM (inf for no stress, None for no value)."""
    if von_mises_MPa is None or not math.isfinite(von_mises_MPa):
        return None
    return math.inf if von_mises_MPa <= 0 else float(yield_strength / von_mises_MPa)


@dataclass(frozen=True)
class HotSpotFatigue:
    """The fatigue check of one hot spot.

    Attributes
    ----------
    name : str
        The hot spot (``structural``, ``contact_zone``).
    peak : rvfem.evaluate.postprocess.PeakStress
        Where it is.
    amplitude_MPa, mean_MPa : float
        σ_a and σ_m of the signed von Mises stress over the cycle (the P1 history scaled by the
        hot spot's P2/P1 factor).
    max_MPa, min_MPa : float
        Largest and smallest signed von Mises stress, MPa.
    safety_factor : float or None
        Findley's safety factor (:func:`findley`) of the structural hot spot; None for a contact
        zone, assessed as ``assessed_as`` says.
    p2_factor : float
        The P2/P1 factor applied (1 where not re-solved).
    goodman_safety_factor : float
        The former criterion's factor (:func:`goodman_safety_factor` of the signed von Mises
        stress), for comparison.
    findley : FindleyResult or None
        The critical plane (structural hot spot only).
    assessed_as : str or None
        How a contact-zone hot spot is assessed instead (:data:`ASSESSED_AS`).
    """

    name: str
    peak: PeakStress
    amplitude_MPa: float
    mean_MPa: float
    max_MPa: float
    min_MPa: float
    safety_factor: float | None
    p2_factor: float
    goodman_safety_factor: float = math.nan
    findley: FindleyResult | None = None
    assessed_as: str | None = None


def _assessed_as(peak: PeakStress) -> str:
    stem = (peak.feature or "").rpartition("_")[0] or (peak.feature or "")
    return ASSESSED_AS.get(stem, "a vertex stress under a load footprint (mesh-dependent): no fatigue factor")


def hot_spot_fatigue(history: HotSpotHistory, material: Material) -> tuple[HotSpotFatigue, ...]:
    """The fatigue check of every hot spot of a :class:`rvfem.evaluate.postprocess.HotSpotHistory`
    with the strength of ``material`` (:class:`rvfem.case.definition.Material`): Findley's factor
    at the structural hot spot from its stress-tensor history (times its P2/P1 factor), the
    contact zone named for what it is (module docstring)."""
    out = []
    for j, name in enumerate(history.names):
        f = float(history.p2_factor[j])
        sv = signed_von_mises(f * history.s1[:, j], f * history.s2[:, j])
        a, m = amplitude_mean(sv)
        goodman = goodman_safety_factor(float(a), float(m), material.fatigue_limit, material.ultimate_strength)
        fin, safety, assessed = None, None, None
        if name == "contact_zone":
            assessed = _assessed_as(history.peaks[j])
        elif all(getattr(history, c, None) is not None for c in ("sxx", "syy", "sxy")):
            sxx, syy, sxy = (np.asarray(getattr(history, c)) for c in ("sxx", "syy", "sxy"))
            fin = findley(f * sxx[:, j], f * syy[:, j], f * sxy[:, j], material.fatigue_limit)
            safety = fin.safety_factor
        out.append(HotSpotFatigue(
            name=name, peak=history.peaks[j], amplitude_MPa=float(a), mean_MPa=float(m),
            max_MPa=float(np.max(sv)), min_MPa=float(np.min(sv)), safety_factor=safety, p2_factor=f,
            goodman_safety_factor=goodman, findley=fin, assessed_as=assessed))
    return tuple(out)


def fatigue_field(sv_max: np.ndarray, sv_min: np.ndarray, material: Material) -> np.ndarray:
    """Fatigue safety factor of every vertex from the largest and smallest signed von Mises
    stress over the cycle (P1 vertex stresses), capped at 1e3 for plotting."""
    a, m = 0.5 * (sv_max - sv_min), 0.5 * (sv_max + sv_min)
    s = goodman_safety_factor(a, m, material.fatigue_limit, material.ultimate_strength)
    return np.minimum(np.asarray(s, dtype=float), 1.0e3)
