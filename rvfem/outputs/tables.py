"""CSV tables of a load cycle (one header row, comma-separated, numbers with 10 significant digits).

``bearing_loads.csv``
    One row per crank angle: ``theta_deg`` and, for every bearing i = 1…N,
    ``bearing{i}_flexible_Fx_N``, ``bearing{i}_flexible_Fy_N``, ``bearing{i}_flexible_F_N`` (FE) and
    ``bearing{i}_rigid_Fx_N``, ``bearing{i}_rigid_Fy_N``, ``bearing{i}_rigid_F_N`` (handbook; ``nan``
    where it is not defined, Zp − Zc ≠ 1), then ``bearing{i}_equal_share_Fx_N``,
    ``bearing{i}_equal_share_Fy_N``, ``bearing{i}_equal_share_F_N`` (the FE pin resultant shared
    equally) for every bearing: the force of the bearing on the disc in the disc frame and its
    magnitude.
``roller_loads.csv``
    One row per crank angle, bearing and roller (bearing model ``rollers`` only): ``theta_deg``,
    ``bearing``, ``roller`` (1-based), ``roller_angle_deg`` (position about the bore centre, disc
    frame), ``load_N``.
``pin_forces.csv``
    One row per crank angle and pin: ``theta_deg``, ``pin`` (1-based; pin k sits at
    360°·(k − 1)/Zp on the housing), ``x_mm``, ``y_mm`` (pin centre in the disc frame),
    ``flexible_N`` (FE), ``classical_N`` (classical rigid distribution with the exact moment;
    ``nan`` where it is not defined, Zp − Zc ≠ 1).
``cycle.csv``
    One row per crank angle: ``theta_deg``, ``pins_in_contact``, ``carrier_rotation_arcmin``,
    ``equilibrium_residual``, ``active_set_iterations``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from rvfem.evaluate import strength
from rvfem.outputs.csvfile import write_csv, write_csv_columns
from rvfem.units import arcmin_from_rad, crank_angle_deg

__all__ = ["write_bearing_loads", "write_roller_loads", "write_pin_forces", "write_cycle_table",
           "write_stress_history"]


def _write(path: str | os.PathLike, header: list[str], rows) -> Path:
    return write_csv(path, header, rows)


def _degrees(theta: np.ndarray) -> np.ndarray:
    """:func:`rvfem.units.crank_angle_deg` of every angle (the same numbers, one call per angle)."""
    return np.array([crank_angle_deg(t) for t in np.asarray(theta, dtype=float).ravel().tolist()], dtype=float)


def write_bearing_loads(path: str | os.PathLike, theta: np.ndarray, flexible: np.ndarray,
                        rigid: np.ndarray, equal_share: np.ndarray | None = None) -> Path:
    """Write ``bearing_loads.csv``.

    Parameters
    ----------
    path : path-like
    theta : ndarray (n,)
        Crank angles, rad.
    flexible, rigid : ndarray (n, N, 2)
        Force of each bearing on the disc, N (FE and handbook; NaN where the handbook is not
        defined).
    equal_share : ndarray (n, N, 2), optional
        The equal share of the FE pin resultant, N (its columns follow the others).
    """
    n_b = flexible.shape[1]
    models = [("flexible", flexible), ("rigid", rigid)]
    if equal_share is not None:
        models.append(("equal_share", equal_share))
    header = ["theta_deg"]
    for i in range(1, n_b + 1):
        for name, _ in models[:2]:
            header += [f"bearing{i}_{name}_Fx_N", f"bearing{i}_{name}_Fy_N", f"bearing{i}_{name}_F_N"]
    for i in range(1, n_b + 1):
        for name, _ in models[2:]:
            header += [f"bearing{i}_{name}_Fx_N", f"bearing{i}_{name}_Fy_N", f"bearing{i}_{name}_F_N"]
    mags = {name: np.linalg.norm(f, axis=2) for name, f in models}
    columns = [_degrees(theta)]
    for group in (models[:2], models[2:]):
        for i in range(n_b):
            for name, f in group:
                columns += [f[:, i, 0], f[:, i, 1], mags[name][:, i]]
    return write_csv_columns(path, header, columns)


def write_roller_loads(path: str | os.PathLike, theta: np.ndarray, roller_angles: np.ndarray,
                       roller_loads: np.ndarray) -> Path:
    """Write ``roller_loads.csv``.

    Parameters
    ----------
    path : path-like
    theta : ndarray (n,)
        rad.
    roller_angles : ndarray (n, N, Z)
        rad.
    roller_loads : ndarray (n, N, Z)
        N.
    """
    n, n_b, z = roller_loads.shape
    angles = np.array([crank_angle_deg(a) % 360.0 for a in np.asarray(roller_angles, dtype=float).ravel().tolist()])
    columns = [np.repeat(_degrees(theta), n_b * z), np.tile(np.repeat(np.arange(1, n_b + 1), z), n),
               np.tile(np.arange(1, z + 1), n * n_b), angles, np.asarray(roller_loads).reshape(-1)]
    return write_csv_columns(path, ["theta_deg", "bearing", "roller", "roller_angle_deg", "load_N"], columns)


def write_pin_forces(path: str | os.PathLike, theta: np.ndarray, pin_xy: np.ndarray, flexible: np.ndarray,
                     classical: np.ndarray) -> Path:
    """Write ``pin_forces.csv``.

    Parameters
    ----------
    path : path-like
    theta : ndarray (n,)
        rad.
    pin_xy : ndarray (n, Zp, 2)
        Pin centres in the disc frame, mm.
    flexible : ndarray (n, Zp)
        FE pin forces, N.
    classical : ndarray (n, Zp)
        Classical rigid pin forces, N.
    """
    n, zp = flexible.shape
    pin_xy = np.asarray(pin_xy)
    columns = [np.repeat(_degrees(theta), zp), np.tile(np.arange(1, zp + 1), n), pin_xy[:, :, 0].reshape(-1),
               pin_xy[:, :, 1].reshape(-1), np.asarray(flexible).reshape(-1), np.asarray(classical).reshape(-1)]
    return write_csv_columns(path, ["theta_deg", "pin", "x_mm", "y_mm", "flexible_N", "classical_N"], columns)


def write_cycle_table(path: str | os.PathLike, theta: np.ndarray, pins_in_contact: np.ndarray,
                      carrier_rotation: np.ndarray, residual: np.ndarray, iterations: np.ndarray) -> Path:
    """Write ``cycle.csv`` (per-angle solver quantities; carrier rotation given in rad, written in
    arcmin)."""
    arcmin = arcmin_from_rad(np.asarray(carrier_rotation))
    rows = ([crank_angle_deg(t), int(p), a, r, int(i)]
            for t, p, a, r, i in zip(theta, pins_in_contact, arcmin, residual, iterations))
    return _write(path, ["theta_deg", "pins_in_contact", "carrier_rotation_arcmin", "equilibrium_residual",
                         "active_set_iterations"], rows)


def write_stress_history(path: str | os.PathLike, history) -> Path:
    """Write ``stress_history.csv``: per crank angle, the stresses at each hot spot of a
    :class:`rvfem.evaluate.postprocess.HotSpotHistory`, MPa, first as the load cycle's model gives
    them, then scaled by the hot spot's P2/P1 factor: the values the fatigue check of
    ``summary.json`` uses (:func:`rvfem.evaluate.strength.hot_spot_fatigue`).

    Columns per hot spot ``<name>``: ``<name>_cycle_von_mises_MPa``, ``<name>_cycle_s1_MPa``,
    ``<name>_cycle_s2_MPa``, ``<name>_cycle_dominant_MPa`` (the cycle's element order, usually P1;
    dominant: the in-plane principal stress of larger magnitude, signed), ``<name>_p2_factor`` (the
    same number on every row; 1 where not re-solved on P2), then ``<name>_von_mises_MPa``,
    ``<name>_s1_MPa``, ``<name>_s2_MPa``, ``<name>_dominant_MPa`` and ``<name>_signed_von_mises_MPa``
    (FKM's signed von Mises stress, :func:`rvfem.evaluate.strength.signed_von_mises`): the cycle's
    values times the factor, P2-consistent at the hot spot.
    """
    header = ["theta_deg"]
    for name in history.names:
        header += [f"{name}_cycle_von_mises_MPa", f"{name}_cycle_s1_MPa", f"{name}_cycle_s2_MPa",
                   f"{name}_cycle_dominant_MPa", f"{name}_p2_factor", f"{name}_von_mises_MPa", f"{name}_s1_MPa",
                   f"{name}_s2_MPa", f"{name}_dominant_MPa", f"{name}_signed_von_mises_MPa"]
    dominant = history.dominant
    factors = np.asarray(history.p2_factor, dtype=float)
    signed = strength.signed_von_mises(factors * history.s1, factors * history.s2)
    rows = []
    for k, theta in enumerate(history.theta):
        row = [crank_angle_deg(theta)]
        for j, f in enumerate(factors):
            row += [history.von_mises[k, j], history.s1[k, j], history.s2[k, j], dominant[k, j], f,
                    f * history.von_mises[k, j], f * history.s1[k, j], f * history.s2[k, j], f * dominant[k, j],
                    signed[k, j]]
        rows.append(row)
    return _write(path, header, rows)
