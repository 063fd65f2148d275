"""Every scene starts in the static equilibrium of the parameters in force (docs/equilibrium.md).

Nothing in a scene is a stretch or a coordinate typed by hand: the FMUs derive the start at
initialization (the rope's hang length under the pendulum's rest tension, the taut rope's length,
the load on the ground, chassis settlements, girder sag, drivetrain pretwist).  So after any change
of a mass, stiffness, length or angle the co-simulation starts at rest: every velocity output moves
by less than 1e-9 g over the first steps (Jacobi, zero-order hold: an output moves only by what its
own FMU's acceleration at t = 0 makes it).  The monolithic reference starts from the same state.
A release offset (a parameter of its own) starts a sway scene away from rest by exactly that offset.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from cranefmu.master.run import run
from cranefmu.analysis.reference import Monolith
from cranefmu.scenes import static_outrigger_loads

G = 9.81
H, STEPS = 1e-3, 3
AT_REST = 1e-9 * G          # [m/s2]
# derandomized (the same sample every run), no shrinking (each example is a co-simulation in a child process)
SAMPLE = settings(max_examples=10, deadline=None, derandomize=True, phases=[Phase.explicit, Phase.generate],
                  suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
RELEASES = settings(SAMPLE, max_examples=5)
# the truck telescopes and pays out from t = 0: hold the manoeuvre back past the short run
HELD = {"boom.telescope_start": 1.0, "drive.start_time": 1.0}
NO_RELEASE = {"elastic_pendulum": {"pendulum.theta0": 0.0},
              "hook_sway": {"pendulum.theta_payload0": 0.0, "pendulum.phi_payload0": 0.0}}


def is_velocity(column: str) -> bool:
    var = column.partition(".")[2]
    return var.startswith("v") or var in ("gamma_rate", "motor_speed", "drum_speed", "payout_rate")


def start(scene: str, parameters: dict, parameter_set: str = "default"):
    """First STEPS + 1 rows of a co-simulation at H and the largest |dv/dt| [m/s2 or rad/s2] of any
    velocity output over them, with the column it belongs to."""
    res = run(scene, stop_time=STEPS * H, step_size=H, algorithm="jacobi", extrapolation=0,   # held inputs
              parameter_set=parameter_set, parameters=parameters).result
    acc = {c: float(np.max(np.abs(np.diff(res[c])))) / H for c in res.dtype.names if is_velocity(c)}
    worst = max(acc, key=acc.get)
    return res, acc[worst], worst


def same_start_as_the_monolith(scene: str, parameters: dict, res, parameter_set: str = "default") -> None:
    """The monolithic reference (cranefmu.analysis.reference) initializes to the co-simulation's first row."""
    mono = Monolith(scene, parameter_set, parameters)
    row = dict(zip(mono.columns, mono.output_row(0.0, mono.initial_state(0.0))))
    for c in ("pendulum.x", "pendulum.y", "pendulum.z", "rope.tension", "rope.elongation"):
        assert row[c] == pytest.approx(float(res[c][0]), rel=1e-8, abs=1e-9), c


def assert_at_rest(scene: str, parameters: dict, parameter_set: str = "default") -> None:
    res, a, worst = start(scene, parameters, parameter_set)
    assert a < AT_REST, f"{scene} {parameters}: d{worst}/dt = {a:.3g} at the start"
    same_start_as_the_monolith(scene, parameters, res, parameter_set)


# --- after a change of masses, stiffnesses, lengths and angles, every scene starts at rest ----------------
# Ranges: each scene as a co-simulation can run it (axial rope mode omega H < 1 at H = 1 ms, c / m < 1e6 s^-2).
# Beyond that the round-off of the equilibrium itself, (c / m) L eps per ulp of the hook position, passes
# 1e-9 g (a 1 kg load on a 1 m rope of E = 4e11 Pa: 5e-9 g per ulp).
@SAMPLE
@given(mass=st.floats(100.0, 2e4), E=st.floats(1e10, 1e12), length=st.floats(2.0, 40.0),
       n_lines=st.sampled_from([1, 2, 4]), dimension=st.sampled_from([2, 3]))
def test_elastic_pendulum_starts_at_rest(built, mass, E, length, n_lines, dimension):
    assert_at_rest("elastic_pendulum", {**NO_RELEASE["elastic_pendulum"], "pendulum.mass": mass, "rope.E": E,
                                        "rope.length": length, "rope.n_lines": n_lines,
                                        "pendulum.dimension": dimension})


