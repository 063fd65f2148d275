"""Operator moves with their own start and stop ramps and jerk-limited S-curves (issue 37), in closed form."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.experiments.profiles import ProfileError, moves
from cranefmu.experiments.reader import ExperimentError, load


def test_a_move_with_a_short_start_ramp_and_a_long_stop_ramp():
    # 0 -> 10 at 2 /s from t = 1: 1 s up (a = 2), 3 s down (a = 2/3); the ramps cover 2 (1 + 3) / 2 = 4, cruise 3 s
    p = moves(0.0, [{"start": 1.0, "to": 10.0, "speed": 2.0, "accel_time": 1.0, "decel_time": 3.0}])
    assert p.at(1.5) == pytest.approx((0.25, 1.0, 2.0), abs=1e-14)
    assert p.at(2.0) == pytest.approx((1.0, 2.0, 0.0), abs=1e-14)
    assert p.at(5.0) == pytest.approx((7.0, 2.0, -2 / 3), abs=1e-14)
    assert p.at(6.5) == pytest.approx((9.25, 1.0, -2 / 3), abs=1e-14)
    assert p.at(8.0) == (10.0, 0.0, 0.0) and p.end() == pytest.approx(8.0, abs=1e-14)


def test_an_s_curve_limits_the_jerk():
    # 2 s ramps to 2 /s with 0.5 s of jerk: peak acceleration 2 / (2 - 0.5) = 4/3, jerk 8/3
    p = moves(0.0, [{"start": 0.0, "to": 10.0, "speed": 2.0, "accel_time": 2.0, "jerk_time": 0.5}])
    jerk = (4 / 3) / 0.5
    assert p.at(0.25) == pytest.approx((jerk * 0.25 ** 3 / 6, jerk * 0.25 ** 2 / 2, jerk * 0.25), abs=1e-14)
    assert p.at(1.0)[2] == pytest.approx(4 / 3, abs=1e-14)
    assert p.at(2.0) == pytest.approx((2.0, 2.0, 0.0), abs=1e-14)   # a ramp of T covers v T / 2
    assert p.at(5.0)[:2] == pytest.approx((8.0, 2.0), abs=1e-14)
    assert p.end() == pytest.approx(7.0, abs=1e-14) and p.at(7.0) == (10.0, 0.0, 0.0)
    t = np.linspace(0.0, 7.5, 30001)
    x, v, a = np.array([p.at(s) for s in t]).T
    assert np.max(np.abs(np.diff(a))) < 2 * jerk * (t[1] - t[0])   # the acceleration has no step
    assert np.allclose(np.gradient(x, t), v, atol=1e-6)


def test_a_short_move_lowers_the_speed_keeping_each_ramps_acceleration():
    p = moves(0.0, [{"start": 0.0, "to": 1.0, "speed": 2.0, "accel_time": 2.0, "decel_time": 1.0}])
    a1, a2 = 1.0, 2.0
    peak = math.sqrt(2 * 1.0 / (1 / a1 + 1 / a2))
    assert p.at(peak / a1) == pytest.approx((peak ** 2 / (2 * a1), peak, -a2), abs=1e-14)
    assert p.end() == pytest.approx(peak / a1 + peak / a2, abs=1e-14) and p.at(p.end()) == (1.0, 0.0, 0.0)


def test_bad_ramps_are_refused(tmp_path):
    with pytest.raises(ProfileError, match="jerk_time = 0.8 s is not allowed: at most half of the shorter ramp"):
        moves(0.0, [{"start": 0.0, "to": 1.0, "speed": 1.0, "accel_time": 2.0, "decel_time": 1.0, "jerk_time": 0.8}])
    with pytest.raises(ProfileError, match="decel_time > 0 exactly when accel_time > 0"):
        moves(0.0, [{"start": 0.0, "to": 1.0, "speed": 1.0, "accel_time": 0.0, "decel_time": 1.0}])
    f = tmp_path / "r.toml"
    f.write_text('scene = "elastic_pendulum"\n[[commands]]\ninputs = "rope.payout"\nmoves = [{to = 0.5, speed = '
                 '0.2, accel_time = "0.5 s", decel_time = "1.5 s", jerk_time = "200 ms"}]\n'
                 '[[assert]]\ncolumn = "rope.tension"\nmax = 1e9\n')
    move = load(f)[0].commands[0].moves[0]
    assert (move["accel_time"], move["decel_time"], move["jerk_time"]) == (0.5, 1.5, 0.2)
