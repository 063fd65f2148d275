"""Girder and drum bearing physics (seed 001 eq. 6, 10, Table 6)."""
import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.signal import argrelmax

from cranefmu.physics.girder import (
    GirderModel, GirderParams, damping_from_decrement, energy, eq10_decrement, girder_damping, log_decrement,
    modal_mass,
)
from cranefmu.physics.params import ParameterError

P = GirderParams()
LOAD = -1800.0 * 9.81  # rope force on the trolley, downward


def _u(fy: float) -> np.ndarray:
    return np.array([0.0, fy, 0.0])


def _run(m: GirderModel, x0: np.ndarray, u: np.ndarray, t_end: float, n: int = 20001):
    ts = np.linspace(0.0, t_end, n)
    sol = solve_ivp(lambda t, x: m.derivatives(t, x, u), (0.0, t_end), x0, method="DOP853", rtol=1e-10,
                    atol=1e-13, t_eval=ts)
    assert sol.status == 0
    return ts, sol.y


@pytest.mark.parametrize("bearing", ["elastic", "rigid"])
def test_static_deflection_is_force_over_stiffness(bearing):
    p = dataclasses.replace(P, bearing=bearing, g=0.0)
    m = GirderModel(p)
    x0 = m.initial_state(_u(LOAD))
    c = p.c1 if bearing == "rigid" else 1.0 / (1.0 / p.c1 + 1.0 / p.c3)  # springs in series
    y = m.output_values(0.0, x0, _u(LOAD))
    assert y[6] == pytest.approx(LOAD / c, rel=1e-12)
    assert y[1] == pytest.approx(p.height + LOAD / c, rel=1e-12)
    assert y[7] == pytest.approx(LOAD / p.c1, rel=1e-12)
    assert np.max(np.abs(m.derivatives(0.0, x0, _u(LOAD)))) < 1e-12


def test_static_deflection_with_own_weight_stays_at_rest():
    m = GirderModel(P)
    u = _u(LOAD)
    x0 = m.initial_state(u)
    assert x0[0] == pytest.approx((LOAD - (P.m1 + P.m3) * P.g) / P.c1, rel=1e-12)
    assert x0[2] - x0[0] == pytest.approx((LOAD - P.m3 * P.g) / P.c3, rel=1e-12)
    ts, ys = _run(m, x0, u, 1.0, 101)
    drift = np.max(np.abs(ys - x0[:, None]), axis=1)
    # rounding of the static solution (~1e-13 m/s^2) only: sub-picometre, sub-nm/s
    assert drift[[0, 2]].max() < 1e-12 and drift[[1, 3]].max() < 1e-9


def test_rigid_bearing_frequency():
    p = dataclasses.replace(P, bearing="rigid", b1=0.0)
    m = GirderModel(p)
    u = _u(LOAD)
    x0 = m.initial_state(u) + np.array([1e-3, 0.0, 1e-3, 0.0])
    ts, ys = _run(m, x0, u, 0.5)
    q = ys[0] - m.initial_state(u)[0]
    # upward zero crossings, interpolated linearly
    i = np.flatnonzero((q[:-1] < 0.0) & (q[1:] >= 0.0))
    crossings = ts[i] - q[i] * (ts[i + 1] - ts[i]) / (q[i + 1] - q[i])
    period = np.mean(np.diff(crossings))
    assert 2.0 * math.pi / period == pytest.approx(math.sqrt(p.c1 / (p.m1 + p.m3)), rel=1e-3)
    assert np.array_equal(ys[0], ys[2])  # drum rides on the girder


def test_elastic_bearing_eigenfrequencies():
    """Linear 2-DOF: the Jacobian's eigenvalues are the two undamped modes of (m1, m3; c1, c3)."""
    p = dataclasses.replace(P, b1=0.0, b3=0.0)
    m = GirderModel(p)
    u = _u(LOAD)
    x0 = m.initial_state(u)
    jac = np.column_stack([(m.derivatives(0.0, x0 + e, u) - m.derivatives(0.0, x0 - e, u)) / 2e-6
                           for e in np.eye(4) * 1e-6])
    w_model = np.sort(np.abs(np.linalg.eigvals(jac).imag))[::2]
    k = np.array([[p.c1 + p.c3, -p.c3], [-p.c3, p.c3]])
    m_inv_sqrt = np.diag([p.m1 ** -0.5, p.m3 ** -0.5])
    w_exact = np.sqrt(np.linalg.eigvalsh(m_inv_sqrt @ k @ m_inv_sqrt))
    assert w_model == pytest.approx(np.sort(w_exact), rel=1e-6)
    # the fundamental is the girder mode, within 0.2 % of sqrt(c1 / (m1 + m3))
    assert w_model[0] == pytest.approx(math.sqrt(p.c1 / modal_mass(p)), rel=2e-3)