@SAMPLE
@given(m_hook=st.floats(1.0, 20.0), m_payload=st.floats(2.0, 100.0), hook_length=st.floats(0.2, 3.0),
       sling=st.floats(0.2, 3.0), E=st.floats(2e8, 2e10), luff_deg=st.floats(10.0, 80.0),
       boom=st.floats(8.0, 25.0))
def test_hook_sway_starts_at_rest(built, m_hook, m_payload, hook_length, sling, E, luff_deg, boom):
    assert_at_rest("hook_sway", {**NO_RELEASE["hook_sway"], "pendulum.mass": m_hook, "pendulum.m_payload": m_payload,
                                 "rope.length": hook_length, "pendulum.L_sling": sling, "rope.E": E,
                                 "boom.luff_angle": math.radians(luff_deg), "boom.boom_length_start": boom,
                                 "boom.boom_length_end": boom})


@SAMPLE
@given(m_hook=st.floats(5.0, 200.0), m_payload=st.floats(200.0, 5000.0), E=st.floats(5e10, 2e11),
       n_lines=st.sampled_from([2, 4, 6]), m1=st.floats(2e3, 1e4), c1=st.floats(1e6, 1e7),
       sling=st.floats(0.5, 2.0), c_sling=st.floats(5e6, 5e7), height=st.floats(8.0, 20.0),
       parameter_set=st.sampled_from(["default", "loose"]))
def test_overhead_lift_starts_at_rest(built, m_hook, m_payload, E, n_lines, m1, c1, sling, c_sling, height,
                                      parameter_set):
    params = {"pendulum.mass": m_hook, "pendulum.m_payload": m_payload, "rope.E": E, "rope.n_lines": n_lines,
              "girder.girder_mass": m1, "girder.c1": c1, "pendulum.L_sling": sling, "pendulum.c_sling": c_sling,
              "girder.height": height}
    assert_at_rest("overhead_lift", params, parameter_set)


@SAMPLE
@given(load=st.floats(300.0, 3500.0), E=st.floats(1e10, 1.4e11), length=st.floats(4.0, 15.0),
       luff_deg=st.floats(30.0, 75.0), boom=st.floats(10.5, 14.0), soil=st.floats(3e7, 3e8),
       cylinder=st.sampled_from(["prescribed", "spring_damper"]))
def test_truck_telescope_starts_at_rest(built, load, E, length, luff_deg, boom, soil, cylinder):
    # a load the crane cannot hold (front outrigger unloaded) has no static equilibrium: it tips
    if static_outrigger_loads(boom, luff_deg, load)[0] <= 0.05 * load * G:
        return
    assert_at_rest("truck_telescope", {**HELD, "pendulum.mass": load, "rope.E": E, "rope.length": length,
                                       "boom.luff_angle": math.radians(luff_deg), "boom.boom_length_start": boom,
                                       "chassis.soil_coefficient": soil, "boom.cylinder": cylinder})


@pytest.mark.parametrize("scene, parameter_set, extra", [
    ("elastic_pendulum", "default", {"rope.model": "bouc_wen"}),
    ("overhead_lift", "default", {"rope.model": "bouc_wen"}),
    ("overhead_lift", "loose", {"rope.model": "bouc_wen"}),
    ("truck_telescope", "luff30", {**HELD, "rope.model": "bouc_wen"}),
    ("truck_telescope", "load3500", HELD),
    # the elastic sling: seed 001's c_2 = 2e7 N/m on a 3 kg hook 9 m up puts one ulp of the hook height at
    # 1.2e-8 m/s2 (c_2 eps y / m_h): the round-off floor itself.  A sling of 1e6 N/m, and sub-steps of
    # 0.1 ms for the FMU's own rk4 (the sling rings at 600 rad/s)
    ("hook_sway", "default", {"pendulum.payload": "elastic", "pendulum.c_sling": 1e6, "pendulum.max_step": 1e-4})])
def test_fidelity_switches_and_parameter_sets_start_at_rest(built, scene, parameter_set, extra):
    """The Bouc-Wen rope hangs the hook by its virgin loading curve, the same derivation."""
    assert_at_rest(scene, {**NO_RELEASE.get(scene, {}), **extra}, parameter_set)


