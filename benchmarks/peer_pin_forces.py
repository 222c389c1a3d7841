"""Benchmark: pin forces of the RV-40E stage with compliant pins, against the peer tool cycloidgen.

The peer tool cycloidgen (8.0.0, ``cycloidgen.analysis.stiffness``) shares the torque of one disc
over the pins with clearance and compliant pins: a rigid disc turned about its centre with the
crank locked, one gapped nonlinear spring per loaded pin, the torque T/discs as a moment about the
disc centre. This script solves the same problem with rvfem's pin laws and compares the peak pin
force and the number of loaded pins, in four configurations of the profile modification
(rvfem's sign convention, ``cycloid.modification``):

* zero clearance;
* ΔRrp = +0.005 mm (equidistant);
* ΔRp = −0.003 mm (shift);
* both.

For each, at the peer's own crank angles (the eight states of its stiffness sweep, φ_k =
k·(2π·Zc/Zp)/8; rvfem's crank angle θ = φ·Zp/Zc = k·45° loads the same pins, see
:func:`rvfem_angle`):

(a) the peer's model, when ``import cycloidgen`` works (it is not a dependency of rvfem; a line
    says so when it is skipped): per loaded pin δ = c·Q^0.9, c fitted to the line-contact
    approach of Johnson, *Contact Mechanics*, eq. 4.45, at the pin's classical force; the gap of
    each pin is the distance of its centre to a 2000-point polyline of the modified profile less
    the pin radius, negative gaps clamped to zero;
(b) a locked-crank rigid disc with rvfem's ``hertz`` pin law (:func:`rvfem.solve.contact.hertz_pin_law`,
    the flank curvature at each contact, the exact gaps of :func:`rvfem.geometry.pin_profile_contacts`):
    one rotation ψ about the disc centre, Σ Q_j(ψ·h_j − g_j)·h_j = T_disc;
(c) the same with rvfem's ``palmgren`` pin law (one coefficient for every pin);
(d) unless ``--no-fe``: rvfem's full FE, crank bearings as rigid rings with a stiff spring and the
    disc 1000 times stiffer (``bearing_model="rigid_bore"``, ``bearing_stiffness_scale=1e3``,
    ``stiffness_scale=1e3``), pins ``hertz`` (the pin law keeps the real elastic constants), as a
    check of (b); and (e), the same with the real disc.

Between (a) and (b) the script solves the intermediate models that take one difference at a time:
(a1) the peer with its gaps measured on a fine polyline; (a2) the peer's law (with its power-law
fit) on rvfem's exact gaps and flank curvatures, written here from Johnson's eq. 4.45 so that it
runs without the peer; (a3) the same law inverted exactly.

What it shows (RV-40E, cases/rv40e.toml: Zc 39, Zp 40, Rp 64, r_rp 3, e 1.3, b 9 mm, steel
206 GPa / 0.3 for pins and disc, 412 N·m over two discs):

* the peer's 2000 polyline points are uniform in the profile parameter; at the roots their chords
  are up to 1.56 mm long on a flank of 3.07 mm radius, so the measured gaps of the pins there are
  up to 0.1 mm short. Clamped to zero, those pins take the load first: with a 3-8 µm modification
  the peer's peak pin force is 1.8 to 3.5 times what its own model gives on exact gaps (a1);
* (a1), (a2) and (a3) agree within 0.6 %: same geometry, and the peer's power-law fit costs
  little;
* (b) is 11-20 % above (a3). The only difference is the disc's term of the approach: rvfem's law
  counts the disc's compression from the Hertz half-width a to the FE footprint half-width w
  (2P(1 − ν²)/(πE)·ln(w/a)), leaving the rest to the FE, while the peer's rigid disc counts it
  to the depth of the flank's own radius R_d (2P(1 − ν²)/(πE)·(ln(4R_d/a) − ½)). At 500 N the
  approach of rvfem's law is 17-37 % smaller, most at the concave flanks next to the roots
  (radius 3.2-5.8 mm against the 3 mm pin) whose pins carry the peak, so on a rigid disc those
  pins take more;
* (d) reproduces (b) within 0.2 %; (c) is 10 % under the peer at zero clearance and within
  2 % of (a1) with a modification (Palmgren's law is uniform and softer than both).

Run: ``python benchmarks/peer_pin_forces.py [CASE] [--no-fe] [--mesh-dir meshes]``
(with ``PYTHONPATH`` holding a cycloidgen installation to include (a)).
"""

