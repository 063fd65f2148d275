"""Scene-level conformance of the two FMU kinds: one scene and parameter set run with the native FMUs and
with the pythonfmu FMUs, every column compared relative to its range (issue 33: 1e-9 of range).

Used by tests/scenes/test_native_scenes.py (short windows) and benchmarks/native_conformance.py (each
scene's natural length).  Each run is isolated (a worker process): pythonfmu FMUs cannot be instantiated
again in a process once an instance was freed.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

TOLERANCE = 1e-9   # of a column's range


@dataclass(frozen=True)
class Agreement:
    """How far a scene's native run is from its pythonfmu run."""

    scene: str
    parameter_set: str | None
    stop_time: float
    rows: tuple[int, int]          # (python, native)
    worst: float                   # largest |native - python| / range over all columns
    column: str                    # where it is
    wall: dict[str, float]         # kind -> the run's own wall time [s] (stats.wall_time)

    @property
    def ok(self) -> bool:
        return self.rows[0] == self.rows[1] and self.worst <= TOLERANCE


def relative_difference(a: np.ndarray, b: np.ndarray) -> tuple[float, str]:
    """(largest |a - b| / range of a over every common column, that column).  A column's range is its
    peak-to-peak value; a constant column is compared to its magnitude (an all-zero one absolutely)."""
    worst, where = 0.0, ""
    for name in a.dtype.names:
        if name not in b.dtype.names:
            return float("inf"), name
        x, y = np.asarray(a[name], float), np.asarray(b[name], float)
        span = float(np.ptp(x)) or float(np.max(np.abs(x))) or 1.0
        both_nan = np.isnan(x) & np.isnan(y)
        diff = np.where(both_nan, 0.0, np.abs(x - y))
        err = float(np.max(diff)) / span if len(diff) else 0.0
        if not err <= worst:   # NaN counts as the worst
            worst, where = (float("inf") if err != err else err), name
    return worst, where


def agreement(scene: str, parameter_set: str | None = None, stop_time: float | None = None,
              **settings) -> Agreement:
    """Run ``scene`` (with ``parameter_set``, to ``stop_time``, default its own; ``settings``: more run
    settings) with each kind of FMU and compare the results."""
    from ..master.run import run

    results, wall, end = {}, {}, stop_time
    for kind in ("python", "native"):
        t0 = time.perf_counter()
        res = run(scene, parameter_set=parameter_set, stop_time=stop_time, fmus=kind, isolate=True, progress=False,
                  **settings)
        wall[kind] = res.stats.wall_time or time.perf_counter() - t0
        results[kind] = res.result
        end = res.settings.stop_time
    worst, column = relative_difference(results["python"], results["native"])
    return Agreement(scene, parameter_set, float(end), (len(results["python"]), len(results["native"])), worst,
                     column, wall)


def scene_sets() -> list[tuple[str, str | None]]:
    """Every (shipped scene, parameter set) pair; None is the default set."""
    from ..master.run import preview
    from ..scene_catalog import scene_names

    out = []
    for name in scene_names():
        sets = preview(name, "python").parameter_sets
        out += [(name, None if s == "default" else s) for s in sets]
    return out
