"""The native Pendulum (native/models/Pendulum.c) against its Python twin (cranefmu.physics.pendulum), called
directly through the cffi harness: random parameter sets of every dimension, payload, start and ground with
and without the pin damper, the inertias and drag; random states and inputs; the ground events (touch-down,
lift-off, the clipped damper); the lone hook's closed-form step; whole steps as fmi_adapter.advance takes
them (rk4, exact, auto); the scenes' sets over a run; the same refusals in the same words.

Tolerance: bitwise equality, everywhere.  The rigid sling with c_pin, J_payload or J_hook (a 3x3 dot, product
and solve) and the lone hook with J_hook go through cranefmu.physics.small_linalg in Python and cf_dense.h's
twins in C: one fixed order of operations, no BLAS and no fused multiply-add (before, the C mirrored this
machine's OpenBLAS kernels, fused multiply-adds and all, and another CPU's kernel could round differently:
those configurations were held only to 1e-12 of the vector's largest component)."""
from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

pytest.importorskip("cffi")

from cranefmu.adapter.fmi_adapter import advance  # noqa: E402
from cranefmu.adapter.integrators import rk4_list  # noqa: E402
from cranefmu.native.harness import load  # noqa: E402
from cranefmu.physics.params import ParameterError  # noqa: E402
from cranefmu.physics.pendulum import PendulumModel, PendulumParams  # noqa: E402
from structural_cases import refused_as_in_python  # noqa: E402

DIMENSIONS, PAYLOADS = (1, 2, 3), ("none", "rigid", "elastic")
STARTS, GROUNDS = ("position", "below_top", "on_ground"), ("none", "spring_damper")
CONFIGS = [c for c in itertools.product(DIMENSIONS, PAYLOADS, STARTS, GROUNDS)
           if not (c[2] == "on_ground" and c[3] == "none")]
EXTRAS = ("pin", "j_payload", "j_hook", "drag")


def random_pendulum(rng: np.random.Generator, dimension: int, payload: str, start: str, ground: str,
                    extras: set[str]) -> PendulumParams:
    """A valid parameter set of the configuration, every other field drawn within its range."""
    v = dict(dimension=dimension, payload=payload, start=start, ground=ground)
    v["mass"] = float(10 ** rng.uniform(0.5, 4))
    v["g"] = float(rng.uniform(9.0, 10.0))
    v["vx0"], v["vy0"], v["vz0"] = (float(a) for a in rng.normal(size=3))
    if start == "position":
        v["x0"], v["y0"], v["z0"] = float(rng.normal() * 3), float(rng.uniform(-20, -2)), float(rng.normal() * 3)
    elif start == "below_top":
        if dimension >= 2:
            v["theta0"] = float(rng.uniform(-1.4, 1.4))
        if dimension == 3:
            v["phi0"] = float(rng.uniform(-1.4, 1.4))
    else:
        v["x0"], v["z0"] = float(rng.normal() * 3), float(rng.normal() * 3)
    if payload != "none":
        v["m_payload"] = float(10 ** rng.uniform(0, 4))
        v["L_sling"] = float(rng.uniform(0.1, 3.0))
        v["c_sling"] = float(10 ** rng.uniform(5, 8))
        v["zeta_sling"] = float(rng.uniform(0, 2))
        v["theta_payload0"] = float(rng.uniform(-math.pi, math.pi))
        v["phi_payload0"] = float(rng.uniform(-1.4, 1.4))
        if "pin" in extras:
            v["c_pin"] = float(10 ** rng.uniform(0, 4))
        if "j_payload" in extras:
            v["J_payload"] = float(10 ** rng.uniform(-1, 3))
    if "j_hook" in extras:
        v["J_hook"] = float(10 ** rng.uniform(-1, 3))
    v["ground_height"] = float(rng.uniform(-15, -5))
    v["c_ground"] = float(10 ** rng.uniform(6, 9))
    v["b_ground"] = float(10 ** rng.uniform(3, 7)) if rng.uniform() < 0.8 else 0.0
    if "drag" in extras:
        v["drag_coefficient"] = float(rng.uniform(0.1, 2.0))
        v["drag_area"] = float(rng.uniform(0.1, 5.0))
        v["drag_area_hook"] = float(rng.uniform(0.0, 0.1))
        v["rho_air"] = float(rng.uniform(1.0, 1.3))
    return PendulumParams(**v)