from __future__ import annotations

import argparse
import importlib
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rvfem.solve import contact  # noqa: E402
from rvfem.case.definition import load_case  # noqa: E402
from rvfem.solve.cycle import FOOTPRINT_ELEMENTS  # noqa: E402
from rvfem.geometry import disc_geometry, pin_profile_contacts, profile_curvature  # noqa: E402

#: (label, ΔRrp equidistant mm, ΔRp shift mm)
CONFIGURATIONS = (
    ("zero clearance", 0.0, 0.0),
    ("+0.005 equidistant", 0.005, 0.0),
    ("-0.003 shift", 0.0, -0.003),
    ("both", 0.005, -0.003),
)

#: States of the peer's stiffness sweep: every 18th of 144 over the ring-stage period.
PEER_STATES = 8

#: The peer's load exponent, δ = c·Q^0.9.
PEER_EXPONENT = 0.9

#: Polyline samples of the peer's gap measurement (``cycloidgen.core.kinematics.mesh_gaps``), and
#: the fine count used to measure what that sampling costs.
PEER_POLYLINE = 2000
FINE_POLYLINE = 400_000

#: A pin counts as loaded above this fraction of the angle's peak pin force.
LOADED_FRACTION = 1e-3

#: Force (N) up to which the line-contact approach is inverted exactly (it is monotone there; at
#: a contact half-width of the order of the radii its logarithm stops growing).
JOHNSON_MAX_FORCE = 2.0e4


@dataclass(frozen=True)
class Pins:
    """The pin contacts of one crank angle for a rigid disc turned about its centre.

    Attributes
    ----------
    arms : ndarray (Zp,)
        h_j = P_j × n_j, mm: the approach of pin j per unit rotation ψ of the disc (rad).
    gaps : ndarray (Zp,)
        Initial gap g_j of the actual profile, mm.
    curvature : ndarray (Zp,)
        Signed flank curvature at the contact, 1/mm (positive convex).
    """

    arms: np.ndarray
    gaps: np.ndarray
    curvature: np.ndarray


@dataclass(frozen=True)
class Distribution:
    """Pin forces of one crank angle.

    Attributes
    ----------
    forces : ndarray
        Pin force magnitudes, N.
    """

    forces: np.ndarray

    @property
    def peak(self) -> float:
        """Largest pin force, N."""
        return float(np.max(self.forces))

    @property
    def loaded(self) -> int:
        """Number of loaded pins: forces above :data:`LOADED_FRACTION` of the peak (the FE
        check's disc and bearings leave a few newtons on pins with a vanishing lever arm)."""
        return int(np.count_nonzero(self.forces > LOADED_FRACTION * self.peak))


def rvfem_case(path: str, equidistant: float, shift: float):
    """The case at ``path`` with the given modification and no friction (the peer has none)."""
    return load_case(path, ["analysis.friction=0.0",
                            f"cycloid.modification.equidistant={equidistant!r}",
                            f"cycloid.modification.shift={shift!r}"])


def peer_angles(case) -> np.ndarray:
    """The peer's crank angles φ_k (rad, its convention) of the stiffness sweep."""
    zc, zp = case.cycloid.teeth, case.pins.count
    return 2.0 * np.pi * zc / zp * np.arange(PEER_STATES) / PEER_STATES


