"""The checks of a case's mesh sizes: the estimated number of nodes against the largest mesh rvfem
builds, and the element sizes a pin's and a roller's footprint allow (the footprint must stay within
a flank and a quarter of a bore)."""

from __future__ import annotations

import math
from typing import Any

from rvfem.case.schema import table_error

Case = Any
"""A case (:class:`rvfem.case.whole_case.Case`, the layer above this module, which calls these checks)."""

__all__ = ["BORE_FOOTPRINT_FRACTION", "FLANK_FOOTPRINT_FRACTION", "FOOTPRINT_ELEMENTS", "MAX_MESH_NODES",
           "check_mesh", "check_mesh_sizes", "contact_grid_spacing", "estimated_mesh_nodes", "footprint_half_widths",
           "max_element_sizes"]


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


def check_mesh(case: Case) -> None:
    parts = estimated_mesh_nodes(case)
    if parts["total"] > MAX_MESH_NODES:
        by_key = {k: v for k, v in parts.items() if k != "total"}
        if case.mesh.size_hole is None:   # the hole size follows size_bore
            by_key["mesh.size_bore"] += by_key.pop("mesh.size_hole")
        worst = max(by_key, key=by_key.__getitem__)
        raise table_error(case.source, worst,
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


def contact_grid_spacing(case: Case) -> dict[str, float]:
    """Spacing of the contact grid (the footprint columns) along the profile and the bores, mm:
    ``mesh.contact_grid_flank`` / ``mesh.contact_grid_bore``, else the element size there
    (``mesh.size_flank`` / ``mesh.size_bore``: a column at every boundary vertex).

    Returns
    -------
    dict
        ``{"profile": spacing, "bore": spacing}``, mm.
    """
    ms = case.mesh
    return {"profile": ms.contact_grid_flank if ms.contact_grid_flank is not None else ms.size_flank,
            "bore": ms.contact_grid_bore if ms.contact_grid_bore is not None else ms.size_bore}


def footprint_half_widths(case: Case) -> dict[str, float]:
    """Half-width of the pin (``"profile"``) and roller (``"bore"``) load footprints, mm:
    :data:`FOOTPRINT_ELEMENTS` spacings of the contact grid (:func:`contact_grid_spacing`)."""
    return {name: FOOTPRINT_ELEMENTS * h for name, h in contact_grid_spacing(case).items()}


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


def check_mesh_sizes(case: Case) -> None:
    """Refuse a contact grid (the element size, or ``mesh.contact_grid_*`` when given) whose load
    footprints would not act locally (:func:`max_element_sizes`), naming the key that sets it."""
    limits = max_element_sizes(case)
    ms = case.mesh
    spacing = contact_grid_spacing(case)
    flank_key = "mesh.contact_grid_flank" if ms.contact_grid_flank is not None else "mesh.size_flank"
    bore_key = "mesh.contact_grid_bore" if ms.contact_grid_bore is not None else "mesh.size_bore"
    unit = "grid spacings" if ms.contact_grid_flank is not None else "element sizes"
    if limits["mesh.size_flank"] > 0 and spacing["profile"] > limits["mesh.size_flank"]:
        raise table_error(case.source, flank_key,
                     f"({spacing['profile']:g} mm) is too coarse for the teeth: a pin load is spread over "
                     f"±{FOOTPRINT_ELEMENTS:g} {unit}, which must stay within one flank (half a lobe, "
                     f"π·r_root/Zc = {2.0 * FOOTPRINT_ELEMENTS * limits['mesh.size_flank']:.3g} mm); "
                     f"use at most {_floor3(limits['mesh.size_flank']):g} mm")
    unit = "grid spacings" if ms.contact_grid_bore is not None else "element sizes"
    if spacing["bore"] > limits["mesh.size_bore"]:
        raise table_error(case.source, bore_key,
                     f"({spacing['bore']:g} mm) is too coarse for the bores: a roller load is spread over "
                     f"±{FOOTPRINT_ELEMENTS:g} {unit}, which must stay within a quarter of the bore "
                     f"circumference ({2.0 * FOOTPRINT_ELEMENTS * limits['mesh.size_bore']:.3g} mm for "
                     f"crank_bearing.bore_radius = {case.crank_bearing.bore_radius:g} mm); use at most "
                     f"{_floor3(limits['mesh.size_bore']):g} mm")
