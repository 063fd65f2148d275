"""Re-export of :mod:`cranefmu.studies.late` (moved into the package so benchmarks use public API only)."""
from cranefmu.studies.late import *  # noqa: F401,F403
