"""The tables of a case file (``[cycloid]``, ``[pins]``, ``[crank_bearing]``, ...): one small frozen
dataclass per table, each key declared once on its field with :func:`rvfem.case.schema.param`, and
the constants their bounds are drawn from.

The dataclasses keep the file's units (see :mod:`rvfem.case.definition`); they are plain values,
checked when they become part of a :class:`~rvfem.case.whole_case.Case`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping

from rvfem.case.registry import bearing_model_names, pin_model_names
from rvfem.case.schema import param
from rvfem.errors import CaseError
from rvfem.units import nmm_from_nm

__all__ = [
    "ProfileModification",
    "PitchError",
    "Cycloid",
    "Pins",
    "Cranks",
    "B_M_RANGE",
    "LAMBDA_NU_RANGE",
    "ROLLER_PROFILE_KINDS",
    "RollerProfile",
    "DEFAULT_ISO_VG",
    "Lubricant",
    "CrankBearing",
    "FanHoles",
    "RoundHoles",
    "Material",
    "DutyRow",
    "TORQUE_SPLITS",
    "Loads",
    "MAX_FRICTION",
    "Analysis",
    "MeshSettings",
    "CrankSupport",
    "PIN_ROLLING",
    "Wear",
]


# --------------------------------------------------------------------------------------------
# Dataclasses (units in the file's convention; see rvfem.case.definition). Bounds: see the section
# "Bounds" of docs/case-format.md for why each range is what it is.
# --------------------------------------------------------------------------------------------

_ANGLE = dict(unit="deg", low=-360.0, high=360.0)


@dataclass(frozen=True)
class ProfileModification:
    """Standard cycloid profile modifications (sign convention of Liu et al., *Degradation law
    analysis and life estimation of transmission accuracy of RV reducer ...*).

    Attributes
    ----------
    equidistant : float
        ΔRrp, mm. Increase of the generating pin radius; positive removes material.
    shift : float
        ΔRp, mm. Increase of the generating pin-circle radius; positive adds material at the tip.
    rotation_deg : float
        Rotation of the profile about the disc centre, degrees.
    """

    equidistant: float = param(0.0, unit="mm", low=-2.0, high=2.0,
                               doc="ΔRrp, change of the generating pin radius (positive removes material)")
    shift: float = param(0.0, unit="mm", low=-2.0, high=2.0, doc="ΔRp, change of the generating pin-circle radius")
    rotation_deg: float = param(0.0, unit="deg", low=-10.0, high=10.0,
                                doc="rotation of the profile about the disc centre")


@dataclass(frozen=True)
class PitchError:
    """Per-tooth pitch (angular position) errors of the cycloid teeth, as a tangential offset in mm.

    Either the sinusoidal pattern of Li et al. (*Life calculation of the swivel-arm bearing of an
    RV reducer considering cycloid pitch error*), E_t(k) = E_t,max · sin((k − 1)·π/2) for tooth
    k = 1…Zc (``amplitude`` = E_t,max), or an explicit list of ``values`` (one per tooth).
    """

    amplitude: float = param(0.0, unit="mm", low=-1.0, high=1.0,
                             doc="E_t,max of E_t(k) = E_t,max·sin((k − 1)·π/2), k = 1…Zc")
    values: tuple[float, ...] = param((), unit="mm", low=-1.0, high=1.0, max_length=199,
                                      doc="one error per tooth (exactly Zc values)")


@dataclass(frozen=True)
class Cycloid:
    """The cycloid disc.

    Attributes
    ----------
    teeth : int
        Number of lobes Zc.
    eccentricity : float
        Crank eccentricity e, mm.
    thickness : float
        Disc thickness (face width) b, mm; plane-stress thickness.
    central_hole_radius : float
        Radius of the central hole, mm.
    modification : ProfileModification
    pitch_error : PitchError
    """

    teeth: int = param(low=3, high=199, doc="number of lobes Zc")
    eccentricity: float = param(unit="mm", low=0.01, high=50.0, doc="crank eccentricity e")
    thickness: float = param(unit="mm", low=0.1, high=500.0, doc="disc width b (plane-stress thickness)")
    central_hole_radius: float = param(unit="mm", low=0.1, high=1000.0, doc="radius of the central hole")
    modification: ProfileModification = param(ProfileModification())
    pitch_error: PitchError = param(PitchError())


@dataclass(frozen=True)
class Pins:
    """The pin (needle-pin) ring fixed in the housing.

    Attributes
    ----------
    count : int
        Number of pins Zp.
    circle_radius : float
        Pin-circle radius Rp, mm.
    radius : float
        Pin radius r_rp, mm.
    model : str
        How a pin acts on the flank (:mod:`rvfem.solve.models`, registered in :mod:`rvfem.case.registry`):
        ``"hertz"`` (default: the Hertz line contact of pin and flank at the flank's local
        curvature), ``"rigid"`` (Signorini contact with a rigid pin), ``"palmgren"`` (Palmgren's
        steel roller formula; ``"hertz"`` before rvfem had the Hertz pin law) or ``"linear"``
        (the classical pin-force distribution's linear springs).
    youngs_modulus, poissons_ratio : float
        Elastic constants of the pins (the Hertz law), MPa and –.
    linear_stiffness_N_per_mm : float or None
        Stiffness of the ``"linear"`` model, N/mm.
    """

    count: int = param(low=4, high=200, doc="number of pins Zp, must exceed `cycloid.teeth`")
    circle_radius: float = param(unit="mm", low=1.0, high=2000.0, doc="pin-circle radius Rp")
    radius: float = param(unit="mm", low=0.1, high=200.0,
                          doc="pin radius r_rp; neighbouring pins must not overlap (r_rp < Rp·sin(π/Zp))")
    model: str = param("hertz", choices=pin_model_names,
                       doc="`\"hertz\"`: Hertz line contact of pin and flank at the flank's local curvature "
                           "(the reducer's physics; default); `\"rigid\"`: rigid pins (Signorini contact; "
                           "the contact compliance is then the mesh's); `\"palmgren\"`: Palmgren's steel roller "
                           "formula, independent of pin radius, curvature and materials (rvfem's former "
                           "`\"hertz\"`); `\"linear\"`: linear springs of `linear_stiffness_N_per_mm`, the "
                           "classical pin-force distribution (with a rigid disc)")
    youngs_modulus: float = param(206000.0, unit="MPa", low=1.0e3, high=1.2e6,
                                  doc="E of the pins (Hertz law); default bearing steel")
    poissons_ratio: float = param(0.3, low=0.0, high=0.5, high_open=True,
                                  doc="ν of the pins (Hertz law); default bearing steel")
    linear_stiffness_N_per_mm: float | None = param(None, unit="N/mm", low=1.0, high=1.0e10,
                                                    doc="pin stiffness; required when `model = \"linear\"`")


def _equal_crank_angles(values: Mapping[str, Any]) -> tuple[float, ...]:
    n = values["cranks.count"]
    return tuple(90.0 + 360.0 * i / n for i in range(n))


@dataclass(frozen=True)
class Cranks:
    """The crankshafts (turning arms) carried by the output carrier.

    Attributes
    ----------
    count : int
        Number of cranks N.
    circle_radius : float
        Radius r0 of the circle of crank (and bore) centres, mm.
    angles_deg : tuple of float
        Angular positions of the cranks on that circle, degrees. Default in a file: equally
        spaced, the first at 90° (a case built in code gives them).
    """

    count: int = param(low=2, high=12, doc="number of cranks N")
    circle_radius: float = param(unit="mm", low=1.0, high=2000.0,
                                 doc="radius r0 of the circle of crank (and bore) centres")
    angles_deg: tuple[float, ...] = param(**_ANGLE, max_length=12, default_from=_equal_crank_angles,
                                          default_doc="equally spaced, first at 90°",
                                          doc="angular positions α_i of the cranks (N distinct values)")


B_M_RANGE = (1.0, 1.3)
"""Allowed ``crank_bearing.b_m``: ISO 281:2007 (Table 1) tabulates b_m from 1.0 to 1.3 by bearing
type (1.1 for radial roller bearings, the crank bearing's type); 1.0 reproduces the ratings of the
standard's editions before 2007, which had no such factor."""

LAMBDA_NU_RANGE = (0.4, 1.0)
"""Allowed ``crank_bearing.lambda_nu``: λ·ν is the reduction of f_c (ISO 281 and ISO/TR 1281-1) for
the edge stresses and the non-uniform load along a real roller and for manufacturing accuracy; 0.83
for radial roller bearings (the ISO 281 tables; Gao et al. and Li et al. use it). It is at most 1
(no reduction: ideally uniform line contact). The rating C is proportional to λ·ν and the life to
its 10/3 power: at 0.4 the life is already (0.4/0.83)^(10/3) ≈ 9 % of the standard's; a value far
below says the bearing is not one ISO 281 rates, and near 0 the life underflows to 0 h."""


ROLLER_PROFILE_KINDS: dict[str, tuple[str, ...]] = {
    "straight": (),
    "arc": ("crown_radius",),
    "logarithmic": ("design_load_N",),
    "combined": ("modification_length", "modification_drop"),
}
"""The kinds of roller profile (``crank_bearing.profile.kind``), each with the keys of
``[crank_bearing.profile]`` that shape its drop and no other kind uses. The one list of kinds: the
case accepts these, the report shows each one's keys, and the drop of each is a function of
:data:`rvfem.evaluate.roller_slices.PROFILE_DROPS`, which refuses to import unless it has one
for every kind here (a new kind without its drop fails at import, before any run)."""


@dataclass(frozen=True)
class RollerProfile:
    """Axial profile (generatrix) of the crank-bearing rollers (table ``[crank_bearing.profile]``).

    The drop z(x) of the roller surface below its straight generatrix along the effective length
    L_we (x from the roller centre; the corners lie outside L_we). ``kind``:

    * ``"straight"``: z = 0 (the default: the usual roller of RV-reducer crank bearings, as
      Zhang et al., *Contact load and elastohydrodynamic lubrication analysis of eccentric
      bearings in RV reducer considering the effects of roller profile modification*, describe
      it, eq. 8; the conservative choice when a case gives no profile, and the one that keeps
      ISO 281's edge-stress factor λν meaningful);
    * ``"arc"``: z = R − √(R² − x²), R = ``crown_radius`` (their eq. 9);
    * ``"logarithmic"``: Johns–Gohar's drop for the design load Q_d = ``design_load_N``,
      z = 2Q_d/(π·L·E′)·ln[1/(1 − (1 − b²/l²)(x/l)²)], E′ = 2E*, l = L/2, b the Hertz half-width
      at Q_d (uniform pressure along the roller at Q_d);
    * ``"combined"``: straight centre, then a circular segment of length a =
      ``modification_length`` dropping by b = ``modification_drop`` at the end of L_we (their
      eq. 10, R = (a² + b²)/(2b)).

    Every kind ends in rounded corners beyond L_we: a circular arc of radius r =
    ``corner_radius`` tangent to the generatrix at ±L_we/2, over an axial length c =
    ``chamfer_length`` (default r: a quarter circle down to the end face; a maker's chamfer
    dimension where it is shorter). Zhang et al. describe the RV crank-bearing roller as a
    "straight generatrix and round corners" (their eq. 8 and Fig. 5) without giving r; ISO 12297
    (cylindrical rollers; its national twin GOST 22696-2013) counts the corner outside the
    effective length, L_we = L_w − 2r with r the roller's chamfer dimension, as the case does.
    The default r = 0.2 mm is a chamfer of that standard's order for a roller of a few mm
    diameter, not a value read from its table for D_w = 5 mm: give the maker's value where it is
    known (the edge pressure grows as r shrinks; r = 0 is the sharp end, whose edge pressure is a
    singularity that grows with the number of slices). The corner is what bounds the straight
    roller's edge pressure (docs/theory.md § 12).
    """

    kind: str = param("straight", choices=lambda: tuple(ROLLER_PROFILE_KINDS),
                      doc="roller generatrix: straight, arc (crown radius), logarithmic (Johns–Gohar) or combined "
                          "(straight centre and a modified end segment)")
    crown_radius: float = param(500.0, unit="mm", low=10.0, high=1.0e6, doc="R of the `arc` profile")
    design_load_N: float = param(2000.0, unit="N", low=1.0, high=1.0e6,
                                 doc="roller load Q_d at which the `logarithmic` profile gives a uniform pressure")
    modification_length: float = param(1.23, unit="mm", low=0.01, high=100.0,
                                       doc="length a of each modified end segment of the `combined` profile")
    modification_drop: float = param(0.006, unit="mm", low=0.0, high=0.2,
                                     doc="drop b of the `combined` profile at the end of the effective length")
    misalignment_mrad: float = param(0.0, unit="mrad", low=-10.0, high=10.0,
                                     doc="extra tilt of the eccentric against the bore (mounting, machining), "
                                         "added to the crankshaft's slope")
    corner_radius: float = param(0.2, unit="mm", low=0.0, high=20.0,
                                 doc="radius r of the rounded corners beyond the effective length, every kind "
                                     "(0: a sharp end)")
    chamfer_length: float | None = param(None, unit="mm", low=0.0, low_open=True, high=20.0,
                                         default_doc="`corner_radius` (a quarter circle)",
                                         doc="axial length c of each corner (the maker's chamfer dimension), "
                                             "at most `corner_radius`")
    slices: int = param(30, low=8, high=400, doc="slices along the roller of the slice model")


DEFAULT_ISO_VG = 68
"""ISO viscosity grade of a ``[lubricant]`` that gives no viscosity (neither ``iso_vg`` nor
``nu40``/``nu100``)."""


@dataclass(frozen=True)
class Lubricant:
    """The lubricant of the crank bearings (table ``[lubricant]``, all keys optional).

    Viscosity from two points (``nu40``, ``nu100``; or ``iso_vg`` alone, ν100 then from the grade
    at a viscosity index of about 100), the operating temperature, the pressure–viscosity
    coefficient and density for the film thickness, the contamination factor e_C of ISO 281
    (given, or from a cleanliness level, ISO 281 Table 14 for D_pw < 100 mm) and the roughness.
    """

    iso_vg: int | None = param(None, choices=(22, 32, 46, 68, 100, 150, 220, 320, 460),
                               default_doc="68 unless `nu40` and `nu100` are given",
                               doc="ISO viscosity grade (ν40 = the grade; ν100 at viscosity index ≈ 100); not "
                                   "together with `nu40` and `nu100` (one or the other)")
    nu40: float | None = param(None, unit="mm²/s", low=2.0, high=5000.0, doc="kinematic viscosity at 40 °C")
    nu100: float | None = param(None, unit="mm²/s", low=1.0, high=500.0, doc="kinematic viscosity at 100 °C")
    temperature_C: float = param(60.0, unit="°C", low=-30.0, high=150.0, doc="operating temperature of the bearing")
    pressure_viscosity_per_GPa: float = param(20.0, unit="1/GPa", low=1.0, high=60.0,
                                              doc="pressure–viscosity coefficient α (mineral oils 15–25)")
    density: float = param(870.0, unit="kg/m³", low=500.0, high=2000.0, doc="density at the operating temperature")
    contamination_factor: float | None = param(None, low=0.0, high=1.0,
                                               doc="ISO 281 e_C; overrides `cleanliness`")
    cleanliness: str = param("normal", choices=("extreme", "high", "normal", "slight", "typical", "severe",
                                                "very_severe"),
                             doc="ISO 281 cleanliness level giving e_C (Table 14, D_pw < 100 mm, mid-range)")
    roughness_Ra_um: float = param(0.1, unit="µm", low=0.005, high=5.0,
                                   doc="Ra of roller and raceways (composite σ = 1.25·√2·Ra for Λ)")

    def __post_init__(self) -> None:
        # the grade is the default only where no viscosity is given: a case with nu40 and nu100
        # has no iso_vg, so the two never stand side by side (Case refuses them together)
        if self.iso_vg is None and self.nu40 is None and self.nu100 is None:
            object.__setattr__(self, "iso_vg", DEFAULT_ISO_VG)


@dataclass(frozen=True)
class CrankBearing:
    """The crank (turning-arm) bearing: rollers between the eccentric and the disc bore.

    Attributes
    ----------
    rollers : int
        Number of rollers Z.
    roller_diameter : float
        D_we, mm.
    roller_length : float
        Effective roller length L_we, mm.
    pitch_diameter : float
        D_m, mm.
    bore_radius : float
        Radius of the disc bore (outer raceway), mm; D_m/2 + D_we/2 for a full-complement
        bearing running directly on the disc.
    radial_clearance : float
        Diametral play of the bearing expressed as the radial clearance, mm (half of it on each
        side when centred). Negative: a preload (interference); every roller is then compressed
        by half of it at zero load. Bounded below at −0.02 mm: a 10 µm approach per roller
        already gives each roller of the shipped bearings about 1.5 kN of preload, of the order
        of the operating roller loads (Palmgren's line contact). Bounded above at 0.2 mm (crank
        bearings run at a few µm to tens of µm): with 1 mm the discs rattle in their bearings and
        the contact set of the solid RV-40E stage no longer settles (at θ = 46°); the shipped
        RV-40E pair and the CRV-80E solve at 0.1 and 0.2 mm.
    b_m, lambda_nu : float
        ISO 281 rating factors (material/manufacturing and edge-stress reduction).
    model : str
        ``"rollers"`` (discrete compression-only roller springs) or ``"rigid_bore"`` (bore tied to
        a rigid ring with one isotropic bearing spring); any model registered in
        :mod:`rvfem.case.registry`.
    stiffness_law : str
        ``"palmgren"`` (line-contact load–deflection, both raceways) or ``"linear"``.
    linear_stiffness_N_per_mm : float or None
        Roller stiffness for the linear law, N/mm.
    rigid_bore_stiffness_N_per_mm : float
        Isotropic bearing stiffness of the ``rigid_bore`` model, N/mm.
    profile : RollerProfile
        Axial roller profile (``[crank_bearing.profile]``) for the pressure along the roller.
    static_load_rating_N, fatigue_load_limit_N : float or None
        C0 and C_u overrides, N (None: from the geometry, ISO 76 and ISO 281 Annex B).
    """

    rollers: int = param(low=2, high=200, doc="number of rollers Z")
    roller_diameter: float = param(unit="mm", low=0.1, high=200.0,
                                   doc="D_we; γ = D_we/D_m must lie in (0, 1)")
    roller_length: float = param(unit="mm", low=0.1, high=500.0,
                                 doc="effective roller length L_we (rating and Hertz contact length)")
    pitch_diameter: float = param(unit="mm", low=1.0, high=2000.0, doc="D_m; the rollers must fit: Z·D_we < π·D_m")
    bore_radius: float = param(unit="mm", low=0.5, high=1000.0,
                               doc="radius of the disc bore, at least (D_m + D_we)/2 (the outer raceway)")
    radial_clearance: float = param(0.0, unit="mm", low=-0.02, high=0.2,
                                    doc="radial clearance of the bearing; negative: a preload (interference)")
    b_m: float = param(1.1, low=B_M_RANGE[0], high=B_M_RANGE[1],
                       doc="ISO 281 rating factor for material and manufacturing quality (1.1 for radial roller "
                           "bearings; ISO 281 tabulates 1.0–1.3)")
    lambda_nu: float = param(0.83, low=LAMBDA_NU_RANGE[0], high=LAMBDA_NU_RANGE[1],
                             doc="ISO 281 reduction factor λ·ν of f_c (edge stress, accuracy; 0.83 for radial roller "
                                 "bearings, 1 = no reduction)")
    model: str = param("rollers", choices=bearing_model_names,
                       doc="discrete compression-only roller springs, or the bore tied to a rigid ring with one "
                           "isotropic spring (registered bearing models)")
    stiffness_law: str = param("palmgren", choices=("palmgren", "linear"), doc="roller load–deflection law")
    linear_stiffness_N_per_mm: float | None = param(None, unit="N/mm", low=1.0e2, high=1.0e10,
                                                    doc="roller stiffness; required when `stiffness_law = \"linear\"`")
    rigid_bore_stiffness_N_per_mm: float = param(7.0e5, unit="N/mm", low=1.0e2, high=1.0e10,
                                                 doc="bearing stiffness of the `rigid_bore` model")
    profile: RollerProfile = param(RollerProfile())
    static_load_rating_N: float | None = param(None, unit="N", low=1.0, high=1.0e8,
                                               doc="C0; default ISO 76 from the geometry")
    fatigue_load_limit_N: float | None = param(None, unit="N", low=1.0, high=1.0e7,
                                               doc="C_u; default ISO 281 Annex B from C0")

    @property
    def inner_raceway_radius(self) -> float:
        """Radius of the inner raceway (on the eccentric), mm."""
        return 0.5 * (self.pitch_diameter - self.roller_diameter)

    @property
    def outer_raceway_radius(self) -> float:
        """Radius of the outer raceway (the disc bore), mm."""
        return 0.5 * (self.pitch_diameter + self.roller_diameter)


def _crank_count(values: Mapping[str, Any]) -> int:
    return values["cranks.count"]


@dataclass(frozen=True)
class FanHoles:
    """Fan-shaped lightening holes: annular sectors between the bores.

    Attributes
    ----------
    count : int
        Number of holes (default in a file: one between each pair of neighbouring cranks).
    inner_radius, outer_radius : float
        Radial extent of the sector, mm.
    span_deg : float or None
        Angular span of a hole, degrees. Give this or ``ligament``.
    ligament : float or None
        Narrowest wall between a hole and the neighbouring bores, mm; the span follows from it.
    fillet_radius : float
        Corner fillet radius, mm.
    angle_offset_deg : float or None
        Angular position of the first hole's centre line, degrees; default midway between the
        first two cranks.
    """

    inner_radius: float = param(unit="mm", low=0.5, high=2000.0, doc="inner radius of the sector")
    outer_radius: float = param(unit="mm", low=0.5, high=2000.0, doc="outer radius, > `inner_radius`")
    count: int = param(low=1, high=12, default_from=_crank_count, default_doc="`cranks.count`",
                       doc="number of holes")
    span_deg: float | None = param(None, unit="deg", low=0.0, low_open=True, high=180.0,
                                   doc="angular span of one hole; span × count < 360°")
    ligament: float | None = param(None, unit="mm", low=0.1, high=500.0,
                                   doc="narrowest wall between a hole and the bores (the span follows)")
    fillet_radius: float = param(1.0, unit="mm", low=0.0, high=100.0, doc="corner fillet radius")
    angle_offset_deg: float | None = param(None, **_ANGLE, default_doc="midway between the first two cranks",
                                           doc="centre line of the first hole")

    def check(self, fail: Callable[[str, str], CaseError]) -> None:
        """The checks between keys of the table; ``fail(key, message)`` is the error for one of its
        keys (run by :class:`Case`, see :func:`register_hole_table`)."""
        if self.outer_radius <= self.inner_radius:
            raise fail("outer_radius", "must exceed inner_radius")
        if (self.span_deg is None) == (self.ligament is None):
            raise fail("span_deg", "or 'ligament': give exactly one of them")
        if self.span_deg is not None and self.span_deg * self.count >= 360.0:
            raise fail("span_deg", f"× count must stay below 360°, got {self.span_deg * self.count}°")

    @property
    def outline_length(self) -> float:
        """Length of the outlines of all holes (unfilleted sectors), mm, for the mesh-size estimate."""
        return self.count * 2.0 * (self.outer_radius + self.outer_radius - self.inner_radius)


@dataclass(frozen=True)
class RoundHoles:
    """Round lightening holes on a circle (radius, circle radius, count)."""

    radius: float = param(unit="mm", low=0.1, high=1000.0, doc="hole radius")
    circle_radius: float = param(unit="mm", low=0.5, high=2000.0, doc="radius of the circle of hole centres")
    count: int = param(low=1, high=60, default_from=_crank_count, default_doc="`cranks.count`",
                       doc="number of holes")
    angle_offset_deg: float | None = param(None, **_ANGLE, doc="angular position of the first hole")

    @property
    def outline_length(self) -> float:
        """Length of the outlines of all holes, mm, for the mesh-size estimate."""
        return self.count * 2.0 * math.pi * self.radius



@dataclass(frozen=True)
class Material:
    """Linear elastic material of the disc (and of the rollers in the roller Hertz pressures; the
    pins have their own constants, ``pins.youngs_modulus`` and ``pins.poissons_ratio``)."""

    name: str = param("bearing steel", max_length=200, doc="label")
    youngs_modulus: float = param(206000.0, unit="MPa", low=1.0e3, high=1.2e6, doc="E")
    poissons_ratio: float = param(0.3, low=0.0, high=0.5, high_open=True, doc="ν")
    # mass and strength (the defaults: through-hardened bearing steel 100Cr6 / GCr15 / SAE 52100,
    # quenched and tempered at about 150 °C, 62 HRC; docs/theory.md, "Mass and strength")
    density_kg_m3: float = param(7810.0, unit="kg/m³", low=1.0, high=3.0e4,
                                 doc="density ρ (disc mass and inertia); 7810 kg/m³ for 100Cr6")
    yield_strength: float = param(1800.0, unit="MPa", low=1.0, high=1.0e4,
                                  doc="0.2 % proof stress R_p0.2 (static safety factor, yield warning)")
    ultimate_strength: float = param(2400.0, unit="MPa", low=1.0, high=1.0e4,
                                     doc="tensile strength R_m (the Goodman line of the fatigue check)")
    fatigue_limit: float = param(960.0, unit="MPa", low=1.0, high=1.0e4,
                                 doc="fully reversed (R = −1) fatigue limit σ_W of the material, "
                                     "default 0.40·R_m, below the FKM guideline's 0.45·R_m by choice (docs/theory.md, "
                                     "\"Mass and strength\")")


@dataclass(frozen=True)
class DutyRow:
    """One row of a duty cycle: share of time, output speed (rpm), output torque (N·m)."""

    time_share: float = param(unit="any", low=1.0e-9, high=1.0e9, doc="share of time (only ratios matter)")
    speed_rpm: float = param(unit="rpm", low=1.0e-3, high=1.0e4, doc="output speed")
    torque_Nm: float = param(unit="N·m", low=-1.0e6, high=1.0e6,
                             doc="output torque, negative when reversed (0 or at least 0.001 N·m in magnitude)")


TORQUE_SPLITS = ("stiffness", "equal")
"""Values of ``loads.torque_split``."""


@dataclass(frozen=True)
class Loads:
    """Operating point of the reducer.

    Attributes
    ----------
    torque_Nm : float
        Output torque T, N·m (the whole reducer). Negative for a reversed torque (the carrier
        driven the other way round); the loads are then those of the reverse direction.
    speed_rpm : float
        Output speed, rpm.
    discs : int
        Number of cycloid discs sharing the torque.
    duty_cycle : tuple of DutyRow
        Optional load spectrum.
    torque_split : str
        How the discs share the torque: ``"stiffness"`` (two discs on one carrier, the torque
        divides in proportion to their stiffness; one or two discs only) or ``"equal"`` (each disc
        carries T/discs: the handbook's assumption).
    """

    torque_Nm: float = param(unit="N·m", low=-1.0e6, high=1.0e6,
                             doc="output torque T of the whole reducer; negative reverses it (at least 0.001 N·m in "
                                 "magnitude)")
    speed_rpm: float = param(unit="rpm", low=1.0e-3, high=1.0e4, doc="output speed")
    discs: int = param(2, low=1, high=4, doc="number of cycloid discs sharing the torque")
    duty_cycle: tuple[DutyRow, ...] = param((), max_length=1000)
    torque_split: str = param("stiffness", choices=TORQUE_SPLITS,
                              doc="`\"stiffness\"`: two discs on one carrier share the torque in proportion to "
                                  "their stiffness (1 or 2 discs); `\"equal\"`: each disc carries T/discs "
                                  "(the handbook's assumption)")

    @property
    def disc_torque_Nmm(self) -> float:
        """Torque carried by one disc, N·mm: T·1000 / discs (the handbook's T/2 for two discs)."""
        return nmm_from_nm(self.torque_Nm) / self.discs


MAX_FRICTION = 0.3
"""Largest ``analysis.friction``. Lubricated steel pins on a hardened disc have a Coulomb coefficient
of about 0.01–0.1 (0.05 in the published 3D model), boundary lubrication up to about 0.15; 0.3 is a
nearly dry contact. Beyond it the model leaves its range: friction along the known sliding direction
tilts the pin forces, and the pin and bearing loads needed for the same torque grow steeply and
without bound as μ nears the value at which the drive locks. On the RV-40E fan-hole case (10°
steps) the largest bearing load over the friction-free handbook is +11 % at μ = 0.05, +26 % at 0.2,
+43 % at 0.3, +120 % at 0.5 and +908 % at 0.7; at 0.85 and 1.0 the contact problem has no settled
solution even at the first crank angle (no iteration bound helps)."""


@dataclass(frozen=True)
class Analysis:
    """Analysis options.

    Attributes
    ----------
    equivalent_load_exponent : float
        Exponent p of the equivalent load (mean F^p)^(1/p); 10/3 for roller bearings (ISO 281),
        4 to reproduce Gao et al.
    angle_step_deg : float
        Crank-angle step of the load cycle, degrees.
    element_order : int
        1 (P1) or 2 (P2) triangles.
    friction : float
        Coulomb friction coefficient at the pins (force μ·λ along the known sliding direction,
        the pin centre's velocity relative to the disc); 0.05 in the published 3D model, 0 by
        default (see docs/theory.md, "Pin contact"). At most :data:`MAX_FRICTION`.
    max_active_set_iterations : int
        Bound of the contact active-set loop.
    saved_angles_deg : tuple of float
        Crank angles at which displacement/stress fields are kept for output.
    """

    equivalent_load_exponent: float = param(
        10.0 / 3.0, low=1.0, high=20.0,
        doc="p of the equivalent load (mean F^p)^(1/p) over a crank turn; 10/3 per ISO 281, 4 reproduces Gao et al.")
    angle_step_deg: float = param(1.0, unit="deg", low=0.05, high=30.0,
                                  doc="crank-angle step of the load cycle; the cycle has round(360/step) equal steps")
    element_order: int = param(1, choices=(1, 2), labels={1: "P1", 2: "P2"}, doc="P1 or P2 triangles")
    friction: float = param(0.0, low=0.0, high=MAX_FRICTION,
                            doc="Coulomb friction coefficient at the pins (along the pins' known sliding "
                                "direction; 0.05 in Zhang et al.; lubricated steel 0.01–0.1)")
    max_active_set_iterations: int = param(50, low=1, high=1000, doc="bound of the contact active-set loop")
    saved_angles_deg: tuple[float, ...] = param((0.0, 90.0, 180.0, 270.0), **_ANGLE, max_length=360,
                                                doc="crank angles at which fields are written")


@dataclass(frozen=True)
class MeshSettings:
    """Target element sizes (mm) and the thinnest wall the geometry check accepts.

    ``size_hole`` is the size on the central hole and the lightening holes; None means twice
    ``size_bore``, capped by ``size_interior``. ``size_fillet`` is the size on the corner fillets
    of the lightening holes, which carry the structural stress peak; None means half the hole size.
    ``symmetric`` lets the mesher build an exactly N-fold symmetric mesh from one sector when the
    disc is N-fold symmetric (see :func:`rvfem.mesh.symmetry_order`).
    """

    size_flank: float = param(0.4, unit="mm", low=0.01, high=100.0, doc="element size along the tooth flanks")
    size_bore: float = param(0.4, unit="mm", low=0.01, high=100.0, doc="element size along the bores")
    size_interior: float = param(2.5, unit="mm", low=0.01, high=100.0, doc="element size inside the disc")
    min_wall: float = param(1.0, unit="mm", low=0.01, high=100.0, doc="thinnest wall the geometry check accepts")
    size_hole: float | None = param(None, unit="mm", low=0.01, high=100.0,
                                    default_doc="2 × `size_bore` (≤ `size_interior`)",
                                    doc="element size on the central hole and the lightening holes (their "
                                        "fillets carry the structural stress peaks)")
    size_fillet: float | None = param(None, unit="mm", low=0.01, high=100.0,
                                      default_doc="½ × the hole size (`size_hole` or its default)",
                                      doc="element size on the corner fillets of the lightening holes, where the "
                                          "structural stress peak is (a local refinement: the rest of the hole "
                                          "keeps `size_hole`)")
    contact_grid_flank: float | None = param(None, unit="mm", low=0.01, high=100.0,
                                             default_doc="`size_flank` (a column at every boundary vertex)",
                                             doc="spacing of the contact grid along the profile: the pin-load footprint "
                                                 "columns and their half-width (1.5 spacings); set it to keep the contact "
                                                 "model, and its cost, fixed while the mesh is refined (docs/theory.md § 6)")
    contact_grid_bore: float | None = param(None, unit="mm", low=0.01, high=100.0,
                                            default_doc="`size_bore` (a column at every boundary vertex)",
                                            doc="spacing of the contact grid along the bores (the roller-load footprint "
                                                "columns), as `contact_grid_flank`")
    symmetric: bool = param(True, doc="mesh one 360°/N sector and copy it by rotation when the disc is N-fold "
                                      "symmetric (exactly symmetric mesh; the load cycle then solves one sector "
                                      "of crank angles)")


@dataclass(frozen=True)
class CrankSupport:
    """The crankshaft as a beam on two support bearings (optional table ``[crank_support]``).

    Either the beam (``span``, ``eccentric_positions``, one of ``journal_diameter`` and
    ``bending_stiffness_Nmm2``, the material and the support/carrier stiffnesses) or directly the
    influence matrix ``influence_mm_per_N`` of the eccentrics. Only read and validated here; the
    physics is elsewhere.

    Attributes
    ----------
    span : float or None
        Distance between the load centres of the two support bearings, mm.
    eccentric_positions : tuple of float or None
        Position of each eccentric (one per disc), mm from support 1, inside (0, span).
    journal_diameter : float or None
        Diameter of the crankshaft journal (solid circular section), mm.
    bending_stiffness_Nmm2 : float or None
        E·I of the crankshaft, N·mm².
    youngs_modulus, poissons_ratio : float
        Material of the crankshaft (MPa, –).
    shear : bool
        Include the Timoshenko shear deflection (needs ``journal_diameter``).
    support_stiffness_N_per_mm : float or tuple of float or None
        Radial stiffness of the support bearings: one value for both or (support 1, support 2),
        N/mm; None: rigid supports.
    carrier_stiffness_N_per_mm : float or tuple of float or None
        Stiffness of the carrier at the supports, in series with the support bearings, N/mm.
    influence_mm_per_N : tuple of tuple of float or None
        discs × discs symmetric positive-definite matrix: displacement of eccentric i per unit
        force on eccentric j, mm/N.
    support_bearing_C_N : float or None
        Basic dynamic load rating C of one support bearing, N (None: loads only, no life).
    support_bearing_life_exponent : float
        Its life exponent p (10/3 roller, 3 ball bearings).
    radial_clearance : float
        Radial internal clearance of the support bearings (the crankshaft's total free radial
        movement in them), mm; each eccentric may move by half of it relative to the carrier before
        the supports carry.
    """

    span: float | None = param(None, unit="mm", low=1.0, high=5000.0,
                               doc="distance between the load centres of the two support bearings")
    eccentric_positions: tuple[float, ...] | None = param(
        None, unit="mm", low=0.0, low_open=True, high=5000.0, max_length=4,
        doc="position of each eccentric from support 1, one per disc (`loads.discs`), distinct, inside (0, span)")
    journal_diameter: float | None = param(None, unit="mm", low=1.0, high=1000.0,
                                           doc="crankshaft journal diameter (solid circular section)")
    bending_stiffness_Nmm2: float | None = param(None, unit="N·mm²", low=1.0e3, high=1.0e18,
                                                 doc="crankshaft bending stiffness E·I; give this or `journal_diameter`")
    youngs_modulus: float = param(206000.0, unit="MPa", low=1.0e3, high=1.2e6, doc="crankshaft E")
    poissons_ratio: float = param(0.3, low=0.0, high=0.5, high_open=True, doc="crankshaft ν")
    shear: bool = param(True, doc="Timoshenko shear deflection (needs `journal_diameter`)")
    support_stiffness_N_per_mm: float | tuple[float, ...] | None = param(
        None, unit="N/mm", low=1.0e2, high=1.0e10, max_length=2, default_doc="none (rigid supports)",
        doc="radial stiffness of the support bearings: one value for both, or [support 1, support 2]")
    carrier_stiffness_N_per_mm: float | tuple[float, ...] | None = param(
        None, unit="N/mm", low=1.0e2, high=1.0e10, max_length=2, default_doc="none (rigid carrier)",
        doc="carrier stiffness at the supports, in series with the support bearings: one value or a list of 2")
    influence_mm_per_N: tuple[tuple[float, ...], ...] | None = param(
        None, unit="mm/N", low=-1.0, high=1.0, max_length=4,
        doc="instead of the beam keys: discs × discs symmetric positive-definite matrix, displacement of "
            "eccentric i per unit force on eccentric j")
    support_bearing_C_N: float | None = param(
        None, unit="N", low=1.0, high=1.0e8, default_doc="none (support-bearing loads only, no life)",
        doc="basic dynamic load rating C of one support bearing (from its maker's catalogue): gives the support "
            "bearings' ISO 281 L10h from their loads over the cycle")
    support_bearing_life_exponent: float = param(
        10.0 / 3.0, low=1.0, high=10.0, default_doc="10/3 (roller bearings)",
        doc="life exponent p of the support bearings, L10 = (C/P)^p: 10/3 roller, 3 ball bearings")
    radial_clearance: float = param(
        0.0, unit="mm", low=0.0, high=0.2,
        default_doc="0 (tapered roller support bearings mounted with axial preload, as RV reducers are: no play; "
                    "Harris & Kotzalas, *Rolling Bearing Analysis*, on preloaded tapered roller pairs)",
        doc="radial internal clearance of the support bearings (the crankshaft's total free radial movement in "
            "them): each eccentric moves by half of it relative to the carrier before the supports carry; adds "
            "to the crank bearing's clearance (needs the `rollers` bearing model)")

    @staticmethod
    def _pair(value: float | tuple[float, ...] | None) -> tuple[float | None, float | None]:
        if value is None:
            return (None, None)
        if isinstance(value, tuple):
            return (value[0], value[1])
        return (value, value)

    @property
    def support_stiffness_pair(self) -> tuple[float | None, float | None]:
        """Stiffness of support 1 and support 2, N/mm (None where not given: rigid)."""
        return self._pair(self.support_stiffness_N_per_mm)

    @property
    def carrier_stiffness_pair(self) -> tuple[float | None, float | None]:
        """Carrier stiffness at support 1 and support 2, N/mm (None where not given: rigid)."""
        return self._pair(self.carrier_stiffness_N_per_mm)


PIN_ROLLING = ("none", "free")
"""Values of ``wear.pin_rolling``."""


@dataclass(frozen=True)
class Wear:
    """Archard wear over the hours of service (optional table ``[wear]``, all keys optional; read by
    ``rvfem wear``). The duty is the case's ``[loads]``: its torque and speed, or its duty cycle
    (negative torques load the other flanks)."""

    k_flank_pin: float = param(
        2.8e-11, unit="mm²/N", low=0.0, high=1.0e-3,
        default_doc="2.8e-11 (2.8e-17 m²/N): Liu et al.'s k of the cycloid–pin pair (Janakiraman's regression, not "
                    "printed), recovered from their mean flank wear of 2.70e-5 µm per output revolution at 412 N·m "
                    "and 15 rpm (docs/theory.md, \"Transmission-accuracy life\")",
        doc="Archard wear coefficient k = K/H of the cycloid flank and pin pair")
    crank_bearing_rate_um_per_N_Mrev: float = param(
        5.3e-7, unit="µm/(N·10⁶ rev)", low=0.0, high=1.0,
        default_doc="5.3e-7: Liu et al.'s turning-arm bearing, 1.15e-4 µm/N over 6000 h at 600 rpm",
        doc="growth of the crank bearings' radial clearance per N of mean radial load and per million "
            "revolutions of the crank relative to the disc (the roller–raceway wear)")
    support_bearing_rate_um_per_N_Mrev: float = param(
        9.0e-7, unit="µm/(N·10⁶ rev)", low=0.0, high=1.0,
        default_doc="9.0e-7: Liu et al.'s crankshaft support bearing, 1.90e-4 µm/N over 6000 h at 585 rpm",
        doc="growth of the support bearings' radial clearance per N of mean radial load and per million "
            "revolutions of the crank relative to the carrier (needs `[crank_support]`)")
    update_step_um: float = param(
        2.5, unit="µm", low=0.01, high=100.0,
        default_doc="2.5 (Liu et al., after Zhang et al.: below it the contact pressures do not change)",
        doc="the geometry is updated whenever the largest wear increment of any part reaches this")
    lost_motion_limit_arcsec: float = param(
        60.0, unit="arcsec", low=0.1, high=3600.0, default_doc="60 (Liu et al.)",
        doc="the lost motion at which the transmission-accuracy life ends")
    pin_rolling: str = param(
        "none", choices=PIN_ROLLING, default_doc="`\"none\"` (Liu et al.)",
        doc="`\"none\"`: the pins do not turn in their grooves (their wear stays on the contact arc); "
            "`\"free\"`: they turn slowly, spreading their worn area over the whole circumference")
