"""The master loop: an algorithm steps, a step controller judges, observers see each accepted step.

The shape of libcosim's execution (an *algorithm* decides how far the FMUs step and when values
move; *observers* see the results and never steer) with scipy OdeSolver's single contract: every
algorithm implements :class:`~.algorithms.Algorithm`, every step controller the methods of
:class:`StepControl`, every observer :class:`Observer`.  An observer may end the run as a result
by returning a reason (a stop condition), or fail it by raising :class:`~cranefmu.errors.SimulationError`
(an alarm); the row it fails on is recorded first (the recorder is the first observer).

What both the step controller and the observers need of a step is measured once, by the loop
(:class:`Sampler`): the discrete outputs right after the algorithm's step (the controller judges
them, the row records them) and, for an accepted step, the power bonds' energy residuals (the row
records them, the ECCO controller sizes the next step from them).
"""
from __future__ import annotations

from typing import Protocol

import numpy as np

from .algorithms import Algorithm


class Observer(Protocol):
    """``values``: the row, an array the loop reuses for the next row (copy what you keep).

    Optional: ``batchable = True`` (rows may come after the fact, behind a compiled stretch);
    ``steps_complete(times, hs, rows)``, the rows of a stretch at once (2-D, one per step), returning
    (row index, reason or error) at the first row that stops or fails the run, or None; ``passive = True``
    (never stops the run on a row's content: given its rows once the stop is known).  See :func:`_deliver`."""

    def simulation_initialized(self, t: float, values: np.ndarray) -> str | None:
        """The row at the start time [s]; a reason to stop at once, or None."""

    def step_complete(self, t: float, h: float, values: np.ndarray) -> str | None:
        """The row after an accepted step of h ending at t [s]; a reason to stop, or None."""


class StepControl(Protocol):
    rolls_back: bool   # a step may be rejected: the FMUs' state is saved before each step
    judges: bool       # prepare() and judge() do something (False: every step is taken as proposed)

    def begin(self, flags: list[int]) -> None: ...                    # the discrete outputs at the start
    def propose(self, t: float) -> float | None: ...                  # next step from t, None: done
    def prepare(self, t: float, h: float, algorithm: Algorithm) -> None: ...
    def judge(self, t: float, h: float, algorithm: Algorithm, flags: list[int]) -> bool: ...  # accept it?
    def advance(self, t: float, h: float) -> float: ...               # the time the step reached
    def accepted(self, h: float, bonds) -> None: ...                  # after the observers: next h


class Coupled(Protocol):
    """What the loop needs of the coupling (:class:`~.coupled.Coupling`): snapshots and statistics."""

    stats: object

    def snapshot(self): ...
    def restore(self, snapshot) -> None: ...
    def release(self, snapshot) -> None: ...


BATCH = True    # a stretch's rows go to the observers in blocks (False: one by one, the reference)
STRETCH = 4096   # most macro steps one compiled call takes when no observer needs them one by one; each stretch
#                 costs the observers ~0.5 ms of numpy calls (256 left 12 of them in a 6 s overhead_lift run, a third
#                 of its CPU: benchmarks/warm_breakdown.py); its rows, 4096 x the columns, bound what a run holds.
#                 An observer may ask for shorter ones (``stretch_limit``: the recorder writing a file, whose rows
#                 a crash inside a stretch would lose)


def march(coupling: Coupled, algorithm: Algorithm, control: StepControl, sample: Sampler,
          observers: list[Observer], t: float) -> str:
    """Step from t until the controller is done or an observer stops the run; returns why it stopped
    ('' at the end).  ``sample`` measures what a step gives (flags, bond residuals, the row)."""
    m = March(coupling, algorithm, control, sample, observers, t)
    while m.step(stretch=True):
        pass
    return m.reason or ""


