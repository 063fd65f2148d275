"""Telescopic boom with luffing cylinder (seed 000): telescoping law, eq. 1, statics, dynamics."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cranefmu.physics.boom import (BoomModel, BoomParams, cylinder_geometry, mass_state, telescope_law,
                                   trapezoid_motion)
from cranefmu.physics.params import ParameterError

G = 9.81
OUT = {s.name: i for i, s in enumerate(BoomModel.outputs)}
IN = BoomModel.input_index()


def inputs(**kw: float) -> np.ndarray:
    u = BoomModel.default_inputs()
    for k, v in kw.items():
        u[IN[k]] = v
    return u


def out(model: BoomModel, t: float, x: np.ndarray, u: np.ndarray, name: str) -> float:
    return float(model.output_values(t, x, u)[OUT[name]])


def integrate(model: BoomModel, u: np.ndarray, t_end: float, x0: np.ndarray | None = None, **kw):
    x0 = model.initial_state(u) if x0 is None else x0
    return solve_ivp(lambda t, x: model.derivatives(t, x, u), (0.0, t_end), x0, method="DOP853",
                     rtol=1e-10, atol=1e-12, dense_output=True, **kw)


def hand_moment(psi: float, length: float, fx: float, fy: float, p: BoomParams) -> float:
    """Moment about O2 of the tip force and the weights of the retracted boom (segments at l/2, eq. 13)."""
    weights = p.m_seg5 * p.l_seg5 / 2 + p.m_seg4 * p.l_seg4 / 2 + p.m_seg3 * p.l_seg3 / 2 + p.m_head * length
    return length * (fy * math.cos(psi) - fx * math.sin(psi)) - G * weights * math.cos(psi)


# --- telescoping law ------------------------------------------------------------------------------
def test_telescoping_law_seed000_timing():
    """10.5 -> 22.4 m with V10 = V20 = 0.35 m/s, T1 = 3 s: T2 = 11.9 / 0.7 = 17 s, T3 = 20 s (seed 000 Fig. 5)."""
    m = BoomModel(BoomParams(tip="kinematic"))
    u = inputs()
    x = m.initial_state(u)
    length = {t: out(m, t, x, u, "boom_length") for t in (0.0, 1.5, 3.0, 10.0, 17.0, 18.5, 20.0, 30.0)}
    assert length[0.0] == pytest.approx(10.5, abs=1e-12)
    assert length[3.0] == pytest.approx(10.5 + 2 * 0.5 * 0.35 * 3.0, abs=1e-12)        # 11.55 m
    assert length[1.5] == pytest.approx(10.5 + 2 * 0.5 * (0.35 / 3.0) * 1.5 ** 2, abs=1e-12)
    assert length[10.0] == pytest.approx(10.5 + 2 * 0.35 * (10.0 - 1.5), abs=1e-12)
    assert length[17.0] == pytest.approx(22.4 - 2 * 0.5 * 0.35 * 3.0, abs=1e-12)       # 21.35 m
    assert length[20.0] == pytest.approx(22.4, abs=1e-12)
    assert length[30.0] == pytest.approx(22.4, abs=1e-12)
    s, sd, sdd = telescope_law(10.0, m.p)
    np.testing.assert_allclose(sd, [0.35, 0.35], atol=1e-15)          # V10 = V20 in the steady phase
    np.testing.assert_allclose(telescope_law(20.0, m.p)[0], [5.95, 5.95], atol=1e-12)
    np.testing.assert_allclose(telescope_law(1.0, m.p)[2], [0.35 / 3, 0.35 / 3], atol=1e-15)
    # the tip moves along the boom at 60 deg with 2 x 0.35 m/s
    assert out(m, 10.0, x, u, "vx_tip") == pytest.approx(0.7 * math.cos(math.radians(60)), abs=1e-12)
    assert out(m, 10.0, x, u, "vy_tip") == pytest.approx(0.7 * math.sin(math.radians(60)), abs=1e-12)


def test_trapezoid_is_consistent_and_speed_ratio():
    """Velocity integrates to the position, acceleration to the velocity; unequal segment speeds."""
    t = np.linspace(-1.0, 25.0, 26001)
    pos, vel, acc = np.array([trapezoid_motion(ti, 2.0, -4.0, 0.5, 1.5) for ti in t]).T
    assert pos[-1] == pytest.approx(-4.0, abs=1e-12) and vel.min() == pytest.approx(-0.5)
    np.testing.assert_allclose(np.diff(pos), 0.5 * (vel[1:] + vel[:-1]) * np.diff(t), atol=1e-9)
    np.testing.assert_allclose(np.diff(vel), 0.5 * (acc[1:] + acc[:-1]) * np.diff(t), atol=3e-4)
    p = BoomParams(telescope_speed_ratio=0.5)
    s_end = telescope_law(100.0, p)[0]
    assert s_end.sum() == pytest.approx(11.9, abs=1e-12) and s_end[1] / s_end[0] == pytest.approx(0.5)


def test_tip_velocity_is_derivative_of_tip_position():
    m = BoomModel(BoomParams(luff_delta=0.3, luff_rate=0.04, luff_t_acc=2.0, luff_start=1.0))
    u = inputs(gamma=2e-3, gamma_rate=1e-3, y_base=-2e-3, vy_base=-1e-3)
    x = m.initial_state(u)
    h = 1e-5
    for t in (2.0, 5.0, 9.0, 18.0):
        up, um = u.copy(), u.copy()
        for name, rate in (("gamma", "gamma_rate"), ("y_base", "vy_base")):
            up[IN[name]] += h * u[IN[rate]]
            um[IN[name]] -= h * u[IN[rate]]
        for q in ("x", "y"):
            fd = (out(m, t + h, x, up, f"{q}_tip") - out(m, t - h, x, um, f"{q}_tip")) / (2 * h)
            assert out(m, t, x, u, f"v{q}_tip") == pytest.approx(fd, abs=1e-7)


# --- statics ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("cylinder", ["prescribed", "spring_damper"])
def test_base_reactions_balance_tip_load_and_weight(cylinder):
    """At rest the chassis receives the tip force plus the boom weight, and their moment about O2."""
    p = BoomParams(cylinder=cylinder)
    m = BoomModel(p)
    fx, fy, gamma = 1.2e3, -3500.0 * G, 2.5e-4
    u = inputs(Fx_tip=fx, Fy_tip=fy, gamma=gamma, y_base=-2e-3)
    x = m.initial_state(u)
    y = m.output_values(0.0, x, u)
    mass = p.m_head + p.m_seg3 + p.m_seg4 + p.m_seg5
    psi = p.luff_angle - gamma
    assert y[OUT["Fx_base"]] == pytest.approx(fx, rel=1e-12, abs=1e-6)
    assert y[OUT["Fy_base"]] == pytest.approx(fy - mass * G, rel=1e-12)
    assert y[OUT["M_base"]] == pytest.approx(hand_moment(psi, 10.5, fx, fy, p), rel=1e-12)
    # the cylinder alone carries the moment about the pivot: F_cyl * lever = -M_base
    _, lever, _ = cylinder_geometry(p.luff_angle, p)
    assert y[OUT["cylinder_force"]] * lever == pytest.approx(-y[OUT["M_base"]], rel=1e-12)
    assert y[OUT["luff_angle_out"]] == pytest.approx(p.luff_angle, abs=1e-15)
    assert y[OUT["x_tip"]] == pytest.approx(10.5 * math.cos(psi), rel=1e-14)
    assert y[OUT["y_tip"]] == pytest.approx(-2e-3 + 10.5 * math.sin(psi), rel=1e-14)


def test_spring_damper_initial_state_is_static_equilibrium():
    """Derivatives vanish at initial_state(u) and the boom stays at rest (telescoping later)."""
    p = BoomParams(cylinder="spring_damper", telescope_start=10.0)
    m = BoomModel(p)
    u = inputs(Fx_tip=-800.0, Fy_tip=-3500.0 * G, gamma=3e-4)
    x0 = m.initial_state(u)
    d = m.derivatives(0.0, x0, u)
    assert abs(d[1]) < 1e-10 and d[0] == 0.0 and d[2] == 0.0
    # the oil column is compressed by F_cyl / k (about 7 mm under 3.5 t)
    force = out(m, 0.0, x0, u, "cylinder_force")
    assert x0[2] == pytest.approx(force / p.cylinder_stiffness, rel=1e-12)
    assert 0.005 < x0[2] < 0.01
    sol = integrate(m, u, 2.0)
    assert np.max(np.abs(sol.y[0] - x0[0])) < 1e-10
    assert np.max(np.abs(sol.y[1])) < 1e-9


# --- dynamics of the elastic cylinder ---------------------------------------------------------------------
def test_constraint_residual_eq1_during_luffing_manoeuvre():
    """Spring-damper cylinder, luffing 60 -> 40 deg while telescoping: |eq. 1| < 1e-8 m throughout."""
    p = BoomParams(cylinder="spring_damper", luff_delta=math.radians(-20.0), luff_rate=0.05, luff_t_acc=1.0,
                   luff_start=0.5, telescope_start=0.0, boom_length_end=14.0)
    m = BoomModel(p)
    u = inputs(Fy_tip=-2500.0 * G, Fx_tip=300.0, gamma=2e-4)
    sol = integrate(m, u, 20.0)
    la, lb, al = p.cyl_boom_arm, p.cyl_base_distance, p.cyl_base_angle
    worst = 0.0
    for t in np.linspace(0.0, 20.0, 801):
        y = m.output_values(t, sol.sol(t), u)
        phi1, s3 = y[OUT["luff_angle_out"]], y[OUT["cylinder_length"]]
        worst = max(worst, y[OUT["constraint_residual"]])
        # independent check: eq. 1 with phi2 eliminated (law of cosines in the loop O2-D-O1)
        assert s3 ** 2 == pytest.approx(la ** 2 + lb ** 2 - 2 * la * lb * math.cos(phi1 - al), abs=1e-8)
    assert worst < 1e-8
    # the boom has luffed down by 20 deg and settled; it lags the command by the extra compression of
    # the oil column under the larger load moment at 40 deg and 14 m (statics, hand calculation)
    x_end = sol.sol(20.0)
    y_end = m.output_values(20.0, x_end, u)
    phi1, psi = y_end[OUT["luff_angle_out"]], x_end[0]
    assert abs(x_end[1]) < 1e-5
    ms = mass_state(20.0, p)
    moment = 14.0 * (-2500.0 * G * math.cos(psi) - 300.0 * math.sin(psi)) - G * ms.S * math.cos(psi)
    _, lever, _ = cylinder_geometry(phi1, p)
    s3_cmd, _, _ = cylinder_geometry(math.radians(40.0), p)
    compression = -moment / lever / p.cylinder_stiffness
    assert y_end[OUT["cylinder_length"]] == pytest.approx(s3_cmd + x_end[2] - compression, abs=1e-7)
    assert math.radians(39.5) < phi1 < math.radians(40.0)


def test_luffing_natural_frequency():
    """Without gravity and load: omega^2 = k (ds3/dphi1)^2 / J_O (derived)."""
    p = BoomParams(cylinder="spring_damper", cylinder_damping=0.0, g=0.0, boom_length_end=10.5)
    m = BoomModel(p)
    u = inputs()
    ms = mass_state(0.0, p)
    _, lever, _ = cylinder_geometry(p.luff_angle, p)
    omega = math.sqrt(p.cylinder_stiffness * lever ** 2 / ms.J)
    period = 2 * math.pi / omega
    x0 = m.initial_state(u)
    psi_eq, delta = x0[0], 1e-7
    x0[0] += delta
    sol = integrate(m, u, period, x0)
    assert abs(sol.sol(period / 4)[0] - psi_eq) < 1e-4 * delta
    assert sol.sol(period / 2)[0] - psi_eq == pytest.approx(-delta, rel=1e-5)
    assert sol.sol(period)[0] - psi_eq == pytest.approx(delta, rel=1e-5)
    assert 10.0 < omega < 50.0      # 2-8 Hz luffing mode of the retracted boom


def test_energy_conserved_without_damping():
    """Gravity, constant tip force and oil column are conservative: energy constant with damping off."""
    p = BoomParams(cylinder="spring_damper", cylinder_damping=0.0, boom_length_end=10.5)
    m = BoomModel(p)
    u = inputs(Fx_tip=500.0, Fy_tip=-3500.0 * G, gamma=1e-4)
    x0 = m.initial_state(u)
    x0[0] += 2e-3
    x0[1] = 0.05
    sol = integrate(m, u, 3.0, x0)
    e = np.array([m.energy(t, x, u) for t, x in zip(sol.t, sol.y.T)])
    swing = 0.5 * m.p.cylinder_stiffness * (1e-3) ** 2        # order of the vibration energy
    assert np.max(np.abs(e - e[0])) < 1e-6 * swing


def test_reactions_follow_momentum_balance_during_manoeuvre():
    """F_base = F_tip + m g - dP/dt with P from finite differences of the simulated centre of mass;
    M_base = -F_cyl ds3/dphi1 (Newton-Euler and the cylinder agree)."""
    p = BoomParams(cylinder="spring_damper", luff_delta=math.radians(10.0), luff_rate=0.05, luff_t_acc=1.0,
                   luff_start=1.0, t_acc=1.0, boom_length_end=16.0)
    m = BoomModel(p)
    fx, fy = 200.0, -2000.0 * G
    u = inputs(Fx_tip=fx, Fy_tip=fy)
    sol = integrate(m, u, 6.0)

    def com(t: float) -> np.ndarray:
        ms = mass_state(t, p)
        psi = sol.sol(t)[0]
        return ms.S / ms.mass * np.array([math.cos(psi), math.sin(psi)])

    h = 1e-3
    mass = mass_state(0.0, p).mass
    for t in (0.5, 1.5, 2.5, 4.2, 5.5):   # away from the jumps of the trapezoid accelerations
        acc = (com(t + h) - 2 * com(t) + com(t - h)) / h ** 2
        y = m.output_values(t, sol.sol(t), u)
        expect = np.array([fx, fy - mass * G]) - mass * acc
        np.testing.assert_allclose([y[OUT["Fx_base"]], y[OUT["Fy_base"]]], expect, atol=0.5)
        _, lever, _ = cylinder_geometry(y[OUT["luff_angle_out"]], p)
        assert y[OUT["M_base"]] == pytest.approx(-y[OUT["cylinder_force"]] * lever, rel=1e-9)


# --- modes and parameters -----------------------------------------------------------------------------
def test_kinematic_tip_ignores_base_and_prescribed_follows_chassis():
    u = inputs(y_base=-0.01, gamma=0.01, vy_base=0.1, gamma_rate=0.02)
    kin = BoomModel(BoomParams(tip="kinematic", x_foot=1.0, y_foot=2.5))
    x = kin.initial_state(u)
    assert out(kin, 0.0, x, u, "x_tip") == pytest.approx(1.0 + 10.5 * math.cos(math.radians(60)), rel=1e-14)
    assert out(kin, 0.0, x, u, "y_tip") == pytest.approx(2.5 + 10.5 * math.sin(math.radians(60)), rel=1e-14)
    assert out(kin, 0.0, x, u, "vy_tip") == 0.0
    rig = BoomModel(BoomParams())
    psi = math.radians(60) - 0.01
    assert out(rig, 0.0, x, u, "x_tip") == pytest.approx(10.5 * math.cos(psi), rel=1e-14)
    assert out(rig, 0.0, x, u, "vy_tip") == pytest.approx(0.1 - 10.5 * 0.02 * math.cos(psi), rel=1e-14)
    assert np.all(rig.derivatives(0.0, x, u) == 0.0)


def test_bad_parameters_are_refused():
    with pytest.raises(ParameterError, match=r"boom\.t_acc = 18\.0"):
        BoomParams(t_acc=18.0)                      # T2 = 11.9 m / 0.7 m/s = 17 s < t_acc
    with pytest.raises(ParameterError, match=r"boom\.cylinder = 'hydraulic'"):
        BoomParams(cylinder="hydraulic")
    with pytest.raises(ParameterError, match=r"boom\.telescope_speed = -0\.35"):
        BoomParams(telescope_speed=-0.35)
    with pytest.raises(ParameterError, match=r"boom\.cyl_base_angle"):
        BoomParams(cyl_base_angle=math.radians(100.0))


def test_crane_motions_carry_a_kinematic_tip_in_3d():
    """Seed 002's floor-crane motions (travel, steering about the vertical axis through the origin, the
    auxiliary boom on the main boom): the tip is (x_c + r cos psi, y, r sin psi) and its velocity the time
    derivative of that (central differences), with travel 1 m, steering 90 deg and the auxiliary boom turned."""
    p = BoomParams(tip="kinematic", boom_length_end=10.5, luff_angle=0.5, luff_delta=-0.3,
                   luff_rate=0.1, travel_distance=1.0, travel_speed=0.3, steer_delta=math.pi / 2, steer_rate=0.3,
                   aux_length=1.2, aux_angle=-0.8, aux_delta=0.4, aux_rate=0.2, aux_start=0.5)
    m = BoomModel(p)
    u, x = m.default_inputs(), np.zeros(3)

    def tip(t):
        y = m.output_values(t, x, u)
        return y[0:3], y[3:6]

    for t in (0.7, 2.2, 4.1, 6.3):
        h = 1e-6
        vel = (tip(t + h)[0] - tip(t - h)[0]) / (2 * h)
        assert np.allclose(tip(t)[1], vel, rtol=0, atol=1e-7)
    end, v_end = tip(30.0)
    beta, beta_a = 0.5 - 0.3, 0.5 - 0.3 - 0.8 + 0.4
    r = 10.5 * math.cos(beta) + 1.2 * math.cos(beta_a)
    assert end == pytest.approx([1.0, 10.5 * math.sin(beta) + 1.2 * math.sin(beta_a), r], abs=1e-12)
    assert np.all(v_end == 0.0)
    with pytest.raises(ParameterError, match="kinematic tip"):
        BoomParams(travel_distance=1.0)
