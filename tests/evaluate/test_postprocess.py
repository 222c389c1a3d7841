"""What rvfem.evaluate.postprocess promises, against closed forms and brute-force references:
the peak von Mises stress of a field with a known answer and where it lies, the contact bands it
leaves out, ties among equal peaks, the field snapshots at the kept and the requested angles, the
stress envelope over a cycle and the hot-spot histories.

Fields with known stresses on a structured annulus (inner radius 8 mm, outer 30 mm, six rings of
72 vertices; the outer loop named ``profile``, the inner ``central_hole``):

* a uniform strain ε (a symmetric displacement gradient, no rigid rotation) gives the uniform
  plane stress σ = λ tr(ε) I + 2μ ε, reproduced exactly by P1 and P2 (the patch test);
* pure bending, u_x = κxy, u_y = −κ(x² + νy²)/2, gives σ_xx = Eκy, σ_yy = τ_xy = 0 (plane stress;
  Timoshenko & Goodier § 22): von Mises Eκ|y|, linear, reproduced exactly by P2.
"""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import coarse_case, structured_annulus

from rvfem import fem
from rvfem.evaluate import postprocess
from rvfem.evaluate.postprocess import (
    field_snapshots,
    max_load_index,
    nearest_index,
    peak_von_mises,
)
from rvfem.mesh import mesh_case
from rvfem.solve import cycle as cycle_module

E, NU, THICK = 2.1e5, 0.3, 10.0
R_IN, R_OUT, N_R, N_T = 8.0, 30.0, 6, 72
RINGS = np.linspace(R_IN, R_OUT, N_R)
KAPPA = 1e-5                                       # bending curvature, 1/mm: Eκ·30 mm = 63 MPa


