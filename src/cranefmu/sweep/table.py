"""The sweep's table: one CSV row per run, appended and flushed as each run finishes.

CSV rather than Parquet: a row is appended the moment its run finishes (Parquet files are written
whole, so a crash or Ctrl-C would lose every row since the last rewrite), a resumed sweep reads the
keys back with the standard library, the file is readable by any tool, and it needs no pyarrow.
Floats are written with ``repr``, which reads back to the identical double (``pandas.read_csv``,
``float()``), so the table is as exact as the runs.  Columns: ``key`` (hash of the run's inputs),
the inputs, the metrics, then :data:`TAIL`.
"""
from __future__ import annotations

import csv
import math
import os
from pathlib import Path

from ..errors import SettingsError

TAIL = ("status", "error", "stopped", "fmus", "steps", "rejections", "wall_time", "task_time", "attempts", "worker")
_TEXT = ("key", "status", "error", "stopped", "fmus", "worker")   # never read as numbers (a key may look like 12e4)
#: statuses of a run that finished: ran to its stop time (ok), ended by the tipping flag (tipped), ended by another
#: stop condition (stopped: a result, e.g. a lifted load; the reason in ``stopped``)
FINISHED = ("ok", "tipped", "stopped")
# status: ok | tipped | stopped | failed | lost (with its worker or the scheduler: run again on resume); error: the message of a failed run; stopped: why a stop condition ended the run
# (a result, e.g. tipping); fmus: the kind of FMU that ran (native or python; empty: a scene file of other FMUs); steps, rejections: accepted and rejected macro steps; wall_time [s]: the run's own (master loop); task_time [s]: on the worker,
# scene loading, FMU set-up and metrics included; attempts: 2 when the run was retried


def header(inputs: list[str], metrics: list[str]) -> list[str]:
    tail = [c for c in TAIL if not (c == "fmus" and c in inputs)]   # fmus given as an input: its one column
    clash = set(inputs) & (set(metrics) | set(tail) | {"key"})
    if clash:
        raise SettingsError(f"column(s) {', '.join(sorted(clash))} would be both an input and a metric or a "
                            "status column: rename the metric")
    return ["key", *inputs, *metrics, *tail]


def cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return ",".join(map(str, value))
    return str(value)


class Table:
    """The CSV at ``path`` with ``columns``: opened for appending (an existing file must have the same
    columns: it is the same sweep, resumed) and written one flushed row at a time.  ``done``: keys
    whose last row is finished (ok or failed); a ``lost`` run is not done: a resumed sweep reruns it."""

    def __init__(self, path: str | Path, columns: list[str]):
        self.path = Path(path)
        self.columns = columns
        self.done: set[str] = set()
        self.keys: set[str] = set()   # every key in the file
        if self.path.exists() and self.path.stat().st_size > 0:
            with open(self.path, newline="") as f:
                reader = csv.reader(f)
                old = next(reader, [])
                if old != columns:
                    raise SettingsError(f"output {self.path} holds a different sweep (columns {', '.join(old)}); "
                                        f"this one has {', '.join(columns)}: give another output")
                status = columns.index("status")
                last = {r[0]: r[status] for r in reader if len(r) == len(columns)}
            self.keys = set(last)
            self.done = {k for k, v in last.items() if v != "lost"}
            self._file = open(self.path, "a", newline="")
        else:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = open(self.path, "w", newline="")
            csv.writer(self._file).writerow(columns)
            self._file.flush()
        self._writer = csv.writer(self._file)

    def write(self, row: dict) -> None:
        self._writer.writerow([cell(row.get(c)) for c in self.columns])
        # flushed to the OS: the row survives Ctrl-C or a crash of the client process (no fsync: at
        # thousands of rows per minute on a large cluster its milliseconds would throttle the client)
        self._file.flush()
        self.keys.add(row["key"])
        if row.get("status") == "lost":
            self.done.discard(row["key"])
        else:
            self.done.add(row["key"])

    def drop(self, keys: set[str]) -> None:
        """Remove every row of ``keys`` (:func:`drop`)."""
        self._file.close()
        drop(self.path, keys)
        self.keys -= keys
        self.done -= keys
        self._file = open(self.path, "a", newline="")
        self._writer = csv.writer(self._file)

    def close(self) -> None:
        self._file.close()


def reorder(path: str | Path, keys: list[str]) -> None:
    """Rewrite the table at ``path`` with the rows of ``keys`` in that order (the design's), each key's last
    row; rows of other keys (an earlier design) after them in file order. Beside it, then renamed over it."""
    path = Path(path)
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    last = {r[0]: r for r in rows[1:] if r}
    ordered = [last.pop(k) for k in dict.fromkeys(keys) if k in last]
    partial = path.with_name(path.name + ".order")
    with open(partial, "w", newline="") as f:
        csv.writer(f).writerows([rows[0], *ordered, *last.values()])
        f.flush()
        os.fsync(f.fileno())
    partial.replace(path)


def drop(path: str | Path, keys: set[str]) -> None:
    """Remove every row of ``keys`` from the table at ``path`` (rewritten beside it, then renamed over it)."""
    path = Path(path)
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f)]
    import io

    from ..whole_file import write

    text = io.StringIO(newline="")
    csv.writer(text).writerows([rows[0]] + [r for r in rows[1:] if r and r[0] not in keys])
    write(path, text.getvalue(), "sweep table")   # beside it, synced, renamed: the old table or the new


def read(path: str | Path) -> list[dict]:
    """The rows of a sweep table, numbers as floats (empty cells as None, other text as text); of a key
    written twice (a lost run, rerun), its last row, in the place of its first."""
    with open(path, newline="") as f:
        rows = {}
        for r in csv.DictReader(f):
            rows[r["key"]] = {k: v if k in _TEXT else _value(v) for k, v in r.items()}
    return list(rows.values())


def _value(text: str):
    if text == "":
        return None
    try:
        v = float(text)
    except ValueError:
        return text
    return v if math.isfinite(v) or text.lower() in ("nan", "inf", "-inf") else text
