"""The crank bearing in depth: slices along every roller, film, κ, a_ISO and the three lives
(:mod:`rvfem.evaluate.roller_life`)."""

from __future__ import annotations

from typing import Any

from rvfem.evaluate import roller_life
from rvfem.results.analysis import rigid_bearing_forces

from rvfem.results.format import angle

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'compute', 'depth_life_dict', 'summary']

def depth_life_dict(d: Any) -> dict[str, Any] | None:
    """κ, a_ISO and the lives of one BearingDepth (``rvfem rigid --json``'s bearings)."""
    if d is None:
        return None
    return {"kappa": d.kappa, "a_iso": d.a_iso, "L_nm_h": d.L_nm_h, "L10r_h": d.L10r_h,
            "film_thickness_min_um": d.film_thickness_min_um, "roller_peak_pressure_MPa": d.roller_peak_pressure_MPa}


def _depth_dict(d: Any) -> dict[str, Any]:
    return {
        "roller_peak_pressure_MPa": d.roller_peak_pressure_MPa,
        "roller_edge_factor": d.roller_edge_factor,
        "peak_raceway": d.raceway,
        "peak_theta_deg": angle(d.theta_deg),
        "peak_roller": d.roller + 1,
        "peak_roller_load_N": d.roller_load_N,
        "max_roller_load_N": d.max_roller_load_N,
        "max_roller_theta_deg": angle(d.max_roller_theta_deg),
        "max_roller": d.max_roller + 1,
        "peak_tilt_mrad": d.tilt_mrad,
        "max_shear_MPa": d.max_shear_MPa,
        "max_shear_depth_mm": d.max_shear_depth_mm,
        "film_thickness_min_um": d.film_thickness_min_um,
        "film_thickness_central_um": d.film_thickness_central_um,
        "film_parameter": d.film_parameter,
        "kappa": d.kappa,
        "a_iso": d.a_iso,
        "L10h_h": d.L10h,
        "L_nm_h": d.L_nm_h,
        "L10r_h": d.L10r_h,
        **_damage_dict(getattr(d, "damage", None)),
    }


def _damage_dict(g: Any) -> dict[str, Any]:
    """Where the lamina damage concentrates (a :class:`rvfem.evaluate.roller_life.DamageLocation`)."""
    keys = ("damage_raceway", "damage_x_mm", "damage_peak_over_mean", "damage_spread_mm", "damage_middle_share")
    if g is None:
        return dict.fromkeys(keys)
    return dict(zip(keys, (g.raceway, g.x_mm, g.peak_over_mean, g.spread_mm, g.middle_share)))


def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    depth = getattr(a, "roller_depth", None)
    if depth is None:
        return {"crank_bearing_depth": None}
    rigid = {d.bearing: d for d in depth.rigid}
    bearings = []
    for f in depth.flexible:
        r = rigid.get(f.bearing)
        ratio = (lambda key: None if r is None or not getattr(r, key) else getattr(f, key) / getattr(r, key))
        bearings.append({"bearing": f.bearing + 1, "rigid": None if r is None else _depth_dict(r),
                         "flexible": _depth_dict(f), "L10h_ratio": ratio("L10h"), "L_nm_ratio": ratio("L_nm_h"),
                         "L10r_ratio": ratio("L10r_h")})
    return {"crank_bearing_depth": {
        "profile": a.case.crank_bearing.profile.kind,
        "slices": a.case.crank_bearing.profile.slices,
        "max_slope_mrad": depth.max_slope_mrad,
        "bearings": bearings,
    }}


def compute(inputs: Any) -> roller_life.CrankBearingDepth | None:
    """The crank bearing in depth: slices of every roller, film, a_ISO, L_nm and L10r, rigid and
    flexible (:func:`rvfem.evaluate.roller_life.crank_bearing_depth`)."""
    rigid = inputs["rigid"]
    rigid_depths = tuple(b.depth for b in rigid.bearings if b.depth is not None)
    return roller_life.crank_bearing_depth(inputs["case"], inputs["theta"], inputs["cycle"],
                                           rigid_bearing_forces(rigid, inputs["theta"]), inputs["comparison"],
                                           rigid.rating_N, rigid.bearing_speed_rpm, rigid_depths=rigid_depths or None,
                                           progress=inputs["progress"])