def rvfem_angle(case, phi: float) -> float:
    """rvfem's crank angle θ of the peer's state φ: θ = +φ·Zp/Zc.

    Seen from the disc, the peer's pins at φ are rvfem's pins at −φ·Zp/Zc (both put the pin
    circle's centre at −e opposite the eccentric and turn the ring by the same amount), but the
    peer's torque loads the flank with h = P × n < 0 and rvfem's disc torque the flank with h > 0.
    The mirror image about the disc's symmetry axis swaps both, so the peer's loaded pins at φ are
    rvfem's at θ = +φ·Zp/Zc, pin by pin (the benchmark's states of (a1) and (a2) agree to 0.1 %).
    """
    return phi * case.pins.count / case.cycloid.teeth


def rigid_disc_pins(geometry, theta: float) -> Pins:
    """Pin arms, gaps and flank curvatures at crank angle θ.

    rvfem's disc torque (:mod:`rvfem.solve.contact`, moment about the disc centre) loads the pins with
    h = P × n > 0 (P the contact point, n the profile's outward normal); the FE check (d) loads
    the same pins.
    """
    pc = pin_profile_contacts(geometry, theta)
    p, n = np.asarray(pc.point), np.asarray(pc.normal)
    arms = p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0]
    kappa = profile_curvature(geometry.profile, pc.segment, pc.param)
    return Pins(arms, np.asarray(pc.gap), kappa)


def solve_rotation(pins: Pins, torque: float, law) -> Distribution:
    """Rotation ψ of the rigid disc with Σ Q_j·h_j = T and the pin forces there.

    ``law(delta, live) -> (Q, anything)`` gives the forces of the pins selected by the mask
    ``live`` at their approaches ``delta`` (compression only). Only pins with h_j > 0 can be
    loaded by the rotation; Σ Q_j(ψh_j − g_j)·h_j is monotone in ψ, so a bracket and Brent's
    method find the root.
    """
    live = pins.arms > 0
    h, g = pins.arms[live], pins.gaps[live]

    def moment(psi: float) -> float:
        q, _ = law(psi * h - g, live)
        return float(np.sum(q * h)) - torque

    lo = max(float(np.min(g / h)), 0.0)
    hi = lo + 1e-6
    while moment(hi) < 0.0:
        hi = lo + 2.0 * (hi - lo)
    psi = brentq(moment, lo, hi, xtol=1e-16, rtol=1e-14, maxiter=500)
    forces = np.zeros_like(pins.arms)
    forces[live] = law(psi * h - g, live)[0]
    return Distribution(forces)


def hertz_law(case, pins: Pins):
    """rvfem's ``hertz`` pin law with the flank curvature of each pin (selected by ``live``)."""
    def law(delta, live):
        return contact.hertz_pin_law(**_hertz_params(case, pins.curvature[live]))(delta)
    return law


def _hertz_params(case, curvature) -> dict:
    """Parameters of :func:`rvfem.solve.contact.hertz_pin_approach` as :class:`rvfem.solve.models.HertzPins`
    passes them."""
    return dict(length=case.cycloid.thickness, pin_radius=case.pins.radius,
                flank_curvature=np.asarray(curvature, dtype=float),
                pin_modulus=case.pins.youngs_modulus, pin_poisson=case.pins.poissons_ratio,
                disc_modulus=case.material.youngs_modulus, disc_poisson=case.material.poissons_ratio,
                footprint_half_width=FOOTPRINT_ELEMENTS * case.mesh.size_flank)


def palmgren_law(case):
    """rvfem's ``palmgren`` pin law (one contact over the disc width)."""
    base = contact.palmgren_law(case.cycloid.thickness, contacts=1)

    def law(delta, live):
        return base(delta)
    return law


