"""Lubrication and the modified life of the crank bearings: viscosity at the operating temperature,
entrainment speed, EHL film thickness of the roller line contact, ISO 281's reference viscosity
ν1, viscosity ratio κ, life modification factor a_ISO, static rating C0 and fatigue load limit C_u.

Plain functions of numbers (viscosities in mm²/s, temperatures in °C, speeds in rpm, lengths in mm,
loads in N, moduli in MPa).

Sources
-------
* ASTM D341, *Viscosity–temperature charts for liquid petroleum products* (Walther's equation).
* H. Pan, B. J. Hamrock, *Simple formulas for performance parameters used in elastohydrodynamically
  lubricated line contacts*, J. Tribology 111 (1989) 246-251 (central and minimum film thickness).
* D. Dowson, G. R. Higginson, *Elasto-hydrodynamic lubrication*, 2nd ed., Pergamon 1977
  (minimum film thickness of a line contact, used as the cross-check).
* ISO 281:2007, *Rolling bearings - Dynamic load ratings and rating life*, 9.3 (ν1, κ, e_C, a_ISO
  for radial roller bearings) and Annex B (C_u).
* ISO 76:2006, *Rolling bearings - Static load ratings* (C0 of radial roller bearings).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rvfem.case.definition import Lubricant

__all__ = [
    "ISO_VG_NU100",
    "CLEANLINESS_EC",
    "A_ISO_MAX",
    "FilmThickness",
    "walther_viscosity",
    "lubricant_viscosity",
    "entrainment_speed",
    "pan_hamrock_film",
    "dowson_higginson_min_film",
    "reference_viscosity",
    "a_iso_roller",
    "static_load_rating",
    "fatigue_load_limit",
    "contamination_factor",
    "composite_roughness_um",
]

#: ν100 (mm²/s) of the ISO viscosity grades at a viscosity index of about 100 (ν40 = the grade).
ISO_VG_NU100 = {22: 4.3, 32: 5.4, 46: 6.8, 68: 8.7, 100: 11.3, 150: 14.7, 220: 19.0, 320: 24.0, 460: 30.0}

#: e_C of the ISO 281 cleanliness levels for D_pw < 100 mm, the middle of each range (ISO 281
#: Table 14: extreme 1; high 0.8–0.6; normal 0.6–0.5; slight 0.5–0.3; typical 0.3–0.1; severe
#: 0.1–0; very severe 0).
CLEANLINESS_EC = {"extreme": 1.0, "high": 0.7, "normal": 0.55, "slight": 0.4, "typical": 0.2, "severe": 0.05,
                  "very_severe": 0.0}

#: ISO 281 caps a_ISO at 50.
A_ISO_MAX = 50.0


@dataclass(frozen=True)
class FilmThickness:
    """EHL film of a line contact (Pan & Hamrock).

    Attributes
    ----------
    central_um, minimum_um : float
        h_c and h_min, µm.
    speed_parameter, load_parameter, material_parameter : float
        U = η0·u/(E'·R'), W' = w'/(E'·R'), G = α·E' (dimensionless).
    """

    central_um: float
    minimum_um: float
    speed_parameter: float
    load_parameter: float
    material_parameter: float


def walther_viscosity(nu40: float, nu100: float, temperature_C: float) -> float:
    """Kinematic viscosity at ``temperature_C`` from the values at 40 and 100 °C, mm²/s.

    ASTM D341 (Walther): log10(log10(ν + 0.7)) = A − B·log10(T), T in K, through the two points.
    """
    if not (nu40 > nu100 > 0):
        raise ValueError("walther_viscosity needs nu40 > nu100 > 0")
    t1, t2 = math.log10(313.15), math.log10(373.15)
    y1 = math.log10(math.log10(nu40 + 0.7))
    y2 = math.log10(math.log10(nu100 + 0.7))
    slope = (y2 - y1) / (t2 - t1)
    y = y1 + slope * (math.log10(temperature_C + 273.15) - t1)
    return 10.0 ** (10.0 ** y) - 0.7


def lubricant_viscosity(lubricant: Lubricant) -> tuple[float, float, float]:
    """(ν40, ν100, ν at the operating temperature) of a case's ``[lubricant]``, mm²/s."""
    if lubricant.nu40 is not None and lubricant.nu100 is not None:
        nu40, nu100 = lubricant.nu40, lubricant.nu100
    elif lubricant.nu40 is not None or lubricant.nu100 is not None:
        raise ValueError("lubricant: give both nu40 and nu100, or iso_vg alone")
    else:
        assert lubricant.iso_vg is not None   # the case gives the grade or both viscosities
        nu40, nu100 = float(lubricant.iso_vg), ISO_VG_NU100[int(lubricant.iso_vg)]
    return nu40, nu100, walther_viscosity(nu40, nu100, lubricant.temperature_C)