def random_inputs(rng: np.random.Generator, p: PendulumParams) -> np.ndarray:
    u = np.zeros(len(PendulumModel.inputs))
    u[0:3] = rng.normal(size=3) * (p.mass + p.m_payload) * 10
    u[1] = abs(u[1])
    u[3:6] = [rng.normal() * 5, rng.uniform(-2, 10), rng.normal() * 5]
    u[6] = rng.uniform(2, 15)
    u[7:10] = rng.normal(size=3)
    return u


def random_rates(rng: np.random.Generator, p: PendulumParams) -> tuple[np.ndarray, np.ndarray]:
    scale = np.array([(p.mass + p.m_payload) * 10] * 3 + [1.0] * 3 + [0.0] + [1.0] * 3)
    return rng.normal(size=10) * scale, rng.normal(size=10) * scale * 10


def random_state(rng: np.random.Generator, p: PendulumParams, u: np.ndarray) -> np.ndarray:
    """A state about the configuration: the hook below the top, the payload about a sling length below it."""
    hook = u[3:6] + np.array([rng.normal() * 3, -rng.uniform(2, 15), rng.normal() * 3])
    vh = rng.normal(size=3) * 2
    if p.payload == "none":
        return np.concatenate([hook, vh])
    if p.payload == "rigid":
        return np.concatenate([hook, vh, [rng.uniform(-2.5, 2.5), rng.uniform(-1.3, 1.3)], rng.normal(size=2) * 2])
    d = rng.normal(size=3)
    d[1] = -abs(d[1]) - 0.3
    d *= p.L_sling * (1 + 1e-3 * rng.normal()) / np.linalg.norm(d)
    return np.concatenate([hook, vh, hook + d, vh + rng.normal(size=3)])


def assert_agree(python, native, p, what: str) -> None:
    """The same bits (module docstring)."""
    python, native = np.asarray(python, dtype=float), np.asarray(native, dtype=float)
    assert python.shape == native.shape, what
    bad = np.flatnonzero(python != native)
    assert bad.size == 0, f"{what}: differ at {bad.tolist()}: python {python[bad].tolist()} native {native[bad].tolist()}"


def configured_sets(seed: int, per_config: int):
    rng = np.random.default_rng(seed)
    for config in CONFIGS:
        for k in range(per_config):
            extras = {e for e in EXTRAS if rng.integers(2)} if k else set()   # the plain form first
            yield rng, random_pendulum(rng, *config, extras)


def test_random_sets_every_configuration():
    """Initial state, derivatives, outputs and the end-of-step update equal to Python's over 45
    configurations x 3 sets x 6 (state, input) pairs, with the pin damper, inertias and drag on and off."""
    seen_body = seen_turning = 0
    for rng, p in configured_sets(0, 3):
        py, c = PendulumModel(p), load("Pendulum", p)
        seen_body += py._body
        seen_turning += p.payload == "none" and p.J_hook != 0.0
        assert c.m.n_states == len(py.state_names())
        assert [c.state_name(i) for i in range(c.m.n_states)] == list(py.state_names())
        assert not c.frozen() and c.exact_applies() == py.exact_applies()
        for _ in range(6):
            u = random_inputs(rng, p)
            x = random_state(rng, p, u)
            t = float(rng.uniform(0, 10))
            assert_agree(py.initial_state(u), c.initial_state(u), p, f"initial_state {p}")
            assert_agree(py.derivatives(t, x, u), c.derivatives(t, x, u), p, f"derivatives {p} x={x} u={u}")
            assert_agree(py.output_list(t, x, u), c.outputs(t, x, u), p, f"outputs {p} x={x} u={u}")
            assert_agree(py.after_step(t, x, u), c.after_step(t, x, u), p, f"after_step {p}")
    assert seen_body >= 15 and seen_turning >= 8   # the general solve was exercised


