"""Commands started or stopped by an event on any result column (issue 37): ``when = "chassis.N3 < 10 kN"``.

A :class:`Trigger` watches the run's rows (a master observer: the master hands it the column names with
:meth:`Trigger.watch` and every row after a step) and notes the first communication point t_e where its
condition holds.  The command's sources (:class:`Triggered`, one per fed input: the value's and the rate's)
read it in ``at(t)``: the master feeds the commanded inputs at every exchange after the observers saw the
row, so the command changes at the step where the event is found, with exact values and rates from t_e on:

- ``start``: the command's profile runs from t_e (its moves' times counted from the event); before it the
  profile's start value is held;
- ``stop``: the profile runs until t_e, then the motion is brought to rest with constant deceleration over
  ``stop_ramp`` seconds (0: held where it is at once, a speed step) from the value and rate it had at t_e.

An emergency stop (``[emergency_stop]``) is a ``stop`` trigger shared by every command of the case.
"""
from __future__ import annotations

import math
import re

from ..adapter import units
from ..errors import CraneFmuError
from .expressions import evaluate, names as expression_names, parse
from .profiles import Profile

OPERATORS = ("<=", ">=", "<", ">")
ACTIONS = ("start", "stop")


class EventError(CraneFmuError):
    """A condition that cannot be read (one line)."""


def parse_condition(text: str) -> tuple[str, str, float | str]:
    """``"chassis.N3 < 10 kN"`` -> (left expression, operator, right: SI number or expression text)."""
    if not isinstance(text, str):
        raise EventError(f"when = {text!r} is not allowed: a condition \"<expression> < <value>\" (one of "
                         f"{', '.join(OPERATORS)})")
    found = re.search(r"(<=|>=|<|>)", text)
    if found is None or text.count("<") + text.count(">") != 1:
        raise EventError(f"when = {text!r} is not allowed: one comparison \"<expression> <op> <value>\", op one of "
                         f"{', '.join(OPERATORS)}")
    left, op, right = text[:found.start()].strip(), found.group(1), text[found.end():].strip()
    if not left or not right:
        raise EventError(f"when = {text!r}: both sides of {op} are needed")
    parse(left)
    if units.is_quantity(right):
        return left, op, units.quantity(right)[0]
    parse(right)
    return left, op, right


class Trigger:
    """The first row (time t_e) where ``condition`` holds; a master observer (batchable: no, it acts on each
    row).  ``values``: the parameters' values for the condition's expressions."""

    batchable = False

    def __init__(self, condition: str, values: dict | None = None, label: str = ""):
        self.condition = condition
        self.left, self.op, self.right = parse_condition(condition)
        self.values = dict(values or {})
        self.label = label or condition
        self.columns: list[str] = []
        self.t_event: float | None = None

    def watch(self, columns: list[str]) -> None:
        """The run's column names (the rows' order); refuses a condition naming no column or parameter."""
        known = set(columns) | set(self.values)
        for side in (self.left, self.right):
            if isinstance(side, str):
                unknown = [n for n in expression_names(side) if n not in known and n not in ("g", "pi", "e")]
                if unknown:
                    raise EventError(f"when = {self.condition!r}: {unknown[0]!r} is not a result column or a parameter")
        self.columns = list(columns)
        self.t_event = None

    def _holds(self, row) -> bool:
        scope = {**self.values, **dict(zip(self.columns, row.tolist() if hasattr(row, "tolist") else row))}
        a = float(evaluate(self.left, scope))
        b = float(evaluate(self.right, scope)) if isinstance(self.right, str) else self.right
        return {"<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b}[self.op]

    def simulation_initialized(self, t: float, values) -> None:
        self._see(t, values)

    def step_complete(self, t: float, h: float, values) -> None:
        self._see(t, values)

    def _see(self, t: float, values) -> None:
        if self.t_event is None and self.columns and self._holds(values):
            self.t_event = float(t)


class Triggered:
    """A command source whose ``profile`` starts, or stops, at its trigger's event (module doc)."""

    def __init__(self, profile: Profile, trigger: Trigger, action: str = "start", stop_ramp: float = 0.0):
        if action not in ACTIONS:
            raise EventError(f"action = {action!r} is not allowed: one of {', '.join(ACTIONS)}")
        if not (math.isfinite(stop_ramp) and stop_ramp >= 0):
            raise EventError(f"stop_ramp = {stop_ramp!r} s is not allowed: a finite number >= 0")
        self.profile, self.watcher, self.action, self.stop_ramp = profile, trigger, action, stop_ramp

    @property
    def before(self) -> float:
        return self.profile.before

    def taylor(self, t: float) -> tuple[float, float, float, float]:
        """(value, rate, acceleration, jerk) at t [s], as :meth:`.profiles.Profile.taylor` (so a triggered
        source can itself be started or stopped by another trigger: an emergency stop)."""
        te = self.watcher.t_event
        if self.action == "start":
            if te is None:
                return (self.profile.before, 0.0, 0.0, 0.0)
            return tuple(self.profile.taylor(t - te))
        if te is None or t < te:
            return tuple(self.profile.taylor(t))
        x, v, _, _ = self.profile.taylor(te)
        s = t - te
        if self.stop_ramp == 0.0 or v == 0.0:
            return (x, 0.0, 0.0, 0.0)
        a = -v / self.stop_ramp
        if s >= self.stop_ramp:
            return (x + v * self.stop_ramp / 2, 0.0, 0.0, 0.0)
        return (x + s * (v + s * a / 2), v + a * s, a, 0.0)

    def at(self, t: float) -> tuple[float, float, float]:
        """The master's source contract: (value, rate, curvature) at t [s]."""
        return self.taylor(t)[:3]

    def watchers(self) -> list[Trigger]:
        """Every trigger this source follows (its own, and those of the sources it wraps)."""
        inner = self.profile.watchers() if isinstance(self.profile, Triggered) else []
        return [self.watcher, *inner]


class RateOf:
    """The rate of a triggered source, for a velocity input fed beside its position (``rate_inputs``)."""

    def __init__(self, source: Triggered):
        self.source = source

    def at(self, t: float) -> tuple[float, float, float]:
        return self.source.taylor(t)[1:]

    def watchers(self) -> list[Trigger]:
        return self.source.watchers()
