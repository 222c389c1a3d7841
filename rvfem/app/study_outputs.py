"""What a design study writes besides its variants' folders: ``study.csv`` (one row per variant),
``study.json`` (the study as run), the plots and ``report.html`` (rendered from the template
``study.html.j2`` of :mod:`rvfem.outputs`)."""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path
from typing import Any, Sequence

from rvfem.app.study_definition import _SAFE, Parameter, Study, _value_text
from rvfem.case.schema import toml_literal
from rvfem.outputs.csvfile import csv_text
from rvfem.outputs.figures import new_figure, save_figure
from rvfem.outputs.report import png_data_uri, template_environment
from rvfem.outputs.summary import result_folder

__all__ = ["study_rows", "read_study_csv", "study_figures", "study_table_columns", "STUDY_KEY_RESULTS",
           "study_csv_text", "study_dict", "write_plots", "report_context", "report_html"]

def _pct(value: float | None, ref: float | None) -> float | None:
    if value is None or ref is None or not ref:
        return None
    return 100.0 * (value - ref) / ref


def _ratio(value: float | None, ref: float | None) -> float | None:
    if value is None or ref is None or not ref:
        return None
    return value / ref


def _get(d: Any, *keys: str) -> Any:
    for k in keys:
        if not isinstance(d, dict):
            return None
        d = d.get(k)
    return d


def _depth_columns(s: Any) -> dict[str, Any]:
    """The crank bearing in depth of a variant (bearing model ``rollers``): the shortest flexible and
    rigid L10r, the largest flexible roller pressure, and where the lamina damage of the bearing of
    the shortest flexible L10r peaks (summary.json ``crank_bearing_depth``; None without it)."""
    bearings = _get(s, "crank_bearing_depth", "bearings") or []
    flex = [b["flexible"] for b in bearings if b.get("flexible")]
    rigid = [b["rigid"] for b in bearings if b.get("rigid")]
    worst: dict[str, Any] = min(flex, key=lambda f: f["L10r_h"], default={})
    return {
        "L10r_h": worst.get("L10r_h"),
        "handbook_L10r_h": min((f["L10r_h"] for f in rigid), default=None),
        "roller_peak_pressure_MPa": max((f["roller_peak_pressure_MPa"] for f in flex), default=None),
        "damage_raceway": worst.get("damage_raceway"),
        "damage_x_mm": worst.get("damage_x_mm"),
        "damage_peak_over_mean": worst.get("damage_peak_over_mean"),
        "damage_middle_share": worst.get("damage_middle_share"),
    }


