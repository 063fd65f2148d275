"""BLAS and OpenMP thread pools pinned to one thread while a run steps (threadpoolctl).

A co-simulation step makes many small numpy/scipy calls (a few coupling values, an FMU's 6 x 6 matrix
exponential); with OpenBLAS's default of one thread per core they cost more CPU, not less (issue 33:
truck_telescope's Chassis took 3.7x the CPU with the default threads), and on a machine shared by several
runs the threads only compete.  Pinned inside :func:`.run._run_here`, so in the caller's process (for the
run only: its own limits come back after), in a worker process and in a sweep's workers alike.
"""
from __future__ import annotations

import contextlib
import sys
from collections.abc import Iterator

_FOUND: tuple = (-1, None)   # (len(sys.modules) when the loaded libraries were scanned, their controller)


@contextlib.contextmanager
def one_thread() -> Iterator[None]:
    """BLAS and OpenMP pools limited to one thread for the block (a no-op without threadpoolctl)."""
    controller = _controller()
    if controller is None:   # an install without threadpoolctl: the pools keep their sizes
        yield
        return
    with controller.limit(limits=1):
        yield


def _controller():
    """threadpoolctl's controller of the loaded BLAS/OpenMP libraries, scanned again only when a module was
    imported since (a new pool comes with an extension module: numpy, scipy, an FMU's code).  Scanning reads
    /proc/self/maps, 1-2 ms a call in a Dask worker: a sweep run pinned twice on every run."""
    global _FOUND
    modules = len(sys.modules)
    if _FOUND[0] != modules:
        try:
            from threadpoolctl import ThreadpoolController
        except ImportError:
            _FOUND = (len(sys.modules), None)
            return None
        _FOUND = (len(sys.modules), ThreadpoolController())
    return _FOUND[1]
