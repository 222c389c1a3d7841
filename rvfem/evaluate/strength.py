"""Strength of the disc: a static safety factor against yield and a fatigue safety factor at
each hot spot from its stress history over the load cycle.

Static
    S_static = R_p0.2 / σ_vM,max at the structural peak (P2, away from the contact bands; the
    contact-zone peak is mesh-dependent and a matter of the bearing and the pin contact).

Fatigue: the FKM guideline's signed von Mises approach on a Goodman (Haigh) diagram
    At a hot spot the in-plane principal stresses σ1(θ), σ2(θ) over the crank angle θ give the
    signed von Mises stress (FKM guideline "Analytical strength assessment of components", 6th
    ed. 2012, the equivalent stress for proportional multiaxial stress states:
    the von Mises stress with the sign of the first stress invariant)

        σ_sv(θ) = sign(σ1 + σ2) · sqrt(σ1² − σ1 σ2 + σ2²)                       (plane stress)

    and its amplitude and mean over the cycle, σ_a = (max − min)/2, σ_m = (max + min)/2. The
    Goodman line of the Haigh diagram joins the fully reversed fatigue limit σ_W (σ_m = 0) to the
    tensile strength R_m (σ_a = 0); the safety factor is the factor by which the stresses may grow
    proportionally (a ray from the origin of the diagram) before the point reaches the line:

        S_fatigue = 1 / (σ_a/σ_W + σ_m/R_m)        for σ_m ≥ 0
        S_fatigue = σ_W / σ_a                      for σ_m < 0 (no credit for a compressive mean,
                                                   the conservative horizontal branch)

    Under uniaxial stress σ_sv = σ, so S_fatigue is the textbook Goodman safety factor
    (Shigley's Mechanical Engineering Design, 10th ed., eq. 6-41: 1/n = σ_a/S_e + σ_m/S_ut). A
    proportional load scaling by s scales σ_a and σ_m by s and S_fatigue by 1/s.

The material data are the case's ``[material]`` (yield_strength, ultimate_strength,
fatigue_limit); σ_W is the material's polished-specimen limit: surface, size and notch-support
factors are not applied (docs/theory.md, "Mass and strength").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, overload

import numpy as np

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
]

FATIGUE_CRITERION = "FKM signed von Mises, Goodman line (σ_W, R_m)"
"""Name of the fatigue criterion, for outputs."""


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
    safety_factor : float
        :func:`goodman_safety_factor`.
    p2_factor : float
        The P2/P1 factor applied (1 where not re-solved).
    """

    name: str
    peak: PeakStress
    amplitude_MPa: float
    mean_MPa: float
    max_MPa: float
    min_MPa: float
    safety_factor: float
    p2_factor: float


def hot_spot_fatigue(history: HotSpotHistory, material: Material) -> tuple[HotSpotFatigue, ...]:
    """The fatigue check of every hot spot of a :class:`rvfem.evaluate.postprocess.HotSpotHistory`
    with the strength of ``material`` (:class:`rvfem.case.definition.Material`)."""
    out = []
    for j, name in enumerate(history.names):
        f = float(history.p2_factor[j])
        sv = signed_von_mises(f * history.s1[:, j], f * history.s2[:, j])
        a, m = amplitude_mean(sv)
        out.append(HotSpotFatigue(
            name=name, peak=history.peaks[j], amplitude_MPa=float(a), mean_MPa=float(m),
            max_MPa=float(np.max(sv)), min_MPa=float(np.min(sv)),
            safety_factor=goodman_safety_factor(float(a), float(m), material.fatigue_limit,
                                                material.ultimate_strength),
            p2_factor=f))
    return tuple(out)


def fatigue_field(sv_max: np.ndarray, sv_min: np.ndarray, material: Material) -> np.ndarray:
    """Fatigue safety factor of every vertex from the largest and smallest signed von Mises
    stress over the cycle (P1 vertex stresses), capped at 1e3 for plotting."""
    a, m = 0.5 * (sv_max - sv_min), 0.5 * (sv_max + sv_min)
    s = goodman_safety_factor(a, m, material.fatigue_limit, material.ultimate_strength)
    return np.minimum(np.asarray(s, dtype=float), 1.0e3)