def entrainment_speed(bearing_speed_rpm: float, pitch_diameter_mm: float, roller_diameter_mm: float) -> float:
    """Mean rolling (entrainment) speed u = (u_roller + u_raceway)/2 of a roller bearing with one
    ring turning at n_b relative to the other, m/s.

    Relative to the cage the turning raceway moves at ω·D_m·(1 − γ²)/4 (cage at ω·(1 − γ)/2,
    raceway radius D_m·(1 − γ)/2), the same at both raceways, γ = D_we/D_m (Harris & Kotzalas).
    """
    gamma = roller_diameter_mm / pitch_diameter_mm
    omega = 2.0 * math.pi * bearing_speed_rpm / 60.0
    return omega * pitch_diameter_mm * 1e-3 * (1.0 - gamma * gamma) / 4.0


def pan_hamrock_film(load_per_length_N_per_mm: float, reduced_radius_mm: float, composite_modulus_MPa: float,
                     viscosity_Pas: float, speed_m_s: float, pressure_viscosity_per_GPa: float) -> FilmThickness:
    """Central and minimum EHL film thickness of a line contact (Pan & Hamrock 1989).

    H_c = 2.922·W'^−0.166·U^0.692·G^0.470, H_min = 1.714·W'^−0.128·U^0.694·G^0.568, H = h/R',
    with E' = 2E* (their E' = 2/[(1 − ν_a²)/E_a + (1 − ν_b²)/E_b]), U = η0·u/(E'·R'),
    W' = w'/(E'·R'), G = α·E'. Isothermal, Newtonian, fully flooded, smooth.

    Chosen over Dowson–Higginson because it gives h_c and h_min from one fit to numerical solutions
    over a wide range (Hamrock, *Fundamentals of Fluid Film Lubrication*, ch. 21); Dowson–Higginson's
    h_min (:func:`dowson_higginson_min_film`) is kept as a cross-check.

    Parameters
    ----------
    load_per_length_N_per_mm : float
        w' = Q/L, N/mm.
    reduced_radius_mm : float
        R', mm.
    composite_modulus_MPa : float
        E*, MPa.
    viscosity_Pas : float
        η0, Pa·s.
    speed_m_s : float
        Entrainment speed u, m/s.
    pressure_viscosity_per_GPa : float
        α, 1/GPa.
    """
    e_prime = 2.0 * composite_modulus_MPa * 1e6                  # Pa
    r = reduced_radius_mm * 1e-3                                  # m
    u = viscosity_Pas * speed_m_s / (e_prime * r)
    w = load_per_length_N_per_mm * 1e3 / (e_prime * r)
    g = pressure_viscosity_per_GPa * 1e-9 * e_prime
    hc = 2.922 * w**-0.166 * u**0.692 * g**0.470 * r
    hm = 1.714 * w**-0.128 * u**0.694 * g**0.568 * r
    return FilmThickness(central_um=hc * 1e6, minimum_um=hm * 1e6, speed_parameter=u, load_parameter=w,
                         material_parameter=g)


def dowson_higginson_min_film(load_per_length_N_per_mm: float, reduced_radius_mm: float,
                              composite_modulus_MPa: float, viscosity_Pas: float, speed_m_s: float,
                              pressure_viscosity_per_GPa: float) -> float:
    """Minimum film thickness of a line contact after Dowson & Higginson (1977), µm:
    H_min = 2.65·U^0.70·G^0.54·W'^−0.13 (same U, W', G and E' = 2E* as :func:`pan_hamrock_film`)."""
    f = pan_hamrock_film(load_per_length_N_per_mm, reduced_radius_mm, composite_modulus_MPa, viscosity_Pas,
                         speed_m_s, pressure_viscosity_per_GPa)
    return (2.65 * f.speed_parameter**0.70 * f.material_parameter**0.54 * f.load_parameter**-0.13
            * reduced_radius_mm * 1e3)


