"""Files written in one step: a reader sees the old file or the new one, never half of either."""

from __future__ import annotations

import os
import uuid
from pathlib import Path

__all__ = ["write_text_atomic"]


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
