"""cranefmu.analysis.scene_questions: each scene's question over its natural length, the ladder's criterion beside range
and modes (issue 34). Checked on motions with a closed form: a rigid double pendulum at rest and a single
swing of known amplitude (hook at rest below the tip, payload on the sling), no simulation."""
import math

import numpy as np
import pytest

from cranefmu.analysis.scene_questions import DECAY_LIMIT, answers, swing_energy, swing_energy_loss, worst
from cranefmu.scenes import G

M_HOOK, M_PAYLOAD, L_SLING, HANG = 3.0, 10.0, 0.5, 0.4
TIP_Y = 9.0


def payload_swing(amplitude, t: np.ndarray) -> dict[str, np.ndarray]:
    """The hook held at its rest point below the tip, the payload swinging in x on the sling with angle
    amplitude(t) * cos(w t) [rad], the small-angle frequency w = sqrt(g / L_sling); velocities exact."""
    w = math.sqrt(G / L_SLING)
    a = np.asarray(amplitude(t), dtype=float)
    theta = a * np.cos(w * t)
    dtheta = np.gradient(theta, t)
    y_hook = np.full_like(t, TIP_Y - HANG)
    zero = np.zeros_like(t)
    return {"time": t, "boom.y_tip": np.full_like(t, TIP_Y), "rope.hang_length": np.full_like(t, HANG),
            "pendulum.y": y_hook, "pendulum.vx": zero, "pendulum.vy": zero, "pendulum.vz": zero,
            "pendulum.y_payload": y_hook - L_SLING * np.cos(theta),
            "pendulum.vx_payload": L_SLING * np.cos(theta) * dtheta, "pendulum.vy_payload": L_SLING * np.sin(theta) * dtheta,
            "pendulum.vz_payload": zero}


def test_swing_energy_is_the_drop_of_the_payload_at_release():
    t = np.linspace(0.0, 10.0, 20001)
    r = payload_swing(lambda t: np.full_like(t, 0.2), t)
    e = swing_energy(r, M_HOOK, M_PAYLOAD, L_SLING)
    assert e[0] == pytest.approx(M_PAYLOAD * G * L_SLING * (1 - math.cos(0.2)), rel=1e-5)   # v(0) by np.gradient
    # the small-angle motion conserves it to O(theta^4): no loss
    assert abs(swing_energy_loss(r, M_HOOK, M_PAYLOAD, L_SLING)) < 5e-3


def test_the_loss_of_a_decaying_swing_is_one_minus_the_amplitude_ratio_squared():
    t = np.linspace(0.0, 30.0, 60001)
    decay = 0.004                                    # [1/s]: the amplitude at 29.5 s is exp(-0.118) of the first
    r = payload_swing(lambda t: 0.1 * np.exp(-decay * t), t)
    expected = 1.0 - math.exp(-2 * decay * 29.5)     # the last 1 s's mean, centred at 29.5 s
    assert swing_energy_loss(r, M_HOOK, M_PAYLOAD, L_SLING) == pytest.approx(expected, rel=0.02)


def test_hook_sway_answer_fails_a_run_that_damps_the_swing_more_than_the_monolith():
    """issue 34: 27 % extra numerical damping of the decay is far over the 5 % limit; 2 % is within it."""
    t = np.linspace(0.0, 30.0, 30001)
    params = {"pendulum.mass": M_HOOK, "pendulum.m_payload": M_PAYLOAD, "pendulum.L_sling": L_SLING}
    ref = payload_swing(lambda t: 0.1 * np.exp(-0.0013 * t), t)
    over = payload_swing(lambda t: 0.1 * np.exp(-1.27 * 0.0013 * t), t)
    near = payload_swing(lambda t: 0.1 * np.exp(-1.02 * 0.0013 * t), t)
    (a,) = answers("hook_sway", over, ref, params)
    assert a.name == "swing energy lost" and a.limit == DECAY_LIMIT
    assert a.err == pytest.approx(0.27, rel=0.05) and not a.meets
    assert answers("hook_sway", near, ref, params)[0].meets


def test_a_truck_run_that_tips_where_the_monolith_does_not_fails_its_question():
    t = np.linspace(0.0, 4.0, 401)
    pad = 2e4 + 1e3 * np.sin(t)
    ref = {"time": t, "pendulum.x": 0 * t, "pendulum.y": 0 * t - 5, "pendulum.z": 0.1 * np.sin(t), "boom.x_tip": 0 * t,
           "boom.y_tip": 0 * t, "boom.z_tip": 0 * t, **{f"chassis.N{i}": pad for i in range(1, 5)}}
    run = dict(ref, **{"chassis.N1": pad - 2.1e4, "chassis.N2": pad - 2.1e4})   # two pads off: tipping
    found = answers("truck_slewing", run, ref)
    assert {a.name for a in found} >= {"max_sway_deg", "N_min", "N_max", "tipping", "pads_lifted_max"}
    assert worst(found).name in ("tipping", "pads_lifted_max", "N_min") and not worst(found).meets
    assert all(a.meets and a.err == 0 for a in answers("truck_slewing", ref, ref))
