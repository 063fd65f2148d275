"""Numbers measured from one run's result (a structured array with a ``time`` column).

A metric is written ``KIND:COLUMN``:

- ``max``, ``min``, ``initial`` (the static state: a scene starts at rest), ``final``, ``mean`` (time-weighted, trapezoid), ``ptp`` (peak to peak), ``absmax``;
- ``cross:COLUMN>VALUE`` / ``cross:COLUMN<VALUE``: time [s] of the first sample above / below VALUE
  (NaN if never);
- ``dynamic_factor:COLUMN``: peak / static value, the static value being the column at the start (a
  scene starts at rest in its static equilibrium), or ``dynamic_factor:COLUMN/STATIC`` with STATIC given;
- ``freq:COLUMN`` / ``damping:COLUMN``: natural frequency [Hz] / damping ratio [1] of the strongest of
  the (up to three) modes fitted in the column (matrix pencil, :func:`cranefmu.analysis.modal.fit_modes`; NaN if
  none is found), or with ``~F`` (``freq:rope.tension~3.8``) of the one nearest F [Hz];
- ``scene``: the scene's own key metrics (:data:`cranefmu.scenes.METRICS`, e.g. overhead_lift's
  dynamic factor, truck_telescope's sway and tipping), one column each.

From Python, a :class:`Custom` metric is any function ``fn(result, inputs) -> {name: value}`` (it
travels to the workers by value, so it may live in a script).

The table column of a metric is its text (``max:rope.tension``); scene metrics keep their own names.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import SettingsError
from .spec import number

_trapezoid = getattr(np, "trapezoid", None) or np.trapz   # numpy 2 renamed it
KINDS = ("max", "min", "initial", "final", "mean", "ptp", "absmax", "cross", "dynamic_factor", "freq", "damping",
         "scene")
MODAL_FIT = 3    # modes fitted (fewer if the signal has fewer)


@dataclass(frozen=True)
class Metric:
    kind: str
    column: str = ""
    threshold: float | None = None   # cross: the level; dynamic_factor: the static value (None: at start)
    above: bool = True               # cross: upward (>) or downward (<)

    @property
    def name(self) -> str:
        if self.kind == "scene":
            return "scene"
        if self.kind == "cross":
            return f"cross:{self.column}{'>' if self.above else '<'}{self.threshold!r}"
        if self.kind == "dynamic_factor" and self.threshold is not None:
            return f"dynamic_factor:{self.column}/{self.threshold!r}"
        if self.kind in ("freq", "damping") and self.threshold is not None:
            return f"{self.kind}:{self.column}~{self.threshold!r}"
        return f"{self.kind}:{self.column}"


@dataclass(frozen=True)
class Custom:
    """A metric computed by ``fn(result, inputs)`` returning ``{name: float}`` for each of ``names``;
    ``columns``: the result columns it reads, checked before anything runs."""

    names: tuple[str, ...]
    fn: Callable
    columns: tuple[str, ...] = ()
    kind = "custom"


def parse_metric(text: str | Custom) -> Metric | Custom:
    """'max:rope.tension', 'cross:pendulum.y>0.1', 'dynamic_factor:rope.tension', 'scene', ..."""
    if isinstance(text, Custom):
        return text
    text = str(text).strip()
    kind, _, rest = text.partition(":")
    kind = kind.strip().lower()
    allowed = ("max:COLUMN, min:, initial:, final:, mean:, ptp:, absmax:, cross:COLUMN>VALUE, cross:COLUMN<VALUE, "
               "dynamic_factor:COLUMN[/STATIC], freq:COLUMN[~HZ], damping:COLUMN[~HZ], scene")
    if kind == "scene" and not rest:
        return Metric("scene")
    if kind not in KINDS or kind == "scene" or not rest.strip():
        raise SettingsError(f"metric {text!r} is not allowed: one of {allowed}")
    rest = rest.strip()
    if kind == "cross":
        op = ">" if ">" in rest else "<" if "<" in rest else ""
        column, _, level = rest.partition(op) if op else (rest, "", "")
        value = number(level)
        if not op or value is None:
            raise SettingsError(f"metric {text!r} is not allowed: cross:COLUMN>VALUE or cross:COLUMN<VALUE")
        return Metric("cross", column.strip(), value, op == ">")
    if kind == "dynamic_factor" and "/" in rest:
        column, _, static = rest.partition("/")
        value = number(static)
        if value is None or value == 0:
            raise SettingsError(f"metric {text!r} is not allowed: the static value after '/' is a non-zero number")
        return Metric(kind, column.strip(), value)
    if kind in ("freq", "damping") and "~" in rest:
        column, _, near = rest.partition("~")
        value = number(near)
        if value is None or not value > 0:
            raise SettingsError(f"metric {text!r} is not allowed: the frequency after '~' is a number > 0 [Hz]")
        return Metric(kind, column.strip(), value)
    return Metric(kind, rest)


def scene_metric_names(scene: str, columns: list[str]) -> list[str]:
    """The names :func:`cranefmu.scenes.metrics` returns for ``scene``, found by measuring a made-up
    result at rest with every column (the names do not depend on the values)."""
    from ..scenes import METRICS

    fn = METRICS.get(scene)
    if fn is None:
        raise SettingsError(f"metric 'scene' is not allowed for scene {scene!r}: it has no key metrics "
                            f"(scenes with them: {', '.join(METRICS)})")
    fake = np.zeros(8, dtype=[(c, float) for c in ["time", *columns]])
    fake["time"] = np.linspace(0.0, 1.0, 8)
    for c in columns:
        fake[c] = 1.0
    with np.errstate(all="ignore"):
        return list(fn(fake))


def check(metrics: list[Metric], scene: str, columns: list[str]) -> list[str]:
    """Refuse a metric on a column the scene does not have (before anything runs); returns the table's
    metric column names in order."""
    known = set(columns) | {"time"}
    names: list[str] = []
    for m in metrics:
        if m.kind == "scene":
            names += scene_metric_names(scene, columns)
            continue
        for column in (m.columns if m.kind == "custom" else (m.column,)):
            if column not in known:
                close = [c for c in columns if column.split(".")[-1] in c] or columns
                label = ",".join(m.names) if m.kind == "custom" else m.name
                raise SettingsError(f"metric {label!r}: column {column!r} is not an output "
                                    f"of scene {scene}: one of {', '.join(close[:12])}"
                                    f"{' ...' if len(close) > 12 else ''}")
        names += list(m.names) if m.kind == "custom" else [m.name]
    if len(set(names)) != len(names):
        raise SettingsError(f"metrics {names} name a column twice")
    return names


def measure(metrics: list[Metric | Custom], scene: str, result: np.ndarray, inputs: dict | None = None) -> dict[str, float]:
    """Every metric of one run's result (NaN where the result has fewer than two rows)."""
    from ..scenes import METRICS

    out: dict[str, float] = {}
    t = np.asarray(result["time"], dtype=float)
    for m in metrics:
        if m.kind == "scene":
            with np.errstate(all="ignore"):
                out.update({k: float(v) for k, v in METRICS[scene](result).items()} if len(t) > 1 else {})
            continue
        if m.kind == "custom":
            values = m.fn(result, dict(inputs or {})) if len(t) > 1 else {}
            out.update({k: float(values.get(k, math.nan)) for k in m.names})
            continue
        y = np.asarray(result[m.column], dtype=float)
        out[m.name] = _one(m, t, y) if len(t) > 1 else math.nan
    return out


