"""Comparison of two result folders of :func:`rvfem.app.run.run_case` ("what do the holes cost?").

:func:`read_result` reads a folder's interface files — ``summary.json`` and
``bearing_loads.csv`` (schema: ``docs/outputs.md``) — and :func:`compare_results` puts two of
them side by side: per bearing the flexible maximum, minimum and equivalent load F_m and the
L10h life of A and B and their ratios B / A, plus the largest load, the handbook values and the
structural stress peaks (the headline P2 value and the P1 cycle's, both away from contacts). :func:`comparison_figure` overlays the load curves (a matplotlib ``Figure``;
:func:`comparison_plot` writes it as a PNG) and :func:`comparison_html`
writes a small self-contained page. ``rvfem compare A B`` is the command line for it.

Example::

    from rvfem.app.result_compare import read_result, compare_results
    c = compare_results(read_result("results/rv40e_solid"), read_result("results/rv40e_fanholes"))
    c["bearings"][0]["ratio"]["max_load_N"]      # fan holes / solid
"""

from __future__ import annotations

import csv
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from rvfem.app.run import run_case
from rvfem.case.definition import Case, load_case
from rvfem.errors import OutputError
from rvfem.outputs.figures import new_figure, save_figure
from rvfem.outputs.report import png_data_uri, template_environment

__all__ = ["ResultFolder", "STATISTICS", "read_result", "result_from_case", "compare_results",
           "overall_titles", "comparison_figure", "comparison_plot", "comparison_html", "headline"]

STATISTICS = (("max_load_N", "max N"), ("min_load_N", "min N"), ("equivalent_load_N", "F_m N"), ("L10h_h", "L10h h"))
"""Per-bearing statistics compared (summary.json key of ``bearings[].flexible``, column title)."""


@dataclass(frozen=True)
class ResultFolder:
    """The interface numbers of one result folder.

    Attributes
    ----------
    path : Path
    label : str
        Name shown in tables and plots (the case name).
    summary : dict
        Content of ``summary.json``.
    theta_deg : ndarray, shape (n,)
        Crank angles of ``bearing_loads.csv``, degrees.
    flexible_N, rigid_N : ndarray, shape (n, bearings)
        |F| of every bearing over θ, FE and handbook, N.
    """

    path: Path
    label: str
    summary: dict
    theta_deg: np.ndarray
    flexible_N: np.ndarray
    rigid_N: np.ndarray