def test_beam_reduced_mass_is_17_35_of_the_girder_and_sets_the_frequency():
    """mass_model = 'beam': a uniform simply supported girder of mass M moves at mid-span with Rayleigh's
    17/35 M (static deflection shape, c1 = 48 E I / L^3); 5000 kg -> 2428.6 kg, and the rigid-bearing mode
    oscillates at sqrt(c1 / (17/35 M + m3)); for the beam alone Rayleigh's frequency is 0.72 % above the exact
    first bending mode's sqrt(pi^4 E I / (2 L^3) / (M / 2)) (an upper bound, as Rayleigh's quotient must be)."""
    p = dataclasses.replace(P, mass_model="beam", girder_mass=5000.0, bearing="rigid", b1=0.0)
    assert modal_mass(p) - p.m3 == pytest.approx(2428.571428571, rel=1e-12)
    m = GirderModel(p)
    u = _u(LOAD)
    jac = np.column_stack([(m.derivatives(0.0, m.initial_state(u) + e, u) - m.derivatives(0.0, m.initial_state(u) - e, u))
                           / 2e-6 for e in np.eye(4) * 1e-6])
    w = np.max(np.abs(np.linalg.eigvals(jac[:2, :2]).imag))
    assert w == pytest.approx(math.sqrt(p.c1 / (17.0 / 35.0 * 5000.0 + p.m3)), rel=1e-9)
    # the girder alone: Rayleigh (static shape) against the exact sine mode, both with c1 = 48 E I / L^3
    ei_over_l3 = p.c1 / 48.0
    exact = math.sqrt(math.pi ** 4 / 2.0 * ei_over_l3 / 2500.0)
    assert 0.0 < math.sqrt(p.c1 / (17.0 / 35.0 * 5000.0)) / exact - 1.0 < 7.5e-3
    with pytest.raises(ParameterError, match=r"girder\.m1 = 4000.0 is not used with girder\.mass_model = 'beam'"):
        dataclasses.replace(p, m1=4000.0)


@pytest.mark.parametrize("damping_model,height", [("table", 1.0), ("decrement", 1.0), ("decrement", 2.0)])
def test_logarithmic_decrement(damping_model, height):
    p = dataclasses.replace(P, bearing="rigid", damping_model=damping_model, girder_height=height)
    if damping_model == "decrement":
        assert log_decrement(p) == pytest.approx(eq10_decrement(height, p.span), rel=1e-12)
    m = GirderModel(p)
    u = _u(LOAD)
    x_static = m.initial_state(u)
    x0 = x_static + np.array([5e-3, 0.0, 5e-3, 0.0])
    ts, ys = _run(m, x0, u, 0.6, 60001)
    q = ys[0] - x_static[0]
    peaks = argrelmax(q)[0][:2]
    # refine each peak with a parabola through three samples
    amps = []
    for i in peaks:
        a, b, c = q[i - 1], q[i], q[i + 1]
        amps.append(b - 0.125 * (a - c) ** 2 / (a - 2 * b + c))
    assert math.log(amps[0] / amps[1]) == pytest.approx(log_decrement(p), rel=1e-4)


def test_eq10_small_damping_form():
    """Eq. 10's b1 = delta/pi sqrt(c m) is the small-delta limit of the exact relation used."""
    delta = 0.06
    exact = damping_from_decrement(delta, P.c1, P.m1)
    assert exact == pytest.approx(delta / math.pi * math.sqrt(P.c1 * P.m1), rel=1e-3)
    # Table 6's b1 = 2.3e4 N s/m corresponds to delta ~ 0.47
    assert log_decrement(P) == pytest.approx(0.465, abs=5e-3)
    assert girder_damping(P) == P.b1


@pytest.mark.parametrize("bearing", ["elastic", "rigid"])
def test_energy_conserved_without_damping(bearing):
    p = dataclasses.replace(P, bearing=bearing, b1=0.0, b3=0.0)
    m = GirderModel(p)
    u = _u(LOAD)
    x0 = m.initial_state(u) + np.array([2e-3, 0.05, -1e-4 if bearing == "elastic" else 2e-3, 0.05])
    ts, ys = _run(m, x0, u, 0.2, 2001)
    e = np.array([energy(x, LOAD, p) for x in ys.T])
    e_static = energy(m.initial_state(u), LOAD, p)
    assert np.max(np.abs(e - e[0])) < 1e-6 * (e[0] - e_static)


def test_horizontal_forces_are_ignored_and_outputs_fixed():
    m = GirderModel(P)
    x0 = m.initial_state(_u(LOAD))
    u = np.array([500.0, LOAD, -300.0])
    assert np.array_equal(m.derivatives(0.0, x0, u), m.derivatives(0.0, x0, _u(LOAD)))
    y = m.output_values(0.0, x0, u)
    assert (y[0], y[2], y[3], y[5]) == (P.x_pos, P.z_pos, 0.0, 0.0)


def test_bad_parameters_are_refused():
    with pytest.raises(ParameterError, match=r"girder\.girder_height"):
        GirderParams(damping_model="decrement", girder_height=0.5)
    with pytest.raises(ParameterError, match=r"girder\.c1"):
        GirderParams(c1=0.0)
    with pytest.raises(ParameterError, match=r"girder\.bearing"):
        GirderParams(bearing="soft")
