"""What every ``rvfem`` subcommand is made of: its exit codes and the :class:`Subcommand` record
(:mod:`rvfem.app.cli` and :mod:`rvfem.app.cli_study` define the subcommands)."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from typing import Callable

__all__ = ["Subcommand", "EXIT_OK", "EXIT_INTERNAL_ERROR", "EXIT_USER_ERROR", "EXIT_INTERRUPTED",
           "EXIT_BROKEN_PIPE"]

EXIT_OK = 0
EXIT_INTERNAL_ERROR = 1
EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130
EXIT_BROKEN_PIPE = 141


@dataclass(frozen=True)
class Subcommand:
    """One ``rvfem`` subcommand: its name, one-line help, argument setup and action."""

    name: str
    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]
