"""The master loop: an algorithm steps, a step controller judges, observers see each accepted step.

The shape of libcosim's execution (an *algorithm* decides how far the FMUs step and when values
move; *observers* see the results and never steer) with scipy OdeSolver's single contract: every
algorithm implements :class:`~.algorithms.Algorithm`, every step controller the methods of
:class:`StepControl`, every observer :class:`Observer`.  An observer may end the run as a result
by returning a reason (a stop condition), or fail it by raising :class:`~cranefmu.errors.SimulationError`
(an alarm); the row it fails on is recorded first (the recorder is the first observer).
"""
from __future__ import annotations

from typing import Protocol

import numpy as np

from .algorithms import Algorithm
from .step_control import FixedSteps


class Observer(Protocol):
    """``values``: the row, an array the loop reuses for the next row (copy what you keep)."""

    def simulation_initialized(self, t: float, values: np.ndarray) -> str | None:
        """The row at the start time [s]; a reason to stop at once, or None."""

    def step_complete(self, t: float, h: float, values: np.ndarray) -> str | None:
        """The row after an accepted step of h ending at t [s]; a reason to stop, or None."""


class StepControl(Protocol):
    rolls_back: bool   # a step may be rejected: the FMUs' state is saved before each step

    def propose(self, t: float) -> float | None: ...                  # next step from t, None: done
    def prepare(self, t: float, h: float, algorithm: Algorithm) -> None: ...
    def judge(self, t: float, h: float, algorithm: Algorithm) -> bool: ...  # accept the step taken?
    def advance(self, t: float, h: float) -> float: ...               # the time the step reached
    def accepted(self, h: float) -> None: ...                         # after the observers: next h


def march(system, algorithm: Algorithm, control: StepControl, sample, observers: list[Observer],
          t: float) -> str:
    """Step from t until the controller is done or an observer stops the run; returns why it stopped
    ('' at the end).  ``sample(h)`` gives the row of every output after a step of h (None: start)."""
    reason = _first(o.simulation_initialized(t, sample(None)) for o in observers)
    stats = system.stats
    # a controller that never rejects nor prepares (fixed steps) and an algorithm without rollback
    # step directly (what _attempt does for them, without its calls)
    plain = not control.rolls_back and type(control).prepare is FixedSteps.prepare \
        and type(control).judge is FixedSteps.judge
    while not reason and (h := control.propose(t)) is not None:
        if plain and not algorithm.needs_snapshot:
            iterations = algorithm.step(t, h, None)
        else:
            iterations = _attempt(system, algorithm, control, t, h)
            if iterations is None:
                continue
        t = control.advance(t, h)
        _count(stats, h, iterations)
        row = sample(h)
        for o in observers:   # the first reason to stop: those after it do not see the row
            reason = o.step_complete(t, h, row)
            if reason:
                break
        if not reason:
            control.accepted(h)
    return reason or ""


def _attempt(system, algorithm: Algorithm, control: StepControl, t: float, h: float) -> int | None:
    """One try of the step: its coupling iterations, or None if the controller rejected it (rolled back)."""
    snapshot = system.save() if control.rolls_back or algorithm.needs_snapshot else None
    try:
        control.prepare(t, h, algorithm)
        iterations = algorithm.step(t, h, snapshot)
        if not control.judge(t, h, algorithm):
            system.restore(snapshot)
            system.stats.rejections += 1
            return None
        return iterations
    finally:
        system.release(snapshot)


def _first(reasons) -> str | None:
    """The first reason to stop (every observer before it has seen the row; those after have not)."""
    for reason in reasons:
        if reason:
            return reason
    return None


def _count(stats, h: float, iterations: int) -> None:
    stats.steps += 1
    stats.iterations += iterations
    stats.max_iterations = max(stats.max_iterations, iterations)
    stats.min_step = h if stats.steps == 1 else min(stats.min_step, h)
    stats.max_step = max(stats.max_step, h)


class Sampler:
    """The row of a communication point: every output, then each power bond's dE and E (measured
    over the step just taken)."""

    def __init__(self, system, bonds, adaptive: bool):
        self.system, self.bonds = system, bonds
        self.read_flags = not adaptive and bool(system.flag_names)   # the adaptive controller read them
        self.n = len(system.columns)
        self.row = np.zeros(self.n + len(bonds.row))   # reused: observers copy what they keep

    def __call__(self, h: float | None) -> np.ndarray:
        if h is not None and self.bonds.bonds:
            self.bonds.measure(h)
        if self.read_flags:
            self.system.flags()
        row = self.system.fill_outputs(self.row)
        if self.bonds.bonds:
            row[self.n:] = self.bonds.row
        return row
