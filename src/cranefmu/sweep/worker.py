"""What a Dask worker runs: one simulation in its own process (no child per run), its metrics, one row.

The scene reaches a worker as an :class:`SspFile`: on a local cluster its path; on a remote cluster
its bytes too (scattered once to every worker), written once per worker process under the worker's
local directory and reused by every later run.
"""
from __future__ import annotations

import hashlib
import os
import tempfile
import time as clock
from dataclasses import dataclass
from pathlib import Path

from ..errors import CraneFmuError
from .metrics import Custom, Metric, measure
from .spec import Run

_LOCAL: dict[str, Path] = {}   # sha256 -> the .ssp written in this worker process


@dataclass(frozen=True)
class SspFile:
    """A built scene: its name, content hash, path on the client, and (remote workers) its bytes."""

    name: str
    sha256: str
    path: str
    data: bytes | None = None

    @classmethod
    def of(cls, path: Path, name: str, with_data: bool) -> "SspFile":
        data = Path(path).read_bytes()
        return cls(name, hashlib.sha256(data).hexdigest(), str(path), data if with_data else None)

    def local(self) -> Path:
        """The .ssp on this machine: the client's path, or the bytes written once per process."""
        if self.data is None:
            return Path(self.path)
        if self.sha256 not in _LOCAL:
            try:
                from distributed import get_worker

                base = Path(get_worker().local_directory)
            except (ImportError, ValueError):
                base = Path(tempfile.gettempdir())
            target = base / f"cranefmu_{self.sha256[:16]}" / Path(self.path).name
            target.parent.mkdir(parents=True, exist_ok=True)
            partial = target.with_suffix(f".{os.getpid()}.part")
            partial.write_bytes(self.data)
            partial.replace(target)   # atomic: a second process on the machine never reads half a file
            _LOCAL[self.sha256] = target
        return _LOCAL[self.sha256]


def execute(ssp: SspFile, run: Run, metrics: list[Metric | Custom], results_dir: str | None = None) -> dict:
    """Run ``run`` in this process and return its row (inputs, metrics, status, error, cost).

    Every exception is caught into the row: a CraneFmuError (bad value, unstable coupling, ...) is the
    run's result and is not repeated; anything else is marked ``retry`` for the engine to try once more.
    """
    from ..master.run import execute
    from ..master.runspec import resolve

    t0 = clock.perf_counter()
    row: dict = {"key": run.key, **run.row, "status": "ok", "error": "", "stopped": "", "steps": 0,
                 "worker": _worker_name()}
    try:
        spec = resolve(ssp.local(), parameters=run.parameters, parameter_set=run.parameter_set,
                       **{"progress": False, **run.settings})   # in this worker process, rows kept
        res = execute(spec)
        row.update(measure(metrics, run.scene, res.result, run.si_inputs))
        stopped = _one_line(res.stats.stopped or "")
        row.update(fmus=spec.settings.fmus or "", steps=res.stats.steps, rejections=res.stats.rejections,
                   wall_time=res.stats.wall_time, stopped=stopped, status=status_of(stopped))
        if results_dir is not None:
            import numpy as np

            np.save(Path(results_dir) / f"{run.key}.npy", res.result)
    except CraneFmuError as err:
        row.update(status="failed", error=_one_line(str(err)))
    except Exception as err:  # noqa: BLE001 - any failure of one run is recorded, never raised into the sweep
        row.update(status="failed", error=_one_line(f"{type(err).__name__}: {err}"), retry=True)
    row["task_time"] = clock.perf_counter() - t0
    return row


def execute_runs(ssp: SspFile, runs: list[Run], metrics: list[Metric | Custom],
                 results_dir: str | None = None) -> list[dict]:
    """:func:`execute` of each of ``runs`` in turn, in this process: one Dask task for several short runs
    (:mod:`.feed`); their rows in the same order."""
    return [execute(ssp, run, metrics, results_dir) for run in runs]


def status_of(stopped: str) -> str:
    """A finished run's status from why it stopped: ok (ran to its stop time), tipped (the tipping flag
    ended it), stopped (another stop condition)."""
    if not stopped:
        return "ok"
    return "tipped" if ".tipping" in stopped else "stopped"


def _one_line(text: str) -> str:
    return " ".join(text.split())


def _worker_name() -> str:
    try:
        from distributed import get_worker

        return str(get_worker().name)
    except (ImportError, ValueError):
        return f"pid{os.getpid()}"
