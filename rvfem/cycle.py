"""The flexible load cycle: the disc model of a case, one crank angle, a full crank revolution.

Typical use from a notebook::

    from rvfem.case import load_case
    from rvfem.mesh import mesh_case
    from rvfem.cycle import build_system, solve_angle, load_cycle

    case = load_case("cases/rv40e_fanholes.toml")
    system = build_system(case, mesh_case(case))
    one = solve_angle(system, theta=0.0)             # crank angle in rad
    cycle = load_cycle(system)                       # 0…360° at the case's angle step

The stiffness of the disc is assembled and factorised once (:func:`build_system`); every crank
angle reuses it through the lazily filled column compliance of :mod:`rvfem.contact`.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from threadpoolctl import threadpool_limits

from . import contact
from .case import Case
from .contact import AngleSolution, Compliance, ContactSet, Interface
from .errors import CaseError
from .geometry import crank_centres as bore_centres  # centres c_i of the crank bores, (N, 2), mm

log = logging.getLogger(__name__)

__all__ = [
    "DiscSystem",
    "AngleResult",
    "CycleResult",
    "build_system",
    "contact_set",
    "solve_angle",
    "load_cycle",
    "displacement",
    "bore_centres",
    "roller_angles",
]


FOOTPRINT_ELEMENTS = 1.5
"""Half-width of the pin and roller load footprints in element sizes (mesh.size_flank at the
profile, mesh.size_bore at the bores). The Hertz half-widths of these contacts (≈0.1 mm) are below
one element at the default sizes, so the footprint spreads each force over a few elements; the
bearing loads do not depend on it (global equilibrium), only the stress right under a contact."""


def roller_angles(case: Case, theta: float) -> np.ndarray:
    """Angular positions of the rollers of every bearing at crank angle θ, (N, Z), rad.

    Measured about each bore centre from the disc's x axis. The eccentric turns by θ relative to
    the disc (the disc only translates relative to the carrier), so the cage turns by
    θ·(1 − γ)/2 with γ = D_we/D_m (outer ring fixed). The cages of the N bearings are phased by
    Δ_i·(1 + γ)/2 for a crank at Δ_i from the first, which makes the N bearings equivalent by the
    disc's N-fold symmetry (their load curves are then exact 360°/N shifts when Zc is divisible
    by N). Rollers of one bearing are 2π/Z apart.
    """
    b = case.crank_bearing
    gamma = b.roller_diameter / b.pitch_diameter
    alpha = np.radians(case.cranks.angles_deg)
    cage = theta * (1.0 - gamma) / 2.0 + (alpha - alpha[0]) * (1.0 + gamma) / 2.0
    return cage[:, None] + 2.0 * np.pi * np.arange(b.rollers)[None, :] / b.rollers


@dataclass(frozen=True)
class DiscSystem:
    """Everything that does not change with the crank angle.

    Attributes
    ----------
    case : Case
    mesh : mesh object with ``points``, ``triangles``, ``boundaries``
    model : the FE model (:mod:`rvfem.fem`)
    interface : contact.Interface
    compliance : contact.Compliance
        Cache of the column compliance (filled lazily; the only mutable part).
    solve : callable
        K_s⁻¹ applied to a right-hand side.
    rigid_modes : ndarray (n_dofs, 3)
    bearing_model : str
        ``"rollers"`` or ``"rigid_bore"``.
    setup_seconds : dict
        Wall times of assembly, factorisation and interface build.
    """

    case: Case
    mesh: object
    model: object
    interface: Interface
    compliance: Compliance
    solve: object
    rigid_modes: np.ndarray
    bearing_model: str
    stiffness_scale: float
    pin_model: str
    geometry: object
    bearing_stiffness_scale: float = 1.0
    pin_stiffness_N_per_mm: float | None = None
    setup_seconds: dict = field(default_factory=dict)


def build_system(case: Case, mesh, *, order: int | None = None, bearing_model: str | None = None,
                 stiffness_scale: float = 1.0, pin_model: str | None = None,
                 bearing_stiffness_scale: float = 1.0,
                 pin_stiffness_N_per_mm: float | None = None, column_stride: int = 1) -> DiscSystem:
    """Assemble and factorise the disc and build its footprint interface.

    Parameters
    ----------
    case : Case
    mesh : DiscMesh
        From :func:`rvfem.mesh.mesh_case`.
    order : {1, 2}, optional
        Element order; default ``case.analysis.element_order``.
    bearing_model : {"rollers", "rigid_bore"}, optional
        Default ``case.crank_bearing.model``.
    stiffness_scale : float
        Multiplies the disc's Young's modulus (1000 gives the "rigid disc" limit of the design
        notes' validation ladder).
    pin_model : {"rigid", "hertz", "linear"}, optional
        Default ``case.pins.model``. ``"linear"`` (a validation device: the classical pin-force
        distribution assumes pin deflections proportional to the forces) needs
        ``pin_stiffness_N_per_mm``.
    bearing_stiffness_scale : float
        Multiplies the ``rigid_bore`` bearing stiffness (for the rigid-limit checks).
    pin_stiffness_N_per_mm : float, optional
        Stiffness of the ``"linear"`` pin model, N/mm.
    column_stride : int
        Interface columns at every stride-th boundary vertex. 1 (default) is the accurate
        choice; 2 halves the back-substitutions (default fan-hole case: cycle 8.5 → 6.0 s) at the
        price of 0.6 % of the maximum bearing load and 5 % on single pin forces.
    """
    from . import fem
    from .geometry import disc_geometry

    order = order or case.analysis.element_order
    bearing_model = bearing_model or case.crank_bearing.model
    pin_model = pin_model or case.pins.model
    if pin_model not in ("rigid", "hertz", "linear"):
        raise CaseError(f"pin model must be 'rigid', 'hertz' or 'linear', got {pin_model!r}")
    if pin_model == "linear" and not (pin_stiffness_N_per_mm and pin_stiffness_N_per_mm > 0):
        raise CaseError("pin model 'linear' needs a positive pin_stiffness_N_per_mm")
    if bearing_model not in ("rollers", "rigid_bore"):
        raise CaseError(f"bearing model must be 'rollers' or 'rigid_bore', got {bearing_model!r}")
    times = {}
    geometry = disc_geometry(case)
    t0 = time.perf_counter()
    model = fem.build_model(mesh.points, mesh.triangles,
                            youngs_modulus=case.material.youngs_modulus * stiffness_scale,
                            poissons_ratio=case.material.poissons_ratio,
                            thickness=case.cycloid.thickness, order=order)
    times["assembly"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    factor = fem.factorize(model)
    times["factorization"] = time.perf_counter() - t0
    rigid = fem.rigid_body_modes(model)  # about the disc centre (the origin)

    t0 = time.perf_counter()
    centres = bore_centres(case)
    names = ["profile"] + [f"bore_{i}" for i in range(case.cranks.count)]
    boundaries = {n: mesh.boundaries[n] for n in names}
    half = {"profile": FOOTPRINT_ELEMENTS * case.mesh.size_flank}
    for i in range(case.cranks.count):
        half[f"bore_{i}"] = FOOTPRINT_ELEMENTS * case.mesh.size_bore
    iface = contact.build_interface(model, boundaries, rigid,
                                    {f"bore_{i}": centres[i] for i in range(len(centres))}, half,
                                    {name: column_stride for name in boundaries})
    times["interface"] = time.perf_counter() - t0
    compliance = Compliance(factor.solve, iface.B)
    return DiscSystem(case, mesh, model, iface, compliance, factor.solve, rigid, bearing_model,
                      stiffness_scale, pin_model, geometry, bearing_stiffness_scale,
                      pin_stiffness_N_per_mm, times)


def contact_set(system: DiscSystem, theta: float) -> tuple[ContactSet, list[str]]:
    """The contacts of crank angle θ (rad): every pin, then the bearing contacts.

    Returns the contact set and a name per contact (``pin 7``, ``bearing 1 roller 3``, ...).
    """
    from .geometry import pin_centres, pin_profile_contacts

    case = system.case
    iface = system.interface
    prof = iface.grids["profile"]
    pc = pin_profile_contacts(system.geometry, theta)
    zp = case.pins.count
    s = prof.arc_of(np.asarray(pc.point))
    inward = -np.asarray(pc.normal)
    cols, wts = prof.columns_at(s, inward)   # pins push along the inward normal
    mu = case.analysis.friction
    pin_load = None
    if mu > 0:
        # Coulomb friction along the known sliding direction: the pin centre's velocity relative
        # to the disc (the pins are taken as not rolling in their grooves); the friction force on
        # the disc drags its surface along with the pin: μ·λ·sign(v·t)·t, t the profile tangent
        h = 1e-6
        vel = (pin_centres(case, theta + h) - pin_centres(case, theta - h)) / (2 * h)
        tangent = np.stack([-inward[:, 1], inward[:, 0]], axis=1)
        slide = np.sign(np.einsum("ij,ij->i", vel, tangent))
        _, pin_load = prof.columns_at(s, inward + mu * slide[:, None] * tangent)
    rows_w = [cols.ravel()]
    cols_w = [np.repeat(np.arange(zp), cols.shape[1])]
    vals_w = [wts.ravel()]
    gap0 = np.zeros(zp)
    offset = np.zeros(zp)
    signorini = np.zeros(zp, dtype=bool)
    names = [f"pin {j}" for j in range(zp)]
    laws = []
    if system.pin_model == "rigid":
        signorini[:] = True
        gap0[:] = pc.gap
    else:
        offset[:] = -np.asarray(pc.gap)
        law = (contact.palmgren_law(case.cycloid.thickness, contacts=1) if system.pin_model == "hertz"
               else contact.linear_law(system.pin_stiffness_N_per_mm))
        laws.append((np.arange(zp), law))

    centres = bore_centres(case)
    b = case.crank_bearing
    n = zp
    bearing_of = []
    if system.bearing_model == "rollers":
        psi = roller_angles(case, theta)
        law = (contact.palmgren_law(b.roller_length, contacts=2) if b.stiffness_law == "palmgren"
               else contact.linear_law(b.linear_stiffness_N_per_mm))
        idx = []
        for i, c in enumerate(centres):
            grid = iface.grids[f"bore_{i}"]
            pts = c + b.bore_radius * np.stack([np.cos(psi[i]), np.sin(psi[i])], axis=1)
            cc, ww = grid.columns_at(grid.arc_of(pts))
            z = len(psi[i])
            rows_w.append(cc.ravel())
            cols_w.append(np.repeat(np.arange(n, n + z), 2))
            vals_w.append(ww.ravel())
            names += [f"bearing {i} roller {k}" for k in range(z)]
            idx.append(np.arange(n, n + z))
            bearing_of += [i] * z
            n += z
        nb = n - zp
        laws.append((np.concatenate(idx), law))
        gap0 = np.concatenate([gap0, np.zeros(nb)])
        offset = np.concatenate([offset, np.full(nb, -0.5 * b.radial_clearance)])
        signorini = np.concatenate([signorini, np.zeros(nb, dtype=bool)])
    else:
        k_b = b.rigid_bore_stiffness_N_per_mm * system.bearing_stiffness_scale
        for i, c in enumerate(centres):
            grid = iface.grids[f"bore_{i}"]
            ang = np.arctan2(*(iface.points[grid.offset:grid.offset + grid.count] - c).T[::-1])
            colsb = grid.offset + np.arange(grid.count)
            for comp, w in (("x", np.cos(ang)), ("y", np.sin(ang))):
                rows_w.append(colsb)
                cols_w.append(np.full(grid.count, n))
                vals_w.append(2.0 / grid.count * w)
                names.append(f"bearing {i} {comp}")
                bearing_of.append(i)
                n += 1
        nb = n - zp
        laws.append((np.arange(zp, n), contact.linear_law(k_b, bilateral=True)))
        gap0 = np.concatenate([gap0, np.zeros(nb)])
        offset = np.concatenate([offset, np.zeros(nb)])
        signorini = np.concatenate([signorini, np.zeros(nb, dtype=bool)])

    W = sp.csc_matrix((np.concatenate(vals_w), (np.concatenate(rows_w), np.concatenate(cols_w))),
                      shape=(iface.n_columns, n))
    W_load = None
    if pin_load is not None:
        vals_w[0] = pin_load.ravel()
        W_load = sp.csc_matrix((np.concatenate(vals_w), (np.concatenate(rows_w), np.concatenate(cols_w))),
                               shape=(iface.n_columns, n))
    F = np.asarray(W.T @ iface.resultants[:, :2])     # force on the disc per unit λ
    cb = centres[np.asarray(bearing_of, dtype=int)]
    lever = np.concatenate([np.zeros(zp), cb[:, 0] * F[zp:, 1] - cb[:, 1] * F[zp:, 0]])
    return ContactSet(W, signorini, gap0, offset, lever, laws, W_load), names


@dataclass(frozen=True)
class AngleResult:
    """Loads at one crank angle (all forces act on the disc, N; disc frame).

    Attributes
    ----------
    theta : float
        Crank angle, rad.
    bearing_forces : ndarray (N, 2)
        Force of each crank bearing on the disc.
    roller_loads : ndarray (N, Z) or None
        Roller loads (``rollers`` model), N.
    roller_angles : ndarray (N, Z) or None
        Roller positions about each bore centre, rad.
    pin_forces : ndarray (Zp,)
        Pin force magnitudes, N.
    pin_vectors : ndarray (Zp, 2)
    pin_gaps : ndarray (Zp,)
        Final pin gaps (rigid pins) or −approach (compliant pins), mm.
    carrier_rotation : float
        φ, rad (carrier relative to the pin housing, about the disc centre).
    solution : contact.AngleSolution
    """

    theta: float
    bearing_forces: np.ndarray
    roller_loads: np.ndarray | None
    roller_angles: np.ndarray | None
    pin_forces: np.ndarray
    pin_vectors: np.ndarray
    pin_gaps: np.ndarray
    carrier_rotation: float
    solution: AngleSolution
    contacts: ContactSet

    @property
    def bearing_loads(self) -> np.ndarray:
        """|F| of each bearing, N."""
        return np.linalg.norm(self.bearing_forces, axis=1)

    @property
    def pins_in_contact(self) -> int:
        return int(np.count_nonzero(self.pin_forces > 1e-9 * max(self.pin_forces.max(), 1.0)))


def solve_angle(system: DiscSystem, theta: float, start: AngleResult | None = None, *,
                contacts: tuple[ContactSet, list[str]] | None = None) -> AngleResult:
    """Solve one crank angle θ (rad). ``start`` warm-starts from a neighbouring angle;
    ``contacts`` passes the angle's :func:`contact_set` if it is already built."""
    case = system.case
    cset, names = contact_set(system, theta) if contacts is None else contacts
    sol = contact.solve_contact(
        cset, system.interface, system.compliance, case.loads.disc_torque_Nmm,
        start=None if start is None else start.solution,
        max_iterations=case.analysis.max_active_set_iterations,
        label=f"at crank angle {math.degrees(theta):.2f}° ", names=names,
    )
    zp = case.pins.count
    n = case.cranks.count
    if system.bearing_model == "rollers":
        z = case.crank_bearing.rollers
        vec = sol.vectors[zp:].reshape(n, z, 2)
        bearing = vec.sum(axis=1)
        rollers = sol.force[zp:].reshape(n, z)
        angles = roller_angles(case, theta)
    else:
        bearing = sol.vectors[zp:].reshape(n, 2, 2).sum(axis=1)
        rollers = angles = None
    return AngleResult(theta, bearing, rollers, angles, sol.force[:zp], sol.vectors[:zp],
                       sol.gap[:zp], sol.carrier_rotation, sol, cset)


def displacement(system: DiscSystem, result: AngleResult) -> np.ndarray:
    """Displacement field (n_dofs,) of the disc at a solved angle, mm (rigid motion included)."""
    f = system.interface.B @ (result.contacts.W @ result.solution.force)
    return system.solve(np.asarray(f)) + system.rigid_modes @ result.solution.rigid


@dataclass(frozen=True)
class CycleResult:
    """A full crank revolution (arrays indexed by angle first).

    Attributes
    ----------
    theta : ndarray (n,)
        Crank angles, rad.
    bearing_forces : ndarray (n, N, 2)
        Force of each bearing on the disc, N.
    roller_loads : ndarray (n, N, Z) or None
    pin_forces : ndarray (n, Zp)
    pins_in_contact : ndarray (n,)
    carrier_rotation : ndarray (n,)
        rad.
    equilibrium_residual : ndarray (n,)
        |ΣF| / Σ|λ| of the disc at each angle (dimensionless).
    iterations : ndarray (n,)
    fields : dict angle (rad) → displacement (n_dofs,)
        At the case's saved angles and the angle of the maximum bearing load.
    timings : dict
    von_mises_envelope : ndarray (n_vertices,) or None
        Largest vertex von Mises stress of every mesh vertex over all solved angles, MPa (with
        ``stress_envelope=True``); the same vertex stresses as :func:`rvfem.fem.stress_fields`.
    von_mises_envelope_theta : ndarray (n_vertices,) or None
        Crank angle at which each vertex reaches it, rad.
    solutions : tuple of AngleResult
        The full solution of every angle (any displacement field can be rebuilt exactly from it
        with :func:`displacement`).
    """

    theta: np.ndarray
    bearing_forces: np.ndarray
    roller_loads: np.ndarray | None
    roller_angles: np.ndarray | None
    pin_forces: np.ndarray
    pins_in_contact: np.ndarray
    carrier_rotation: np.ndarray
    equilibrium_residual: np.ndarray
    iterations: np.ndarray
    fields: dict
    timings: dict
    von_mises_envelope: np.ndarray | None = None
    von_mises_envelope_theta: np.ndarray | None = None
    solutions: tuple = field(default=(), repr=False)

    @property
    def bearing_loads(self) -> np.ndarray:
        """|F|, (n, N), N."""
        return np.linalg.norm(self.bearing_forces, axis=2)

    def torsional_stiffness_Nm_per_arcmin(self, torque_Nmm: float) -> float:
        """Mean disc torque / carrier rotation, N·m/arcmin."""
        phi = float(np.mean(np.abs(self.carrier_rotation)))
        return abs(torque_Nmm) / 1000.0 / (phi * 180.0 * 60.0 / math.pi)


def likely_columns(system: DiscSystem, sets: list[ContactSet]) -> np.ndarray:
    """Interface columns the load cycle will need, to compute them in one parallel sweep.

    Every roller and bearing column, and those of the pins that touch (gap ≤ 1 µm) on the side
    that resists the disc torque (with a margin). Columns missed here are computed when first
    needed, at a higher cost per column (small batches, one thread).
    """
    T = system.case.loads.disc_torque_Nmm
    zp = system.case.pins.count
    cols = []
    for cset in sets:
        W = cset.W.tocsc()
        moment = np.asarray(W.T @ system.interface.resultants[:, 2])[:zp]
        gap = np.where(cset.signorini[:zp], cset.gap0[:zp], -cset.offset[:zp])
        likely = np.ones(W.shape[1], dtype=bool)
        # a flexible disc also loads pins just past the ends of the classical loaded arc, whose
        # lever arms are small and of either sign: keep those within 25 % of the largest arm
        likely[:zp] = (gap <= 1e-3) & (moment * np.sign(T) <= 0.25 * np.abs(moment).max())
        cols.append(W[:, np.flatnonzero(likely)].indices)
    return np.unique(np.concatenate(cols))


def cycle_angles(case: Case) -> np.ndarray:
    """Crank angles of a full revolution at the case's step (endpoint excluded), rad."""
    n = int(round(360.0 / case.analysis.angle_step_deg))
    return np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)


