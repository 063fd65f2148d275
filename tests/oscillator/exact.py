"""Re-export of :mod:`cranefmu.studies.oscillator.exact`."""
from cranefmu.studies.oscillator.exact import *  # noqa: F401,F403
