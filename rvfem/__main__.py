"""``python -m rvfem``: the ``rvfem`` command line (:func:`rvfem.app.cli.main`)."""

import sys

from rvfem.app.cli import main

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
