"""The crane scenes: static equilibrium at the start, and summaries that are finite and physically ordered."""
import math

import numpy as np
import pytest

from cranefmu.master.run import run
from cranefmu.analysis.reference import Monolith
from cranefmu.scenes import (SCENES, hook_sway_parameters, metrics, plot_groups, static_outrigger_loads, summary,
                             truck_telescope_parameters)

from reference_cache import solve   # one solve per argument set in the session

G = 9.81
AT_REST = {"hook_sway": {"pendulum.theta_payload0": 0.0, "pendulum.phi_payload0": 0.0}}
CASES = [("elastic_pendulum", "default"), ("overhead_lift", "default"), ("overhead_lift", "loose"),
         ("truck_telescope", "default"), ("truck_telescope", "luff30"), ("truck_telescope", "luff45"),
         ("hook_sway", "default")]


@pytest.mark.parametrize("scene, parameter_set", CASES)
def test_every_scene_starts_in_static_equilibrium(scene, parameter_set):
    """All accelerations of the initialized scene vanish (below 1e-7 g): no start-up transient.
    elastic_pendulum is released from 5 deg: only its axial (radial) direction is at rest."""
    mono = Monolith(scene, parameter_set, AT_REST.get(scene))
    x0 = mono.initial_state(0.0)
    dx = mono.split(mono.rhs(0.0, x0))
    for name, model, d, x in zip(mono.names, mono.models, dx, mono.split(x0)):
        states = model.state_names()
        if scene == "elastic_pendulum" and name == "pendulum":
            radial = x[:2] / np.linalg.norm(x[:2])
            assert abs(d[3:5] @ radial) < 1e-7 * G
            continue
        for s, v in zip(states, d):
            if s.startswith(("v", "w_", "d")) or s in ("M_e", "Theta", "gamma_rate", "psi_rate"):
                assert abs(v) < 1e-7 * max(G, 1.0), f"{name}.{s}' = {v} at t = 0"


def test_truck_start_matches_the_static_outrigger_loads_of_seed_000():
    """2.5 t at 60 deg, 10.5 m: N2 = 104.13 kN (rear, boom side), N1 = 77.8 kN (seed 000, labels swapped)."""
    mono = Monolith("truck_telescope")
    y = dict(zip(mono.columns, mono.output_row(0.0, mono.initial_state(0.0))))
    assert y["chassis.N_rear"] == pytest.approx(104.13e3, rel=2e-3)
    assert y["chassis.N_front"] == pytest.approx(77.8e3, rel=2e-3)
    assert y["rope.tension"] == pytest.approx(2500 * G, rel=1e-7)


def test_hook_sway_at_rest_stays_at_rest_in_the_cosimulation(built):
    res = run("hook_sway", stop_time=0.05, step_size=1e-3, parameters=AT_REST["hook_sway"]).result
    for k in ("pendulum.x", "pendulum.y", "pendulum.z", "rope.tension"):
        drift = np.max(np.abs(res[k] - res[k][0]))
        assert drift < 1e-9 * max(1.0, abs(res[k][0])), (k, drift)


# the truck scene starts telescoping at t = 0: hold the manoeuvre back so that only the start is tested
HELD = {"truck_telescope": {"boom.telescope_start": 1.0, "drive.start_time": 1.0}}


@pytest.mark.parametrize("scene, parameter_set", [("truck_telescope", "default"), ("truck_telescope", "luff30"),
                                                   ("truck_telescope", "luff45"), ("overhead_lift", "default")])
def test_crane_scenes_start_at_rest_in_the_cosimulation(built, scene, parameter_set):
    """The co-simulation initializes every crane scene at rest (at 30 deg the initialization loop used
    to stall: pendulum.start = below_top).  Measured: velocities <= 3e-13 m/s, drifts <= 2e-12 relative."""
    res = run(scene, stop_time=0.05, step_size=1e-3, parameter_set=parameter_set, parameters=HELD.get(scene)).result
    assert np.max(np.abs(res["pendulum.vy"])) < 1e-9
    if scene != "truck_telescope":
        return
    for k in ("pendulum.vx", "chassis.vy_base", "chassis.gamma_rate"):
        assert np.max(np.abs(res[k])) < 1e-9, k
    for k in ("rope.tension", "chassis.N_front", "chassis.N_rear", "chassis.gamma", "pendulum.x", "pendulum.y"):
        drift = np.max(np.abs(res[k] - res[k][0]))
        assert drift < 1e-9 * max(1.0, abs(res[k][0])), (k, drift)
    assert res["rope.tension"][0] == pytest.approx(2500 * G, rel=1e-9)      # the hook hangs from the rope alone
    assert abs(res["pendulum.theta"][0]) < 1e-12                           # straight below the tip


