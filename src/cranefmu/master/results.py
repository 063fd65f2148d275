"""Observers: record the outputs at every communication point, streaming to CSV as they come.

A recorder never steers the run.  Rows are written to the file descriptor in whole rows, at the
first row and then every ``flush_every`` rows, so a run that fails or is killed part-way leaves
every row written before on disk in a well-formed CSV.  A failed write (disk full) cuts the file
back to its last whole row and raises a :class:`~cranefmu.errors.SimulationError` saying so.
"""
from __future__ import annotations

import csv
import io
import os
import stat

import numpy as np

from ..errors import SimulationError


class Recorder:
    """Rows of (time, values...) kept in memory (optionally) and streamed to an open file descriptor.

    ``name`` is how the file is called in messages (the run's target), ``path`` where it is now.  ``count`` rows were
    recorded, ``written`` of them are on disk.  The values given are copied (the caller may reuse its array).
    """

    batchable = True   # takes rows after the fact: a stretch of compiled steps may precede it (loop.march)
    passive = True     # never stops the run on a row's content: takes a stretch's rows once its stop is known

    BLOCK = 1024   # rows per preallocated block in memory

    def __init__(self, columns: list[str], fd: int | None = None, name: str = "", keep: bool = True,
                 flush_every: int = 1000, path: str = ""):
        self.columns = ["time", *columns]
        self.fd = fd
        # writing a file: compiled stretches of at most 256 steps (loop.STRETCH was 256), so that a crash
        # inside an FMU loses at most those and the rows not yet flushed, as before
        self.stretch_limit = 256 if fd is not None else None
        self.name = name
        self.path = path or name    # the file on disk while the run goes on (``name`` + ".part")
        self.keep = keep
        # rows in blocks of preallocated 2-D arrays, filled row by row (no per-row array); without
        # ``keep`` one row, overwritten
        self._blocks: list[np.ndarray] = []
        self._block = np.empty((self.BLOCK if keep else 1, len(self.columns)))
        self._at = 0
        self.count = 0
        self.written = 0
        self.write_error = ""
        self.last_time = float("nan")
        self._flush_every = flush_every
        self._buffer = io.StringIO()
        self._writer = csv.writer(self._buffer)
        self._offset = 0
        self._pending = 0
        if fd is not None:
            self._regular = stat.S_ISREG(os.fstat(fd).st_mode)
            self._writer.writerow(self.columns)

    @property
    def output(self) -> str | None:
        return self.name or None

    def record(self, time: float, values: np.ndarray) -> None:
        if self._at == len(self._block):
            if self.keep:
                self._blocks.append(self._block)
                self._block = np.empty_like(self._block)
            self._at = 0
        row = self._block[self._at]
        row[0] = time
        row[1:] = values
        self._at += 1
        self.last_time = time
        self.count += 1
        if self.fd is not None:
            self._buffer.write(csv_lines([row.tolist()]))
            self._pending += 1
            if self.count == 1 or self._pending >= self._flush_every:
                self.flush()

    def steps_complete(self, times: np.ndarray, hs: np.ndarray, rows: np.ndarray) -> None:
        """The rows of a stretch at once (:func:`.loop.march`): as :meth:`record` of each, flushed at the
        same rows."""
        data = np.empty((len(times), len(self.columns)))
        data[:, 0] = times
        data[:, 1:] = rows
        at, n = 0, len(data)
        while at < n:
            take = n - at
            if self.fd is not None:   # up to the next flush
                take = min(take, 1 if self.count == 0 else max(1, self._flush_every - self._pending))
            chunk = data[at:at + take]
            self._store(chunk)
            self.count += take
            self.last_time = float(chunk[-1, 0])
            at += take
            if self.fd is not None:
                self._buffer.write(csv_lines(chunk.tolist()))
                self._pending += take
                if self.count == take or self._pending >= self._flush_every:
                    self.flush()

    def _store(self, chunk: np.ndarray) -> None:
        """Rows into the blocks in memory (without ``keep``: the last one)."""
        if not self.keep:
            self._block[0] = chunk[-1]
            self._at = 1
            return
        at = 0
        while at < len(chunk):
            if self._at == len(self._block):
                self._blocks.append(self._block)
                self._block = np.empty_like(self._block)
                self._at = 0
            take = min(len(chunk) - at, len(self._block) - self._at)
            self._block[self._at:self._at + take] = chunk[at:at + take]
            self._at += take
            at += take

    def flush(self) -> None:
        """Write the buffered rows; on failure cut the file back to its last whole row and raise."""
        if self.fd is None or self.write_error:
            return
        data = self._buffer.getvalue().encode()
        self._buffer.seek(0)
        self._buffer.truncate()
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(self.fd, view):]
        except OSError as err:
            self.write_error = err.strerror or str(err)
            if self._regular:
                try:
                    os.ftruncate(self.fd, self._offset)
                except OSError:
                    pass
            kept = (f"the {self.written} rows written before are in {self.name}" if self.written
                    else "no rows were written")
            raise SimulationError(f"writing the results to {self.name} failed at row {self.count}: "
                                  f"{self.write_error}; {kept}") from None
        self._offset += len(data)
        self.written += self._pending
        self._pending = 0

    def simulation_initialized(self, t: float, values: np.ndarray) -> None:
        self.record(t, values)

    def step_complete(self, t: float, h: float, values: np.ndarray) -> None:
        self.record(t, values)   # the failing row too: it shows what went wrong

    def close(self) -> None:
        """Write what is buffered (errors after a failed write are not repeated)."""
        if self.fd is not None and not self.write_error and self._pending:
            self.flush()

    def result(self) -> np.ndarray:
        """The kept rows as a numpy structured array with one float field per column."""
        dtype = [(c, np.float64) for c in self.columns]
        blocks = [*self._blocks, self._block[:self._at]] if self.keep else []
        out = np.empty(sum(len(b) for b in blocks), dtype=dtype)
        # a row of float64 fields is laid out as a row of a (rows, columns) float array: the blocks are
        # copied in whole (one contiguous copy each, not one strided copy per column)
        flat, at = out.view(np.float64).reshape(len(out), len(self.columns)), 0
        for b in blocks:
            flat[at:at + len(b)] = b
            at += len(b)
        return out


def csv_lines(rows: list[list[float]]) -> str:
    """Rows of floats as csv.writer (default dialect) writes them, byte for byte: each float as its
    repr() (every digit kept; nan, inf), comma-separated, CRLF-terminated; about 30 % less CPU than
    csv.writer, which checks every field for quoting (a float never needs it)."""
    r = float.__repr__
    return "".join([",".join(map(r, row)) + "\r\n" for row in rows])


def read_csv(path, columns: list[str] | None = None) -> np.ndarray:
    """Read a result CSV written by :class:`Recorder` back into a structured array (only ``columns``
    and time, if given: a long run's file need not fit in memory whole)."""
    if columns is None:
        return np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True, deletechars="", dtype=np.float64))
    with open(path, newline="") as f:
        header = next(csv.reader(f))
    wanted = ["time", *[c for c in columns if c != "time"]]
    index = [header.index(c) for c in wanted]
    data = np.loadtxt(path, delimiter=",", skiprows=1, usecols=index, ndmin=2)
    out = np.zeros(len(data), dtype=[(c, np.float64) for c in wanted])
    for i, c in enumerate(wanted):
        out[c] = data[:, i]
    return out
