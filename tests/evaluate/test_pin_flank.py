"""The pin–flank Hertz contact (rvfem.evaluate.pin_flank) against closed forms: a pin on a convex
and on a concave flank, and the roller–raceway formulas of rvfem.evaluate.hertz for the same two
cylinders."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rvfem.evaluate import hertz, pin_flank

E_STAR = 206000.0 / (2.0 * (1.0 - 0.3 ** 2))     # steel on steel, plane strain: 113 187 MPa


@pytest.mark.parametrize("rho, convex", [(10.0, True), (2.0, True), (10.0, False), (40.0, False)])
def test_pin_on_flank_by_hand(rho, convex):
    """Q = 1000 N, L = 9 mm, r = 3 mm: 1/R' = 1/r ± 1/ρ, p_H = √(Q·E*/(π·L·R')),
    b = √(4QR'/(π·L·E*)), and p_H = 2Q/(π·L·b)."""
    q, L, r = 1000.0, 9.0, 3.0
    kappa = 1.0 / rho if convex else -1.0 / rho
    p, b, rr = pin_flank.pin_flank_pressure(q, L, r, kappa, E_STAR)
    r_rel = r * rho / (rho + r) if convex else r * rho / (rho - r)
    assert float(rr) == pytest.approx(r_rel, rel=1e-14)
    assert float(p) == pytest.approx(math.sqrt(q * E_STAR / (math.pi * L * r_rel)), rel=1e-14)
    assert float(b) == pytest.approx(math.sqrt(4 * q * r_rel / (math.pi * L * E_STAR)), rel=1e-14)
    assert float(p) == pytest.approx(2 * q / (math.pi * L * float(b)), rel=1e-12)
    # the same two cylinders as a roller on a convex (inner) or concave (outer) raceway
    c = hertz.hertz_line_contact(q, L, r, rho, concave=not convex)
    assert float(p) == pytest.approx(c.peak_pressure_MPa, rel=1e-12)
    assert float(b) == pytest.approx(c.half_width_mm, rel=1e-12)


def test_hand_number_and_guards():
    """Q = 730 N on a 9 mm wide flank of ρ = 1.6335 mm (convex) under a 3 mm pin, E* of steel:
    R' = 1.0576 mm, p_H = √(730·113187/(π·9·1.0576)) = 1662 MPa; no load, no pressure; a concave
    flank tighter than the pin has no Hertz contact (NaN)."""
    p, _, rr = pin_flank.pin_flank_pressure(730.06, 9.0, 3.0, 1.0 / 1.6335416, E_STAR)
    assert float(rr) == pytest.approx(1.05764, rel=1e-4)
    assert float(p) == pytest.approx(1662.3, rel=1e-4)
    assert float(pin_flank.pin_flank_pressure(0.0, 9.0, 3.0, 0.1, E_STAR)[0]) == 0.0
    assert np.isnan(pin_flank.pin_flank_pressure(100.0, 9.0, 3.0, -1.0 / 2.0, E_STAR)[0])


def test_subsurface_shear_constants():
    """Johnson §4.3: τ1,max = 0.300 p0 at z = 0.786 b; τ_zx,max = 0.250 p0 at z = 0.5 b — checked by
    evaluating McEwen's subsurface stresses on the axis, σ_x = −p0[(1 + 2ζ²)/√(1 + ζ²) − 2ζ],
    σ_z = −p0/√(1 + ζ²), τ1 = (σ_x − σ_z)/2, at its maximum."""
    zeta = np.linspace(0.0, 3.0, 300001)
    sx = -((1 + 2 * zeta ** 2) / np.sqrt(1 + zeta ** 2) - 2 * zeta)
    sz = -1.0 / np.sqrt(1 + zeta ** 2)
    t1 = 0.5 * np.abs(sx - sz)
    j = int(np.argmax(t1))
    ratio, depth, _, _ = pin_flank.SUBSURFACE_SHEAR
    assert t1[j] == pytest.approx(ratio, abs=1e-3)
    assert zeta[j] == pytest.approx(depth, abs=1e-3)