def test_ground_contact_touch_down_and_lift_off_states():
    """seed 001 eq. 7 at the contact's edges: above the ground (N = 0, lifted), pressing in (N = c pen - b vy),
    pressing in but leaving faster than the spring pushes (the damper clipped: N = 0, lifted), exactly at
    the surface; the lowest body is the payload where there is one."""
    for dimension, payload in itertools.product(DIMENSIONS, PAYLOADS):
        extra = dict(m_payload=500.0, L_sling=1.0) if payload != "none" else {}
        p = PendulumParams(dimension=dimension, payload=payload, ground="spring_damper", ground_height=-10.0,
                           c_ground=2e8, b_ground=1e6, mass=100.0, **extra)
        py, c = PendulumModel(p), load("Pendulum", p)
        u = np.array([0.0, 3000.0, 0.0, 0.0, 0.0, 0.0, 10.0, 0.0, 0.0, 0.0])
        for y_low, vy, n_want in ((-9.9, 0.0, 0.0), (-10.001, -0.1, 2e8 * 0.001 + 1e6 * 0.1),
                                  (-10.001, 0.5, 0.0), (-10.0, -1.0, 0.0), (-10.002, 0.3, 2e8 * 0.002 - 1e6 * 0.3)):
            x = np.zeros(py.initial_state(u).size)
            x[1] = y_low + (1.0 if payload != "none" else 0.0)   # rigid: the payload straight below at L = 1
            if payload == "elastic":
                x[7] = y_low
                x[10] = vy
            x[4] = vy
            out, want = c.outputs(0.0, x, u), py.output_list(0.0, x, u)
            assert_agree(want, out, p, f"outputs at y={y_low} vy={vy} {payload}")
            assert_agree(py.derivatives(0.0, x, u), c.derivatives(0.0, x, u), p, f"derivatives {payload}")
            assert out[8] == pytest.approx(n_want, rel=1e-6) and out[18] == (1.0 if n_want == 0.0 else 0.0)
            assert out[10] == pytest.approx(y_low, abs=1e-12)   # y_payload: the lowest body


def test_rope_lifts_the_load_off_and_sets_it_down_again():
    """A whole run through touch-down and lift-off (overhead_lift's set: elastic sling, ground, load on the
    ground): the rope force ramps above the weight and back down; the C steps equal the Python advance to
    the bit, and the load leaves the ground and lands again."""
    p = PendulumParams(dimension=1, mass=30.0, payload="elastic", m_payload=1800.0, L_sling=1.0, c_sling=2e7,
                       ground="spring_damper", ground_height=0.0, c_ground=2e8, b_ground=1e6, start="on_ground")
    py, c = PendulumModel(p), load("Pendulum", p)
    weight = 1830.0 * 9.81
    u = np.array([0.0, 0.0, 0.0, 0.0, 12.0, 0.0, 10.0, 0.0, 0.0, 0.0])
    x = py.initial_state(u)
    xc = c.initial_state(u)
    assert_agree(x, xc, p, "initial state")
    def pull(time):   # 0 -> 1.4 weight over 0.6 s, held to 0.8 s, back to 0 at 1.4 s, then 0
        return 1.4 * weight * min(time / 0.6, 1.0, max(0.0, (1.4 - time) / 0.6))
    h, t, lifted = 0.005, 0.0, []
    for k in range(400):
        r1 = np.zeros(10)
        r1[1] = (pull(t + h) - pull(t)) / h   # the rate a master sets for the step
        x = advance(py, t, x, h, u, r1, np.zeros(10), "rk4", 1e-6, 1e-3)
        xc = native_step(c, t, xc, h, u, r1, np.zeros(10), "rk4", 1e-3)
        t += h
        u = u + h * r1
        assert_agree(x, xc, p, f"state at t={t}")
        out = c.outputs(t, xc, u)
        assert_agree(py.output_list(t, x, u), out, p, f"outputs at t={t}")
        lifted.append(out[18])
    changes = sum(1 for a, b in zip(lifted, lifted[1:]) if a != b)
    assert lifted[0] == 0.0 and 1.0 in lifted and changes >= 2, lifted   # lift-off and touch-down seen


