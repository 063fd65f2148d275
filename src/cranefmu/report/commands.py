"""Operator commands in the report: what each command fed over the run, as the operator commanded it, beside
the output it drives (issue 37: "operator commands are not plotted in the report").

A command (:class:`cranefmu.master.commands.Command`: a source feeding an input ``component.variable``) is
evaluated at every row's time.  The inputs of a boom motion are changes from a start parameter
(``slew_command`` = sigma - ``slew_angle_start``, cranefmu.physics.boom and .slewing): the start value in force
is added back, so a slew command is plotted as the slewing angle sigma beside ``boom.slew_angle_out``.  An
output in another frame than its input (the boom tip moved by ``x_travel``, the rope lengthened by
``payout``) is plotted as its change from the first row.  Sources started or stopped by an event
(:mod:`cranefmu.experiments.events`) are evaluated with the event found again on the recorded rows (every
communication point is a row: the run's event time), and the event is marked on the plot.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Drives:
    """What a commanded input variable moves: ``output`` of the same component; ``start`` the parameter the
    input is a change from (added back to show the commanded quantity); ``relative``: the output is shown as
    its change from the first row (its frame is not the input's)."""

    output: str
    start: str = ""
    relative: bool = False


DRIVES = {
    "slew_command": Drives("slew_angle_out", "slew_angle_start"),
    "luff_command": Drives("luff_angle_out", "luff_angle"),
    "extension_command": Drives("boom_length", "boom_length_start"),
    "x_travel": Drives("x_tip", relative=True),
    "vx_travel": Drives("vx_tip"),
    "payout": Drives("rope_length", relative=True),
    "x_top": Drives("x_suspension"),
    "y_top": Drives("y_suspension"),
    "z_top": Drives("z_suspension"),
}


def _luff_from_radius(rows, comp: str) -> tuple[str, np.ndarray] | None:
    """A SlewingBoom has no luff_angle_out: its luffing angle from the radius and the length, above the
    horizontal (name, values [rad]); None without those columns."""
    radius, length = f"{comp}.radius", f"{comp}.boom_length"
    if not {radius, length} <= set(rows.dtype.names):
        return None
    r, L = np.asarray(rows[radius], dtype=float), np.asarray(rows[length], dtype=float)
    return f"acos({radius} / {length})", np.arccos(np.clip(r / L, -1.0, 1.0))


@dataclass
class CommandPlots:
    """The command series of a run: ``groups`` (title, series names) for :func:`.page.plot_specs`, the
    series' values by name (``values``, SI, one per row), their ``units``, vertical ``marks`` by group title
    ((t [s], label): the events), and ``notes`` for the page."""

    groups: list[tuple[str, list[str]]] = field(default_factory=list)
    values: dict[str, np.ndarray] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    marks: dict[str, list[tuple[float, str]]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    dashed: set[str] = field(default_factory=set)


def _by_source(commands) -> list[tuple[object, list[str]]]:
    """The commands grouped by their source object (one profile fed to several inputs is one command)."""
    found: dict[int, tuple[object, list[str]]] = {}
    for c in commands or ():
        found.setdefault(id(c.source), (c.source, []))[1].append(str(c.target))
    return list(found.values())


def _watchers(source) -> list:
    return list(source.watchers()) if hasattr(source, "watchers") else []


def command_columns(commands, names) -> list[str]:
    """The result columns (of ``names``) the command plots read: driven outputs and event conditions."""
    from ..experiments.expressions import names as expression_names

    wanted = set()
    for source, targets in _by_source(commands):
        for target in targets:
            comp, _, var = target.partition(".")
            if var in DRIVES:
                wanted.add(f"{comp}.{DRIVES[var].output}")
            if var == "luff_command":
                wanted |= {f"{comp}.radius", f"{comp}.boom_length"}
        for w in _watchers(source):
            for side in (w.left, w.right):
                if isinstance(side, str):
                    wanted |= expression_names(side)
    return [c for c in names if c in wanted]


def _event_times(watchers, rows) -> dict[int, float | None]:
    """Each trigger's event time on the recorded rows: the first row where its condition holds (None: never;
    KeyError: a column it reads is not in the rows)."""
    from ..experiments.expressions import CONSTANTS, evaluate, names as expression_names

    t = np.asarray(rows["time"], dtype=float)
    scope_rows = {n: np.asarray(rows[n], dtype=float) for n in rows.dtype.names}
    out = {}
    for w in watchers:
        scope = {**w.values, **scope_rows}
        missing = sorted(n for side in (w.left, w.right) if isinstance(side, str)
                         for n in expression_names(side) if n not in scope and n not in CONSTANTS)
        if missing:
            raise KeyError(", ".join(missing))
        a = np.broadcast_to(np.asarray(evaluate(w.left, scope, vector=True), dtype=float), t.shape)
        b = w.right if not isinstance(w.right, str) else evaluate(w.right, scope, vector=True)
        b = np.broadcast_to(np.asarray(b, dtype=float), t.shape)
        holds = {"<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b}[w.op]
        hit = np.flatnonzero(holds)
        out[id(w)] = float(t[hit[0]]) if len(hit) else None
    return out


def command_plots(commands, rows, units: dict[str, str], starts: dict[str, float] | None = None) -> CommandPlots:
    """The plots of ``commands`` over ``rows`` (a structured array with ``time``): one group per command with
    the commanded quantity (dashed) and the outputs it drives; ``units`` the scene's (column -> unit, the
    inputs' too); ``starts``: parameter values 'comp.var' (the boom motions' start values)."""
    from ..experiments.expressions import ExpressionError

    out = CommandPlots()
    names = set(rows.dtype.names)
    t = np.asarray(rows["time"], dtype=float)
    starts = starts or {}
    for source, targets in _by_source(commands):
        watchers = _watchers(source)
        try:
            events = _event_times(watchers, rows)
        except KeyError as err:
            out.notes.append(f"command on {', '.join(targets)} not plotted: its event condition reads "
                             f"{err.args[0]}, which the result does not hold")
            continue
        except ExpressionError as err:
            out.notes.append(f"command on {', '.join(targets)} not plotted: its event condition: {err}")
            continue
        saved = [(w, w.t_event) for w in watchers]
        try:   # the event as the run found it, on these rows (restored after: the source is the caller's)
            for w in watchers:
                w.t_event = events[id(w)]
            fed = np.array([float(source.at(float(x))[0]) for x in t])
        finally:
            for w, te in saved:
                w.t_event = te
        comp, _, var = targets[0].partition(".")
        drives = DRIVES.get(var)
        offset, label = 0.0, ", ".join(targets)
        if drives is not None and drives.start:
            key = f"{comp}.{drives.start}"
            if key in starts:
                offset, label = float(starts[key]), f"{key} + {label}"
            else:
                out.notes.append(f"command on {label} plotted as the change from {key} (its value is not known)")
        name = f"command: {label}"
        out.values[name] = fed + offset
        unit = units.get(targets[0], units.get(f"{comp}.{drives.output}") if drives else None)
        if unit is not None:
            out.units[name] = unit
        out.dashed.add(name)
        series = [name]
        for target in targets:
            c, _, v = target.partition(".")
            d = DRIVES.get(v)
            column = f"{c}.{d.output}" if d is not None else ""
            if column not in names:
                derived = _luff_from_radius(rows, c) if v == "luff_command" else None
                if derived is not None:
                    out.values[derived[0]] = derived[1]
                    if unit is not None:
                        out.units[derived[0]] = unit
                    series.append(derived[0])
                continue
            shown = f"{column} - its start" if d.relative else column
            y = np.asarray(rows[column], dtype=float)
            out.values[shown] = y - y[0] if d.relative else y
            if units.get(column, unit) is not None:
                out.units[shown] = units.get(column, unit)
            series.append(shown)
        if len(series) == 1:
            out.notes.append(f"command on {label}: no output of the result shows what it drives; the command alone "
                             "is plotted")
        title = f"Operator command on {', '.join(targets)}" + (
            " beside the output it drives" if len(series) > 1 else "")
        out.groups.append((title, series))
        out.marks[title] = [(te, f"{'emergency stop' if w.label == 'emergency stop' else 'event'}: {w.condition}")
                            for w in watchers if (te := events[id(w)]) is not None]
    return out


def scene_values(spec) -> tuple[dict[str, float], dict[str, str]]:
    """(the parameter values in force in the run ``spec``, 'comp.var' -> value: its scene's defaults, its
    parameter set, its parameters; every variable's declared unit, inputs too); ({}, {}) when the scene
    cannot be read."""
    from ..errors import CraneFmuError
    from ..experiments.scene_check import interface

    try:
        scene = interface(str(spec.ssp), getattr(spec.settings, "fmus", None))
        return scene.parameter_values(spec.parameter_set, dict(spec.parameters)), dict(scene.units or {})
    except (CraneFmuError, OSError):   # a scene file no longer where it was: the inputs as fed, said so
        return {}, {}
