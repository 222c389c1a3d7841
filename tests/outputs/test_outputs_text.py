"""Numbers and values as users read them: screen tables (significant figures, lives), case values
in the report (TOML, not Python), warning lines."""

from __future__ import annotations

import math

import pytest

from rvfem.results.screen_lines import life as _life, sig as _sig, warning_lines
from rvfem.outputs.report import toml_text


@pytest.mark.parametrize("value, fmt, text", [
    (5576.9, "9.1f", "   5576.9"),          # as before: fixed point where it shows 4 figures
    (183000.4, "8.0f", "  183000"),
    (645.6, "8.0f", "   645.6"),            # a small load keeps 4 significant figures
    (0.0071134, "9.1f", " 0.007113"),       # 1e-3 N·m: not "0.0"
    (0.0, "8.0f", "       0"),
    (3.8133e8, "8.0f", "3.813e+08"),        # wider than the column: exponent form
    (None, "8.0f", "       –"),
    (107.08, ".0f", "107.1"),
    (332732.1, ".1f", "332732.1"),
])
def test_screen_numbers_keep_significant_figures(value, fmt, text):
    assert _sig(value, fmt) == text


@pytest.mark.parametrize("value, text", [
    (6009.4, "6009"), (0.0497, "0.0497"), (2.67e23, "2.67e+23"), (math.inf, "inf"), (None, "–"), (0.0, "0"),
    (9999999.0, "9999999"), (1.2e7, "1.2e+07"),
])
def test_lives_in_hours_or_exponent_form(value, text):
    assert _life(value) == text
    assert _life(value, 9) == text.rjust(9)


@pytest.mark.parametrize("value, text", [
    (True, "true"), (False, "false"), (3, "3"), (0.3, "0.3"), (206000.0, "206000.0"), ("rollers", '"rollers"'),
    ([90.0, 210.0, 330.0], "[90.0, 210.0, 330.0]"), ([], "[]"),
    ({"equidistant": 0.0, "shift": 0.0, "rotation_deg": 0.0}, "{equidistant = 0.0, shift = 0.0, rotation_deg = 0.0}"),
    ({"amplitude": 0.0, "values": []}, "{amplitude = 0.0, values = []}"),
    ({"a b": True}, '{"a b" = true}'),
])
def test_case_values_are_written_as_in_a_case_file(value, text):
    assert toml_text(value) == text


def test_warning_lines():
    assert warning_lines([]) == []
    lines = warning_lines([{"code": "load_ratio", "message": "P/C = 6.09 (bearing 1, flexible) > 0.5: …"}])
    assert lines == ["", "  warning: P/C = 6.09 (bearing 1, flexible) > 0.5: …"]


def test_roller_depth_lines_merge_bearings_with_equal_results():
    """With N-fold symmetry the bearings carry equal loads: one set of lines names them together;
    a bearing that differs keeps its own lines."""
    from rvfem.results.screen_lines import roller_depth_lines

    entry = {"roller_peak_pressure_MPa": 1911.0, "roller_edge_factor": 1.22, "peak_raceway": "eccentric",
             "film_thickness_min_um": 0.053, "kappa": 0.72, "a_iso": 0.92, "L10h_h": 27768.0,
             "L_nm_h": 25630.0, "L10r_h": 58061.0}
    bearing = {"rigid": entry, "flexible": entry, "L10h_ratio": 1.0, "L_nm_ratio": 1.0, "L10r_ratio": 1.0}
    depth = {"profile": "straight", "slices": 30, "max_slope_mrad": 0.14,
             "bearings": [dict(bearing, bearing=i) for i in (1, 2, 3)]}
    text = "\n".join(roller_depth_lines(depth))
    assert "bearings 1–3 rigid" in text and "bearing 1 " not in text
    depth["bearings"][2] = dict(bearing, bearing=3, L10r_ratio=0.5)
    text = "\n".join(roller_depth_lines(depth))
    assert "bearings 1–2 flexible/rigid" in text and "bearing 3 flexible/rigid" in text