def test_elastic_sling_pushing_and_zero_length():
    """The elastic sling is bilateral (seed 001's c_2, the hook resting on the load): compressed it pushes
    (S < 0); at zero length its direction is taken straight down."""
    p = PendulumParams(dimension=3, payload="elastic", m_payload=200.0, mass=50.0, zeta_sling=0.3)
    py, c = PendulumModel(p), load("Pendulum", p)
    u = np.array([10.0, 2000.0, -5.0, 0.0, 0.0, 0.0, 10.0, 0.0, 0.0, 0.0])
    for d in ((0.0, -0.2, 0.0), (0.0, 0.0, 0.0), (0.1, 0.3, -0.05)):
        x = np.array([0.0, -10.0, 0.0, 0.1, -0.2, 0.3, 0.0 + d[0], -10.0 + d[1], d[2], 0.0, 0.5, 0.0])
        out = c.outputs(0.0, x, u)
        assert_agree(py.output_list(0.0, x, u), out, p, f"outputs d={d}")
        assert_agree(py.derivatives(0.0, x, u), c.derivatives(0.0, x, u), p, f"derivatives d={d}")
        assert out[17] < 0.0   # shorter than L_sling = 0.5: pushing


def native_step(c, t: float, x: np.ndarray, h: float, u0, r1, r2, solver: str, max_step: float) -> np.ndarray:
    """One communication step of the C model as the FMU layer takes it (fmi_adapter.advance): auto resolved by
    exact_applies, the closed form where it gives one, else rk4 over the C derivatives with the inputs
    u0 + s r1 + s^2/2 r2, operation by operation as integrators.rk4_list; then after_step."""
    moving = bool(np.any(r1) or np.any(r2))
    if solver == "auto":
        solver = "exact" if c.exact_applies() else "rk4"
    x1 = c.exact_step(t, x, h, u0, r1, r2, max_step) if solver == "exact" else None
    if x1 is None:
        u, d1, d2 = u0.tolist(), r1.tolist(), r2.tolist()

        def f(ti, xi):
            if not moving:
                return c.derivatives(ti, xi, u0).tolist()
            s = ti - t
            half = 0.5 * s
            return c.derivatives(ti, xi, [a + s * (b + half * q) for a, b, q in zip(u, d1, d2)]).tolist()
        x1 = np.array(rk4_list(f, t, x.tolist(), h, max_step))
    return c.after_step(t + h, x1, u0 + h * (r1 + 0.5 * h * r2) if moving else u0)


def test_exact_step_of_the_lone_hook():
    """The closed form (no payload, ground, drag or J_hook) equals Python's to the bit for random steps and
    input rates; with ground, drag or J_hook there is none (None: rk4); with a payload 'exact' is refused in
    Python's words (the Python FMU at initialization, the C model at its first exact step)."""
    rng = np.random.default_rng(3)
    for dimension in DIMENSIONS:
        for extra in ({}, {"ground": "spring_damper"}, {"drag_coefficient": 1.0}, {"J_hook": 5.0}):
            p = PendulumParams(dimension=dimension, mass=float(10 ** rng.uniform(0, 4)), **extra)
            py, c = PendulumModel(p), load("Pendulum", p)
            assert c.exact_applies() and py.exact_applies()
            for _ in range(10):
                u0 = random_inputs(rng, p)
                r1, r2 = random_rates(rng, p)
                x = random_state(rng, p, u0)
                h = float(10 ** rng.uniform(-4, -0.5))
                want = py.exact_step(0.0, x, h, u0, r1, r2, 1e-3)
                got = c.exact_step(0.0, x, h, u0, r1, r2, 1e-3)
                if extra:
                    assert want is None and got is None
                else:
                    assert_agree(want, got, p, f"exact_step h={h}")
    for payload in ("rigid", "elastic"):
        p = PendulumParams(payload=payload, m_payload=10.0)
        py, c = PendulumModel(p), load("Pendulum", p)
        assert not c.exact_applies() and not py.exact_applies()
        with pytest.raises(ParameterError) as python:
            py.prepare_exact_step()
        with pytest.raises(FloatingPointError) as native:
            c.exact_step(0.0, py.initial_state(PendulumModel.default_inputs()), 1e-3,
                         *(np.zeros(10) for _ in range(3)), 1e-3)
        assert str(native.value) == str(python.value)


