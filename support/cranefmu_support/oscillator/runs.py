"""The two-mass oscillator cases the master tests share (parameters of :mod:`oscillator.exact`) and
a run of one through the master."""
import numpy as np
from scipy.optimize import brentq

from cranefmu.master.run import run
from .exact import Oscillator

DAMPED = Oscillator(d1=2.0, dc=2.0, d2=2.0)
UNDAMPED = Oscillator()
# a mass on a massless spring to an anchor: omega^2 = kc / m1, all stiffness in the coupling;
# Jacobi ZOH gains 1 + (omega H)^2 / 2 per step
SINGLE = Oscillator(k1=0.0, m2=0.0, kc=100.0)
X0 = 0.1
Z0 = np.array([X0, 0.0, 0.0, 0.0])


def jacobi_limit():
    return brentq(lambda h: max(abs(np.linalg.eigvals(DAMPED.jacobi_zoh_matrix(h)))) - 1.0, 0.02, 0.2)


def go(ssp, h, osc, stop=3.0, **kw):
    return run(ssp, stop_time=stop, step_size=h, parameters={**osc.parameters(), "mass.x0": X0}, **kw)