KEYS = (
    KeyRow('`crank_bearing_depth`',
           'object or null',
           'the crank bearing in depth (bearing model `rollers`, else null; docs/theory.md, "The crank bearing in depth"): the pressure along the rollers by the slice model, film, κ, a_ISO and the three lives'),
    KeyRow('`crank_bearing_depth.profile`, `crank_bearing_depth.slices`',
           'str, int',
           'roller profile (`crank_bearing.profile.kind`) and slices per roller'),
    KeyRow('`crank_bearing_depth.max_slope_mrad`',
           'float',
           'largest slope of the crankshaft at an eccentric over the cycle, mrad (0 with rigid crank support); the tilt of eccentric against bore'),
    KeyRow('`crank_bearing_depth.bearings[]`',
           'array',
           'one entry per bearing'),
    KeyRow('`crank_bearing_depth.bearings[].bearing`',
           'int',
           'bearing number (from 1)'),
    KeyRow('`crank_bearing_depth.bearings[].rigid`, `crank_bearing_depth.bearings[].flexible`',
           'object (`rigid` may be null)',
           "from the handbook forces on rigid rings with the case's clearance or preload and Palmgren's law (the FE roller law's rigid-disc limit), untilted (null for Zp − Zc ≠ 1); from the FE roller loads with the crankshaft's tilt; both with the case's extra misalignment (the ratio in steps: `crank_bearing_l10r_steps`)"),
    KeyRow('&nbsp;&nbsp;`.roller_peak_pressure_MPa`, `.roller_edge_factor`',
           'float',
           "largest pressure along a roller over the cycle (both raceways), MPa; its ratio to the Hertz p_h of the same roller's Q/L"),
    KeyRow('&nbsp;&nbsp;`.peak_raceway`, `.peak_theta_deg`, `.peak_roller`, `.peak_roller_load_N`, `.peak_tilt_mrad`',
           'str, float, int, float, float',
           "where the pressure peaks: `eccentric` or `bore`, crank angle, roller (from 1), that roller's load and tilt (not necessarily the most loaded roller: a tilt moves the peak)"),
    KeyRow('&nbsp;&nbsp;`.max_roller_load_N`, `.max_roller_theta_deg`, `.max_roller`',
           'float, float, int',
           'the most loaded roller of the bearing: the largest roller load over the cycle, its crank angle and roller (from 1); the same quantity as `hertz.fe_rollers` (flexible) and `hertz.stribeck_rigid` (rigid)'),
    KeyRow('&nbsp;&nbsp;`.max_shear_MPa`, `.max_shear_depth_mm`',
           'float',
           'subsurface principal shear stress 0.300·p and its depth 0.786·b under the peak (Tresca, plane strain)'),
    KeyRow('&nbsp;&nbsp;`.film_thickness_min_um`, `.film_thickness_central_um`, `.film_parameter`',
           'float',
           'EHL film of the most loaded roller on the eccentric (Pan & Hamrock), µm; Λ = h_min/σ'),
    KeyRow('&nbsp;&nbsp;`.kappa`, `.a_iso`',
           'float',
           'viscosity ratio κ = ν/ν1 and the ISO 281 life modification factor a_ISO (radial roller bearings, e_C·C_u/P with P = F_m)'),
    KeyRow('&nbsp;&nbsp;`.L10h_h`, `.L_nm_h`, `.L10r_h`',
           'float',
           'basic rating life, modified rating life a1·a_ISO·L10h (a1 = 1), and the ISO/TS 16281 reference life from the lamina loads (Palmgren–Miner over the cycle; lamina ratings from C/λν as ISO/TS 16281 has them), hours'),
    KeyRow('&nbsp;&nbsp;`.damage_raceway`, `.damage_x_mm`, `.damage_peak_over_mean`, `.damage_spread_mm`, `.damage_middle_share`',
           'str, float, float, float, float (null without load)',
           "where spalling starts: the lamina damage of L10r shared among the laminae as ISO/TS 16281's Weibull sum has it, over the cycle (`roller_damage.csv`); the raceway and lamina centre (mm from the roller's centre) of the largest damage per length, that largest over the raceway's mean over L_we (1: spread evenly), the length over which it is at least half its largest (mm), and the share of both raceways' damage in the middle half of the roller, \\|x\\| ≤ L_we/4 (0.5: spread evenly)"),
    KeyRow('`crank_bearing_depth.bearings[].L10h_ratio`, `crank_bearing_depth.bearings[].L_nm_ratio`, `crank_bearing_depth.bearings[].L10r_ratio`',
           'float or null',
           'flexible / rigid of each life'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("roller_depth", summary, KEYS, requires=("case", "theta", "cycle", "rigid", "comparison"),
                  compute=compute, applies=lambda inputs: inputs["cycle"].roller_loads is not None, stage="roller_slices",
                  screen=lambda s: screen_lines.roller_depth_lines(s.get("crank_bearing_depth")), screen_rank=50)
