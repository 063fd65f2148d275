"""The native Drive (native/models/Drive.c) against its Python twin (cranefmu.physics.drive), called
directly through the cffi harness: initial state, derivatives and outputs of both modes over random
parameters, states, line forces and times on every side of the supply start, the ramp's end and the
brake release; the kinematic trapezoid in each of its phases; rk4 steps with and without input rates
against cranefmu.adapter.fmi_adapter.advance; and the cross-field parameter checks with Python's words.

Every comparison is exact (the same bits): the C model does Python's operations in Python's order and
calls libm only where Python does (pow for i_p ** 2), so no tolerance is needed; measured worst relative
difference over these cases: 0."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from cranefmu.adapter.fmi_adapter import advance
from cranefmu.physics.drive import DriveModel, DriveParams
from cranefmu.physics.params import ParameterError

from structural_cases import random_params, refused_as_in_python

pytest.importorskip("cffi")
from cranefmu.native.harness import load  # noqa: E402  (needs cffi)

MODES = ("motor", "kinematic")


def random_drive(rng: np.random.Generator, mode: str) -> DriveParams:
    """Random fields within their ranges; drawn again until the cross-field checks pass."""
    while True:
        v = random_params(DriveParams, rng, mode=mode)
        v["pole_pairs"] = int(rng.integers(1, 7))   # realistic machines (the checks refuse most others)
        if rng.random() < 0.2:
            v["ramp_time"] = 0.0                    # direct on line
        if rng.random() < 0.3:   # hoisting (the docs' sign; the Python law then gives no motion, since
            v["payout_speed"] = -v["payout_speed"]  # trapezoid_motion returns 0 for speed <= 0: mirrored)
        try:
            return DriveParams(**v)
        except ParameterError:
            continue


def cases(seed: int, per_mode: int):
    rng = np.random.default_rng(seed)
    for mode in MODES:
        for _ in range(per_mode):
            yield rng, random_drive(rng, mode)


def times(p: DriveParams, rng: np.random.Generator) -> list[float]:
    """Times on both sides of every switch of the law: start, end of ramp, brake release, the trapezoid's
    corners, and random ones."""
    s = p.start_time
    corners = [s, s + p.ramp_time, s + p.brake_delay, s + p.t_acc, s + p.duration - p.t_acc, s + p.duration]
    out = []
    for c in corners:
        out += [c, math.nextafter(c, -math.inf), math.nextafter(c, math.inf), c + 0.1, c - 0.1]
    return out + list(rng.uniform(s - 1.0, s + p.duration + 2.0, size=6))


def random_state(rng: np.random.Generator) -> np.ndarray:
    scale = np.array([300.0, 300.0, 20.0, 20.0, 20.0, 0.3, 100.0, 100.0, 100.0, 2.0])
    return rng.normal(size=10) * scale


def test_state_names_and_size():
    p = DriveParams()
    nat = load("Drive", p)
    assert nat.m.n_states == 10
    assert [nat.state_name(i) for i in range(10)] == list(DriveModel(p).state_names())


def test_initial_state_derivatives_and_outputs_are_bitwise_python():
    checked = 0
    for rng, p in cases(seed=1, per_mode=40):
        nat, py = load("Drive", p), DriveModel(p)
        assert nat.frozen() == py.frozen
        assert nat.exact_applies() == py.exact_applies()
        for force in (0.0, *rng.normal(size=2) * 2e4):
            u = np.array([force])
            np.testing.assert_array_equal(nat.initial_state(u), py.initial_state(u))
            for t in times(p, rng):
                x = random_state(rng)
                np.testing.assert_array_equal(nat.derivatives(t, x, u), py.derivatives(t, x, u))
                np.testing.assert_array_equal(nat.outputs(t, x, u), np.array(py.output_list(t, x, u)))
                np.testing.assert_array_equal(nat.after_step(t, x, u), py.after_step(t, x, u))
                checked += 1
    assert checked > 2000


def test_derivatives_equal_the_helper_form_of_eq_4_and_5():
    """The C right-hand side against the Python model's form assembled from motor_rhs and
    drivetrain_accelerations (a second reading of eq. 4-5), to 1e-12 relative of the largest term."""
    for rng, p in cases(seed=2, per_mode=10):
        if p.mode != "motor":
            continue
        nat, py = load("Drive", p), DriveModel(p)
        for t in times(p, rng):
            x, u = random_state(rng), rng.normal(size=1) * 2e4
            got, want = nat.derivatives(t, x, u), py.derivatives_from_helpers(t, x, u)
            scale = np.maximum(np.abs(want), 1e-12 * np.max(np.abs(want)))
            assert np.all(np.abs(got - want) <= 1e-12 * scale + 1e-9), (t, got, want)


def test_kinematic_law_in_each_phase():
    """Payout, rate and torque of the trapezoid equal Python's in acceleration, cruise, deceleration and
    after the stop; the payout is continuous at the corners and reaches speed (duration - t_acc)."""
    p = DriveParams(mode="kinematic", start_time=0.5, payout_speed=0.4, t_acc=2.0, duration=10.0)
    nat, py = load("Drive", p), DriveModel(p)
    x, u = np.zeros(10), np.array([1.2e4])
    for t in np.linspace(0.0, 12.0, 241):
        np.testing.assert_array_equal(nat.outputs(t, x, u), np.array(py.output_list(t, x, u)))
    end = nat.outputs(20.0, x, u)
    assert end[0] == pytest.approx(0.4 * (10.0 - 2.0), rel=1e-15) and end[1] == 0.0
    for corner in (2.5, 9.5):
        before, after = nat.outputs(corner - 1e-9, x, u), nat.outputs(corner + 1e-9, x, u)
        assert abs(before[0] - after[0]) < 1e-8


def test_rk4_steps_equal_advance():
    """Stepping the C derivatives with rk4 as integrators.rk4_list does (with the inputs u0 + s r1 + s^2/2
    r2) gives the state fmi_adapter.advance gives with solver rk4, to the bit, over steps that cross the
    supply start and the brake release."""
    for rng, p in cases(seed=3, per_mode=6):
        nat, py = load("Drive", p), DriveModel(p)
        u0 = rng.normal(size=1) * 2e4
        x = py.initial_state(u0)
        t = p.start_time - 0.0015
        for k in range(8):
            h, max_step = 1e-3, 1e-4 * (1 + k % 3)
            r1, r2 = (rng.normal(size=1) * 1e4, rng.normal(size=1) * 1e5) if k % 2 else (None, None)
            want = advance(py, t, x, h, u0, r1, r2, "rk4", 1e-6, max_step)
            got = native_rk4_step(nat, t, x, h, u0, r1, r2, max_step)
            np.testing.assert_array_equal(got, want)
            x, t = want, t + h


def native_rk4_step(nat, t0, x0, h, u0, r1, r2, max_step):
    """One communication step of the C model as fmi_adapter.advance takes it with solver rk4 (the harness's)."""
    return nat.rk4_step(t0, x0, h, u0, r1, r2, max_step)


BAD = [
    dict(duration=5.0, t_acc=3.0),                  # shorter than accelerate + decelerate
    dict(duration=0.3, t_acc=0.2),
    dict(M_k=100.0),                                # below P_n / w_n = 101.05 N.m
    dict(P_n=40e3),                                 # nominal torque above the breakdown torque
    dict(s_k=0.05),                                 # below the nominal slip 0.055
    dict(n_n=999.0, s_k=0.0005),
    dict(n_n=990.0, s_k=0.005),                     # nominal slip 0.01
]


@pytest.mark.parametrize("bad", BAD)
def test_cross_field_checks_say_what_python_says(bad):
    refused_as_in_python("Drive", DriveParams, bad)


def test_accepted_sets_pass_the_c_checks():
    for _, p in cases(seed=4, per_mode=30):
        load("Drive", p)   # raises on a refusal
    edge = dataclasses.replace(DriveParams(), duration=6.0, t_acc=3.0)   # exactly 2 t_acc: allowed
    load("Drive", edge)


SCENE_SETS = {   # the drive fields of the scenes' parameter sets (ssp/*/default.ssv and variants)
    "overhead_lift": dict(R_3=0.25, n_drum_lines=2, start_time=0.2, ramp_time=0.5),
    "truck_telescope": dict(mode="kinematic", n_drum_lines=1, payout_speed=1.212435565298214, duration=20.0,
                            t_acc=3.0),
    "truck_telescope fast": dict(mode="kinematic", n_drum_lines=1, payout_speed=1.905255888325765,
                                 duration=13.818181818181817, t_acc=3.0),
    "truck_telescope slow": dict(mode="kinematic", n_drum_lines=1, payout_speed=0.6928203230275509, duration=32.75,
                                 t_acc=3.0),
    "truck_slewing": dict(mode="kinematic", n_drum_lines=1, payout_speed=0.0),
}


@pytest.mark.parametrize("scene", list(SCENE_SETS))
def test_scene_sets_are_bitwise_python(scene):
    p = DriveParams(**SCENE_SETS[scene])
    nat, py = load("Drive", p), DriveModel(p)
    rng = np.random.default_rng(5)
    u0 = np.array([2453.0])
    np.testing.assert_array_equal(nat.initial_state(u0), py.initial_state(u0))
    for t in times(p, rng):
        x, u = random_state(rng), rng.normal(size=1) * 2e4
        np.testing.assert_array_equal(nat.derivatives(t, x, u), py.derivatives(t, x, u))
        np.testing.assert_array_equal(nat.outputs(t, x, u), np.array(py.output_list(t, x, u)))
