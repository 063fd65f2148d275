"""Iterative (strong) coupling: converges where Jacobi is unstable, IQN-ILS faster than Aitken,
the coupling satisfied at every communication point, energy error bounded (no drift), and a clear
report when it does not converge."""
import numpy as np
import pytest
from scipy.optimize import brentq

from cranefmu.errors import SimulationError
from cranefmu.master.run import run
from oscillator.exact import Oscillator

DAMPED = Oscillator(d1=2.0, dc=2.0, d2=2.0)
UNDAMPED = Oscillator()
X0 = 0.1
Z0 = np.array([X0, 0.0, 0.0, 0.0])


def jacobi_limit():
    return brentq(lambda h: max(abs(np.linalg.eigvals(DAMPED.jacobi_zoh_matrix(h)))) - 1.0, 0.02, 0.2)


def error(res, osc):
    exact = osc.solution(res["time"], Z0)
    return np.max(np.abs(res["mass.x"] - exact[:, 0]))


def go(ssp, h, osc, stop=3.0, **kw):
    return run(ssp, stop_time=stop, step_size=h, parameters={**osc.parameters(), "mass.x0": X0}, **kw)


def test_converges_beyond_the_jacobi_stability_limit(oscillator_ssp):
    h1, h2 = 1.7 * jacobi_limit(), 1.15 * jacobi_limit()
    jac = go(oscillator_ssp, h1, DAMPED, stop=60 * h1, instability_alarm=False).result
    amp = np.abs(jac["mass.x"])
    assert amp[-15:].max() > amp[:15].max()              # Jacobi grows at h1
    it1 = go(oscillator_ssp, h1, DAMPED, algorithm="iterative", extrapolation=2)
    it2 = go(oscillator_ssp, h2, DAMPED, algorithm="iterative", extrapolation=2)
    assert it1.stats.iterations / it1.stats.steps < 5   # IQN-ILS, reusing past steps
    e1, e2 = error(it1.result, DAMPED), error(it2.result, DAMPED)
    # degree-2 interpolation of the inputs: third order in H, measured 2.6 between these steps
    assert np.log(e1 / e2) / np.log(h1 / h2) > 2.3
    assert e1 < 0.15 * X0


def test_iqn_ils_needs_fewer_iterations_than_aitken(oscillator_ssp):
    h = 1.5 * jacobi_limit()
    iqn = go(oscillator_ssp, h, DAMPED, algorithm="iterative", extrapolation=2, accelerator="iqn-ils").stats
    ait = go(oscillator_ssp, h, DAMPED, algorithm="iterative", extrapolation=2, accelerator="aitken").stats
    assert iqn.iterations < 0.5 * ait.iterations
    assert iqn.iterations / iqn.steps < 4.0


def test_undamped_energy_error_is_bounded_and_second_order(oscillator_ssp):
    """Linear interpolation (extrapolation=1): the energy error oscillates, it does not drift, and
    falls as H^2; Jacobi ZOH at the same step gains energy without bound."""
    errs = []
    for h in (0.02, 0.01):
        r = go(oscillator_ssp, h, UNDAMPED, stop=5.0, algorithm="iterative", extrapolation=1).result
        z = np.column_stack([r["mass.x"], r["mass.v"], r["spring.x"], r["spring.v"]])
        e = UNDAMPED.energy(z)
        errs.append(np.max(np.abs(e - e[0])) / e[0])
        half = len(e) // 2
        assert np.max(np.abs(e[half:] - e[0])) < 1.5 * np.max(np.abs(e[:half] - e[0]))   # no drift
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.25)
    assert errs[1] < 2e-3
    jac = go(oscillator_ssp, 0.01, UNDAMPED, stop=5.0).result
    zj = np.column_stack([jac["mass.x"], jac["mass.v"], jac["spring.x"], jac["spring.v"]])
    assert UNDAMPED.energy(zj)[-1] > 10 * UNDAMPED.energy(zj)[0]


def test_non_convergence_is_reported_with_connection_time_and_advice(oscillator_ssp):
    with pytest.raises(SimulationError) as info:
        go(oscillator_ssp, 0.15, DAMPED, algorithm="iterative", accelerator="none", max_iterations=3)
    msg = str(info.value)
    assert "did not converge" in msg and "t = 0 s" in msg and "after 3 iterations" in msg
    assert "->" in msg and "smaller --step" in msg
