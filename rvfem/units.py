"""The unit conversions the package makes in more than one place, defined once.

Torques are N·m at the case's and the results' surface and N·mm inside the model (lengths in mm,
forces in N); rotations are rad inside the model and arcmin (or arcsec) where the catalogues give
rigidity, lost motion and transmission error.
"""

from __future__ import annotations

import math

__all__ = ["ARCMIN_PER_RAD", "ARCSEC_PER_RAD", "NMM_PER_NM", "arcmin_from_rad", "crank_angle_deg", "nm_from_nmm",
           "nmm_from_nm"]

NMM_PER_NM = 1000.0
"""N·mm per N·m."""

ARCMIN_PER_RAD = 180.0 * 60.0 / math.pi
"""Arc minutes per radian (10 800/π ≈ 3437.75)."""

ARCSEC_PER_RAD = ARCMIN_PER_RAD * 60.0
"""Arc seconds per radian (648 000/π ≈ 206 264.8)."""


def nmm_from_nm(torque_Nm):
    """A torque in N·mm from N·m (float or ndarray)."""
    return torque_Nm * NMM_PER_NM


def nm_from_nmm(torque_Nmm):
    """A torque in N·m from N·mm (float or ndarray)."""
    return torque_Nmm / NMM_PER_NM


def arcmin_from_rad(angle_rad):
    """An angle in arc minutes from rad (float or ndarray)."""
    return angle_rad * ARCMIN_PER_RAD


def crank_angle_deg(angle_rad: float) -> float:
    """A crank (or roller) angle in degrees from rad, rounded to 1e-9° for the tables: the cycle's
    angles are k·step in rad, and their degrees read 3.0, not 3.0000000000000004 (1e-9° is far
    below the smallest step of a case, 0.05°)."""
    return round(math.degrees(float(angle_rad)), 9)
