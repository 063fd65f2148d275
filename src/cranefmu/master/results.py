"""Observers: record the outputs at every communication point, streaming to CSV as they come.

A recorder never steers the run.  The CSV is flushed every ``flush_every`` rows and on close, so
a run that fails part-way leaves every row computed before the failure on disk.
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np


class Recorder:
    """Rows of (time, values...) kept in memory (optionally) and streamed to a CSV file."""

    def __init__(self, columns: list[str], output: Path | None = None, keep: bool = True,
                 flush_every: int = 1000):
        self.columns = ["time", *columns]
        self.output = Path(output) if output else None
        self.keep = keep
        self.rows: list[np.ndarray] = []
        self.count = 0
        self._flush_every = flush_every
        self._file = None
        self._writer = None
        if self.output:
            self.output.parent.mkdir(parents=True, exist_ok=True)
            self._file = open(self.output, "w", newline="")
            self._writer = csv.writer(self._file)
            self._writer.writerow(self.columns)

    def record(self, time: float, values: np.ndarray) -> None:
        row = np.concatenate(([time], values))
        if self.keep:
            self.rows.append(row)
        if self._writer is not None:
            self._writer.writerow(row.tolist())  # csv writes a float as repr(): every digit kept
            if self.count % self._flush_every == 0:
                self._file.flush()
        self.count += 1

    def simulation_initialized(self, t: float, values: np.ndarray) -> None:
        self.record(t, values)

    def step_complete(self, t: float, h: float, values: np.ndarray) -> None:
        self.record(t, values)   # the failing row too: it shows what went wrong

    def close(self) -> None:
        if self._file is not None and not self._file.closed:
            self._file.flush()
            self._file.close()

    def result(self) -> np.ndarray:
        """The kept rows as a numpy structured array with one float field per column."""
        dtype = [(c, np.float64) for c in self.columns]
        data = np.array(self.rows) if self.rows else np.zeros((0, len(self.columns)))
        out = np.zeros(len(data), dtype=dtype)
        for i, c in enumerate(self.columns):
            out[c] = data[:, i]
        return out


def read_csv(path: Path) -> np.ndarray:
    """Read a result CSV written by :class:`Recorder` back into a structured array."""
    return np.genfromtxt(path, delimiter=",", names=True, deletechars="", dtype=np.float64)
