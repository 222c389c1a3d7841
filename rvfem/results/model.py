"""The ``model`` section: the model as solved (elements, mesh, models, torque convention, bearing rating)."""

from __future__ import annotations

from typing import Any

from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'summary']

def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    case, model, c = a.case, a.system.model, a.comparison
    return {"model": {
        "bearing_model": case.crank_bearing.model,
        "element_order": model.order,
        "pin_model": a.system.pin_model,
        "pin_friction": case.analysis.friction,
        "nodes": model.n_nodes,
        "vertices": model.n_vertices,
        "dofs": model.n_dofs,
        "elements": model.n_elements,
        "mesh_file": a.mesh.path.name,
        "mesh_min_quality": a.mesh.min_quality,
        "mesh_symmetry": a.system.symmetry,
        "angle_step_deg": 360.0 / len(a.theta),
        "angles": len(a.theta),
        "angles_solved": int(a.cycle.timings.get("pair_solves", len(a.theta))),
        "output_torque_Nm": case.loads.torque_Nm,
        "discs": case.loads.discs,
        "disc_torque_Nmm": case.loads.disc_torque_Nmm,
        "torque_convention": "the carrier (output) turns about the reducer axis and carries T_out; a disc's pin "
                             "forces have the moment T_out/discs about that axis, T_out/discs·Zc/Zp about the disc "
                             "centre (the handbook's sum P_x = T/(2 e Zc) takes T/2 about the disc centre)",
        "radial_clearance_mm": case.crank_bearing.radial_clearance,
        "equivalent_load_exponent": c.exponent,
        "dynamic_load_rating_N": c.rating_N,
        "bearing_speed_rpm": c.bearing_speed_rpm,
        "handbook_k_y": c.handbook_k_y,
        "fe_pin_resultant_ratio": c.pin_resultant_ratio,
    }}


KEYS = (
    KeyRow('`model`',
           'object',
           'the model as solved'),
    KeyRow('`model.bearing_model`',
           'str',
           '`rollers` or `rigid_bore`'),
    KeyRow('`model.element_order`',
           'int',
           '1 or 2'),
    KeyRow('`model.pin_model`',
           'str',
           '`rigid` or `hertz`'),
    KeyRow('`model.pin_friction`',
           'float',
           'Coulomb friction coefficient at the pins (0: frictionless)'),
    KeyRow('`model.nodes`, `model.vertices`, `model.dofs`, `model.elements`',
           'int',
           'FE nodes (P2: vertices + edge midpoints), mesh vertices, degrees of freedom, triangles'),
    KeyRow('`model.mesh_file`, `model.mesh_min_quality`',
           'str, float',
           'cached mesh file name (in the mesh cache), its minimal Gmsh minSICN quality'),
    KeyRow('`model.mesh_symmetry`',
           'int',
           'N when the mesh is one 360°/N sector copied by rotation (exactly N-fold symmetric: compliance columns and crank angles of one sector, the rest turned), 1 for a full-disc mesh'),
    KeyRow('`model.angle_step_deg`, `model.angles`',
           'float, int',
           'crank-angle step actually used (360/angles) and number of angles'),
    KeyRow('`model.angles_solved`',
           'int',
           'crank angles (pairs of discs for the reducer stage) actually solved; the others follow by the N-fold symmetry and the 180° mirror of the pair'),
    KeyRow('`model.output_torque_Nm`, `model.discs`, `model.disc_torque_Nmm`',
           'float, int, float',
           'torque of the reducer, number of discs, torque per disc'),
    KeyRow('`model.torque_convention`',
           'str',
           'the output torque is carried by the carrier turning about the reducer axis: a disc\'s pin forces have the moment T_out/discs about that axis, Zc/Zp of it about the disc centre (docs/theory.md § 6; the handbook takes T/2 about the disc centre, Zp/Zc more)'),
    KeyRow('`model.radial_clearance_mm`',
           'float',
           'crank-bearing radial clearance'),
    KeyRow('`model.equivalent_load_exponent`',
           'float',
           'p of F_m = (mean F^p)^(1/p)'),
    KeyRow('`model.dynamic_load_rating_N`',
           'float',
           'ISO 281 rating C of the crank bearing'),
    KeyRow('`model.bearing_speed_rpm`',
           'float',
           'n_b = n_out·Zp/(Zp − Zc)'),
    KeyRow('`model.handbook_k_y`, `model.fe_pin_resultant_ratio`',
           'float (`handbook_k_y` may be null)',
           "handbook k_y = ΣP_y/ΣP_x (null for Zp − Zc ≠ 1) and the FE's mean \\|P_y/P_x\\|"),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("model", summary, KEYS)