@pytest.mark.parametrize("solver", ["rk4", "exact", "auto"])
def test_whole_steps_equal_the_python_advance(solver):
    """fmi_adapter.advance against the same stepping over the C model: 4 steps of every configuration (auto:
    the closed form without payload, rk4 with one; exact: only where Python accepts it, without payload)."""
    for rng, p in configured_sets(7, 2):
        if solver == "exact" and p.payload != "none":
            continue
        py, c = PendulumModel(p), load("Pendulum", p)
        u = random_inputs(rng, p)
        x = xc = py.initial_state(u)
        h = float(rng.choice([1e-3, 2.5e-3, 5e-3]))
        max_step = float(rng.choice([1e-3, 4e-3]))
        t = 0.0
        for k in range(4):
            r1, r2 = random_rates(rng, p) if k % 2 else (np.zeros(10), np.zeros(10))
            x = advance(py, t, x, h, u, r1, r2, solver, 1e-6, max_step)
            xc = native_step(c, t, xc, h, u, r1, r2, solver, max_step)
            assert_agree(x, xc, p, f"{solver} step {k} {p}")
            t += h
            u = u + h * (r1 + 0.5 * h * r2)


@pytest.mark.parametrize("dimension", [2, 3])
def test_pin_damper_and_inertias_step_bit_for_bit(dimension):
    """A payload on a rigid sling swinging with the hook-pin damper and both inertias (the general 3x3 solve,
    hook_sway's pin_damper set and more) under a moving top: 300 rk4 steps of 2 ms of fmi_adapter.advance
    against the same steps over the C model, the same bits every step (the C and Python small linear algebra
    in one order, small_linalg / cf_dense.h)."""
    p = PendulumParams(dimension=dimension, payload="rigid", mass=40.0, m_payload=1500.0, L_sling=1.2,
                       theta_payload0=0.4, phi_payload0=0.2 if dimension == 3 else 0.0, c_pin=800.0,
                       J_payload=300.0, J_hook=2.0, start="below_top", theta0=0.1)
    py, c = PendulumModel(p), load("Pendulum", p)
    assert py._body
    u = np.array([0.0, (40.0 + 1500.0) * 9.81, 0.0, 0.0, 0.0, 0.0, 8.0, 0.0, 0.0, 0.0])
    x = xc = py.initial_state(u)
    assert_agree(x, c.initial_state(u), p, "initial_state")
    t, h = 0.0, 2e-3
    for k in range(300):
        w = 2.0 * math.pi * 0.7
        r1 = np.array([300.0 * math.cos(w * t), 0.0, 200.0 * math.sin(w * t), 0.5 * math.cos(w * t), 0.0,
                       0.3 * math.sin(w * t), 0.0, 0.0, 0.0, 0.0])
        u[7], u[9] = 0.5 * math.sin(w * t), -0.3 * math.cos(w * t) + 0.3   # the top's velocity
        x = advance(py, t, x, h, u, r1, np.zeros(10), "rk4", 1e-6, h)
        xc = native_step(c, t, xc, h, u, r1, np.zeros(10), "rk4", h)
        assert_agree(x, xc, p, f"step {k}")
        assert_agree(py.output_list(t + h, x, u), c.outputs(t + h, xc, u), p, f"outputs {k}")
        t += h
        u = u + h * r1
    assert abs(x[8]) > 0.05   # it swung (theta rate of the payload)


