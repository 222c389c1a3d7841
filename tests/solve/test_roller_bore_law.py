"""The roller–bore law counts the bore's local contact compliance once: Palmgren's two line contacts
less what the FE bore footprint already holds (rvfem.solve.contact_laws.roller_bore_law).

References: Palmgren's law δ = 2·3.84e-5·Q^0.9/L^0.8 (Harris & Kotzalas) in the rigid-disc limit;
the closed form 1.5·3.84e-5·Q^0.9/L^0.8 when the footprint is as narrow as the Hertz contact; and the
FE disc itself: its bore footprint's compliance grows by 2(1 − ν²)/(πEL)·ln 2 when the footprint is
halved (a half-plane's), which the law gives back, so that law + FE does not depend on the mesh.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import coarse_case

from rvfem.geometry import crank_centres
from rvfem.mesh import mesh_case
from rvfem.solve import contact, cycle, models

LENGTH = 9.0                                   # the RV-40E roller: L_we 9 mm, D_we 5 mm, bore radius 18 mm
R_BORE = 2.5 * 18.0 / (18.0 - 2.5)
E, NU = 206000.0, 0.3
PARAMS = dict(length=LENGTH, reduced_radius_bore=R_BORE, disc_modulus=E, disc_poisson=NU, footprint_half_width=0.6)
LOADS = np.geomspace(1.0, 2.0e4, 25)


def _palmgren(q, contacts=2.0):
    return contacts * 3.84e-5 * np.asarray(q) ** 0.9 / LENGTH**0.8


def _hertz_half_width(q):
    e_star = E / (2.0 * (1.0 - NU**2))
    return np.sqrt(4.0 * q * R_BORE / (math.pi * e_star * LENGTH))


def test_the_law_inverts_its_approach_and_is_monotone():
    delta, slope = contact.roller_bore_approach(LOADS, **PARAMS)
    assert np.all(np.diff(delta) > 0.0) and np.all(slope > 0.0)
    q, dq = contact.roller_bore_law(**PARAMS)(delta)
    assert q == pytest.approx(LOADS, rel=1e-9)
    assert dq * slope == pytest.approx(np.ones_like(LOADS), rel=1e-9)
    # compression only, and a trial approach far beyond any roller load stays on a rising line
    q0, dq0 = contact.roller_bore_law(**PARAMS)(np.array([-1e-3, 0.0]))
    assert np.all(q0 == 0.0) and np.all(dq0 == 0.0)
    far = contact.roller_bore_law(**PARAMS)(np.array([1.0, 2.0, 4.0]))[0]
    assert np.all(np.diff(far) > 0.0)


def test_its_derivative_is_the_difference_quotient():
    law = contact.roller_bore_law(**PARAMS)
    d = contact.roller_bore_approach(np.array([50.0, 800.0, 3000.0]), **PARAMS)[0]
    h = 1e-7 * d
    numeric = (law(d + h)[0] - law(d - h)[0]) / (2.0 * h)
    assert law(d)[1] == pytest.approx(numeric, rel=1e-5)


@pytest.mark.parametrize("scale", [1e3, 1e6])
def test_rigid_disc_limit_recovers_palmgren(scale):
    """A disc stiffened by the rigid-limit checks' factor holds none of the bore's compliance: the
    law is Palmgren's two contacts (within 1 %; 0.03 % at 10³, to round-off at 10⁶)."""
    delta = contact.roller_bore_approach(LOADS, **PARAMS, disc_stiffness_scale=scale)[0]
    assert delta == pytest.approx(_palmgren(LOADS), rel=0.01 if scale < 1e6 else 1e-5)
    q = contact.roller_bore_law(**PARAMS, disc_stiffness_scale=scale)(_palmgren(LOADS))[0]
    q_palmgren = contact.palmgren_law(LENGTH, contacts=2)(_palmgren(LOADS))[0]
    assert q == pytest.approx(q_palmgren, rel=0.01)


