"""How results are written into ``summary.json`` (and ``rvfem rigid --json``): strict JSON, crank
angles rounded, stress locations and load statistics as objects. Shared by every section."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from rvfem.case.schema import toml_literal
from rvfem.errors import CaseError
from rvfem.evaluate.postprocess import user_feature_name

__all__ = ["ANGLE_DECIMALS", "angle", "json_ready", "peak_dict", "stats_dict", "toml_text"]

ANGLE_DECIMALS = 6
"""Crank angles in ``summary.json`` and ``rvfem rigid --json`` are rounded to this many decimals
(no float noise such as 255.00000000000003; every step rvfem accepts is a whole multiple of
1e-6°)."""


def angle(deg: float | None) -> float | None:
    """A crank angle for the user, degrees, rounded to :data:`ANGLE_DECIMALS` (None stays None)."""
    return None if deg is None else round(float(deg), ANGLE_DECIMALS) + 0.0


def json_ready(obj: Any) -> Any:
    """A copy of ``obj`` that :func:`json.dumps` writes as strict JSON.

    Numpy scalars become Python numbers, tuples lists, dataclasses dicts, and non-finite floats
    (an infinite life at zero load, a ratio that cannot be formed) become ``None`` (JSON
    ``null``): ``Infinity`` and ``NaN`` are not JSON and most readers reject them.
    """
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return json_ready(dataclasses.asdict(obj))
    if isinstance(obj, dict):
        return {str(k): json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_ready(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_ready(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    return obj


def peak_dict(peak: Any) -> dict[str, Any]:
    """Where a stress peak is (:class:`rvfem.evaluate.postprocess.PeakStress`): the ``…_at`` objects."""
    return {
        "x_mm": peak.x_mm,
        "y_mm": peak.y_mm,
        "radius_mm": peak.radius_mm,
        "theta_deg": angle(peak.theta_deg),
        "feature": user_feature_name(peak.feature),
        "feature_label": peak.feature_label,
        "distance_to_feature_mm": peak.distance_to_feature_mm,
    }


def stats_dict(s: Any) -> dict[str, Any]:
    """Load statistics of one bearing over the cycle (:class:`rvfem.evaluate.compare.LoadStats`)."""
    return {
        "max_load_N": s.max_N,
        "max_at_deg": angle(s.max_at_deg),
        "min_load_N": s.min_N,
        "min_at_deg": angle(s.min_at_deg),
        "equivalent_load_N": s.equivalent_N,
        "L10h_h": s.L10h,
    }


def toml_text(value: Any) -> str:
    """A case value as it is written in a case file (TOML): ``true``, ``0.0``, ``"text"``,
    ``[1.0, 2.0]``, ``{equidistant = 0.0, shift = 0.0}`` (no Python ``True`` or dicts in what users
    read; :func:`rvfem.case.schema.toml_literal` with bare keys), or ``str(value)`` for anything TOML
    cannot hold."""
    try:
        return toml_literal(value, bare_keys=True)
    except CaseError:
        return str(value)
