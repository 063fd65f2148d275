"""Truck body on four outrigger pads in 3-D (physics/chassis4.py): the rigid-cap statics, the two-outrigger
chassis as its working-plane section, unilateral lift-off (rocking on three pads is not tipping; a second pad
off, of one edge or the diagonal, is), energy without damping, the heave frequency."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cranefmu.physics.chassis import ChassisModel, ChassisParams
from cranefmu.physics.chassis4 import Chassis4Model, Chassis4Params, contact_statics
from cranefmu.physics.params import ParameterError

OUT = {s.name: i for i, s in enumerate(Chassis4Model.outputs)}
IDX = Chassis4Model.input_index()


def inputs(**kw: float) -> np.ndarray:
    u = Chassis4Model.default_inputs()
    for k, v in kw.items():
        u[IDX[k]] = v
    return u


def reactions(model: Chassis4Model, x: np.ndarray, u: np.ndarray) -> np.ndarray:
    y = model.output_list(0.0, x, u)
    return np.array([y[OUT[f"N{i}"]] for i in range(1, 5)])


def test_at_slewing_angle_zero_the_pad_pairs_carry_the_two_outrigger_loads():
    """Loads in the working plane only: front pads together = N_front, rear pads = N_rear of the seed 000
    chassis (same masses, base, soil), and left = right."""
    u4 = inputs(Fx_base=300.0, Fy_base=-3.0e4, Mz_base=-2.2e5)
    two = ChassisModel(ChassisParams(h_foot=0.8)).static_reactions(np.array([300.0, -3.0e4, -2.2e5]))
    four = Chassis4Model(Chassis4Params(h_foot=0.8))
    n = reactions(four, four.initial_state(u4), u4)
    assert n[0] == pytest.approx(n[1], rel=1e-12) and n[2] == pytest.approx(n[3], rel=1e-12)
    assert n[0] + n[1] == pytest.approx(two[0], rel=1e-9)
    assert n[2] + n[3] == pytest.approx(two[1], rel=1e-9)


@pytest.mark.parametrize("mx, mz, fz", [(5.0e4, -1.5e5, 0.0), (-8.0e4, -5.0e4, 2.0e3), (1.2e5, -2.0e5, -1.0e3)])
def test_rigid_cap_formula_is_the_equilibrium_of_the_model(mx, mz, fz):
    """initial_state is at rest (no acceleration), its reactions are the closed form of the module docstring,
    and they satisfy the force and both moment balances."""
    model = Chassis4Model(Chassis4Params(h_foot=1.2))
    u = inputs(Fy_base=-4.0e4, Fz_base=fz, Mx_base=mx, Mz_base=mz)
    x = model.initial_state(u)
    n = reactions(model, x, u)
    assert n.min() > 0.0
    np.testing.assert_allclose(n, model.static_reactions(u), rtol=1e-9)
    assert np.abs(model.derivatives(0.0, x, u)[3:]).max() < 1e-9
    w, m_gamma, m_beta = model.applied_loads(u)
    assert n.sum() == pytest.approx(w, rel=1e-12)
    assert n @ model.xs == pytest.approx(m_gamma, rel=1e-9)
    assert n @ model.zs == pytest.approx(m_beta, rel=1e-9)


def test_a_pad_with_a_pull_in_the_formula_lifts_off_and_three_pads_carry_the_loads():
    """One pad off is the crane resting on three pads, the resultant inside the support polygon: not tipping."""
    model = Chassis4Model(Chassis4Params())
    u = inputs(Fy_base=-3.0e4, Mx_base=2.72e5, Mz_base=-1.0e5)
    assert model.static_reactions(u).min() < 0.0        # the rigid-cap formula pulls on a -z pad
    x = model.initial_state(u)
    y = model.output_list(0.0, x, u)
    n = reactions(model, x, u)
    assert y[OUT["pads_lifted"]] == 1.0 and y[OUT["tipping"]] == 0.0
    off = int(np.argmin(n))
    assert n[off] == 0.0 and model.zs[off] < 0.0 and y[OUT[f"q{off + 1}"]] <= 0.0
    w, m_gamma, m_beta = model.applied_loads(u)
    # statically determinate: the three balances alone give the three reactions
    on = [i for i in range(4) if i != off]
    three = np.linalg.solve(np.array([np.ones(3), model.xs[on], model.zs[on]]), [w, m_gamma, m_beta])
    np.testing.assert_allclose(n[on], three, rtol=1e-9)
    assert np.abs(model.derivatives(0.0, x, u)[3:]).max() < 1e-9


def test_resultant_outside_the_pads_has_no_equilibrium():
    model = Chassis4Model(Chassis4Params())
    w, _, _ = model.applied_loads(inputs(Fy_base=-3.0e4))
    # the resultant 0.2 m beyond the +z edge
    assert contact_statics(model.xs, model.zs, w, 0.0, w * (0.5 * 3.08 + 0.2), model.stiffness) is None
    # the model then starts on the two +z pads, which carry all of it, the -z pads just clear: tipping
    u = inputs(Fy_base=-3.0e4, Mx_base=w * (0.5 * 3.08 + 0.2), Mz_base=model.p.g * model.first_moment)   # x_R = 0
    y = dict(zip(OUT, model.output_list(0.0, model.initial_state(u), u)))
    assert y["pads_lifted"] == 2.0 and y["tipping"] == 1.0
    assert y["N2"] + y["N4"] == pytest.approx(w, rel=1e-12) and y["N1"] == y["N3"] == 0.0
    # the lower of them just clear: 1e-9 of the +z pads' larger settlement, so that round-off cannot press it
    assert -1.01e-9 * max(y["q2"], y["q4"]) < max(y["q1"], y["q3"]) < 0.0


def test_a_second_pad_off_is_tipping_and_a_diagonal_pair_never_lifts_alone():
    """tipping counts the pads carrying nothing: 0 or 1 is not tipping, 2 (an edge) or more is.  On the
    rectangle of pads the settlements lie on a plane, q1 + q4 = q2 + q3 (and so does c q + b q'), so a
    diagonal pair cannot lift while the other two press: the second pad off is always of one edge."""
    model = Chassis4Model(Chassis4Params())
    u = inputs(Fy_base=-3.0e4)
    d = np.column_stack([np.ones(4), model.xs, model.zs])
    # q1, q2, q3 wanted (q4 = q2 + q3 - q1 follows) -> the pads off
    for q123, off in (((2e-3, 3e-3, 1e-3), ()), ((2e-3, 3e-3, -1e-4), (2,)), ((-1e-4, 2e-3, -2e-4), (0, 2)),
                      ((-1e-4, -2e-4, 2e-3), (0, 1)), ((3e-3, 2e-3, -1e-3), (2, 3)),
                      ((-1e-3, -1e-4, -1e-4), (0, 1, 2))):
        neg_y, gamma, beta = np.linalg.solve(d[:3], q123)
        y = dict(zip(OUT, model.output_list(0.0, np.array([-neg_y, gamma, beta, 0.0, 0.0, 0.0]), u)))
        n = [y[f"N{i}"] for i in range(1, 5)]
        assert [i for i in range(4) if n[i] == 0.0] == list(off), (off, n)
        assert y["pads_lifted"] == len(off)
        assert y["tipping"] == (1.0 if len(off) >= 2 else 0.0), off
    rng = np.random.default_rng(1)
    for x in rng.normal(size=(2000, 6)) * [1e-3, 1e-3, 1e-3, 1e-2, 1e-2, 1e-2]:
        y = dict(zip(OUT, model.output_list(0.0, x, u)))
        off = {i for i in range(4) if y[f"N{i + 1}"] == 0.0}
        assert off not in ({0, 3}, {1, 2}), x


def test_rocking_on_three_pads_never_lifts_a_second_pad():
    """Pushed in roll from rest on four pads (a roll rate of 0.01 rad/s, no damping): the chassis rocks, a
    -z pad lifting off and landing again, the other three carrying on, never a second pad off: it rocks on
    three pads and does not tip (the resultant stays inside the pads)."""
    model = Chassis4Model(Chassis4Params(damping=0.0))
    u = inputs(Fy_base=-3.0e4, Mx_base=2.6e5, Mz_base=-1.0e5)
    x0 = model.initial_state(u) + np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1e-2])
    sol = solve_ivp(lambda t, x: model.derivatives(t, x, u), (0.0, 0.5), x0, method="DOP853",
                    rtol=1e-10, atol=1e-14, dense_output=True, max_step=1e-4)
    ys = np.array([model.output_list(t, sol.sol(t), u) for t in np.linspace(0.0, 0.5, 2001)])
    lifted = ys[:, OUT["pads_lifted"]]
    assert lifted.max() == 1.0 and lifted[0] == 0.0
    assert np.count_nonzero(np.diff(lifted) > 0) >= 2      # lifts, lands and lifts again
    assert ys[:, OUT["tipping"]].max() == 0.0


def test_energy_is_conserved_without_damping_through_lift_off():
    """Released from the level unloaded position under a lateral moment that lifts a pad while it rocks."""
    model = Chassis4Model(Chassis4Params(damping=0.0))
    u = inputs(Fy_base=-3.0e4, Mx_base=1.6e5, Mz_base=-1.0e5)
    x0 = np.zeros(6)
    sol = solve_ivp(lambda t, x: model.derivatives(t, x, u), (0.0, 0.3), x0, method="DOP853", rtol=1e-11,
                    atol=1e-14, dense_output=True, max_step=1e-4)
    ts = np.linspace(0.0, 0.3, 301)
    lifted = [model.output_list(t, sol.sol(t), u)[OUT["pads_lifted"]] for t in ts]
    assert max(lifted) >= 1.0 and min(lifted) == 0.0         # the motion crosses lift-off
    e = np.array([model.energy(sol.sol(t), u) for t in ts])
    scale = 0.5 * model.stiffness * 4 * max(np.abs(sol.y[0]).max(), 1e-6) ** 2
    assert np.abs(e - e[0]).max() < 1e-6 * scale


def test_heave_frequency_is_four_pad_springs_on_the_mass():
    """Symmetric in z, no pitch coupling (pads centred under the centre of mass): heave alone at
    omega^2 = 4 c / M (small oscillation, damping off)."""
    p = Chassis4Params(damping=0.0, x_body=1.54, x_platform=1.54, x_slew=1.54)
    model = Chassis4Model(p)
    u = inputs()
    x0 = model.initial_state(u) + np.array([1e-4, 0.0, 0.0, 0.0, 0.0, 0.0])
    omega = math.sqrt(4.0 * model.stiffness / model.mass)
    period = 2.0 * math.pi / omega
    sol = solve_ivp(lambda t, x: model.derivatives(t, x, u), (0.0, period), x0, method="DOP853", rtol=1e-12,
                    atol=1e-15)
    np.testing.assert_allclose(sol.y[:, -1], x0, atol=1e-10)
    half = solve_ivp(lambda t, x: model.derivatives(t, x, u), (0.0, period / 2), x0, method="DOP853", rtol=1e-12,
                     atol=1e-15)
    rest = model.initial_state(u)[0]
    assert half.y[0, -1] - rest == pytest.approx(-(x0[0] - rest), rel=1e-6)


def test_only_left_and_right_pads_at_each_outrigger():
    with pytest.raises(ParameterError, match="chassis.pads_per_outrigger = 3 .*allowed 2"):
        Chassis4Params(pads_per_outrigger=3)
