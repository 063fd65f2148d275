"""A progress bar over simulated time (tqdm), only on a terminal and only for runs that last."""
from __future__ import annotations

import sys
import time as clock


class Progress:
    """Shows a bar after ``delay`` seconds of wall time, if stderr is a terminal; never steers."""

    batchable = True   # takes rows after the fact: a stretch of compiled steps may precede it (loop.march)
    passive = True     # never stops the run on a row's content: takes a stretch's rows once its stop is known

    def __init__(self, start: float, stop: float, enabled: bool | None = None, delay: float = 3.0):
        self.start, self.stop = start, stop
        self.enabled = sys.stderr.isatty() if enabled is None else enabled
        self.delay = delay
        self.t0 = clock.perf_counter()
        self.bar = None
        self.shown = 0.0

    def simulation_initialized(self, t: float, values) -> None:
        return None

    def step_complete(self, t: float, h: float, values) -> None:
        self.update(t)

    def steps_complete(self, times, hs, rows) -> None:
        """The rows of a stretch at once (:func:`.loop.march`): the bar moves to the last."""
        if len(times):
            self.update(float(times[-1]))

    def update(self, t: float) -> None:
        if not self.enabled:
            return
        if self.bar is None:
            if clock.perf_counter() - self.t0 < self.delay:
                return
            try:
                from tqdm import tqdm
            except ImportError:
                self.enabled = False
                return
            self.bar = tqdm(total=self.stop - self.start, unit="s sim", file=sys.stderr, leave=False,
                            bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]")
        self.bar.update(t - self.start - self.shown)
        self.shown = t - self.start

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None
