"""Adaptive macro step on the damped two-mass oscillator: error below the requested tolerance with
fewer steps than the cheapest fixed step that meets it; discrete outputs switching inside a step
are located to the minimum step by rollback."""
import numpy as np
import pytest
from scipy.optimize import brentq

from cranefmu.errors import SettingsError
from cranefmu.master.run import run
from cranefmu_support.oscillator.exact import Oscillator

OSC = Oscillator(d1=3.0, dc=3.0, d2=3.0)   # decays: a fixed step is too fine for most of the run
X0, T = 0.1, 6.0
Z0 = np.array([X0, 0.0, 0.0, 0.0])


def relative_error(res):
    exact = OSC.solution(res["time"], Z0)
    return max(np.max(np.abs(res["mass.x"] - exact[:, 0])), np.max(np.abs(res["spring.x"] - exact[:, 2]))) / X0


def go(ssp, h, **kw):
    return run(ssp, stop_time=T, step_size=h, extrapolation=1, parameters={**OSC.parameters(), "mass.x0": X0}, **kw)


def test_error_below_tolerance_with_fewer_steps_than_the_cheapest_fixed_step(oscillator_ssp):
    tol = 1e-3
    adaptive = go(oscillator_ssp, 1e-3, adaptive=True, tolerance=tol)
    assert relative_error(adaptive.result) < tol
    # fixed steps: second order (extrapolation 1), so the largest fixed step meeting tol follows
    # from two runs; the adaptive run must cost fewer steps (rejected ones included)
    e1, e2 = (relative_error(go(oscillator_ssp, h).result) for h in (1e-2, 5e-3))
    assert e1 > tol > e2
    order = np.log(e1 / e2) / np.log(2.0)
    assert order == pytest.approx(2.0, abs=0.3)
    h_fixed = 5e-3 * (tol / e2) ** (1 / order)
    cheapest_fixed = T / h_fixed
    st = adaptive.stats
    assert st.steps + st.rejections < 0.6 * cheapest_fixed
    assert st.max_step > 10 * st.min_step


def test_discrete_output_switch_is_located_to_the_minimum_step(oscillator_ssp):
    x_flag, h_min = 0.05, 1e-5
    res = run(oscillator_ssp, stop_time=0.5, step_size=1e-2, adaptive=True, min_step=h_min, extrapolation=1,
              parameters={**OSC.parameters(), "mass.x0": X0, "mass.x_flag": x_flag})
    r = res.result
    t_switch = brentq(lambda t: OSC.solution(np.array([t]), Z0)[0, 0] - x_flag, 0.0, 0.3)
    i = int(np.flatnonzero(np.diff(r["mass.flag"]) != 0)[0])
    assert r["mass.flag"][i] == 1 and r["mass.flag"][i + 1] == 0
    assert r["mass.x"][i] > x_flag >= r["mass.x"][i + 1]            # the co-simulated crossing ...
    assert r["time"][i + 1] - r["time"][i] <= h_min * (1 + 1e-6)   # ... bracketed to the minimum step
    assert abs(r["time"][i + 1] - t_switch) < 1e-4                  # the exact one, within the coupling error
    assert res.stats.rejections >= 3          # bisection from 1e-2 down to 1e-5


def test_bad_adaptive_settings_are_named(oscillator_ssp):
    for kw, needle in [(dict(min_step=1.0), "min_step = 1.0"), (dict(tolerance=0.0), "tolerance = 0.0"),
                       (dict(step_control="pid"), "step_control = 'pid'")]:
        with pytest.raises(SettingsError, match=needle.replace("(", r"\(")):
            go(oscillator_ssp, 1e-3, adaptive=True, **kw)
