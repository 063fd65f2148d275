"""Experiment files (TOML, read with the standard library's tomllib) into checked :class:`Case` objects.

One file is one experiment: a scene, parameter changes, run settings, commands and assertions; with
``[cases.NAME]`` tables it is a base whose cases each inherit every key and override what they give
(``set`` merged key by key, ``commands`` replaced when a case gives any, assertions added, a case's
assertion of a base assertion's name replacing it).  Only the cases run then; without cases the
experiment runs once, as case ``base``.  The format: docs/experiments.md.

Every error is one :class:`ExperimentError` line 'FILE:LINE: key: what is wrong' (the line where the
file's text shows it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from pathlib import Path

from ..adapter import units
from ..errors import CraneFmuError
from .lines import Lines
from .metrics import REGISTRY

try:
    import tomllib
except ModuleNotFoundError:   # Python 3.10: the same parser as the tomli package
    import tomli as tomllib


class ExperimentError(CraneFmuError):
    """An experiment file that cannot be read or does not fit its scene (one line: file, line, key)."""


WHEN = ("always", "finally", "at", "during")
METRICS = ("max", "min", "max_abs", "mean", "first_crossing", "smallest_peak", "dynamic_factor", "frequency",
           "damping", *REGISTRY)
COMMAND_KINDS = ("hoist", "lower", "telescope", "luff", "slew", "travel", "setpoint", "table")
BOOM_MOTIONS = ("telescope", "luff", "slew")   # kinds bound to a boom's command input when no inputs are given
CASE_KEYS = {"description", "scene", "parameter_set", "set", "commands", "assert", "expect_stop", "emergency_stop"}
EXPECT_STOP_KEYS = {"reason", "during"}
TOP_KEYS = CASE_KEYS | {"name", "cases"}
ASSERT_KEYS = {"name", "column", "value", "always", "finally", "at", "during", "metric", "level", "static", "mode",
               "n_modes", "min", "max", "equals", "rel", "abs", "source", "description"}
COMMAND_KEYS = {"kind", "inputs", "rate_inputs", "initial", "moves", "table", "interpolation", "shaper",
                "frequency", "damping", "description", "when", "action", "stop_ramp"}
EMERGENCY_KEYS = {"when", "ramp", "description"}
MOVE_KEYS = {"start", "to", "speed", "accel_time", "decel_time", "jerk_time"}


@dataclass(frozen=True)
class CommandSpec:
    """One operator command as written: a profile (``moves`` from ``initial``, or a ``table``) fed
    into ``inputs``, its rate into ``rate_inputs``, optionally through an input ``shaper``."""

    inputs: tuple[str, ...]
    where: str                                  # FILE:LINE of the command
    keys: dict = field(default_factory=dict)    # key -> FILE:LINE where it is written
    kind: str = "setpoint"
    rate_inputs: tuple[str, ...] = ()
    initial: float = 0.0
    moves: tuple[dict, ...] = ()
    table: tuple[tuple[float, float], ...] = ()
    interpolation: str = "linear"
    shaper: str | None = None
    frequency: str | float | None = None         # Hz, a number or an expression of parameters
    damping: str | float = 0.0
    offset: float = 0.0                          # subtracted from the profile (a boom motion's start, .crane_commands)
    quantities: dict = field(default_factory=dict)   # "to", "initial", "speed" -> the unit written (SI inside)
    when: str | None = None                      # an event condition on result columns (.events)
    action: str = "start"                        # what the event does: start the profile, or stop the motion
    stop_ramp: float = 0.0                       # s: action stop (and an emergency stop) brings it to rest over this


@dataclass(frozen=True)
class AssertionSpec:
    """One assertion as written (docs/experiments.md lists the keys)."""

    name: str
    column: str                                  # a result column, or (expression) an expression of columns
    where: str
    expression: bool = False
    when: str = "always"
    at: float | None = None
    during: tuple[float, float] | None = None
    metric: str | None = None
    level: float | None = None
    static: str | float | None = None
    mode: int = 1
    n_modes: int = 1
    min: str | float | None = None
    max: str | float | None = None
    equals: str | float | None = None
    rel: float | None = None
    abs: float | None = None
    source: str = ""                             # where the limit comes from (a paper's value, a derivation)
    keys: dict = field(default_factory=dict)     # key -> FILE:LINE where it is written
    quantities: dict = field(default_factory=dict)   # limit key -> the unit written ("15 kN": SI inside, "kN")


@dataclass(frozen=True)
class ExpectedStop:
    """``expect_stop = {reason = "chassis.tipping", during = [t1, t2]}``: the run is to end early, for a
    reason whose text names ``reason`` (a stop condition's column), at a time in [after, before] s."""

    reason: str
    after: float
    before: float
    where: str = ""


@dataclass(frozen=True)
class Case:
    """One run of an experiment and its assertions."""

    experiment: str
    name: str
    file: Path
    scene: str
    parameter_set: str | None = None
    parameters: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    commands: tuple[CommandSpec, ...] = ()
    assertions: tuple[AssertionSpec, ...] = ()
    where: str = ""                               # FILE:LINE of the case's table (of the file for the base)
    expect_stop: ExpectedStop | None = None       # the run is to stop early (else an early stop fails it)
    emergency_stop: tuple[str, float, str] | None = None   # (condition, ramp [s], FILE:LINE): stops every command
    keys: dict = field(default_factory=dict)      # key of the case (scene, set, a run setting) -> FILE:LINE


def load(path: str | Path) -> list[Case]:
    """The cases of the experiment file ``path`` (checked for form; :func:`.scene_check.check` checks
    them against their scene)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise ExperimentError(f"{path}: cannot be read: {err.strerror or err}") from None
    except UnicodeDecodeError:
        raise ExperimentError(f"{path}: is not UTF-8 text (a TOML file)") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ExperimentError(f"{path}: malformed TOML: {err}") from None
    lines = Lines(path, text)
    _known(data, TOP_KEYS, lines, "")
    name = data.get("name", path.stem)
    if not isinstance(name, str) or not name:
        raise ExperimentError(f"{lines.at('', 'name')}: name = {name!r} must be a non-empty string")
    base = _case_fields(data, lines, "")
    cases = data.get("cases")
    if cases is None:
        return [_make(name, "base", path, base, str(path), lines)]
    if not isinstance(cases, dict) or not cases:
        raise ExperimentError(f"{lines.at('', 'cases')}: cases must be tables [cases.NAME]")
    out = []
    for case_name, body in cases.items():
        table = f"cases.{case_name}"
        if not isinstance(body, dict):
            raise ExperimentError(f"{lines.at('cases', case_name)}: cases.{case_name} must be a table")
        _known(body, CASE_KEYS, lines, table)
        own = _case_fields(body, lines, table)
        merged = dict(base)
        for key, value in own.items():
            if key == "parameters":
                merged[key] = {**base.get(key, {}), **value}
            elif key in ("settings", "keys"):
                merged[key] = {**base.get(key, {}), **value}
            elif key == "assertions":
                replaced = {a.name for a in value}
                merged[key] = tuple(a for a in base.get(key, ()) if a.name not in replaced) + value
            else:
                merged[key] = value
        out.append(_make(name, case_name, path, merged, lines.at(table), lines))
    return out


def _make(experiment: str, case: str, path: Path, values: dict, where: str, lines: Lines) -> Case:
    if "scene" not in values:
        raise ExperimentError(f"{where}: scene: missing (a shipped scene's name, or a path to an .ssp file or a "
                              "scene directory)")
    names = [a.name for a in values.get("assertions", ())]
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        second = [a for a in values.get("assertions", ()) if a.name == dup][-1]
        raise ExperimentError(f"{second.keys.get('name', second.where)}: name: two assertions of case {case} are "
                              f"named {dup!r}")
    return Case(experiment, case, path, values["scene"], values.get("parameter_set"), values.get("parameters", {}),
                values.get("settings", {}), values.get("commands", ()), values.get("assertions", ()), where,
                expect_stop=values.get("expect_stop"), keys=values.get("keys", {}),
                emergency_stop=values.get("emergency_stop"))


def _known(table: dict, allowed: set[str], lines: Lines, name: str) -> None:
    from ..master.settings import Settings

    settings = {f.name for f in fields(Settings)}
    for key in table:
        if key not in allowed and key not in settings:
            raise ExperimentError(f"{lines.at(name, key)}: {key}: unknown key; allowed "
                                  f"{', '.join(sorted(allowed))} and the run settings "
                                  f"({', '.join(sorted(settings))})")


def _case_fields(data: dict, lines: Lines, table: str) -> dict:
    """The case keys of one table (the top or [cases.NAME]) as Case fields."""
    from ..master.settings import Settings

    out: dict = {"keys": {key: lines.at(table, key) for key in data if key != "cases"}}
    prefix = f"{table}." if table else ""
    if "scene" in data:
        scene = data["scene"]
        if isinstance(scene, dict):
            raise ExperimentError(f"{lines.at(table, 'scene')}: scene: a scene composed inline is not read yet: give "
                                  "a shipped scene's name, an .ssp file, a scene directory or a scene source .toml (docs/experiments.md)")
        if not isinstance(scene, str) or not scene:
            raise ExperimentError(f"{lines.at(table, 'scene')}: scene = {scene!r} must be a name or a path")
        out["scene"] = _scene_reference(scene, lines.path)
    if "parameter_set" in data:
        out["parameter_set"] = _string(data["parameter_set"], lines, table, "parameter_set")
    if "set" in data:
        values = data["set"]
        if not isinstance(values, dict):
            raise ExperimentError(f"{lines.at(table, 'set')}: set must be a table {{\"component.variable\" = value}}")
        for key, value in values.items():
            comp, _, var = key.partition(".")
            if not comp or not var or isinstance(value, (dict, list)):
                raise ExperimentError(f"{lines.at(table, 'set')}: set: {key!r} = {value!r} is not allowed: "
                                      "\"component.variable\" = a number, a boolean or a switch's name")
            if isinstance(value, float) and not math.isfinite(value):
                raise ExperimentError(f"{lines.at(table, 'set')}: set: {key} = {value!r} is not allowed: a finite "
                                      "number")
        out["parameters"] = dict(values)
    settings = {f.name for f in fields(Settings)}
    given = {k: v for k, v in data.items() if k in settings}
    for key, value in given.items():
        kind = next(f.metadata.get("type") for f in fields(Settings) if f.name == key)
        if kind in (float, int) and (isinstance(value, (str, bool)) or not isinstance(value, (int, float))):
            raise ExperimentError(f"{lines.at(table, key)}: {key} = {value!r} is not allowed: a number"
                                  + (" (without quotes)" if isinstance(value, str) else ""))
    if isinstance(given.get("stop_when"), str):   # as on the command line: "a,b", or "none" (run on)
        from ..master.settings import _comma_list

        given["stop_when"] = _comma_list(given["stop_when"])
    if given:
        out["settings"] = given
    if "expect_stop" in data:
        out["expect_stop"] = _expect_stop(data["expect_stop"], lines, table)
    if "emergency_stop" in data:
        out["emergency_stop"] = _emergency_stop(data["emergency_stop"], lines, table)
    if "commands" in data:
        items = _tables(data["commands"], lines, table, "commands")
        out["commands"] = tuple(_command(c, lines, f"{prefix}commands", k) for k, c in enumerate(items))
    if "assert" in data:
        items = _tables(data["assert"], lines, table, "assert")
        out["assertions"] = tuple(_assertion(a, lines, f"{prefix}assert", k) for k, a in enumerate(items))
    return out


def _condition(value, where: str, key: str = "when") -> str:
    from .events import EventError, parse_condition

    try:
        parse_condition(value)
    except CraneFmuError as err:
        raise ExperimentError(f"{where}: {key}: {err}") from None
    return value


def _known_keys(value: dict, allowed: set[str], where: str, name: str) -> None:
    """Refuse the first key of the inline table ``name`` (at ``where``) that is not in ``allowed``."""
    unknown = set(value) - allowed
    if unknown:
        raise ExperimentError(f"{where}: {name}: {sorted(unknown)[0]}: unknown key; allowed {', '.join(sorted(allowed))}")


def _emergency_stop(value, lines: Lines, table: str) -> tuple[str, float, str]:
    """``emergency_stop = {when = "chassis.N3 < 10 kN", ramp = "0.5 s"}``: every command stops at the event."""
    where = lines.at(table, "emergency_stop")
    if not isinstance(value, dict) or "when" not in value:
        raise ExperimentError(f"{where}: emergency_stop = {value!r} is not allowed: a table {{when = \"<column> < "
                              "<value>\", ramp = \"0.5 s\"}} (ramp: the time to rest, default 0)")
    _known_keys(value, EMERGENCY_KEYS, where, "emergency_stop")
    ramp = _number(value.get("ramp", 0.0), lines, table, "emergency_stop", unit="s", name="ramp")
    if ramp < 0:
        raise ExperimentError(f"{where}: emergency_stop: ramp = {ramp:g} s is not allowed: >= 0")
    return _condition(value["when"], where, "emergency_stop: when"), ramp, where


def _expect_stop(value, lines: Lines, table: str) -> ExpectedStop:
    where = lines.at(table, "expect_stop")
    if not isinstance(value, dict):
        raise ExperimentError(f"{where}: expect_stop = {value!r} is not allowed: a table "
                              "{reason = \"component.variable\", during = [t1, t2]}")
    _known_keys(value, EXPECT_STOP_KEYS, where, "expect_stop")
    if "reason" not in value or "during" not in value:
        raise ExperimentError(f"{where}: expect_stop needs reason = the stop condition's column (e.g. "
                              "\"chassis.tipping\") and during = [t1, t2] s, the window it is to stop in")
    reason = _string(value["reason"], lines, table, "expect_stop")
    span = value["during"]
    if not isinstance(span, list) or len(span) != 2:
        raise ExperimentError(f"{where}: expect_stop: during = {span!r} is not allowed: [t1, t2] s")
    t1, t2 = (_number(x, lines, table, "expect_stop", unit="s", name="during") for x in span)
    if not 0 <= t1 <= t2:
        raise ExperimentError(f"{where}: expect_stop: during = {span!r} is not allowed: 0 <= t1 <= t2")
    return ExpectedStop(reason, t1, t2, where)


def _scene_reference(scene: str, path: Path) -> str:
    """A name as it is; a path (has a '/' or ends in .ssp or .toml) relative to the experiment file's folder."""
    if "/" in scene or scene.endswith((".ssp", ".toml")):
        return str((path.parent / scene).resolve())
    return scene


def _tables(value, lines: Lines, table: str, key: str) -> list[dict]:
    if isinstance(value, dict):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise ExperimentError(f"{lines.at(table, key)}: {key} must be tables [[{key}]]")
    return value


def _string(value, lines: Lines, table: str, key: str) -> str:
    if not isinstance(value, str) or not value:
        raise ExperimentError(f"{lines.at(table, key)}: {key} = {value!r} must be a non-empty string")
    return value


def _number(value, lines: Lines, table: str, key: str, index: int | None = None, expression: bool = False,
            unit: str | None = None, found: dict | None = None, name: str | None = None):
    """A finite number (or, with ``expression``, the text of an expression, checked for form).

    A string ``"NUMBER UNIT"`` (``"15 kN"``, ``"90 deg"``, ``"0.5 s"``; :func:`cranefmu.adapter.units.quantity`) is
    converted to SI: checked against ``unit`` when the key's unit is known here, else recorded in ``found``
    (``name`` -> the unit written) for the scene check, which knows the column's or input's unit."""
    name = name or key
    if isinstance(value, str) and units.is_quantity(value):
        number, written = units.quantity(value)
        if unit is not None and not units.same_dimension(written, unit):
            raise ExperimentError(f"{lines.at(table, key, index)}: {name} = {value!r} is not allowed: {name} is in "
                                  f"{unit}, {written!r} is not")
        if found is not None:
            found[name] = written
        return number
    if expression and isinstance(value, str):
        from .expressions import parse

        try:
            parse(value)
        except CraneFmuError as err:
            raise ExperimentError(f"{lines.at(table, key, index)}: {key}: {err}") from None
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        what = "a number or an expression" if expression else "a finite number"
        raise ExperimentError(f"{lines.at(table, key, index)}: {key} = {value!r} is not allowed: {what}")
    return float(value)


def _names(value, lines: Lines, table: str, key: str, index: int) -> tuple[str, ...]:
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, list) or not items or not all(isinstance(v, str) and "." in v for v in items):
        raise ExperimentError(f"{lines.at(table, key, index)}: {key} = {value!r} is not allowed: "
                              "\"component.variable\" or a list of them")
    return tuple(items)


