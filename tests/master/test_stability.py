"""Largest stable macro step of Jacobi with zero-order hold: measured by runs, against the spectral
radius of the linear recurrence z_{n+1} = M(H) z_n of the scheme (support/cranefmu_support/oscillator/exact.py)."""
import numpy as np
import pytest
from scipy.optimize import brentq

from cranefmu.errors import SimulationError
from cranefmu.master.run import run
from cranefmu_support.oscillator.runs import DAMPED as OSC

N_STEPS = 400


def spectral_radius(h):
    return max(abs(np.linalg.eigvals(OSC.jacobi_zoh_matrix(h))))


def grows(ssp, h):
    """True if the co-simulated oscillation grows over N_STEPS steps of h (judged here: the default
    instability alarm also stops coarse stable runs, see test_instability_alarm.py)."""
    try:
        res = run(ssp, stop_time=N_STEPS * h, step_size=h, parameters={**OSC.parameters(), "mass.x0": 0.1},
                  instability_alarm=False).result
    except SimulationError:
        return True
    q = N_STEPS // 4
    amp = np.abs(res["mass.x"]) + np.abs(res["spring.x"])
    return amp[-q:].max() > amp[1:q + 1].max()


def test_recurrence_matrix_is_the_scheme(oscillator_ssp):
    # the analytical amplification matrix reproduces the master's Jacobi steps to rounding
    h = 0.02
    res = run(oscillator_ssp, stop_time=10 * h, step_size=h, parameters={**OSC.parameters(), "mass.x0": 0.1}).result
    z = np.array([0.1, 0.0, 0.0, 0.0])
    m = OSC.jacobi_zoh_matrix(h)
    for n in range(10):
        z = m @ z
    got = [res[c][-1] for c in ("mass.x", "mass.v", "spring.x", "spring.v")]
    assert np.allclose(got, z, rtol=1e-6, atol=1e-9)


def test_largest_stable_step_matches_the_spectral_radius_limit(oscillator_ssp):
    h_limit = brentq(lambda h: spectral_radius(h) - 1.0, 0.02, 0.2)
    assert spectral_radius(0.9 * h_limit) < 1 < spectral_radius(1.1 * h_limit)
    lo, hi = 0.7 * h_limit, 1.4 * h_limit   # bisection on runs: stable at lo, unstable at hi
    assert not grows(oscillator_ssp, lo) and grows(oscillator_ssp, hi)
    for _ in range(4):
        mid = 0.5 * (lo + hi)
        if grows(oscillator_ssp, mid):
            hi = mid
        else:
            lo = mid
    measured = 0.5 * (lo + hi)
    assert measured == pytest.approx(h_limit, rel=0.10)