def _one(m: Metric, t: np.ndarray, y: np.ndarray) -> float:
    if m.kind == "max":
        return float(y.max())
    if m.kind == "min":
        return float(y.min())
    if m.kind == "initial":
        return float(y[0])
    if m.kind == "final":
        return float(y[-1])
    if m.kind == "absmax":
        return float(np.abs(y).max())
    if m.kind == "ptp":
        return float(y.max() - y.min())
    if m.kind == "mean":
        return float(_trapezoid(y, t) / (t[-1] - t[0]))
    if m.kind == "cross":
        hit = np.flatnonzero(y > m.threshold if m.above else y < m.threshold)
        return float(t[hit[0]]) if len(hit) else math.nan
    if m.kind in ("freq", "damping"):
        return _modal(m, t, y)
    static = y[0] if m.threshold is None else m.threshold   # dynamic_factor
    return float(y.max() / static) if static != 0 else math.nan


def _modal(m: Metric, t: np.ndarray, y: np.ndarray) -> float:
    from ..analysis.modal import ModalFitError, fit_modes, nearest

    for n in range(MODAL_FIT, 0, -1):   # as many of the strongest modes as the signal has
        try:
            modes = fit_modes(t, y, n)
        except ModalFitError:
            continue
        mode = nearest(modes, m.threshold) if m.threshold is not None else max(modes, key=lambda x: x.amplitude)
        return mode.frequency if m.kind == "freq" else mode.damping
    return math.nan