def _item(d: dict, allowed: set[str], what: str, lines: Lines, table: str, k: int) -> dict:
    """The fields every item (a command, an assertion) has: where it is and where each key is; an
    unknown key refused."""
    for key in d:
        if key not in allowed:
            raise ExperimentError(f"{lines.at(table, key, k)}: {key}: unknown key of {what}; allowed "
                                  f"{', '.join(sorted(allowed))}")
    return {"where": lines.at(table, None, k), "keys": {key: lines.at(table, key, k) for key in d}}


def _move_value(value, lines: Lines, table: str, k: int, name: str, found: dict, key: str = "moves") -> float:
    """A move's ``start``/``to``/``speed``/``accel_time`` (or the command's ``initial``): a number in the
    target's SI unit, a quantity (``"90 deg"``, ``"0.2 m/s"``; times in s) or an expression of constants
    (``"radians(90)"``)."""
    time_unit = "s" if name in ("start", "accel_time", "decel_time", "jerk_time") else None
    if isinstance(value, str) and not units.is_quantity(value):
        from .expressions import evaluate

        try:
            return float(evaluate(value, {}))
        except CraneFmuError as err:
            raise ExperimentError(f"{lines.at(table, key, k)}: {name}: {err}") from None
    return _number(value, lines, table, key, k, unit=time_unit, found=None if time_unit else found, name=name)


