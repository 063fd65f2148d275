"""Independent tasks on the sweep's Dask cluster, for callers that are not a sweep (``cranefmu check``).

:func:`run_tasks` submits one task per item to the cluster :func:`.engine.connect` gives (a LocalCluster
of ``workers`` processes, or the cluster at ``scheduler``) and returns each task's result in the items'
order.  A task whose worker dies (or that raises something unexpected) is submitted once more, as a
sweep's run is; the second failure, or a lost scheduler, gives a :class:`TaskLost` with the reason in
the task's place: the other tasks still run.  :func:`.engine.ship_ssp` makes a scene file reach the workers.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from .engine import MAX_ATTEMPTS, close, connect, ship_ssp  # noqa: F401 (ship_ssp: for the callers of run_tasks)


@dataclass(frozen=True)
class TaskLost:
    """A task that gave no result: why (one line)."""

    reason: str


def run_tasks(fn: Callable, items: list[tuple], *, workers: int | None = None, scheduler: str | None = None,
              client=None, prepare: Callable | None = None, done: Callable | None = None,
              name: str = "cranefmu-task") -> list:
    """``fn(*args)`` for every ``args`` of ``items`` on Dask, results in the items' order (a
    :class:`TaskLost` where a task gave none).  ``prepare(client) -> items`` replaces ``items`` once the
    client is up (to ship files to its workers); ``done(index, result)`` is called as each task ends.
    A client of our own (none given) is closed at the end, however it ends."""
    from distributed import as_completed

    own, cluster = client is None, None
    if own:
        client, cluster = connect(workers, scheduler)
    results: list = [None] * len(items)
    quiet = logging.getLogger("distributed.client")   # a lost scheduler is one TaskLost each, not tracebacks
    level = quiet.level
    quiet.setLevel(logging.CRITICAL)
    try:
        if prepare is not None:
            items = prepare(client)
        futures: dict = {}

        def submit(i: int, attempt: int):
            fut = client.submit(fn, *items[i], key=f"{name}-{i}-{attempt}-{id(results):x}", pure=False)
            futures[fut] = (i, attempt)
            return fut

        pending = as_completed([submit(i, 1) for i in range(len(items))])
        for fut in pending:
            i, attempt = futures.pop(fut)
            try:
                result = fut.result()
            except Exception as err:  # noqa: BLE001 - the worker died, the task or the scheduler was lost
                text = " ".join(f"{type(err).__name__}: {err}".split())
                if attempt < MAX_ATTEMPTS and client.status == "running":
                    pending.add(submit(i, attempt + 1))
                    continue
                result = TaskLost(f"lost with its worker after {attempt} attempt(s): {text}")
            results[i] = result
            if done is not None:
                done(i, result)
        for i, result in enumerate(results):   # what a lost cluster never ran
            if result is None:
                results[i] = TaskLost("lost: the cluster ended before it ran")
                if done is not None:
                    done(i, results[i])
    finally:
        quiet.setLevel(level)
        if own:
            close(client, cluster)
    return results


