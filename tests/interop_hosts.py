"""Re-export of :mod:`cranefmu.studies.hosts` (moved into the package so benchmarks use public API only)."""
from cranefmu.studies.hosts import *  # noqa: F401,F403
