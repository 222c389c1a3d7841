"""Design studies: many variants of one case, each a full analysis, run on Dask distributed.

The public names of the three modules a study is made of, importable from here as one:

- :mod:`rvfem.app.study_definition`: the study file (a base case and how to vary it: a grid, a
  one-at-a-time sensitivity or a list of variants; its format there and in ``docs/studies.md``),
  read and checked up front by :func:`load_study`;
- :mod:`rvfem.app.study_run`: :func:`run_study`, each variant a :func:`rvfem.app.run.run_case` on a
  Dask cluster, the study folder locked, resumed and cleaned up;
- :mod:`rvfem.app.study_outputs`: what the study writes beside its variants' folders — study.csv
  (:func:`study_rows`, :func:`read_study_csv`), study.json, the plots (:func:`study_figures`) and
  report.html.
"""

from __future__ import annotations

from rvfem.app.study_definition import (
    MAX_ID_LENGTH,
    STUDY_KINDS,
    Parameter,
    Study,
    Variant,
    load_study,
    short_id,
)
from rvfem.app.study_outputs import (
    STUDY_KEY_RESULTS,
    read_study_csv,
    study_figures,
    study_rows,
    study_table_columns,
)
from rvfem.app import study_run as _study_run
from rvfem.app.study_run import (
    BLAS_THREAD_VARIABLES,
    LOCK_NAME,
    ClusterError,
    ProgressCallback,
    StudyResult,
    VariantTask,
    local_cluster,
    run_study,
    run_variant,
)
from rvfem.case.schema import toml_literal

__all__ = [
    "STUDY_KINDS",
    "MAX_ID_LENGTH",
    "LOCK_NAME",
    "BLAS_THREAD_VARIABLES",
    "STUDY_KEY_RESULTS",
    "ClusterError",
    "Parameter",
    "Variant",
    "Study",
    "VariantTask",
    "StudyResult",
    "ProgressCallback",
    "load_study",
    "short_id",
    "run_variant",
    "run_study",
    "local_cluster",
    "SingleThreadedBlas",
    "study_rows",
    "study_figures",
    "study_table_columns",
    "read_study_csv",
    "toml_literal",
]


def __getattr__(name: str):
    """``SingleThreadedBlas`` on first use (a Dask class: :func:`rvfem.app.study_run._plugin_class`)."""
    if name == "SingleThreadedBlas":
        return _study_run.SingleThreadedBlas
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
