"""Observed order of the global error of Jacobi and Gauss-Seidel with extrapolation 0, 1, 2 on the
two-mass oscillator, against its exact solution (matrix exponential): about p + 1."""
import numpy as np
import pytest

from cranefmu.master.run import run
from cranefmu_support.oscillator.exact import Oscillator

OSC = Oscillator(d1=0.5, dc=2.0)          # omega = 7.0 and 15.8 rad/s, lightly damped
X0 = 0.1                                   # mass released 0.1 m from rest
STEPS = [2e-3, 2e-3 * 10 ** 0.5, 2e-2]     # a decade of H


def global_error(ssp, h, algorithm, p):
    res = run(ssp, stop_time=1.0, step_size=h, algorithm=algorithm, extrapolation=p,
              parameters={**OSC.parameters(), "mass.x0": X0}).result
    exact = OSC.solution(res["time"], np.array([X0, 0.0, 0.0, 0.0]))
    return max(np.max(np.abs(res["mass.x"] - exact[:, 0])), np.max(np.abs(res["spring.x"] - exact[:, 2])))


@pytest.mark.parametrize("algorithm", ["jacobi", "gauss-seidel"])
@pytest.mark.parametrize("p", [0, 1, 2])
def test_observed_order_is_extrapolation_order_plus_one(oscillator_ssp, algorithm, p):
    errors = [global_error(oscillator_ssp, h, algorithm, p) for h in STEPS]
    order = np.polyfit(np.log(STEPS), np.log(errors), 1)[0]
    assert order == pytest.approx(p + 1, abs=0.3), errors
    assert errors[0] < 0.02 * X0


def test_gauss_seidel_order_override(oscillator_ssp):
    from cranefmu.errors import SettingsError

    pars = {**OSC.parameters(), "mass.x0": X0}
    mass_first = run(oscillator_ssp, stop_time=0.5, step_size=1e-2, algorithm="gauss-seidel", order=["mass", "spring"],
                     parameters=pars).result
    spring_first = run(oscillator_ssp, stop_time=0.5, step_size=1e-2, algorithm="gauss-seidel",
                       order=["spring", "mass"], parameters=pars).result
    exact = OSC.solution(mass_first["time"], np.array([X0, 0.0, 0.0, 0.0]))
    for r in (mass_first, spring_first):
        assert np.max(np.abs(r["mass.x"] - exact[:, 0])) < 0.1 * X0
    assert np.max(np.abs(mass_first["mass.x"] - spring_first["mass.x"])) > 1e-5   # really another scheme
    with pytest.raises(SettingsError, match="gauss-seidel order \\['mass'\\] is not allowed"):
        run(oscillator_ssp, stop_time=0.1, step_size=1e-2, algorithm="gauss-seidel", order=["mass"])
