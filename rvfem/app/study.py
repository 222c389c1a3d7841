"""Design studies: many variants of one case, each a full analysis, run on Dask distributed.

A **study file** (TOML) names a base case and how to vary it::

    name = "rv40e_ligament"
    base_case = "../cases/rv40e_fanholes.toml"   # relative to the study file
    kind = "grid"                                # "grid", "sensitivity" or "list"

    [overrides]                                  # applied to the base and to every variant
    "analysis.angle_step_deg" = 2.0

    [[parameter]]                                # grid: every combination of the values
    key = "fan_holes.ligament"
    values = [3.5, 4.5, 5.5]

    [[parameter]]                                # sensitivity: one at a time, low and high
    key = "loads.torque_Nm"                      # around the base (tornado chart)
    low = 300.0
    high = 500.0

    [[variant]]                                  # list: explicit variants
    id = "rigid-bore"
    set = { "crank_bearing.model" = "rigid_bore" }

Keys are the dotted keys of the case format (``docs/case-format.md``); a value may be a number or
a model choice (``crank_bearing.model``, ``pins.model``). :func:`load_study` validates the file and
every variant's case up front (through :func:`rvfem.case.definition.load_case`, so an unknown key gets a
"did you mean"), and always adds the base case itself as variant ``base``.

:func:`run_study` runs each variant as :func:`rvfem.app.run.run_case` (images off) on a Dask
cluster — a :class:`distributed.LocalCluster` with one single-threaded worker process per core
by default, or an existing scheduler by address — and writes::

    DIR/variants/<id>/      the variant's result folder (summary.json, CSV, VTK, plots, report)
    DIR/study.csv           one row per variant: parameters, loads, deltas, lives, stress, status
    DIR/study.json          the study as run: base case, overrides and digest of every variant
    DIR/plots/*.png         response curves (grid), tornado chart (sensitivity), bar chart (list)
    DIR/report.html         self-contained report

Where the results go: every worker writes its variant's result folder directly into
``DIR/variants/<id>/`` (atomically, by :func:`~rvfem.app.run.run_case`), so ``DIR`` must be on a
file system the workers share with the client — the usual set-up of a cluster (NFS, Lustre) and
trivially true on one machine. Only the small ``summary.json`` content travels back through
Dask (about 10 kB per variant); the VTK files and tables (megabytes) never pass through the
scheduler. The client checks that it sees each folder and says so if it does not.

Robustness: a variant that fails (bad geometry, contact not converging, worker lost) is recorded
with its message and the study goes on; a rerun skips every variant whose folder holds a
``summary.json`` of the same case digest (resume); Ctrl-C cancels the futures and leaves no
half-written variant folder (nor plots folder: both are written through
:func:`rvfem.outputs.summary.result_folder`); a lock file refuses a second study writing into the same
folder.

The study lives in three modules, imported here as one: the study file
(:mod:`rvfem.app.study_definition`), the run on Dask with its lock and resume
(:mod:`rvfem.app.study_run`), and what the study writes beside the variants' folders — study.csv,
study.json, the plots and the report (:mod:`rvfem.app.study_outputs`).
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
from rvfem.app.study_run import (
    BLAS_THREAD_VARIABLES,
    LOCK_NAME,
    ClusterError,
    ProgressCallback,
    SingleThreadedBlas,
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
