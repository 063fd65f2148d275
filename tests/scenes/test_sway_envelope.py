"""Payload sway envelope of hook_sway against the linear double-pendulum modes (cranefmu.analysis.sway_envelope)."""
import math

import numpy as np
import pytest

from cranefmu.errors import CraneFmuError
from cranefmu.analysis.sway_envelope import (air_drag_decay, double_pendulum_modes, envelope, initial_lengths, payload_sway_envelope,
                                    quadratic_drag_amplitude, simulate_hook_sway)

SMALL = {"pendulum.theta_payload0": 0.01, "pendulum.phi_payload0": 0.005}   # linear range, 3-D release


def test_envelope_of_two_tones_has_its_first_minimum_at_half_the_beat_period():
    w1, w2, a, b = 3.4, 13.4, 0.53, 0.07
    t = np.linspace(0.0, 4.0, 4001)
    env = envelope(t, a * np.cos(w1 * t) + b * np.cos(w2 * t))
    assert env.first_min_time == pytest.approx(math.pi / (w2 - w1), rel=5e-3)
    assert env.min_ratio == pytest.approx((a - b) / (a + b), abs=2e-3)
    assert env.envelope[0] == pytest.approx(a + b, rel=1e-3)


def test_a_shorter_last_step_is_left_out():
    """hook_sway's stored 3 ms does not divide its 10 s: the run ends with a 1 ms step, which the shipped
    sway-envelope experiment refused ('time must be equally spaced') until that row was left out."""
    w1, w2, a, b = 3.4, 13.4, 0.53, 0.07
    t = np.append(np.arange(3334) * 0.003, 10.0)   # the last step 1 ms
    env = envelope(t, a * np.cos(w1 * t) + b * np.cos(w2 * t))
    assert env.first_min_time == pytest.approx(math.pi / (w2 - w1), rel=5e-3)


def test_modes_match_the_closed_form_and_decouple_for_a_heavy_hook():
    m1, m2, l1, l2, g = 3.0, 10.0, 0.4, 0.5, 9.81
    modes = double_pendulum_modes(m1, m2, l1, l2, g)
    mt = m1 + m2
    root = math.sqrt((l1 + l2) ** 2 - 4.0 * m1 * l1 * l2 / mt)     # textbook double pendulum
    assert modes.w1 ** 2 == pytest.approx(g * mt / (2 * m1 * l1 * l2) * (l1 + l2 - root), rel=1e-12)
    assert modes.w2 ** 2 == pytest.approx(g * mt / (2 * m1 * l1 * l2) * (l1 + l2 + root), rel=1e-12)
    # the release is the sum of both modes: theta_2(0) = 1 and the tip angle l2 / (l1 + l2)
    assert modes.a_hook + modes.b_hook == pytest.approx(1.0, rel=1e-12)
    assert modes.a_tip + modes.b_tip == pytest.approx(l2 / (l1 + l2), rel=1e-12)
    heavy = double_pendulum_modes(1e6, m2, l1, l2, g)
    assert sorted((heavy.w1, heavy.w2)) == pytest.approx(sorted((math.sqrt(g / l1), math.sqrt(g / l2))), rel=1e-4)


def test_bad_input_is_refused_with_the_name_and_value():
    with pytest.raises(CraneFmuError, match="m_hook = -1"):
        double_pendulum_modes(-1.0, 10.0, 0.4, 0.5)
    with pytest.raises(CraneFmuError, match="equally spaced"):
        envelope(np.array([0.0, 0.1, 0.3, 0.4, 0.5]), np.ones(5))


@pytest.fixture(scope="module")
def runs():
    return {mh: simulate_hook_sway(mh, 0.4, 4.0, extra=SMALL) for mh in (3.0, 5.0)}


@pytest.mark.parametrize("m_hook", [3.0, 5.0])
def test_simulated_envelope_minimum_is_at_half_the_beat_period(runs, m_hook):
    """The monolithic hook_sway run (elastic rope, 3-D release of 0.01/0.005 rad) against the linear
    modes (measured 2026-11: time within 0.17 %, depth within 0.0012): the swing about the hook and
    the sway seen from the tip."""
    r = runs[m_hook]
    modes = double_pendulum_modes(m_hook, 10.0, *initial_lengths(r))
    for about in ("hook", "tip"):
        env = payload_sway_envelope(r, about)
        assert env.first_min_time == pytest.approx(modes.half_beat, rel=5e-3)
        assert env.min_ratio == pytest.approx(modes.min_ratio(about), abs=5e-3)


def test_heavier_hook_draws_more_of_the_swing_off(runs):
    """Seed 002's trend: a heavier hook takes a larger part of the payload's swing (deeper envelope
    minimum) and at a higher rate; the minimum comes later (the beat slows as the modes approach)."""
    env = {mh: payload_sway_envelope(r, "tip") for mh, r in runs.items()}
    assert env[5.0].min_ratio < env[3.0].min_ratio - 0.04
    assert (1 - env[5.0].min_ratio) / env[5.0].first_min_time > (1 - env[3.0].min_ratio) / env[3.0].first_min_time
    assert env[5.0].first_min_time > env[3.0].first_min_time


def test_quadratic_drag_law_halves_the_amplitude_when_the_drag_term_reaches_the_initial_one():
    x0, omega, k = 0.1, 3.0, 0.05
    t_half = 1.0 / (4.0 / (3.0 * math.pi) * k * omega * x0)
    assert quadratic_drag_amplitude(x0, omega, k, t_half) == pytest.approx(0.5 * x0, rel=1e-12)


def test_air_drag_takes_off_what_the_quadratic_drag_law_predicts():
    """A 1 m2 plate on the 10 kg payload (the hook without drag), 4 s: the sway reduction against the
    undamped run agrees with the payload-only law x0 / (1 + 4/(3 pi) (k/m) w1 x0 t), t the time between
    the two swing peaks compared, within 15 % (measured 2026-11: 2.24 % against 2.41 %; 6 s: 3.63 / 4.01 %)."""
    d = air_drag_decay(drag_area=1.0, drag_area_hook=0.0, stop_time=4.0)
    assert d["ratio_drag"] < d["ratio_no_drag"]
    assert d["reduction"] == pytest.approx(d["reduction_estimate"], rel=0.15)


def test_cosimulation_engine_runs_the_same_scene(built):
    """engine='cosimulation' (Jacobi, linear extrapolation, H = 1 ms) against the monolith: the payload
    path within 1e-5 m over 1 s (measured 2.1e-6 m)."""
    co = simulate_hook_sway(3.0, 0.4, 1.0, engine="cosimulation", step_size=1e-3)
    mono = simulate_hook_sway(3.0, 0.4, 1.0)
    assert np.array_equal(co["time"], mono["time"])
    for k in ("pendulum.x_payload", "pendulum.y_payload", "pendulum.z_payload"):
        assert np.max(np.abs(co[k] - mono[k])) < 1e-5
