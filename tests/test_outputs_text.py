"""Numbers and values as users read them: screen tables (significant figures, lives), case values
in the report (TOML, not Python), warning lines."""

from __future__ import annotations

import math

import pytest

from rvfem.app.screen import _life, _sig, warning_lines
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
