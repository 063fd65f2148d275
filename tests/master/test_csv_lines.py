"""The recorder's CSV rows (master/results.csv_lines) are the bytes csv.writer writes: the format of every
output file stays what it was (floats by repr, nan and inf, CRLF), only cheaper to make."""
from __future__ import annotations

import csv
import io
import os

import numpy as np

from cranefmu.master.results import Recorder, csv_lines


def _csv_writer(rows: list[list[float]]) -> str:
    buffer = io.StringIO()
    csv.writer(buffer).writerows(rows)
    return buffer.getvalue()


def test_rows_are_csv_writers_bytes_for_every_kind_of_float():
    rng = np.random.default_rng(7)
    values = rng.standard_normal((200, 12)) * np.logspace(-30, 30, 12)
    values[0, :6] = [np.nan, np.inf, -np.inf, -0.0, 0.0, 1e16]
    values[1, :6] = [1e-5, 1e-4, 5e-324, 1.7976931348623157e308, 0.1, 1.0 / 3.0]
    rows = values.tolist()
    assert csv_lines(rows) == _csv_writer(rows)
    assert csv_lines([]) == ""


def test_a_recorded_file_is_what_csv_writer_gives(tmp_path):
    path = tmp_path / "out.csv"
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    rec = Recorder(["a.x", "b,y"], fd=fd, name=str(path), flush_every=3)
    rows = np.array([[0.1, np.nan], [2.5e-8, -np.inf], [1e300, -0.0]])
    rec.record(0.0, rows[0])
    rec.steps_complete(np.array([0.5, 1.0]), np.array([0.5, 0.5]), rows[1:])
    rec.flush()
    os.close(fd)
    expected = _csv_writer([["time", "a.x", "b,y"]]) + _csv_writer([[0.0, *rows[0]], [0.5, *rows[1]], [1.0, *rows[2]]])
    assert path.read_bytes() == expected.encode()
