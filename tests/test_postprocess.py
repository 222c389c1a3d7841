"""Tests of the helpers of rvfem.evaluate.postprocess against brute-force references."""

from __future__ import annotations

import numpy as np

from rvfem.evaluate import postprocess


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
