"""Re-export of :mod:`cranefmu.studies.foreign_ssp` (moved into the package so benchmarks use public API only)."""
from cranefmu.studies.foreign_ssp import *  # noqa: F401,F403
