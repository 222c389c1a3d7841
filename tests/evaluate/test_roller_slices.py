"""The slice model of the crank-bearing rollers against independent references: Hertz line contact,
a full two-dimensional half-space (boundary-element) solve written here, the published Hertz check
of Zhang et al., the logarithmic profile's design property and the profile ranking of Zhang et al."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rvfem.case.definition import RollerProfile
from rvfem.evaluate import roller_slices as rs
from rvfem.evaluate.hertz import composite_modulus, hertz_line_contact, reduced_radius

E_STAR = composite_modulus(206000.0, 0.3)                  # steel on steel, MPa
R_INNER = reduced_radius(2.5, 13.0, concave=False)         # RV-40E roller on its 13 mm eccentric, mm
LENGTH = 9.0                                               # L_we, mm


# --------------------------------------------------------------------------------------------
# An independent half-space contact solve: a grid of rectangles over the whole contact area
# (x along the roller, y across), the contact width solved, not assumed
# --------------------------------------------------------------------------------------------


def _corner(u, v):
    """∫∫ dx dy / r over [0, u] × [0, v] with the log form u·ln((v + r)/|u|) + v·ln((u + r)/|v|)."""
    r = np.sqrt(u * u + v * v)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = np.where(u != 0, np.abs(u) * np.log((np.abs(v) + r) / np.abs(u)), 0.0)
        t2 = np.where(v != 0, np.abs(v) * np.log((np.abs(u) + r) / np.abs(v)), 0.0)
    return np.sign(u) * np.sign(v) * (t1 + t2)


def _bem_contact(load, length, r_red, drop_fn, nx, ny, half_span):
    """Pressure on an nx × ny grid of rectangles over [−L/2, L/2] × [−half_span, half_span]: the
    half-space displacement (Boussinesq over rectangles) equals the approach minus the gap
    h = y²/(2R') + drop(x) where p > 0, p ≥ 0 elsewhere, Σp·ΔA = Q (active set)."""
    xe = np.linspace(-length / 2, length / 2, nx + 1)
    ye = np.linspace(-half_span, half_span, ny + 1)
    xc, yc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1])
    hx, hy = 0.5 * np.diff(xe)[0], 0.5 * np.diff(ye)[0]
    X, Y = np.meshgrid(xc, yc, indexing="ij")
    px, py = X.ravel(), Y.ravel()
    dx = px[None, :] - px[:, None]
    dy = py[None, :] - py[:, None]
    C = (_corner(dx + hx, dy + hy) - _corner(dx - hx, dy + hy) - _corner(dx + hx, dy - hy)
         + _corner(dx - hx, dy - hy)) / (math.pi * E_STAR)
    gap = py**2 / (2 * r_red) + drop_fn(px)
    area = 4 * hx * hy
    n = px.size
    active = gap < np.quantile(gap, 0.5)
    for _ in range(100):
        s = np.flatnonzero(active)
        m = np.zeros((s.size + 1, s.size + 1))
        m[:-1, :-1] = C[np.ix_(s, s)]
        m[:-1, -1] = -1.0
        m[-1, :-1] = area
        sol = np.linalg.solve(m, np.concatenate([-gap[s], [load]]))
        p = np.zeros(n)
        p[s] = sol[:-1]
        delta = sol[-1]
        sep = C @ p - delta + gap
        neg = active & (p < 0)
        pen = ~active & (sep < -1e-9)
        if not neg.any() and not pen.any():
            return xc, yc, p.reshape(nx, ny), 2 * hy
        active = (active & ~neg) | pen
    raise AssertionError("the reference contact did not settle")


def test_love_rectangle_gives_the_centre_of_a_square():
    # Johnson, Contact Mechanics, §3.9: centre of a uniformly loaded square of side 2a:
    # w = 8·p·a·ln(1 + √2)/(π·E*) ≈ 2.24·p·a/E* (both bodies through E*)
    c = rs.rectangle_influence([0.0], [2.0], 1.0, 1.0)
    assert c[0, 0] == pytest.approx(8 * math.log(1 + math.sqrt(2)) / math.pi, rel=1e-12)