class March:
    """The loop of :func:`march`, one macro step (or one stretch) at a time: :meth:`step` until it
    returns False (the controller is done, or an observer stopped the run: :attr:`reason`).

    Where every step is taken as proposed on a fixed grid and every observer takes rows after the fact
    (``batchable``), a step may be a stretch of steps in one call of the algorithm
    (:meth:`~.algorithms.Algorithm.stretch`, the compiled Jacobi); the observers then see its rows in
    order (in one block each where they take blocks: :func:`_deliver`), and one that stops the run or
    fails it does so at its row (the FMUs have gone on to the end of the stretch)."""

    def __init__(self, coupling: Coupled, algorithm: Algorithm, control: StepControl, sample: Sampler,
                 observers: list[Observer], t: float):
        self.coupling, self.algorithm, self.control, self.sample = coupling, algorithm, control, sample
        self.stretch_steps = min([STRETCH, *(o.stretch_limit for o in observers
                                            if getattr(o, "stretch_limit", None))])
        self.observers, self.t = observers, t
        self.stats = coupling.stats
        control.begin(sample.flags())
        self.reason = _first(o.simulation_initialized(t, sample.row()) for o in observers)
        self.done = False   # the controller proposed no further step
        # a step nobody may reject and that needs no snapshot is taken directly (what _attempt does, without its calls)
        self.direct = not control.rolls_back and not control.judges
        self.batched = (self.direct and hasattr(control, "upcoming") and hasattr(control, "advance_grid")
                        and isinstance(sample, Sampler)
                        and all(getattr(o, "batchable", False) for o in observers))
        if self.batched:
            sample.prepare_stretches()

    def step(self, until: float | None = None, stretch: bool = False) -> bool:
        """Take the next accepted macro step (``stretch``: or a stretch of them, none ending after
        ``until`` [s] on a fixed grid); False if none was taken (the run is over, or ``t`` is at or past
        ``until``)."""
        algorithm, control, sample = self.algorithm, self.control, self.sample
        while True:
            if self.reason or self.done:
                return False
            t = self.t
            if until is not None and t >= until - 1e-12 * max(1.0, abs(until)):
                return False
            h = control.propose(t)
            if h is None:
                self.done = True
                return False
            if stretch and self.batched and not algorithm.needs_snapshot:
                ts = control.upcoming(t, self.stretch_steps)
                if until is not None:
                    past = np.flatnonzero(ts[1:] >= until - 1e-12 * max(1.0, abs(until)))
                    if len(past):
                        ts = ts[:past[0] + 2]
                got = algorithm.stretch(ts)
                if got is not None:
                    self.t, self.reason = _deliver(got, algorithm, control, sample, self.observers, self.stats, ts)
                    return True
            if self.direct and not algorithm.needs_snapshot:
                h, iterations = algorithm.step(t, h, None)
                sample.flags()
            else:
                taken = _attempt(self.coupling, algorithm, control, sample, t, h)
                if taken is None:
                    continue
                h, iterations = taken
            algorithm.accepted()
            self.t = t = control.advance(t, h)
            _count(self.stats, h, iterations)
            bonds = sample.after(h)
            row = sample.row()
            for o in self.observers:   # the first reason to stop: those after it do not see the row
                self.reason = o.step_complete(t, h, row)
                if self.reason:
                    break
            if not self.reason:
                control.accepted(h, bonds)
            return True


def _deliver(stretch, algorithm: Algorithm, control: StepControl, sample: Sampler, observers: list[Observer],
             stats, ts: np.ndarray) -> tuple[float, str | None]:
    """The rows of a stretch (rows, steps done, failure or None) to the observers as :func:`march` gives
    them step by step: every observer sees the rows up to the first that stops or fails the run, those
    before the one that stops it see that row too; then the stretch's failure, if it had one.

    An observer with ``steps_complete(times, hs, rows)`` takes the rows at once and returns (row index,
    reason or error) at the first it stops or fails on (None: it took them all); the others take them
    one by one.  Observers marked ``passive`` (they never stop a run on a row's content: the recorder, the
    progress bar) take their rows last, once it is known where the run stops; the others in their order,
    each over the rows before the first stop found so far (where a later observer stops before an
    earlier one's stop, the earlier one has seen rows past it: the run is over, and only the rows, the
    bonds and the statistics, all cut at the stop, are its result)."""
    t = float(ts[0])
    if not BATCH:
        return _deliver_rows(stretch, algorithm, control, sample, observers, stats, t)
    rows, done, failure = stretch
    times, hs = ts[1:done + 1], np.diff(ts[:done + 1])
    block = sample.take_block(rows[:done, 1:], hs)
    limit, stop, who = done, None, len(observers)
    for k, o in enumerate(observers):
        if getattr(o, "passive", False) or not limit:
            continue
        got = _observe(o, times[:limit], hs[:limit], block[:limit])
        if got is not None:
            limit, stop, who = got[0], got[1], k
    seen = limit + 1 if stop is not None else limit   # rows the run took: the stopping one too
    for k, o in enumerate(observers):
        if getattr(o, "passive", False):
            n = seen if k < who else limit
            if n:
                got = _observe(o, times[:n], hs[:n], block[:n])
                if got is not None and isinstance(got[1], BaseException):
                    raise got[1]
    many = getattr(algorithm, "accepted_many", None)
    if many is not None:
        many(seen)
    else:
        for _ in range(seen):
            algorithm.accepted()
    if seen:
        t = control.advance_grid(ts, seen)
        _count_many(stats, hs[:seen])
        sample.commit_block(block, seen)
    if isinstance(stop, BaseException):
        raise stop
    if stop is None and failure is not None:
        raise failure
    return t, stop


def _observe(o, times: np.ndarray, hs: np.ndarray, rows: np.ndarray):
    """(row index, reason or error) where ``o`` stops or fails on the rows, or None."""
    batch = getattr(o, "steps_complete", None)
    if batch is not None:
        return batch(times, hs, rows)
    for i in range(len(hs)):
        try:
            reason = o.step_complete(float(times[i]), float(hs[i]), rows[i])
        except Exception as err:   # raised once the observers before it have seen the row (as row by row)
            return i, err
        if reason:
            return i, reason
    return None


