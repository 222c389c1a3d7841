"""The screen text of the command line: the tables ``rvfem run`` and ``rvfem rigid`` print, from
their summaries (:func:`rvfem.outputs.summary.build_summary`, :func:`rvfem.outputs.summary.rigid_summary`).
Each result section gives its own lines (:attr:`rvfem.results.section.Section.screen`, most of them
in :mod:`rvfem.results.screen_lines`); :func:`summary_text` puts them in the sections' ``screen_rank``
order."""

from __future__ import annotations

import math

from rvfem.results import registry
from rvfem.results.bearing_checks import bearing_check_lines
from rvfem.results.screen_lines import (
    life,
    num,
    reference_lines,
    sig,
    stress_lines,
    warning_lines,
)

from rvfem.units import nm_from_nmm

__all__ = ["summary_text", "stage_time_lines", "rigid_text", "warning_lines", "reference_lines", "stress_lines"]


def summary_text(summary: dict, stages=None) -> str:
    """One screen of text with the key numbers of a ``summary.json`` (what ``rvfem run`` prints):
    every result section's lines in ``screen_rank`` order; with ``stages`` (the names of the run's
    stages, :data:`rvfem.app.run.STAGES`) also where the wall time went (:func:`stage_time_lines`),
    after the wall-time line of the ``files`` section."""

    lines: list[str] = []
    for section in sorted((s for s in registry.sections() if s.screen is not None), key=lambda s: s.screen_rank):
        assert section.screen is not None
        lines += section.screen(summary)
        if section.name == "files":
            lines += stage_time_lines(summary["timings_s"], stages)
    return "\n".join(lines)


def stage_time_lines(timings: dict, stages=None, shown: int = 8) -> list[str]:
    """Where the wall time went: ``total = Σ stages + other`` (``timings_s`` of a run,
    :func:`rvfem.app.run.outside_stages`), the ``shown`` longest of ``stages`` (names) by name,
    the rest summed; nothing without ``stages`` or for timings without ``other`` (a summary of
    an earlier version)."""
    if stages is None or "other" not in timings:
        return []
    spans = sorted(((float(timings[k]), k) for k in stages if k in timings), reverse=True)
    parts = [f"{name} {seconds:.1f}" for seconds, name in spans[:shown]]
    rest = spans[shown:]
    if rest:
        parts.append(f"{len(rest)} shorter stages {sum(sec for sec, _ in rest):.1f}")
    parts.append(f"between the stages {timings['other']:.1f}")
    return [f"  time {timings['total']:.1f} s = " + " + ".join(parts) + " s"]



def rigid_text(report: dict) -> str:
    """The rigid handbook evaluation (a :func:`rigid_summary` dict) as a table (``rvfem rigid``)."""

    p = report["equivalent_load_exponent"]
    p_text = "10/3" if math.isclose(p, 10.0 / 3.0) else f"{p:g}"
    defined = report["references"]["handbook"]["defined"]
    lines = [
        f"Case {report['case']} ({report['source']}): {report['model']}",
        f"  output torque {report['output_torque_Nm']:g} N·m, disc torque {nm_from_nmm(report['disc_torque_Nmm']):g} N·m, "
        f"output speed {report['output_speed_rpm']:g} rpm, bearing speed {report['bearing_speed_rpm']:g} rpm",
        f"  k = {report['k']:.4f}, k_y = {num(report['k_y'], '.4f')}, ΣPx = {sig(report['sum_px_N'], '.1f')} N, "
        f"ΣPy = {sig(report['sum_py_N'], '.1f')} N, crank-angle step {report['angle_step_deg']:g}°",
        f"  dynamic load rating C = {report['dynamic_load_rating_N']:.1f} N; equivalent load exponent p = {p_text}",
    ]
    if report.get("overrides"):
        lines.append(f"  overrides: {', '.join(report['overrides'])}")
    if not defined:
        lines += reference_lines(report["references"])
    header = (f"{'bearing':>7} {'max N':>9} {'at °':>6} {'min N':>9} {'at °':>6} {'F_m N':>9} "
              f"{'L10h h':>9} {'Q_max N':>8} {'p_in MPa':>9} {'p_out MPa':>9} {'κ':>5} {'a_ISO':>5} "
              f"{'L_nm h':>9} {'L10r h':>9}")
    lines += ["", header, "-" * len(header)]
    for b in report["bearings"]:
        if b["max_load_N"] is None and not defined:
            lines.append(f"{b['bearing']:>7d}  not defined for Zp − Zc ≠ 1 (rvfem run compares the FE with the "
                         "equal share)")
            continue
        lines.append(
            f"{b['bearing']:>7d} {sig(b['max_load_N'], '9.1f')} {b['max_at_deg']:6.1f} {sig(b['min_load_N'], '9.1f')} "
            f"{b['min_at_deg']:6.1f} {sig(b['equivalent_load_N'], '9.1f')} {life(b['L10h_h'], 9)} "
            f"{sig(b['max_roller_load_N'], '8.1f')} {sig(b['hertz_inner']['peak_pressure_MPa'], '9.1f')} "
            f"{sig(b['hertz_outer']['peak_pressure_MPa'], '9.1f')}"
            + (f" {num(d['kappa'], '5.2f')} {num(d['a_iso'], '5.2f')} {life(d['L_nm_h'], 9)} {life(d['L10r_h'], 9)}"
               if (d := b.get("depth")) else ""))
    lines += [
        "",
        "  at °: crank angle θ of the eccentric relative to the carrier; F_m = (mean F^p)^(1/p) over a turn",
        f"  L10h = 1e6/(60·n_b)·(C/F_m)^(10/3); Q_max: the most loaded roller, rigid rings with the rollers at "
        f"their cage positions (= {report['stribeck_factor']:.2f}·F_max/Z), Hertz at it (p_in: eccentric, p_out: "
        "disc bore); κ, a_ISO, L_nm = a_ISO·L10h (ISO 281), L10r the lamina life (ISO/TS 16281)",
    ]
    lines += bearing_check_lines(report.get("bearing_checks"))
    duty = report.get("duty_cycle")
    if "duty_cycle" in report and duty is None:
        lines.append("  duty cycle: service life not defined (no handbook bearing lives for Zp − Zc ≠ 1)")
    if duty:
        lines.append(
            f"  duty cycle: equivalent torque {duty['equivalent_torque_Nm']:.1f} N·m, equivalent speed "
            f"{duty['equivalent_speed_rpm']:.2f} rpm, service life {life(duty['service_life_h'])} h "
            f"(from the shortest rated life {life(duty['rated_life_h'])} h)")
    lines += warning_lines(report.get("warnings", []))
    return "\n".join(lines)

