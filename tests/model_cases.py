"""Re-export of :mod:`cranefmu.studies.model_cases` (moved into the package so benchmarks use public API only)."""
from cranefmu.studies.model_cases import *  # noqa: F401,F403