def test_contact_band_mask_equals_brute_force_distances():
    """The band mask (k-d tree searches cut off at the band) keeps exactly the vertices whose
    distance to every excluded boundary's vertices, computed pairwise, is at least the band."""
    rng = np.random.default_rng(7)
    points = rng.uniform(-10.0, 10.0, size=(2000, 2))
    # two "boundaries": the first 60 and the next 40 points, as edges (i, i + 1)
    boundaries = {"profile": np.column_stack([np.arange(60), np.arange(1, 61) % 60]),
                  "bore_0": np.column_stack([60 + np.arange(40), 60 + (np.arange(1, 41) % 40)]),
                  "hole_0": np.column_stack([100 + np.arange(10), 100 + (np.arange(1, 11) % 10)])}
    exclude = {"profile": 1.5, "bore_0": 0.7, "hole_0": 0.0, "missing": 3.0}
    expected = np.ones(len(points), dtype=bool)
    for name in ("profile", "bore_0"):
        b = points[boundaries[name][:, 0]]
        d = np.sqrt(((points[:, None, :] - b[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
        expected &= d >= exclude[name]
    mask = postprocess._mask(points, boundaries, exclude)
    assert 0 < mask.sum() < len(points)
    assert np.array_equal(mask, expected)


# --------------------------------------------------------------------------------------------
# Fields with a known answer
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def annulus():
    points, triangles, boundaries = structured_annulus(R_IN, R_OUT, N_R, N_T)
    models = {order: fem.build_model(points, triangles, E, NU, THICK, order) for order in (1, 2)}
    return points, boundaries, models


def _field(model, ux, uy) -> np.ndarray:
    """A displacement vector of ``model`` from functions of the node coordinates."""
    x, y = model.node_coords.T
    u = np.zeros(model.n_dofs)
    u[model.node_dofs[:, 0]] = ux(x, y)
    u[model.node_dofs[:, 1]] = uy(x, y)
    return u


def _bending(model, kappa: float = KAPPA) -> np.ndarray:
    return _field(model, lambda x, y: kappa * x * y, lambda x, y: -0.5 * kappa * (x * x + NU * y * y))


def _cycle_of(fields: dict, theta=None, solutions=()):
    """The part of a load cycle :func:`field_snapshots` reads: angles, kept fields, solutions."""
    theta = np.array(sorted(fields)) if theta is None else np.asarray(theta)
    return SimpleNamespace(theta=theta, fields=fields, solutions=solutions)


def _vertex(ring: int, step: int) -> int:
    """Vertex of the structured annulus on ring ``ring`` (0 = inner) at angle ``step``·5°."""
    return ring * N_T + step


@pytest.mark.parametrize("order", [1, 2])
def test_a_uniform_strain_gives_its_plane_stress_and_the_first_vertex_as_peak(annulus, order):
    points, boundaries, models = annulus
    model = models[order]
    g = np.array([[4e-4, 1e-4], [1e-4, -2e-4]])                  # symmetric: no rotation
    lam, mu = fem.plane_stress_constants(E, NU)
    sig = lam * np.trace(g) * np.eye(2) + 2 * mu * g
    vm = math.sqrt(sig[0, 0] ** 2 - sig[0, 0] * sig[1, 1] + sig[1, 1] ** 2 + 3 * sig[0, 1] ** 2)
    tx, ty, om = 0.02, -0.01, 3e-4                               # a rigid motion on top
    strain = _field(model, lambda x, y: g[0, 0] * x + g[0, 1] * y, lambda x, y: g[1, 0] * x + g[1, 1] * y)
    rigid = _field(model, lambda x, y: tx - om * y, lambda x, y: ty + om * x)
    theta = 0.7
    (snap,) = field_snapshots(SimpleNamespace(model=model), _cycle_of({theta: strain + rigid}))
    vdofs = model.node_dofs[: model.n_vertices]
    assert (snap.theta, snap.index, snap.theta_deg) == (theta, 0, math.degrees(theta))
    np.testing.assert_array_equal(snap.displacement, (strain + rigid)[vdofs])
    # the annulus is symmetric about its centre: the least-squares rigid part is the rigid motion
    np.testing.assert_allclose(snap.rigid_motion, [tx, ty, om], rtol=1e-12)
    np.testing.assert_allclose(snap.deformation, strain[vdofs], rtol=0, atol=1e-15)
    np.testing.assert_allclose(snap.stress.nodal.von_mises, vm, rtol=1e-12)
    # every vertex ties: the peak is the first vertex, on the central hole
    peak = peak_von_mises((snap,), points, boundaries)
    assert peak.von_mises_MPa == pytest.approx(vm, rel=1e-12)
    assert (peak.x_mm, peak.y_mm, peak.radius_mm) == (R_IN, 0.0, R_IN)
    assert (peak.feature, peak.feature_label, peak.distance_to_feature_mm) == ("central_hole", "central hole", 0.0)
    assert peak.theta_deg == pytest.approx(math.degrees(theta))


def test_pure_bending_peaks_at_the_outer_fibre(annulus):
    points, boundaries, models = annulus
    snaps = field_snapshots(SimpleNamespace(model=models[2]), _cycle_of({0.0: _bending(models[2])}))
    vm = snaps[0].stress.nodal.von_mises
    np.testing.assert_allclose(vm, E * KAPPA * np.abs(points[:, 1]), rtol=1e-9, atol=1e-9 * E * KAPPA * R_OUT)
    peak = peak_von_mises(snaps, points, boundaries)
    # y = +30 mm and y = −30 mm tie (round-off apart): the lower vertex, at 90°
    assert vm[_vertex(N_R - 1, N_T // 4)] == pytest.approx(vm[_vertex(N_R - 1, 3 * N_T // 4)], rel=1e-12)
    assert peak.von_mises_MPa == pytest.approx(E * KAPPA * R_OUT, rel=1e-12)
    assert (peak.x_mm, peak.y_mm) == pytest.approx((0.0, R_OUT), abs=1e-12)
    assert (peak.feature, peak.feature_label, peak.distance_to_feature_mm) == ("profile", "tooth profile", 0.0)


def test_equal_peaks_are_told_apart_by_angle_then_vertex_never_by_round_off(annulus):
    """On a symmetric disc the peak has rotated copies that differ by round-off: among values
    within TIE_RTOL of the largest the one at the smallest crank angle is taken, then the lowest
    vertex; a value larger by more than that wins."""
    points, boundaries, _ = annulus
    top, bottom = _vertex(N_R - 1, N_T // 4), _vertex(N_R - 1, 3 * N_T // 4)     # (0, 30) and (0, −30)
    vm = E * KAPPA * np.abs(points[:, 1])
    vm[top] = vm[bottom] = E * KAPPA * R_OUT

    def peak(bump: float, theta_top: float = 0.0, theta_bottom: float = 0.0):
        values, theta = vm.copy(), np.zeros(len(points))
        values[bottom] *= 1.0 + bump
        theta[top], theta[bottom] = theta_top, theta_bottom
        return peak_von_mises(postprocess.StressEnvelope(values, theta), points, boundaries)

    assert peak(1e-12).y_mm == pytest.approx(R_OUT)                  # a round-off larger: the lower vertex
    assert peak(1e-6).y_mm == pytest.approx(-R_OUT)                  # truly larger
    assert peak(1e-12, theta_top=0.5, theta_bottom=0.2).y_mm == pytest.approx(-R_OUT)    # the earlier angle
    assert peak(0.0, theta_top=2 * math.pi + 0.1, theta_bottom=0.2).y_mm == pytest.approx(R_OUT)  # on the circle
    assert peak(1e-12, theta_top=0.5, theta_bottom=0.2).theta_deg == pytest.approx(math.degrees(0.2))


@pytest.mark.parametrize("band, ring", [(3.0, N_R - 2), (5.0, N_R - 3), (10.0, N_R - 4)])
def test_a_contact_band_moves_the_peak_to_the_first_ring_outside_it(annulus, band, ring):
    """Rings 4.4 mm apart: a band along the outer loop leaves out the rings within it, and the
    bending peak is Eκ·r on the outermost ring left (``band`` or more from the loop), at 90°; its
    feature is the nearer of the two loops."""
    points, boundaries, models = annulus
    snaps = field_snapshots(SimpleNamespace(model=models[2]), _cycle_of({0.0: _bending(models[2])}))
    peak = peak_von_mises(snaps, points, boundaries, exclude={"profile": band})
    assert peak.von_mises_MPa == pytest.approx(E * KAPPA * RINGS[ring], rel=1e-9)
    assert (peak.x_mm, peak.y_mm) == pytest.approx(tuple(points[_vertex(ring, N_T // 4)]), abs=1e-12)
    assert R_OUT - RINGS[ring] >= band > R_OUT - RINGS[ring + 1]
    nearest = min((R_OUT - RINGS[ring], "profile"), (RINGS[ring] - R_IN, "central_hole"))
    assert (peak.distance_to_feature_mm, peak.feature) == (pytest.approx(nearest[0]), nearest[1])


def test_bands_that_leave_no_vertex_give_no_peak(annulus):
    points, boundaries, models = annulus
    snaps = field_snapshots(SimpleNamespace(model=models[2]), _cycle_of({0.0: _bending(models[2])}))
    assert peak_von_mises(snaps, points, boundaries, exclude={"profile": 12.0, "central_hole": 12.0}) is None
    # a band of a boundary the mesh does not have, or of zero width, leaves everything
    for exclude in ({"bore_0": 50.0}, {"profile": 0.0}):
        assert peak_von_mises(snaps, points, boundaries, exclude=exclude) == peak_von_mises(snaps, points, boundaries)


def test_the_peak_over_snapshots_is_the_largest_and_the_earliest_of_equal_ones(annulus):
    points, boundaries, models = annulus
    m = models[2]
    system = SimpleNamespace(model=m)
    # twice the curvature at the later angle (opposite sign: the same |y|)
    snaps = field_snapshots(system, _cycle_of({0.2: _bending(m), 1.1: _bending(m, -2 * KAPPA)}))
    assert [s.theta for s in snaps] == [0.2, 1.1]
    peak = peak_von_mises(snaps, points, boundaries)
    assert peak.von_mises_MPa == pytest.approx(2 * E * KAPPA * R_OUT, rel=1e-12)
    assert peak.theta_deg == pytest.approx(math.degrees(1.1))
    # the same field at two angles: the smaller angle
    same = field_snapshots(system, _cycle_of({1.1: _bending(m), 0.2: _bending(m)}))
    assert peak_von_mises(same, points, boundaries).theta_deg == pytest.approx(math.degrees(0.2))
    with pytest.raises(ValueError, match="at least one snapshot"):
        peak_von_mises((), points, boundaries)


def test_snapshots_at_requested_angles_are_rebuilt_from_the_nearest_solved_angle(annulus, monkeypatch):
    """Kept fields as they are; a requested angle gives the field of the nearest solved angle (on
    the circle: 359.9° is 0°), rebuilt from its solution, once; snapshots in order of angle."""
    _, _, models = annulus
    m = models[1]
    theta = np.radians(np.arange(0.0, 360.0, 30.0))
    solved = [_bending(m, KAPPA * (1 + k)) for k in range(len(theta))]         # one field per angle
    monkeypatch.setattr(postprocess, "displacement", lambda system, solution: solution)
    kept = {float(theta[9]): solved[9], float(theta[0]): solved[0]}
    cyc = _cycle_of(kept, theta=theta, solutions=solved)
    snaps = field_snapshots(SimpleNamespace(model=m), cyc,
                            extra_angles=[math.radians(61.0), math.radians(359.9), math.radians(270.0),
                                          math.radians(58.0)])
    assert [round(s.theta_deg, 9) for s in snaps] == [0.0, 60.0, 270.0]
    assert [s.index for s in snaps] == [0, 2, 9]
    vdofs = m.node_dofs[: m.n_vertices]
    for s in snaps:
        np.testing.assert_array_equal(s.displacement, solved[s.index][vdofs])
    assert [s.index for s in field_snapshots(SimpleNamespace(model=m), cyc)] == [0, 9]


def test_nearest_index_is_on_the_circle():
    theta = np.radians(np.arange(0.0, 360.0, 30.0))
    assert nearest_index(theta, math.radians(355.0)) == 0
    assert nearest_index(theta, math.radians(-20.0)) == 11
    assert nearest_index(theta, math.radians(76.0)) == 3
    assert nearest_index(theta, 2 * math.pi + math.radians(44.0)) == 1


# --------------------------------------------------------------------------------------------
# The largest bearing load
# --------------------------------------------------------------------------------------------


def test_max_load_index_takes_the_first_of_equal_loads_and_the_largest_otherwise():
    forces = np.zeros((4, 3, 2))
    forces[0, 1] = (-70.0, 70.0)                       # |F| = 99.0 N
    forces[1, 2] = (60.0, 80.0)                        # |F| = 100 N
    forces[2, 0] = (0.0, -100.0 * (1 + 1e-12))         # the same load, a round-off larger, later
    assert max_load_index(forces) == (1, 2)
    forces[2, 0] = (0.0, -100.0 * (1 + 1e-6))          # truly larger
    assert max_load_index(forces) == (2, 0)
    forces[3, 0] = (150.0, 0.0)
    assert max_load_index(forces) == (3, 0)


def test_feature_names_are_numbered_from_one_for_users():
    assert [postprocess.feature_label(n) for n in ("profile", "central_hole", "bore_0", "hole_2", "slot_1")] == [
        "tooth profile", "central hole", "bore 1", "hole 3", "slot_1"]
    names = [postprocess.user_feature_name(n) for n in ("bore_0", "hole_2", "profile")]
    assert names == ["bore_1", "hole_3", "profile"]


def test_one_naming_of_features_on_screen_in_reports_and_messages():
    """What is printed names a feature as the check's messages do ("bore 1", the README's promise),
    from the mesh's name (from 0) and from the files' identifier (from 1) alike."""
    from rvfem.geometry.features import feature_text

    for mesh_name in ("bore_0", "bore_2", "hole_0", "hole_4", "central_hole", "profile"):
        words = postprocess.feature_label(mesh_name)
        assert words == feature_text(mesh_name).removeprefix("the ")
        assert postprocess.user_feature_label(postprocess.user_feature_name(mesh_name)) == words
        assert "_" not in words


# --------------------------------------------------------------------------------------------
# A solved load cycle
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def solved(tmp_path_factory):
    """The CRV-80E on a coarse mesh, a load cycle at 30° with its stress envelope, and the
    snapshots of all its angles rebuilt from its solutions."""
    case = coarse_case("crv80e")
    system = cycle_module.build_system(case, mesh_case(case, tmp_path_factory.mktemp("meshes")))
    theta = np.radians(np.arange(0.0, 360.0, 30.0))
    cyc = cycle_module.load_cycle(system, theta, saved_angles_deg=(60.0,), stress_envelope=True)
    every = field_snapshots(system, dataclasses.replace(cyc, fields={}), extra_angles=theta)
    return system, cyc, every


def test_a_rebuilt_field_is_the_field_the_cycle_kept(solved):
    system, cyc, every = solved
    kept = field_snapshots(system, cyc)
    assert 60.0 in [round(s.theta_deg, 9) for s in kept]
    by_index = {s.index: s for s in every}
    for s in kept:
        again = by_index[s.index]
        scale = np.abs(s.displacement).max()
        np.testing.assert_allclose(again.displacement, s.displacement, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(again.stress.nodal.von_mises, s.stress.nodal.von_mises, rtol=1e-9,
                                   atol=1e-12 * s.stress.nodal.von_mises.max())


def test_the_envelope_peak_is_the_peak_over_every_angle(solved):
    system, cyc, every = solved
    points, boundaries = system.mesh.points, system.mesh.boundaries
    band = {"profile": 3.6, **{f"bore_{i}": 3.6 for i in range(3)}}      # six elements of the coarse mesh
    for exclude in (None, band):
        from_cycle = peak_von_mises(cyc, points, boundaries, exclude=exclude)
        from_fields = peak_von_mises(every, points, boundaries, exclude=exclude)
        assert from_cycle.von_mises_MPa == pytest.approx(from_fields.von_mises_MPa, rel=1e-9)
        assert (from_cycle.x_mm, from_cycle.y_mm) == (from_fields.x_mm, from_fields.y_mm)
        assert from_cycle.theta_deg == pytest.approx(from_fields.theta_deg)
        assert from_cycle.feature == from_fields.feature
    away = peak_von_mises(cyc, points, boundaries, exclude=band)
    assert away.von_mises_MPa < peak_von_mises(cyc, points, boundaries).von_mises_MPa
    # the band kept every vertex within it out
    assert postprocess._mask(np.asarray(points), boundaries, band)[postprocess.vertex_of(np.asarray(points), away)]


def test_hot_spot_histories_are_the_stresses_of_every_angle(solved):
    """By influence coefficients (Maxwell–Betti): the same vertex stresses as the full fields."""
    system, cyc, every = solved
    points, boundaries = system.mesh.points, system.mesh.boundaries
    spots = {"contact_zone": peak_von_mises(cyc, points, boundaries),
             "structural": peak_von_mises(cyc, points, boundaries, exclude={"profile": 3.6})}
    history = postprocess.hot_spot_history(system, cyc, spots, {"structural": 1.1})
    assert history.names == ("contact_zone", "structural") and history.p2_factor == (1.0, 1.1)
    by_index = {s.index: s for s in every}
    for j, v in enumerate(history.vertices):
        assert v == postprocess.vertex_of(np.asarray(points), spots[history.names[j]])
        for k in range(len(cyc.theta)):
            nodal = by_index[k].stress.nodal
            scale = nodal.von_mises.max()
            assert history.von_mises[k, j] == pytest.approx(nodal.von_mises[v], rel=1e-7, abs=1e-9 * scale)
            assert history.s1[k, j] == pytest.approx(nodal.s1[v], rel=1e-7, abs=1e-9 * scale)
            assert history.s2[k, j] == pytest.approx(nodal.s2[v], rel=1e-7, abs=1e-9 * scale)
    # the envelope's peak value is the history's largest value at the contact-zone hot spot
    assert history.von_mises[:, 0].max() == pytest.approx(spots["contact_zone"].von_mises_MPa, rel=1e-9)
