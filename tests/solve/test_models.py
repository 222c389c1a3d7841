"""The pin models: the Hertz pin–flank law against closed forms, and the case format's models."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import CASES_DIR
from scipy.integrate import quad

from rvfem.case import registry
from rvfem.case.definition import load_case
from rvfem.geometry import (
    build_profile,
    pin_profile_contacts,
    profile_curvature,
    trochoid_curvature,
)
from rvfem.solve import contact, models

E, NU = 206000.0, 0.3
L = 9.0


def johnson_two_cylinders(Q, R1, R2, E1=E, nu1=NU, E2=E, nu2=NU, length=L):
    """Approach of the centres of two convex cylinders in line contact (Johnson, *Contact
    Mechanics*): δ = P(1−ν1²)/(πE1)(2 ln(4R1/a) − 1) + P(1−ν2²)/(πE2)(2 ln(4R2/a) − 1),
    a = √(4PR/(πE*)), 1/R = 1/R1 + 1/R2."""
    P = Q / length
    e_star = 1.0 / ((1 - nu1**2) / E1 + (1 - nu2**2) / E2)
    R = 1.0 / (1.0 / R1 + 1.0 / R2)
    a = math.sqrt(4 * P * R / (math.pi * e_star))
    return (P * (1 - nu1**2) / (math.pi * E1) * (2 * math.log(4 * R1 / a) - 1)
            + P * (1 - nu2**2) / (math.pi * E2) * (2 * math.log(4 * R2 / a) - 1))


def law_for(curvature, footprint, pin_radius=3.0, **kw):
    params = dict(length=L, pin_radius=pin_radius, flank_curvature=np.asarray(curvature, float),
                  pin_modulus=E, pin_poisson=NU, disc_modulus=E, disc_poisson=NU,
                  footprint_half_width=footprint)
    params.update(kw)
    return contact.hertz_pin_law(**params), params


def test_hertz_pin_law_is_johnsons_two_cylinder_approach_for_a_convex_flank():
    """With the footprint half-width w = 4R2/√e, the disc term 2c·ln(w/a) is Johnson's
    c·(2 ln(4R2/a) − 1): the law must give his approach of the centres of two cylinders."""
    r_pin, r_flank = 3.0, np.array([1.6, 2.5, 8.0])
    for R2 in r_flank:
        law, _ = law_for([1.0 / R2], footprint=4 * R2 / math.sqrt(math.e), pin_radius=r_pin)
        for Q in (1.0, 50.0, 400.0, 3000.0):
            delta = johnson_two_cylinders(Q, r_pin, R2)
            q, dq = law(np.array([delta]))
            assert q[0] == pytest.approx(Q, rel=1e-10)
            h = 1e-6 * delta
            fd = (johnson_two_cylinders(Q * (1 + 1e-6), r_pin, R2) - johnson_two_cylinders(Q * (1 - 1e-6), r_pin, R2)) / (2e-6 * Q)
            assert dq[0] == pytest.approx(1.0 / fd, rel=1e-6)
            assert h > 0


def test_hertz_pin_law_concave_flank_half_width_and_approach():
    """Concave flank of radius R2 > r_rp (a pin in a conforming groove): relative curvature
    1/R = 1/r_rp − 1/R2, so a is larger and the contact softer than on a convex flank of the same
    radius; the approach is the closed form with that a."""
    r_pin, R2, w, Q = 3.0, 3.5, 0.5, 400.0
    P = Q / L
    e_star = E / (2 * (1 - NU**2))
    a = math.sqrt(4 * P * (1 / (1 / r_pin - 1 / R2)) / (math.pi * e_star))
    c = (1 - NU**2) / (math.pi * E)
    closed = P * c * (2 * math.log(4 * r_pin / a) - 1) + 2 * P * c * math.log(w / a)
    law, params = law_for([-1.0 / R2, 1.0 / R2], footprint=w, pin_radius=r_pin)
    delta, _ = contact.hertz_pin_approach(np.array([Q, Q]), **params)
    assert delta[0] == pytest.approx(closed, rel=1e-12)
    assert delta[0] < delta[1]          # conforming contact: wider band, smaller log term
    q, _ = law(np.array([closed, closed]))
    assert q[0] == pytest.approx(Q, rel=1e-10)
    assert q[1] < Q                      # the same approach on the convex flank carries less


def test_disc_term_is_the_half_plane_compression_difference_of_hertz_and_footprint():
    """The disc term 2P(1−ν²)/(πE)·ln(w/a): the difference between the compressions, to a depth
    z far below, of the half-plane under a Hertz pressure of half-width a and under the FE's
    elliptical footprint of half-width w, integrated numerically from the subsurface stresses on
    the axis (Johnson, *Contact Mechanics*, plane strain)."""
    P, a, w, z = 40.0, 0.08, 0.5, 400.0

    def compression(c):
        p0 = 2 * P / (math.pi * c)
        sz = lambda y: -p0 * c / math.sqrt(c * c + y * y)                                  # noqa: E731
        sx = lambda y: -p0 / c * ((c * c + 2 * y * y) / math.sqrt(c * c + y * y) - 2 * y)  # noqa: E731
        strain = lambda y: ((1 - NU**2) * sz(y) - NU * (1 + NU) * sx(y)) / E             # noqa: E731
        return -quad(strain, 0.0, z, limit=400, points=[c, 10 * c])[0]

    numeric = compression(a) - compression(w)
    closed = 2 * P * (1 - NU**2) / (math.pi * E) * math.log(w / a)
    assert numeric == pytest.approx(closed, rel=1e-5)


def test_hertz_pin_law_is_compression_only_and_increasing():
    law, _ = law_for(np.linspace(-0.32, 0.6, 7), footprint=0.5)
    q, dq = law(np.full(7, -1e-3))
    assert np.all(q == 0) and np.all(dq == 0)
    deltas = np.geomspace(1e-6, 2e-2, 40)
    qs = np.array([law(np.full(7, d))[0] for d in deltas])
    assert np.all(np.diff(qs, axis=0) > 0)


def test_profile_curvature_is_the_parallel_curve_of_the_trochoid():
    """Unmodified profile: κ = κ_T/(1 − r·κ_T), the parallel curve of the pin-centre trochoid."""
    case = load_case(CASES_DIR / "rv40e.toml")
    prof = build_profile(case)
    s = np.linspace(-prof.half_range, prof.half_range, 41)
    kt = trochoid_curvature(prof.generating_circle_radius, prof.eccentricity, float(prof.pins), s)
    expected = kt / (1 - prof.generating_pin_radius * kt)
    assert np.allclose(profile_curvature(prof, np.zeros(41, int), s), expected, rtol=1e-9, atol=1e-12)
    # convex near the tips, concave near the roots, the concave radius never below r_rp
    pc = pin_profile_contacts(case, 0.3)
    k = profile_curvature(prof, pc.segment, pc.param)
    assert k.max() > 0 > k.min()
    assert np.all(1.0 / case.pins.radius + k > 0)


def test_every_pin_model_of_the_case_format_is_registered_and_described():
    case = load_case(CASES_DIR / "rv40e.toml")
    assert set(registry.pin_model_names()) >= {"rigid", "hertz", "palmgren", "linear"}
    for name in ("rigid", "hertz", "palmgren"):
        assert models.pin_model(name)(case).describe()
    assert "Hertz line contact" in models.pin_model("hertz")(case).describe()
    assert "Palmgren" in models.pin_model("palmgren")(case).describe()
    assert "1e+04 N/mm" in models.pin_model("linear")(case, 1e4).describe() or \
        "10000 N/mm" in models.pin_model("linear")(case, 1e4).describe()


@pytest.mark.slow
def test_classical_model_through_its_case_file_gives_the_textbook_distribution(tmp_path):
    """cases/rv40e_classical.toml (linear pins, stiff disc, rigid bearings, μ = 0, T/2 on one disc)
    reproduces the classical distribution scaled by Zc/Zp (the textbook's T/2 is about the disc centre,
    rvfem's about the reducer axis): peak 406.7 N·39/40 on the RV-40E stage, 19-20 loaded pins,
    and every pin force within 0.5 % of the peak. The distribution repeats every pin pitch (9°)."""
    from rvfem.evaluate import rigid
    from rvfem.mesh import mesh_case
    from rvfem.solve import cycle

    case = load_case(CASES_DIR / "rv40e_classical.toml")
    system = cycle.build_system(case, mesh_case(case, tmp_path))
    thetas = np.radians(np.arange(0.0, 9.0, 0.5))
    result = cycle.load_cycle(system, thetas, saved_angles_deg=())
    # the textbook takes T/2 about the disc centre; the carrier turns about the reducer axis, where the
    # pins' moment is T/2 and about the disc centre Zc/Zp of it (docs/theory.md § 6): every pin force × Zc/Zp
    ratio = case.cycloid.teeth / case.pins.count
    classical = ratio * rigid.classical_pin_forces(case, thetas, exact_moment=True).magnitude.T
    assert result.pin_forces.max() == pytest.approx(406.7 * ratio, rel=1e-3)
    assert np.abs(result.pin_forces - classical).max() <= 5e-3 * classical.max()
    assert set(result.pins_in_contact) <= {19, 20}