def _command(c: dict, lines: Lines, table: str, k: int) -> CommandSpec:
    kw = _item(c, COMMAND_KEYS, "a command", lines, table, k)
    found: dict = {}
    kw["quantities"] = found
    where = kw["where"]
    kind = c.get("kind", "table" if "table" in c else "setpoint")
    if kind not in COMMAND_KINDS:
        raise ExperimentError(f"{lines.at(table, 'kind', k)}: kind = {kind!r} is not allowed: one of "
                              f"{', '.join(COMMAND_KINDS)}")
    kw["kind"] = kind
    if "inputs" in c:
        kw["inputs"] = _names(c["inputs"], lines, table, "inputs", k)
    elif kind in BOOM_MOTIONS:   # bound to the boom's command input (.crane_commands)
        kw["inputs"] = ()
    else:
        raise ExperimentError(f"{where}: inputs: missing (the \"component.variable\" the command feeds)")
    if "rate_inputs" in c:
        kw["rate_inputs"] = _names(c["rate_inputs"], lines, table, "rate_inputs", k)
    if ("moves" in c) == ("table" in c):
        raise ExperimentError(f"{where}: a command needs moves = [...] or table = ... (one of them)")
    if "moves" in c:
        moves = _tables(c["moves"], lines, table, "moves")
        checked = []
        for m in moves:
            unknown = set(m) - MOVE_KEYS
            missing = {"to", "speed"} - set(m)
            if unknown or missing:
                raise ExperimentError(f"{lines.at(table, 'moves', k)}: moves: {sorted(unknown or missing)[0]}: "
                                      f"{'unknown key' if unknown else 'missing'}; a move has "
                                      f"{', '.join(sorted(MOVE_KEYS))} (start, accel_time and jerk_time default 0, "
                                      "decel_time accel_time)")
            move = {key: _move_value(m.get(key, 0.0), lines, table, k, key, found)
                    for key in ("start", "to", "speed", "accel_time")}
            for key in ("decel_time", "jerk_time"):   # only where given: the symmetric ramp's arithmetic otherwise
                if key in m:
                    move[key] = _move_value(m[key], lines, table, k, key, found)
            if move["start"] < 0:
                raise ExperimentError(f"{lines.at(table, 'moves', k)}: moves: start = {move['start']:g} s is not "
                                      "allowed: a move starts at t >= 0 (the run starts at 0)")
            checked.append(move)
        kw["moves"] = tuple(checked)
        kw["initial"] = _move_value(c.get("initial", 0.0), lines, table, k, "initial", found, key="initial")
    else:
        kw["table"] = _table_points(c["table"], lines, table, k)
        kw["interpolation"] = c.get("interpolation", "linear")
        if kw["interpolation"] not in ("linear", "cubic"):
            raise ExperimentError(f"{lines.at(table, 'interpolation', k)}: interpolation = "
                                  f"{kw['interpolation']!r} is not allowed: linear or cubic")
    if "shaper" in c:
        from .profiles import SHAPERS

        if c["shaper"] not in SHAPERS:
            raise ExperimentError(f"{lines.at(table, 'shaper', k)}: shaper = {c['shaper']!r} is not allowed: "
                                  f"one of {', '.join(SHAPERS)}")
        if "frequency" not in c:
            raise ExperimentError(f"{lines.at(table, 'shaper', k)}: shaper needs frequency = the mode's [Hz] "
                                  "(a number or an expression of parameters)")
        kw["shaper"] = c["shaper"]
        kw["frequency"] = _number(c["frequency"], lines, table, "frequency", k, expression=True)
        kw["damping"] = _number(c.get("damping", 0.0), lines, table, "damping", k, expression=True)
    if "when" in c:
        kw["when"] = _condition(c["when"], lines.at(table, "when", k))
        action = c.get("action", "start")
        if action not in ("start", "stop"):
            raise ExperimentError(f"{lines.at(table, 'action', k)}: action = {action!r} is not allowed: start (the "
                                  "profile runs from the event) or stop (the motion comes to rest at the event)")
        kw["action"] = action
        if "stop_ramp" in c:
            kw["stop_ramp"] = _number(c["stop_ramp"], lines, table, "stop_ramp", k, unit="s")
            if kw["stop_ramp"] < 0 or action != "stop":
                raise ExperimentError(f"{lines.at(table, 'stop_ramp', k)}: stop_ramp is not allowed here: a time "
                                      ">= 0 s, with action = \"stop\"")
    elif "action" in c or "stop_ramp" in c:
        raise ExperimentError(f"{lines.at(table, 'action' if 'action' in c else 'stop_ramp', k)}: "
                              f"{'action' if 'action' in c else 'stop_ramp'} needs when = \"<condition>\"")
    return CommandSpec(**kw)


