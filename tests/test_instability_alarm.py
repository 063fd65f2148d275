"""The default instability alarm (master/divergence.py): an unstable explicit coupling whose blow-up
a slack rope bounds (finite nonsense without the alarm) is stopped with the bond, the time and the
advice; stable runs of every scene at its default step raise no alarm."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.master.divergence import GrowthAlarm
from cranefmu.master.errors import SimulationError
from cranefmu.master.run import run
from cranefmu.scenes import SCENES
from test_extremes import G, at_rest_on_rope


SILENT = {
    # (parameters, H [s], stop [s], static tension [N]); without the alarm each run finishes finite
    "rope_1000x_stiffer": (at_rest_on_rope(1e14, 1000.0), 1e-3, 1.0, 1000.0 * G),   # peak 891 kN
    "step_10_rope_periods": (at_rest_on_rope(1e11, 1000.0), 2.64, 30.0, 1000.0 * G),  # peak 4e38 N
    "hook_of_1_kg": (at_rest_on_rope(1e11, 1.0), 1e-3, 1.0, 1.0 * G),                # peak 137 N
}


@pytest.mark.parametrize("case", sorted(SILENT))
def test_unstable_coupling_is_stopped_by_default(built, case):
    params, h, stop, _ = SILENT[case]
    with pytest.raises(SimulationError) as err:
        run("elastic_pendulum", stop_time=stop, step_size=h, parameters=params, progress=False)
    msg = str(err.value)
    for needle in ("power bond hook", "rope and pendulum", "grew", "t = ", "smaller --step",
                   "--algorithm iterative"):
        assert needle in msg, (needle, msg)
    rows = err.value.result
    assert rows is not None and rows["time"][-1] < stop
    assert f"t = {rows['time'][-1]:.9g} s" in msg
    for name in rows.dtype.names:
        assert np.all(np.isfinite(rows[name])), name


def test_the_stiff_rope_is_stopped_before_its_tension_is_nonsense(built):
    """Measured without the alarm: 891 kN peak.  With it the run stops while the tension is still
    within 10 % of static (the growth is seen in the residual long before in the tension)."""
    params, h, stop, static = SILENT["rope_1000x_stiffer"]
    with pytest.raises(SimulationError) as err:
        run("elastic_pendulum", stop_time=stop, step_size=h, parameters=params, progress=False)
    assert err.value.result["rope.tension"].max() < 1.1 * static


def test_alarm_off_runs_on_to_finite_nonsense(built):
    """instability_alarm=False: the 1 kg hook runs to the end, finite, tension far above static."""
    params, h, stop, static = SILENT["hook_of_1_kg"]
    res = run("elastic_pendulum", stop_time=stop, step_size=h, parameters=params, progress=False,
              instability_alarm=False).result
    assert res["time"][-1] == pytest.approx(stop)
    assert np.all(np.isfinite(res["rope.tension"])) and res["rope.tension"].max() > 5 * static


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_stable_scene_at_its_default_step_raises_no_alarm(built, scene):
    r = run(scene, stop_time=2.0, progress=False)
    assert r.stats.steps == 2000
    assert all(math.isfinite(e) for e in r.stats.bond_energy.values()) and r.stats.bond_energy


@pytest.mark.parametrize("factor, stopped", [(0.9, False), (1.1, True), (1.7, True)])
def test_oscillator_jacobi_is_stopped_just_beyond_its_spectral_limit(oscillator_ssp, factor, stopped):
    """Generic (two FMUs that are no crane): the damped two-mass oscillator with Jacobi and zero-order
    hold at factor x the H where the spectral radius of its step matrix is 1, 400 steps."""
    from test_master_iterative import DAMPED, go, jacobi_limit

    h = factor * jacobi_limit()
    if not stopped:
        assert go(oscillator_ssp, h, DAMPED, stop=400 * h, progress=False).stats.steps == 400
        return
    with pytest.raises(SimulationError, match="power bond coupling .between spring and mass.: its energy residual"):
        go(oscillator_ssp, h, DAMPED, stop=400 * h, progress=False)


def test_growth_alarm_on_synthetic_residuals():
    """Geometric growth of 1.05 per step trips it; a power of the time (t^3, from rest) and a slow
    geometric gain of 1.005 per step (below ``per_step``) do not."""
    def first_trip(values):
        alarm = GrowthAlarm(1)
        for n, v in enumerate(values):
            hit = alarm.update(np.array([v]), np.array([1.0]))
            if hit is not None:
                return n, hit
        return None

    n = np.arange(1, 3001)
    trip = first_trip(1e-6 * 1.05 ** n)
    assert trip is not None and trip[1].per_step() == pytest.approx(1.05, rel=1e-9)
    assert first_trip(1e-6 * n ** 3.0) is None
    assert first_trip(1e-6 * 1.005 ** n) is None