def load_cycle(system: DiscSystem, thetas: np.ndarray | None = None, *, progress=None,
               saved_angles_deg: tuple[float, ...] | None = None,
               stress_envelope: bool = False) -> CycleResult:
    """Solve every crank angle of a revolution, warm-starting each from the previous one.

    Parameters
    ----------
    system : DiscSystem
    thetas : ndarray, optional
        Crank angles, rad; default a full revolution at ``case.analysis.angle_step_deg``.
    progress : callable, optional
        Called as ``progress(i, n)`` after each angle (the CLI draws its progress bar with it).
    saved_angles_deg : tuple, optional
        Angles whose displacement fields are kept; default ``case.analysis.saved_angles_deg``
        (the nearest solved angle is used) plus the angle of the maximum bearing load.
    stress_envelope : bool
        Also track the largest vertex von Mises stress of every vertex over all angles: one
        back-substitution and one sparse product per angle (about 5 ms on the default case).
    """
    case = system.case
    thetas = cycle_angles(case) if thetas is None else np.asarray(thetas, dtype=float)
    t0 = time.perf_counter()
    results: list[AngleResult] = []
    prev = None
    # the per-angle systems are small (~100 unknowns): threaded BLAS only adds overhead there
    # (measured 7x slower on two cores), so the cycle runs BLAS single-threaded
    t_envelope = 0.0
    envelope = envelope_theta = None
    if stress_envelope:
        from .fem import nodal_stress_operator

        stress_op = nodal_stress_operator(system.model)
        nv = system.model.n_vertices
        envelope = np.full(nv, -np.inf)
        envelope_theta = np.zeros(nv)
    with threadpool_limits(limits=1, user_api="blas"):
        sets = [contact_set(system, float(th)) for th in thetas]
        system.compliance.ensure(likely_columns(system, [c for c, _ in sets]))
        t_prefetch = time.perf_counter() - t0
        for i, th in enumerate(thetas):
            prev = solve_angle(system, float(th), prev, contacts=sets[i])
            results.append(prev)
            if stress_envelope:
                t1 = time.perf_counter()
                sxx, syy, sxy = (stress_op @ displacement(system, prev)).reshape(3, nv)
                vm = np.sqrt(sxx * sxx - sxx * syy + syy * syy + 3.0 * sxy * sxy)
                higher = vm > envelope
                envelope[higher] = vm[higher]
                envelope_theta[higher] = th
                t_envelope += time.perf_counter() - t1
            if progress is not None:
                progress(i + 1, len(thetas))
    t_cycle = time.perf_counter() - t0 - t_envelope

    bf = np.stack([r.bearing_forces for r in results])
    loads = np.linalg.norm(bf, axis=2)
    saved = case.analysis.saved_angles_deg if saved_angles_deg is None else saved_angles_deg
    keep = {int(np.argmin(np.abs(np.angle(np.exp(1j * (thetas - math.radians(a))))))) for a in saved}
    keep.add(int(np.unravel_index(np.argmax(loads), loads.shape)[0]))
    t1 = time.perf_counter()
    fields = {float(thetas[k]): displacement(system, results[k]) for k in sorted(keep)}
    t_fields = time.perf_counter() - t1
    rollers = None if results[0].roller_loads is None else np.stack([r.roller_loads for r in results])
    rangles = None if results[0].roller_angles is None else np.stack([r.roller_angles for r in results])
    return CycleResult(
        theta=thetas,
        bearing_forces=bf,
        roller_loads=rollers,
        roller_angles=rangles,
        pin_forces=np.stack([r.pin_forces for r in results]),
        pins_in_contact=np.array([r.pins_in_contact for r in results]),
        carrier_rotation=np.array([r.carrier_rotation for r in results]),
        equilibrium_residual=np.array([r.solution.residual["relative"] for r in results]),
        iterations=np.array([r.solution.iterations for r in results]),
        fields=fields,
        timings={"cycle": t_cycle, "prefetch": t_prefetch, "fields": t_fields,
                 "stress_envelope": t_envelope,
                 "columns_solved": system.compliance.columns_solved,
                 "column_solve": system.compliance.solve_seconds},
        von_mises_envelope=envelope,
        von_mises_envelope_theta=envelope_theta,
        solutions=tuple(results),
    )