def _table_points(value, lines: Lines, table: str, k: int) -> tuple[tuple[float, float], ...]:
    """Inline [[t, v], ...] or a CSV file (t, value per line; a header line and # comments skipped)."""
    where = lines.at(table, "table", k)
    if isinstance(value, str):
        path = (lines.path.parent / value)
        try:
            data = path.read_bytes()
            rows = [r.split("#")[0].strip() for r in data.decode("utf-8").splitlines()]
        except OSError as err:
            raise ExperimentError(f"{where}: table = {value!r}: cannot be read: {err.strerror or err}") from None
        except UnicodeDecodeError as err:   # a binary file: the line of the first byte that is not text
            line = data.count(b"\n", 0, err.start) + 1
            raise ExperimentError(f"{where}: table {path}:{line}: byte {data[err.start]:#04x} is not UTF-8 text "
                                  "(a CSV of 't, value' lines)") from None
        points = []
        for n, row in enumerate(rows, 1):
            if not row:
                continue
            parts = row.replace(";", ",").split(",")
            try:
                points.append((float(parts[0]), float(parts[1])))
            except (ValueError, IndexError):
                if points or n > 1:
                    raise ExperimentError(f"{where}: table {path}:{n}: {row!r} is not 't, value'") from None
        value = points
    if not isinstance(value, list) or len(value) < 2:
        raise ExperimentError(f"{where}: table must hold at least 2 points [t, value] (inline or a CSV file)")
    out = []
    for p in value:
        if not isinstance(p, (list, tuple)) or len(p) != 2:
            raise ExperimentError(f"{where}: table: {p!r} is not a point [t, value]")
        out.append((_number(p[0], lines, table, "table", k), _number(p[1], lines, table, "table", k)))
    if any(b[0] <= a[0] for a, b in zip(out, out[1:])):
        raise ExperimentError(f"{where}: table: the times must increase")
    return tuple(out)