def test_hertz_at_mid_length_of_a_long_straight_roller_against_the_2d_half_space():
    # the independent grid solve of a straight roller: at mid-length the pressure across the strip
    # is Hertz's ellipse of the local load per length (peak and half-width < 1 %)
    q = 1978.0
    b0 = hertz_line_contact(q, LENGTH, 2.5, 13.0, concave=False).half_width_mm
    xc, yc, p, dy = _bem_contact(q, LENGTH, R_INNER, lambda x: 0.0 * x, 30, 41, 1.25 * b0)
    mid = p[len(xc) // 2 - 1: len(xc) // 2 + 1].mean(axis=0)
    line = mid.sum() * dy
    ph, b = rs.hertz_peak_from_line_load(line, R_INNER, E_STAR)
    peak = mid.max()
    b_moment = 2.0 * math.sqrt(float(np.sum(mid * yc**2) / np.sum(mid)))   # ∫p y² / ∫p = b²/4 for Hertz
    assert peak == pytest.approx(ph, rel=0.01)
    assert b_moment == pytest.approx(b, rel=0.01)
    # the half-space takes less load per length at mid-length than Q/L (the ends carry more)
    assert 0.90 < line / (q / LENGTH) < 0.97


@pytest.mark.parametrize("kind", ["straight", "combined", "arc", "logarithmic"])
def test_slice_model_against_the_2d_half_space(kind):
    # sharp ends (corner_radius = 0), the roller the grid below models: contact only over L
    q = 1978.0
    prof = RollerProfile(kind=kind, crown_radius=500.0, modification_length=1.23, modification_drop=0.006,
                         design_load_N=q, corner_radius=0.0)
    # 60 slices: at 30 the slices of the body are 0.5 mm wide, and the combined roller's slice
    # where its pressure falls steeply towards the lifted end is 12 % low against the grid
    slices = 60
    c = rs.roller_contact(q, LENGTH, R_INNER, E_STAR, prof, slices=slices)
    b0 = hertz_line_contact(q, LENGTH, 2.5, 13.0, concave=False).half_width_mm
    drop = lambda x: rs.profile_drop(prof, LENGTH, x, composite_modulus_MPa=E_STAR, reduced_radius_mm=R_INNER)
    span = 1.6 * b0 if kind == "arc" else 1.3 * b0
    nx = 60
    xc, yc, p, dy = _bem_contact(q, LENGTH, R_INNER, drop, nx, 27, span)
    grid_line = p.sum(axis=1) * dy
    assert grid_line.sum() * LENGTH / nx == pytest.approx(q, rel=1e-9)
    # the grid's load per length over each slice (the slices are refined at the ends, the grid is not)
    cum = np.concatenate([[0.0], np.cumsum(grid_line * LENGTH / nx)])
    grid_edges = np.linspace(-LENGTH / 2, LENGTH / 2, nx + 1)
    # averaged as the slice model reports it: over ±b about the slice (over the slice where it is
    # wider than 2b), zero beyond the roller
    dx = c.widths_mm
    h = np.maximum(b0, dx / 2)
    line = (np.interp(c.x_mm + h, grid_edges, cum) - np.interp(c.x_mm - h, grid_edges, cum)) / (2 * h)
    ph_bem, _ = rs.hertz_peak_from_line_load(line, R_INNER, E_STAR)
    # away from the very edge of the contact: slices at least a grid cell wide whose neighbours
    # both carry load in the models (for the arc also away from where either contact ends)
    loaded = (ph_bem > 0) & (c.pressure_MPa > 0)
    inner = loaded & np.roll(loaded, 1) & np.roll(loaded, -1) & (dx >= LENGTH / nx)
    inner[[0, -1]] = False
    # and more than 2b from where either contact ends (the slice model reports line loads
    # averaged over ±b, which reach past a contact's end)
    ends = np.concatenate([c.x_mm[~loaded], [-LENGTH / 2, LENGTH / 2]])
    inner &= np.min(np.abs(c.x_mm[:, None] - ends[None, :]), axis=1) > 2 * b0
    assert dx[inner].sum() >= 0.6 * LENGTH
    np.testing.assert_allclose(c.pressure_MPa[inner], ph_bem[inner], rtol=0.05)
    assert c.peak_pressure_MPa == pytest.approx(ph_bem.max(), rel=0.10)


def test_zhang_hertz_check_and_the_rv40e_geometry():
    # Zhang et al.: p_h = 2Q/(π·L·b) with their b = 95 µm, Q = 1978 N, L = 8.5 mm gives 1.56 GPa
    q, L = 1978.0, 8.5
    assert 2 * q / (math.pi * L * 0.095) == pytest.approx(1560.0, rel=0.005)
    # the effective radius behind their b: R' = π·L·E*·b²/(4Q) ≈ 3.45 mm
    assert math.pi * L * E_STAR * 0.095**2 / (4 * q) == pytest.approx(3.45, rel=0.01)
    # the RV-40E crank bearing (D_we 5 mm on a 13 mm eccentric radius) at the same load and length
    h = hertz_line_contact(q, L, 2.5, 13.0, concave=False)
    assert h.half_width_mm == pytest.approx(0.074, rel=0.01)
    assert h.peak_pressure_MPa == pytest.approx(2000.0, rel=0.01)


def test_logarithmic_profile_is_flat_at_its_design_load():
    q = 1978.0
    # the profile's design property over the effective length: sharp ends (no corners beyond)
    c = rs.roller_contact(q, LENGTH, R_INNER, E_STAR, RollerProfile(kind="logarithmic", design_load_N=q,
                                                                    corner_radius=0.0), slices=60)
    nominal, _ = rs.hertz_peak_from_line_load(q / LENGTH, R_INNER, E_STAR)
    core = np.abs(c.x_mm) < 0.4 * LENGTH                   # the inner 80 % of the length
    # Johns–Gohar's drop is the sag of a uniform strip load on the half-space (Lundberg): at Q_d
    # the pressure is uniform; only the last slices, where the finite drop ends, move at all
    assert c.pressure_MPa[core].max() / c.pressure_MPa[core].min() - 1.0 < 1e-3
    b_d = hertz_line_contact(q, LENGTH, 2.5, 13.0, concave=False).half_width_mm
    within = np.abs(c.x_mm) < 0.5 * LENGTH - 2 * b_d       # to within 2b of the ends (reported over ±b)
    loaded = c.pressure_MPa[within & (c.pressure_MPa > 0)]
    assert loaded.size == within.sum() and loaded.max() / loaded.min() - 1.0 < 0.02
    # the profile's finite end drop leaves a rise of the load per length within a few µm of the
    # ends (b²/l ≈ 1 µm), which the end-refined slices resolve: 1.7 % over ±b there
    assert c.edge_factor < 1.02
    # above its design load the profile's drop is used up towards the ends: edge peaks return
    over = rs.roller_contact(2 * q, LENGTH, R_INNER, E_STAR, RollerProfile(kind="logarithmic", design_load_N=q),
                             slices=60)
    assert over.edge_factor > 1.1
    # a straight roller at the same load is far from flat
    s = rs.roller_contact(q, LENGTH, R_INNER, E_STAR, RollerProfile(), slices=60)
    assert s.pressure_MPa.max() / s.pressure_MPa[core].min() - 1.0 > 0.25


def _profiles():
    return {"straight": RollerProfile(), "arc": RollerProfile(kind="arc", crown_radius=500.0),
            "combined": RollerProfile(kind="combined", modification_length=1.23, modification_drop=0.006)}


def test_zhang_profile_ranking_at_1978_N_and_how_it_moves_with_load():
    half = LENGTH / 2
    res = {k: rs.roller_contact(1978.0, LENGTH, R_INNER, E_STAR, p, slices=60) for k, p in _profiles().items()}
    where = {k: abs(c.x_mm[int(np.argmax(c.pressure_MPa))]) for k, c in res.items()}
    assert where["straight"] > 0.95 * half                 # edge peaks
    assert where["arc"] < 0.05 * half                      # centre peak
    peaks = {k: c.peak_pressure_MPa for k, c in res.items()}
    assert peaks["combined"] == min(peaks.values())        # lowest peak
    assert peaks["arc"] > peaks["straight"]                # as in Zhang et al. (1.32 p_h against 1.24 p_h)
    # at a few times the load the 6 µm drop is used up: the combined roller with sharp ends loads
    # its ends (with the 0.2 mm corners the junction at l − a stays the peak at 8000 N)
    sharp = RollerProfile(kind="combined", modification_length=1.23, modification_drop=0.006, corner_radius=0.0)
    heavy = rs.roller_contact(8000.0, LENGTH, R_INNER, E_STAR, sharp, slices=60)
    light = rs.roller_contact(1978.0, LENGTH, R_INNER, E_STAR, sharp, slices=60)
    ends = np.abs(heavy.x_mm) > 0.95 * half
    assert heavy.pressure_MPa[ends].max() > heavy.pressure_MPa[np.abs(heavy.x_mm) < 0.5 * half].max()
    assert light.pressure_MPa[ends].max() < light.pressure_MPa[np.abs(light.x_mm) < 0.5 * half].max()


def test_rigid_ring_roller_loads_balance_the_bearing_force():
    rng = np.random.default_rng(3)
    f = rng.normal(size=(5, 2)) * 1000.0
    psi = rng.uniform(0, 2 * np.pi, size=(5, 1)) + 2 * np.pi * np.arange(14) / 14
    q = rs.rigid_ring_roller_loads(f, psi)
    resultant = np.stack([(q * np.cos(psi)).sum(axis=1), (q * np.sin(psi)).sum(axis=1)], axis=1)
    np.testing.assert_allclose(resultant, f, rtol=1e-12)
    assert (q >= 0).all()


# --------------------------------------------------------------------------------------------
# A roller with rounded corners against an independent strip solve on the half-space
# --------------------------------------------------------------------------------------------


def _strip_reference(load, length, corner, r_red, half_width):
    """Load per length (N/mm) of a straight roller with round corners of radius ``corner``, from
    strips of the contact (width 2·half_width) over the half-space, written here: its own grid
    (50 µm strips along the body, 1 µm over the last 60 µm of it and the first 30 µm of the corner,
    10 µm beyond), Boussinesq's displacement of uniformly loaded rectangles (_corner), and a
    compression-only active set. Gap: 0 along the body, r − √(r² − u²) on the corner."""
    half = length / 2
    right = np.unique(np.round(np.concatenate([
        np.arange(0.0, half - 0.06, 0.05), np.arange(half - 0.06, half + 0.03, 0.001),
        np.arange(half + 0.03, half + corner, 0.01), [half + corner]]), 9))
    edges = np.concatenate([-right[:0:-1], right])
    xc, w = 0.5 * (edges[1:] + edges[:-1]), np.diff(edges)
    u = np.clip(np.abs(xc) - half, 0.0, corner)
    gap = corner - np.sqrt(corner**2 - u**2)
    dx = xc[:, None] - xc[None, :]
    hx = 0.5 * w[None, :]
    hy = half_width
    c = (_corner(dx + hx, hy) - _corner(dx - hx, hy) - _corner(dx + hx, -hy)
         + _corner(dx - hx, -hy)) / (math.pi * E_STAR)
    area = 2 * hy * w
    active = u == 0.0
    for _ in range(100):
        s = np.flatnonzero(active)
        m = np.zeros((s.size + 1, s.size + 1))
        m[:-1, :-1] = c[np.ix_(s, s)]
        m[:-1, -1] = -1.0
        m[-1, :-1] = area[s]
        sol = np.linalg.solve(m, np.concatenate([-gap[s], [load]]))
        p = np.zeros(xc.size)
        p[s] = sol[:-1]
        sep = c @ p - sol[-1] + gap
        neg = active & (p < 0)
        pen = ~active & (sep < -1e-12)
        if not neg.any() and not pen.any():
            return xc, w, p * 2 * hy
        active = (active & ~neg) | pen
    raise AssertionError("the strip reference did not settle")


def _section_peak(xc, w, q, b):
    """Largest mean of the piecewise constant q over a window [a − b, a + b] (zero beyond the roller),
    a sampled every b/50: the section line load whose Hertz peak the slice model reports."""
    cum = np.concatenate([[0.0], np.cumsum(q * w)])
    edges = np.concatenate([[xc[0] - w[0] / 2], xc + w / 2])
    a = np.arange(edges[0], edges[-1], b / 50)
    load = np.interp(a + b, edges, cum) - np.interp(a - b, edges, cum)
    return float(load.max() / (2 * b))


@pytest.mark.parametrize("load", [500.0, 1300.0, 2500.0])
def test_round_cornered_roller_against_an_independent_strip_solve(load):
    # the shipped straight roller (corner radius 0.2 mm) at the default 30 slices, strips of the
    # nominal Hertz width (no local-width iteration, the same physics in both): the peak and the
    # mid-length pressure against a reference of 392 strips, 1 µm at the ends
    corner = 0.2
    prof = RollerProfile(corner_radius=corner)
    b0 = hertz_line_contact(load, LENGTH, 2.5, 13.0, concave=False).half_width_mm
    xc, w, q = _strip_reference(load, LENGTH, corner, R_INNER, b0)
    assert np.sum(q * w) == pytest.approx(load, rel=1e-9)
    assert q[np.abs(xc) > LENGTH / 2].sum() > 0                  # the contact runs onto the corners
    peak_ref, _ = rs.hertz_peak_from_line_load(_section_peak(xc, w, q, b0), R_INNER, E_STAR)
    mid_ref, _ = rs.hertz_peak_from_line_load(np.interp(0.0, xc, q), R_INNER, E_STAR)
    c = rs.roller_contact(load, LENGTH, R_INNER, E_STAR, prof, local_width_iterations=0)
    mid = float(np.interp(0.0, c.x_mm, c.pressure_MPa))
    assert c.peak_pressure_MPa == pytest.approx(float(peak_ref), rel=0.05)
    assert mid == pytest.approx(float(mid_ref), rel=0.02)
    # the corner bounds the edge: the peak stays within twice the nominal Hertz pressure
    assert c.edge_factor < 2.0


def test_rigid_ring_roller_loads_balance_a_light_force_within_a_wide_clearance():
    """12.5 N within 20 µm of radial play (a light phase of a bearing on the flexible disc): the rings
    close the play and the rollers balance the force (Newton's step once overshot without bound
    there, giving 10¹³ N)."""
    z, length = 14, 9.0
    psi = 0.3 + 2 * np.pi * np.arange(z) / z
    for force in (np.array([-11.83, -4.05]), np.array([0.5, 0.0]), np.array([2500.0, -900.0])):
        q = rs.rigid_ring_roller_loads(force, psi, radial_clearance_mm=0.02, roller_length_mm=length)
        e = np.stack([np.cos(psi), np.sin(psi)], axis=-1)
        assert q @ e == pytest.approx(force, abs=1e-9 * np.linalg.norm(force))
        assert q.max() <= np.linalg.norm(force)       # one roller can carry at most the force


# --------------------------------------------------------------------------------------------
# The cycle's solver: one solve per distinct active set, against one dense solve per contact
# --------------------------------------------------------------------------------------------


def _dense_contact(c, area, g, load):
    """One contact by the textbook active set: [C_SS, −1; A_S, 0]·[p_S; δ] = [g_S; Q] for the set
    S, drop the slices in tension, add the penetrating ones (every slice in contact at first)."""
    n = g.size
    act = np.ones(n, dtype=bool)
    for _ in range(100):
        s = np.flatnonzero(act)
        mat = np.zeros((s.size + 1, s.size + 1))
        mat[:-1, :-1] = c[np.ix_(s, s)]
        mat[:-1, -1] = -1.0
        mat[-1, :-1] = area[s]
        sol = np.linalg.solve(mat, np.concatenate([g[s], [load]]))
        p = np.zeros(n)
        p[s] = sol[:-1]
        gap = c @ p - (sol[-1] + g)
        new = act & (p >= 0.0) | ~act & (gap < -1e-12 * abs(sol[-1]))
        if np.array_equal(new, act):
            return p, sol[-1]
        act = new
    raise AssertionError("the reference active set did not settle")


@pytest.mark.parametrize("kind", ["straight", "logarithmic"])
def test_slice_solver_equals_one_dense_solve_per_contact(kind):
    """The shipped roller (0.2 mm corners) with 120 end-refined slices, loads from 30 to 4000 N and
    tilts of ±0.5 mrad, as a cycle solves them (:class:`SliceSolver`, shapes x and z): equal to a
    dense bordered solve of every contact to round-off; then a second call on the same solver
    with heavier loads, whose contacts reach slices the first call's reach left out."""
    prof = RollerProfile(kind=kind, corner_radius=0.2, design_load_N=2000.0, slices=120)
    x, dx = rs.slice_layout(prof, LENGTH)
    z = rs.profile_drop(prof, LENGTH, x, composite_modulus_MPa=E_STAR, reduced_radius_mm=R_INNER)
    b = 0.07
    c = rs.rectangle_influence(x, dx, b, E_STAR)
    area = 2.0 * b * dx
    solver = rs.SliceSolver(c, area, np.stack([x, z]))
    rng = np.random.default_rng(3)
    for loads in (np.geomspace(30.0, 4000.0, 40), np.geomspace(5000.0, 20000.0, 6)):
        tilts = rng.uniform(-5e-4, 5e-4, loads.size)
        p, delta = solver.solve(np.stack([tilts, -np.ones(loads.size)], axis=1), loads)
        for k in range(loads.size):
            p_ref, d_ref = _dense_contact(c, area, tilts[k] * x - z, loads[k])
            np.testing.assert_allclose(p[k], p_ref, rtol=0, atol=1e-9 * p_ref.max())
            assert delta[k] == pytest.approx(d_ref, rel=1e-9)
    assert solver._reach_known and not solver._reach.all()            # the reach was used ...
    heavy = solver._masks[:solver._count] & ~solver._reach
    assert heavy.any()                                                 # ... and passed by the heavy loads


def test_influence_of_slices_on_one_line_equals_the_four_corner_sum():
    """The slices' influence on one line (two corner-function terms, the function being odd across
    the strip) equals Love's four-corner sum of the general grid of rectangles, to round-off, on
    end-refined slices and with each slice's own strip width."""
    prof = RollerProfile(corner_radius=0.2, slices=200)
    x, dx = rs.slice_layout(prof, LENGTH)
    widths = 0.03 + 0.05 * np.cos(x / LENGTH) ** 2
    for hh in (None, widths):
        line = rs.rectangle_influence(x, dx, 0.07, E_STAR, half_heights_mm=hh)
        grid = rs.rectangle_influence(x, dx, 0.07, E_STAR, y_mm=np.zeros_like(x), half_heights_mm=hh)
        np.testing.assert_allclose(line, grid, rtol=1e-13, atol=1e-15 * np.abs(grid).max())


@pytest.mark.parametrize("slices", [30, 31, 400])
def test_the_influence_matrix_of_a_symmetric_layout_and_its_inverse_by_halves(slices):
    """The slice layout is symmetric about the roller's middle, so C is centrosymmetric and only
    half its rows are computed; C⁻¹ comes from two inverses of half the size. Both against the
    whole computation (Love's corner function on every row, ``numpy.linalg.inv``); an odd count
    and a matrix that is not centrosymmetric take the whole way."""
    from rvfem.evaluate.slice_solver import influence_inverse

    x, dx = rs.slice_layout(RollerProfile(kind="straight", slices=slices), 15.8)
    b, e_star = 0.05, 2.3e5
    c = rs.rectangle_influence(x, dx, b, e_star)
    d = x[:, None] - x[None, :]
    whole = sum(2.0 * s * rs._love(d + s * 0.5 * dx[None, :], np.full(d.shape, b)) for s in (-1.0, 1.0)) / (math.pi * e_star)
    np.testing.assert_allclose(c, whole, rtol=1e-14, atol=0)
    h = influence_inverse(c)
    np.testing.assert_allclose(h, np.linalg.inv(whole), rtol=1e-11, atol=1e-13 * np.abs(h).max())
    np.testing.assert_allclose(c @ h, np.eye(slices), atol=1e-12)
    skew = c.copy()
    skew[0, -1] *= 1.01                                       # not centrosymmetric: inverted as it is
    np.testing.assert_allclose(influence_inverse(skew) @ skew, np.eye(slices), atol=1e-12)
