"""Hoist drive physics: Kloss motor (seed 001 eq. 4, Table 4), drivetrain (eq. 5), kinematic trapezoid."""
import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from cranefmu.physics.drive import (
    DriveModel, DriveParams, drivetrain_accelerations, drivetrain_energy, motor_rhs, nominal_slip,
    nominal_torque, pretwisted_angles, steady_state_slip, steady_state_torque, synchronous_speed, trapezoid,
)
from cranefmu.physics.params import ParameterError

P = DriveParams()
G = 9.81


def test_table4_derived_numbers():
    assert synchronous_speed(P) == pytest.approx(104.72, abs=5e-3)
    assert nominal_torque(P) == pytest.approx(101.05, abs=5e-3)
    assert nominal_slip(P) == pytest.approx(0.055, abs=1e-4)


def test_nominal_torque_gives_nominal_slip():
    assert steady_state_slip(nominal_torque(P), P) == pytest.approx(0.055, abs=1e-3)
    assert steady_state_torque(steady_state_slip(80.0, P), P) == pytest.approx(80.0, rel=1e-12)


def test_kloss_curve_peaks_at_critical_slip():
    res = minimize_scalar(lambda s: -steady_state_torque(s, P), bounds=(1e-3, 1.0), method="bounded",
                          options=dict(xatol=1e-10))
    assert res.x == pytest.approx(P.s_k, rel=1e-4)
    assert -res.fun == pytest.approx(P.M_k, rel=1e-9)
    # M_k / M_n is the 320 % overload of Table 4
    assert P.M_k / nominal_torque(P) == pytest.approx(3.2, rel=1e-3)


@pytest.mark.parametrize("load", [50.0, nominal_torque(P), 250.0])
def test_dynamic_motor_settles_on_static_curve(load):
    """Eq. 4 with a rigid rotor (J_w only) and a constant load torque, supply at nominal frequency."""
    def rhs(t, x):
        slip_freq = P.Omega_s - P.pole_pairs * x[2]
        dm, dth = motor_rhs(x[0], x[1], slip_freq, True, P)
        return [dm, dth, (x[0] - load) / P.J_w]

    # 250 N m exceeds the starting torque (198 N m at s = 1): start those runs near synchronous speed
    w0 = 0.0 if load < steady_state_torque(1.0, P) else 0.9 * synchronous_speed(P)
    sol = solve_ivp(rhs, (0.0, 3.0), [0.0, 0.0, w0], method="Radau", rtol=1e-10, atol=1e-10)
    m_e, _, w = sol.y[:, -1]
    slip = 1.0 - w / synchronous_speed(P)
    assert m_e == pytest.approx(load, rel=1e-6)
    assert slip == pytest.approx(steady_state_slip(load, P), rel=1e-6)
    if load == nominal_torque(P):
        assert slip == pytest.approx(0.055, abs=1e-3)


def test_drivetrain_conserves_energy_without_damping():
    p = dataclasses.replace(P, b_1n=0.0, b_2n=0.0, b_3n=0.0)
    load = 2000.0  # constant drum torque: potential M_L * phi_drum

    def rhs(t, x):
        return np.concatenate((x[4:], drivetrain_accelerations(x[:4], x[4:], 0.0, load, p)))

    def total(x):
        return drivetrain_energy(x[:4], x[4:], p) + load * x[3]

    x0 = np.concatenate((pretwisted_angles(load, p) * 1.3, [2.0, -1.0, 0.5, 0.01]))
    sol = solve_ivp(rhs, (0.0, 0.2), x0, method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)
    e = np.array([total(sol.sol(t)) for t in np.linspace(0.0, 0.2, 400)])
    # the slowest mode (drum on c_3n) has a period of about 11 ms: 0.2 s covers many periods
    scale = drivetrain_energy(x0[:4], x0[4:], p)
    assert np.max(np.abs(e - e[0])) / scale < 1e-6


def test_drivetrain_with_damping_dissipates():
    def rhs(t, x):
        return np.concatenate((x[4:], drivetrain_accelerations(x[:4], x[4:], 0.0, 0.0, P)))
    x0 = np.array([0.0, 0.0, 0.0, 0.0, 5.0, -5.0, 0.0, 0.0])
    sol = solve_ivp(rhs, (0.0, 0.05), x0, method="Radau", rtol=1e-10, atol=1e-12)
    energies = [drivetrain_energy(x[:4], x[4:], P) for x in sol.y.T]
    assert np.all(np.diff(energies) <= 1e-9 * energies[0])
    # momentum about the (gear-reduced) axis is conserved: internal torques only
    j = np.array([P.J_w, P.J_sp, P.J_p1 + P.J_p2 / P.i_p ** 2, P.J_3 / P.i_p])
    assert j @ sol.y[4:, -1] == pytest.approx(j @ x0[4:], abs=1e-9)


def test_static_hold_before_start():
    p = dataclasses.replace(P, start_time=1.0)
    m = DriveModel(p)
    u = np.array([1800.0 * G / 4.0])
    x0 = m.initial_state(u)
    dx = m.derivatives(0.5, x0, u)
    # scale: accelerations a spring-torque of M_L would give on the smallest inertia
    scale = m.load_torque(u) / p.J_sp
    assert np.max(np.abs(dx)) < 1e-12 * scale
    sol = solve_ivp(lambda t, x: m.derivatives(t, x, u), (0.0, 0.99), x0, method="BDF", rtol=1e-10, atol=1e-12)
    y = m.output_values(0.99, sol.y[:, -1], u)
    assert abs(y[0]) < 1e-12 and abs(y[1]) < 1e-12  # payout, payout_rate
    assert y[2] == 0.0  # motor unpowered


