"""Commanded inputs: a source inside the master that feeds an unconnected FMU input over time.

A :class:`Command` binds a source to one input ``component.variable``.  A source is any object with
``at(t) -> (value, rate, curvature)`` (SI units of the input, per second, per second squared): the
master knows nothing of what it commands.  At every communication point t (each exchange, see
:meth:`.coupled.Coupling.exchange`) :class:`CommandFeed` sets the input to the source's exact value at
t and, where the FMU offers them, ``<input>_dt`` and ``<input>_dt2`` to its exact rate and curvature,
so that over the coming step the FMU follows value + s rate + s^2/2 curvature: a profile that is a
polynomial of degree <= 2 between its breakpoints is followed exactly between communication points
that do not straddle a breakpoint, and every communication point gets the exact value.  A component
just stepped to t + h gets its commanded values at t + h at once (:meth:`CommandFeed.after_step`), so
outputs read inside a macro step's iterations (implicit groups, iterative, Gauss-Seidel) see the
command where the FMU is.  At the start the value joins the start values, so the initialization
settles with it.
"""
from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import Protocol

from ..errors import SceneError


class Source(Protocol):
    def at(self, t: float) -> tuple[float, float, float]:
        """(value, first and second time derivative) at t [s]."""


@dataclass(frozen=True)
class Command:
    """``source`` feeds the input ``target`` ('component.variable')."""

    target: str
    source: Source


class CommandFeed:
    """The commands of one run, bound to the FMUs of a :class:`~.coupled.Coupling`."""

    def __init__(self, system, commands: tuple[Command, ...] | list[Command]):
        self.bound = []
        connected = {f"{c.dst}.{c.dst_var}": f"{c.src}.{c.src_var}" for c in system.scene.connections}
        for cmd in commands:
            comp, var = _split(cmd.target, system)
            if cmd.target in connected:
                raise SceneError(f"command on {cmd.target} is not allowed: that input is connected to "
                                 f"{connected[cmd.target]}; command an unconnected input")
            by_name = {v.name: v for v in comp.md.modelVariables}
            v = by_name.get(var)
            if v is None:
                raise SceneError(f"command on {cmd.target}: component {comp.name} has no variable {var!r}")
            if v.causality != "input" or v.type != "Real":
                raise SceneError(f"command on {cmd.target} is not allowed: it is a {v.type} {v.causality}; "
                                 "a command feeds a Real input")
            rates = [by_name.get(var + suffix) for suffix in ("_dt", "_dt2")]
            vrs = [v.valueReference] + ([r.valueReference for r in rates] if all(rates) else [])
            self.bound.append((comp, var, vrs, cmd.source))
        # one fmi2SetReal per component a step: its commanded inputs' values and rates side by side
        self._writes = []
        for comp in dict.fromkeys(b[0] for b in self.bound):
            mine = [(vrs, source) for c, _, vrs, source in self.bound if c is comp]
            n = sum(len(vrs) for vrs, _ in mine)
            self._writes.append((comp, (ctypes.c_uint * n)(*[vr for vrs, _ in mine for vr in vrs]),
                                 (ctypes.c_double * n)(), n, [(len(vrs), source) for vrs, source in mine]))
        self._of = {w[0]: w for w in self._writes}

    def start_values(self, t: float) -> dict[tuple[str, str], float]:
        """(component, variable) -> the commanded value at t, for the start values."""
        return {(comp.name, var): float(source.at(t)[0]) for comp, var, _, source in self.bound}

    def feed(self, t: float) -> None:
        """Set every commanded input (and its rates, where offered) to its source's values at t."""
        for write in self._writes:
            _write(write, t)

    def writes(self) -> list[tuple]:
        """The fmi2SetReal calls of one time, one per component that has commanded inputs, in the order
        :meth:`feed` makes them: (component, ctypes value references, count); the values are
        :meth:`fill`'s, side by side in that order (the compiled exchange, :mod:`.kernel.plan`)."""
        return [(comp, vrs, n) for comp, vrs, _, n, _ in self._writes]

    def fill(self, t: float, out) -> None:
        """Every commanded value at t (value, then rate and curvature where offered; write by write as
        :meth:`writes` lists them) into ``out`` (numbers as :meth:`feed` sets them)."""
        at = 0
        for *_, sources in self._writes:
            for count, source in sources:
                out[at:at + count] = [float(x) for x in source.at(t)][:count]
                at += count

    def after_step(self, comp, t: float) -> None:
        """Set the commanded inputs of ``comp``, just stepped to t, to their values at t: an output read
        before the next exchange (an implicit group's or an iteration's image, Gauss-Seidel's pass-on)
        is then the one at t, as a motion law inside the FMU gives it, not one of the step's start."""
        write = self._of.get(comp)
        if write is not None:
            _write(write, t)


def _write(write, t: float) -> None:
    """One component's commanded inputs set to their sources' values at t (one fmi2SetReal)."""
    comp, vrs, values, n, sources = write
    at = 0
    for count, source in sources:
        values[at:at + count] = [float(x) for x in source.at(t)][:count]
        at += count
    comp.write(vrs, n, values)
    comp.fresh = False


def _split(target: str, system):
    comp_name, _, var = str(target).partition(".")
    comp = system.by_name.get(comp_name)
    if comp is None or not var:
        raise SceneError(f"command on {target!r}: write component.variable with a component of "
                         f"{system.scene.name}: {', '.join(sorted(system.by_name))}")
    return comp, var


def event_watchers(commands, columns: list[str]) -> list:
    """The observers that command sources ask for (a source with ``watchers()``: one started or stopped by
    an event on the run's rows), each told the run's ``columns`` once (``watch``); one per watcher object."""
    found = {}
    for cmd in commands or ():
        for w in (cmd.source.watchers() if hasattr(cmd.source, "watchers") else ()):
            found.setdefault(id(w), w)
    for w in found.values():
        w.watch(list(columns))
    return list(found.values())
