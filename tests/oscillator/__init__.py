"""Re-export of :mod:`cranefmu.studies.oscillator` (moved into the package so benchmarks use public API only)."""
from cranefmu.studies.oscillator import *  # noqa: F401,F403
from cranefmu.studies.oscillator import HERE, SSD, build_oscillator  # noqa: F401