def test_pretwist_carries_the_load_torque():
    m = DriveModel(P)
    u = np.array([4000.0])
    x0 = m.initial_state(u)
    # spring c_3n carries M_L at the drum, the fast shafts carry M_L / i_p
    assert P.c_3n * (x0[5] - x0[4] / P.i_p) == pytest.approx(-m.load_torque(u), rel=1e-12)
    assert P.c_1n * (x0[3] - x0[2]) == pytest.approx(-m.load_torque(u) / P.i_p, rel=1e-9)
    assert m.output_values(0.0, x0, u)[0] == 0.0


def test_hoisting_reaches_kloss_operating_point():
    """Full drive lifting a 1800 kg load (4 lines, twin drum): steady drum speed from the Kloss curve."""
    p = dataclasses.replace(P, start_time=0.1, ramp_time=0.5, brake_delay=0.05)
    m = DriveModel(p)
    u = np.array([1800.0 * G / 4.0])
    x0 = m.initial_state(u)
    sol = solve_ivp(lambda t, x: m.derivatives(t, x, u), (0.0, 2.5), x0, method="Radau", rtol=1e-10, atol=1e-10)
    payout, rate, torque, w_motor, _, w_drum, slip = m.output_values(2.5, sol.y[:, -1], u)
    m_motor = m.load_torque(u) / p.i_p
    s_exp = steady_state_slip(m_motor, p)
    assert torque == pytest.approx(m_motor, rel=1e-6)
    assert slip == pytest.approx(s_exp, rel=1e-5)
    assert w_motor == pytest.approx(p.i_p * w_drum, rel=1e-8)
    assert rate == pytest.approx(-p.n_drum_lines * p.R_3 * synchronous_speed(p) * (1 - s_exp) / p.i_p, rel=1e-6)
    assert payout < 0.0  # hoisting winds rope in
    # the hook of a 4-line reeving rises at about Table 6's V_p = 0.208 m/s (that is at nominal slip)
    assert -rate / 4.0 == pytest.approx(0.208, rel=0.05)


def test_power_balance_of_motor_mode():
    """Motor work = load work + energy stored + dissipated: drum power equals -drum_force * payout_rate."""
    m = DriveModel(P)
    u = np.array([3000.0])
    x = m.initial_state(u)
    x[6:] = [100.0, 100.0, 100.0, 100.0 / P.i_p]
    y = m.output_values(0.0, x, u)
    assert m.load_torque(u) * y[5] == pytest.approx(-u[0] * y[1], rel=1e-12)


def test_kinematic_trapezoid():
    p = dataclasses.replace(P, mode="kinematic", start_time=2.0, t_acc=3.0, duration=20.0, payout_speed=0.35)
    m = DriveModel(p)
    u = np.array([5000.0])
    x0 = m.initial_state(u)
    assert np.all(m.derivatives(5.0, x0, u) == 0.0)
    ts = np.linspace(0.0, 30.0, 3001)
    ys = np.array([m.output_values(t, x0, u) for t in ts])
    assert ys[:, 1].max() == pytest.approx(0.35, rel=1e-12)
    assert ys[-1, 0] == pytest.approx(0.35 * (20.0 - 3.0), rel=1e-12)
    assert ys[ts <= 2.0, 0].max() == 0.0
    # the payout is the integral of the rate (trapezoid rule on a piecewise-linear rate is exact)
    integral = np.concatenate(([0.0], np.cumsum(0.5 * (ys[1:, 1] + ys[:-1, 1]) * np.diff(ts))))
    assert np.max(np.abs(integral - ys[:, 0])) < 1e-9
    # drum kinematics and quasi-static torque while the rate is constant
    k = p.n_drum_lines * p.R_3
    y = m.output_values(10.0, x0, u)
    assert y[5] == pytest.approx(-0.35 / k) and y[3] == pytest.approx(p.i_p * y[5])
    assert y[2] == pytest.approx(p.n_drum_lines * u[0] * p.R_3 / p.i_p, rel=1e-12)
    # rate derivative matches a finite difference of the rate
    for t in (3.0, 12.0, 20.5):
        h = 1e-6
        a_fd = (trapezoid(t + h, p)[1] - trapezoid(t - h, p)[1]) / (2 * h)
        assert trapezoid(t, p)[2] == pytest.approx(a_fd, abs=1e-6)


def test_bad_parameters_are_refused():
    with pytest.raises(ParameterError, match=r"drive\.duration"):
        DriveParams(t_acc=5.0, duration=8.0)
    with pytest.raises(ParameterError, match=r"drive\.mode"):
        DriveParams(mode="hydraulic")
    with pytest.raises(ParameterError, match=r"drive\.s_k"):
        DriveParams(s_k=0.04)
    with pytest.raises(ValueError):
        steady_state_slip(1.01 * P.M_k, P)
    assert math.isfinite(steady_state_slip(-P.M_k, P))


@pytest.mark.parametrize("t", [-0.1, 0.05, 0.3, 2.0])   # unpowered/braked, braked ramp, ramp, full supply
def test_plain_float_derivatives_equal_the_equation_helpers(t):
    """The hot-path right-hand side is eq. 4-5 as motor_rhs and drivetrain_accelerations state them."""
    m = DriveModel(DriveParams(brake_delay=0.1, start_time=0.0))
    rng = np.random.default_rng(7)
    for _ in range(20):
        x = rng.normal(size=10) * np.array([300, 300, 5, 5, 5, 0.1, 100, 100, 100, 2])
        u = np.array([rng.uniform(-5e4, 5e4)])
        fast, ref = m.derivatives(t, x, u), m.derivatives_from_helpers(t, x, u)
        assert np.allclose(fast, ref, rtol=1e-13, atol=1e-13 * np.max(np.abs(ref)))
