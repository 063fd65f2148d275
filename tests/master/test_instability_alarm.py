"""The default instability alarm (master/divergence.py): an unstable explicit coupling whose blow-up
a slack rope bounds (finite nonsense without the alarm) is stopped with the bond, the time and the
advice, also when it saturates before it looks geometric, and in scenes without power bonds;
stable runs of every scene at its default step raise no alarm (every parameter set:
benchmarks/alarm_margins.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.master.divergence import GrowthAlarm, ImbalanceAlarm
from cranefmu.master.power_bonds import ROUNDOFF_SPEED
from cranefmu.errors import SimulationError
from cranefmu.master.run import run
from cranefmu.scenes import SCENES
from pendulum_cases import G, at_rest_on_rope, one_d_pendulum


# the cases were measured with jacobi and zero-order hold (the global defaults; the scene stores others)
HOLD = dict(algorithm="jacobi", extrapolation=0)

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
        run("elastic_pendulum", stop_time=stop, step_size=h, parameters=params, progress=False, **HOLD)
    msg = str(err.value)
    for needle in ("power bond hook", "rope and pendulum", "t = ", "smaller --step", "--algorithm iterative",
                   "--adaptive", "--no-instability-alarm"):
        assert needle in msg, (needle, msg)
    assert "grew" in msg or "created or destroyed" in msg, msg
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
        run("elastic_pendulum", stop_time=stop, step_size=h, parameters=params, progress=False, **HOLD)
    assert err.value.result["rope.tension"].max() < 1.1 * static


def test_alarm_off_runs_on_to_finite_nonsense(built):
    """instability_alarm=False: the 1 kg hook runs to the end, finite, tension far above static."""
    params, h, stop, static = SILENT["hook_of_1_kg"]
    res = run("elastic_pendulum", stop_time=stop, step_size=h, parameters=params, progress=False, **HOLD,
              instability_alarm=False).result
    assert res["time"][-1] == pytest.approx(stop)
    assert np.all(np.isfinite(res["rope.tension"])) and res["rope.tension"].max() > 5 * static


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_stable_scene_at_its_default_step_raises_no_alarm(built, scene):
    r = run(scene, stop_time=2.0, progress=False)   # the scene's stored settings
    assert r.stats.steps == round(2.0 / r.settings.step_size)
    assert all(math.isfinite(e) for e in r.stats.bond_energy.values()) and r.stats.bond_energy


def test_scene_at_rest_at_a_fine_step_raises_no_alarm(built):
    """overhead_lift at rest (its motor starts at 0.2 s) with its stored jacobi x1 at H = 0.25 ms: the
    hook bond's residuals are round-off, 1e-17 to 1e-14 J, and jumped 84 times in 3 steps, which
    stopped the run at t = 0.01225 s before the growth test had a round-off floor.  They stay three
    orders below the floor ROUNDOFF_SPEED |f| h (7e-11 J at the 294 N static tension)."""
    h = 2.5e-4
    r = run("overhead_lift", stop_time=0.05, step_size=h, progress=False)
    assert r.settings.extrapolation == 1 and r.stats.steps == 200
    res = r.result
    assert np.ptp(res["rope.tension"]) < 1e-6 * res["rope.tension"][0]          # at rest
    assert np.all(res["bond.hook.dE"] < 1e-3 * ROUNDOFF_SPEED * res["rope.tension"] * h)


def test_saturating_instability_is_stopped(built):
    """At 2 x the limit the axial oscillation grows only 3.3 times before the rope goes slack each
    period and the bounce is bounded (without the alarm: tension 24-31 x static to the end of the run,
    benchmarks/results/alarm_margins.md); the imbalance detector stops it while the tension is < 8 x
    static, naming bond, components, time and advice."""
    params, h, static = one_d_pendulum(2.0)
    with pytest.raises(SimulationError) as err:
        run("elastic_pendulum", stop_time=20.0, step_size=h, parameters=params, progress=False, **HOLD)
    msg, rows = str(err.value), err.value.result
    for needle in ("power bond hook", "rope and pendulum", "created or destroyed", "--no-instability-alarm",
                   f"t = {rows['time'][-1]:.9g} s"):
        assert needle in msg, (needle, msg)
    assert rows["time"][-1] < 10.0 and rows["rope.tension"].max() < 8.0 * static
    assert rows["rope.slack"].max() == 1.0          # it had gone slack: the growth was bounded


def test_stable_run_just_inside_the_limit_raises_no_alarm(built):
    """0.9 x the limit: the axial oscillation decays (slowly), no alarm (largest window ratio 0.12)."""
    params, h, static = one_d_pendulum(0.9)
    r = run("elastic_pendulum", stop_time=5.0, step_size=h, parameters=params, progress=False, **HOLD)
    assert r.stats.steps == round(5.0 / h) and r.result["rope.tension"].max() < 1.35 * static


@pytest.mark.parametrize("factor, stopped", [(0.3, False), (0.5, True), (1.1, True)])
def test_oscillator_jacobi_is_stopped_beyond_its_limit_or_when_far_too_coarse(oscillator_ssp, factor, stopped):
    """Generic (two FMUs that are no crane): the damped two-mass oscillator with Jacobi and zero-order
    hold at factor x the H where the spectral radius of its step matrix is 1, 400 steps.  Its coupling
    force swings through zero, so the energy the coupling makes up per window is ~ 1.6 omega H of what
    the bond carries: at 0.5 x the limit (stable, error 18 % of the amplitude against the exact
    solution, checked here) it is stopped as far too coarse; at 0.3 x (error 10 %) it runs."""
    from cranefmu_support.oscillator.runs import DAMPED, Z0, go, jacobi_limit

    h = factor * jacobi_limit()
    if not stopped:
        assert go(oscillator_ssp, h, DAMPED, stop=400 * h, progress=False).stats.steps == 400
        return
    with pytest.raises(SimulationError, match="power bond coupling .between spring and mass.: "):
        go(oscillator_ssp, h, DAMPED, stop=400 * h, progress=False)
    if factor < 1.0:
        res = go(oscillator_ssp, h, DAMPED, stop=400 * h, progress=False, instability_alarm=False).result
        assert np.max(np.abs(res["mass.x"] - DAMPED.solution(res["time"], Z0)[:, 0])) > 0.15 * Z0[0]


@pytest.fixture(scope="module")
def oscillator_without_bonds(tmp_path_factory):
    import re

    from cranefmu_support.oscillator import SSD, build_oscillator

    # an empty power-bond annotation: the scene declares that it has none (none are inferred)
    empty = ('<ssd:Annotations><ssc:Annotation type="org.cranefmu.powerbonds"><cf:PowerBonds '
             'xmlns:cf="urn:org.cranefmu.powerbonds"/></ssc:Annotation></ssd:Annotations>')
    return build_oscillator(tmp_path_factory.mktemp("oscillator_nobonds"),
                            ssd=re.sub(r"<ssd:Annotations>.*</ssd:Annotations>", empty, SSD, flags=re.S))


@pytest.mark.parametrize("factor, stopped", [(0.9, False), (1.1, True)])
def test_scene_without_power_bonds_is_watched_by_its_connections(oscillator_without_bonds, factor, stopped):
    """No power bonds: the change per step of a coupling value grows geometrically beyond the limit
    (measured 1.02 per step at 1.1 x); the error names the connection."""
    from cranefmu_support.oscillator.runs import DAMPED, go, jacobi_limit

    h = factor * jacobi_limit()
    if not stopped:
        assert go(oscillator_without_bonds, h, DAMPED, stop=400 * h, progress=False).stats.steps == 400
        return
    with pytest.raises(SimulationError, match=r"connection \S+ -> \S+: its change per step grew .* geometric.*"
                                              r"--no-instability-alarm"):
        go(oscillator_without_bonds, h, DAMPED, stop=400 * h, progress=False)


def test_imbalance_alarm_on_synthetic_windows():
    """r = |net imbalance| / capacity per window of 50 steps: 3 windows over 0.5 in a row trip it; one
    window (an event) does not, nor do windows of a bond at rest (below 1e-6 of the largest capacity),
    which neither count nor break a run."""
    def first_trip(ratios, capacity=None):
        alarm = ImbalanceAlarm(1)
        for w, r in enumerate(ratios):
            c = 1.0 if capacity is None else capacity[w]
            for _ in range(50):
                hit = alarm.update([r * c / 50], [c / 50])
                if hit is not None:
                    return w, hit
        return None

    w, hit = first_trip([0.1, 0.6, 0.7, 0.65, 0.1])
    assert w == 3 and hit.steps == 150 and hit.ratio == pytest.approx(0.6)
    assert first_trip([0.1, 0.9, 0.1, 0.9, 0.1, 0.9, 0.4]) is None
    assert first_trip([0.9, 0.9, 2.0, 0.9], capacity=[1.0, 1.0, 1e-9, 1.0])[0] == 3
    assert first_trip([0.49] * 20) is None


def test_growth_alarm_on_synthetic_residuals():
    """Geometric growth of 1.05 per step trips it; a power of the time (t^3, from rest), a slow
    geometric gain of 1.005 per step (below ``per_step``) and a jump at an event do not."""
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
    # a jump at an event, then decay: truck_telescope at H = 10 ms, x1, when the telescoping stops (the
    # residual rises linearly to 1e-7 J, then 3.5e-6 and 3.5e-2 J); tripped the one-sided test at step 2003
    jump = np.concatenate([np.full(1990, 5e-9), 1.26e-8 * np.arange(1, 10), [3.5e-6], 3.5e-2 * 0.7 ** np.arange(60)])
    assert first_trip(jump) is None


def test_growth_alarm_waits_for_the_roundoff_floor():
    """A residual below the bond's round-off floor is not judged: round-off that jumps 84 times in 3
    steps (overhead_lift at rest, H = 0.25 ms: 2e-17 J, then 3e-16, 1.6e-15, 6.4e-15 J) trips the test
    without the floor and not with it (7e-11 J); geometric growth of 1.05 per step from round-off trips
    it soon after the residual has passed the floor (within 48 steps: a block's maximum must pass it)."""
    def first_trip(values, roundoff):
        alarm = GrowthAlarm(1)
        for n, v in enumerate(values):
            hit = alarm.update([v], [v], None if roundoff is None else [roundoff])
            if hit is not None:
                return n, hit
        return None

    rest = np.concatenate([np.full(46, 2.3e-17), [7.6e-17, 3.0e-16, 1.64e-15, 6.36e-15, 2.0e-15, 2.2e-16]])
    assert first_trip(rest, None) is not None
    assert first_trip(rest, 7e-11) is None
    n = np.arange(1, 3001)
    growth = 1e-17 * 1.05 ** n
    trip = first_trip(growth, 7e-11)
    assert trip is not None and 7e-11 < growth[trip[0]] < 10 * 7e-11     # measured 4.1 x the floor
    assert trip[1].per_step() == pytest.approx(1.05, rel=1e-9)
