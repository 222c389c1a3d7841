"""``python -m rvfem``: the ``rvfem`` command line (:func:`rvfem.cli.main`)."""

import sys

from .cli import main

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