def test_taut_rope_carries_the_hook_and_loose_rope_nothing(built):
    """overhead_lift: the rope is taken up until it carries the hook's weight wherever the girder sags
    (a heavier girder used to leave the hand-placed rope slack); start_slack pays out exactly that."""
    heavy = {"girder.girder_mass": 16000.0}   # reduced mass 17/35 of it: 7771 kg
    tight = run("overhead_lift", stop_time=H, step_size=H, parameters=heavy).result
    loose = run("overhead_lift", stop_time=H, step_size=H, parameter_set="loose", parameters=heavy).result
    assert tight["rope.tension"][0] == pytest.approx(30.0 * G, rel=1e-9)
    assert loose["rope.tension"][0] == 0.0
    delta = tight["rope.elongation"][0]     # Hooke on the length taken up (the girder sags 6 mm more)
    assert delta == pytest.approx(30.0 * G * (tight["rope.rope_length"][0] - delta) / (4 * 1.155e11 * 5.53e-5),
                                  rel=1e-9)
    # 0.1 m paid out beyond taut; the hook, now resting on the load, sinks by m_h g / c_2 = 1.5e-5 m
    assert loose["rope.elongation"][0] - tight["rope.elongation"][0] == pytest.approx(-0.1, abs=2e-5)


# --- a release offset starts the sway scenes away from rest by exactly that offset -------------------------
@RELEASES
@given(theta0_deg=st.floats(1.0, 30.0), mass=st.floats(10.0, 1e4), E=st.floats(1e10, 1e12))
def test_elastic_pendulum_released_at_its_angle_in_radial_equilibrium(built, theta0_deg, mass, E):
    """Released at rest at theta0: the angle is the parameter, the rope holds m g cos(theta0) (radial
    equilibrium: no axial jolt), and the hook accelerates along the tangent at g sin(theta0)."""
    theta0 = math.radians(theta0_deg)
    res, _, _ = start("elastic_pendulum", {"pendulum.theta0": theta0, "pendulum.mass": mass, "rope.E": E})
    assert res["pendulum.theta"][0] == pytest.approx(theta0, rel=1e-12)
    assert res["rope.tension"][0] == pytest.approx(mass * G * math.cos(theta0), rel=1e-9)
    radial = np.array([math.sin(theta0), -math.cos(theta0)])      # suspension point -> hook
    tangent = np.array([math.cos(theta0), math.sin(theta0)])       # direction of increasing theta
    a = np.array([res["pendulum.vx"][1], res["pendulum.vy"][1]]) / H  # from rest, constant force over a step
    assert abs(a @ radial) < AT_REST
    assert a @ tangent == pytest.approx(-G * math.sin(theta0), rel=1e-9)


def test_elastic_pendulum_swings_back_to_minus_its_release_angle(built):
    """The released amplitude is the parameter: half a swing later the load is at -theta0 (within the
    rope's slight axial damping and the elastic pendulum's amplitude correction, 0.5 %)."""
    theta0 = math.radians(8.0)
    period = 2.0 * math.pi * math.sqrt(10.0 / G) * (1.0 + theta0 ** 2 / 16.0)
    res = run("elastic_pendulum", stop_time=0.7 * period, step_size=2e-3, extrapolation=1,
              parameters={"pendulum.theta0": theta0}).result
    assert res["pendulum.theta"][0] == pytest.approx(theta0, rel=1e-12)
    assert res["pendulum.theta"].min() == pytest.approx(-theta0, rel=5e-3)


@RELEASES
@given(theta_deg=st.floats(-30.0, 30.0), phi_deg=st.floats(-20.0, 20.0), m_hook=st.floats(1.0, 10.0))
def test_hook_sway_payload_released_at_its_angles(built, theta_deg, phi_deg, m_hook):
    """The payload starts at rest at exactly the release angles, the hook at rest under the tip."""
    theta, phi = math.radians(theta_deg), math.radians(phi_deg)
    res, _, _ = start("hook_sway", {"pendulum.theta_payload0": theta, "pendulum.phi_payload0": phi,
                                    "pendulum.mass": m_hook})
    assert res["pendulum.theta_payload"][0] == pytest.approx(theta, rel=1e-12, abs=1e-15)
    assert res["pendulum.phi_payload"][0] == pytest.approx(phi, rel=1e-12, abs=1e-15)
    for c in ("pendulum.vx", "pendulum.vy", "pendulum.vz", "pendulum.vx_payload", "pendulum.vy_payload",
              "pendulum.vz_payload"):
        assert res[c][0] == 0.0, c
    assert abs(res["pendulum.theta"][0]) < 1e-12 and abs(res["pendulum.phi"][0]) < 1e-12
