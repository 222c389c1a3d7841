"""Disc stresses of a flexible load cycle: field snapshots, the stress envelope, the peak von Mises
stress and where it is.

Everything here is computed from the results of :func:`rvfem.solve.cycle.load_cycle` (no new solve): the
displacement fields it keeps (the case's saved angles and the angle of the largest bearing load)
give the stress fields; a cycle solved with ``stress_envelope=True`` gives the largest von Mises
stress of every vertex over every solved angle. (Roller-raceway Hertz pressures are in
:mod:`rvfem.evaluate.hertz`.)

Typical use::

    cycle = load_cycle(system, stress_envelope=True)
    peak = peak_von_mises(cycle, mesh.points, mesh.boundaries)
    snapshots = field_snapshots(system, cycle, extra_angles=[math.radians(peak.theta_deg)])
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from rvfem import fem
from rvfem._arrays import TIE_RTOL, first_max, max_load_index, near_max
from rvfem.fem import StressState, nodal_stress_operator
from rvfem.names import FEATURE_LABELS, feature_label, user_feature_label
from rvfem.solve.cycle import displacement, displacements

__all__ = [
    "FieldSnapshot",
    "StressEnvelope",
    "PeakStress",
    "FEATURE_LABELS",
    "feature_label",
    "user_feature_name",
    "user_feature_label",
    "max_load_index",
    "nearest_index",
    "field_snapshots",
    "stress_envelope",
    "peak_von_mises",
    "RECOVERY_ANGLES",
    "RecoveredPeak",
    "peak_angles",
    "recover_peak",
    "HotSpotHistory",
    "vertex_of",
    "hot_spot_history",
    "p1_stress_at",
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
        The same in words, numbered from 1 (``tooth profile``, ``bore 1``, ``hole 2``…).
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


def nearest_index(thetas: np.ndarray, theta: float) -> int:
    """Index of the angle in ``thetas`` (rad) closest to ``theta`` (rad) on the circle."""
    return int(np.argmin(np.abs(np.angle(np.exp(1j * (np.asarray(thetas) - theta))))))


def field_snapshots(system, cycle, extra_angles=()) -> tuple[FieldSnapshot, ...]:
    """Vertex displacements and stresses of every field a load cycle kept, ordered by angle.

    Parameters
    ----------
    system : rvfem.solve.cycle.DiscSystem
    cycle : rvfem.solve.cycle.CycleResult
    extra_angles : iterable of float, optional
        Further solved crank angles (rad, nearest of ``cycle.theta``) whose fields the cycle did
        not keep, e.g. where the stress envelope peaks; rebuilt from the cycle's own solutions.

    Returns
    -------
    tuple of FieldSnapshot
    """

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
    source : StressEnvelope, rvfem.solve.cycle.CycleResult or tuple of FieldSnapshot
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
    mask = _mask(points, boundaries, exclude)
    if not mask.any():
        return None
    candidates = np.flatnonzero(mask)
    vertex = int(candidates[_first_peak(env, candidates)])
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


# --------------------------------------------------------------------------------------------
# The structural peak recovered on P2
# --------------------------------------------------------------------------------------------


RECOVERY_ANGLES = 3
"""Crank angles at which :func:`recover_peak` re-solves the disc on P2: the angles of the largest
P1 envelope values away from the contacts, at least one per feature (hole, bore…) that comes within
10 % of the P1 peak."""


@dataclass(frozen=True)
class RecoveredPeak:
    """The structural stress peak recovered on a P2 model of the same mesh, with its convergence check.

    Method: the disc is re-solved on P2 (scikit-fem ``ElementTriP2`` on the same triangles, same
    footprint interface) loaded with the converged contact and roller forces of the P1 cycle at a
    few crank angles where the P1 peak lies; the stresses are recovered on P2 and the largest vertex
    von Mises stress away from the contacts is taken. The bearing loads are not changed (P1 and P2
    give them within 0.1 %, see docs/theory.md); only the stress is re-evaluated.

    Attributes
    ----------
    peak : PeakStress
        The P2 peak: value (MPa), location, crank angle, nearest feature.
    p1_MPa : float
        The P1 envelope's structural peak (what the P1 cycle alone gives), MPa.
    p1_at_peak_MPa : float
        The P1 vertex value at the P2 peak's vertex and angle, MPa.
    estimated_error_MPa : float
        Estimated error of the P2 peak: the largest difference between the (discontinuous) P2
        element stresses at the peak vertex and their area-weighted average, von Mises, MPa (a
        Zienkiewicz-Zhu type indicator: recovered minus raw stress).
    angles_deg : tuple of float
        Crank angles re-solved on P2, degrees.
    seconds : float
        Wall time of the recovery (P2 assembly, factorisation and the solves), s; made in the P2
        model's child process, it leaves out the P1 value at the peak, computed in the parent.
    method : str
        One line describing the method.
    """

    peak: PeakStress
    p1_MPa: float
    p1_at_peak_MPa: float
    estimated_error_MPa: float
    angles_deg: tuple[float, ...]
    seconds: float
    method: str = ("P2 re-solve of the same mesh at the P1 peak angles, loaded with the P1 cycle's "
                   "contact and roller forces")

    @property
    def p1_error_percent(self) -> float:
        """(P1 − P2)/P2 of the structural peak, %: the error of the P1 envelope's peak."""
        return 100.0 * (self.p1_MPa - self.peak.von_mises_MPa) / self.peak.von_mises_MPa

    @property
    def estimated_error_percent(self) -> float:
        """``estimated_error_MPa`` relative to the P2 peak, %."""
        return 100.0 * self.estimated_error_MPa / self.peak.von_mises_MPa


