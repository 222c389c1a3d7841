"""A subcommand written outside rvfem, in one module: ``rvfem disc-mass CASE`` prints the disc's
mass and polar moment of inertia from its outlines (no mesh, no FE). A test registers it with one
line (``register_subcommand(DISC_MASS)``)."""

from __future__ import annotations

import argparse

from rvfem.app.commands import EXIT_OK, Subcommand
from rvfem.case.definition import load_case
from rvfem.geometry import disc_geometry
from rvfem.geometry.mass import disc_mass_properties


def _arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", help="case file (TOML)")


def _run(args: argparse.Namespace) -> int:
    mass = disc_mass_properties(disc_geometry(load_case(args.case)))
    print(f"disc mass {mass.mass_kg:.6g} kg, polar inertia {mass.polar_inertia_kg_mm2:.6g} kg·mm²")
    return EXIT_OK


DISC_MASS = Subcommand("disc-mass", "the disc's mass and polar inertia from its outlines", _arguments, _run)
