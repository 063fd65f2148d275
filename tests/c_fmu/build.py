"""Re-export of :mod:`cranefmu.studies.c_fmu.build`."""
from cranefmu.studies.c_fmu.build import *  # noqa: F401,F403
