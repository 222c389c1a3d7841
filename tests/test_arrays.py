"""The small array utilities of ``rvfem._arrays``."""

from __future__ import annotations

import numpy as np

from rvfem._arrays import points_in_polygon, single_threaded_blas


def test_points_in_a_convex_polygon_are_those_inside_every_edge():
    """Against the half-plane test of a regular hexagon (inside iff left of every edge)."""
    t = np.linspace(0.0, 2.0 * np.pi, 6, endpoint=False) + 0.1
    hexagon = np.c_[np.cos(t), np.sin(t)] * 5.0
    pts = np.random.default_rng(3).uniform(-6.0, 6.0, (20000, 2))
    edge = np.roll(hexagon, -1, axis=0) - hexagon
    rel = pts[:, None, :] - hexagon[None, :, :]
    left = edge[None, :, 0] * rel[..., 1] - edge[None, :, 1] * rel[..., 0] > 0.0
    assert np.array_equal(points_in_polygon(pts, hexagon), left.all(axis=1))


def test_points_in_a_star_shaped_polygon_follow_its_radius():
    """A finely sampled lobed outline r(φ) = 10 + 3 sin 7φ (both orientations):
    points well inside or outside (1 % away from the outline's radius at their angle) are
    classified by comparing their radius with it; also with a single band."""
    phi = np.linspace(0.0, 2.0 * np.pi, 4000, endpoint=False)
    r = 10.0 + 3.0 * np.sin(7.0 * phi)
    outline = np.c_[r * np.cos(phi), r * np.sin(phi)]
    pts = np.random.default_rng(4).uniform(-14.0, 14.0, (20000, 2))
    rad = np.hypot(pts[:, 0], pts[:, 1])
    at = 10.0 + 3.0 * np.sin(7.0 * np.arctan2(pts[:, 1], pts[:, 0]))
    clear = np.abs(rad / at - 1.0) > 0.01
    for poly in (outline, outline[::-1]):
        inside = points_in_polygon(pts, poly)
        assert np.array_equal(points_in_polygon(pts, poly, bins=1), inside)
        assert np.array_equal(inside[clear], (rad < at)[clear])


def test_single_threaded_blas_limits_and_restores():
    """Inside the context BLAS has one thread; nesting is allowed."""
    from threadpoolctl import threadpool_info

    with single_threaded_blas():
        with single_threaded_blas():
            assert all(i["num_threads"] == 1 for i in threadpool_info() if i["user_api"] == "blas")
