"""How a sweep's runs are cut into Dask tasks: one run a task at first, then as many runs a task as take
about :data:`TASK_SECONDS` on a worker, judged from the task times of the runs finished so far.

A Dask task costs the scheduler and the worker's event loop some milliseconds of CPU whatever it runs
(benchmarks/results/sweep_overhead.md), a good part of a short run's own integration.
Runs of a fraction of a second go several to a task; a run of a second or more stays alone in its task, so
a row still reaches the table within about :data:`TASK_SECONDS` of its run finishing.  The last runs are
spread over the workers (no task larger than an even share of what is left), and about two tasks per worker
are in flight, so a worker always has its next task queued.
"""
from __future__ import annotations

import math
import statistics
from collections import deque

TASK_SECONDS = 0.25   # aimed task length on a worker [s]
MAX_RUNS = 32         # runs in one task at most
KEPT_TIMES = 16       # the task times the estimate uses: the last ones (warm workers)


class TaskFeed:
    """The runs not yet submitted, cut into tasks as the finished runs' times come in."""

    def __init__(self, runs: list, workers: int):
        self.queue = deque(runs)
        self.workers = 1
        self.set_workers(workers)
        self.times: deque[float] = deque(maxlen=KEPT_TIMES)

    def set_workers(self, workers: int) -> None:
        """The cluster's workers now (a cluster may grow or lose some while the sweep runs; at least 1)."""
        self.workers = max(1, int(workers))

    @property
    def in_flight(self) -> int:
        """Tasks to keep submitted: two per worker."""
        return 2 * self.workers

    def observe(self, task_time) -> None:
        """A finished run's time on its worker [s] (``task_time`` of its row; None or nan: not counted)."""
        if isinstance(task_time, (int, float)) and math.isfinite(task_time) and task_time >= 0:
            self.times.append(float(task_time))

    def size(self) -> int:
        """Runs in the next task: 1 until a run's time is known, then TASK_SECONDS over the median time
        (1 to MAX_RUNS), and no more than an even share of the runs left per worker."""
        if not self.times:
            return 1
        per_run = statistics.median(self.times)
        n = MAX_RUNS if per_run <= 0 else int(TASK_SECONDS / per_run)
        share = math.ceil(len(self.queue) / self.workers)
        return max(1, min(n, MAX_RUNS, share))

    def take(self, running: int) -> list[list]:
        """The next tasks' runs, enough to have about two tasks per worker in flight (``running`` now)."""
        out = []
        while self.queue and running + len(out) < self.in_flight:
            n = self.size()
            out.append([self.queue.popleft() for _ in range(min(n, len(self.queue)))])
        return out