def read_result(folder: str | os.PathLike) -> ResultFolder:
    """Read ``summary.json`` and ``bearing_loads.csv`` of a result folder.

    Raises
    ------
    OutputError
        The folder or one of the two files is missing or unreadable (one line naming the file).
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise OutputError(f"{folder}: not a result folder (expected a folder written by rvfem run, or a case file)")
    path = folder / "summary.json"
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
        n = len(summary["bearings"])
    except OSError as exc:
        raise OutputError(f"{path}: cannot read it ({exc.strerror or exc}); is {folder} a result folder?") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise OutputError(f"{path}: not a summary.json of rvfem run ({exc})") from None
    path = folder / "bearing_loads.csv"
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
        theta = np.array([float(r["theta_deg"]) for r in rows])
        flex = np.array([[float(r[f"bearing{i + 1}_flexible_F_N"]) for i in range(n)] for r in rows])
        rigid = np.array([[float(r[f"bearing{i + 1}_rigid_F_N"]) for i in range(n)] for r in rows])
    except OSError as exc:
        raise OutputError(f"{path}: cannot read it ({exc.strerror or exc})") from None
    except (ValueError, KeyError) as exc:
        raise OutputError(f"{path}: not a bearing_loads.csv of rvfem run (column {exc})") from None
    label = str(summary.get("case", {}).get("name") or folder.name)
    return ResultFolder(folder, label, summary, theta, flex.reshape(len(rows), n), rigid.reshape(len(rows), n))


def result_from_case(case, out_dir: str | os.PathLike, *, overrides: Sequence[str] = (),
                     cache_dir: str | os.PathLike = "meshes") -> ResultFolder:
    """Run a case (a :class:`~rvfem.case.definition.Case`, or a case file read with ``overrides``; images
    off) into ``out_dir`` and read the result back."""

    if not isinstance(case, Case):
        case = load_case(case, tuple(overrides))
    run_case(case, out_dir, images=False, overwrite=True, cache_dir=cache_dir)
    return read_result(out_dir)


def _ratio(b: float | None, a: float | None) -> float | None:
    if a is None or b is None or not a or not (math.isfinite(a) and math.isfinite(b)):
        return None
    return b / a


def _overall(r: ResultFolder) -> dict:
    s = r.summary
    flex = [b["flexible"] for b in s["bearings"]]
    rigid = [b["rigid"] for b in s["bearings"] if b.get("rigid")]   # none for Zp − Zc ≠ 1
    away = (s.get("stress") or {}).get("away_from_contacts") or {}
    return {
        "max_load_N": max(f["max_load_N"] for f in flex),
        "equivalent_load_N": max(f["equivalent_load_N"] for f in flex),
        "L10h_h": min(f["L10h_h"] for f in flex),
        "handbook_max_load_N": max((f["max_load_N"] for f in rigid), default=None),
        "handbook_equivalent_load_N": max((f["equivalent_load_N"] for f in rigid), default=None),
        "peak_von_mises_MPa": s.get("peak_von_mises_MPa"),
        "peak_away_from_contacts_MPa": away.get("peak_von_mises_MPa"),
        "disc_mass_kg": s.get("disc_mass_kg"),
        "disc_polar_inertia_kg_mm2": s.get("disc_polar_inertia_kg_mm2"),
        "static_safety_factor": s.get("static_safety_factor"),
        "fatigue_safety_factor": s.get("fatigue_safety_factor"),
        "L10r_h": _shortest_lamina_life(s),
    }


def _shortest_lamina_life(summary: dict) -> float | None:
    """The shortest flexible ISO/TS 16281 lamina life L10r of the crank bearings, h (None for a
    result without the crank bearing in depth)."""
    depth = summary.get("crank_bearing_depth") or {}
    lives = [b["flexible"]["L10r_h"] for b in depth.get("bearings", ()) if (b.get("flexible") or {}).get("L10r_h")]
    return min(lives, default=None)


def _describe(r: ResultFolder) -> dict:
    model = r.summary.get("model", {})
    stress = r.summary.get("stress") or {}
    recovered = stress.get("structural_peak") or {}
    away = stress.get("away_from_contacts") or {}
    cycle_order = away.get("element_order", model.get("element_order"))
    return {"label": r.label, "path": str(r.path), "case_digest": r.summary.get("case", {}).get("digest"),
            "bearing_model": model.get("bearing_model"), "pin_model": model.get("pin_model"),
            "element_order": model.get("element_order"), "angle_step_deg": model.get("angle_step_deg"),
            "output_torque_Nm": model.get("output_torque_Nm"),
            "peak_element_order": recovered.get("element_order", cycle_order),
            "cycle_element_order": cycle_order}


def _orders(a: dict, b: dict, key: str) -> str:
    orders = [a.get(key), b.get(key)]
    if None in orders:
        return "P?"
    return f"P{orders[0]}" if orders[0] == orders[1] else f"P{orders[0]} (A) / P{orders[1]} (B)"


def overall_titles(comparison: dict) -> dict:
    """Titles of the whole-disc quantities of a :func:`compare_results` result (key → title).

    Both stress peaks are structural peaks away from the contacts: ``peak_von_mises_MPa`` is the
    headline value of ``rvfem run`` (re-solved on P2 by default), ``peak_away_from_contacts_MPa``
    the peak of the load cycle's own stress envelope (P1 by default: lower at a hole
    fillet); the titles give the element order of each.
    """
    a, b = comparison["a"], comparison["b"]
    return {"max_load_N": "largest bearing load, N", "equivalent_load_N": "largest F_m, N",
            "L10h_h": "shortest L10h, h", "handbook_max_load_N": "handbook max load, N",
            "handbook_equivalent_load_N": "handbook F_m, N",
            "peak_von_mises_MPa": f"structural peak ({_orders(a, b, 'peak_element_order')}, away from contacts), MPa",
            "peak_away_from_contacts_MPa":
                f"structural peak, {_orders(a, b, 'cycle_element_order')} cycle (away from contacts), MPa",
            "disc_mass_kg": "disc mass, kg", "disc_polar_inertia_kg_mm2": "disc polar inertia, kg·mm²",
            "static_safety_factor": "static safety factor (yield)", "fatigue_safety_factor": "fatigue safety factor",
            "L10r_h": "shortest L10r (ISO/TS 16281 lamina life), h"}


def headline(comparison: dict) -> str | None:
    """The line a comparison leads with: "mass −x %, inertia −y %" (where both results have them),
    then the largest load, the equivalent load, the L10h ratio and the L10r ratio (where both
    results have the crank bearing in depth), B against A."""
    r = comparison["overall"]["ratio"]
    parts = [f"{name} {100 * (r[key] - 1):+.1f} %".replace("+-", "−").replace("-", "−")
             for key, name in (("disc_mass_kg", "mass"), ("disc_polar_inertia_kg_mm2", "inertia"))
             if r.get(key) is not None]
    if r["max_load_N"] is not None and r["equivalent_load_N"] is not None and r["L10h_h"] is not None:
        parts += [f"largest load {100 * (r['max_load_N'] - 1):+.1f} %",
                  f"equivalent load {100 * (r['equivalent_load_N'] - 1):+.1f} %", f"L10h × {r['L10h_h']:.2f}"]
    if r.get("L10r_h") is not None:
        parts.append(f"L10r × {r['L10r_h']:.2f}")
    return ("B against A: " + ", ".join(parts)) if parts else None


def compare_results(a: ResultFolder, b: ResultFolder) -> dict:
    """Side-by-side numbers of two results and the ratios B / A (JSON-ready).

    Returns
    -------
    dict
        ``a``, ``b``: what was compared (label, path, models, step, torque); ``bearings``: per
        bearing ``a`` and ``b`` (max, min, F_m, L10h of the flexible model) and ``ratio`` (B / A);
        ``overall``: the same for the largest load, the largest F_m, the shortest L10h, the handbook
        values and the von Mises peaks; ``life_ratio_from_load``: (F_m,A / F_m,B)^(10/3) of the
        largest F_m, which ``overall.ratio.L10h_h`` should match; ``warnings``: differences in the
        model settings that make the ratio more than the design change.
    """
    n = min(len(a.summary["bearings"]), len(b.summary["bearings"]))
    bearings = []
    for i in range(n):
        fa, fb = a.summary["bearings"][i]["flexible"], b.summary["bearings"][i]["flexible"]
        va = {key: fa.get(key) for key, _ in STATISTICS}
        vb = {key: fb.get(key) for key, _ in STATISTICS}
        bearings.append({"bearing": i + 1, "a": va, "b": vb, "ratio": {k: _ratio(vb[k], va[k]) for k in va}})
    oa, ob = _overall(a), _overall(b)
    warnings = []
    da, db = _describe(a), _describe(b)
    for key in ("bearing_model", "pin_model", "element_order", "angle_step_deg", "output_torque_Nm"):
        if da[key] != db[key]:
            warnings.append(f"{key} differs: {da[key]} (A) vs {db[key]} (B)")
    if len(a.summary["bearings"]) != len(b.summary["bearings"]):
        warnings.append("the numbers of bearings differ; the first "
                        f"{n} are compared")
    exponent = 10.0 / 3.0
    return {
        "a": da,
        "b": db,
        "ratio_is": "B / A",
        "bearings": bearings,
        "overall": {"a": oa, "b": ob, "ratio": {k: _ratio(ob[k], oa[k]) for k in oa}},
        "life_ratio_from_load": (oa["equivalent_load_N"] / ob["equivalent_load_N"]) ** exponent,
        "warnings": warnings,
    }


def comparison_figure(a: ResultFolder, b: ResultFolder):
    """The load curves of A and B as a :class:`matplotlib.figure.Figure`: |F| over θ of every
    bearing, A solid, B dashed, the handbook dotted.

    The figure is drawn without :mod:`matplotlib.pyplot` (an Agg canvas), so the caller's backend
    is left alone; in a notebook, display it with ``display(fig)`` or as a cell's last value.
    """
    from matplotlib import (
        rcParams,  # drawing only: matplotlib is a heavy import the solver never needs
    )

    fig = new_figure((8, 5.5))
    ax = fig.subplots()
    colours = rcParams["axes.prop_cycle"].by_key()["color"]
    for i in range(a.flexible_N.shape[1]):
        ax.plot(a.theta_deg, a.flexible_N[:, i], "-", color=colours[i % len(colours)], lw=1.2,
                label=f"A {a.label}, bearing {i + 1}")
    for i in range(b.flexible_N.shape[1]):
        ax.plot(b.theta_deg, b.flexible_N[:, i], "--", color=colours[i % len(colours)], lw=1.6,
                label=f"B {b.label}, bearing {i + 1}")
    ax.plot(a.theta_deg, a.rigid_N[:, 0], ":", color="k", lw=1, label="A handbook, bearing 1")
    if not np.array_equal(a.rigid_N[:, 0], b.rigid_N[:, 0]) or a.theta_deg.shape != b.theta_deg.shape:
        ax.plot(b.theta_deg, b.rigid_N[:, 0], ":", color="0.5", lw=1, label="B handbook, bearing 1")
    ax.set_xlabel("crank angle θ, degrees")
    ax.set_ylabel("crank-bearing load |F|, N")
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 60))
    ax.grid(alpha=0.3)
    ax.set_title(f"A = {a.label} (solid lines) vs B = {b.label} (dashed)", fontsize=10)
    ax.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.14), frameon=False)
    fig.tight_layout()
    return fig


def comparison_plot(a: ResultFolder, b: ResultFolder, path: str | os.PathLike) -> Path:
    """Write :func:`comparison_figure` as a PNG and return its path."""
    return save_figure(comparison_figure(a, b), path)


def _f(value, spec: str) -> str:
    return "–" if value is None else format(value, spec)


COMPARE_TEMPLATE = "compare.html.j2"
"""The comparison page's template, in the templates of :mod:`rvfem.outputs`."""


