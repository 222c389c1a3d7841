"""Disc mass and polar inertia against closed forms and the mesh integral; the fatigue and static
safety factors against hand calculations (the FKM signed von Mises stress on a Goodman line)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from conftest import CASES_DIR, coarse_case
from rvfem.case.definition import load_case
from rvfem.errors import CaseError
from rvfem.evaluate import strength
from rvfem.geometry import Circle, FanHole, disc_geometry
from rvfem.geometry.mass import (
    disc_mass_properties,
    mesh_area_polar,
    outline_area_polar,
    polygon_area_polar,
)

# --------------------------------------------------------------------------------------------
# Mass and inertia: closed forms
# --------------------------------------------------------------------------------------------


def _regular_polygon(R: float, n: int) -> np.ndarray:
    a = 2 * np.pi * np.arange(n) / n
    return np.stack([R * np.cos(a), R * np.sin(a)], axis=1)


def _ngon(R: float, n: int) -> tuple[float, float]:
    """Area and polar moment of a regular n-gon of circumradius R: n triangles from the centre,
    each A_t = R² sin β / 2 and J_t = A_t (2R² + R² cos β)/6, β = 2π/n."""
    b = 2 * math.pi / n
    at = 0.5 * R * R * math.sin(b)
    return n * at, n * at * R * R * (2 + math.cos(b)) / 6


def _sector(ri: float, ro: float, span: float) -> tuple[float, float]:
    """Annular sector r_i ≤ ρ ≤ r_o over an angle ``span``: A = span (r_o² − r_i²)/2,
    J = span (r_o⁴ − r_i⁴)/4."""
    return span * (ro**2 - ri**2) / 2, span * (ro**4 - ri**4) / 4


def test_polygon_against_the_regular_polygon():
    for n in (3, 7, 400):
        a, j = polygon_area_polar(_regular_polygon(50.0, n))
        ea, ej = _ngon(50.0, n)
        assert a == pytest.approx(ea, rel=1e-12) and j == pytest.approx(ej, rel=1e-12)


def test_circles_and_sharp_fan_holes_against_closed_forms():
    a, j = outline_area_polar(Circle("c", (0.0, 0.0), 12.0))
    assert a == pytest.approx(math.pi * 12**2, rel=1e-12) and j == pytest.approx(math.pi * 12**4 / 2, rel=1e-12)
    # off-centre bore: parallel axes, J = πR⁴/2 + πR² d²
    a, j = outline_area_polar(Circle("b", (36.0 * math.cos(1.2), 36.0 * math.sin(1.2)), 18.0))
    assert j == pytest.approx(math.pi * 18**4 / 2 + math.pi * 18**2 * 36**2, rel=1e-12)
    for centre in (0.0, 0.7, 2.9):
        for half in (0.2, 0.37, 1.3):
            a, j = outline_area_polar(FanHole("h", 17.0, 49.0, centre, half, 0.0))
            ea, ej = _sector(17.0, 49.0, 2 * half)
            assert a == pytest.approx(ea, rel=1e-12) and j == pytest.approx(ej, rel=1e-12)


def test_filleted_fan_hole_against_a_fine_polygon_of_its_outline():
    """The fillets remove four corners: checked against the polygon formula on 0.5 µm samples of
    the outline (an independent path: chords, no arcs; its error ~ spacing²/(12 f) relative)."""
    hole = FanHole("h", 17.0, 49.0, 0.5, 0.37, 2.0)
    a, j = outline_area_polar(hole)
    pa, pj = polygon_area_polar(hole.sample(0.0005))
    assert a == pytest.approx(pa, rel=1e-8) and j == pytest.approx(pj, rel=1e-8)
    sa, sj = _sector(17.0, 49.0, 0.74)
    assert 0 < sa - a < 4 * (1 - math.pi / 4) * 2.0**2 * 1.01    # at most four corner squares


def _fake_geometry(n_holes: int, fillet: float = 0.0):
    """A disc whose outline is a 3600-gon of circumradius 60 with a central hole, three bores and
    ``n_holes`` annular-sector holes."""
    bores = tuple(Circle(f"bore_{i}", (36 * math.cos(a), 36 * math.sin(a)), 9.0)
                  for i, a in enumerate(np.radians([90, 210, 330])))
    holes = tuple(FanHole(f"hole_{i}", 17.0, 49.0, math.radians(30 + 120 * i), 0.3, fillet) for i in range(n_holes))
    case = SimpleNamespace(material=SimpleNamespace(density_kg_m3=7810.0), cycloid=SimpleNamespace(thickness=9.0))
    return SimpleNamespace(case=case, profile=SimpleNamespace(points=_regular_polygon(60.0, 3600)),
                           central_hole=Circle("central_hole", (0.0, 0.0), 12.0), bores=bores, holes=holes)


def test_disc_with_annular_sector_holes_against_closed_forms():
    """Area, mass and polar inertia of a disc with three annular-sector holes (closed forms: n-gon,
    annulus, circles by parallel axes, sectors) to 1e-9 relative (the acceptance asks 1e-6)."""
    m = disc_mass_properties(_fake_geometry(3))
    a_out, j_out = _ngon(60.0, 3600)
    a_solid = a_out - math.pi * 12**2 - 3 * math.pi * 9**2
    j_solid = j_out - math.pi * 12**4 / 2 - 3 * (math.pi * 9**4 / 2 + math.pi * 9**2 * 36**2)
    sa, sj = _sector(17.0, 49.0, 0.6)
    assert m.solid_area_mm2 == pytest.approx(a_solid, rel=1e-9)
    assert m.solid_polar_mm4 == pytest.approx(j_solid, rel=1e-9)
    assert m.area_mm2 == pytest.approx(a_solid - 3 * sa, rel=1e-9)
    assert m.polar_mm4 == pytest.approx(j_solid - 3 * sj, rel=1e-9)
    rho_b = 7810.0 * 1e-9 * 9.0       # kg/mm³ · mm
    assert m.mass_kg == pytest.approx(rho_b * (a_solid - 3 * sa), rel=1e-9)
    assert m.polar_inertia_kg_mm2 == pytest.approx(rho_b * (j_solid - 3 * sj), rel=1e-9)
    assert m.mass_saving_percent == pytest.approx(100 * 3 * sa / a_solid, rel=1e-9)
    assert m.inertia_saving_percent == pytest.approx(100 * 3 * sj / j_solid, rel=1e-9)


def test_the_solid_twin_is_the_shipped_solid_disc():
    """The fan-hole case's solid twin is cases/rv40e.toml (same profile, bores, central hole)."""
    holed = disc_mass_properties(disc_geometry(load_case(CASES_DIR / "rv40e_fanholes.toml")))
    solid = disc_mass_properties(disc_geometry(load_case(CASES_DIR / "rv40e.toml")))
    assert holed.solid_area_mm2 == pytest.approx(solid.area_mm2, rel=1e-12)
    assert holed.solid_polar_inertia_kg_mm2 == pytest.approx(solid.polar_inertia_kg_mm2, rel=1e-12)
    assert solid.mass_saving_percent == 0.0