def study_rows(study: Study, records: dict[str, dict]) -> list[dict]:
    """The rows of ``study.csv`` from the records of :func:`run_variant` (keyed by variant id).

    Per variant: the parameters, status, and from its ``summary.json`` the flexible max / min /
    F_m / L10h of every bearing, the handbook (rigid) values, deltas in % against the handbook
    and against the base variant, life ratios, the largest load and the stress peaks; the shortest
    L10r and where its lamina damage peaks (:func:`_depth_columns`).
    """
    base_summary = (records.get("base") or {}).get("summary")
    n_bearings = max((len(r["summary"]["bearings"]) for r in records.values() if r.get("summary")), default=0)
    rows = []
    for v in study.variants:
        r = records.get(v.id, {})
        s = r.get("summary")
        settings = dict(v.settings)
        row: dict[str, Any] = {"id": v.id, "role": v.role,
                               "varied": ",".join(k for k, _ in v.settings)}
        for p in study.parameters:
            row[p.key] = settings.get(p.key, p.base_value)
        row.update(status=r.get("status", "not run"), computed=r.get("computed", False),
                   same_as=r.get("same_as", ""), error=r.get("error", ""),
                   wall_time_s=r.get("wall_time_s"), digest=v.digest,
                   overrides=";".join(f"{k}={toml_literal(val)}" for k, val in v.settings))
        bearings = s["bearings"] if s else []
        base_bearings = base_summary["bearings"] if base_summary else []
        flex = [b["flexible"] for b in bearings]
        rigid = [b["rigid"] for b in bearings if b.get("rigid")]   # none where the handbook is not defined
        max_load = max((f["max_load_N"] for f in flex), default=None)
        fm = max((f["equivalent_load_N"] for f in flex), default=None)
        life = min((f["L10h_h"] for f in flex), default=None)
        rigid_max = max((f["max_load_N"] for f in rigid), default=None)
        rigid_fm = max((f["equivalent_load_N"] for f in rigid), default=None)
        rigid_life = min((f["L10h_h"] for f in rigid), default=None)
        b_flex = [b["flexible"] for b in base_bearings]
        base_max = max((f["max_load_N"] for f in b_flex), default=None)
        base_fm = max((f["equivalent_load_N"] for f in b_flex), default=None)
        base_life = min((f["L10h_h"] for f in b_flex), default=None)
        row.update({
            "max_load_N": max_load,
            "max_load_bearing": _get(s, "max_bearing_load", "bearing"),
            "equivalent_load_N": fm,
            "L10h_h": life,
            "handbook_max_load_N": rigid_max,
            "handbook_equivalent_load_N": rigid_fm,
            "handbook_L10h_h": rigid_life,
            "max_vs_handbook_percent": _pct(max_load, rigid_max),
            "equivalent_vs_handbook_percent": _pct(fm, rigid_fm),
            "life_ratio": _ratio(life, rigid_life),
            "max_vs_base_percent": _pct(max_load, base_max),
            "equivalent_vs_base_percent": _pct(fm, base_fm),
            "life_ratio_vs_base": _ratio(life, base_life),
            "peak_von_mises_MPa": _get(s, "peak_von_mises_MPa"),
            "peak_away_from_contacts_MPa": _get(s, "stress", "away_from_contacts", "peak_von_mises_MPa"),
            "peak_vs_base_percent": _pct(_get(s, "peak_von_mises_MPa"), _get(base_summary, "peak_von_mises_MPa")),
            "disc_mass_kg": _get(s, "disc_mass_kg"),
            "disc_polar_inertia_kg_mm2": _get(s, "disc_polar_inertia_kg_mm2"),
            "mass_vs_base_percent": _pct(_get(s, "disc_mass_kg"), _get(base_summary, "disc_mass_kg")),
            "static_safety_factor": _get(s, "static_safety_factor"),
            "fatigue_safety_factor": _get(s, "fatigue_safety_factor"),
            **_depth_columns(s),
        })
        for i in range(n_bearings):
            pre = f"bearing{i + 1}_"
            b = bearings[i] if i < len(bearings) else None
            bb = base_bearings[i] if i < len(base_bearings) else None
            f, g = (b or {}).get("flexible", {}), (b or {}).get("rigid") or {}
            vs_handbook = bool(g)   # the deltas are against the equal share where there is no handbook
            fb = (bb or {}).get("flexible", {})
            row.update({
                pre + "max_N": f.get("max_load_N"), pre + "min_N": f.get("min_load_N"),
                pre + "Fm_N": f.get("equivalent_load_N"), pre + "L10h_h": f.get("L10h_h"),
                pre + "handbook_max_N": g.get("max_load_N"), pre + "handbook_Fm_N": g.get("equivalent_load_N"),
                pre + "max_vs_handbook_percent": (b or {}).get("delta_max_percent") if vs_handbook else None,
                pre + "Fm_vs_handbook_percent": (b or {}).get("delta_equivalent_percent") if vs_handbook else None,
                pre + "life_ratio": (b or {}).get("life_ratio") if vs_handbook else None,
                pre + "max_vs_base_percent": _pct(f.get("max_load_N"), fb.get("max_load_N")),
                pre + "Fm_vs_base_percent": _pct(f.get("equivalent_load_N"), fb.get("equivalent_load_N")),
            })
        rows.append(row)
    return rows


def study_csv_text(rows: list[dict]) -> str:
    """The text of ``study.csv``: one column per key of the rows (in order of appearance), cells by
    :func:`rvfem.outputs.csvfile.format_cell` (NaN as an empty cell)."""
    if not rows:
        return ""
    columns: list[str] = []
    for row in rows:
        columns.extend(k for k in row if k not in columns)
    return csv_text(columns, ([row.get(c) for c in columns] for row in rows), nan_as_empty=True)


