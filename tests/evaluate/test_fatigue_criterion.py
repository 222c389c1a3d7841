"""Findley's critical-plane fatigue criterion (rvfem.evaluate.strength.findley) against closed
forms: the fully reversed torsion and bending limits it is calibrated on, a pulsating uniaxial
stress, proportional scaling, and the near-pure-shear history on which the signed von Mises stress
flips sign."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rvfem.evaluate import strength

SIGMA_W = 960.0
TAU_W = SIGMA_W / math.sqrt(3.0)
THETA = np.radians(np.arange(0.0, 360.0, 1.0))
ZERO = np.zeros_like(THETA)


def test_constants_by_hand():
    """q = 2/√3 − 1 = 0.154701; k = q/√(1 − q²) = 0.156586; f = τ_W·√(1 + k²)."""
    k, f = strength.findley_constants(SIGMA_W, TAU_W)
    q = 2.0 / math.sqrt(3.0) - 1.0
    assert k == pytest.approx(q / math.sqrt(1.0 - q * q), rel=1e-14)
    assert k == pytest.approx(0.156586, abs=1e-6)
    assert f == pytest.approx(TAU_W * math.sqrt(1.0 + k * k), rel=1e-14)
    # the same f from the bending side: (σ_W/2)(k + √(1 + k²))
    assert f == pytest.approx(0.5 * SIGMA_W * (k + math.sqrt(1.0 + k * k)), rel=1e-12)
    with pytest.raises(ValueError, match="τ_W"):
        strength.findley_constants(SIGMA_W, 0.4 * SIGMA_W)


@pytest.mark.parametrize("component", ["sxy"])
def test_fully_reversed_torsion_at_the_limit_is_one(component):
    """τ(θ) = τ_W sin θ (pure shear in the disc plane): S = 1; at half the amplitude S = 2."""
    r = strength.findley(ZERO, ZERO, TAU_W * np.sin(THETA), SIGMA_W)
    assert r.safety_factor == pytest.approx(1.0, abs=1e-6)
    assert strength.findley(ZERO, ZERO, 0.5 * TAU_W * np.sin(THETA), SIGMA_W).safety_factor == \
        pytest.approx(2.0, abs=2e-6)
    # pure shear as principal stresses ±τ along x and y is the same state turned by 45°
    r2 = strength.findley(TAU_W * np.sin(THETA), -TAU_W * np.sin(THETA), ZERO, SIGMA_W)
    assert r2.safety_factor == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("direction", ["x", "y", "45"])
def test_fully_reversed_uniaxial_at_the_limit_is_one(direction):
    """σ(θ) = σ_W sin θ along x, y or at 45° in the plane: S = 1."""
    s = SIGMA_W * np.sin(THETA)
    comps = {"x": (s, ZERO, ZERO), "y": (ZERO, s, ZERO), "45": (0.5 * s, 0.5 * s, 0.5 * s)}[direction]
    assert strength.findley(*comps, SIGMA_W).safety_factor == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("sigma", [200.0, 500.0])
def test_pulsating_uniaxial_by_hand(sigma):
    """σ(θ) = σ(1 + sin θ) (R = 0): on the plane at α to the load τ_a = (σ/2)·sin 2α and
    σ_n,max = σ(1 + cos 2α), so F = σ·max_α[(1/2)sin 2α + k(1 + cos 2α)] = σ(k + √(1/4 + k²))."""
    k, f = strength.findley_constants(SIGMA_W, TAU_W)
    r = strength.findley(sigma * (1.0 + np.sin(THETA)), ZERO, ZERO, SIGMA_W)
    assert r.safety_factor == pytest.approx(f / (sigma * (k + math.sqrt(0.25 + k * k))), rel=1e-6)


def test_static_compression_is_safe_and_scaling_is_proportional():
    """A constant compressive stress alternates nothing and puts every plane in compression: S = inf.
    A random history scaled by s has its factor divided by s."""
    assert strength.findley(-100.0 + ZERO, -50.0 + ZERO, ZERO, SIGMA_W).safety_factor == math.inf
    rng = np.random.default_rng(3)
    a = rng.normal(20.0, 60.0, (90, 3))
    r1 = strength.findley(*a.T, SIGMA_W)
    r2 = strength.findley(*(2.5 * a).T, SIGMA_W)
    assert r2.safety_factor == pytest.approx(r1.safety_factor / 2.5, rel=1e-6)


def test_near_pure_shear_does_not_flip():
    """τ(θ) = 300 sin θ with a normal stress of 1 MPa at twice the frequency: the first invariant
    changes sign within the cycle, so the signed von Mises stress jumps between ±√3·τ and its
    amplitude and mean are those of a different history; Findley's factor stays within 0.01 % of
    the pure-shear value f/(300·√(1 + k²))."""
    k, f = strength.findley_constants(SIGMA_W, TAU_W)
    tau, eps = 300.0 * np.sin(THETA), 1.0 * np.sin(2.0 * THETA)
    r = strength.findley(eps, ZERO, tau, SIGMA_W)
    assert r.safety_factor == pytest.approx(f / (300.0 * math.sqrt(1.0 + k * k)), rel=1e-4)
    s1 = 0.5 * eps + np.hypot(0.5 * eps, tau)
    s2 = 0.5 * eps - np.hypot(0.5 * eps, tau)
    sv = strength.signed_von_mises(s1, s2)
    assert np.count_nonzero(np.diff(np.sign(sv))) >= 2          # the signed stress flips
