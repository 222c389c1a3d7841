"""The verification manual: every reference rvfem is checked against, recomputed and written out.

``python -m rvfem.app.verification docs/verification.md`` recomputes each check of the validation
ladder (docs/theory.md, section 10) from the same rvfem functions the test suite calls and writes a
Markdown table per rung: the quantity, its source, the reference value, rvfem's value, the error
and the tolerance. ``--check`` recomputes and compares with the file instead (exit status 1 when it
is stale). The inputs are fixed (shipped case files with coarse mesh overrides, structured meshes
built here with numpy), and every number is printed to a few significant digits. A relative error at
noise level is printed as a bound rather than as its digits, which differ between machines (BLAS
kernels, thread counts): below 1e-12 it is round-off (``< 1e-12``), below 1e-6 round-off amplified
by a solve (``< 1e-06``), each bound lowered to the check's tolerance where that is smaller
(:func:`noise_bound`). The document is then reproducible to the byte wherever every check passes.

The checks are computed in :mod:`rvfem.app.verification_closed_form` (sections 1-3: the FE core,
contact and the seed numbers against closed forms and published values) and
:mod:`rvfem.app.verification_chain` (sections 4-12: the FE chain on the coarse RV-40E pair) and
:mod:`rvfem.app.verification_wear` (section 14: wear and the transmission-accuracy life), on the
rows of :mod:`rvfem.app.verification_check`; this module gathers them and writes the document, and
gives every name of those modules the tests use. The whole document takes under a minute of CPU
time (coarse meshes, 10° steps; about two minutes of wall time on a busy two-core machine).
"""

from __future__ import annotations

import argparse
import logging
import sys
import tempfile
import time
from pathlib import Path

from rvfem.app.verification_chain import (
    _Discs,
    accuracy_section,
    beam_by_integration,
    clearance_section,
    convergence_section,
    invariants_section,
    mass_strength_section,
    reducer_section,
    rigid_limit_section,
    roller_depth_section,
)
from rvfem.app.verification_check import (
    NOISE_FLOOR,
    ROOT,
    ROUND_OFF,
    Check,
    Section,
    _error,
    _number,
    noise_bound,
)
from rvfem.app.verification_closed_form import (
    bearing_checks_section,
    contact_section,
    fe_core_section,
    hertz_cylinder,
    kirsch_concentration,
    kirsch_stress,
    lame_dirichlet_errors,
    lame_pressure_displacement_error,
    lame_solution,
    quads_to_triangles,
    seed_section,
    squeezed_cylinder_mesh,
    structured_annulus,
    structured_plate_with_hole,
    traction_load,
)
from rvfem.app.verification_wear import wear_section

log = logging.getLogger(__name__)

__all__ = [
    "Check", "Section", "all_sections", "render", "main",
    # the rows and the reference computations, from the modules of the checks
    "NOISE_FLOOR", "ROUND_OFF", "noise_bound",
    "accuracy_section", "beam_by_integration", "clearance_section", "convergence_section",
    "invariants_section", "mass_strength_section", "reducer_section", "rigid_limit_section",
    "roller_depth_section",
    "contact_section", "fe_core_section", "hertz_cylinder", "kirsch_concentration", "kirsch_stress",
    "lame_dirichlet_errors", "lame_pressure_displacement_error", "lame_solution", "quads_to_triangles",
    "bearing_checks_section", "seed_section", "squeezed_cylinder_mesh", "structured_annulus", "structured_plate_with_hole",
    "traction_load", "wear_section",
]


def all_sections(cache_dir: str | Path | None = None) -> list[Section]:
    """Compute every section (meshes cached in ``cache_dir``, a temporary folder by default)."""

    with tempfile.TemporaryDirectory() as tmp:
        discs = _Discs(Path(cache_dir) if cache_dir is not None else Path(tmp), {})
        sections = [fe_core_section(), contact_section(), seed_section(), rigid_limit_section(discs)]
        sections.extend(invariants_section(discs))
        sections.append(convergence_section(discs))
        sections.append(reducer_section(discs))
        sections.append(clearance_section(discs))
        sections.append(accuracy_section(discs))
        sections.append(roller_depth_section())
        sections.append(mass_strength_section(discs))
        sections.append(bearing_checks_section())
        sections.append(wear_section(discs.cache))
    return sections


def _value(check: Check) -> str:
    """rvfem's value; against a reference of 0 the value is an error and is printed like one
    (:func:`_error`: two digits, or the bound of :func:`noise_bound` at noise level): its later
    digits depend on the alignment of arrays in the BLAS kernels and change from run to run
    (CHOLMOD's with a reference BLAS do)."""
    v = check.value
    if not isinstance(v, str) and check.reference == 0:
        bound = noise_bound(check, float(v))
        return _number(v, 2) if bound is None else f"< {bound:.0e}"
    return _number(v)


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def render(sections: list[Section]) -> str:
    """The Markdown text of the manual."""
    total = sum(len(s.checks) for s in sections)
    passed = sum(c.passed for s in sections for c in s.checks)
    pending = [p for s in sections for p in s.pending]
    out = [
        "# Verification manual",
        "",
        "<!-- generated by `python -m rvfem.app.verification docs/verification.md`; do not edit by hand -->",
        "",
        "Each row recomputes one reference of the validation ladder (docs/theory.md, section 10) with the same "
        "rvfem functions the test suite calls: the quantity, the source of the reference value, the reference, "
        "rvfem's value, the error and the tolerance (the test suite's for the same check). Errors are relative "
        "unless the column says otherwise. Relative errors at noise level, whose digits differ between machines, "
        "are printed as bounds: below 1e-12 round-off (< 1e-12), below 1e-6 round-off amplified by a solve "
        "(< 1e-06), each bound lowered to the tolerance where that is smaller. "
        "Regenerate with `python -m rvfem.app.verification docs/verification.md` (under a minute of CPU "
        "time); `--check` compares instead and fails when this file is stale.",
        "",
        f"**{passed} of {total} checks within tolerance; {len(pending)} pending.**",
        "",
    ]
    for s in sections:
        out += [f"## {s.title}", "", s.text, "",
                "| quantity | source | reference | rvfem | error | kind | tolerance | |",
                "|---|---|---|---|---|---|---|---|"]
        for c in s.checks:
            out.append(f"| {_cell(c.quantity)} | {_cell(c.source)} | {_number(c.reference)} | {_value(c)} | "
                       f"{_error(c)} | {c.error_kind} | {c.tolerance:.2g} | {'ok' if c.passed else '**FAIL**'} |")
        out.append("")
        for p in s.pending:
            out += [f"*Pending.* {p}", ""]
    return "\n".join(out).rstrip("\n") + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m rvfem.app.verification", description=__doc__.splitlines()[0])
    parser.add_argument("path", nargs="?", default=str(ROOT / "docs" / "verification.md"),
                        help="the manual to write (or to check)")
    parser.add_argument("--check", action="store_true", help="compare with the file instead of writing it")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    text = render(all_sections())
    log.info("verification computed in %.0f s", time.perf_counter() - t0)
    path = Path(args.path)
    if args.check:
        current = path.read_text(encoding="utf-8") if path.is_file() else ""
        if current != text:
            print(f"{path} is stale: regenerate it with python -m rvfem.app.verification {path}", file=sys.stderr)
            return 1
        print(f"{path} is up to date")
        return 0
    path.write_text(text, encoding="utf-8")
    print(f"wrote {path} ({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
