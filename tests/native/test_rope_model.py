"""The native Rope (native/models/Rope.c, models/cf_boucwen.c) against its Python twin
(cranefmu.physics.rope and .boucwen), called directly through the cffi harness: initial state (the
Bouc-Wen virgin curve, start = 'taut'), derivatives, outputs and after_step over random parameters of
every model and start switch, random geometries, velocities, payouts, runs and hysteresis states; the
event cases (slack and re-tension, a Bouc-Wen reversal from saturation, unloading on the zero-force
line, Kelvin-Voigt unloading faster than the rope relaxes); rk4 steps against fmi_adapter.advance; and
the parameter refusals in Python's words.

Every comparison is exact (the same bits): the C code does Python's operations in Python's order and
calls libm's exp, log, pow and sqrt exactly where Python's math module and float ** do (CPython calls the
same libm functions), so no tolerance is needed; measured worst relative difference over these cases: 0.
The Bouc-Wen exponent n is drawn in [1, 2] (its range is [1, 20]): at large n the virgin curve's
sub-step count (boucwen._substeps, ~ n alpha / z_u) makes the Python reference take minutes, not the C;
one case at n = 20 runs on a short elongation."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.adapter.fmi_adapter import advance
from cranefmu.physics import boucwen
from cranefmu.physics.params import ParameterError
from cranefmu.physics.rope import RopeModel, RopeParams, elastic_length

from conformance import _LIFT_ROPE, _TELESCOPE_ROPE
from structural_cases import random_params, refused_as_in_python

pytest.importorskip("cffi")
from cranefmu.native.harness import load  # noqa: E402  (needs cffi)

SWITCHES = [(model, start) for model in ("kelvin_voigt", "bouc_wen") for start in ("length", "taut")]
G = 9.81


def random_rope(rng: np.random.Generator, model: str, start: str) -> RopeParams:
    """Random fields within their ranges, repaired for the cross-field checks."""
    v = random_params(RopeParams, rng, model=model, start=start)
    v["n_lines"] = int(rng.integers(1, 9))
    v["n"] = float(rng.uniform(1.0, 2.0))
    v["gamma"] = min(v["gamma"], v["beta"]) if rng.random() < 0.8 else -0.5 * v["beta"]
    v["run_length"] = float(rng.choice([0.0, 20.0 * v["run_length"]]))
    if start == "taut":
        v["length"] = 10.0
    else:
        v["start_slack"] = 0.0
    return RopeParams(**v)


def cases(seed: int, per_switch: int):
    rng = np.random.default_rng(seed)
    for switches in SWITCHES:
        for _ in range(per_switch):
            yield rng, random_rope(rng, *switches)


def inputs(rng: np.random.Generator, p: RopeParams, l_u: float, delta: float, payout: float = 0.0,
           speed: float = 0.3, mass: float = 1000.0) -> np.ndarray:
    """Inputs with the hook ``delta`` [m] beyond the unstretched length ``l_u`` along a random direction
    (mostly downward), random velocities of size ``speed`` [m/s]."""
    top = rng.normal(size=3) * 5.0
    d = rng.normal(size=3) * 0.3 + [0.0, -1.0, 0.0]
    d /= np.linalg.norm(d)
    hook = top + d * (l_u + delta)
    v_top, v_hook = rng.normal(size=3) * speed, rng.normal(size=3) * speed
    run_ext = float(rng.choice([0.0, rng.uniform(0.0, 5.0)]))
    return np.array([*top, *v_top, *hook, *v_hook, payout, rng.normal() * speed, mass, mass * G, run_ext])


def random_state_inputs(rng, p: RopeParams, py: RopeModel, x0: np.ndarray, load: float):
    """A state near x0 (z anywhere in its band, length0 as taken up) and inputs with the rope slack, at
    zero elongation, or taut by up to a few strains; the static ``load`` [N] kept (constant in a run: the
    Python model caches its strain, whose Bouc-Wen bisection costs ~0.1 s)."""
    length0 = float(x0[-1]) if p.start == "taut" else p.length
    payout = float(rng.choice([0.0, rng.uniform(-0.5, 0.5) * length0]))
    l_u = length0 + payout / p.n_lines
    strain = rng.uniform(0.0, 4e-3) * float(rng.choice([1.0, 1.0, -1.0, 0.0]))
    u = inputs(rng, p, l_u, strain * l_u, payout, speed=float(rng.choice([0.0, 0.3, 3.0])),
               mass=float(rng.uniform(0.0, 5e3)))
    u[15] = load
    x = np.array(x0, dtype=float)
    if p.model == "bouc_wen":
        l_e = elastic_length(p, l_u, float(u[16]))
        zu = boucwen.z_bound(py.bouc_wen_at(l_e))
        x[0] = float(rng.choice([rng.uniform(-1.0, 1.0) * zu, 0.0, zu, -zu]))
    return x, u


def test_state_layout_follows_the_switches():
    for model, start in SWITCHES:
        p = RopeParams(model=model, start=start)
        nat, py = load("Rope", p), RopeModel(p)
        assert nat.m.n_states == len(py.state_names())
        assert [nat.state_name(i) for i in range(nat.m.n_states)] == list(py.state_names())
        assert nat.frozen() == py.frozen
        assert nat.exact_applies() == py.exact_applies()


def test_initial_state_derivatives_outputs_and_projection_are_bitwise_python():
    checked = 0
    for rng, p in cases(seed=11, per_switch=10):
        nat, py = load("Rope", p), RopeModel(p)
        for k in range(2):
            l_u0 = p.length + (p.start_slack if p.start == "taut" else 0.0)
            u0 = inputs(rng, p, l_u0, float(rng.uniform(0.0, 3e-3)) * l_u0 * (k > 0),
                        mass=float(rng.uniform(100.0, 5e3)))
            x0 = py.initial_state(u0)
            np.testing.assert_array_equal(nat.initial_state(u0), x0)
            for _ in range(40):
                x, u = random_state_inputs(rng, p, py, x0, float(u0[15]))
                t = float(rng.uniform(0.0, 10.0))
                np.testing.assert_array_equal(nat.derivatives(t, x, u), py.derivatives(t, x, u))
                np.testing.assert_array_equal(nat.outputs(t, x, u), np.array(py.output_list(t, x, u)))
                np.testing.assert_array_equal(nat.after_step(t, x, u), py.after_step(t, x, u))
                checked += 1
    assert checked >= 3200


def test_taut_start_takes_up_the_chord_and_falls_back_to_length():
    """start = 'taut': the taken-up length carries the load between the end points (Python's formula to the
    bit); with the end points at their start values (chord 0) or a slack longer than the chord allows, the
    length parameter."""
    rng = np.random.default_rng(12)
    for model in ("kelvin_voigt", "bouc_wen"):
        for slack in (0.0, 0.05):
            p = RopeParams(model=model, start="taut", start_slack=slack, n_lines=2, run_length=9.0)
            nat, py = load("Rope", p), RopeModel(p)
            for chord in (0.0, 3.0, 27.5):
                u = inputs(rng, p, chord, 0.0, payout=float(rng.uniform(-1.0, 1.0)), mass=1500.0)
                if chord == 0.0:
                    u[6:9] = u[0:3]
                x = nat.initial_state(u)
                np.testing.assert_array_equal(x, py.initial_state(u))
                assert x[-1] == (10.0 if chord == 0.0 else x[-1])
                if chord > 0.0 and slack == 0.0 and model == "kelvin_voigt":   # at rest it carries the load
                    rest = u.copy()
                    rest[[3, 4, 5, 9, 10, 11, 13]] = 0.0
                    assert nat.outputs(0.0, x, rest)[0] == pytest.approx(u[15], rel=1e-9)


def trajectory_case(model: str, seed: int):
    rng = np.random.default_rng(seed)
    p = RopeParams(model=model, n_lines=2, run_length=9.0)
    return rng, p, load("Rope", p), RopeModel(p)


def rope_inputs(y_hook: float, vy_hook: float, payout: float = 0.0, rate: float = 0.0) -> np.ndarray:
    """Top at the origin, hook straight below at height y_hook [m]."""
    return np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, y_hook, 0.0, 0.0, vy_hook, 0.0, payout, rate,
                     1000.0, 1000.0 * G, 0.0])


def native_rk4_step(nat, t0, x0, h, u0, r1, r2, max_step):
    """One communication step of the C model as fmi_adapter.advance takes it with solver rk4 (the harness's)."""
    return nat.rk4_step(t0, x0, h, u0, r1, r2, max_step)


def run_both(nat, py, x, path, h=2e-3, max_step=5e-4):
    """Step both models along ``path`` (a list of (u0, r1, r2)); assert the same bits at every step and
    return the states and the outputs."""
    states, outs, t = [], [], 0.0
    for u0, r1, r2 in path:
        want = advance(py, t, x, h, u0, r1, r2, "rk4", 1e-6, max_step)
        got = native_rk4_step(nat, t, x, h, u0, r1, r2, max_step)
        np.testing.assert_array_equal(got, want)
        x, t = want, t + h
        u_end = u0 + h * (r1 + 0.5 * h * r2) if r1 is not None else u0
        y = nat.outputs(t, x, u_end)
        np.testing.assert_array_equal(y, np.array(py.output_list(t, x, u_end)))
        states.append(x)
        outs.append(y)
    return np.array(states), np.array(outs)


def oscillation_path(amplitude: float, l_u: float, n: int, h: float = 2e-3, period: float = 0.2):
    """The hook oscillating about l_u below the top with elongation amplitude [m], as inputs with their
    rates (r1 the velocity, r2 the acceleration), one entry per step."""
    w = 2.0 * math.pi / period
    zero = np.zeros(17)
    path = []
    for k in range(n):
        t = k * h
        y = -(l_u + amplitude * math.sin(w * t))
        v = -amplitude * w * math.cos(w * t)
        a = amplitude * w * w * math.sin(w * t)
        u0 = rope_inputs(y, v)
        r1, r2 = zero.copy(), zero.copy()
        r1[7], r1[10], r2[7], r2[10] = v, a, a, -amplitude * w ** 3 * math.cos(w * t)
        path.append((u0, r1, r2))
    return path


@pytest.mark.parametrize("model", ["kelvin_voigt", "bouc_wen"])
def test_slack_and_retension(model):
    """The hook oscillates through the unstretched length: the rope goes slack (tension 0, slack 1, z reset
    to 0 by the projection) and tightens again, every step bitwise Python's."""
    rng, p, nat, py = trajectory_case(model, 13)
    u0 = rope_inputs(-(p.length + 1e-3), 0.0)
    x = py.initial_state(u0)
    states, outs = run_both(nat, py, x, oscillation_path(2e-3, p.length, 150))
    slack = outs[:, 10] == 1.0
    assert slack.any() and (~slack).any()
    assert np.any(np.diff(slack.astype(int)) == -1)           # re-tension after slack
    assert np.all(outs[slack, 0] == 0.0)
    if model == "bouc_wen":
        assert np.all(states[outs[:, 9] <= 0.0, 0] == 0.0)    # z = 0 whenever geometrically slack


def test_bouc_wen_reversal_from_saturation():
    """Loading far past z_u saturates z; the reversal sends z down at the steep rate alpha (1 + (beta -
    gamma)/(beta + gamma)) and the loop dissipates: same bits as Python at every step."""
    rng, p, nat, py = trajectory_case("bouc_wen", 14)
    u0 = rope_inputs(-(p.length + 4e-3), 0.0)
    x = py.initial_state(u0)
    states, outs = run_both(nat, py, x, oscillation_path(3e-3, p.length + 4e-3, 100))
    z = states[:, 0]
    dz = np.diff(z)
    assert np.any(dz > 0) and np.any(dz < 0)                  # reversals
    l_e = elastic_length(p, p.length, 0.0)
    zu = boucwen.z_bound(py.bouc_wen_at(l_e))
    assert np.max(np.abs(z)) <= zu * (1 + 1e-12)


def test_unloading_on_the_zero_force_line():
    """Start on the zero-force line z = -F_1(delta) with the rope shortening: z follows the line
    (z' = -F_1' delta'), the tension stays 0, and reloading leaves the line; same bits as Python."""
    rng, p, nat, py = trajectory_case("bouc_wen", 15)
    delta = 3e-4
    u0 = rope_inputs(-(p.length + delta), 0.02)   # hook rising: delta' = -0.02 m/s
    bw = py.bouc_wen_at(elastic_length(p, p.length, 0.0))
    x = np.array([-boucwen.elastic_force(delta, bw)])
    dz = nat.derivatives(0.0, x, u0)
    np.testing.assert_array_equal(dz, py.derivatives(0.0, x, u0))
    assert dz[0] == pytest.approx(boucwen.elastic_slope(delta, bw) * 0.02, rel=1e-12)
    zero = np.zeros(17)
    h, y0 = 2e-3, -(p.length + delta)

    def moving(y, v):   # hook at y moving at v over the step (the position's rate is its velocity)
        r1 = zero.copy()
        r1[7] = v
        return rope_inputs(y, v), r1, zero

    unload = [moving(y0 + 0.02 * k * h, 0.02) for k in range(5)]
    reload = [moving(y0 + 0.02 * 5 * h - 0.05 * k * h, -0.05) for k in range(5)]
    states, outs = run_both(nat, py, x, unload + reload)
    assert np.all(outs[:5, 0] < 1e-6 * np.max(outs[:, 0])) and np.all(outs[5:, 0] > 1.0)


def test_kelvin_voigt_tension_never_pushes():
    """Taut but contracting faster than the rope relaxes: c delta + b delta' < 0 gives 0, not a push."""
    p = RopeParams(zeta=2.0)
    nat, py = load("Rope", p), RopeModel(p)
    u = rope_inputs(-(p.length + 1e-4), 5.0)
    y = nat.outputs(0.0, np.zeros(0), u)
    np.testing.assert_array_equal(y, np.array(py.output_list(0.0, np.zeros(0), u)))
    assert y[0] == 0.0 and y[10] == 1.0 and y[9] > 0.0


def test_rk4_steps_with_random_rates_equal_advance():
    for rng, p in cases(seed=16, per_switch=4):
        nat, py = load("Rope", p), RopeModel(p)
        u0 = inputs(rng, p, p.length + p.start_slack, 1e-3 * p.length, mass=2000.0)
        x = py.initial_state(u0)
        for k in range(4):
            r1, r2 = rng.normal(size=17) * 0.05, rng.normal(size=17) * 0.5
            r1[14:] = r2[14:] = 0.0
            rates = (r1, r2) if k % 2 else (None, None)
            want = advance(py, 0.0, x, 5e-3, u0, *rates, "rk4", 1e-6, 1e-3)
            np.testing.assert_array_equal(native_rk4_step(nat, 0.0, x, 5e-3, u0, *rates, 1e-3), want)


def test_bouc_wen_at_large_exponent():
    p = RopeParams(model="bouc_wen", n=20.0)
    nat, py = load("Rope", p), RopeModel(p)
    rng = np.random.default_rng(17)
    u = inputs(rng, p, p.length, 2e-6, mass=10.0)
    x = py.initial_state(u)
    np.testing.assert_array_equal(nat.initial_state(u), x)
    for z in (0.0, 0.5, 3.0, -3.0, 1e3):
        xz = np.array([z])
        np.testing.assert_array_equal(nat.derivatives(0.0, xz, u), py.derivatives(0.0, xz, u))   # exp cap
        np.testing.assert_array_equal(nat.after_step(0.0, xz, u), py.after_step(0.0, xz, u))


def test_initialization_errors_say_what_python_says():
    # a payout that leaves no rope
    p = RopeParams(model="bouc_wen")
    u = rope_inputs(-10.0, 0.0, payout=-11.0)
    with pytest.raises(FloatingPointError) as err:
        RopeModel(p).initial_state(u)
    with pytest.raises(ValueError) as native:
        load("Rope", p).initial_state(u)
    assert str(native.value) == str(err.value)
    # a start load the Bouc-Wen curve never reaches (F_2 = b^(c x) decays with c < 0)
    p = RopeParams(model="bouc_wen", start="taut", c=-4000.0, k2=0.0, k3=0.0, n=1.0, beta=1e-6, gamma=0.0)
    u = rope_inputs(-10.0, 0.0)
    u[15] = 1e9
    with pytest.raises(ParameterError) as err:
        RopeModel(p).initial_state(u)
    with pytest.raises(ValueError) as native:
        load("Rope", p).initial_state(u)
    assert str(native.value) == str(err.value)


def test_errors_inside_a_step_give_nan():
    """Python raises inside derivatives/outputs when the payout leaves no rope; the C contract has no error
    return there: NaN, which the FMI layer reports as a non-finite state or output."""
    p = RopeParams(model="bouc_wen")
    nat = load("Rope", p)
    u = rope_inputs(-10.0, 0.0, payout=-11.0)
    with pytest.raises(FloatingPointError):
        RopeModel(p).derivatives(0.0, np.array([0.0]), u)
    assert np.isnan(nat.derivatives(0.0, np.array([0.0]), u)[0])
    assert np.all(np.isnan(nat.outputs(0.0, np.array([0.0]), u)))


BAD = [
    dict(start="taut", length=12.0),
    dict(start="length", start_slack=0.1),
    dict(model="bouc_wen", gamma=-75.0),                      # beta + gamma = 0
    dict(model="bouc_wen", gamma=-100.0),
    dict(model="bouc_wen", gamma=80.0),                       # gamma > beta
    dict(model="bouc_wen", alpha=1e300, beta=1e-300, gamma=0.0),   # z_u = inf
    dict(model="bouc_wen", alpha=5e-324, beta=1e300, gamma=0.0, n=1.0),   # z_u = 0
]


@pytest.mark.parametrize("bad", BAD)
def test_cross_field_checks_say_what_python_says(bad):
    refused_as_in_python("Rope", RopeParams, bad)


def test_kelvin_voigt_ignores_the_bouc_wen_set():
    p = RopeParams()
    object.__setattr__(p, "gamma", 80.0)   # inadmissible, but not used by kelvin_voigt
    load("Rope", p)


SCENE_SETS = {   # the rope fields of the scenes' parameter sets (ssp/*/default.ssv and variants)
    "elastic_pendulum": {},
    "hook_sway": dict(length=0.4, E=1.0e9, A=2.0e-5),
    "overhead_lift": {k: v for k, v in _LIFT_ROPE.items()},
    "overhead_lift loose": dict(_LIFT_ROPE, start_slack=0.1),
    "truck_telescope": dict(_TELESCOPE_ROPE),
}


@pytest.mark.parametrize("scene", list(SCENE_SETS))
def test_scene_sets_are_bitwise_python(scene):
    p = RopeParams(**SCENE_SETS[scene])
    nat, py = load("Rope", p), RopeModel(p)
    rng = np.random.default_rng(18)
    l_u0 = p.length + p.start_slack
    u0 = inputs(rng, p, l_u0 * 1.2 if p.start == "taut" else l_u0, 1e-3 * l_u0, mass=1000.0 * p.n_lines)
    x0 = py.initial_state(u0)
    np.testing.assert_array_equal(nat.initial_state(u0), x0)
    for _ in range(100):
        x, u = random_state_inputs(rng, p, py, x0, float(u0[15]))
        np.testing.assert_array_equal(nat.derivatives(0.0, x, u), py.derivatives(0.0, x, u))
        np.testing.assert_array_equal(nat.outputs(0.0, x, u), np.array(py.output_list(0.0, x, u)))
        np.testing.assert_array_equal(nat.after_step(0.0, x, u), py.after_step(0.0, x, u))