@pytest.mark.slow
def test_truck_crane_tips_at_30_deg_in_the_cosimulation(built):
    """Seed 000: at 30 deg the crane tips while telescoping.  Statically (segments extended) the front
    outrigger unloads at 15.67 m of boom; the telescoping run tips 0.25 m of boom later (monolith: 9.24 s,
    15.92 m): the load swings against the reach there (its sway, about 2 deg, moves the tipping point)."""
    res = run("truck_telescope", stop_time=10.0, step_size=1e-2, parameter_set="luff30").result
    m = metrics("truck_telescope", res)
    assert m["tipping"] == 1.0
    assert 15.0 < m["tipping_boom_length"] < 16.2
    assert abs(m["tipping_boom_length"] - 15.67) < 0.4                               # static, segments out
    assert static_outrigger_loads(15.6, 30.0, 2500.0)[0] > 0.0 > static_outrigger_loads(15.7, 30.0, 2500.0)[0]


@pytest.fixture(scope="module")
def lifts():
    """Tight and loose lift until shortly after lift-off (monolithic solve, loose rtol: ordering only)."""
    return {ps: solve("overhead_lift", stop, np.linspace(0.0, stop, 801), parameter_set=ps, rtol=1e-5)
            for ps, stop in (("default", 1.0), ("loose", 1.5))}


def test_loose_rope_gives_a_larger_dynamic_factor_than_tight(lifts):
    tight, loose = (metrics("overhead_lift", lifts[k]) for k in ("default", "loose"))
    assert all(math.isfinite(v) for v in (*tight.values(), *loose.values()))
    assert 1.0 < tight["dynamic_factor"] < loose["dynamic_factor"] < 2.0
    assert tight["lift_off_time"] < loose["lift_off_time"]      # the slack is taken up first
    assert tight["weight"] == pytest.approx(1830 * G, rel=1e-9)
    labels = [label for label, _ in summary("overhead_lift", lifts["loose"])]
    assert labels[:2] == ["dynamic factor", "lift-off time"]


def test_faster_telescoping_gives_larger_sway():
    """Over the first 6 s (acceleration T1 = 3 s, then the free swing) the tip accelerates at V / T1."""
    sway = {}
    for v in (0.2, 0.55):
        r = solve("truck_telescope", 6.0, np.linspace(0.0, 6.0, 601), parameters=truck_telescope_parameters(speed=v),
                  rtol=1e-6)
        m = metrics("truck_telescope", r)
        assert math.isnan(m["sway_after_deg"])          # still telescoping at 6 s: no free swing yet
        assert m["tipping"] == 0.0 and math.isnan(m["tipping_time"])
        assert all(math.isfinite(x) for k, x in m.items() if k not in ("sway_after_deg", "tipping_time",
                                                                         "tipping_boom_length"))
        sway[v] = m["max_sway_deg"]
    assert 0.0 < sway[0.2] < sway[0.55]


def test_hook_parameters_place_the_hook_under_the_tip():
    p = hook_sway_parameters(m_hook=5.0, hook_length=0.5)
    mono = Monolith("hook_sway", "default", {**p, **AT_REST["hook_sway"]})
    x0 = mono.initial_state(0.0)
    y = dict(zip(mono.columns, mono.output_row(0.0, x0)))
    assert y["rope.tension"] == pytest.approx(15.0 * G, rel=1e-9)
    assert y["pendulum.x"] == pytest.approx(y["boom.x_tip"], abs=1e-12)


def test_plot_groups_cover_the_crane_signals():
    cols = ["time", "rope.tension", "chassis.N_front", "chassis.N_rear", "chassis.q1", "chassis.q2",
            "pendulum.theta", "boom.boom_length"]
    groups = dict(plot_groups("truck_telescope", cols))
    assert groups["Outrigger reactions"] == ["chassis.N_front", "chassis.N_rear"]
    assert groups["Settlements"] == ["chassis.q1", "chassis.q2"]
    assert "Motor torque" not in groups          # no drive torque column given
    assert set(SCENES) >= {"overhead_lift", "truck_telescope", "hook_sway", "elastic_pendulum"}


