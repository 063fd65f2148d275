"""BLAS and OpenMP thread pools pinned to one thread while a run steps (threadpoolctl).

A co-simulation step makes many small numpy/scipy calls (a few coupling values, an FMU's 6 x 6 matrix
exponential); with OpenBLAS's default of one thread per core they cost more CPU, not less (issue 33:
truck_telescope's Chassis took 3.7x the CPU with the default threads), and on a machine shared by several
runs the threads only compete.  Pinned inside :func:`.run._run_here`, so in the caller's process (for the
run only: its own limits come back after), in a worker process and in a sweep's workers alike.
"""
from __future__ import annotations

import contextlib
from collections.abc import Iterator


@contextlib.contextmanager
def one_thread() -> Iterator[None]:
    """BLAS and OpenMP pools limited to one thread for the block (a no-op without threadpoolctl)."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:   # an install without it: the pools keep their sizes
        yield
        return
    with threadpool_limits(limits=1):
        yield