#: the Pendulum sets of the stored scenes (ssp/*/*.ssv over default.ssv) and the solver each runs with
SCENE_SETS = {
    "elastic_pendulum": (dict(dimension=2, mass=1000.0, start="below_top", theta0=0.08726646259971647), "auto"),
    "hook_sway": (dict(dimension=3, mass=3.0, payload="rigid", m_payload=10.0, L_sling=0.5, start="below_top",
                       theta_payload0=0.17453292519943295, phi_payload0=0.08726646259971647), "rk4"),
    "hook_sway/pin_damper": (dict(dimension=3, mass=3.0, payload="rigid", m_payload=10.0, L_sling=0.5,
                                  start="below_top", theta_payload0=0.17453292519943295,
                                  phi_payload0=0.08726646259971647, c_pin=2.0), "rk4"),
    "hook_sway/crane_motion": (dict(dimension=3, mass=3.0, payload="rigid", m_payload=10.0, L_sling=0.5,
                                    start="below_top", c_pin=2.0), "rk4"),
    "overhead_lift": (dict(dimension=1, mass=30.0, payload="elastic", m_payload=1800.0, L_sling=1.0, c_sling=2.0e7,
                           ground="spring_damper", ground_height=0.0, c_ground=2.0e8, b_ground=1.0e6,
                           start="on_ground"), "rk4"),
    "truck_slewing": (dict(dimension=3, mass=2000.0, start="below_top"), "auto"),
    "truck_telescope": (dict(dimension=2, mass=2500.0, start="below_top"), "auto"),
    "truck_telescope/load3500": (dict(dimension=2, mass=3500.0, start="below_top"), "auto"),
}


@pytest.mark.parametrize("scene", list(SCENE_SETS))
def test_scene_sets_over_a_run(scene):
    """Each scene's set on a rope (a stiff spring from a moving top, the force computed from the state as the
    rope FMU would): 1 s of 5 ms steps (max_step 4 ms as hook_sway stores), states and outputs at every step."""
    fields, solver = SCENE_SETS[scene]
    p = PendulumParams(**fields)
    py, c = PendulumModel(p), load("Pendulum", p)
    top = np.array([1.0, 12.0 if p.ground != "none" else 0.0, 0.5])
    k_rope, length = 2e6 * (p.mass + p.m_payload) / 1000.0, 10.0
    u = np.zeros(10)
    u[3:6], u[6] = top, length
    u[1] = py._rest_tension
    x = py.initial_state(u)
    assert_agree(x, c.initial_state(u), p, "initial state")
    xc, t, h = x, 0.0, 0.005
    for k in range(200):
        d = u[3:6] - x[:3]
        ell = float(np.sqrt(d @ d))
        pull = max(0.0, k_rope * (ell - length) + (k * 40.0 if p.ground != "none" else 0.0))
        u = u.copy()
        u[0:3] = pull * d / ell
        u[7] = 0.3 * math.cos(2.0 * t)   # the top moves (the pin damper's rope rotation)
        r1 = np.zeros(10)
        r1[3] = u[7]
        x = advance(py, t, x, h, u, r1, np.zeros(10), solver, 1e-6, 4e-3)
        xc = native_step(c, t, xc, h, u, r1, np.zeros(10), solver, 4e-3)
        t += h
        u[3] += h * r1[3]
        assert_agree(x, xc, p, f"{scene} state at t={t}")
        assert_agree(py.output_list(t, x, u), c.outputs(t, xc, u), p, f"{scene} outputs at t={t}")


REFUSALS = [
    dict(start="below_top", x0=1.5),
    dict(start="below_top", y0=-3.0),
    dict(start="below_top", z0=-0.25),
    dict(start="on_ground", ground="spring_damper", y0=0.1),
    dict(start="on_ground", ground="spring_damper", theta0=0.2),
    dict(start="on_ground", ground="spring_damper", dimension=3, phi0=1e-7),
    dict(start="position", theta0=0.3),
    dict(start="position", phi0=-0.3),
    dict(start="below_top", dimension=1, theta0=0.1),
    dict(start="below_top", dimension=2, phi0=0.1),
    dict(start="below_top", dimension=1, phi0=-0.7),
    dict(start="on_ground"),
    dict(m_payload=3.0),
    dict(payload="rigid"),
    dict(payload="elastic", m_payload=0.0),
]


@pytest.mark.parametrize("bad", REFUSALS, ids=[",".join(f"{k}={v}" for k, v in b.items()) for b in REFUSALS])
def test_the_same_refusal_in_the_same_words(bad):
    refused_as_in_python("Pendulum", PendulumParams, bad)
