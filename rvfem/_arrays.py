"""Small array helpers shared by the modules."""

from __future__ import annotations

import numpy as np


def readonly(a, dtype=None) -> np.ndarray:
    """A C-contiguous, write-protected copy or view of ``a`` (for arrays held by frozen dataclasses)."""
    a = np.ascontiguousarray(a, dtype=dtype)
    a.setflags(write=False)
    return a
