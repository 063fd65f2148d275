"""Re-export of :mod:`cranefmu.studies.c_fmu` (moved into the package so benchmarks use public API only)."""
from cranefmu.studies.c_fmu import *  # noqa: F401,F403
