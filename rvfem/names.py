"""The names of the disc's features as rvfem writes them, defined once.

Mesh boundaries and features are named in code by 0-based keys (``bore_0``, ``hole_2``,
``profile``, ``central_hole``); whatever a user reads numbers them from 1, like the bearings and
the pins. A leaf module (no imports of the package): the processes that only draw (the render
worker, the plot worker) name features without importing the model.
"""

from __future__ import annotations

__all__ = ["FEATURE_LABELS", "feature_label", "feature_text", "user_feature_label"]


def feature_text(name: str) -> str:
    """A feature's name as messages give it, numbered from 1 like bearings and pins: ``bore_0`` →
    "bore 1" (the bore of bearing 1), ``hole_2`` → "hole 3", ``central_hole`` → "the central hole",
    ``profile`` → "the tooth profile"; other names unchanged."""
    if name == "central_hole":
        return "the central hole"
    if name == "profile":
        return "the tooth profile"
    stem, _, number = name.rpartition("_")
    if stem in ("bore", "hole") and number.isdigit():
        return f"{stem} {int(number) + 1}"
    return name


FEATURE_LABELS = {
    "profile": "tooth profile",
    "central_hole": "central hole",
}
"""Readable names of the mesh boundaries (bores and holes are numbered, see :func:`feature_label`)."""


def feature_label(name: str) -> str:
    """Readable name of a mesh boundary, numbered from 1 as everything rvfem prints names it (the
    words of the check's messages, :func:`feature_text`, without the article): ``bore_0`` →
    ``bore 1`` (the bore of bearing 1), ``hole_2`` → ``hole 3`` (lightening hole 3), ``profile``
    → ``tooth profile``, ``central_hole`` → ``central hole``."""
    if name in FEATURE_LABELS:
        return FEATURE_LABELS[name]
    return feature_text(name)


def user_feature_label(name: str) -> str:
    """:func:`feature_label` of a name numbered from 1 already (the ``feature`` of ``summary.json``,
    :func:`rvfem.evaluate.postprocess.user_feature_name`): ``bore_1`` → ``bore 1``,
    ``central_hole`` → ``central hole``."""
    if name in FEATURE_LABELS:
        return FEATURE_LABELS[name]
    stem, _, number = name.rpartition("_")
    if stem in ("bore", "hole") and number.isdigit():
        return f"{stem} {number}"
    return name