def reference_viscosity(speed_rpm: float, pitch_diameter_mm: float) -> float:
    """ISO 281 reference kinematic viscosity ν1 (mm²/s) for adequate lubrication.

    ν1 = 45000·n^−0.83·D_pw^−0.5 for n < 1000 rpm, 4500·n^−0.5·D_pw^−0.5 for n ≥ 1000 rpm
    (ISO 281:2007, 9.3.3, n in rpm, D_pw in mm).
    """
    if speed_rpm <= 0 or pitch_diameter_mm <= 0:
        raise ValueError("reference_viscosity needs a positive speed and pitch diameter")
    if speed_rpm < 1000.0:
        return 45000.0 * speed_rpm**-0.83 * pitch_diameter_mm**-0.5
    return 4500.0 * speed_rpm**-0.5 * pitch_diameter_mm**-0.5


def a_iso_roller(kappa: float, ec_cu_over_p: float) -> float:
    """Life modification factor a_ISO of radial roller bearings (ISO 281:2007, 9.3.3.2, eqs. (34)
    to (36)).

    a_ISO = 0.1·[1 − (1.5859 − c1/κ^e) · (e_C·C_u/P)^0.4]^−9.185 with
    (c1, e) = (1.3993, 0.054381) for 0.1 ≤ κ < 0.4, (1.2348, 0.19087) for 0.4 ≤ κ < 1 and
    (1.2348, 0.071739) for 1 ≤ κ ≤ 4 (the branches meet at κ = 0.4 and 1); κ > 4 is taken as 4
    and κ < 0.1 as 0.1 (outside the standard's range, warned elsewhere); capped at 50 (also where
    the bracket is not positive). The ball-bearing equations (31) to (33) have other constants
    (2.5671, 2.2649, 1.9987) and exponents (0.83, 1/3, −9.3).
    """
    k = min(max(kappa, 0.1), 4.0)
    if k < 0.4:
        c1, e = 1.3993, 0.054381
    elif k < 1.0:
        c1, e = 1.2348, 0.19087
    else:
        c1, e = 1.2348, 0.071739
    x = max(ec_cu_over_p, 0.0)
    bracket = 1.0 - (1.5859 - c1 / k**e) * x**0.4
    if bracket <= 0.0:
        return A_ISO_MAX
    return min(0.1 * bracket**-9.185, A_ISO_MAX)


def static_load_rating(rollers: int, roller_diameter: float, roller_length: float, pitch_diameter: float,
                       rows: int = 1, contact_angle_deg: float = 0.0) -> float:
    """Basic static radial load rating C0 of a radial roller bearing, N (ISO 76:2006, 6.1.2):
    C0r = 44·(1 − D_we·cos α/D_pw)·i·Z·L_we·D_we·cos α."""
    cos_a = math.cos(math.radians(contact_angle_deg))
    return 44.0 * (1.0 - roller_diameter * cos_a / pitch_diameter) * rows * rollers * roller_length \
        * roller_diameter * cos_a


def fatigue_load_limit(static_rating_N: float, pitch_diameter: float) -> float:
    """Fatigue load limit C_u of a roller bearing from C0, N (ISO 281:2007, Annex B, simplified):
    C_u = C0/8.2 for D_pw ≤ 100 mm, times (100/D_pw)^0.3 above."""
    cu = static_rating_N / 8.2
    if pitch_diameter > 100.0:
        cu *= (100.0 / pitch_diameter) ** 0.3
    return cu


def contamination_factor(lubricant: Lubricant) -> float:
    """e_C of a case's ``[lubricant]``: ``contamination_factor`` if given, else from ``cleanliness``
    (:data:`CLEANLINESS_EC`)."""
    if lubricant.contamination_factor is not None:
        return float(lubricant.contamination_factor)
    return CLEANLINESS_EC[lubricant.cleanliness]


def composite_roughness_um(ra_um: float) -> float:
    """Composite rms roughness σ = √(σ1² + σ2²) of two surfaces of the same Ra, with σ ≈ 1.25·Ra
    (Gaussian surface), µm."""
    return math.sqrt(2.0) * 1.25 * ra_um