def test_mesh_integral_agrees_with_the_geometry(tmp_path):
    """The P1 mesh's straight-sided triangles against the exact outline integrals: the chords cut
    each curved boundary by about h²/(12 R) per unit length, 8e-4 of the area at 1.2 mm, 2e-4 at 0.6 mm;
    the agreement improves with the square of the element size (second order)."""
    from rvfem.mesh import mesh_case

    errors = []
    for size in (1.2, 0.6):
        case = coarse_case("rv40e_fanholes", mesh={"size_flank": size, "size_bore": size, "size_hole": size,
                                                   "size_interior": 4.0})
        geo = disc_geometry(case)
        m = disc_mass_properties(geo)
        mesh = mesh_case(case, tmp_path)
        a, j = mesh_area_polar(mesh.points, mesh.triangles)
        errors.append((abs(a / m.area_mm2 - 1), abs(j / m.polar_mm4 - 1)))
    assert max(errors[1]) < 5e-4, errors
    assert errors[0][0] / errors[1][0] > 3.0 and errors[0][1] / errors[1][1] > 3.0, errors   # h² (ratio 4)


# --------------------------------------------------------------------------------------------
# Strength
# --------------------------------------------------------------------------------------------

STEEL = SimpleNamespace(yield_strength=1800.0, ultimate_strength=2400.0, fatigue_limit=960.0)


def _history(s1: np.ndarray, s2: np.ndarray, factor: float = 1.0):
    peak = SimpleNamespace(x_mm=1.0, y_mm=2.0, theta_deg=0.0, feature="hole_0")
    return SimpleNamespace(names=("structural",), peaks=(peak,), s1=s1[:, None], s2=s2[:, None],
                           p2_factor=(factor,))


@pytest.mark.parametrize("mean, amp", [(0.0, 300.0), (200.0, 300.0), (600.0, 100.0), (-200.0, 300.0)])
def test_plate_under_alternating_uniaxial_stress(mean, amp):
    """A plate under σ(θ) = σ_m + σ_a sin θ (σ2 = 0): the signed von Mises stress is σ itself, and
    the Goodman safety factor by hand is 1/(σ_a/σ_W + σ_m/R_m) (σ_m ≥ 0) or σ_W/σ_a (σ_m < 0)."""
    theta = np.radians(np.arange(0.0, 360.0, 1.0))
    s = mean + amp * np.sin(theta)
    (f,) = strength.hot_spot_fatigue(_history(s, np.zeros_like(s)), STEEL)
    assert f.amplitude_MPa == pytest.approx(amp, rel=1e-12) and f.mean_MPa == pytest.approx(mean, abs=1e-9)
    hand = 960.0 / amp if mean < 0 else 1.0 / (amp / 960.0 + mean / 2400.0)
    assert f.goodman_safety_factor == pytest.approx(hand, rel=1e-12)
    # the same history in compression of the other principal direction (σ1 = 0, σ2 = σ): same factor
    (g,) = strength.hot_spot_fatigue(_history(np.zeros_like(s), s), STEEL)
    assert g.goodman_safety_factor == pytest.approx(hand, rel=1e-12)


