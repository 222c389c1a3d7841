"""Finite-element core: plane-stress stiffness of the disc, boundary loads, factorisation, stresses.

One module per stage, every public name re-exported here (``from rvfem.fem import build_model``):

:mod:`rvfem.fem.model`
    :class:`FEModel` and :func:`build_model` (scikit-fem P1/P2 triangles, plane stress,
    :func:`plane_stress_constants`, :func:`plane_stress_stiffness`), edge lookup and outward
    normals.
:mod:`rvfem.fem.loads`
    :class:`BoundaryChain` and :func:`boundary_chains` (boundary edges ordered by arc length),
    :func:`footprint_weights` (consistent nodal weights of Hertz-like footprints) and
    :func:`load_operator` (the sparse map from footprint forces to nodal loads).
:mod:`rvfem.fem.solve`
    :func:`factorize` on a minimal statically determinate support (choice of sparse solver by
    measurement), :func:`rigid_body_modes` and :func:`remove_rigid_motion`.
:mod:`rvfem.fem.stress`
    :func:`stress_fields` (element and vertex stresses, von Mises, principal), its parts
    :func:`displacement_gradients` and :func:`plane_stress_components`, and
    :func:`nodal_stress_operator` (the same vertex stresses as a linear operator).

Units: lengths mm, forces N, moduli and stresses MPa; ``K @ u`` is a force in N. The theory
(plane-stress FE and its convergence rates, footprint loads, the floating body) is written out in
docs/theory.md.
"""

from __future__ import annotations

from rvfem.fem.loads import (
    BoundaryChain,
    boundary_chains,
    footprint_weights,
    load_operator,
)
from rvfem.fem.model import (
    FEModel,
    build_model,
    edge_indices,
    edge_outward_normals,
    plane_stress_constants,
    plane_stress_stiffness,
)
from rvfem.fem.solve import (
    SOLVER_PREFERENCE,
    Factorization,
    available_solvers,
    default_support,
    factorize,
    factorize_matrix,
    remove_rigid_motion,
    rigid_body_modes,
)
from rvfem.fem.stress import (
    StressFields,
    StressState,
    displacement_gradients,
    nodal_stress_operator,
    plane_stress_components,
    stress_fields,
)

__all__ = [
    "FEModel",
    "build_model",
    "plane_stress_constants",
    "plane_stress_stiffness",
    "edge_indices",
    "edge_outward_normals",
    "BoundaryChain",
    "boundary_chains",
    "footprint_weights",
    "load_operator",
    "SOLVER_PREFERENCE",
    "available_solvers",
    "default_support",
    "Factorization",
    "factorize",
    "factorize_matrix",
    "rigid_body_modes",
    "remove_rigid_motion",
    "StressState",
    "StressFields",
    "stress_fields",
    "displacement_gradients",
    "plane_stress_components",
    "nodal_stress_operator",
]
