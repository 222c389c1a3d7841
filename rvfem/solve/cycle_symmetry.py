"""The symmetries of a load cycle: the crank angles that a turn of the disc or a swap of the discs gives.

The load cycle of an exactly N-fold symmetric disc repeats, turned, every 2π/N; a mirrored pair of
discs repeats, with the discs swapped, every π. :func:`symmetry_plan` says which angles of a cycle
are solved and how the others follow, :func:`turn_result` gives the solution at θ + k·2π/N from the
one at θ (the contacts mapped through the interface) and :func:`turn_field` turns a displacement
field.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import scipy.sparse as sp

from rvfem.solve.contact import ContactSet
from rvfem.solve.cycle_angle import AngleResult, angle_result
from rvfem.solve.cycle_contacts import contact_model_key, contact_set
from rvfem.solve.cycle_system import DiscSystem, OperatingPoint


def turn_result(system: DiscSystem, result: AngleResult, k: int,
                contacts: ContactSet | None = None, op: OperatingPoint | None = None) -> AngleResult:
    """The solution at θ + k·2π/N from the one at θ, by the disc's exact N-fold symmetry.

    Turning the whole configuration by 2π/N maps the disc (and its mesh) onto itself, the
    eccentric of crank i onto that of crank i + 1, the pin ring onto itself (pin j onto pin
    j + Zp/N·…, whatever the turned positions say) and each roller cage onto the next bearing's:
    the state at θ + 2π/N is the state at θ turned (:func:`rvfem.solve.models.roller_angles` phases the cages for
    this). The contacts of the turned angle are mapped onto the solved ones through the
    interface: M with W(θ')·M = Qᵏ·W(θ) (a permutation of pins and rollers, a rotation of x/y
    spring pairs), λ' = M·λ; the rigid motion turns with the disc, φ is unchanged.

    Parameters
    ----------
    system : DiscSystem
        With ``system.symmetry = N > 1``.
    result : AngleResult
        Solved at θ.
    k : int
        Number of 2π/N steps.
    contacts : ContactSet, optional
        The contact set at θ + k·2π/N (built here otherwise, at the operating point ``op``).
    op : OperatingPoint, optional
        The operating point ``result`` was solved at; default the case's.

    Raises
    ------
    ValueError
        If the turned contacts do not match the solved ones (the configuration is not
        symmetric, e.g. a pin count or a model that breaks the symmetry): solve that angle
        directly instead.
    """
    k = int(k)
    if k == 0:
        return result
    beta = 2.0 * math.pi * k / system.symmetry      # signed: the result is labelled θ + β
    theta = result.theta + beta
    cset = contacts if contacts is not None else contact_set(system, theta, op)[0]
    old = result.contacts
    # the map depends only on the two contact sets and the turn, which the solved angle, the turn
    # and whether the pins carry friction loads determine (contact sets are built once per angle
    # and friction, :func:`rvfem.solve.cycle_contacts.contact_sets`): found once per system (the
    # attribution's cycles and the operating points of a sweep turn the same solved angles)
    key = ("map", round(float(result.theta), 12), k, old.W_load is not None) + contact_model_key(system)
    M = system.contact_sets.get(key)
    if M is None:
        pairs = [(old.W, cset.W)]
        if old.W_load is not None or cset.W_load is not None:      # friction: the load weights map too
            pairs.append((old.load_weights, cset.load_weights))
        M = _permutation_map(system.compliance.rotation_power(k), *pairs, turned=_turned_probes(system, k))
        if M is None:
            M = _contact_map(system.compliance.rotation_power(k), *pairs)
        system.contact_sets[key] = M
    # gaps, offsets and levers (mm; 1e-9 mm absolute, 1e-8 relative)
    mapped = M @ np.stack([old.gap0, old.offset, old.lever], axis=1)
    direct = np.stack([cset.gap0, cset.offset, cset.lever], axis=1)
    if np.any(np.abs(mapped - direct) > 1e-9 + 1e-8 * np.abs(direct)):
        raise ValueError(f"the contacts at {math.degrees(theta):.3f}° are not the turned contacts of "
                         f"{math.degrees(result.theta):.3f}°")
    sol = result.solution
    lam = M @ sol.force
    WL = cset.load_weights
    vectors = np.asarray(WL.T @ system.interface.resultants[:, :2]) * lam[:, None]
    c, s_ = math.cos(beta), math.sin(beta)
    a = sol.rigid
    rigid = np.array([c * a[0] - s_ * a[1], s_ * a[0] + c * a[1], a[2]])
    turned = dataclasses.replace(sol, force=lam, vectors=vectors, gap=M @ sol.gap, rigid=rigid,
                                 residual=dict(sol.residual))
    root, k0 = result.origin if result.origin is not None else (result, 0)
    return angle_result(system, theta, turned, cset, origin=(root, k0 + k))


@functools.lru_cache(maxsize=8)
def _probes(n_columns: int) -> np.ndarray:
    """Two fixed random vectors over the interface columns (n_columns, 2), read-only."""
    z = np.random.default_rng(0).standard_normal((n_columns, 2))
    z.flags.writeable = False
    return z


def _turned_probes(system: DiscSystem, k: int) -> np.ndarray:
    """Qᵏᵀ·z of the probes z (:func:`_probes`), once per system and k (kept with the contact sets)."""
    compliance = system.compliance
    key = ("probes", int(k) % compliance.order, id(compliance))
    hit = system.contact_sets.get(key)
    if hit is None or hit[0] is not compliance:
        Qk = compliance.rotation_power(k)
        hit = system.contact_sets[key] = (compliance, np.asarray(Qk.T @ _probes(Qk.shape[0])))
    return hit[1]


def _permutation_map(Qk: sp.spmatrix, *pairs: tuple[sp.spmatrix, sp.spmatrix],
                     turned: np.ndarray | None = None) -> np.ndarray | None:
    """M of :func:`_contact_map` when it is a permutation (pins and rollers turn into pins and
    rollers), else None; ``turned`` is Qkᵀ·z of the probes z, when known (:func:`_turned_probes`).

    Found and checked with two random probes z over the columns: the turned weights of contact j
    and the weights of its image σ(j) are the same column, Qk·W0[:, j] = W1[:, σ(j)], so
    (W0ᵀ·Qkᵀ·z)[j] = (W1ᵀ·z)[σ(j)] for both probes, within 1e-8 of the weights' scale; σ pairs
    each value with the nearest one. Two different columns give the same two values with
    probability zero, so the check is that of the columns themselves (on every pair: the gap
    weights and, with friction, the load weights), at the cost of a few sparse products.
    """
    def weighted(W, z):                                       # Wᵀ·z from the CSC arrays
        contact = np.repeat(np.arange(W.shape[1]), np.diff(W.indptr))
        values = W.data[:, None] * z[W.indices]
        return np.stack([np.bincount(contact, values[:, i], W.shape[1]) for i in range(z.shape[1])], axis=1)

    sigma = None
    for W0, W1 in pairs:
        W0, W1 = (W if sp.isspmatrix_csc(W) else sp.csc_matrix(W) for W in (W0, W1))
        if W1.shape != W0.shape or W0.nnz == 0:
            return None
        z = _probes(W0.shape[0])
        Qz = turned if turned is not None else np.asarray(Qk.T @ z)
        mapped = weighted(W0, Qz)                             # (n_contacts, 2)
        direct = weighted(W1, z)
        tol = 1e-8 * float(np.abs(W0.data).max()) * float(np.abs(z).max()) * max(int(np.diff(W0.indptr).max()), 1)
        if sigma is None and len(direct) == 1:
            sigma = np.zeros(1, dtype=int)
        elif sigma is None:
            order = np.argsort(direct[:, 0], kind="stable")
            ranked = direct[order, 0]
            pos = np.clip(np.searchsorted(ranked, mapped[:, 0]), 1, len(ranked) - 1)
            nearer = np.where(np.abs(ranked[pos - 1] - mapped[:, 0]) <= np.abs(ranked[pos] - mapped[:, 0]), pos - 1, pos)
            sigma = order[nearer]
            if len(np.unique(sigma)) != len(sigma):
                return None
        if np.abs(direct[sigma] - mapped).max() > tol:
            return None
    if sigma is None:                                         # no pairs given: nothing to map
        return None
    M = np.zeros((len(sigma), len(sigma)))
    M[sigma, np.arange(len(sigma))] = 1.0
    return M


def _contact_map(Qk: sp.spmatrix, *pairs: tuple[sp.spmatrix, sp.spmatrix]) -> np.ndarray:
    """M (n_contacts × n_contacts) with W1·M = Qk·W0 for the first pair (W0, W1) of contact
    weights, checked on every pair (the gap weights and, with friction, the load weights);
    ValueError if there is none.

    For contacts that do not turn one into one (a rigid bore's x and y springs turn into
    combinations of the next bore's); pins and rollers are matched by :func:`_permutation_map`.
    The weights touch a few hundred of the interface columns: M is found on the dense rows of
    those columns only, (W1ᵀW1)·M = W1ᵀ(Qk·W0) in the least-squares sense, and each pair is
    checked to 1e-8 of its largest weight.
    """
    blocks = []
    for W0, W1 in pairs:
        W0, W1 = sp.csc_matrix(W0), sp.csc_matrix(W1)
        if W1.shape != W0.shape:
            raise ValueError("the turned angle has a different number of contacts")
        blocks.append((W0, sp.csc_matrix(Qk @ W0), W1))
    rows = np.unique(np.concatenate([m.indices for _, T, W1 in blocks for m in (T, W1)]))
    dense_blocks = [(W0, T[rows].toarray(), W1[rows].toarray()) for W0, T, W1 in blocks]
    _, T, A = dense_blocks[0]
    try:
        M = np.linalg.solve(A.T @ A, A.T @ T)
    except np.linalg.LinAlgError:
        raise ValueError("the turned contacts are not the solved ones (a contact without weights)") from None
    M[np.abs(M) < 1e-12] = 0.0
    for W0, T, A in dense_blocks:
        scale = max(float(np.abs(W0.data).max()) if W0.nnz else 0.0, 1e-30)
        if T.size and np.abs(A @ M - T).max() > 1e-8 * scale:
            raise ValueError("the turned contacts are not the solved ones")
    return M


def symmetry_plan(thetas: np.ndarray, order: int = 1, mirror: bool = False):
    """Which crank angles to solve and how to obtain the others by symmetry.

    The angles must be a uniform full revolution (θ_j = θ_0 + j·2π/n). The load cycle of an
    N-fold symmetric disc repeats, turned, every 2π/N (``order`` = N); a mirrored pair of discs
    repeats, with the discs swapped, every π (``mirror``). Together the angle indices repeat
    every g = gcd(n, n/N, n/2) and only the first g angles are solved.

    Returns
    -------
    solve : ndarray of int
        Indices of the angles to solve (0 … g − 1), or all of them when nothing applies.
    source : list of (i, swap, k)
        For every angle j: the solved index i, whether the discs are swapped (0/1) and the
        number k of 2π/N turns (of either sign, so that θ_i + swap·π + k·2π/N is θ_j itself).
    """
    thetas = np.asarray(thetas, dtype=float)
    n = len(thetas)
    steps = np.mod(np.diff(np.append(thetas, thetas[0] + 2 * math.pi)), 2 * math.pi) if n else np.zeros(0)
    uniform = n > 1 and np.allclose(steps, 2 * math.pi / n, rtol=0, atol=1e-9)
    shifts = []
    if uniform and order > 1 and n % order == 0:
        shifts.append((n // order, "turn"))
    if uniform and mirror and n % 2 == 0:
        shifts.append((n // 2, "swap"))
    if not shifts:
        return np.arange(n), [(j, 0, 0) for j in range(n)]
    g = n
    for sh, _ in shifts:
        g = math.gcd(g, sh)
    turn = n // order if (uniform and order > 1 and n % order == 0) else 0
    half = n // 2 if (uniform and mirror and n % 2 == 0) else 0
    # every offset d = j − i is reached exactly, with turns of either sign and no wrap past 2π,
    # so that each result obtained carries the angle θ_j itself
    options = sorted(((swap * half + k * turn, swap, k) for swap in ((0, 1) if half else (0,))
                      for k in (range(-order + 1, order) if turn else (0,))), key=lambda o: abs(o[2]))
    source = []
    for j in range(n):
        i, d = j % g, j - j % g
        swap, k = next((sw, k) for off, sw, k in options if off == d)
        source.append((i, swap, k))
    return np.arange(g), source


def turned_nodes(system: DiscSystem, k: int) -> np.ndarray:
    """The FE node that each node turns into by k·2π/N (k of either sign); vertices come first
    and turn into vertices."""
    perm = system.node_rotation
    if perm is None:
        raise ValueError("the disc model has no node rotation (its mesh is not symmetric)")
    target = np.arange(len(perm))
    step = perm if k > 0 else np.argsort(perm)
    for _ in range(abs(int(k))):
        target = step[target]
    return target


def turn_field(system: DiscSystem, u: np.ndarray, k: int) -> np.ndarray:
    """A displacement field (n_dofs,) turned by k·2π/N with the disc: the vector of node n
    turned by k·2π/N moves to the node n turns into (exact on the symmetric mesh)."""
    k = int(k)
    if k == 0:
        return u
    target = turned_nodes(system, k)
    a = 2.0 * math.pi * k / system.symmetry
    c, s_ = math.cos(a), math.sin(a)
    dofs = system.model.node_dofs
    ux, uy = u[dofs[:, 0]], u[dofs[:, 1]]
    out = np.empty_like(u)
    out[dofs[target, 0]] = c * ux - s_ * uy
    out[dofs[target, 1]] = s_ * ux + c * uy
    return out
