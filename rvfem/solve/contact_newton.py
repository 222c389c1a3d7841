"""The semismooth Newton method of one crank angle's condensed contact problem.

Per crank angle the unknowns are the contact forces λ (pins and rollers), the rigid motion ``a`` of
each disc and the carrier rotation φ; the equations are the contact laws, each disc's equilibrium
Rᵀλ = 0 and the carrier's Σ m_c λ_c = T_disc. They are solved by a semismooth Newton method (the
primal–dual active set for the rigid pins) on this small dense system (:class:`ContactProblem`,
:func:`newton_step`); :func:`rvfem.solve.contact.solve_bodies` chooses its start.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from rvfem.errors import ContactError
from rvfem.solve.contact_state import AngleSolution, Body


OPEN_SPRING_FRACTION = 1e-3
"""Stiffness of an open compression-only spring in the fallback linearised start, relative to its
secant stiffness (:func:`rvfem.solve.contact.solve_bodies`)."""


@dataclass(frozen=True)
class NewtonOptions:
    """Options of the semismooth Newton / primal–dual active-set iteration (:func:`rvfem.solve.contact.solve_bodies`).

    Attributes
    ----------
    max_iterations : int
        Bound of the iteration.
    label : str
        Names the crank angle in error messages (ends with a space).
    tol_gap : float
        Gap tolerance of the rigid (Signorini) contacts, mm.
    names : list of str or None
        Contact names for error messages.
    rigid_dofs : tuple of int
        Rigid-body motions of each body that are unknowns (0: x, 1: y, 2: rotation).
    g_cache : dict or None
        Keeps the contact compliance G of each set of bodies between solves (:class:`ContactProblem`):
        solves of the same contacts at other torques (a hysteresis loop) fill it once. None: each
        solve builds its own.
    """

    max_iterations: int = 50
    label: str = ""
    tol_gap: float = 1e-9
    names: list | None = None
    rigid_dofs: tuple = (0, 1, 2)
    g_cache: dict | None = None

    def name(self, i: int) -> str:
        return self.names[i] if self.names else str(i)


class ContactProblem:
    """The contact problem of bodies sharing one carrier, as functions of the unknowns.

    Unknowns: the contact forces λ (n_c), each body's rigid motion a (3 per body) and the carrier
    rotation φ (when there is a carrier). A contact's approach is δ = offset + lever·φ − v with
    v = G·λ + R_c·a, G = Wᵀ C W_load (+ the crankshaft coupling H) the compliance between the
    contacts; a spring's force is its law q(δ); a rigid contact has the gap g = gap0 + v ≥ 0.
    The equations: springs λ = q(δ), active rigid contacts g = 0, inactive ones λ = 0, each body
    in equilibrium (R_Lᵀλ = 0) and the carrier Σ lever·λ = T.

    G is filled column by column as contacts become loaded: column j once the load columns of
    contact j are known (C is filled column-wise and symmetric, so the rows of every other contact
    come with them); a column of C never changes once computed, so neither does G's.
    """

    def __init__(self, bodies: list, torque: float | None, coupling: np.ndarray | None = None,
                 rigid_dofs: tuple = (0, 1, 2), g_cache: dict | None = None):
        self.bodies = bodies
        self.nb = len(bodies)
        self.carrier = torque is not None            # without a carrier: no φ unknown
        self.torque = 0.0 if torque is None else torque
        csets = [b.cset for b in bodies]
        rigid_dofs = tuple(rigid_dofs)
        fixed = None if g_cache is None else self._cached_parts(g_cache, csets, coupling, rigid_dofs)
        if fixed is None:
            fixed = self._parts(csets, coupling, rigid_dofs)
            if g_cache is not None:
                fixed["G"], fixed["filled"] = self._share_G(g_cache, csets, coupling, fixed["G"], fixed["filled"])
                g_cache[self._parts_key(csets, rigid_dofs)] = (
                    list(csets), [(b.interface, b.compliance) for b in bodies],
                    None if coupling is None else np.array(coupling), fixed)
        self.offs: np.ndarray = fixed["offs"]
        self.nc: int = fixed["nc"]
        self.nr: int = fixed["nr"]                   # rigid-motion unknowns, 3 per body
        self.n: int = fixed["n"]
        self.eq: slice = fixed["eq"]
        self.dropped: list[int] = fixed["dropped"]
        self.Rc: np.ndarray = fixed["Rc"]            # rigid motion → approach, per contact
        self.RL: np.ndarray = fixed["RL"]            # Fx, Fy, Mz on its body per unit λ
        self.Rfull: np.ndarray = fixed["Rfull"]
        self.subs: list = fixed["subs"]
        self.moment: np.ndarray = fixed["moment"]
        self.sig: np.ndarray = fixed["sig"]
        self.spring: np.ndarray = fixed["spring"]
        self.si: np.ndarray = fixed["si"]
        self.gap0: np.ndarray = fixed["gap0"]
        self.offset: np.ndarray = fixed["offset"]
        self.lever: np.ndarray = fixed["lever"]
        self.laws: list = fixed["laws"]
        self.Rc_springs: np.ndarray = fixed["Rc_springs"]
        self.lever_springs: np.ndarray = fixed["lever_springs"]
        self.r_typ: float = fixed["r_typ"]
        self.row_scale: np.ndarray = fixed["row_scale"]
        self.newton_template: np.ndarray = fixed["newton_template"]
        self.G: np.ndarray = fixed["G"]
        self.filled: np.ndarray = fixed["filled"]
        self.scale_f = max(abs(self.torque) / self.r_typ, 1.0)
        self._open_tangent: np.ndarray | None = None

    def _parts(self, csets: list, coupling, rigid_dofs: tuple) -> dict[str, Any]:
        """Everything of the problem that does not depend on the torque: the contacts' rigid-motion
        and load rows, their weights, data and laws, the sizes and scales, the constant rows of the
        Newton matrix and an empty G (with its filled columns)."""
        bodies, nb = self.bodies, self.nb
        offs = np.concatenate([[0], np.cumsum([c.W.shape[1] for c in csets])]).astype(int)
        nc = int(offs[-1])
        nr = 3 * nb                                  # rigid-motion unknowns, 3 per body
        dropped = [k for k in range(3) if k not in rigid_dofs]
        Rc = np.zeros((nc, nr))                      # rigid motion → approach, per contact
        RL = np.zeros((nc, nr))                      # Fx, Fy, Mz on its body per unit λ
        Rfull = np.zeros((nc, 3))
        subs = [_weights(k, b, offs, dropped, Rc, RL, Rfull) for k, b in enumerate(bodies)]
        sig = np.concatenate([c.signorini for c in csets])
        lever = np.concatenate([c.lever for c in csets])
        laws = _grouped_laws([(offs[k] + np.asarray(idx, dtype=int), law)
                              for k, c in enumerate(csets) for idx, law in c.laws])
        spring = ~sig
        si = np.flatnonzero(spring)
        r_typ = max(float(np.abs(lever).max()), 1.0)
        n = nc + nr + 1 if self.carrier else nc + nr
        row_scale = np.tile([1.0, 1.0, 1.0 / r_typ], nb)
        # the rows of the Newton matrix that do not change (:func:`newton_matrix`): each body's
        # equilibrium, the carrier's, and the identity rows of the rigid motions left out
        template = np.zeros((n, n))
        template[nc:nc + nr, :nc] = RL.T * row_scale[:, None]
        if self.carrier:
            template[nc + nr, :nc] = lever / r_typ
        for k in range(nb):
            for d in dropped:
                template[nc + 3 * k + d, nc + 3 * k + d] = 1.0
        return {
            "offs": offs, "nc": nc, "nr": nr, "dropped": dropped, "Rc": Rc, "RL": RL, "Rfull": Rfull,
            "subs": subs, "moment": RL[:, 2::3].sum(axis=1),      # Mz of each contact on its own body
            "sig": sig, "gap0": np.concatenate([c.gap0 for c in csets]),
            "offset": np.concatenate([c.offset for c in csets]), "lever": lever, "laws": laws,
            "spring": spring, "si": si, "Rc_springs": Rc[si], "lever_springs": lever[si],
            "r_typ": r_typ, "n": n, "eq": slice(nc, nc + nr), "row_scale": row_scale,
            "newton_template": template,
            "G": np.zeros((nc, nc)) if coupling is None else np.array(coupling, dtype=float, order="C"),
            "filled": np.zeros(nc, dtype=bool),
        }

    def _parts_key(self, csets: list, rigid_dofs: tuple) -> tuple:
        return (("parts", self.carrier, rigid_dofs) + tuple(id(c) for c in csets)
                + tuple(id(b.interface) for b in self.bodies) + tuple(id(b.compliance) for b in self.bodies))

    def _cached_parts(self, cache: dict, csets: list, coupling, rigid_dofs: tuple) -> dict[str, Any] | None:
        """The torque-independent parts (:meth:`_parts`) of a problem of the same contact sets and
        interfaces (by identity), compliances, coupling, rigid motions and carrier solved before
        with ``cache``, or None. Its G is the shared one (:meth:`_share_G`)."""
        entry = cache.get(self._parts_key(csets, rigid_dofs))
        if entry is None:
            return None
        sets, models, coupled, fixed = entry
        if not (all(a is b for a, b in zip(sets, csets))
                and all(i is b.interface and c is b.compliance for (i, c), b in zip(models, self.bodies))
                and _same_coupling(coupled, coupling)):
            return None
        return fixed

    def _share_G(self, cache: dict, csets: list, coupling, G: np.ndarray, filled: np.ndarray) -> tuple:
        """G and its filled columns from ``cache`` if the same contact sets (by identity), the
        same compliances and the same coupling filled them before, else ``G``, ``filled``, put
        there. G depends on the contacts' weights, the compliance and the coupling only, and its
        columns never change once computed, so the arrays are shared and filled further in place."""
        key = tuple(id(c) for c in csets) + tuple(id(b.compliance) for b in self.bodies)
        entry = cache.get(key)
        if entry is not None and all(a is b for a, b in zip(entry[0], csets)) and _same_coupling(entry[1], coupling):
            return entry[2], entry[3]
        cache[key] = (list(csets), None if coupling is None else np.array(coupling), G, filled)
        return G, filled

    def G_full(self, idx: np.ndarray) -> np.ndarray:
        """G with the columns of contacts ``idx`` valid (the others are not read with weight)."""
        new = idx[~self.filled[idx]]
        if new.size:
            offs = self.offs
            for k, (b, (touched, WsubT, WL_dense, nonzero)) in enumerate(zip(self.bodies, self.subs)):
                local = new[(new >= offs[k]) & (new < offs[k + 1])] - offs[k]
                if local.size:
                    used = np.flatnonzero(nonzero[:, local].any(axis=1))      # their load columns
                    b.compliance.ensure(touched[used])
                    block = _submatrix(b.compliance.C, touched, touched[used])
                    self.G[offs[k]:offs[k + 1], offs[k] + local] += WsubT @ (block @ WL_dense[np.ix_(used, local)])
            self.filled[new] = True
        return self.G

    def G_cols(self, idx: np.ndarray) -> np.ndarray:
        if idx.size == 0:
            return np.zeros((self.nc, 0))
        return self.G_full(idx)[:, idx]

    def state(self, lam, a, phi) -> tuple:
        """(v, δ, q(δ), dq/dδ) at the unknowns λ, a, φ."""
        v = self.G_full(np.flatnonzero(lam != 0)) @ lam + self.Rc @ a      # λ = 0 off the valid columns
        delta = self.offset + self.lever * phi - v
        q = np.zeros(self.nc)
        dq = np.zeros(self.nc)
        for idx, law in self.laws:
            q[idx], dq[idx] = law(delta[idx])
        return v, delta, q, dq

    def unbalance(self, lam) -> float:
        """The largest residual of the bodies' and the carrier's equilibrium (N, N·mm / r_typ)."""
        unbalanced = float(np.abs((self.RL.T @ lam) * self.row_scale).max())
        if self.carrier:
            unbalanced = max(unbalanced, abs(self.lever @ lam - self.torque) / self.r_typ)
        return unbalanced

    def open_tangent(self) -> np.ndarray:
        """Secant stiffness of every spring at the force it is expected to carry (computed once)."""
        if self._open_tangent is None:
            k = np.zeros(self.nc)
            t_ref = self.torque if self.torque else self.r_typ     # no torque: the secant at about 1 N
            for b, (lo, hi) in zip(self.bodies, zip(self.offs[:-1], self.offs[1:])):
                for idx, ks, _ in _secant_stiffnesses(b, t_ref / self.nb):
                    k[lo + np.arange(hi - lo)[idx]] = ks
            self._open_tangent = k
        return self._open_tangent

    def solutions(self, it: "NewtonIterate", iterations: int) -> list[AngleSolution]:
        """One :class:`rvfem.solve.contact_state.AngleSolution` per body from a converged iterate.

        λ from the last Newton step satisfies the (linear) equilibrium equations to round-off and
        the spring laws to the iteration's tolerance; it is not replaced by q(δ), which would trade
        the former for the latter."""
        sig, lever = self.sig, self.lever
        lam = np.where(sig & ~it.active, 0.0, it.lam)
        gap_out = np.where(sig, self.gap0 + it.v, -it.delta)
        carrier_res = float(abs(lever @ lam - self.torque))
        out = []
        for k in range(self.nb):
            rows = slice(self.offs[k], self.offs[k + 1])
            lk, Rk = lam[rows], self.Rfull[rows]
            res_f = float(np.linalg.norm(Rk[:, :2].T @ lk))
            residual = {
                "force_N": res_f,
                "moment_Nmm": float(abs(Rk[:, 2] @ lk)),
                "carrier_Nmm": carrier_res,
                "relative": res_f / max(float(np.abs(lk).sum()), 1e-30),
                "torque_Nmm": float(lever[rows] @ lk),
            }
            out.append(AngleSolution(lk, Rk[:, :2] * lk[:, None], gap_out[rows], it.a[3 * k:3 * k + 3],
                                     float(it.phi), iterations, residual))
        return out


@dataclass
class NewtonIterate:
    """The unknowns of one Newton iterate and what follows from them (:meth:`ContactProblem.state`),
    with the active set of the rigid contacts."""

    lam: np.ndarray
    a: np.ndarray
    phi: float
    active: np.ndarray
    # set by update() (ContactProblem.state): v, δ, q(δ) and dq/dδ at these unknowns
    v: np.ndarray = field(init=False, repr=False)
    delta: np.ndarray = field(init=False, repr=False)
    q: np.ndarray = field(init=False, repr=False)
    dq: np.ndarray = field(init=False, repr=False)

    def update(self, problem: ContactProblem) -> "NewtonIterate":
        self.v, self.delta, self.q, self.dq = problem.state(self.lam, self.a, self.phi)
        return self


def initial_iterate(problem: ContactProblem, start: list | None, tol_gap: float) -> NewtonIterate:
    """The first iterate: a warm start's forces, rigid motions and carrier rotation, with its
    loaded rigid contacts and any overlapping one active; cold, zero unknowns with the touching
    rigid contacts active whose force on the body opposes the torque (the others can only be
    loaded by a reversed torque). The active-set loop corrects either guess."""
    sig, gap0 = problem.sig, problem.gap0
    if start is not None:
        lam = np.concatenate([s.force for s in start])
        active = sig & ((lam > 0) | (gap0 < -tol_gap))
        it = NewtonIterate(lam, np.concatenate([s.rigid for s in start]), start[0].carrier_rotation, active)
    else:
        active = sig & (gap0 <= tol_gap) & (problem.moment * problem.torque <= 0)
        active |= first_to_close(problem, active)
        it = NewtonIterate(np.zeros(problem.nc), np.zeros(problem.nr), 0.0, active)
    return it.update(problem)


def first_to_close(problem: ContactProblem, active: np.ndarray) -> np.ndarray:
    """The rigid contacts a cold start adds to ``active``: per body whose rigid contacts on the
    torque's side (force on the body against the torque) are all open, the one that a rotation of
    the body about its centre closes first (smallest gap / |moment arm|).

    Such a body has a backlash all round (a positive equidistant modification with rigid pins: at
    zero load no pin touches). With none of its rigid contacts active, the rotation of the body and
    the carrier is held by nothing: the first Newton matrix is singular, exactly so for a profile
    without pitch errors (the solve then stops as a mechanism) and up to round-off otherwise (the
    step then depends on the round-off). The torque turns the body through its backlash onto its
    pins; starting with the first pin it meets active, the active-set loop adds the others."""
    out = np.zeros(problem.nc, dtype=bool)
    if not problem.carrier or not problem.torque:
        return out
    arm = np.abs(problem.moment)
    side = problem.sig & (problem.moment * problem.torque < 0) & (arm > 0)
    for lo, hi in zip(problem.offs[:-1], problem.offs[1:]):
        candidates = np.flatnonzero(side[lo:hi]) + lo
        if candidates.size and not active[candidates].any():
            out[candidates[np.argmin(problem.gap0[candidates] / arm[candidates])]] = True
    return out


def penalty_scale(problem: ContactProblem, active: np.ndarray) -> float:
    """κ, N/mm: the gap rows' scale, the inverse median self-compliance of the active rigid
    contacts (1e6 without any, or on a rigid body)."""
    if not active.any():
        return 1e6
    idx = np.flatnonzero(active)
    compliance = float(np.median(np.diag(problem.G_cols(idx)[idx])))
    return 1.0 / compliance if compliance > 0 else 1e6


def newton_matrix(problem: ContactProblem, it: NewtonIterate, q: np.ndarray, dq: np.ndarray,
                  kappa: float) -> tuple[np.ndarray, np.ndarray]:
    """The Newton matrix and residual of the contact problem at an iterate, with the spring
    forces ``q`` and tangents ``dq`` (those of the laws, or of a linearised or regularised law).

    Rows: springs λ − q(δ); active rigid contacts κ·g; inactive ones λ; each body's equilibrium
    (scaled to N); the carrier (Σ lever·λ − T)/r_typ. Columns: λ, a, φ."""
    p = problem
    nc, nr, n, eq, si = p.nc, p.nr, p.n, p.eq, p.si
    lam, active = it.lam, it.active
    J = np.flatnonzero(active | (p.spring & (dq > 0)) | (lam != 0))   # the forces that move the approaches
    G = p.G_full(J).reshape(-1)                  # G[i, j] at i·nc + j (a C-ordered view)
    Jm = p.newton_template.copy()                # the equilibrium and carrier rows, the dropped motions
    flat = Jm.reshape(-1)                        # Jm[i, j] at i·n + j
    r = np.zeros(n)
    dqs = dq[si]
    r[si] = lam[si] - q[si]
    flat[si * (n + 1)] = 1.0
    flat[si[:, None] * n + J] += dqs[:, None] * G.take(si[:, None] * nc + J)
    Jm[si, eq] = dqs[:, None] * p.Rc_springs
    if p.carrier:
        Jm[si, nc + nr] = -dqs * p.lever_springs
    ai = np.flatnonzero(active)
    r[ai] = kappa * (p.gap0[ai] + it.v[ai])
    flat[ai[:, None] * n + J] = kappa * G.take(ai[:, None] * nc + J)
    Jm[ai, eq] = kappa * p.Rc[ai]
    ii = np.flatnonzero(p.sig & ~active)
    r[ii] = lam[ii]
    flat[ii * (n + 1)] = 1.0
    r[eq] = (p.RL.T @ lam) * p.row_scale
    if p.carrier:
        r[nc + nr] = (p.lever @ lam - p.torque) / p.r_typ
    return Jm, r


def known_rows(problem: ContactProblem, active: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """Rows whose step is known: open springs (dq = 0: λ = q) and inactive rigid contacts (λ = 0).

    Their steps are known, and the rest is a smaller system (about half the contacts are open).
    An open spring's force becomes exactly 0: a solve of the whole system would leave round-off
    (1e-18 N), which would mark it as loaded and fetch its compliance columns."""
    known = np.zeros(problem.n, dtype=bool)
    known[problem.si[dq[problem.si] == 0]] = True
    known[np.flatnonzero(problem.sig & ~active)] = True
    return known


def linearised_start_laws(problem: ContactProblem, it: NewtonIterate, engaged: np.ndarray) -> None:
    """The first linear solve of a cold start: the ``engaged`` springs acting both ways, so that the
    system is stable; the others open (``it.q``, ``it.dq`` overwritten)."""
    for idx, law in problem.laws:
        on = engaged[idx]
        it.q[idx] = np.where(on, law(np.abs(it.delta[idx]))[0] * np.sign(it.delta[idx]), 0.0)
        it.dq[idx] = np.where(on, law(np.ones(np.size(it.delta[idx])))[1], 0.0)


def newton_step(problem: ContactProblem, it: NewtonIterate, kappa: float, colscale: np.ndarray,
                label: str = "") -> np.ndarray:
    """The Newton step at an iterate (:func:`reduced_newton_step`: :func:`newton_matrix` reduced by
    :func:`known_rows`, :func:`_reduced_step`).

    If the linearised system is a mechanism (every spring that could hold a rigid motion of a
    body or of the carrier is open: zero tangent, Palmgren's law at δ ≤ 0, e.g. a radial clearance
    wider than the approaches of the current iterate), the step is the Newton step of the
    regularised law the cold start uses (an open spring keeps OPEN_SPRING_FRACTION of its secant
    stiffness as a weak tension spring): it moves the body through the clearance onto its rollers.
    The next steps are the true law's again, so the solution is unchanged.

    Raises
    ------
    ContactError
        If even that system is a mechanism (no contact at all can hold the body).
    """
    step = reduced_newton_step(problem, it, it.q, it.dq, kappa, colscale)
    if step is not None:
        return step
    opened = problem.spring & (it.dq == 0)
    k_open = OPEN_SPRING_FRACTION * problem.open_tangent()
    q = it.q.copy()
    q[opened] = k_open[opened] * np.minimum(it.delta[opened], 0.0)
    dq = np.where(opened, k_open, it.dq)
    step = reduced_newton_step(problem, it, q, dq, kappa, colscale)
    if step is None:
        raise ContactError(
            f"the contact problem {label}is a mechanism: no contact holds the disc or the carrier "
            "(every pin and roller is open). Check the radial clearance, the profile "
            "modifications and the torque.")
    return step


def _not_settled(problem: ContactProblem, it: NewtonIterate, history: list, spring_history: list,
                 options: NewtonOptions) -> ContactError:
    """The error of an iteration that did not settle: the contacts that kept flipping and the
    springs whose law is not met."""
    changes = np.zeros(problem.nc, dtype=int)
    for states in (history, spring_history):
        for h0, h1 in zip(states[:-1], states[1:]):
            changes += h0 != h1
    flipping = [options.name(int(i)) for i in np.flatnonzero(changes)]
    spring, lam, q = problem.spring, it.lam, it.q
    worst = np.argsort(-np.abs(lam - q) * spring)[:5]
    unsettled = [options.name(i) for i in worst if spring[i] and abs(lam[i] - q[i]) > 1e-8 * problem.scale_f]
    return ContactError(
        f"contact active set did not settle {options.label}within {options.max_iterations} iterations"
        + (f"; contacts that keep flipping: {', '.join(flipping)}" if flipping else "")
        + (f"; springs whose force law is not met: {', '.join(unsettled)}" if unsettled else "")
        + ". Check the profile modifications, the clearances and the pin friction (analysis.friction), "
        "or refine the angle step; a set that has not settled by now keeps cycling, so raising "
        "analysis.max_active_set_iterations rarely helps."
    )


def _newton(bodies, torque, coupling, start, options: NewtonOptions, engaged=None) -> list[AngleSolution]:
    """Semismooth Newton / primal–dual active set on :class:`ContactProblem` from ``start`` (a warm
    start per body, or None). ``engaged``: the first step is the linear solve of
    :func:`linearised_start_laws` (a cold start's linearised problem).

    Converged when the active set is unchanged by a step, every body and the carrier are in
    equilibrium, the spring laws hold to 1e-8 of the force scale and the active gaps are closed to
    ``tol_gap``."""
    problem = ContactProblem(bodies, torque, coupling, options.rigid_dofs, options.g_cache)
    p = problem
    it = initial_iterate(problem, start, options.tol_gap)
    kappa = penalty_scale(problem, it.active)
    colscale = np.concatenate([np.ones(p.nc), np.tile([1 / kappa, 1 / kappa, 1 / (kappa * p.r_typ)], p.nb),
                               [1 / (kappa * p.r_typ)]])
    history, spring_history = [], []
    for iteration in range(1, options.max_iterations + 1):
        first_linear = engaged is not None and iteration == 1
        if first_linear:
            linearised_start_laws(problem, it, engaged)
        inactive = np.flatnonzero(p.sig & ~it.active)
        step = newton_step(problem, it, kappa, colscale, options.label)
        it.lam = it.lam + step[:p.nc]
        it.lam[inactive] = 0.0
        it.a = it.a + step[p.eq]
        if p.carrier:
            it.phi = it.phi + step[p.nc + p.nr]
        it.update(problem)
        gap = p.gap0 + it.v
        new_active = p.sig & ((it.lam - kappa * gap) > 0)
        history.append(new_active)
        spring_history.append(p.spring & (it.dq > 0))
        spring_res = float(np.abs(it.lam[p.spring] - it.q[p.spring]).max()) if p.spring.any() else 0.0
        gap_res = float(np.abs(gap[it.active]).max()) if it.active.any() else 0.0
        # equilibrium of every body and of the carrier: met by every solved step (the equations are
        # linear), missed only where a step could not be solved
        balanced = p.unbalance(it.lam) <= 1e-9 * max(p.scale_f, float(np.abs(it.lam).sum()))
        settled = np.array_equal(new_active, it.active)
        it.active = new_active
        if (settled and balanced and spring_res <= 1e-8 * p.scale_f and gap_res <= options.tol_gap
                and not first_linear):
            return problem.solutions(it, iteration)
    raise _not_settled(problem, it, history, spring_history, options)


def reduced_newton_step(problem: ContactProblem, it: NewtonIterate, q: np.ndarray, dq: np.ndarray, kappa: float,
                        colscale: np.ndarray) -> np.ndarray | None:
    """:func:`_reduced_step` of :func:`newton_matrix` with :func:`known_rows`, the same numbers,
    without the rows of the known steps: only the rows of the unknown steps (loaded springs,
    active rigid contacts, the equilibrium and carrier rows) are built, those of the open springs
    and inactive rigid contacts (identity rows, about half the contacts) are not."""
    p = problem
    nc, nr, n = p.nc, p.nr, p.n
    lam, active = it.lam, it.active
    known = known_rows(p, active, dq)
    fixed, free = np.flatnonzero(known), np.flatnonzero(~known)
    J = np.flatnonzero(active | (p.spring & (dq > 0)) | (lam != 0))   # the forces that move the approaches
    G = p.G_full(J).reshape(-1)                  # G[i, j] at i·nc + j (a C-ordered view)
    m = int(np.searchsorted(free, nc))           # free[:m]: the contacts' rows, then eq and carrier
    rows = free[:m]
    is_spring = p.spring[rows]
    ps, pa = np.flatnonzero(is_spring), np.flatnonzero(~is_spring)   # loaded springs, active rigid
    si, ai = rows[ps], rows[pa]
    Jf = np.zeros((free.size, n))                # the rows `free` of newton_matrix's Jm
    flat = Jf.reshape(-1)
    Jf[m:] = p.newton_template[nc:]
    dqs = dq[si]
    flat[ps * n + si] = 1.0
    flat[ps[:, None] * n + J] += dqs[:, None] * G.take(si[:, None] * nc + J)
    Jf[ps, nc:nc + nr] = dqs[:, None] * p.Rc[si]
    if p.carrier:
        Jf[ps, nc + nr] = -dqs * p.lever[si]
    flat[pa[:, None] * n + J] = kappa * G.take(ai[:, None] * nc + J)
    Jf[pa, nc:nc + nr] = kappa * p.Rc[ai]
    r = np.empty(n)
    r[:nc] = lam - q                             # the springs' rows (the rigid contacts' set below)
    r[ai] = kappa * (p.gap0[ai] + it.v[ai])
    inactive = p.sig & ~active
    r[:nc][inactive] = lam[inactive]
    r[nc:nc + nr] = (p.RL.T @ lam) * p.row_scale
    if p.carrier:
        r[nc + nr] = (p.lever @ lam - p.torque) / p.r_typ
    step = np.zeros(n)
    step[fixed] = -r[fixed]
    cscale = colscale[free]
    at = np.arange(free.size)[:, None] * n
    A = flat.take(at + free) * cscale[None, :]
    rhs = -r[free] - flat.take(at + fixed) @ step[fixed]
    return _solved_step(A, rhs, cscale, step, free)


def _reduced_step(Jm: np.ndarray, r: np.ndarray, colscale: np.ndarray, known: np.ndarray) -> np.ndarray | None:
    """The Newton step of the system ``Jm·step = −r``: the ``known`` rows' steps are −r (their
    rows are identity rows), the rest solved with the columns scaled by ``colscale``. None if that
    system is singular and inconsistent (a mechanism: a rigid motion no contact resists)."""
    fixed, free = np.flatnonzero(known), np.flatnonzero(~known)
    step = np.zeros(r.size)
    step[fixed] = -r[fixed]
    cscale = colscale[free]
    rows = free[:, None] * r.size                # Jm[free][:, cols] gathered through the flat view
    flat = Jm.reshape(-1)
    A = flat.take(rows + free) * cscale[None, :]
    rhs = -r[free] - flat.take(rows + fixed) @ step[fixed]
    return _solved_step(A, rhs, cscale, step, free)


def _solved_step(A: np.ndarray, rhs: np.ndarray, cscale: np.ndarray, step: np.ndarray,
                 free: np.ndarray) -> np.ndarray | None:
    """``step`` with its ``free`` entries from A·y = rhs (y scaled by ``cscale``), or None if that
    system is singular and inconsistent (:func:`_reduced_step`)."""
    try:
        y = np.linalg.solve(A, rhs)
    except np.linalg.LinAlgError:
        y = np.linalg.lstsq(A, rhs, rcond=None)[0]
        if np.abs(A @ y - rhs).max() > 1e-8 * max(float(np.abs(rhs).max()), 1e-30):
            return None
    step[free] = y * cscale
    return step


def _weights(k: int, body, offs: np.ndarray, dropped: list, Rc: np.ndarray, RL: np.ndarray,
             Rfull: np.ndarray) -> tuple:
    """Fill body k's rows of R_c, R_L and R_full; its weights on the interface columns it touches
    (:class:`ContactProblem`)."""
    c, rows = body.cset, slice(offs[k], offs[k + 1])
    W = c.W.tocsc()                              # gaps/approaches are measured along W
    WL = c.load_weights.tocsc()                  # loads act along W_load
    Rc[rows, 3 * k:3 * k + 3] = np.asarray(W.T @ body.interface.resultants)
    RL[rows, 3 * k:3 * k + 3] = np.asarray(WL.T @ body.interface.resultants)
    Rfull[rows] = RL[rows, 3 * k:3 * k + 3]
    for d in dropped:
        Rc[rows, 3 * k + d] = 0.0
        RL[rows, 3 * k + d] = 0.0
    # the weights on the touched columns alone: the same CSC arrays with the column indices
    # renumbered (W's arrays read as CSR are Wᵀ)
    touched = np.unique(np.concatenate([W.indices, WL.indices]))
    Wsub_T = sp.csr_matrix((W.data, np.searchsorted(touched, W.indices), W.indptr),
                           shape=(W.shape[1], len(touched)))
    WL_dense = sp.csc_matrix((WL.data, np.searchsorted(touched, WL.indices), WL.indptr),
                             shape=(len(touched), WL.shape[1])).toarray()
    return touched, Wsub_T, WL_dense, WL_dense != 0


def _grouped_laws(laws: list) -> list:
    """The (contacts, law) groups of a problem, those of one elementwise law
    (:data:`rvfem.solve.contact_laws.ForceLaw`: a bearing's, shared by every crank angle and disc)
    joined, so that it is evaluated once for all of them; a group's contacts as a slice where they
    are consecutive (a view instead of a gather)."""
    joined: dict = {}
    out: list = []
    for idx, law in laws:
        if getattr(law, "elementwise", False) and id(law) in joined:
            k = joined[id(law)]
            out[k] = (np.concatenate([out[k][0], idx]), law)
            continue
        if getattr(law, "elementwise", False):
            joined[id(law)] = len(out)
        out.append((idx, law))
    return [(_as_slice(idx), law) for idx, law in out]


def _as_slice(idx: np.ndarray) -> slice | np.ndarray:
    """``idx`` as a slice if it is a run of consecutive indices, else itself."""
    if idx.size and idx[-1] - idx[0] == idx.size - 1 and np.all(np.diff(idx) == 1):
        return slice(int(idx[0]), int(idx[-1]) + 1)
    return idx


def _same_coupling(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    """Both None, or equal arrays."""
    return (a is None and b is None) or (a is not None and b is not None and np.array_equal(a, b))


def _submatrix(C: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """C[rows][:, cols] of a large Fortran-ordered C, gathered through its flat view: the same
    values as ``C[np.ix_(rows, cols)]``, faster (benchmarks/README.md, "Load cycle")."""
    return C.ravel(order="F").take(rows[:, None] + cols[None, :] * C.shape[0])   # a view: C is F-ordered


def _torque_side(body: Body, torque: float) -> np.ndarray:
    """The contacts of a body engaged in the first linear solve of a cycle (:func:`rvfem.solve.contact.solve_bodies`):
    all but the pins whose force on the disc turns it the way the torque does (those only a
    reversed torque loads), unless they overlap. All of them when the set does not say which
    contacts are pins."""
    cset = body.cset
    n = cset.W.shape[1]
    if cset.bearing is None or not torque:
        return np.ones(n, dtype=bool)
    return (np.asarray(cset.bearing) >= 0) | (body.moments() * torque <= 0) | (cset.offset > 0)


def _secant_stiffnesses(body: Body, torque: float) -> list[tuple[np.ndarray, float, bool]]:
    """A secant stiffness (N/mm) per spring group for the first, linearised solve of a cycle, and
    whether the group's law also carries tension (bilateral springs stay bilateral).

    Each group gets the secant of its own law at a force of the order it will carry: a bearing
    contact (with a carrier lever) about a quarter of T/r (r its lever arm); a pin about the mean
    force of the loaded half of the pins, T/(½·Σ|m_j|) with m_j the moment of a unit pin force
    about the disc centre. One secant for every group (the bearings') would give a compliant pin
    the stiffness of a bearing, a thousand times too stiff, and the first Newton steps then
    oscillate between contact states without settling.
    """
    cset = body.cset
    moments = np.abs(body.moments())
    out = []
    for idx, law in cset.laws:
        lever = np.abs(cset.lever[idx]).max() if np.size(idx) else 0.0
        if lever > 0:
            q_ref = abs(torque) / lever / 4.0
        else:
            q_ref = abs(torque) / max(0.5 * float(moments[idx].sum()), 1e-30)
        ks = _secant(law, q_ref)
        out.append((idx, ks, _carries_tension(law, q_ref / ks)))
    return out


def _carries_tension(law, delta: float) -> bool:
    """True if a force law gives a tensile (negative) force at the negative approach −δ (a
    bilateral spring), False for a compression-only law (zero force there)."""
    return bool(np.all(law(np.array([-delta]))[0] < 0))


_SECANTS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
"""The secant stiffnesses found so far, per force law (while it lives) and force: a bearing's law
is one object for every crank angle, and each cold start of a hysteresis loop or TE asks again."""


def _secant(law, q_ref: float) -> float:
    """Secant stiffness q_ref/δ of a force law at the force q_ref (bisection for δ in (0, 1] mm);
    remembered per law and force (:data:`_SECANTS`)."""
    try:
        known = _SECANTS.setdefault(law, {})
    except TypeError:                            # a law that cannot be weakly referenced
        return _bisected_secant(law, q_ref)
    if q_ref not in known:
        known[q_ref] = _bisected_secant(law, q_ref)
    return known[q_ref]


SECANT_PROBE = 2.0 ** -6
"""A bisection point of :func:`_bisected_secant` (15.6 µm, above the approach of a pin or roller
at its expected force), evaluated first."""


def _bisected_secant(law, q_ref: float) -> float:
    """:func:`_secant` by bisection, 80 halvings of (0, 1] mm.

    A force law does not decrease with the approach, so the force at :data:`SECANT_PROBE`, found
    first, settles the comparison at every larger bisection point when it reaches q_ref already
    (the first halvings, where a pin's law is continued beyond its closed form, are not evaluated),
    and at every smaller one when it does not; and the halving stops once the midpoint is one of
    the ends (the interval is one ulp wide: every further halving leaves it as it is). The result
    is that of the 80 halvings."""
    def below(x: float) -> bool:
        return bool(law(np.array([x]))[0][0] < q_ref)

    probe = SECANT_PROBE
    probe_below = below(probe)
    lo, hi = 0.0, 1.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if mid == lo or mid == hi:
            break
        if mid == probe or (mid > probe and not probe_below) or (mid < probe and probe_below):
            is_below = probe_below
        else:
            is_below = below(mid)
        if is_below:
            lo = mid
        else:
            hi = mid
    return q_ref / max(hi, 1e-15)
