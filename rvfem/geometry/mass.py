"""Mass properties of the disc: area, mass, polar moment of inertia, and what the holes save.

Everything is exact integrals over the outlines (Green's theorem), in the disc's body frame with
the origin at the disc centre:

* area            A   = ∬ dA            = ½ ∮ (x dy − y dx)
* polar moment    J_O = ∬ (x² + y²) dA  = ⅓ ∮ (x³ dy − y³ dx)

(Green's theorem ∮(P dx + Q dy) = ∬(∂Q/∂x − ∂P/∂y) dA with P = −y³/3, Q = x³/3.) The tooth
profile is the polygon of its dense samples (:attr:`rvfem.geometry.Profile.points`, the same
polygon :attr:`rvfem.geometry.DiscGeometry.area` integrates); on a polygon both integrals are
exact per edge (the vertex formula J_O = 1/12 Σ c_k (x_k² + x_k x_{k+1} + x_{k+1}² + y_k² +
y_k y_{k+1} + y_{k+1}²), c_k = x_k y_{k+1} − x_{k+1} y_k). The holes' outlines are lines and
circular arcs (:meth:`rvfem.geometry.Feature.outline`); their polar moment is integrated along
each primitive by Gauss–Legendre quadrature, exact to rounding for the line's cubic integrand and,
on arc pieces of at most 90°, for the arc's trigonometric polynomial of degree 4 (error below 1e-15
relative with 16 points).

Mass and inertia of the plane-stress disc of width ``b`` (``cycloid.thickness``) and density ρ:
m = ρ·b·A, I = ρ·b·J_O (a prism: the polar moment of a prism about its axis is its cross-section's
polar moment times ρ·b). The "solid" disc is the same profile with the central hole and the
bearing bores but no lightening holes: the saving is what the lightening holes buy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rvfem.geometry.features import Arc, DiscGeometry, LineSegment

__all__ = [
    "MassProperties",
    "polygon_area_polar",
    "outline_area_polar",
    "disc_mass_properties",
    "mesh_area_polar",
    "KG_PER_M3_TO_KG_PER_MM3",
]

KG_PER_M3_TO_KG_PER_MM3 = 1.0e-9
"""1 kg/m³ = 1e-9 kg/mm³."""

_GAUSS_POINTS = 16
_MAX_ARC_PIECE = math.pi / 2
_GX, _GW = np.polynomial.legendre.leggauss(_GAUSS_POINTS)


def polygon_area_polar(points: np.ndarray) -> tuple[float, float]:
    """Signed area (mm²) and polar moment about the origin (mm⁴) of a closed polygon.

    Parameters
    ----------
    points : ndarray (n, 2)
        Vertices, mm, counter-clockwise for a positive result; the last vertex is joined to the
        first.

    Returns
    -------
    (float, float)
        A = ½ Σ c_k and J_O = 1/12 Σ c_k (x_k² + x_k x_{k+1} + x_{k+1}² + y_k² + y_k y_{k+1} +
        y_{k+1}²), c_k = x_k y_{k+1} − x_{k+1} y_k (Green's theorem on each edge, exact).
    """
    p = np.asarray(points, dtype=float)
    x, y = p[:, 0], p[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    c = x * yn - xn * y
    area = 0.5 * float(np.sum(c))
    polar = float(np.sum(c * (x * x + x * xn + xn * xn + y * y + y * yn + yn * yn))) / 12.0
    return area, polar


def _primitive_polar(q) -> float:
    """⅓ ∫ (x³ dy − y³ dx) along one outline primitive (line or arc), mm⁴."""
    if isinstance(q, LineSegment):
        (x0, y0), (x1, y1) = q.start, q.end
        t = 0.5 * (_GX + 1.0)
        x, y = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
        return float(np.sum(0.5 * _GW * (x**3 * (y1 - y0) - y**3 * (x1 - x0)))) / 3.0
    if isinstance(q, Arc):
        pieces = max(1, math.ceil(abs(q.sweep) / _MAX_ARC_PIECE))
        total = 0.0
        for k in range(pieces):
            a0 = q.start_angle + q.sweep * k / pieces
            da = q.sweep / pieces
            a = a0 + 0.5 * (_GX + 1.0) * da
            x = q.centre[0] + q.radius * np.cos(a)
            y = q.centre[1] + q.radius * np.sin(a)
            dx, dy = -q.radius * np.sin(a), q.radius * np.cos(a)
            total += float(np.sum(0.5 * _GW * da * (x**3 * dy - y**3 * dx))) / 3.0
        return total
    raise TypeError(f"unknown outline primitive {type(q).__name__}")


def outline_area_polar(feature) -> tuple[float, float]:
    """Area (mm²) and polar moment about the disc centre (mm⁴) of a hole, a
    :class:`~rvfem.geometry.Feature` whose outline runs counter-clockwise around it (Green's
    theorem over its lines and arcs; module docstring)."""
    prims = feature.outline()
    return (float(sum(q.area_term() for q in prims)), float(sum(_primitive_polar(q) for q in prims)))


@dataclass(frozen=True)
class MassProperties:
    """Mass properties of a disc and of its solid twin (no lightening holes).

    Attributes
    ----------
    area_mm2, polar_mm4 : float
        Area and polar moment of area about the disc centre of the disc with its holes.
    solid_area_mm2, solid_polar_mm4 : float
        The same without the lightening holes (central hole and bores kept).
    thickness_mm : float
        Disc width b.
    density_kg_m3 : float
        ρ.
    """

    area_mm2: float
    polar_mm4: float
    solid_area_mm2: float
    solid_polar_mm4: float
    thickness_mm: float
    density_kg_m3: float

    @property
    def _rho_b(self) -> float:
        return self.density_kg_m3 * KG_PER_M3_TO_KG_PER_MM3 * self.thickness_mm

    @property
    def mass_kg(self) -> float:
        """m = ρ·b·A, kg."""
        return self._rho_b * self.area_mm2

    @property
    def polar_inertia_kg_mm2(self) -> float:
        """Mass moment of inertia about the disc's axis through its centre, I = ρ·b·J_O, kg·mm²."""
        return self._rho_b * self.polar_mm4

    @property
    def solid_mass_kg(self) -> float:
        return self._rho_b * self.solid_area_mm2

    @property
    def solid_polar_inertia_kg_mm2(self) -> float:
        return self._rho_b * self.solid_polar_mm4

    @property
    def mass_saving_percent(self) -> float:
        """(solid − holed)/solid mass, % (positive: the holes make the disc lighter)."""
        return 100.0 * (1.0 - self.area_mm2 / self.solid_area_mm2)

    @property
    def inertia_saving_percent(self) -> float:
        """(solid − holed)/solid polar inertia, %."""
        return 100.0 * (1.0 - self.polar_mm4 / self.solid_polar_mm4)


def disc_mass_properties(geometry: DiscGeometry, density_kg_m3: float | None = None) -> MassProperties:
    """Area, polar moment, mass and inertia of a disc and of its solid twin.

    Parameters
    ----------
    geometry : DiscGeometry
    density_kg_m3 : float, optional
        Density; default ``geometry.case.material.density_kg_m3``.

    Returns
    -------
    MassProperties
    """
    case = geometry.case
    rho = float(case.material.density_kg_m3 if density_kg_m3 is None else density_kg_m3)
    area, polar = polygon_area_polar(geometry.profile.points)
    cut = [outline_area_polar(f) for f in (geometry.central_hole,) + tuple(geometry.bores)]
    holes = [outline_area_polar(f) for f in geometry.holes]
    solid_a = area - sum(a for a, _ in cut)
    solid_j = polar - sum(j for _, j in cut)
    return MassProperties(area_mm2=solid_a - sum(a for a, _ in holes), polar_mm4=solid_j - sum(j for _, j in holes),
                          solid_area_mm2=solid_a, solid_polar_mm4=solid_j,
                          thickness_mm=float(case.cycloid.thickness), density_kg_m3=rho)


def mesh_area_polar(points: np.ndarray, triangles: np.ndarray) -> tuple[float, float]:
    """Area (mm²) and polar moment about the origin (mm⁴) of a triangle mesh: per triangle
    ∬(x² + y²) dA = A/6 · Σ_{i≤j} (x_i x_j + y_i y_j) (exact for a straight-sided triangle).
    The independent check of :func:`disc_mass_properties` (the mesh's straight edges cut the
    curved boundaries by chords)."""
    p = np.asarray(points, dtype=float)[np.asarray(triangles)]
    x, y = p[..., 0], p[..., 1]
    a = 0.5 * ((x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0]))

    def sym(u: np.ndarray) -> np.ndarray:
        return (u[:, 0] ** 2 + u[:, 1] ** 2 + u[:, 2] ** 2 + u[:, 0] * u[:, 1] + u[:, 0] * u[:, 2]
                + u[:, 1] * u[:, 2])

    return float(np.sum(a)), float(np.sum(a / 6.0 * (sym(x) + sym(y))))

