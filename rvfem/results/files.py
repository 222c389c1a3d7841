"""What the result folder holds: the kept fields (VTU files and stress images), the images and plots,
the wall time per stage and every file. The names of those files are declared here, where the
summary lists them; the writers of :mod:`rvfem.outputs` use the same functions."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rvfem.results.format import angle

from rvfem.results import screen_lines
from rvfem.results.section import KeyRow, Section, SummaryContext

__all__ = ['SECTION', 'stress_image_name', 'summary', 'vtu_name']

def vtu_name(theta_deg: float) -> str:
    """File name of the field at crank angle θ (degrees): ``disc_theta_060.00.vtu``."""
    return f"disc_theta_{theta_deg % 360.0:06.2f}.vtu"


def stress_image_name(theta_deg: float) -> str:
    """File name of the stress image at crank angle θ (degrees): ``stress_theta_060.00.png``."""
    return f"stress_theta_{theta_deg % 360:06.2f}.png"


def _image_key(rel: str) -> str:
    return Path(rel).stem


def summary(a: Any, ctx: SummaryContext) -> dict[str, Any]:
    files = set(ctx.files)
    fields = []
    for snap in a.stress.snapshots:
        entry = {"theta_deg": angle(snap.theta_deg), "vtu": f"vtk/{vtu_name(snap.theta_deg)}"}
        image = f"images/{stress_image_name(snap.theta_deg)}"
        if image in files:
            entry["image"] = image
        fields.append(entry)
    return {
        "fields": sorted(fields, key=lambda f: f["theta_deg"]),
        "images": {_image_key(f): f for f in sorted(files) if f.startswith("images/") and f.endswith(".png")},
        "plots": {_image_key(f): f for f in sorted(files) if f.startswith("plots/") and f.endswith(".png")},
        "timings_s": dict(ctx.timings),
        "files": sorted(files),
    }


KEYS = (
    KeyRow('`fields[]`',
           'array',
           'one entry per kept angle'),
    KeyRow('`fields[].theta_deg`, `fields[].vtu`, `fields[].image`',
           'float, str, str',
           'crank angle, VTU path, stress image path (only if images were rendered)'),
    KeyRow('`images`, `plots`',
           'object',
           'name → path of every PNG'),
    KeyRow('`timings_s`',
           'object',
           "wall time per stage (`check`, `mesh`, `model`, `rigid`, `cycle`, `evaluation`, `stress`, `attribution`, `duty_cycle` (with a duty cycle), `accuracy`, `roller_slices` (bearing model `rollers`: the crank bearing in depth, slices of every roller, film and lives; `roller_depth` is the slice evaluation's own part of it), `tables`, `vtk`, `plots`, `images`, `report`), `model_*` set-up details, `cycle_per_angle`, `total`, and `other`: the stages are spans of the run's wall time one after the other, and `total` = their sum + `other` (the time between the stages: building the summary, the bearing checks, starting child processes). Work done beside a stage (below) counts only as the stage's wait for it: in `analyse()` the attribution is computed on a thread beside the stress stage (`attribution` is the wait for it after that stage, `attribution_compute` its own wall time); `rvfem run` with images computes it after the VTK files while the render worker draws; `check` includes the wait for the rendering check; with images, the mesh picture is drawn by a child process during the cycle, the stress images from the end of the `stress` section on and the plots from the end of the crank bearing in depth on, while the other sections are computed and the tables and VTK files written (`plots` and `images` are the waits for it, `drawing_background` the span from handing the stress images over to having every drawing, which the screen's wall-time line shows); the P2 model of the `stress` stage is built in another child process during the cycle"),
    KeyRow('`files`',
           'array',
           'every file of the folder, relative paths'),
)
"""Its rows of the key table (docs/outputs.md)."""

SECTION = Section("files", summary, KEYS,
                  screen=screen_lines.wall_time_lines, screen_rank=80)