def read_study_csv(path: str | os.PathLike) -> list[dict]:
    """Read ``study.csv`` back: numbers as floats (bit-identical to what was written), empty
    cells as None, other cells as strings."""
    rows = []
    with open(path, newline="", encoding="utf-8") as f:
        for raw in csv.DictReader(f):
            row: dict[str, float | str | None] = {}
            for k, text in raw.items():
                if text == "":
                    row[k] = None
                    continue
                try:
                    row[k] = float(text)
                except ValueError:
                    row[k] = text
            rows.append(row)
    return rows


def study_dict(study: Study) -> dict:
    return {
        "name": study.name, "description": study.description,
        "study_file": str(study.path) if study.path else None, "base_case": str(study.base_case),
        "kind": study.kind, "overrides": list(study.overrides),
        "parameters": [{"key": p.key, "values": list(p.values), "base_value": p.base_value, "label": p.label}
                       for p in study.parameters],
        "variants": [{"id": v.id, "role": v.role, "settings": {k: val for k, val in v.settings},
                      "overrides": list(v.overrides), "digest": v.digest} for v in study.variants],
    }


# --------------------------------------------------------------------------------------------
# Plots and report
# --------------------------------------------------------------------------------------------


def _numeric(values: Sequence[Any]) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def _response_figure(study: Study, p: Parameter, ok: Sequence[dict]):
    """Grid: the largest bearing load against parameter ``p``, one curve per combination of the
    other parameters, the handbook dotted."""
    others = [q for q in study.parameters if q is not p]
    fig = new_figure((6.4, 4.2))
    ax = fig.subplots()
    groups: dict[tuple, list[dict]] = {}
    for r in ok:
        if r["role"] == "grid":
            groups.setdefault(tuple(r[q.key] for q in others), []).append(r)
    numeric = _numeric(p.values)
    positions = {v: i for i, v in enumerate(p.values)}
    for combo, members in sorted(groups.items(), key=lambda kv: repr(kv[0])):
        members.sort(key=lambda r: positions.get(r[p.key], 0))
        x = [r[p.key] if numeric else positions[r[p.key]] for r in members]
        label = ", ".join(f"{q.label} = {_value_text(c)}" for q, c in zip(others, combo)) or "flexible"
        line, = ax.plot(x, [r["max_load_N"] for r in members], "o-", label=label)
        ax.plot(x, [r["handbook_max_load_N"] for r in members], ":", color=line.get_color(), lw=1)
    if not numeric:
        ax.set_xticks(range(len(p.values)), [str(v) for v in p.values])
    ax.set_xlabel(p.label)
    ax.set_ylabel("largest crank-bearing load, N")
    ax.set_title(f"{study.name}: largest bearing load vs {p.label}\n(dotted: rigid handbook)", fontsize=10)
    ax.grid(alpha=0.3)
    if len(groups) <= 8:
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def _tornado_bars(study: Study, ok: Sequence[dict], base: dict) -> list[tuple]:
    """Per parameter ``(span, parameter, [load % low, high], [L10h %], [stress peak %], [mass %])``, smallest span
    first (a side equal to the base value is the base itself)."""
    bars = []
    for p in study.parameters:
        lo, hi = (base if p.values[i] == p.base_value else
                  next((r for r in ok if r["role"] == role and r["varied"] == p.key), None)
                  for i, role in enumerate(("low", "high")))
        d = [r["max_vs_base_percent"] if r else float("nan") for r in (lo, hi)]
        life = [100.0 * (r["life_ratio_vs_base"] - 1.0) if r and r["life_ratio_vs_base"] else float("nan")
                for r in (lo, hi)]
        stress, mass = ([r.get(key) if r and r.get(key) is not None else float("nan") for r in (lo, hi)]
                        for key in ("peak_vs_base_percent", "mass_vs_base_percent"))
        span = max((abs(x) for x in d if not math.isnan(x)), default=0.0)
        bars.append((span, p, d, life, stress, mass))
    bars.sort(key=lambda b: b[0])
    return bars