def johnson_approach(Q, case, curvature, reference: float):
    """Approach of two cylinders in line contact, Johnson, *Contact Mechanics*, eq. 4.45, mm.

    δ = 2P/π·[(1 − ν_p²)/E_p·(ln(4R_p/a) − ½) + (1 − ν_d²)/E_d·(ln(4R_d/a) − ½)], P = Q/L, with
    the pin radius R_p, the flank's radius of curvature R_d = 1/|κ| and the half-width a of the
    relative radius 1/R = 1/R_p + κ; both radii capped at ``reference`` (mm). This is the law of
    the peer tool (``cycloidgen.analysis.stiffness.line_contact_approach``, the cap there being
    the pin circle radius); the disc's term reaches to a depth of the order of the flank radius.
    """
    P = np.maximum(np.asarray(Q, dtype=float), 1e-300) / case.cycloid.thickness
    kappa = np.asarray(curvature, dtype=float)
    r_p = min(case.pins.radius, reference)
    r_d = np.clip(1.0 / np.maximum(np.abs(kappa), 1e-12), 1e-9, reference)
    inv_r = 1.0 / r_p + np.sign(kappa) / r_d
    e_p = (1.0 - case.pins.poissons_ratio**2) / case.pins.youngs_modulus
    e_d = (1.0 - case.material.poissons_ratio**2) / case.material.youngs_modulus
    a = np.sqrt(4.0 * P / (np.pi * np.abs(inv_r)) * (e_p + e_d))
    return 2.0 * P / np.pi * (e_p * (np.log(4.0 * r_p / a) - 0.5) + e_d * (np.log(4.0 * r_d / a) - 0.5))


def johnson_law(case, pins: Pins, reference: float, fit_forces: np.ndarray | None = None):
    """The peer's line-contact law as an rvfem law: exact (``fit_forces`` None) or, as the peer
    does, the power law δ = c·Q^0.9 through the approach at ``fit_forces`` (one per pin)."""
    def law(delta, live):
        d = np.maximum(delta, 0.0)
        kappa = pins.curvature[live]
        if fit_forces is not None:
            ref = np.maximum(fit_forces[live], 1e-6)
            c = johnson_approach(ref, case, kappa, reference) / ref**PEER_EXPONENT
            return np.where(d > 0, (d / c) ** (1.0 / PEER_EXPONENT), 0.0), None
        # bisection on ln Q, vectorised: δ(Q) is monotone up to JOHNSON_MAX_FORCE
        lo = np.full(d.shape, math.log(1e-30))
        hi = np.full(d.shape, math.log(JOHNSON_MAX_FORCE))
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            short = johnson_approach(np.exp(mid), case, kappa, reference) < d
            lo, hi = np.where(short, mid, lo), np.where(short, hi, mid)
        q = np.exp(0.5 * (lo + hi))
        # far beyond any pin load (a trial rotation of the solver): continued linearly
        top = johnson_approach(np.full(d.shape, JOHNSON_MAX_FORCE), case, kappa, reference)
        q = np.where(d >= top, JOHNSON_MAX_FORCE * d / top, q)
        q = np.where(d > 0, q, 0.0)
        return q, None
    return law


def classical_forces(pins: Pins, torque: float) -> np.ndarray:
    """The classical distribution, F_j ∝ h_j on the pins with h_j > 0, Σ F_j h_j = T."""
    h = np.where(pins.arms > 0, pins.arms, 0.0)
    return torque * h / np.sum(h * h)


# ------------------------------------------------------------------------------------------------
# The peer tool (optional)
# ------------------------------------------------------------------------------------------------


def peer_available() -> bool:
    """True when cycloidgen can be imported."""
    try:
        importlib.import_module("cycloidgen")
    except ImportError:
        return False
    return True


