"""A roller-profile kind written outside rvfem, in one module: a parabolic crown with a fixed drop
at the ends of the effective length, z = δ·(2x/L)² (δ = :data:`END_DROP_MM`). A test registers it
with one line (``register_profile_kind(NAME, parabolic_drop)``)."""

from __future__ import annotations

import numpy as np

NAME = "test_parabolic"
END_DROP_MM = 0.004
"""δ, the drop at the ends of the effective length, mm."""


def parabolic_drop(profile, length_mm, x, **contact):
    """z = δ·(2x/L)², mm (the signature of rvfem.evaluate.roller_slices.PROFILE_DROPS)."""
    return END_DROP_MM * (2.0 * np.asarray(x, dtype=float) / length_mm) ** 2