def test_static_tipping_of_the_truck_crane():
    """Seed 000: 104.13 / 77.8 kN at 10.5 m and 60 deg (2.5 t), 125.49 / 66.25 kN with 3.5 t; stable fully
    extended at 60 deg, tips at 30 deg; with the text's 3.5 t it tips at 60 deg before 22.4 m.  Segments
    extended with the tip: static tipping at 15.67 / 19.14 / 26.96 m (30 / 45 / 60 deg, 2.5 t)."""
    front, rear = static_outrigger_loads(10.5, 60.0, 2500.0)
    assert (front, rear) == (pytest.approx(77.8e3, rel=1e-3), pytest.approx(104.13e3, rel=1e-3))
    assert static_outrigger_loads(22.4, 60.0, 2500.0)[0] > 0.0
    assert static_outrigger_loads(22.4, 30.0, 2500.0)[0] < 0.0
    assert static_outrigger_loads(20.9, 60.0, 3500.0)[0] > 0.0 > static_outrigger_loads(21.1, 60.0, 3500.0)[0]
    assert static_outrigger_loads(10.5, 60.0, 3500.0) == (pytest.approx(66.25e3, rel=1e-3),
                                                          pytest.approx(125.49e3, rel=1e-3))
    for angle, length in ((30.0, 15.67), (45.0, 19.14), (60.0, 26.96)):   # the old, retracted segments: 16.2, 20.1, 28.7
        assert static_outrigger_loads(length - 0.01, angle, 2500.0)[0] > 0.0 > \
            static_outrigger_loads(length + 0.01, angle, 2500.0)[0]
    # the total is the weight of everything standing on the outriggers, whatever the reach
    assert sum(static_outrigger_loads(22.4, 45.0, 2500.0)) == pytest.approx(sum((front, rear)), rel=1e-12)


def test_truck_starts_with_linear_extrapolation_at_10_ms(built):
    """The iterative start-up of Jacobi with extrapolation 1 converges at H = 10 ms (it stalled at the
    map's noise, 4e-9 of a 2e-6 m/s hook velocity, against 1e-10) and the tension follows the monolithic solve."""
    res = run("truck_telescope", stop_time=0.2, step_size=1e-2, extrapolation=1).result
    assert len(res) == 21
    ref = solve("truck_telescope", 0.2, res["time"], rtol=1e-8)
    assert np.abs(res["rope.tension"] - ref["rope.tension"]).max() < 1e-3 * np.abs(ref["rope.tension"]).max()


def test_luffing_set_ends_in_the_static_reactions_of_its_new_angle():
    """Parameter set luffing: the elastic cylinder (seed 000's luffing degree of freedom) luffs the retracted
    boom from 60 to 45 deg.  Averaged over two swings of the load afterwards, the outrigger reactions are the
    closed-form statics at the angle the cylinder holds (measured 0.06 %); the oil column sags the boom by
    about 0.08 deg under the larger moment, and the luffing sets the load swinging (about 2 deg)."""
    T = 30.0
    t = np.linspace(0.0, T, 3001)
    r = solve("truck_telescope", T, t, parameter_set="luffing", rtol=1e-6)
    w = t >= T - 4.0 * math.pi * math.sqrt(9.1 / G)
    phi = math.degrees(float(np.mean(r["boom.luff_angle_out"][w])))
    assert 44.8 < phi < 45.0
    front, rear = static_outrigger_loads(10.5, phi, 2500.0)
    assert np.mean(r["chassis.N_front"][w]) == pytest.approx(front, rel=3e-3)
    assert np.mean(r["chassis.N_rear"][w]) == pytest.approx(rear, rel=3e-3)
    assert 1.0 < math.degrees(np.ptp(r["pendulum.theta"][w]) / 2) < 4.0


def test_travel_and_steering_of_the_floor_crane_set_the_load_swinging():
    """hook_sway's crane motions (seed 002): the hook alone (no payload) on its 0.4 m rope, the crane travelling
    1 m at 0.3 m/s with 1 s ramps, swings while coasting with the closed-form amplitude of a pendulum whose
    suspension accelerates at a for T: 2 (a / g) |sin(omega T / 2)|, omega = sqrt(g / L) (measured 0.07 %).
    Steering 45 deg at 0.2 rad/s swings it sideways: about the tangential estimate 2 (r alpha / g) |sin(omega T
    / 2)| (r = 5.25 m; measured 7 % more: the centripetal part and the large angle)."""
    hook = {"pendulum.payload": "none", "pendulum.m_payload": 0.0, "pendulum.theta_payload0": 0.0,
            "pendulum.phi_payload0": 0.0}
    t = np.linspace(0.0, 3.3, 1651)
    r = solve("hook_sway", 3.3, t, rtol=1e-9, parameters={**hook, "boom.travel_distance": 1.0,
                                                            "boom.travel_speed": 0.3, "boom.travel_t_acc": 1.0})
    length = r["boom.y_tip"][0] - r["pendulum.y"][0]
    half = 0.5 * math.sqrt(G / length) * 1.0
    coast = t > 1.2
    assert np.max(np.abs(r["pendulum.theta"][coast])) == pytest.approx(2.0 * 0.3 / G * abs(math.sin(half)), rel=5e-3)
    r = solve("hook_sway", 3.3, t, rtol=1e-9, parameters={**hook, "boom.steer_delta": math.pi / 4,
                                                            "boom.steer_rate": 0.2, "boom.steer_t_acc": 1.0})
    tangential = 2.0 * 5.25 * 0.2 / G * abs(math.sin(half))
    assert 1.0 < np.max(np.abs(r["pendulum.phi"][coast])) / tangential < 1.15