def comparison_context(comparison: dict, plot: str | os.PathLike | None) -> dict:
    """The context of ``compare.html.j2`` for a :func:`compare_results` result: what was compared,
    the headline and notes, the bearing and whole-disc tables with their numbers formatted ("–"
    where missing), the load curves as a data URI."""
    a, b = comparison["a"], comparison["b"]
    o = comparison["overall"]
    titles = overall_titles(comparison)

    def spec(key: str) -> str:
        return ".4g" if key in ("disc_mass_kg", "static_safety_factor", "fatigue_safety_factor") else ".1f"

    return {
        "a": {**a, "bearing_model": str(a["bearing_model"])}, "b": {**b, "bearing_model": str(b["bearing_model"])},
        "headline": headline(comparison), "warnings": comparison["warnings"],
        "statistics": [t for _, t in STATISTICS],
        "bearings": [{"bearing": row["bearing"],
                      "cells": [c for k, _ in STATISTICS for c in (_f(row["a"][k], ".1f"), _f(row["b"][k], ".1f"),
                                                                   _f(row["ratio"][k], ".4f"))]}
                     for row in comparison["bearings"]],
        "overall": [{"title": titles.get(key, key),
                     "cells": [_f(o["a"][key], spec(key)), _f(o["b"][key], spec(key)), _f(o["ratio"][key], ".4f")]}
                    for key in o["a"]],
        "plot": png_data_uri(plot) if plot is not None else None,
    }


def comparison_html(comparison: dict, plot: str | os.PathLike | None, path: str | os.PathLike) -> Path:
    """A self-contained HTML page of a :func:`compare_results` result (plot embedded), rendered by
    ``compare.html.j2``."""
    page = template_environment().get_template(COMPARE_TEMPLATE).render(comparison_context(comparison, plot))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(page, encoding="utf-8")
    return path