def _mask(points: np.ndarray, boundaries: dict[str, np.ndarray], exclude: dict[str, float] | None) -> np.ndarray:
    """Vertices at least ``exclude[name]`` (mm) from every named boundary's vertices (the mask of
    :func:`peak_von_mises`); the k-d tree search stops at the band (farther vertices are kept
    whatever their distance)."""

    mask = np.ones(len(points), dtype=bool)
    for name, band in (exclude or {}).items():
        if name in boundaries and band > 0:
            tree = cKDTree(points[np.asarray(boundaries[name])[:, 0]])
            mask &= tree.query(points, distance_upper_bound=band)[0] >= band
    return mask


def _first_peak(env: StressEnvelope, candidates: np.ndarray) -> int:
    """Position in ``candidates`` of the largest envelope value; among values within
    :data:`rvfem._arrays.TIE_RTOL` of it (on a symmetric disc the peak has rotated copies that differ by round-off) the one reached
    at the smallest crank angle, then the lowest vertex."""
    tied = near_max(env.von_mises[candidates])
    theta = np.mod(env.theta[candidates][tied], 2.0 * np.pi)
    return int(tied[np.lexsort((tied, np.round(theta, 9)))[0]])


def peak_angles(source, points: np.ndarray, boundaries: dict[str, np.ndarray], *,
                exclude: dict[str, float] | None = None, count: int = RECOVERY_ANGLES,
                within: float = 0.1) -> tuple[float, ...]:
    """Crank angles (rad) where the structural peak may lie: for every mesh boundary, the angle at
    which its nearest vertices reach their largest envelope value, if that comes within ``within``
    of the overall peak; the ``count`` highest, the overall peak's angle first."""
    env = stress_envelope(source)
    points = np.asarray(points, dtype=float)
    mask = _mask(points, boundaries, exclude)
    candidates = np.flatnonzero(mask)
    if candidates.size == 0:
        return ()
    names = list(boundaries)
    dist = np.stack([_distances(points[candidates], points[np.asarray(boundaries[n])[:, 0]]) for n in names])
    nearest = np.argmin(dist, axis=0)
    top = float(env.von_mises[candidates].max())
    best: list[tuple[float, float]] = []
    for j in range(len(names)):
        sel = candidates[nearest == j]
        if sel.size == 0:
            continue
        v = sel[_first_peak(env, sel)]
        if env.von_mises[v] >= (1.0 - within) * top:
            best.append((float(env.von_mises[v]), float(env.theta[v])))
    angles: list[float] = []
    # highest first; equal peaks (the rotated copies of a symmetric disc, round-off apart) by angle
    for _, th in sorted(best, key=lambda b: (-round(b[0] / top, 9), b[1])):
        if not any(math.isclose(th, a, abs_tol=1e-12) for a in angles):
            angles.append(th)
    return tuple(angles[:count])


def p1_stress_at(system_p1, cycle, peak: PeakStress) -> float:
    """The P1 vertex von Mises stress of the cycle at a peak's vertex and crank angle, MPa (what
    :attr:`RecoveredPeak.p1_at_peak_MPa` compares the P2 value with)."""
    return _p1_stress(system_p1, cycle, nearest_index(cycle.theta, math.radians(peak.theta_deg)),
                      vertex_of(system_p1.mesh.points, peak))


def _p1_stress(system_p1, cycle, k: int, vertex: int) -> float:
    """The P1 vertex von Mises stress of the cycle's angle k at a vertex, MPa."""

    u1 = displacement(system_p1, cycle.solutions[k])
    return float(fem.stress_fields(system_p1.model, u1).nodal.von_mises[vertex])


