"""Files written in one step (a reader sees the old file or the new one, never half of either), and
the regeneration of the generated blocks of a document."""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
import uuid
from pathlib import Path

__all__ = ["regenerate_document", "write_text_atomic"]


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    """Replace the file ``path`` by ``text`` (UTF-8) in one step: a temporary file beside it, then
    :func:`os.replace` (atomic on POSIX and Windows); the temporary file is removed if anything
    fails. For single files among others (a study's ``study.json``, ``study.csv``,
    ``report.html``); whole result folders go through :func:`rvfem.outputs.summary.result_folder`.
    Returns the path."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex[:8]}.tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path


def regenerate_document(module: str, what: str, render: Callable[[str], str], argv: list[str] | None = None) -> int:
    """The ``main`` of ``python -m MODULE [--check] DOC``: regenerate in place (or only check) the
    generated blocks of a document, ``render(text) -> text``; prints one line, returns 0 (up to date
    or regenerated) or 1 (``--check`` and stale).

    Parameters
    ----------
    module : str
        The module run with ``python -m`` (named in the usage and the hint).
    what : str
        What the blocks are, for the messages (``"tables"``, ``"key table"``).
    render : callable
        The document's text → its text with the blocks regenerated.
    argv : list of str, optional
        The arguments (default: the process's).
    """
    parser = argparse.ArgumentParser(prog=f"python -m {module}",
                                     description=f"regenerate (or check) the generated {what} of a document")
    parser.add_argument("doc", help="the document, e.g. docs/outputs.md")
    parser.add_argument("--check", action="store_true", help=f"only report whether the {what} are stale")
    args = parser.parse_args(argv)
    path = Path(args.doc)
    text = path.read_text(encoding="utf-8")
    new = render(text)
    if new == text:
        print(f"{path}: up to date")
        return 0
    if args.check:
        print(f"{path}: stale; regenerate with: python -m {module} {path}")
        return 1
    path.write_text(new, encoding="utf-8")
    print(f"{path}: {what} regenerated")
    return 0

