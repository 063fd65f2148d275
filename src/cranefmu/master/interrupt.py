"""Stop a run cleanly on SIGINT/SIGTERM/SIGHUP: an observer that asks the loop to stop at the next step.

A KeyboardInterrupt raised inside an FMU's Python code (pythonfmu) gives status fatal and leaves a
dangling instance, so during a run the signal only sets a flag; the loop ends at the next
communication point, the run is closed (rows written, FMUs freed), and then
:class:`RunInterrupted` (a KeyboardInterrupt) carries the rows computed so far to the caller.
"""
from __future__ import annotations

import signal
import threading


STOP_SIGNALS: list[int] = [signal.SIGINT]   # what stops a run; the CLI adds SIGTERM and SIGHUP (see stop_on)
RECEIVED: list[int] = []   # every stop signal this process's handlers saw, in order (see :func:`note`)


def stop_on(*signals: int) -> None:
    """Make ``signals`` stop every later run of this process between steps (the CLI: SIGINT, SIGTERM, SIGHUP)."""
    STOP_SIGNALS[:] = list(signals)


def wanted(signals) -> tuple[int, ...]:
    """``signals`` less SIGHUP when this process was started with it ignored (``nohup``): it must
    then not stop the run."""
    return tuple(s for s in signals if s != signal.SIGHUP or signal.getsignal(s) != signal.SIG_IGN)


def note(signum: int) -> bool:
    """Record a stop signal; True if it is the first this process received (a handler outside a run
    raises only then, so a second Ctrl-C never interrupts the cleanup the first one started)."""
    RECEIVED.append(int(signum))
    return len(RECEIVED) == 1


def raise_first(signum: int, frame=None, when: str = "") -> None:
    """Signal handler outside a run: the first stop signal raises :class:`RunInterrupted`, later ones are noted."""
    if note(signum):
        raise RunInterrupted(f"interrupted by {signal_name(signum)}{when}", signum=signum)


class Outside:
    """The command line's handler of stop signals outside a run (start-up, checks, after the run): the
    first one raises :class:`RunInterrupted` saying what was kept (``when``, set by ``cranefmu run`` once
    its rows are written), later ones are only noted."""

    def __init__(self) -> None:
        self.when = " before the run started: no rows were written"

    def __call__(self, signum: int, frame=None) -> None:
        raise_first(signum, frame, self.when)


OUTSIDE = Outside()   # one per process: cranefmu.cli installs it, cranefmu.subcommands.run sets its ``when``



class RunInterrupted(KeyboardInterrupt):
    """The run was stopped by a signal after closing cleanly; ``result`` holds the rows so far,
    ``output`` the CSV they are in (or None), ``signum`` the signal."""

    def __init__(self, message: str, result=None, output=None, signum: int = signal.SIGINT):
        super().__init__(message)
        self.result = result
        self.output = output
        self.signum = int(signum)

    @property
    def exit_code(self) -> int:
        """What a shell reports for a process ended by this signal: 128 + its number (130, 143, 129)."""
        return 128 + self.signum

    def __reduce__(self):  # crosses the process boundary of an isolated run whole
        return (type(self), (str(self), self.result, self.output, self.signum))


def signal_name(signum: int) -> str:
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


class Interrupt:
    """Observer: ``step_complete`` returns a reason to stop once one of ``signals`` arrived.

    Used as a context manager it installs its handler (main thread only: elsewhere signals go to
    the main thread anyway) and restores the previous handlers on exit.  Further signals while the
    run closes are counted, never raised.
    """

    batchable = True   # takes rows after the fact: a stretch of compiled steps may precede it (loop.march)

    def __init__(self, signals: tuple[int, ...] | None = None):
        self.signals = wanted(STOP_SIGNALS if signals is None else signals)
        self.signum: int | None = None
        self.count = 0
        self._old: dict[int, object] = {}

    def handle(self, signum: int, frame=None) -> None:
        note(signum)
        self.count += 1
        if self.signum is None:
            self.signum = signum

    def simulation_initialized(self, t: float, values) -> str | None:
        return self.step_complete(t, 0.0, values)

    def step_complete(self, t: float, h: float, values) -> str | None:
        if self.signum is None:
            return None
        return f"interrupted by {signal_name(self.signum)} at t = {t:.9g} s"

    def steps_complete(self, times, hs, rows):
        """The rows of a stretch at once (:func:`.loop.march`): a signal that arrived stops at the first."""
        reason = self.step_complete(float(times[0]), float(hs[0]), rows[0]) if len(times) else None
        return (0, reason) if reason else None

    def __enter__(self) -> "Interrupt":
        if threading.current_thread() is threading.main_thread():
            for s in self.signals:
                self._old[s] = signal.signal(s, self.handle)
        return self

    def __exit__(self, *exc) -> None:
        for s, old in self._old.items():
            signal.signal(s, old)
        self._old.clear()
