"""The result sections of an analysis, listed in one place.

rvfem's own sections are listed in :data:`BUILTIN_SECTIONS`, in the order of ``summary.json`` (as
meshio lists its formats in its ``__init__``): a new section of this package is its module plus its
line here, with no registration by the side effect of an import. A section defined outside the
package (a notebook, a test module, a plug-in) adds itself with one line::

    from rvfem.results.registry import register_section
    register_section(SECTION)                   # after the built-in sections

:func:`sections` lists them all, in order; :func:`key_table` is the key table of docs/outputs.md,
generated from the sections' declarations (``python -m rvfem.results.registry docs/outputs.md``
rewrites it; a test fails when it is stale).
"""

from __future__ import annotations

import re
import sys

from rvfem._files import regenerate_document

from rvfem.results import (
    accuracy,
    attribution,
    bearing_checks,
    bearings,
    cycle,
    duty_cycle,
    files,
    header,
    hertz,
    mass_strength,
    model,
    pin_flank,
    reducer_stage,
    references,
    roller_depth,
    roller_life_steps,
    stress,
    warnings,
)
from rvfem.results.section import Section

__all__ = ["BUILTIN_SECTIONS", "key_table", "main", "register_section", "render_outputs_doc", "section",
           "sections", "unregister_section"]

BUILTIN_SECTIONS: tuple[Section, ...] = (
    header.SECTION,
    warnings.SECTION,
    model.SECTION,
    references.SECTION,
    bearings.SECTION,
    cycle.SECTION,
    stress.SECTION,
    mass_strength.SECTION,
    hertz.SECTION,
    pin_flank.SECTION,
    duty_cycle.SECTION,
    reducer_stage.SECTION,
    attribution.SECTION,
    roller_depth.SECTION,
    roller_life_steps.SECTION,
    bearing_checks.SECTION,
    accuracy.SECTION,
    files.SECTION,
)
"""rvfem's own result sections, in the order of their keys in ``summary.json``."""

_ADDED: dict[str, Section] = {}
"""Sections added with :func:`register_section` (a module-level list, like the writer and model
registries; a test fixture saves and restores it)."""


def sections() -> tuple[Section, ...]:
    """Every section: the built-in ones, then those registered, in the order they were; the
    ``files`` section (the folder's listing and timings) stays last."""
    *front, last = BUILTIN_SECTIONS
    return (*front, *_ADDED.values(), last)


def section(name: str) -> Section:
    """The section named ``name`` (KeyError naming the known ones otherwise)."""
    for s in sections():
        if s.name == name:
            return s
    raise KeyError(f"no result section {name!r}; known: {', '.join(s.name for s in sections())}")


def register_section(new: Section) -> Section:
    """Add a section after the built-in ones (before ``files``); returns it. A name already taken
    raises ValueError."""
    if any(s.name == new.name for s in sections()):
        raise ValueError(f"a result section named {new.name!r} is already registered")
    _ADDED[new.name] = new
    return new


def unregister_section(name: str) -> None:
    """Remove a section added with :func:`register_section` (built-in ones stay)."""
    _ADDED.pop(name, None)


def key_table() -> str:
    """The key table of ``summary.json`` in docs/outputs.md, from every section's
    :attr:`~rvfem.results.section.Section.keys`, in section order."""
    rows = ["| key | type | meaning |", "|---|---|---|"]
    for s in sections():
        rows += [f"| {r.keys} | {r.type} | {r.meaning} |" for r in s.keys]
    return "\n".join(rows)


_BLOCK = re.compile(r"(<!-- summary keys: generated from the result sections -->\n)(.*?)(<!-- /summary keys -->)", re.S)


def render_outputs_doc(text: str) -> str:
    """``text`` (docs/outputs.md) with its generated key table replaced by :func:`key_table`."""
    if not _BLOCK.search(text):
        raise ValueError("the document has no '<!-- summary keys: generated from the result sections -->' block")
    return _BLOCK.sub(lambda m: f"{m.group(1)}{key_table()}\n{m.group(3)}", text)


def main(argv: list[str] | None = None) -> int:
    """``python -m rvfem.results.registry [--check] DOC``: regenerate (or check) the key table of DOC."""
    return regenerate_document("rvfem.results.registry", "key table", render_outputs_doc, argv)

if __name__ == "__main__":
    sys.exit(main())
