"""Case files: one TOML file describes one reducer and one analysis.

A case file is read with the standard library (:mod:`tomllib`) and turned into small frozen
dataclasses. Units follow the project convention: lengths in mm, forces in N, moduli in MPa,
torque in N·m and speeds in rpm *in the file* (keys say so: ``torque_Nm``, ``speed_rpm``), angles in
degrees in the file (``*_deg``). The dataclasses keep the file's units; helpers such as
:attr:`Loads.disc_torque_Nmm` convert.

One schema
----------
Every key is declared once, on its dataclass field, with :func:`rvfem.case.schema.param`: type (from
the annotation), unit, default, bounds, choices and meaning. The generic reader
(:func:`rvfem.case.schema.read_table`) checks a file against these declarations and the reference
tables of ``docs/case-format.md`` are generated from them (``python -m rvfem.case.format_doc
docs/case-format.md``). Checks that involve several keys are the ``_check_*`` functions below.

Validation
----------
Validation is complete before anything is returned: an unknown or misspelled key (with the closest
known key suggested; unknown keys are reported before missing ones), a missing required key, a
wrong type, a non-finite or out-of-range number or a failed cross-field check raises
:class:`~rvfem.errors.CaseError` naming the file and the dotted key, on one line. Nothing is
half-read.

A :class:`Case` built in code is validated the same way: :meth:`Case.__post_init__` checks every
key of every table against its declaration (numbers are normalized to float, lists to tuples) and
runs the cross-field checks, so ``Case(...)``, :meth:`Case.replace` and ``dataclasses.replace(case,
...)`` all raise :class:`~rvfem.errors.CaseError` for an invalid case (the message names
:attr:`Case.source`). The table dataclasses (:class:`Cycloid`, :class:`Pins`, ...) are plain values
that are checked when they become part of a :class:`Case`.

Example
-------
>>> from rvfem.case.definition import load_case
>>> case = load_case("cases/rv40e_fanholes.toml")    # doctest: +SKIP
>>> case.pins.count, case.cycloid.teeth                # doctest: +SKIP
(40, 39)
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import math
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

from rvfem.case.registry import bearing_model_names, model_requires, pin_model_names
from rvfem.case.schema import (
    check_fields,
    closest,
    file_fields,
    param,
    read_table,
    table_error,
)
from rvfem.errors import CaseError
from rvfem.units import nmm_from_nm

__all__ = [
    "Case",
    "name_problem",
    "Cycloid",
    "ProfileModification",
    "PitchError",
    "Pins",
    "Cranks",
    "CrankBearing",
    "RollerProfile",
    "ROLLER_PROFILE_KINDS",
    "Lubricant",
    "CrankSupport",
    "FanHoles",
    "RoundHoles",
    "Material",
    "DutyRow",
    "Loads",
    "Analysis",
    "MeshSettings",
    "MAX_MESH_NODES",
    "estimated_mesh_nodes",
    "max_element_sizes",
    "load_case",
    "parse_override",
    "apply_overrides",
    "case_from_dict",
    "case_to_dict",
    "table_class",
    "table_to_dict",
    "file_sha256",
    "BUILTIN_HOLE_TABLES",
    "register_hole_table",
    "unregister_hole_table",
    "hole_table_names",
    "registered_hole_shapes",
]


# --------------------------------------------------------------------------------------------
# Dataclasses (units in the file's convention; see module docstring). Bounds: see the section
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
    """

    kind: str = param("straight", choices=tuple(ROLLER_PROFILE_KINDS),
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


# --------------------------------------------------------------------------------------------
# Hole tables. A kind of lightening hole is one hole shape (rvfem.geometry.holes.HoleShape) that
# owns one table of the case file. The built-in tables are fields of Case; the table of a shape
# registered later (rvfem.geometry.holes.register_hole_shape, from any module, a test module
# included) is read into Case.other_holes and is a top-level table of the file like them.
# --------------------------------------------------------------------------------------------

BUILTIN_HOLE_TABLES = ("fan_holes", "round_holes")
"""The hole tables that are fields of :class:`Case`, in the order their holes are numbered."""

_BUILTIN_HOLE_CLASSES = {"fan_holes": FanHoles, "round_holes": RoundHoles}
_HOLE_SHAPES: dict[str, type[Any]] = {}


def register_hole_table(shape: type) -> None:
    """Make ``shape.table`` (a frozen dataclass declared with :func:`~rvfem.case.schema.param`) the table
    ``[shape.name]`` of the case format. Use :func:`rvfem.geometry.holes.register_hole_shape`,
    which calls this.

    The table class must have a property ``outline_length`` (the length of all its holes'
    outlines, mm, for :func:`estimated_mesh_nodes`) and may have a method ``check(fail)`` with
    the checks between its keys (``fail(key, message)`` returns the error to raise).

    Raises
    ------
    ValueError
        ``shape.name`` is not a valid table name, names another table of the case format, or is
        registered by another shape.
    TypeError
        ``shape.table`` is not such a dataclass.
    """
    name, table = getattr(shape, "name", None), getattr(shape, "table", None)
    if not (isinstance(name, str) and name.isidentifier()):
        raise ValueError(f"a hole shape needs a table name (a Python identifier), got {name!r}")
    if name in _BUILTIN_HOLE_CLASSES and table is not _BUILTIN_HOLE_CLASSES[name]:
        raise ValueError(f"the table {name!r} is read as {_BUILTIN_HOLE_CLASSES[name].__name__}")
    if name not in _BUILTIN_HOLE_CLASSES and name in {f.name for f in dataclasses.fields(Case)}:
        raise ValueError(f"{name!r} is a table of the case format already")
    if _HOLE_SHAPES.get(name, shape) is not shape:
        raise ValueError(f"the hole table {name!r} is registered by {_HOLE_SHAPES[name].__qualname__} already")
    if not (isinstance(table, type) and dataclasses.is_dataclass(table) and getattr(table, "__dataclass_params__").frozen):
        raise TypeError(f"the table of hole shape {name!r} must be a frozen dataclass, got {table!r}")
    file_fields(table)     # every key declared with param (raises TypeError otherwise)
    if not hasattr(table, "outline_length"):
        raise TypeError(f"{table.__name__} (table {name!r}) needs a property 'outline_length'")
    _HOLE_SHAPES[name] = shape


def unregister_hole_table(name: str) -> None:
    """Remove the table ``name`` of a registered hole shape from the case format (a built-in
    table cannot be removed; an unknown name is ignored)."""
    if name in BUILTIN_HOLE_TABLES:
        raise ValueError(f"the built-in hole table {name!r} cannot be unregistered")
    _HOLE_SHAPES.pop(name, None)


def hole_table_names() -> tuple[str, ...]:
    """The hole tables of the case format, in the order their holes are numbered: the built-in
    ones, then those of the registered hole shapes in the order they were registered."""
    return tuple(dict.fromkeys([*BUILTIN_HOLE_TABLES, *_HOLE_SHAPES]))


def registered_hole_shapes() -> tuple[type[Any], ...]:
    """The registered hole shapes, in the order of :func:`hole_table_names`."""
    return tuple(_HOLE_SHAPES[name] for name in hole_table_names() if name in _HOLE_SHAPES)


def _other_hole_names() -> tuple[str, ...]:
    """The registered hole tables that are not fields of :class:`Case`."""
    return tuple(name for name in _HOLE_SHAPES if name not in BUILTIN_HOLE_TABLES)


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

    ``size_hole`` is the size on the central hole and the lightening holes (their fillets carry
    the structural stress peaks); None means twice ``size_bore``, capped by ``size_interior``.
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


MAX_NAME_LENGTH = 100
"""Longest case name, characters (it names result folders, with suffixes such as ``-accuracy``)."""

NAME_CHARACTERS = "letters A–Z a–z, digits and . _ + -"
"""What a case name may hold, in words (:data:`_NAME_PATTERN`)."""

_NAME_PATTERN = re.compile(r"[A-Za-z0-9_+][A-Za-z0-9._+-]*")
"""A case name is one portable file-name component: the POSIX portable file-name characters and
``+``, not starting with ``.`` (a hidden file; ``.`` and ``..``) or ``-`` (read as an option)."""


def name_problem(name: str) -> str | None:
    """Why ``name`` cannot be a case name (it names the result folder ``results/<name>``), or
    None if it can: 1 to :data:`MAX_NAME_LENGTH` characters of :data:`NAME_CHARACTERS`, not
    starting with ``.`` or ``-`` (so no path separator, no ``.`` or ``..``, nothing hidden)."""
    rule = (f"one file-name component (it names the result folder): 1–{MAX_NAME_LENGTH} {NAME_CHARACTERS}, "
            "not starting with '.' or '-'")
    if not isinstance(name, str) or not name:
        return f"must be {rule}; got an empty name"
    if len(name) > MAX_NAME_LENGTH:
        return f"must be {rule}; got {len(name)} characters"
    if _NAME_PATTERN.fullmatch(name) is None:
        bad = sorted({c for c in name if not re.fullmatch(r"[A-Za-z0-9._+-]", c)})
        what = (f"it holds {', '.join(repr(c) for c in bad)}" if bad else f"it starts with {name[0]!r}")
        return f"must be {rule}; {what} in {name!r}"
    return None


def _file_stem(values: Mapping[str, Any]) -> str:
    """The default case name: the file name without ``.toml``, each character outside
    :data:`NAME_CHARACTERS` replaced by ``_`` (and a leading ``.`` or ``-`` too)."""
    source = values.get("<source>", "")
    if not source.endswith(".toml"):
        return "case"
    stem = re.sub(r"[^A-Za-z0-9._+-]", "_", Path(source).stem)[:MAX_NAME_LENGTH]
    stem = re.sub(r"^[.-]", "_", stem)
    return stem or "case"


@dataclass(frozen=True, kw_only=True)
class Case:
    """One reducer and one analysis, validated on construction (see the module docstring).

    All arguments are keywords. ``source`` names the file (or ``"<code>"``) in error messages;
    ``overrides`` records the ``KEY=VALUE`` overrides applied on reading. ``other_holes`` holds
    the tables of the registered hole shapes that are not fields (:func:`register_hole_table`) as
    ``(table name, table)`` pairs; :meth:`replace` sets them by name like fields, and
    :meth:`hole_tables` lists every hole table of the case.
    """

    name: str = param(max_length=MAX_NAME_LENGTH, default_from=_file_stem,
                      default_doc="file name without `.toml` (other characters replaced by `_`)",
                      doc="case name used in reports and as the result folder `results/<name>`: one file-name "
                          "component of letters, digits and `._+-`, not starting with `.` or `-`")
    cycloid: Cycloid = param()
    pins: Pins = param()
    cranks: Cranks = param()
    crank_bearing: CrankBearing = param()
    material: Material = param(Material())
    loads: Loads = param()
    analysis: Analysis = param(Analysis())
    mesh: MeshSettings = param(MeshSettings())
    fan_holes: FanHoles | None = param(None)
    round_holes: RoundHoles | None = param(None)
    crank_support: CrankSupport | None = param(None)
    lubricant: Lubricant = param(Lubricant())
    description: str = param("", max_length=10000, doc="free text")
    source: str = param("<code>", compare=False, in_file=False)
    overrides: tuple[str, ...] = param((), compare=False, in_file=False)
    other_holes: tuple[tuple[str, Any], ...] = param((), in_file=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "overrides", tuple(self.overrides))
        check_fields(self, "", self.source)
        _check_other_holes(self)
        for check in _CROSS_CHECKS:
            check(self)

    def hole_tables(self) -> tuple[tuple[str, Any], ...]:
        """``(table name, table)`` of every hole table the case has, in the order the holes are
        numbered (:func:`hole_table_names`)."""
        builtin = tuple((name, getattr(self, name)) for name in BUILTIN_HOLE_TABLES if getattr(self, name) is not None)
        return builtin + self.other_holes

    def hole_shapes(self) -> tuple[tuple[type[Any], Any], ...]:
        """``(hole shape, table)`` of every hole table the case has, in the order of
        :meth:`hole_tables` (the shapes are :class:`rvfem.geometry.holes.HoleShape` classes,
        registered when :mod:`rvfem.geometry` is imported).

        Raises
        ------
        LookupError
            A table's shape is not registered.
        """
        try:
            return tuple((_HOLE_SHAPES[name], table) for name, table in self.hole_tables())
        except KeyError as exc:
            raise LookupError(f"no hole shape is registered for the table {exc.args[0]!r} "
                              "(the built-in ones are registered by importing rvfem.geometry)") from None

    def hole_table(self, name: str) -> Any:
        """The hole table ``name`` of the case, or None if the case has none."""
        return dict(self.hole_tables()).get(name)

    @property
    def short_amplitude_coefficient(self) -> float:
        """k = e·Zp/Rp (must be < 1 for a non-looping epitrochoid)."""
        return self.cycloid.eccentricity * self.pins.count / self.pins.circle_radius

    def replace(self, **changes: Any) -> "Case":
        """A copy with top-level fields replaced (validated again); the table of a registered hole
        shape is replaced by its name like a field (None removes it)."""
        others = {name: changes.pop(name) for name in _other_hole_names() if name in changes}
        if others:
            tables = {**dict(changes.get("other_holes", self.other_holes)), **others}
            changes["other_holes"] = tuple((name, t) for name, t in tables.items() if t is not None)
        return dataclasses.replace(self, **changes)

    def digest(self) -> str:
        """sha256 of the canonical case data (used to name cached meshes and results)."""
        return hashlib.sha256(repr(case_to_dict(self)).encode()).hexdigest()


# --------------------------------------------------------------------------------------------
# Cross-field checks (run by Case.__post_init__, in this order)
# --------------------------------------------------------------------------------------------


def _error(case: Case, key: str, message: str) -> CaseError:
    return table_error(case.source, key, message)


def _check_name(case: Case) -> None:
    problem = name_problem(case.name)
    if problem is not None:
        raise _error(case, "name", problem)


def _check_cycloid_and_pins(case: Case) -> None:
    cyc, pins = case.cycloid, case.pins
    p = cyc.pitch_error
    if p.values and len(p.values) != cyc.teeth:
        raise _error(case, "cycloid.pitch_error.values",
                     f"must have one value per tooth ({cyc.teeth}), got {len(p.values)}")
    if p.values and p.amplitude:
        raise _error(case, "cycloid.pitch_error.amplitude", "and 'values' exclude each other; give one of them")
    if pins.count <= cyc.teeth:
        raise _error(case, "pins.count", f"(Zp = {pins.count}) must exceed cycloid.teeth (Zc = {cyc.teeth}); "
                                         "a cycloid drive needs more pins than lobes")
    k = case.short_amplitude_coefficient
    if k >= 1.0:
        raise _error(case, "cycloid.eccentricity",
                     f"is too large: the short-amplitude coefficient k = e·Zp/Rp = {k:.3f} must be < 1 "
                     "(reduce the eccentricity or enlarge pins.circle_radius)")
    if pins.radius >= pins.circle_radius * math.sin(math.pi / pins.count):
        raise _error(case, "pins.radius", f"({pins.radius} mm) is too large: neighbouring pins overlap")


def _check_cranks(case: Case) -> None:
    cranks = case.cranks
    if len(cranks.angles_deg) != cranks.count:
        raise _error(case, "cranks.angles_deg",
                     f"must list {cranks.count} angles (cranks.count), got {len(cranks.angles_deg)}")
    wrapped = sorted(a % 360.0 for a in cranks.angles_deg)
    gaps = [b - a for a, b in zip(wrapped, wrapped[1:] + [wrapped[0] + 360.0])]
    if min(gaps) < 1e-6:
        raise _error(case, "cranks.angles_deg", f"must be distinct angles (mod 360°), got {list(cranks.angles_deg)}")


def _check_crank_bearing(case: Case) -> None:
    b = case.crank_bearing
    key = "crank_bearing."
    for table, kind, model in (("pins", "pin", case.pins.model), ("crank_bearing", "bearing", b.model)):
        for name in model_requires(kind, model):   # the keys the model declares it needs
            if getattr(getattr(case, table), name) is None:
                raise _error(case, f"{table}.{name}", f"is missing (required when {table}.model = {model!r})")
    if b.stiffness_law == "linear" and b.linear_stiffness_N_per_mm is None:
        raise _error(case, key + "linear_stiffness_N_per_mm", "is missing (required when stiffness_law = 'linear')")
    if b.roller_diameter >= b.pitch_diameter:   # γ = D_we/D_m in (0, 1): ISO 281 f_c, inner raceway > 0
        raise _error(case, key + "roller_diameter", "must be smaller than pitch_diameter")
    if math.pi * b.pitch_diameter - b.rollers * b.roller_diameter <= 0:
        raise _error(case, key + "rollers",
                     f": {b.rollers} rollers of {b.roller_diameter} mm do not fit the pitch circle of "
                     f"{b.pitch_diameter} mm (circumference {math.pi * b.pitch_diameter:.2f} mm)")
    if b.bore_radius <= 0.5 * b.pitch_diameter:
        raise _error(case, key + "bore_radius",
                     f"({b.bore_radius} mm) must exceed half the pitch diameter ({0.5 * b.pitch_diameter} mm)")
    outer = b.outer_raceway_radius
    if b.bore_radius < outer * (1.0 - 1e-9):
        raise _error(case, key + "bore_radius",
                     f"({b.bore_radius} mm) must be at least the outer raceway radius (D_m + D_we)/2 = {outer:g} mm: "
                     "the rollers do not fit between the eccentric and the bore")


def _check_other_holes(case: Case) -> None:
    """Check the tables of :attr:`Case.other_holes` like the fields (each against its declaration)
    and put them in the order of :func:`hole_table_names`."""
    given = case.other_holes
    pairs = list(given.items()) if isinstance(given, Mapping) else list(given)
    names = _other_hole_names()
    seen: set[str] = set()
    for pair in pairs:
        if not (isinstance(pair, tuple) and len(pair) == 2 and pair[0] in names):
            known = ", ".join(names) or "none"
            raise _error(case, "other_holes", f"must hold (table name, table) pairs of the registered hole shapes "
                                              f"({known}), got {pair!r}")
        name, table = pair
        if name in seen:
            raise _error(case, name, "is given twice")
        seen.add(name)
        if table is None:
            continue
        cls = _HOLE_SHAPES[name].table
        if not isinstance(table, cls):
            raise _error(case, name, f"must be a {cls.__name__}, got {table!r}")
        check_fields(table, name, case.source)
    ordered = tuple(sorted((p for p in pairs if p[1] is not None), key=lambda p: names.index(p[0])))
    object.__setattr__(case, "other_holes", ordered)


def _check_holes(case: Case) -> None:
    for name, table in case.hole_tables():
        check = getattr(table, "check", None)
        if check is not None:
            check(lambda key, message, name=name: _error(case, f"{name}.{key}", message))


MIN_DUTY_TORQUE_NM = 1.0e-3
"""Smallest non-zero torque of a duty-cycle row, N·m (a smaller one is a zero in disguise whose
T^p underflows and makes the service life infinite)."""


def _check_loads(case: Case) -> None:
    loads = case.loads
    if loads.torque_split == "stiffness" and loads.discs > 2:
        raise _error(case, "loads.torque_split",
                     f"= 'stiffness' needs 1 or 2 discs (loads.discs = {loads.discs}); use 'equal'")
    if abs(loads.torque_Nm) < MIN_DUTY_TORQUE_NM:
        raise _error(case, "loads.torque_Nm",
                     f"must be at least {MIN_DUTY_TORQUE_NM:g} N·m in magnitude (negative reverses it), "
                     f"got {loads.torque_Nm!r}")
    for i, row in enumerate(loads.duty_cycle):
        if 0.0 < abs(row.torque_Nm) < MIN_DUTY_TORQUE_NM:
            raise _error(case, f"loads.duty_cycle[{i}].torque_Nm",
                         f"must be 0 or at least {MIN_DUTY_TORQUE_NM:g} N·m in magnitude, got {row.torque_Nm!r}")
    if loads.duty_cycle and not any(row.torque_Nm != 0 for row in loads.duty_cycle):
        raise _error(case, "loads.duty_cycle", "needs at least one row with a non-zero torque_Nm")


MAX_MESH_NODES = 2_000_000
"""Largest estimated node count a case may ask for (:func:`estimated_mesh_nodes`)."""

_MESH_SIZE_GROWTH = 0.25
_MESH_BAND_FACTOR = 2.0
_MESH_HOLE_SIZE_FACTOR = 2.0


def estimated_mesh_nodes(case: Case) -> dict[str, float]:
    """Estimate of the node count of the disc mesh, before meshing, per size key.

    The mesh sizes follow the size field of :mod:`rvfem.mesh`: size h_c on a curve of length L_c,
    held for a band of 2·h_c and growing by 0.25 mm/mm to ``size_interior`` H. A triangulation of
    nearly equilateral triangles of edge h has 2/(√3·h²) nodes per unit area, so

        n ≈ 2/√3 · [A/H² + Σ_c L_c·(2/h_c + (1/h_c − 1/H)/0.25)]

    with A the disc area (pin-circle disc minus holes, bores and pins' depth) and L_c the lengths of
    the profile (≈ 2π·Rp·(1 + k), the lobes' arc), the bores, the central hole and the lightening
    holes. It is meant for refusing absurd requests, not for planning: it is 1.2–1.4 times Gmsh's
    vertex counts on the shipped cases. For P2 elements (``analysis.element_order = 2``) the
    nodes are the vertices plus the edge midpoints, about 3 edges per vertex: four times the
    vertex count.

    Returns
    -------
    dict
        ``{"mesh.size_interior": n_interior, "mesh.size_flank": n_flank, "mesh.size_bore": n_bore,
        "mesh.size_hole": n_hole, "total": n}`` (node counts, float).
    """
    ms, cyc, pins = case.mesh, case.cycloid, case.pins
    big = ms.size_interior
    hole_size = ms.size_hole if ms.size_hole is not None else min(big, _MESH_HOLE_SIZE_FACTOR * ms.size_bore)
    outer = max(pins.circle_radius - pins.radius, 1e-3)
    bore = case.crank_bearing.bore_radius
    area = math.pi * outer ** 2 - math.pi * cyc.central_hole_radius ** 2 - case.cranks.count * math.pi * bore ** 2
    hole_length = 2.0 * math.pi * cyc.central_hole_radius
    for _, table in case.hole_tables():
        hole_length += table.outline_length
    density = 2.0 / math.sqrt(3.0)

    def band(length: float, size: float) -> float:
        size = min(size, big)
        return density * length * (_MESH_BAND_FACTOR / size + (1.0 / size - 1.0 / big) / _MESH_SIZE_GROWTH)

    parts = {
        "mesh.size_interior": density * max(area, 0.0) / big ** 2,
        "mesh.size_flank": band(2.0 * math.pi * pins.circle_radius * (1.0 + case.short_amplitude_coefficient),
                                ms.size_flank),
        "mesh.size_bore": band(case.cranks.count * 2.0 * math.pi * bore, ms.size_bore),
        "mesh.size_hole": band(hole_length, hole_size),
    }
    if case.analysis.element_order == 2:
        parts = {key: 4.0 * value for key, value in parts.items()}
    parts["total"] = sum(parts.values())
    return parts


def _check_mesh(case: Case) -> None:
    parts = estimated_mesh_nodes(case)
    if parts["total"] > MAX_MESH_NODES:
        by_key = {k: v for k, v in parts.items() if k != "total"}
        if case.mesh.size_hole is None:   # the hole size follows size_bore
            by_key["mesh.size_bore"] += by_key.pop("mesh.size_hole")
        worst = max(by_key, key=by_key.__getitem__)
        raise _error(case, worst,
                     f"asks for too fine a mesh: about {parts['total']:.3g} "
                     f"{'P2 ' if case.analysis.element_order == 2 else ''}nodes estimated "
                     f"({by_key[worst]:.3g} from this size), more than "
                     f"{MAX_MESH_NODES:.0e}; make it larger")


FOOTPRINT_ELEMENTS = 1.5
"""Half-width of the pin and roller load footprints in element sizes (mesh.size_flank at the
profile, mesh.size_bore at the bores); the solver spreads the loads over it (:mod:`rvfem.solve.cycle`),
the case bounds the mesh sizes with it. The Hertz half-widths of these contacts (≈0.1 mm) are below
one element at the default sizes, so the footprint spreads each force over a few elements; the
bearing loads do not depend on it (global equilibrium), only the stress right under a contact."""

BORE_FOOTPRINT_FRACTION = 0.25
"""Largest part of a bore's circumference a roller footprint (2·FOOTPRINT_ELEMENTS·size_bore wide)
may cover."""

FLANK_FOOTPRINT_FRACTION = 0.5
"""Largest part of a lobe a pin footprint (2·FOOTPRINT_ELEMENTS·size_flank wide) may cover: one
flank. The lobe is measured on the root circle, 2π·r_root/Zc, a lower bound of its length."""


def max_element_sizes(case: Case) -> dict[str, float]:
    """Largest ``mesh.size_flank`` and ``mesh.size_bore`` whose load footprints still act locally, mm.

    A pin's and a roller's force enter the disc spread over ±FOOTPRINT_ELEMENTS element sizes along
    the profile and the bore (the Hertz half-widths, about 0.1 mm, are below one element). That
    footprint is a contact patch only while it is small against the feature it loads: a pin's
    footprint may cover at most one flank (half a lobe, measured on the root circle: π·r_root/Zc),
    a roller's at most a quarter of the bore circumference (π·bore_radius/2). Beyond that the load
    is smeared over the neighbouring lobe or most of the bore, and at half the bore circumference
    the load operator cannot be built at all.

    Returns
    -------
    dict
        ``{"mesh.size_flank": h_flank_max, "mesh.size_bore": h_bore_max}``, mm.
    """
    cyc, pins = case.cycloid, case.pins
    mod = cyc.modification
    root = (pins.circle_radius + mod.shift) - cyc.eccentricity - (pins.radius + mod.equidistant)
    lobe = 2.0 * math.pi * max(root, 0.0) / cyc.teeth
    bore = 2.0 * math.pi * case.crank_bearing.bore_radius
    return {"mesh.size_flank": FLANK_FOOTPRINT_FRACTION * lobe / (2.0 * FOOTPRINT_ELEMENTS),
            "mesh.size_bore": BORE_FOOTPRINT_FRACTION * bore / (2.0 * FOOTPRINT_ELEMENTS)}


def _floor3(x: float) -> float:
    """x rounded down to three significant digits (a limit to quote that the quoted value meets)."""
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.floor(x / step + 1e-9) * step


def _check_mesh_sizes(case: Case) -> None:
    limits = max_element_sizes(case)
    ms = case.mesh
    if limits["mesh.size_flank"] > 0 and ms.size_flank > limits["mesh.size_flank"]:
        raise _error(case, "mesh.size_flank",
                     f"({ms.size_flank:g} mm) is too coarse for the teeth: a pin load is spread over "
                     f"±{FOOTPRINT_ELEMENTS:g} element sizes, which must stay within one flank (half a lobe, "
                     f"π·r_root/Zc = {2.0 * FOOTPRINT_ELEMENTS * limits['mesh.size_flank']:.3g} mm); "
                     f"use at most {_floor3(limits['mesh.size_flank']):g} mm")
    if ms.size_bore > limits["mesh.size_bore"]:
        raise _error(case, "mesh.size_bore",
                     f"({ms.size_bore:g} mm) is too coarse for the bores: a roller load is spread over "
                     f"±{FOOTPRINT_ELEMENTS:g} element sizes, which must stay within a quarter of the bore "
                     f"circumference ({2.0 * FOOTPRINT_ELEMENTS * limits['mesh.size_bore']:.3g} mm for "
                     f"crank_bearing.bore_radius = {case.crank_bearing.bore_radius:g} mm); use at most "
                     f"{_floor3(limits['mesh.size_bore']):g} mm")


def _check_crank_support(case: Case) -> None:
    s = case.crank_support
    if s is None:
        return
    discs = case.loads.discs
    key = "crank_support."
    beam_keys = ("span", "eccentric_positions", "journal_diameter", "bending_stiffness_Nmm2",
                 "support_stiffness_N_per_mm", "carrier_stiffness_N_per_mm")
    if s.influence_mm_per_N is not None:
        for name in beam_keys:
            if getattr(s, name) is not None:
                raise _error(case, key + name, "and 'influence_mm_per_N' exclude each other: the influence "
                                               "matrix replaces the beam model; give one of them")
        defaults = {f.name: f.default for f in dataclasses.fields(CrankSupport)}
        for name in ("youngs_modulus", "poissons_ratio", "shear"):
            if getattr(s, name) != defaults[name]:
                raise _error(case, key + name, "only applies to the beam model, not with 'influence_mm_per_N'")
        matrix = s.influence_mm_per_N
        if len(matrix) != discs or any(len(row) != discs for row in matrix):
            shape = f"{len(matrix)}×{'/'.join(sorted({str(len(r)) for r in matrix})) or 0}"
            raise _error(case, key + "influence_mm_per_N",
                         f"must be a {discs}×{discs} matrix (loads.discs = {discs}), got {shape}")
        scale = max(abs(v) for row in matrix for v in row)
        for i in range(discs):
            for j in range(i):
                if abs(matrix[i][j] - matrix[j][i]) > 1e-9 * scale:
                    raise _error(case, key + "influence_mm_per_N",
                                 f"must be symmetric, got [{i}][{j}] = {matrix[i][j]!r} and [{j}][{i}] = {matrix[j][i]!r}")
        if not _positive_definite(matrix):
            raise _error(case, key + "influence_mm_per_N", "must be positive definite (a compliance matrix)")
        return
    for name in ("span", "eccentric_positions"):
        if getattr(s, name) is None:
            raise _error(case, key + name, "is missing (required for the beam model; or give 'influence_mm_per_N')")
    positions = s.eccentric_positions
    assert positions is not None and s.span is not None   # both checked just above
    if len(positions) != discs:
        raise _error(case, key + "eccentric_positions",
                     f"must list {discs} positions (loads.discs), got {len(positions)}")
    for i, x in enumerate(positions):
        if not 0.0 < x < s.span:
            raise _error(case, f"{key}eccentric_positions[{i}]",
                         f"({x:g} mm) must lie strictly between the supports, in (0, {s.span:g}) mm (crank_support.span)")
    if len(set(positions)) != len(positions):
        raise _error(case, key + "eccentric_positions", f"must be distinct, got {list(positions)}")
    if (s.journal_diameter is None) == (s.bending_stiffness_Nmm2 is None):
        raise _error(case, key + "journal_diameter",
                     "or 'bending_stiffness_Nmm2': give exactly one of them (or 'influence_mm_per_N' instead of the beam)")
    if s.shear and s.journal_diameter is None:
        raise _error(case, key + "shear", "= true needs 'journal_diameter' (the shear area); set shear = false "
                                          "with bending_stiffness_Nmm2")
    for name in ("support_stiffness_N_per_mm", "carrier_stiffness_N_per_mm"):
        value = getattr(s, name)
        if isinstance(value, tuple) and len(value) != 2:
            raise _error(case, key + name, f"must be one number or a list of 2 (support 1, support 2), got {len(value)} values")


def _positive_definite(matrix: tuple[tuple[float, ...], ...]) -> bool:
    """Cholesky factorization succeeds (symmetric input)."""
    n = len(matrix)
    low = [[0.0] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1):
            s = matrix[i][j] - sum(low[i][k] * low[j][k] for k in range(j))
            if i == j:
                if not s > 0.0:
                    return False
                low[i][i] = math.sqrt(s)
            else:
                low[i][j] = s / low[j][j]
    return True


def _check_roller_profile(case: Case) -> None:
    """A crowned roller's drop has to fit its length: the combined profile's modified segment within
    half the roller, the arc's radius beyond it (docs/theory.md § 12)."""
    b, key = case.crank_bearing, "crank_bearing.profile."
    half = 0.5 * b.roller_length
    if b.profile.kind == "combined" and b.profile.modification_length >= half:
        raise _error(case, key + "modification_length", f"({b.profile.modification_length:g} mm) must be shorter than "
                     f"half the roller length ({half:g} mm): the modified segment runs from each end inwards")
    if b.profile.kind == "arc" and b.profile.crown_radius <= half:
        raise _error(case, key + "crown_radius", f"({b.profile.crown_radius:g} mm) must exceed half the roller "
                     f"length ({half:g} mm)")
    defaults = {f.name: f.default for f in dataclasses.fields(RollerProfile)}
    for name, kind in _PROFILE_KEY_KIND.items():
        value = getattr(b.profile, name)
        if b.profile.kind != kind and value != defaults[name]:
            raise _error(case, key + name, f"= {value:g} is given, but kind = {b.profile.kind!r} does not use it "
                         f"(it shapes the {kind!r} profile): set {key}kind = {kind!r}, or leave {name} out")


_PROFILE_KEY_KIND = {key: kind for kind, keys in ROLLER_PROFILE_KINDS.items() for key in keys}
"""The profile keys that only one ``kind`` uses. Given with another kind they are refused, unless
they hold their default (a case written out whole, as ``case.json``, holds every key)."""


def _check_lubricant(case: Case) -> None:
    """Two viscosities or none (then ``iso_vg``), and the oil thinner when hot (Walther's line)."""
    oil = case.lubricant
    if (oil.nu40 is None) != (oil.nu100 is None):
        given, missing = ("lubricant.nu40", "lubricant.nu100") if oil.nu100 is None else ("lubricant.nu100",
                                                                                        "lubricant.nu40")
        raise _error(case, missing, f"is missing: '{given}' alone does not fix the viscosity–temperature line; "
                     "give both, or neither and 'lubricant.iso_vg'")
    if oil.nu40 is not None and oil.iso_vg is not None:
        raise _error(case, "lubricant.iso_vg", f"= {oil.iso_vg} and 'lubricant.nu40'/'lubricant.nu100' "
                     f"({oil.nu40:g}/{oil.nu100:g} mm²/s) are both given: give the grade or the two viscosities, "
                     "not both")
    if oil.nu40 is not None and oil.nu100 is not None and oil.nu100 >= oil.nu40:
        raise _error(case, "lubricant.nu100", f"({oil.nu100:g} mm²/s) must be below 'lubricant.nu40' "
                     f"({oil.nu40:g} mm²/s): an oil thins as it warms")


_MATERIAL_DEFAULT_FATIGUE_LIMIT = next(f.default for f in dataclasses.fields(Material) if f.name == "fatigue_limit")


def _check_material(case: Case) -> None:
    """σ_W < R_m, R_p0.2 ≤ R_m (the fatigue check's Goodman line, docs/theory.md "Mass and strength") and
    σ_W ≤ R_p0.2: a fully reversed stress amplitude above the yield strength yields the material in
    every cycle, so it cannot be an endurance limit (for steels σ_W ≈ 0.4–0.5·R_m, below R_p0.2)."""
    m = case.material
    if m.yield_strength < m.fatigue_limit:
        raise _error(case, "material.yield_strength", f"{m.yield_strength:g} MPa is below the fatigue limit "
                     f"'material.fatigue_limit' = {m.fatigue_limit:g} MPa ({_MATERIAL_DEFAULT_FATIGUE_LIMIT:g} MPa, that of 100Cr6, when not given): a "
                     "fatigue limit above the yield strength is not physical (the material would yield in every "
                     "cycle); give the strengths of the disc's material together")
    if m.yield_strength > m.ultimate_strength:
        raise _error(case, "material.yield_strength", f"{m.yield_strength:g} MPa is above the ultimate strength "
                     f"{m.ultimate_strength:g} MPa; give a yield strength ≤ 'material.ultimate_strength'")
    if m.fatigue_limit >= m.ultimate_strength:
        raise _error(case, "material.fatigue_limit", f"{m.fatigue_limit:g} MPa is not below the ultimate strength "
                     f"{m.ultimate_strength:g} MPa; lower it")


_CROSS_CHECKS = (_check_name, _check_cycloid_and_pins, _check_cranks, _check_crank_bearing, _check_roller_profile, _check_holes,
                 _check_loads, _check_mesh, _check_mesh_sizes, _check_crank_support, _check_lubricant, _check_material)


# --------------------------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------------------------


def case_from_dict(data: dict, source: str = "<dict>") -> Case:
    """Validate a parsed case (a dict shaped like the TOML file) and build a :class:`Case`.

    Raises
    ------
    CaseError
        With the file (``source``) and the dotted key of the first problem found.
    """
    others = _other_hole_names()
    if not others or not isinstance(data, dict):
        return read_table(Case, data, "", source, extra={"source": source})
    known = tuple(spec.name for spec in file_fields(Case)) + others
    for name in data:
        if name not in known:
            hint = closest(name, known)
            raise table_error(source, name, "is not a known key" + (f" (did you mean '{hint}'?)" if hint else "")
                              + "; remove it or check the spelling")
    values: dict[str, Any] = {"<source>": source}
    case = read_table(Case, {k: v for k, v in data.items() if k not in others}, "", source, values,
                      extra={"source": source})
    tables = tuple((name, read_table(_HOLE_SHAPES[name].table, data[name], name, source, values))
                   for name in others if name in data)
    return dataclasses.replace(case, other_holes=tables) if tables else case


def table_class(dotted: str) -> type:
    """The dataclass of the table at dotted key ``dotted`` ("" for the top level, e.g.
    ``"cycloid.modification"``, ``"loads.duty_cycle"``)."""
    cls: type = Case
    parts = [p for p in dotted.split(".") if p]
    if parts and parts[0] in _other_hole_names():
        cls, parts = _HOLE_SHAPES[parts[0]].table, parts[1:]
    for part in parts:
        spec = {s.name: s for s in file_fields(cls)}.get(part)
        if spec is None or spec.item is None:
            raise KeyError(f"no table {dotted!r} in the case format")
        cls = spec.item
    return cls


def parse_override(text: str) -> tuple[tuple[str, ...], Any]:
    """Split an override ``KEY=VALUE`` into the dotted key's parts and the value.

    The value is a TOML literal (``4.5``, ``"rigid_bore"``, ``[1.0, 2.0]``, ``true``); a bare word
    that is not a TOML literal is taken as a string (``crank_bearing.model=rigid_bore``).
    """
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep or not key or any(not part.strip() for part in key.split(".")):
        raise CaseError(f"override {text!r}: expected KEY=VALUE with a dotted key of the case format, "
                        "e.g. fan_holes.ligament=4.0")
    value = value.strip()
    try:
        parsed = tomllib.loads(f"v = {value}")["v"]
    except tomllib.TOMLDecodeError:
        if not value or any(c in value for c in "[]{}\"\'=,"):
            raise CaseError(f"override {text!r}: {value!r} is not a TOML value") from None
        parsed = value
    return tuple(part.strip() for part in key.split(".")), parsed


def apply_overrides(data: dict, overrides: Sequence[str]) -> dict:
    """A copy of the parsed case ``data`` with the ``KEY=VALUE`` overrides applied (not validated:
    :func:`case_from_dict` validates the result like a file, unknown keys included)."""

    data = copy.deepcopy(data)
    for text in overrides:
        parts, value = parse_override(text)
        table = data
        for depth, part in enumerate(parts[:-1]):
            nxt = table.setdefault(part, {})
            if not isinstance(nxt, dict):
                raise CaseError(f"override {text!r}: {'.'.join(parts[:depth + 1])} is not a table")
            table = nxt
        table[parts[-1]] = value
    return data


def load_case(path: str | Path, overrides: Sequence[str] = ()) -> Case:
    """Read and validate a TOML case file, optionally with overrides.

    Parameters
    ----------
    path : path
    overrides : sequence of str
        ``KEY=VALUE`` strings (see :func:`parse_override`), applied to the file's data before
        validation, so an override is checked exactly like the file (an unknown key gets a
        "did you mean"). They are recorded in :attr:`Case.overrides`.

    Raises
    ------
    CaseError
        If the file is missing, is not valid TOML, or any key is missing, unknown, mistyped or
        non-physical. The message names the file and the key.
    """
    path = Path(path)
    try:
        text = path.read_bytes()
    except OSError as exc:
        raise CaseError(f"{path}: cannot read the case file ({exc.strerror or exc})") from None
    try:
        data = tomllib.loads(text.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise CaseError(f"{path}: not a valid TOML file ({exc})") from None
    overrides = tuple(overrides)
    if not overrides:
        return case_from_dict(data, source=str(path))
    case = case_from_dict(apply_overrides(data, overrides), source=f"{path} (with overrides)")
    return dataclasses.replace(case, overrides=overrides)


_NOT_IN_FILE = ("source", "overrides", "other_holes")


def table_to_dict(table: Any) -> Any:
    """A table (a dataclass of the case format) as plain dicts and lists in the file's layout; keys
    whose value is None are left out."""
    if dataclasses.is_dataclass(table):
        return {f.name: table_to_dict(getattr(table, f.name)) for f in dataclasses.fields(table)
                if getattr(table, f.name) is not None and f.name not in _NOT_IN_FILE}
    if isinstance(table, tuple):
        return [table_to_dict(v) for v in table]
    return table


def case_to_dict(case: Case) -> dict:
    """The case as a plain dict in the file's layout (round-trips through :func:`case_from_dict`);
    the tables of registered hole shapes (:attr:`Case.other_holes`) are top-level tables."""
    data = table_to_dict(case)
    data["loads"]["duty_cycle"] = data["loads"].get("duty_cycle", [])
    for name, table in case.other_holes:
        data[name] = table_to_dict(table)
    return data


def file_sha256(path: str | Path) -> str:
    """sha256 of a file's bytes (recorded in results so they can be traced to their case file)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()