def _tornado_figure(study: Study, ok: Sequence[dict], base: dict):
    """Sensitivity: change of the largest load, of L10h, of the structural stress peak and of the
    disc mass against the base, per parameter."""
    bars = _tornado_bars(study, ok, base)
    fig = new_figure((16, 1.2 + 0.55 * len(bars)))
    axes = fig.subplots(nrows=1, ncols=4, sharey=True)
    y = range(len(bars))
    for ax, idx, title in ((axes[0], 2, "largest bearing load vs base, %"),
                           (axes[1], 3, "L10h vs base, %"),
                           (axes[2], 4, "structural stress peak vs base, %"),
                           (axes[3], 5, "disc mass vs base, %")):
        for yi, bar in zip(y, bars):
            lo, hi = bar[idx]
            ax.barh(yi, lo, color="tab:blue", height=0.6, label="low" if yi == 0 else None)
            ax.barh(yi, hi, color="tab:red", height=0.6, alpha=0.8, label="high" if yi == 0 else None)
        ax.axvline(0.0, color="k", lw=0.8)
        ax.set_xlabel(title)
        ax.grid(axis="x", alpha=0.3)
    axes[0].set_yticks(list(y), [f"{b[1].label}\n{_value_text(b[1].values[0])} / {_value_text(b[1].values[1])}"
                                 for b in bars], fontsize=8)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"{study.name}: one-at-a-time sensitivity around the base "
                 f"(largest load {base['max_load_N']:.0f} N)", fontsize=10)
    fig.tight_layout()
    return fig


def _variants_figure(study: Study, rows: Sequence[dict]):
    """Every variant: flexible largest load and F_m as bars, the handbook maximum as a tick."""
    fig = new_figure((max(6.4, 0.45 * len(rows) + 2) + 1.8, 4.2))   # + the legend's column
    ax = fig.subplots()
    x = range(len(rows))
    ax.bar([i - 0.2 for i in x], [r["max_load_N"] or 0.0 for r in rows], width=0.4, label="flexible, largest load")
    ax.bar([i + 0.2 for i in x], [r["equivalent_load_N"] or 0.0 for r in rows], width=0.4, label="flexible, F_m")
    ax.plot(list(x), [r["handbook_max_load_N"] or float("nan") for r in rows], "k_", ms=14, label="handbook max")
    ax.set_xticks(list(x), [r["id"] for r in rows], rotation=60, ha="right", fontsize=7)
    ax.set_ylabel("crank-bearing load, N")
    ax.set_title(f"{study.name}: all variants", fontsize=10)
    # right of the axes: inside it would hide bars
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    return fig


def study_figures(study: Study, rows: Sequence[dict]) -> dict:
    """The plots of a study as :class:`matplotlib.figure.Figure` objects, by name.

    ``"response_<key>"`` per parameter (grid), ``"tornado"`` (sensitivity, when the base is ok) and
    ``"variants"`` (always, once a variant is ok); empty if no variant is ok. ``rows`` are the rows
    of ``study.csv`` (:attr:`StudyResult.rows` or :func:`read_study_csv`). The figures are drawn
    without :mod:`matplotlib.pyplot`, so the caller's backend is left alone; in a notebook, show
    one with ``display(fig)`` or as a cell's last value.
    """
    ok = [r for r in rows if r["status"] == "ok"]
    figures: dict[str, Any] = {}
    if not ok:
        return figures
    if study.kind == "grid":
        for p in study.parameters:
            figures[f"response_{p.key}"] = _response_figure(study, p, ok)
    elif study.kind == "sensitivity":
        base = {r["id"]: r for r in rows}.get("base")
        if base and base["status"] == "ok":
            figures["tornado"] = _tornado_figure(study, ok, base)
    figures["variants"] = _variants_figure(study, rows)
    return figures


def _plot_file_name(name: str) -> str:
    return f"{_SAFE.sub('_', name)}.png"