def recover_peak(system_p2, cycle, angles, points: np.ndarray, boundaries: dict[str, np.ndarray], *,
                 exclude: dict[str, float] | None = None, p1_peak: PeakStress | None = None,
                 system_p1=None, setup_seconds: float = 0.0) -> RecoveredPeak:
    """Re-solve the disc on P2 at ``angles`` with the P1 cycle's forces; the structural peak.

    Parameters
    ----------
    system_p2 : rvfem.solve.cycle.DiscSystem
        The P2 model of the same mesh (``build_system(case, mesh, order=2)``): its footprint
        interface has the same columns as the P1 cycle's.
    cycle : rvfem.solve.cycle.CycleResult
        The P1 cycle (its ``solutions`` hold the converged contact and roller forces); or, in the
        P2 model's child process, its angles and the :class:`rvfem.solve.cycle.AngleLoads` of the
        angles to re-solve (``theta`` and ``solutions``, a dict by angle index).
    angles : iterable of float
        Crank angles to re-solve, rad (nearest of ``cycle.theta``).
    points, boundaries, exclude
        As for :func:`peak_von_mises` (mesh vertices, boundary edges, contact bands).
    p1_peak : PeakStress, optional
        The P1 structural peak (reported beside the P2 value).
    system_p1 : rvfem.solve.cycle.DiscSystem, optional
        The P1 model of the cycle: gives ``p1_at_peak_MPa`` (NaN without it).
    setup_seconds : float
        Time already spent building ``system_p2``, added to ``seconds``.

    Returns
    -------
    RecoveredPeak

    Notes
    -----
    The load of the P2 model is ``B₂ W λ``: the same footprint forces λ of the converged P1
    contact problem spread by the P2 consistent footprint weights, so each body is in equilibrium
    exactly as in the P1 solve. The P2 response is the stress under these forces; the contact
    forces themselves would change by less than 0.1 % on P2 (the bearing loads do, docs/theory.md).
    Each distinct solved angle is back-substituted once: on a symmetric disc an angle the cycle
    obtained by symmetry gets its origin's P2 field turned (:func:`rvfem.solve.cycle.displacements`),
    the field :func:`rvfem.solve.cycle.displacement` gives.
    """


    t0 = time.perf_counter()
    model = system_p2.model
    ks = [nearest_index(cycle.theta, float(theta)) for theta in angles]
    if any(system_p2.interface.B.shape[1] != cycle.solutions[k].column_loads.shape[0] for k in ks):
        raise ValueError("the P2 model's interface does not match the P1 cycle's")
    points = np.asarray(points, dtype=float)
    mask = _mask(points, boundaries, exclude)
    candidates = np.flatnonzero(mask)
    best: tuple[float, int, int, np.ndarray] | None = None
    for k, u in zip(ks, displacements(system_p2, [cycle.solutions[k] for k in ks])):
        g = fem.displacement_gradients(model, u)
        vm = fem.stress_fields(model, u, gradients=g).nodal.von_mises
        v = int(candidates[first_max(vm[candidates])[0]])
        if best is None or vm[v] > best[0] * (1.0 + TIE_RTOL):   # the first of equal peaks
            best = (float(vm[v]), v, k, g)
    if best is None:
        raise ValueError("no crank angle to recover the peak at")
    value, vertex, k, g = best
    # the spread of the P2 element stresses at the peak vertex around their average
    g = g[:, :, :, :3]                                           # (2, 2, n_elements, 3 vertices)
    local, elems = np.nonzero(model.mesh.t == vertex)
    sxx, syy, sxy = fem.plane_stress_components(model, g[:, :, elems, local])
    vm_raw = np.sqrt(sxx * sxx - sxx * syy + syy * syy + 3.0 * sxy * sxy)
    spread = float(np.max(np.abs(vm_raw - value)))
    envelope = np.full(len(points), -np.inf)
    envelope[vertex] = value
    peak = peak_von_mises(StressEnvelope(envelope, np.full(len(points), float(cycle.theta[k]))), points,
                          boundaries)
    assert peak is not None   # the envelope is finite at the peak vertex
    p1_here = _p1_stress(system_p1, cycle, k, vertex) if system_p1 is not None else math.nan
    return RecoveredPeak(
        peak=peak,
        p1_MPa=float(p1_peak.von_mises_MPa) if p1_peak is not None else math.nan,
        p1_at_peak_MPa=p1_here,
        estimated_error_MPa=spread,
        angles_deg=tuple(round(math.degrees(float(cycle.theta[k])), 9) for k in ks),
        seconds=setup_seconds + time.perf_counter() - t0,
    )


def user_feature_name(name: str) -> str:
    """A mesh boundary's name as users read it, numbered from 1 like bearings, pins and rollers:
    ``bore_0`` → ``bore_1``, ``hole_2`` → ``hole_3``; other names unchanged. (The mesh's boundary
    names are numbered from 0 internally; every output maps them with this function.)"""
    stem, _, number = name.rpartition("_")
    if stem in ("bore", "hole") and number.isdigit():
        return f"{stem}_{int(number) + 1}"
    return name


