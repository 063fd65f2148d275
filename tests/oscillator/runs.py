"""Re-export of :mod:`cranefmu.studies.oscillator.runs`."""
from cranefmu.studies.oscillator.runs import *  # noqa: F401,F403
