"""The first coupled scene: Rope + Pendulum through the master, against physics and a monolithic solve."""
import math

import numpy as np
import pytest

from cranefmu.master.run import run
from cranefmu.analysis.reference import elastic_pendulum as reference

G = 9.81
E, A, L, M = 1.0e11, 5.655e-5, 10.0, 1000.0
C = E * A / L                 # rope stiffness of the scene [N/m]
DELTA = M * G / C             # static stretch [m]


def zero_crossing_period(t, x):
    """Mean period from upward zero crossings (linear interpolation)."""
    i = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    tc = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    return float(np.mean(np.diff(tc)))


@pytest.fixture(scope="module")
def damped(built):
    return run("elastic_pendulum", stop_time=20.0, step_size=1e-3).result


def test_small_angle_period_is_the_elastic_pendulum_period(damped):
    # swing of a spring pendulum: omega^2 = g / (L + delta_static), to first order in the amplitude;
    # the 5 deg amplitude adds (1 + theta0^2/16) to the period
    theta0 = math.radians(5.0)
    expected = 2 * math.pi * math.sqrt((L + DELTA) / G) * (1 + theta0 ** 2 / 16)
    measured = zero_crossing_period(damped["time"], damped["pendulum.theta"])
    assert measured == pytest.approx(expected, rel=0.005)


def test_sway_matches_the_monolithic_solve_within_1_percent(damped):
    ref = reference(20.0, damped["time"])
    amplitude = np.max(np.abs(ref["pendulum.theta"]))
    err = np.max(np.abs(damped["pendulum.theta"] - ref["pendulum.theta"]))
    assert err < 0.01 * amplitude


def test_starts_in_radial_equilibrium(damped):
    # released at rest with the rope stretched to m g cos(theta0): tension starts at m g cos(theta0)
    assert damped["rope.tension"][0] == pytest.approx(M * G * math.cos(math.radians(5.0)), rel=1e-6)
    assert damped["pendulum.theta"][0] == pytest.approx(math.radians(5.0), rel=1e-9)


def axial_energy(res):
    """Energy of the axial (vertical) oscillation about the static equilibrium [J]."""
    y_eq = -(L + DELTA)
    return 0.5 * M * res["pendulum.vy"] ** 2 + 0.5 * C * (res["pendulum.y"] - y_eq) ** 2


@pytest.mark.parametrize("h", [1e-3, 2e-3])
def test_jacobi_zero_order_hold_gains_energy_by_the_predicted_factor(built, h):
    """Known limitation (undamped rope, Jacobi, zero-order hold): the step matrix of an undamped
    spring-mass has determinant 1 + (omega H)^2 / 2, so the oscillation energy grows by that factor
    per step on average.  The fitted growth rate must match it within 3 %."""
    a = 1e-3  # initial axial offset [m], small enough that the rope never goes slack
    res = run("elastic_pendulum", stop_time=5.0, step_size=h, algorithm="jacobi", extrapolation=0, parameters={
        "rope.zeta": 0.0, "pendulum.start": "position", "pendulum.theta0": 0.0, "pendulum.x0": 0.0,
        "pendulum.y0": -(L + DELTA + a)}).result
    e = axial_energy(res)
    n = np.arange(len(e))
    slope = np.polyfit(n, np.log(e), 1)[0]  # log-energy per step (the 2-step ripple averages out)
    omega = math.sqrt(C / M)
    assert slope == pytest.approx(math.log(1 + (omega * h) ** 2 / 2), rel=0.03)
    assert e[-1] > 2 * e[0]  # it really grows


def test_gauss_seidel_and_extrapolation_run_and_stay_close(built):
    res = run("elastic_pendulum", stop_time=5.0, step_size=1e-3, algorithm="gauss-seidel", extrapolation=1).result
    ref = reference(5.0, res["time"])
    err = np.max(np.abs(res["pendulum.theta"] - ref["pendulum.theta"]))
    assert err < 0.01 * math.radians(5.0)
