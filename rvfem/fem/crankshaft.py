"""Crankshafts as beams: the influence coefficients between the eccentrics of one crankshaft.

Every crankshaft of a two-disc RV reducer is a beam on two support bearings in the carrier's end
plates carrying both discs' eccentrics. The eccentric of crank i under disc k moves by
w_k,i = −Σ_k' f_kk' · F_k',i (F the bearing force on disc k', so −F acts on the eccentric), the
same 2×2 influence matrix f (mm/N) in x and y (a round shaft on radially isotropic bearings). The
solve of the reducer stage (:mod:`rvfem.solve.cycle`) takes f as it is; this module only computes it.

**Crankshaft influence coefficients** (:func:`beam_influence`): a beam of span L between two elastic
supports with compliances c₁, c₂ (support bearing plus carrier in series), loaded at the eccentric
positions z_k. Bending (Roark's *Formulas for Stress and Strain*, simply supported beam with an
intermediate point load), shear (Timoshenko beam, shear coefficient κ = 6(1 + ν)/(7 + 6ν) of a
solid circular section after Cowper) and the rigid-body motion of the beam on its supports add up.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["beam_influence", "crankshaft_beam", "crankshaft_influence"]


def beam_influence(span: float, positions, bending_stiffness: float, shear_stiffness: float | None = None,
                   support_compliance: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """Influence matrix of a beam on two elastic supports: deflection at z_i per unit load at z_j.

    Parameters
    ----------
    span : float
        L, distance between the two supports, mm.
    positions : sequence of float
        Load positions z measured from support 1, each in (0, L), mm.
    bending_stiffness : float
        EI, N·mm² (``inf`` for a rigid shaft).
    shear_stiffness : float, optional
        κ·G·A, N (None or ``inf``: no shear deflection).
    support_compliance : (float, float)
        Radial compliance of support 1 and support 2, mm/N (0: rigid).

    Returns
    -------
    ndarray (n, n)
        f_ij, mm/N, symmetric (Maxwell–Betti).

    Notes
    -----
    For a unit load at b (from support 1) and a point x ≤ b, with L the span:

    * bending, simply supported (Roark's *Formulas for Stress and Strain*, beam table, simple
      supports, intermediate load): y = (L − b)·x·(L² − (L − b)² − x²) / (6·L·EI); for x ≥ b the
      mirror image (x → L − x, b → L − b). At mid-span for a central load this is L³/(48·EI).
    * shear (Timoshenko): y = (L − b)·x / (L·κGA) for x ≤ b and b·(L − x) / (L·κGA) for x ≥ b
      (L/(4·κGA) at the centre for a central load).
    * supports: the reactions R₁ = (L − b)/L, R₂ = b/L deflect the supports by c₁R₁ and c₂R₂, and
      the beam follows the line between them: y = c₁R₁·(L − x)/L + c₂R₂·x/L.
    """
    L = float(span)
    z = np.asarray(positions, dtype=float)
    if not (L > 0 and np.all((z > 0) & (z < L))):
        raise ValueError("the load positions must lie strictly between the supports")
    c1, c2 = (float(c) for c in support_compliance)
    x = z[:, None]
    b = z[None, :]
    lo = np.minimum(x, b)                      # the point nearer support 1 ...
    hi = np.maximum(x, b)                      # ... and the one nearer support 2
    f = np.zeros((len(z), len(z)))
    if np.isfinite(bending_stiffness):
        f += (L - hi) * lo * (L * L - (L - hi) ** 2 - lo * lo) / (6.0 * L * bending_stiffness)
    if shear_stiffness is not None and np.isfinite(shear_stiffness):
        f += (L - hi) * lo / (L * shear_stiffness)
    f += c1 * (L - x) * (L - b) / L**2 + c2 * x * b / L**2
    return f


def crankshaft_beam(cs) -> tuple[float, float | None, tuple[float, float]]:
    """The beam of a ``[crank_support]`` table: bending stiffness EI (N·mm²) from
    ``bending_stiffness_Nmm2`` or from ``journal_diameter`` (E·π·d⁴/64), shear stiffness κGA (N;
    G = E/(2(1 + ν)), A = π·d²/4, κ = 6(1 + ν)/(7 + 6ν)) when ``shear`` is on and the journal is
    given (else None), and the compliance 1/k_support + 1/k_carrier of each support (mm/N)."""
    E, nu = cs.youngs_modulus, cs.poissons_ratio
    shear = None
    if cs.bending_stiffness_Nmm2 is not None:
        EI = float(cs.bending_stiffness_Nmm2)
    else:
        d = cs.journal_diameter
        EI = E * math.pi * d**4 / 64.0
        if cs.shear:
            kappa = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)
            shear = kappa * E / (2.0 * (1.0 + nu)) * math.pi * d * d / 4.0
    ks = cs.support_stiffness_pair
    kc = cs.carrier_stiffness_pair
    c1, c2 = ((1.0 / ks[i] if ks[i] else 0.0) + (1.0 / kc[i] if kc[i] else 0.0) for i in range(2))
    return EI, shear, (c1, c2)


def crankshaft_influence(case) -> np.ndarray | None:
    """The crankshaft influence matrix of a case (mm/N, one row per disc), None for rigid support.

    From ``[crank_support]``: the direct ``influence_mm_per_N``, or a beam of ``span`` with the
    eccentrics at ``eccentric_positions``, EI from ``bending_stiffness_Nmm2`` or from
    ``journal_diameter`` (EI = E·π·d⁴/64; shear κGA with G = E/(2(1 + ν)), A = π·d²/4 and
    κ = 6(1 + ν)/(7 + 6ν) when ``shear`` is on), on supports of compliance
    1/k_support + 1/k_carrier per side.
    """
    cs = case.crank_support
    if cs is None:
        return None
    if cs.influence_mm_per_N is not None:
        return np.asarray(cs.influence_mm_per_N, dtype=float)
    EI, shear, compliance = crankshaft_beam(cs)
    return beam_influence(cs.span, cs.eccentric_positions, EI, shear, compliance)