# --------------------------------------------------------------------------------------------
# Stress history at the hot spots (for a fatigue check)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class HotSpotHistory:
    """Stress over the crank angle at a few vertices (the hot spots), for a fatigue check.

    Attributes
    ----------
    names : tuple of str
        ``structural`` (the structural peak's vertex) and ``contact_zone`` (the overall peak's).
    vertices : tuple of int
        Mesh vertex of each hot spot.
    peaks : tuple of PeakStress
        Where each hot spot is (value and angle of the envelope there).
    theta : ndarray (n,)
        Crank angles, rad (the cycle's).
    von_mises, s1, s2 : ndarray (n, hot spots)
        Vertex von Mises and in-plane principal stresses of the cycle's model at every angle, MPa.
    p2_factor : tuple of float
        P2/P1 ratio of the von Mises stress at the hot spot at the recovery's angle (1 where not
        re-solved): multiply the P1 history by it for an estimate of the P2 history.
    sxx, syy, sxy : ndarray (n, hot spots) or None
        The Cartesian components of the same stresses (the fatigue criterion's tensor history), MPa.
    """

    names: tuple[str, ...]
    vertices: tuple[int, ...]
    peaks: tuple[PeakStress, ...]
    theta: np.ndarray
    von_mises: np.ndarray
    s1: np.ndarray
    s2: np.ndarray
    p2_factor: tuple[float, ...]
    sxx: np.ndarray | None = None
    syy: np.ndarray | None = None
    sxy: np.ndarray | None = None

    @property
    def dominant(self) -> np.ndarray:
        """The in-plane principal stress of larger magnitude, signed, (n, hot spots), MPa: at a
        free edge the one non-zero stress (the tangential one), whose range and mean a fatigue
        check uses."""
        return np.where(np.abs(self.s1) >= np.abs(self.s2), self.s1, self.s2)


def vertex_of(points: np.ndarray, peak: PeakStress) -> int:
    """Index of the mesh vertex at a peak's position."""
    return int(np.argmin(np.hypot(points[:, 0] - peak.x_mm, points[:, 1] - peak.y_mm)))


def hot_spot_history(system, cycle, spots: dict[str, PeakStress],
                     p2_factor: dict[str, float] | None = None) -> HotSpotHistory:
    """Vertex stresses at the hot spots at every crank angle of a cycle, by influence
    coefficients: the few rows S_h of :func:`rvfem.fem.nodal_stress_operator` at the hot spots
    are back-substituted once, Z = A·S_hᵀ with A = Π K_s⁻¹ Πᵀ the disc's (symmetric) floating
    compliance (:meth:`rvfem.solve.contact.Compliance.field`), and the stresses of an angle with nodal
    loads f = B·W·λ and rigid motion a are S_h·(A f + R a) = (ZᵀB)(Wλ) + (S_h R) a: three
    numbers per hot spot and angle from a product with the angle's contact forces, exactly the
    stresses of the angle's displacement field (Maxwell–Betti reciprocity).

    Parameters
    ----------
    system : rvfem.solve.cycle.DiscSystem
    cycle : rvfem.solve.cycle.CycleResult
    spots : dict
        Name → PeakStress (its vertex is the hot spot).
    p2_factor : dict, optional
        Name → P2/P1 ratio at the hot spot (see :class:`HotSpotHistory`).
    """

    points = np.asarray(system.mesh.points, dtype=float)
    names = tuple(spots)
    vertices = tuple(vertex_of(points, spots[n]) for n in names)
    sub = nodal_stress_operator(system.model, vertices)            # (3·hot spots, n_dofs)
    Z = system.compliance.fields(sub.T.toarray())                  # A·S_hᵀ, (n_dofs, 3·hot spots)
    ZB = np.asarray(system.interface.B.T @ Z).T                    # (3·hot spots, n_columns)
    SR = np.asarray(sub @ system.rigid_modes)                      # ≈ 0: rigid motions do not strain
    comps = np.stack([ZB @ r.column_loads + SR @ r.rigid_motion
                      for r in cycle.solutions])                   # (n, 3·hot spots)
    k = len(vertices)
    state = StressState.from_components(comps[:, :k], comps[:, k:2 * k], comps[:, 2 * k:])
    factors = tuple(float((p2_factor or {}).get(n, 1.0)) for n in names)
    return HotSpotHistory(names=names, vertices=vertices, peaks=tuple(spots[n] for n in names),
                          theta=np.asarray(cycle.theta), von_mises=np.asarray(state.von_mises),
                          s1=np.asarray(state.s1), s2=np.asarray(state.s2), p2_factor=factors,
                          sxx=np.asarray(state.sxx), syy=np.asarray(state.syy), sxy=np.asarray(state.sxy))