def _deliver_rows(stretch, algorithm: Algorithm, control: StepControl, sample: Sampler,
                  observers: list[Observer], stats, t: float) -> tuple[float, str | None]:
    """:func:`_deliver` one row at a time, each through every observer's ``step_complete`` (the reference,
    and the path before batches: ``BATCH = False``)."""
    rows, done, failure = stretch
    reason = None
    for i in range(done):
        h = control.propose(t)
        algorithm.accepted()
        t = control.advance(t, h)
        _count(stats, h, 1)
        row = sample.take(rows[i, 1:], h)
        for o in observers:
            reason = o.step_complete(t, h, row)
            if reason:
                break
        if reason:
            break
        control.accepted(h, sample.bonds)
    if failure is not None and not reason:
        raise failure
    return t, reason


def _attempt(coupling: Coupled, algorithm: Algorithm, control: StepControl, sample: Sampler, t: float,
             h: float) -> tuple[float, int] | None:
    """One try of the step: (step taken, coupling iterations), or None if the controller rejected it
    (rolled back)."""
    snapshot = coupling.snapshot() if control.rolls_back or algorithm.needs_snapshot else None
    try:
        control.prepare(t, h, algorithm)
        taken = algorithm.step(t, h, snapshot)
        flags = sample.flags()
        if control.judges and not control.judge(t, h, algorithm, flags):
            coupling.restore(snapshot)
            coupling.stats.rejections += 1
            return None
        return taken
    finally:
        coupling.release(snapshot)


def _first(reasons) -> str | None:
    """The first reason to stop (every observer before it has seen the row; those after have not)."""
    for reason in reasons:
        if reason:
            return reason
    return None


def _count_many(stats, hs: np.ndarray) -> None:
    """:func:`_count` of one iteration for each step of ``hs`` [s]."""
    first = stats.steps == 0
    stats.steps += len(hs)
    stats.iterations += len(hs)
    stats.max_iterations = max(stats.max_iterations, 1)
    least, most = float(hs.min()), float(hs.max())
    stats.min_step = least if first else min(stats.min_step, least)
    stats.max_step = max(stats.max_step, most)


def _count(stats, h: float, iterations: int) -> None:
    stats.steps += 1
    stats.iterations += iterations
    stats.max_iterations = max(stats.max_iterations, iterations)
    stats.min_step = h if stats.steps == 1 else min(stats.min_step, h)
    stats.max_step = max(stats.max_step, h)


class Sampler:
    """What a communication point gives, measured once: the discrete outputs (:meth:`flags`, right
    after the algorithm's step), the power bonds' dE of an accepted step (:meth:`after`), and the row
    (every output, then each bond's dE and E)."""

    def __init__(self, system, bonds):
        self.system, self.bonds = system, bonds
        self.has_flags = bool(system.flag_names)
        self.n = len(system.columns)
        self.row_ = np.zeros(self.n + len(bonds.row))   # reused: observers copy what they keep

    def flags(self) -> list[int]:
        """Every discrete output now (also kept for the row)."""
        return self.system.flags() if self.has_flags else []

    def after(self, h: float):
        """The power bonds measured over the accepted step of h just taken; returns the monitor."""
        if self.bonds.bonds:
            self.bonds.measure(h)
        return self.bonds

    def prepare_stretches(self) -> None:
        """A compiled stretch's rows also carry what the power bonds measure (after the outputs)."""
        if self.bonds.bonds:
            self.system.row_extra = self.bonds.stretch_layout(self.system._read_at)

    def take(self, values: np.ndarray, h: float) -> np.ndarray:
        """The row of a step of h taken in a stretch (as :meth:`row` gives it) from the stretch's row
        ``values`` (outputs, discrete outputs, the bonds' values); the bonds measured from it."""
        row = self.row_
        n = self.n
        row[:n] = values[:n]
        if self.has_flags:
            self.system.flag_value[:] = values[n - len(self.system.flag_value):n]
        if self.bonds.bonds:
            self.bonds.measure_values(values[n:], h)
            row[n:] = self.bonds.row
        return row

    def take_block(self, values: np.ndarray, hs: np.ndarray) -> np.ndarray:
        """The rows of a stretch's steps hs [s] (as :meth:`take` gives them, one per step) from its rows
        ``values``; the bonds measured over them (:attr:`block`), not yet committed (:meth:`commit_block`)."""
        n = self.n
        rows = np.empty((len(hs), len(self.row_)))
        rows[:, :n] = values[:, :n]
        if self.bonds.bonds:
            self.bonds.block = b = self.bonds.measure_block(values[:, n:], hs)
            rows[:, n::2] = b.residual
            rows[:, n + 1::2] = b.total
        return rows

    def commit_block(self, rows: np.ndarray, taken: int) -> None:
        """The sampler and the bonds as :meth:`take` leaves them after the first ``taken`` rows."""
        last = rows[taken - 1]
        self.row_[:] = last
        if self.has_flags:
            flags = self.system.flag_value
            flags[:] = last[self.n - len(flags):self.n]
        if self.bonds.bonds:
            self.bonds.commit(self.bonds.block, taken)

    def row(self) -> np.ndarray:
        row = self.system.fill_outputs(self.row_)
        if self.bonds.bonds:
            row[self.n:] = self.bonds.row
        return row