def test_refined_footprint_limit_leaves_one_and_a_half_contacts():
    """A footprint as narrow as the Hertz contact (w = a) holds the bore's whole local compliance:
    the law keeps the eccentric's contact and the roller's side of the bore's, 1.5 Palmgren
    contacts."""
    for q in (10.0, 500.0, 1300.0, 5000.0):
        params = dict(PARAMS, footprint_half_width=float(_hertz_half_width(q)) * (1.0 + 1e-12))
        delta = float(contact.roller_bore_approach(q, **params)[0])
        assert delta == pytest.approx(float(_palmgren(q, 1.5)), rel=1e-9)


def test_a_wider_footprint_gives_back_a_half_plane_share():
    """Doubling w adds 2(1 − ν²)/(πEL)·Q·ln 2 to the law: the half-plane's approach of an
    elliptical load of half-width w at a fixed depth falls by that much (the scaling of
    ∫∫ρρ ln(1/|x − s|) by the width)."""
    q = LOADS
    wide = contact.roller_bore_approach(q, **dict(PARAMS, footprint_half_width=1.2))[0]
    narrow = contact.roller_bore_approach(q, **PARAMS)[0]
    k = 2.0 * (1.0 - NU**2) / (math.pi * E * LENGTH)
    assert wide - narrow == pytest.approx(k * q * math.log(2.0), rel=1e-9)


def _bore_compliance(size_bore, mesh_dir):
    """Diagonal FE compliance of the bore-1 footprint column nearest 200° (mm/N) and the case."""
    case = coarse_case("rv40e_solid", mesh={"size_bore": size_bore})
    system = cycle.build_system(case, mesh_case(case, mesh_dir))
    grid = system.interface.grids["bore_0"]
    pts = system.interface.points[grid.offset:grid.offset + grid.count] - crank_centres(case)[0]
    ang = np.arctan2(pts[:, 1], pts[:, 0])
    j = grid.offset + int(np.argmin(np.abs(np.angle(np.exp(1j * (ang - math.radians(200.0)))))))
    system.compliance.ensure(np.array([j]))
    return float(system.compliance.C[j, j]), case


def test_law_plus_fe_bore_does_not_depend_on_the_footprint(tmp_path):
    """The FE's own refined-footprint limit: halving the bore's element size (and with it the
    footprint) makes the FE bore's compliance under a roller grow by the half-plane's
    2(1 − ν²)/(πEL)·ln 2 (within 10 %: the FE resolves a footprint with 3 elements), and the
    roller's law loses as much, so that a roller's whole approach (law + FE bore) changes by under
    0.1 % at 1300 N, where Palmgren's law alone on the FE bore changed by 2.5 %."""
    (c_coarse, case), (c_fine, _) = (_bore_compliance(s, tmp_path) for s in (0.6, 0.3))
    m = case.material
    k = 2.0 * (1.0 - m.poissons_ratio**2) / (math.pi * m.youngs_modulus * case.crank_bearing.roller_length)
    assert c_fine - c_coarse == pytest.approx(k * math.log(2.0), rel=0.10)
    q = 1300.0
    totals = []
    for size, c in ((0.6, c_coarse), (0.3, c_fine)):
        law = models.RollerBearing(coarse_case("rv40e_solid", mesh={"size_bore": size}))._law
        # the roller's approach at q: law⁻¹ by bisection on the law itself
        lo, hi = 0.0, 0.05
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if law(np.array([mid]))[0][0] < q else (lo, mid)
        totals.append(0.5 * (lo + hi) + c * q)
    assert totals[1] == pytest.approx(totals[0], rel=1e-3)
    palmgren = [float(_palmgren(q)) + c * q for c in (c_coarse, c_fine)]
    assert abs(palmgren[1] / palmgren[0] - 1.0) > 10 * abs(totals[1] / totals[0] - 1.0)
