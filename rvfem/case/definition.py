"""Case files: one TOML file describes one reducer and one analysis.

This module is the case layer's public face: every name below is reached as
``rvfem.case.definition.X``. The tables' dataclasses live in :mod:`rvfem.case.tables`, :class:`Case`,
its hole-table registry and its checks across tables in :mod:`rvfem.case.whole_case`, and reading
(files, dicts, ``--set`` overrides) in :mod:`rvfem.case.reading`.

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
docs/case-format.md``). Checks that involve several keys are the ``_check_*`` functions of
:mod:`rvfem.case.whole_case`.

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


from rvfem.case.reading import (
    apply_overrides,
    case_from_dict,
    file_sha256,
    load_case,
    parse_override,
    table_class,
)
from rvfem.case.tables import (
    B_M_RANGE,
    DEFAULT_ISO_VG,
    LAMBDA_NU_RANGE,
    MAX_FRICTION,
    ROLLER_PROFILE_KINDS,
    TORQUE_SPLITS,
    Analysis,
    CrankBearing,
    Cranks,
    CrankSupport,
    Cycloid,
    DutyRow,
    FanHoles,
    Loads,
    Lubricant,
    Material,
    MeshSettings,
    Pins,
    PitchError,
    ProfileModification,
    RollerProfile,
    RoundHoles,
)
from rvfem.case.mesh_checks import _MESH_BAND_FACTOR, _MESH_HOLE_SIZE_FACTOR, _MESH_SIZE_GROWTH
from rvfem.case.whole_case import (
    BORE_FOOTPRINT_FRACTION,
    BUILTIN_HOLE_TABLES,
    FLANK_FOOTPRINT_FRACTION,
    FOOTPRINT_ELEMENTS,
    MAX_MESH_NODES,
    MAX_NAME_LENGTH,
    MIN_DUTY_TORQUE_NM,
    NAME_CHARACTERS,
    Case,
    ComponentTable,
    case_to_dict,
    component_tables,
    estimated_mesh_nodes,
    hole_table_names,
    max_element_sizes,
    name_problem,
    register_component_table,
    register_hole_table,
    registered_hole_shapes,
    table_to_dict,
    unregister_component_table,
    unregister_hole_table,
)


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
    "ComponentTable",
    "register_component_table",
    "unregister_component_table",
    "component_tables",
    # reached as definition.X by the repository, beside the names above
    "B_M_RANGE",
    "LAMBDA_NU_RANGE",
    "DEFAULT_ISO_VG",
    "TORQUE_SPLITS",
    "MAX_FRICTION",
    "MAX_NAME_LENGTH",
    "NAME_CHARACTERS",
    "MIN_DUTY_TORQUE_NM",
    "FOOTPRINT_ELEMENTS",
    "BORE_FOOTPRINT_FRACTION",
    "FLANK_FOOTPRINT_FRACTION",
    "_MESH_SIZE_GROWTH",
    "_MESH_BAND_FACTOR",
    "_MESH_HOLE_SIZE_FACTOR",
]
