"""The one CSV writer (rvfem.outputs.csvfile): a table given by its columns is written with exactly
the text of the cell-by-cell writer, and the run's long tables read back bit-identical."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from rvfem.outputs import tables
from rvfem.outputs.csvfile import format_cell, format_column, write_csv, write_csv_columns

AWKWARD = [0.0, -0.0, 1.0, 3.0000000000000004, 0.1 + 0.2, 1e-5, 1.5e-4, 1e16, 9.999999999999998e15, -2.5e-300,
           5e-324, 1.7976931348623157e308, math.pi, float("inf"), -float("inf"), float("nan")]


@pytest.mark.parametrize("nan_as_empty", [False, True])
def test_a_float_column_is_formatted_as_cell_by_cell(nan_as_empty):
    column = np.array(AWKWARD)
    assert format_column(column, nan_as_empty=nan_as_empty) == [format_cell(x, nan_as_empty=nan_as_empty)
                                                                 for x in column]


def test_integer_bool_float32_and_other_columns_are_formatted_as_cell_by_cell():
    for column in (np.array([0, -7, 2**62], dtype=np.int64), np.array([3, 65535], dtype=np.uint16),
                   np.array([True, False]), np.array([0.1, 1e-7, np.nan], dtype=np.float32),
                   ["rigid", None, 1.5, 2, True], np.array([[1.0, 2.0]])):
        assert format_column(column) == [format_cell(x) for x in column]


def test_floats_read_back_bit_identical():
    rng = np.random.default_rng(3)
    column = rng.normal(size=500) * 10.0 ** rng.integers(-12, 12, size=500)
    assert np.array_equal(np.array([float(c) for c in format_column(column)]), column)


def test_a_table_by_columns_is_the_file_of_its_rows(tmp_path):
    header = ["theta_deg", "model", "pin", "load_N", "loaded"]
    columns = [np.array([0.0, 1.5, 3.0000000000000004]), ["rigid", "flexible, FE", 'a "quoted" one'],
               np.arange(1, 4), np.array([np.nan, 1e-5, 2.0]), np.array([True, False, True])]
    by_rows = write_csv(tmp_path / "rows.csv", header, zip(*columns))
    by_columns = write_csv_columns(tmp_path / "columns.csv", header, columns)
    assert by_columns.read_bytes() == by_rows.read_bytes()
    assert write_csv_columns(tmp_path / "c.csv", header, columns, nan_as_empty=True).read_bytes() == \
        write_csv(tmp_path / "r.csv", header, zip(*columns), nan_as_empty=True).read_bytes()


def test_columns_of_different_lengths_are_refused(tmp_path):
    with pytest.raises(ValueError, match="differ in length"):
        write_csv_columns(tmp_path / "x.csv", ["a", "b"], [np.arange(3), np.arange(2)])
    with pytest.raises(ValueError, match="2 columns for 3 names"):
        write_csv_columns(tmp_path / "x.csv", ["a", "b", "c"], [np.arange(3), np.arange(3)])


def _rows(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.reader(fh))


def test_roller_and_pin_tables_hold_one_row_per_angle_and_roller_or_pin(tmp_path):
    rng = np.random.default_rng(7)
    n, n_b, z, zp = 4, 2, 3, 5
    theta = np.radians(np.arange(n) * 3.0)
    angles = rng.uniform(-7.0, 7.0, size=(n, n_b, z))
    loads = rng.uniform(0.0, 900.0, size=(n, n_b, z))
    rows = _rows(tables.write_roller_loads(tmp_path / "roller_loads.csv", theta, angles, loads))
    assert rows[0] == ["theta_deg", "bearing", "roller", "roller_angle_deg", "load_N"]
    body = rows[1:]
    assert len(body) == n * n_b * z
    for r, (k, i, j) in zip(body, np.ndindex(n, n_b, z)):
        assert r[:3] == [repr(3.0 * k), str(i + 1), str(j + 1)]
        assert float(r[3]) == round(math.degrees(angles[k, i, j]), 9) % 360.0
        assert float(r[4]) == loads[k, i, j]

    xy = rng.normal(size=(n, zp, 2)) * 60.0
    fe, classical = rng.uniform(0, 500, size=(n, zp)), np.full((n, zp), np.nan)
    rows = _rows(tables.write_pin_forces(tmp_path / "pin_forces.csv", theta, xy, fe, classical))
    assert rows[0] == ["theta_deg", "pin", "x_mm", "y_mm", "flexible_N", "classical_N"]
    for r, (k, j) in zip(rows[1:], np.ndindex(n, zp)):
        assert r == [repr(3.0 * k), str(j + 1), *(repr(float(v)) for v in (xy[k, j, 0], xy[k, j, 1], fe[k, j])), "nan"]
    assert len(rows) == 1 + n * zp


def test_bearing_table_columns_per_bearing_and_model(tmp_path):
    theta = np.radians([0.0, 120.0])
    flexible = np.arange(12.0).reshape(2, 3, 2)
    rigid = -flexible
    share = flexible + 0.5
    rows = _rows(tables.write_bearing_loads(tmp_path / "b.csv", theta, flexible, rigid, share))
    assert rows[0][:7] == ["theta_deg", "bearing1_flexible_Fx_N", "bearing1_flexible_Fy_N", "bearing1_flexible_F_N",
                           "bearing1_rigid_Fx_N", "bearing1_rigid_Fy_N", "bearing1_rigid_F_N"]
    assert rows[0][19:22] == ["bearing1_equal_share_Fx_N", "bearing1_equal_share_Fy_N", "bearing1_equal_share_F_N"]
    second = rows[2]
    assert second[0] == "120.0"
    assert second[1:4] == [repr(6.0), repr(7.0), repr(math.hypot(6.0, 7.0))]
    assert second[4:7] == [repr(-6.0), repr(-7.0), repr(math.hypot(6.0, 7.0))]
    assert second[19:22] == [repr(6.5), repr(7.5), repr(math.hypot(6.5, 7.5))]
    assert len(second) == 1 + 3 * 9
