"""Scene-level conformance of the two FMU kinds: one scene and parameter set run with the native FMUs and
with the pythonfmu FMUs, every column compared relative to its range (issue 33: 1e-9 of range).

Used by tests/scenes/test_native_scenes.py (short windows) and benchmarks/native_conformance.py (each
scene's natural length).  The runs are in this process (the master keeps the pythonfmu FMUs' extracted
folders for the process, so runs of one scene follow each other), or isolated in a worker (``isolate``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

TOLERANCE = 1e-9   # of a column's range
# a column's range is at least this fraction of its magnitude and this absolute value (SI units): a column at
# rest (a settled girder deflection, a payout held at zero) moves only by roundoff, and its range is no scale
RANGE_FLOOR_REL = 1e-6
RANGE_FLOOR_ABS = 1e-9


@dataclass(frozen=True)
class Agreement:
    """How far a scene's native run is from its pythonfmu run."""

    scene: str
    parameter_set: str | None
    stop_time: float
    rows: tuple[int, int]          # (python, native)
    worst: float                   # largest |native - python| / range over all columns
    column: str                    # where it is
    wall: dict[str, float]         # kind -> the run's own wall time [s] (stats.wall_time: the master loop)
    bonds: float = 0.0             # the same measure over the power bonds' columns (DERIVED)

    @property
    def ok(self) -> bool:
        return self.rows[0] == self.rows[1] and self.worst <= TOLERANCE


DERIVED = "bond."   # the power bonds' energy residuals: the master's sums of F v products that cancel to roundoff
#                     at rest; compared apart (Agreement.bonds), not against the 1e-9 of the FMUs' outputs


def relative_difference(a: np.ndarray, b: np.ndarray, columns: list[str] | None = None,
                        floor: float = RANGE_FLOOR_ABS, floor_rel: float = RANGE_FLOOR_REL,
                        units: dict[str, str] | None = None) -> tuple[float, str]:
    """(largest |a - b| / range of a over ``columns`` (default every column of ``a``), that column).  A column's range is its
    peak-to-peak value, at least ``floor_rel`` of its magnitude and ``floor``; with ``units`` (column -> unit), also at
    least ``floor_rel`` of the largest magnitude of the columns in its unit (a force that stays at round-off zero,
    a sling at rest, is compared on the scene's force scale, not on its own noise)."""
    names = list(columns if columns is not None else a.dtype.names)
    scale: dict[str, float] = {}
    for name in names if units else ():
        if name in units and len(a):
            scale[units[name]] = max(scale.get(units[name], 0.0), float(np.max(np.abs(np.asarray(a[name], float)))))
    worst, where = 0.0, ""
    for name in names:
        if name not in b.dtype.names:
            return float("inf"), name
        x, y = np.asarray(a[name], float), np.asarray(b[name], float)
        by_unit = floor_rel * scale.get((units or {}).get(name), 0.0)
        span = max(float(np.ptp(x)), floor_rel * float(np.max(np.abs(x))), floor, by_unit) if len(x) else 1.0
        both_nan = np.isnan(x) & np.isnan(y)
        diff = np.where(both_nan, 0.0, np.abs(x - y))
        err = float(np.max(diff)) / span if len(diff) else 0.0
        if not err <= worst:   # NaN counts as the worst
            worst, where = (float("inf") if err != err else err), name
    return worst, where


def agreement(scene: str, parameter_set: str | None = None, stop_time: float | None = None,
              floor: float = RANGE_FLOOR_ABS, floor_rel: float = RANGE_FLOOR_REL, isolate: bool = False,
              **settings) -> Agreement:
    """Run ``scene`` (with ``parameter_set``, to ``stop_time``, default its own; ``settings``: more run
    settings) with each kind of FMU and compare the results (``floor``, ``floor_rel``: the smallest range,
    see :func:`relative_difference`; a short window at rest needs larger ones)."""
    from ..master.run import run

    results, wall, end = {}, {}, stop_time
    for kind in ("python", "native"):
        t0 = time.perf_counter()
        res = run(scene, parameter_set=parameter_set, stop_time=stop_time, fmus=kind, isolate=isolate, progress=False,
                  **settings)
        wall[kind] = res.stats.wall_time or time.perf_counter() - t0
        results[kind] = res.result
        end = res.settings.stop_time
    a, b = results["python"], results["native"]
    outputs = [n for n in a.dtype.names if not n.startswith(DERIVED)]
    from ..master.run import preview

    worst, column = relative_difference(a, b, outputs, floor, floor_rel, preview(scene, "python").units)
    bonds = relative_difference(a, b, [n for n in a.dtype.names if n.startswith(DERIVED)], floor, floor_rel)[0]
    return Agreement(scene, parameter_set, float(end), (len(a), len(b)), worst, column, wall, bonds)


def scene_sets() -> list[tuple[str, str | None]]:
    """Every (shipped scene, parameter set) pair; None is the default set."""
    from ..master.run import preview
    from ..scenes.catalog import scene_names

    out = []
    for name in scene_names():
        sets = preview(name, "python").parameter_sets
        out += [(name, None if s == "default" else s) for s in sets]
    return out
