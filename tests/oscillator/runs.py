"""Runs of the two-mass oscillator through the master at the parameters of :mod:`oscillator.exact`;
shared by the iterative-coupling and instability-alarm tests."""
import numpy as np
from scipy.optimize import brentq

from cranefmu.master.run import run
from oscillator.exact import Oscillator

DAMPED = Oscillator(d1=2.0, dc=2.0, d2=2.0)
UNDAMPED = Oscillator()
X0 = 0.1
Z0 = np.array([X0, 0.0, 0.0, 0.0])


def jacobi_limit():
    return brentq(lambda h: max(abs(np.linalg.eigvals(DAMPED.jacobi_zoh_matrix(h)))) - 1.0, 0.02, 0.2)


def go(ssp, h, osc, stop=3.0, **kw):
    return run(ssp, stop_time=stop, step_size=h, parameters={**osc.parameters(), "mass.x0": X0}, **kw)
