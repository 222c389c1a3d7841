"""Disc stresses of a flexible load cycle: field snapshots, the stress envelope, the peak von Mises
stress and where it is.

Everything here is computed from the results of :func:`rvfem.cycle.load_cycle` (no new solve): the
displacement fields it keeps (the case's saved angles and the angle of the largest bearing load)
give the stress fields; a cycle solved with ``stress_envelope=True`` gives the largest von Mises
stress of every vertex over every solved angle. (Roller-raceway Hertz pressures are in
:mod:`rvfem.hertz`.)

Typical use::

    cycle = load_cycle(system, stress_envelope=True)
    peak = peak_von_mises(cycle, mesh.points, mesh.boundaries)
    snapshots = field_snapshots(system, cycle, extra_angles=[math.radians(peak.theta_deg)])
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import fem

__all__ = [
    "FieldSnapshot",
    "StressEnvelope",
    "PeakStress",
    "FEATURE_LABELS",
    "feature_label",
    "max_load_index",
    "nearest_index",
    "field_snapshots",
    "stress_envelope",
    "peak_von_mises",
]


@dataclass(frozen=True, eq=False)
class FieldSnapshot:
    """Displacement and stresses of the disc at one crank angle, on the mesh vertices.

    For P2 models the values are those at the mesh vertices (the linear mesh); the edge-midpoint
    nodes are not kept.

    Attributes
    ----------
    theta : float
        Crank angle, rad.
    index : int
        Position of ``theta`` in the cycle's angle array.
    displacement : ndarray (n_vertices, 2)
        Displacement as solved (disc frame, includes the disc's rigid-body motion), mm.
    deformation : ndarray (n_vertices, 2)
        ``displacement`` minus its best-fitting rigid motion (nodal least squares), mm: what the
        deformed-shape images magnify.
    rigid_motion : ndarray (3,)
        The removed rigid motion: translation x, y (mm) and rotation about the disc centre (rad).
    stress : rvfem.fem.StressFields
        Vertex (area-averaged) and element stresses, MPa.
    """

    theta: float
    index: int
    displacement: np.ndarray
    deformation: np.ndarray
    rigid_motion: np.ndarray
    stress: fem.StressFields

    @property
    def theta_deg(self) -> float:
        """Crank angle, degrees."""
        return math.degrees(self.theta)


@dataclass(frozen=True)
class PeakStress:
    """The largest von Mises stress (over every solved angle, or over given fields) and where it occurs.

    Attributes
    ----------
    von_mises_MPa : float
        Largest vertex (area-averaged) von Mises stress, MPa.
    x_mm, y_mm : float
        Position of that vertex in the disc frame, mm.
    radius_mm : float
        Its distance from the disc centre, mm.
    theta_deg : float
        Crank angle of the field, degrees.
    feature : str
        Mesh boundary nearest to the point (``profile``, ``bore_0``, ``hole_1``, ``central_hole``…).
    feature_label : str
        The same in words (``tooth profile``, ``bore of bearing 1``, ``lightening hole 2``…).
    distance_to_feature_mm : float
        Distance from the point to the nearest vertex of that boundary, mm (0 on the boundary).
    """

    von_mises_MPa: float
    x_mm: float
    y_mm: float
    radius_mm: float
    theta_deg: float
    feature: str
    feature_label: str
    distance_to_feature_mm: float


FEATURE_LABELS = {
    "profile": "tooth profile",
    "central_hole": "central hole",
}
"""Readable names of the mesh boundaries (bores and holes are numbered, see :func:`feature_label`)."""


def feature_label(name: str) -> str:
    """Readable name of a mesh boundary: ``bore_0`` → ``bore of bearing 1``, ``hole_2`` →
    ``lightening hole 3``, ``profile`` → ``tooth profile``."""
    if name in FEATURE_LABELS:
        return FEATURE_LABELS[name]
    stem, _, number = name.rpartition("_")
    if number.isdigit():
        if stem == "bore":
            return f"bore of bearing {int(number) + 1}"
        if stem == "hole":
            return f"lightening hole {int(number) + 1}"
    return name


def max_load_index(bearing_forces: np.ndarray) -> tuple[int, int]:
    """Angle index and bearing index of the largest bearing load |F| of a cycle.

    Parameters
    ----------
    bearing_forces : ndarray (n, N, 2)

    Returns
    -------
    (int, int)
    """
    loads = np.linalg.norm(bearing_forces, axis=2)
    k, i = np.unravel_index(int(np.argmax(loads)), loads.shape)
    return int(k), int(i)


def nearest_index(thetas: np.ndarray, theta: float) -> int:
    """Index of the angle in ``thetas`` (rad) closest to ``theta`` (rad) on the circle."""
    return int(np.argmin(np.abs(np.angle(np.exp(1j * (np.asarray(thetas) - theta))))))


def field_snapshots(system, cycle, extra_angles=()) -> tuple[FieldSnapshot, ...]:
    """Vertex displacements and stresses of every field a load cycle kept, ordered by angle.

    Parameters
    ----------
    system : rvfem.cycle.DiscSystem
    cycle : rvfem.cycle.CycleResult
    extra_angles : iterable of float, optional
        Further solved crank angles (rad, nearest of ``cycle.theta``) whose fields the cycle did
        not keep, e.g. where the stress envelope peaks; rebuilt from the cycle's own solutions.

    Returns
    -------
    tuple of FieldSnapshot
    """
    from .cycle import displacement

    model = system.model
    vdofs = model.node_dofs[: model.n_vertices]
    fields = dict(cycle.fields)
    for theta in extra_angles:
        k = nearest_index(cycle.theta, float(theta))
        if not any(math.isclose(cycle.theta[k], t, abs_tol=1e-12) for t in fields):
            fields[float(cycle.theta[k])] = displacement(system, cycle.solutions[k])
    out = []
    for theta in sorted(fields):
        u = np.asarray(fields[theta], dtype=float)
        u_def, motion = fem.remove_rigid_motion(model, u)
        out.append(FieldSnapshot(
            theta=float(theta),
            index=nearest_index(cycle.theta, float(theta)),
            displacement=u[vdofs],
            deformation=u_def[vdofs],
            rigid_motion=np.asarray(motion, dtype=float),
            stress=fem.stress_fields(model, u),
        ))
    return tuple(out)


def _distances(points: np.ndarray, boundary_points: np.ndarray) -> np.ndarray:
    """Distance of every point to the nearest of ``boundary_points`` (k-d tree), mm."""
    from scipy.spatial import cKDTree

    return cKDTree(boundary_points).query(points)[0]


@dataclass(frozen=True, eq=False)
class StressEnvelope:
    """Largest vertex von Mises stress of every vertex over a set of crank angles.

    Attributes
    ----------
    von_mises : ndarray (n_vertices,)
        MPa.
    theta : ndarray (n_vertices,)
        Crank angle at which each vertex reaches it, rad.
    """

    von_mises: np.ndarray
    theta: np.ndarray


def stress_envelope(source) -> StressEnvelope:
    """The envelope of a load cycle computed with ``stress_envelope=True`` (every solved angle),
    or of a tuple of :class:`FieldSnapshot` (the kept angles only)."""
    if isinstance(source, StressEnvelope):
        return source
    if getattr(source, "von_mises_envelope", None) is not None:
        return StressEnvelope(np.asarray(source.von_mises_envelope), np.asarray(source.von_mises_envelope_theta))
    snapshots = tuple(source)
    if not snapshots:
        raise ValueError("peak_von_mises needs at least one snapshot")
    vm = np.stack([s.stress.nodal.von_mises for s in snapshots])
    k = np.argmax(vm, axis=0)
    cols = np.arange(vm.shape[1])
    return StressEnvelope(vm[k, cols], np.array([s.theta for s in snapshots])[k])


def peak_von_mises(source, points: np.ndarray,
                   boundaries: dict[str, np.ndarray], *,
                   exclude: dict[str, float] | None = None) -> PeakStress | None:
    """The largest vertex von Mises stress and the boundary it lies nearest to.

    Parameters
    ----------
    source : StressEnvelope, rvfem.cycle.CycleResult or tuple of FieldSnapshot
        Where to search: a cycle solved with ``stress_envelope=True`` covers every solved angle;
        snapshots cover the kept angles only (at least one).
    points : ndarray (n_vertices, 2)
        Mesh vertices, mm.
    boundaries : dict
        Mesh boundary name → edges (vertex index pairs), as :attr:`rvfem.mesh.DiscMesh.boundaries`.
    exclude : dict, optional
        Boundary name → band width (mm): vertices closer than that to the boundary are ignored
        (e.g. the tooth profile and the bores, where the pin and roller forces are applied over
        a footprint of a few elements and the local stress depends on that footprint).

    Returns
    -------
    PeakStress or None
        None only if ``exclude`` leaves no vertex.
    """
    env = stress_envelope(source)
    points = np.asarray(points, dtype=float)
    mask = np.ones(len(points), dtype=bool)
    for name, band in (exclude or {}).items():
        if name in boundaries and band > 0:
            mask &= _distances(points, points[np.asarray(boundaries[name])[:, 0]]) >= band
    if not mask.any():
        return None
    candidates = np.flatnonzero(mask)
    vertex = int(candidates[np.argmax(env.von_mises[candidates])])
    p = points[vertex]
    feature, dist = "", math.inf
    for name, edges in boundaries.items():
        d = float(_distances(p[None, :], points[np.asarray(edges)[:, 0]])[0])
        if d < dist:
            feature, dist = name, d
    return PeakStress(
        von_mises_MPa=float(env.von_mises[vertex]),
        x_mm=float(p[0]),
        y_mm=float(p[1]),
        radius_mm=float(np.hypot(*p)),
        theta_deg=float(np.degrees(env.theta[vertex])),
        feature=feature,
        feature_label=feature_label(feature),
        distance_to_feature_mm=dist,
    )