def test_hand_numbers():
    """σ_m = 200, σ_a = 300 MPa: 1/(300/960 + 200/2400) = 1/(0.3125 + 0.08333) = 2.526."""
    assert strength.goodman_safety_factor(300.0, 200.0, 960.0, 2400.0) == pytest.approx(2.5263157894736842)
    assert strength.goodman_safety_factor(0.0, -50.0, 960.0, 2400.0) == math.inf
    assert strength.static_safety_factor(110.0, 1800.0) == pytest.approx(16.363636, rel=1e-6)


def test_pure_shear_and_biaxial_signed_von_mises():
    """Pure shear σ1 = τ, σ2 = −τ: von Mises √3 τ, first invariant 0 (counted positive); equibiaxial
    σ1 = σ2 = −p: −p."""
    assert strength.signed_von_mises(100.0, -100.0) == pytest.approx(math.sqrt(3) * 100.0)
    assert strength.signed_von_mises(-50.0, -50.0) == pytest.approx(-50.0)


@pytest.mark.parametrize("s", [0.5, 2.0, 48.0])
def test_proportional_scaling_scales_amplitude_and_mean(s):
    """A load scaled by s scales the stress history, so σ_a and σ_m by s and the factor by 1/s."""
    rng = np.random.default_rng(7)
    s1, s2 = rng.normal(40.0, 60.0, 90), rng.normal(-30.0, 40.0, 90)
    (f,) = strength.hot_spot_fatigue(_history(s1, s2), STEEL)
    (g,) = strength.hot_spot_fatigue(_history(s * s1, s * s2), STEEL)
    assert g.amplitude_MPa == pytest.approx(s * f.amplitude_MPa, rel=1e-12)
    assert g.mean_MPa == pytest.approx(s * f.mean_MPa, rel=1e-12)
    assert g.goodman_safety_factor == pytest.approx(f.goodman_safety_factor / s, rel=1e-12)
    # the P2/P1 factor is a proportional scaling too
    (h,) = strength.hot_spot_fatigue(_history(s1, s2, factor=s), STEEL)
    assert h.goodman_safety_factor == pytest.approx(g.goodman_safety_factor, rel=1e-12)


def test_structural_hot_spot_gets_findley_and_the_contact_zone_none():
    """A plate under σ_x = σ_W·sin θ at the structural hot spot: Findley's factor 1 (its bending
    calibration), times 1/p2_factor; the contact zone at a bore gets no factor and is named the
    bearing's outer raceway."""
    theta = np.radians(np.arange(0.0, 360.0, 1.0))
    s = 960.0 * np.sin(theta)
    z = np.zeros_like(s)
    peaks = (SimpleNamespace(x_mm=1.0, y_mm=2.0, theta_deg=0.0, feature="hole_0"),
             SimpleNamespace(x_mm=3.0, y_mm=4.0, theta_deg=0.0, feature="bore_0"))
    two = np.stack([s, s], axis=1)
    zz = np.zeros_like(two)
    history = SimpleNamespace(names=("structural", "contact_zone"), peaks=peaks, s1=two, s2=zz,
                              p2_factor=(0.5, 1.0), sxx=two, syy=zz, sxy=zz)
    f, c = strength.hot_spot_fatigue(history, STEEL)
    assert f.safety_factor == pytest.approx(2.0, rel=1e-6)
    assert c.safety_factor is None and "outer raceway" in c.assessed_as and "L10r" in c.assessed_as


def test_material_strength_keys_are_checked(tmp_path):
    with pytest.raises(CaseError, match="material.yield_strength"):
        load_case(CASES_DIR / "rv40e_fanholes.toml", ("material.yield_strength=2500",))
    with pytest.raises(CaseError, match="material.fatigue_limit"):
        load_case(CASES_DIR / "rv40e_fanholes.toml", ("material.fatigue_limit=2400",))


@pytest.mark.slow
def test_envelope_field_agrees_with_the_hot_spot_histories(tmp_path):
    """Two independent paths to the same stresses: the cycle's vertex envelope (every angle's full
    field) and the hot spots' influence-coefficient history. At each hot spot the envelope's fatigue
    field equals the hot spot's P1 factor (its P2/P1 factor undone); the static factor is R_p0.2
    over the structural peak."""
    from rvfem.app.analysis import analyse
    from rvfem.evaluate.design_checks import design_checks
    from rvfem.results.mass_strength import fatigue_point_data

    a = analyse(coarse_case("rv40e_fanholes"), angle_step_deg=10.0, cache_dir=tmp_path / "meshes")
    field = fatigue_point_data(a)["fatigue_safety_factor_P1"]
    checks = design_checks(a)
    for f, vertex in zip(checks.fatigue, a.stress.history.vertices):
        assert field[vertex] == pytest.approx(f.goodman_safety_factor * f.p2_factor, rel=1e-9)
    assert checks.static_safety_factor == pytest.approx(1800.0 / a.stress.structural.von_mises_MPa, rel=1e-12)
    assert checks.mass.mass_kg == pytest.approx(disc_mass_properties(disc_geometry(a.case)).mass_kg, rel=1e-15)