def peer_spec(case, equidistant: float, shift: float):
    """A cycloidgen GearSpec of the case's stage, with rvfem's elastic constants and modification.

    The peer has one clearance and a mode (equidistant, pin circle or half of each); the pair of
    independent modifications of the fourth configuration is given by overriding its effective
    generating radii (rvfem's ΔRrp = +c is the peer's equidistant c, ΔRp = −c its pin-circle c).
    """
    from cycloidgen.core import spec as peer

    if case.pins.youngs_modulus != case.material.youngs_modulus or \
            case.pins.poissons_ratio != case.material.poissons_ratio:
        raise ValueError("one material for pins and disc expected")
    name = "rvfem case steel"
    peer.MATERIALS[name] = peer.MATERIALS["Bearing steel 100Cr6"].model_copy(update=dict(
        name=name, E_GPa=case.material.youngs_modulus / 1000.0, nu=case.material.poissons_ratio))

    class Spec(peer.GearSpec):
        @property
        def effective_R(self) -> float:
            return self.pin_circle_radius + shift

        @property
        def effective_Rr(self) -> float:
            return self.pin_radius + equidistant

    return Spec(pin_circle_radius=case.pins.circle_radius, pin_radius=case.pins.radius,
                eccentricity=case.cycloid.eccentricity, lobes=case.cycloid.teeth,
                disc_thickness=case.cycloid.thickness, disc_count=case.loads.discs,
                output_torque_Nm=case.loads.torque_Nm, disc_material=name, pin_material=name,
                process=peer.Process.CNC, profile_clearance=0.0)