def _assertion(a: dict, lines: Lines, table: str, k: int) -> AssertionSpec:
    kw = _item(a, ASSERT_KEYS, "an assertion", lines, table, k)
    found: dict = {}
    kw["quantities"] = found
    where = kw["where"]
    if ("column" in a) == ("value" in a):
        raise ExperimentError(f"{where}: an assertion needs column = \"component.variable\" (a result column) "
                              "or value = an expression of columns and parameters (one of them)")
    if "column" in a:
        kw["column"] = _string(a["column"], lines, table, "column")
    else:
        kw["column"] = _number(_string(a["value"], lines, table, "value"), lines, table, "value", k, expression=True)
        kw["expression"] = True
    default = f"{kw['column'].replace('.', '_')}_{k + 1}" if "column" in a else f"value_{k + 1}"
    kw["name"] = _string(a.get("name", default), lines, table, "name")
    if not kw["name"].isidentifier():
        raise ExperimentError(f"{lines.at(table, 'name', k)}: name = {kw['name']!r} is not allowed: letters, digits "
                              "and _ (another case's limit names it case.name)")
    chosen = [w for w in WHEN if w in a]
    if len(chosen) > 1:
        raise ExperimentError(f"{lines.at(table, chosen[1], k)}: {chosen[1]}: an assertion takes one of "
                              f"{', '.join(WHEN)}, not {' and '.join(chosen)}")
    when = chosen[0] if chosen else "always"
    kw["when"] = when
    if when in ("always", "finally") and when in a and a[when] is not True:
        raise ExperimentError(f"{lines.at(table, when, k)}: {when} = {a[when]!r} is not allowed: true")
    if when == "at":
        kw["at"] = _number(a["at"], lines, table, "at", k, unit="s")
    if when == "during":
        span = a["during"]
        if not isinstance(span, list) or len(span) != 2:
            raise ExperimentError(f"{lines.at(table, 'during', k)}: during = {span!r} is not allowed: [t1, t2]")
        t1, t2 = (_number(x, lines, table, "during", k, unit="s") for x in span)
        if not t2 >= t1:
            raise ExperimentError(f"{lines.at(table, 'during', k)}: during = {span!r}: t2 must be >= t1")
        kw["during"] = (t1, t2)
    metric = a.get("metric")
    if metric is not None:
        if metric not in METRICS:
            raise ExperimentError(f"{lines.at(table, 'metric', k)}: metric = {metric!r} is not allowed: one of "
                                  f"{', '.join(METRICS)}")
        if when in ("at", "finally"):
            raise ExperimentError(f"{lines.at(table, 'metric', k)}: metric {metric} is taken over the run "
                                  f"(always) or a window (during), not with {when}")
        kw["metric"] = metric
        if metric == "first_crossing":
            if "level" not in a:
                raise ExperimentError(f"{lines.at(table, 'metric', k)}: metric first_crossing needs level = the "
                                      "value crossed")
            kw["level"] = _number(a["level"], lines, table, "level", k, found=found)
        if metric in ("frequency", "damping"):
            for key in ("mode", "n_modes"):
                if key in a:
                    if isinstance(a[key], bool) or not isinstance(a[key], int) or a[key] < 1:
                        raise ExperimentError(f"{lines.at(table, key, k)}: {key} = {a[key]!r} is not allowed: "
                                              "an integer >= 1")
                    kw[key] = a[key]
            if kw.get("mode", 1) > kw.get("n_modes", 1):
                kw["n_modes"] = kw["mode"]
        if "static" in a:
            if metric != "dynamic_factor":
                raise ExperimentError(f"{lines.at(table, 'static', k)}: static is a key of metric dynamic_factor")
            kw["static"] = _number(a["static"], lines, table, "static", k, expression=True)
    for key in ("level", "mode", "n_modes"):
        if key in a and key not in kw:
            raise ExperimentError(f"{lines.at(table, key, k)}: {key} is not a key of "
                                  f"{'metric ' + metric if metric else 'an assertion without a metric'}")
    for key in ("min", "max", "equals"):
        if key in a:
            kw[key] = _number(a[key], lines, table, key, k, expression=True, found=found)
    for key in ("rel", "abs"):
        if key in a:
            kw[key] = _number(a[key], lines, table, key, k, unit="1" if key == "rel" else None, found=found)
            if kw[key] < 0:
                raise ExperimentError(f"{lines.at(table, key, k)}: {key} = {a[key]!r} must be >= 0")
    if "equals" in kw:
        if "min" in kw or "max" in kw:
            raise ExperimentError(f"{lines.at(table, 'equals', k)}: equals takes rel or abs, not min or max")
        if "rel" not in kw and "abs" not in kw:
            raise ExperimentError(f"{lines.at(table, 'equals', k)}: equals needs a tolerance: rel = ... or abs = ...")
    elif "min" not in kw and "max" not in kw:
        raise ExperimentError(f"{where}: the assertion {kw['name']!r} has no limit: give min, max or equals")
    elif "rel" in kw or "abs" in kw:
        raise ExperimentError(f"{lines.at(table, 'rel' if 'rel' in kw else 'abs', k)}: rel and abs go with equals")
    if "source" in a:
        kw["source"] = _string(a["source"], lines, table, "source")
    return AssertionSpec(**kw)
