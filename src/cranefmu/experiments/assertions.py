"""Assertions on a run's rows: the value an assertion measures, and its verdict against its limit.

When (one of): ``always`` (every row of the run, the default), ``finally`` (the last row), ``at = t``
(the column linearly interpolated at t), ``during = [t1, t2]`` (every row with t1 <= t <= t2).
A ``metric`` turns the rows of ``always``/``during`` into one number:

- ``max``, ``min``, ``max_abs``, ``mean`` of the column;
- ``first_crossing``: the first time [s] the column crosses ``level`` (linear between rows);
- ``smallest_peak``: the smallest local maximum of the column (a row >= the one before and > the one
  after), e.g. the smallest swing peak of a sway (the beat of two pendulum modes);
- ``dynamic_factor``: max / static, static = ``static`` (an expression) or the column's first row
  of the run (the scene starts at rest, so its first row is the static value);
- ``frequency`` [Hz], ``damping`` [1]: of mode ``mode`` (lowest frequency first) among the
  ``n_modes`` strongest of the column, fitted by :func:`cranefmu.analysis.modal.fit_modes` (matrix pencil);
- the metrics registered in :mod:`.metrics` (``envelope_first_minimum``, ``envelope_min_ratio``,
  ``envelope_fall_rate``: the Hilbert envelope of a released sway).

Limits: ``min`` and/or ``max``, or ``equals`` with ``rel`` and/or ``abs`` (the larger tolerance
counts); each a number or an expression (:mod:`.expressions`).  The margin is how far inside the
limit the value is (negative: outside), in the column's unit (the metric's for a metric).  Without a
metric, ``always``/``during`` report the row with the smallest margin and its time.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .expressions import evaluate
from .metrics import REGISTRY
from .reader import AssertionSpec


@dataclass(frozen=True)
class Verdict:
    """One assertion of one case."""

    experiment: str
    case: str
    name: str
    column: str
    value: float
    limit: str
    margin: float
    passed: bool
    time: float | None = None     # the row the value is from (always/during without a metric, at, finally)
    note: str = ""                # why it failed without a value (a run failure, a window with no row, ...)
    source: str = ""
    unit: str = ""                # the unit of value, limit and margin (the column's, or its metric's)

    def as_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in self.__dict__.items()}


def measured(a: AssertionSpec, t: np.ndarray, y: np.ndarray, values: dict) -> tuple[np.ndarray, np.ndarray] | float:
    """What ``a`` measures: one number (a metric, ``at``, ``finally``) or the (times, values) of its rows.
    Raises ValueError saying why there is nothing to measure."""
    if a.when == "finally":
        return float(y[-1])
    if a.when == "at":
        if not t[0] - 1e-12 <= a.at <= t[-1] + 1e-12:
            raise ValueError(f"at = {a.at:g} s is outside the run ({t[0]:g} to {t[-1]:g} s)")
        return float(np.interp(a.at, t, y))
    first = float(y[0])   # the run's first row: the static value of a scene that starts at rest
    if a.when == "during":
        inside = (t >= a.during[0] - 1e-12) & (t <= a.during[1] + 1e-12)
        if not inside.any():
            raise ValueError(f"no row in during = [{a.during[0]:g}, {a.during[1]:g}] s (run {t[0]:g} to {t[-1]:g} s)")
        t, y = t[inside], y[inside]
    if a.metric is None:
        return t, y
    return metric(a, t, y, values, first)


def metric(a: AssertionSpec, t: np.ndarray, y: np.ndarray, values: dict, first: float) -> float:
    """The metric of ``a`` over the rows (t, y); ``first``: the run's first value (dynamic factor)."""
    m = a.metric
    if m == "max":
        return float(np.max(y))
    if m == "min":
        return float(np.min(y))
    if m == "max_abs":
        return float(np.max(np.abs(y)))
    if m == "mean":
        return float(np.mean(y))
    if m == "first_crossing":
        d = y - a.level
        hit = np.flatnonzero((d[:-1] < 0) != (d[1:] < 0)) if len(d) > 1 else []
        if d[0] == 0:
            return float(t[0])
        if not len(hit):
            raise ValueError(f"{a.column} never crosses level {a.level:g}")
        i = int(hit[0])
        return float(t[i] + (t[i + 1] - t[i]) * (0 - d[i]) / (d[i + 1] - d[i]))
    if m == "smallest_peak":
        inner = np.flatnonzero((y[1:-1] >= y[:-2]) & (y[1:-1] > y[2:])) + 1
        if not len(inner):
            raise ValueError(f"{a.column or 'the value'} has no peak (no local maximum) in its rows")
        return float(np.min(y[inner]))
    if m == "dynamic_factor":
        static = evaluate(a.static, values) if a.static is not None else first
        if static == 0:
            raise ValueError("the static value is 0: no dynamic factor")
        return float(np.max(y) / static)
    if m in REGISTRY:
        return float(REGISTRY[m](t, y))
    from ..analysis.modal import fit_modes

    modes = fit_modes(t, y, a.n_modes)
    mode = modes[a.mode - 1]
    return mode.frequency if m == "frequency" else mode.damping


def judge(a: AssertionSpec, got, values: dict) -> tuple[float, str, float, float | None]:
    """(value, limit text, margin, time) of what ``measured`` gave against the limits of ``a``."""
    if a.equals is not None:
        target = evaluate(a.equals, values)
        tol = max(a.abs or 0.0, (a.rel or 0.0) * abs(target))
        margins = lambda v: tol - np.abs(v - target)   # noqa: E731
        parts = [f"{'rel ' + format(a.rel, 'g') if a.rel is not None else ''}",
                 f"{'abs ' + format(a.abs, 'g') if a.abs is not None else ''}"]
        limit = f"= {target:.10g} ({', '.join(p for p in parts if p)})"
    else:
        lo = evaluate(a.min, values) if a.min is not None else -math.inf
        hi = evaluate(a.max, values) if a.max is not None else math.inf
        margins = lambda v: np.minimum(v - lo, hi - v)   # noqa: E731
        limit = " and ".join(x for x in (f">= {lo:.10g}" if a.min is not None else "",
                                         f"<= {hi:.10g}" if a.max is not None else "") if x)
    if isinstance(got, tuple):
        t, y = got
        m = margins(y)
        bad = ~np.isfinite(y)
        if bad.any():   # a non-finite value fails where it is
            i = int(np.flatnonzero(bad)[0])
            return float(y[i]), limit, -math.inf, float(t[i])
        i = int(np.argmin(m))
        return float(y[i]), limit, float(m[i]), float(t[i])
    if not math.isfinite(got):
        return got, limit, -math.inf, None
    return got, limit, float(margins(np.array(got))), a.at if a.when == "at" else None
