"""The reference tables of ``docs/case-format.md``, generated from the declarations of the case's
tables (:func:`rvfem.case.schema.markdown_table`).

``python -m rvfem.case.format_doc docs/case-format.md`` rewrites every block between
``<!-- schema: TABLE -->`` and ``<!-- /schema -->`` in place (``--check`` only reports whether they
are stale; a test fails when they are).
"""

from __future__ import annotations

import re
import sys

from rvfem._files import regenerate_document
from rvfem.case.definition import table_class
from rvfem.case.schema import markdown_table

__all__ = ["render_case_format", "main"]


_BLOCK = re.compile(r"(<!-- schema: (?P<table>[\w.\[\]]*) -->\n)(?P<body>.*?)(<!-- /schema -->)", re.S)


def render_case_format(text: str) -> str:
    """``text`` (the case-format document) with every block between ``<!-- schema: TABLE -->`` and
    ``<!-- /schema -->`` replaced by the generated table of that table ("" for the top level)."""
    def block(match: re.Match) -> str:
        cls = table_class(match.group("table"))
        return f"{match.group(1)}{markdown_table(cls)}\n{match.group(4)}"

    return _BLOCK.sub(block, text)


def main(argv: list[str] | None = None) -> int:
    """``python -m rvfem.case.format_doc [--check] DOC``: regenerate (or check) the tables of DOC."""
    return regenerate_document("rvfem.case.format_doc", "tables", render_case_format, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