def peer_distributions(spec, fine: bool = False) -> tuple[list[Distribution], float]:
    """The peer's compliant pin forces at its stiffness-sweep states (its own solve).

    ``fine`` measures the gaps on a polyline of :data:`FINE_POLYLINE` samples instead of the
    peer's :data:`PEER_POLYLINE` (everything else the peer's).

    Returns
    -------
    distributions : list of Distribution
        One per state.
    gap_error : float
        Largest difference (mm) between the gaps measured on the peer's polyline and on the fine
        one, over the loaded flank's pins of all states, before the peer clamps negative gaps
        (interference) to zero.
    """
    from cycloidgen.analysis import stiffness as peer
    from cycloidgen.core.kinematics import SWEEP_STEPS, mesh_gaps, sweep

    states = sweep(spec, SWEEP_STEPS)
    torque = spec.output_torque_Nm * 1000.0 / spec.disc_count
    out, error = [], 0.0
    for cs in states[:: max(1, len(states) // PEER_STATES)]:
        stage = peer._ring_contacts(spec, cs, torque)
        coarse = mesh_gaps(spec, cs.phi, n=PEER_POLYLINE)[cs.loaded_mask]
        exact = mesh_gaps(spec, cs.phi, n=FINE_POLYLINE)[cs.loaded_mask]
        error = max(error, float(np.max(np.abs(coarse - exact))))
        gaps = np.maximum(exact, 0.0) if fine else stage.gaps
        _, forces = peer._solve_rotation(stage.c, stage.arms, gaps, torque)
        out.append(Distribution(np.asarray(forces)))
    return out, error


# ------------------------------------------------------------------------------------------------
# rvfem's full FE
# ------------------------------------------------------------------------------------------------


def fe_distributions(case, thetas, mesh_dir: str, disc_scale: float = 1e3) -> list[Distribution]:
    """rvfem's FE with rigid-ring crank bearings (their spring 1000 times stiffer) and Hertz pins.

    ``disc_scale`` multiplies the disc's Young's modulus in the FE (1000: the rigid-disc check of
    (b); 1: the real disc). The pin law keeps the case's elastic constants either way.
    """
    from rvfem.solve import cycle
    from rvfem.mesh import mesh_case

    system = cycle.build_system(case, mesh_case(case, mesh_dir), bearing_model="rigid_bore",
                                bearing_stiffness_scale=1e3, stiffness_scale=disc_scale,
                                pin_model="hertz")
    out, start = [], None
    for theta in thetas:
        res = cycle.solve_angle(system, float(theta), start)
        out.append(Distribution(np.asarray(res.pin_forces)))
        start = res
    return out


# ------------------------------------------------------------------------------------------------


def _row(label: str, dists: list[Distribution], refs: dict[str, list[Distribution]]) -> str:
    """One model's line: φ = 0 and the largest over the states, and the differences to ``refs``."""
    peaks = [d.peak for d in dists]
    k = int(np.argmax(peaks))
    text = (f"  {label:40s} {dists[0].peak:7.1f} {dists[0].loaded:4d}"
            f"   {peaks[k]:7.1f} {dists[k].loaded:4d} (state {k})")
    for name, ref in refs.items():
        text += (f"   vs {name}: {100 * (dists[0].peak / ref[0].peak - 1):+6.1f} %"
                 f" {100 * (peaks[k] / max(r.peak for r in ref) - 1):+6.1f} %")
    return text


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default=str(ROOT / "cases" / "rv40e.toml"))
    ap.add_argument("--no-fe", action="store_true", help="skip (d) and (e), rvfem's FE")
    ap.add_argument("--mesh-dir", default="meshes")
    ap.add_argument("--states", action="store_true", help="also print every state's peak/loaded pins")
    args = ap.parse_args(argv)

    have_peer = peer_available()
    if not have_peer:
        print("(a) skipped: cycloidgen is not importable (it is optional, not an rvfem dependency)")
    print("Peak pin force (N) and loaded pins at the peer's first state (φ = 0) and the largest over its "
          f"{PEER_STATES} states; differences in % at φ = 0 and of the largest.\n"
          "  (a)  the peer as shipped: power law δ = c·Q^0.9 fitted to Johnson's eq. 4.45 at the classical\n"
          f"       force, gaps measured on a {PEER_POLYLINE}-point polyline of the profile\n"
          "  (a1) the same with the gaps measured on a fine polyline\n"
          "  (a2) the peer's law (same fit) on rvfem's exact gaps and flank curvatures (no cycloidgen needed)\n"
          "  (a3) the peer's law solved exactly, no power-law fit\n"
          "  (b)  rvfem's hertz pin law: Johnson's pin term, the disc compressed only to the FE footprint\n"
          "  (c)  rvfem's palmgren pin law\n"
          "  (d)  rvfem's FE, rigid_bore bearings x1e3, disc E x1e3, hertz pins (check of (b))\n"
          "  (e)  rvfem's FE as (d) with the real disc (supplies the disc compression below the footprint)")

    for label, equidistant, shift in CONFIGURATIONS:
        case = rvfem_case(args.case, equidistant, shift)
        geometry = disc_geometry(case)
        torque = case.loads.disc_torque_Nmm
        phis = peer_angles(case)
        thetas = [rvfem_angle(case, phi) for phi in phis]
        states = [rigid_disc_pins(geometry, theta) for theta in thetas]
        reference = case.pins.circle_radius          # the peer's cap of the body radii

        models: dict[str, list[Distribution]] = {}
        note = ""
        if have_peer:
            spec = peer_spec(case, equidistant, shift)
            models["(a)"], error = peer_distributions(spec)
            models["(a1)"], _ = peer_distributions(spec, fine=True)
            note = f"; the peer's {PEER_POLYLINE}-point gaps are off by up to {1000 * error:.1f} µm"
        models["(a2)"] = [solve_rotation(p, torque, johnson_law(case, p, reference,
                                                                classical_forces(p, torque)))
                          for p in states]
        models["(a3)"] = [solve_rotation(p, torque, johnson_law(case, p, reference)) for p in states]
        models["(b)"] = [solve_rotation(p, torque, hertz_law(case, p)) for p in states]
        models["(c)"] = [solve_rotation(p, torque, palmgren_law(case)) for p in states]
        if not args.no_fe:
            models["(d)"] = fe_distributions(case, thetas, args.mesh_dir)
            models["(e)"] = fe_distributions(case, thetas, args.mesh_dir, disc_scale=1.0)

        refs = {k: models[k] for k in ("(a)", "(a1)") if k in models}
        print(f"\n{label}: ΔRrp = {equidistant:+.3f} mm, ΔRp = {shift:+.3f} mm, T_disc = "
              f"{torque / 1000:g} N·m, states φ = k·{math.degrees(phis[1]):.3f}° (θ = k·45°){note}")
        print(f"  {'model':40s} {'φ=0 N':>7s} {'pins':>4s}   {'max N':>7s} {'pins':>4s}")
        for name, dists in models.items():
            print(_row(name, dists, refs))
            if args.states:
                print("      " + "  ".join(f"{d.peak:6.1f}/{d.loaded}" for d in dists))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
