"""Re-export of :mod:`cranefmu.studies.fmu_child` (moved into the package so benchmarks use public API only)."""
from cranefmu.studies.fmu_child import *  # noqa: F401,F403