def write_plots(study: Study, rows: list[dict], folder: Path) -> dict:
    """Write :func:`study_figures` into ``folder`` as PNG files; name → path.

    The folder is written as a whole through :func:`rvfem.outputs.summary.result_folder`: it holds the
    plots of one run, and an interrupted run leaves the earlier plots as they were.
    """
    files: dict[str, Path] = {}
    with result_folder(folder, overwrite=True, what="study plots") as tmp:
        for name, fig in study_figures(study, rows).items():
            save_figure(fig, tmp / _plot_file_name(name))
            files[name] = folder / _plot_file_name(name)
    return files


def _fmt(value: Any, spec: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return format(value, spec)
    return str(value)


STUDY_KEY_RESULTS = ("max_load_N", "max_vs_base_percent", "L10h_h", "life_ratio_vs_base", "peak_von_mises_MPa")
"""The columns of the study report's table right after the id and the status: what a variant gives."""


def study_table_columns(study: Study) -> list[tuple[str, str, str]]:
    """The columns of the study report's table, (key, CSS class, format): the id and the status,
    the key results (:data:`STUDY_KEY_RESULTS`), the other results, then the parameter values and
    the run's wall time and error, so that the results are on screen with many parameters."""
    results = [("max_load_N", "", ".1f"), ("max_vs_base_percent", "", "+.1f"), ("L10h_h", "", ".0f"),
               ("life_ratio_vs_base", "", ".3f"), ("peak_von_mises_MPa", "", ".1f"),
               ("handbook_max_load_N", "", ".1f"), ("max_vs_handbook_percent", "", "+.1f"),
               ("equivalent_load_N", "", ".1f"), ("equivalent_vs_base_percent", "", "+.1f"),
               ("life_ratio", "", ".3f")]
    return [("id", "l id", "s"), ("status", "l", "s"), *results, *[(p.key, "l", "s") for p in study.parameters],
            ("wall_time_s", "", ".1f"), ("error", "l", "s")]


STUDY_TEMPLATE = "study.html.j2"
"""The study report's template, in the templates of :mod:`rvfem.outputs`."""


def _cell_text(value: Any, spec: str) -> str:
    """A cell of the report's table: a number in ``spec`` ("–" if missing), a text (``spec`` "s")
    as :func:`~rvfem.app.study_definition._value_text` shows it."""
    if spec != "s":
        return _fmt(value, spec)
    return _value_text(value) if value is not None else ""


def report_context(study: Study, rows: Sequence[dict], plots: dict, wall_s: float, compute_s: float) -> dict:
    """The context of the template ``study.html.j2``: texts, the plots as data URIs and the table
    of :func:`study_table_columns` with its cells formatted."""
    cols = study_table_columns(study)
    return {
        "name": study.name, "description": study.description, "kind": study.kind,
        "base_case": study.base_case.name, "overrides": "; ".join(study.overrides),
        "variants": len(rows), "ok": sum(r["status"] == "ok" for r in rows),
        "earlier": sum(r["status"] == "ok" and not r["computed"] and not r["same_as"] for r in rows),
        "compute_s": f"{compute_s:.1f}", "wall_s": f"{wall_s:.1f}",
        "plots": [{"name": name, "src": png_data_uri(path)} for name, path in plots.items()],
        "columns": [{"name": n, "css": c} for n, c, _ in cols],
        "rows": [{"failed": r["status"] != "ok",
                  "cells": [{"css": c, "text": _cell_text(r.get(n), spec)} for n, c, spec in cols]} for r in rows],
    }


def report_html(study: Study, rows: Sequence[dict], plots: dict, wall_s: float, compute_s: float) -> str:
    """The study's ``report.html``: :func:`report_context` rendered by ``study.html.j2``.

    Parameters
    ----------
    study : Study
    rows : sequence of dict
        The rows of ``study.csv`` (:func:`study_rows`).
    plots : dict
        Plot name → PNG file (:func:`write_plots`), embedded in the page.
    wall_s, compute_s : float
        Wall time of the run and the variants' run times added up, seconds.
    """
    return template_environment().get_template(STUDY_TEMPLATE).render(
        report_context(study, rows, plots, wall_s, compute_s))
