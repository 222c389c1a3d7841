"""The reference tables of ``docs/case-format.md``, generated from the declarations of the case's
tables (:func:`rvfem.case.schema.markdown_table`).

``python -m rvfem.case.format_doc docs/case-format.md`` rewrites every block between
``<!-- schema: TABLE -->`` and ``<!-- /schema -->`` in place (``--check`` only reports whether they
are stale; a test fails when they are).
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

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
    parser = argparse.ArgumentParser(prog="python -m rvfem.case.format_doc", description=main.__doc__)
    parser.add_argument("doc", help="the case-format document, e.g. docs/case-format.md")
    parser.add_argument("--check", action="store_true", help="only report whether the tables are stale")
    args = parser.parse_args(argv)
    path = Path(args.doc)
    text = path.read_text(encoding="utf-8")
    new = render_case_format(text)
    if new == text:
        print(f"{path}: up to date")
        return 0
    if args.check:
        print(f"{path}: stale; regenerate with: python -m rvfem.case.format_doc {path}")
        return 1
    path.write_text(new, encoding="utf-8")
    print(f"{path}: tables regenerated")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
