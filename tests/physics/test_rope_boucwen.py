"""Rope model with the modified Bouc-Wen law (seed 001 eq. 1-3): the hysteresis state z is the
model's own state, integrated in time like the FMU does; static equilibrium, bounded dissipative
loops that agree with the path integration of boucwen.py, slack and re-tightening."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.adapter.integrators import integrate
from cranefmu.physics import boucwen
from cranefmu.physics.params import ParameterError
from cranefmu.physics.rope import RopeModel, RopeParams, static_elongation

L, NL = 10.0, 2
P = RopeParams(model="bouc_wen", length=L, n_lines=NL)


def hook_at(model: RopeModel, y: float, vy: float = 0.0, payout: float = 0.0, payout_rate: float = 0.0):
    u = model.default_inputs()
    u[7], u[10], u[12], u[13] = y, vy, payout, payout_rate
    return u


def drive(model: RopeModel, y_of_t, vy_of_t, t_end: float, h: float = 1e-3, solver: str = "rk4"):
    """Step the model like the FMU does (ZOH inputs over each step, after_step projection).
    Returns times, elongations, tensions and z."""
    u = hook_at(model, y_of_t(0.0), vy_of_t(0.0))
    x = model.initial_state(u)
    ts, rows = [0.0], [model.output_values(0.0, x, u)]
    n = round(t_end / h)
    for k in range(n):
        t = k * h
        u = hook_at(model, y_of_t(t + 0.5 * h), vy_of_t(t + 0.5 * h))  # midpoint hold: 2nd order in h
        x = integrate(lambda tt, xx: model.derivatives(tt, xx, u), t, x, h, solver, 1e-8, 1e-6, h)
        u1 = hook_at(model, y_of_t(t + h), vy_of_t(t + h))
        x = model.after_step(t + h, x, u1)
        ts.append(t + h)
        rows.append(model.output_values(t + h, x, u1))
    rows = np.array(rows)
    return np.array(ts), rows[:, 9], rows[:, 0], rows[:, 11]


def test_static_load_is_an_equilibrium():
    m = RopeModel(P)
    load = 20e3
    d = static_elongation(P, load)
    u = hook_at(m, -(L + d))
    x = m.initial_state(u)
    assert m.output_values(0.0, x, u)[0] == pytest.approx(load, rel=1e-9)
    assert m.derivatives(0.0, x, u) == pytest.approx([0.0], abs=0.0)
    # held at rest for 1 s: nothing moves
    _, _, tension, z = drive(m, lambda t: -(L + d), lambda t: 0.0, 1.0, h=1e-2)
    assert np.all(tension == tension[0]) and np.all(z == z[0])
    # the hysteretic part is on the virgin curve and inside its bound
    assert 0.0 < x[0] <= boucwen.z_bound(m.bouc_wen_at(L))


def test_default_set_has_the_kelvin_voigt_small_amplitude_stiffness():
    m = RopeModel(P)
    kv = RopeParams(length=L, n_lines=NL)
    assert boucwen.small_amplitude_stiffness(m.bouc_wen_at(L)) == pytest.approx(NL * kv.E * kv.A / L, rel=1e-12)


def test_time_integrated_loop_matches_path_integration_and_dissipates():
    """Hook moved through two load-unload cycles 0 -> 12 mm -> 0 of elongation (period 1 s)."""
    m = RopeModel(P)
    amp, w = 6e-3, 2.0 * math.pi
    y = lambda t: -(L + amp * (1.0 - math.cos(w * t)))          # noqa: E731
    vy = lambda t: -amp * w * math.sin(w * t)                     # noqa: E731
    ts, delta, tension, z = drive(m, y, vy, 2.0, h=1e-3)
    bw = m.bouc_wen_at(L)
    _, f_path = boucwen.simulate_path(delta, bw)
    assert np.max(np.abs(tension - f_path)) < 1e-3 * np.max(tension)
    assert np.all(np.abs(z) <= boucwen.z_bound(bw) * (1 + 1e-6))
    assert np.all(tension >= 0.0) and np.max(tension) < 1.5 * NL * 1e11 * 5.655e-5 / L * 2 * amp
    # work done on the rope over the second cycle (trapezoid in delta): positive, a part of the loading work
    # (measured: 24 J of 64 J; z rises to z_u while loading and drops to the zero-force line unloading)
    second = ts >= 1.0 - 1e-12
    f2, d2 = tension[second], delta[second]
    work = np.trapezoid(f2, d2)
    top = np.argmax(d2) + 1
    loading = np.trapezoid(f2[:top], d2[:top])
    assert 0.01 * loading < work < 0.5 * loading


def test_slack_and_retightening_follow_the_virgin_curve():
    """Loaded, then the hook rises 5 mm above the slack point, then comes back down further."""
    m = RopeModel(P)
    d = static_elongation(P, 15e3)
    y = lambda t: -(L + d) + (d + 5e-3) * math.sin(math.pi * t)   # noqa: E731  (t in [0, 1]: up and back)
    vy = lambda t: (d + 5e-3) * math.pi * math.cos(math.pi * t)    # noqa: E731
    ts, delta, tension, z = drive(m, y, vy, 1.0, h=1e-3)
    slack = delta < 0.0
    assert slack.any() and np.all(tension[slack] == 0.0) and np.all(z[slack] == 0.0)
    u = hook_at(m, -(L - 1e-3))
    assert m.output_values(0.0, np.array([0.0]), u)[10] == 1.0  # slack flag
    # back at the start elongation the rope is taut again on its virgin curve (no dead band)
    back = ts > 0.5
    k = np.flatnonzero(back)[np.argmin(np.abs(delta[back] - 0.5 * d))]
    bw = m.bouc_wen_at(L)
    assert tension[k] == pytest.approx(boucwen.tension(delta[k], 0.0, boucwen.virgin_z(delta[k], bw), bw), rel=2e-3)
    assert tension[-1] == pytest.approx(15e3, rel=2e-3)


def test_payout_uses_the_longer_line():
    m = RopeModel(P)
    d = static_elongation(P, 10e3, payout=4.0)  # 4 m over 2 lines: each line 12 m
    u = hook_at(m, -(L + 2.0 + d), payout=4.0)
    x = m.initial_state(u)
    assert m.output_values(0.0, x, u)[0] == pytest.approx(10e3, rel=1e-9)
    assert d > static_elongation(P, 10e3)  # softer


def test_kelvin_voigt_has_no_state_and_zero_hysteresis_output():
    m = RopeModel(RopeParams(length=L, n_lines=NL))
    u = hook_at(m, -(L + 0.01))
    assert m.initial_state(u).size == 0 and m.state_names() == ()
    assert m.output_values(0.0, np.zeros(0), u)[11] == 0.0


@pytest.mark.parametrize("change,name", [(dict(gamma=100.0), "rope.gamma"), (dict(beta=5.0, gamma=-10.0), "rope.gamma"),
                                         (dict(n=0.5), "rope.n"), (dict(alpha=0.0), "rope.alpha"),
                                         (dict(k1=-1.0), "rope.k1")])
def test_inadmissible_bouc_wen_sets_are_refused(change, name):
    with pytest.raises(ParameterError, match=name):
        RopeParams(model="bouc_wen", **change)
    if "gamma" in change:  # the admissibility of the loop only matters when the law is used
        RopeParams(model="kelvin_voigt", **change)


# --- regimes for event-located solvers (cranefmu.analysis.reference) -------------------------------------

def _states_in_each_regime():
    """(regime, z, hook y, hook vy) samples inside each regime's domain of the unpinned law."""
    bw = RopeModel(P).bouc_wen_at(L)
    out = []
    for d in (1e-4, 1e-3, 2e-3):
        delta = (L + d) - L                                # as the geometry computes it
        zl = -boucwen.elastic_force(delta, bw)            # the zero-force line
        assert zl > -boucwen.z_bound(bw)                   # reachable: inside the band |z| <= z_u
        for z, vy in ((0.5 * boucwen.virgin_z(delta, bw), 0.3), (0.5 * boucwen.virgin_z(delta, bw), -0.3),
                      (zl + 50.0, -0.2)):
            out.append(("taut", z, -(L + delta), vy))
        out.append(("on_line", zl, -(L + delta), 0.2))    # vy > 0: the hook rises, the rope unloads
        out.append(("slack", 0.0, -(L - delta), 0.4))
    return out


@pytest.mark.parametrize("model", ["bouc_wen", "kelvin_voigt"])
def test_pinned_regime_equations_are_the_law_on_its_domain(model):
    """The monolith integrates each regime's equations between located switches: on the regime's own
    domain they must be exactly what the FMU's unpinned law computes."""
    m = RopeModel(RopeParams(model=model, length=L, n_lines=NL))
    for regime, z, y, vy in _states_in_each_regime():
        if model == "kelvin_voigt" and regime == "on_line":
            continue
        u = hook_at(m, y, vy)
        x = np.array([z]) if model == "bouc_wen" else np.zeros(0)
        m.pin(None)
        assert m.regime(x, u) == regime
        free = (m.derivatives(0.0, x, u), m.output_values(0.0, x, u))
        m.pin(regime)
        pinned = (m.derivatives(0.0, x, u), m.output_values(0.0, x, u))
        assert pinned[0] == pytest.approx(free[0], rel=1e-12, abs=1e-9)
        assert pinned[1] == pytest.approx(free[1], rel=1e-12, abs=1e-9)
        # no switching function has crossed into its firing side inside the domain
        for g, direction, _ in m.regime_events(x, u):
            assert g * direction < 0.0


def test_regime_entry_resets_are_the_projection_of_the_fmu():
    m = RopeModel(P)
    bw = m.bouc_wen_at(L)
    for delta, z in ((-1e-3, -25.0), (2e-3, -boucwen.elastic_force(2e-3, bw) - 40.0)):
        u = hook_at(m, -(L + delta), 0.1)
        regime = "slack" if delta < 0 else "on_line"
        assert m.enter(regime, np.array([z]), u) == pytest.approx(m.after_step(0.0, np.array([z]), u), abs=1e-9)
        assert m.pinned == regime
    with pytest.raises(ValueError, match="on_line"):
        RopeModel(RopeParams(length=L)).pin("on_line")


# --- through the built FMU (fmpy, in a child process) ------------------------------------------

def _fmu_bouc_wen_run() -> dict:
    from cranefmu_support.fmu_child import session

    load = 20e3
    d = static_elongation(P, load)
    names = ["tension", "elongation", "z_hysteresis", "slack"]
    h, amp, w = 1e-3, 6e-3 + d, 2.0 * math.pi
    with session() as open_fmu:
        rope = open_fmu("Rope")
        rope.start(dict(model="bouc_wen", length=L, n_lines=NL), dict(y_hook=-(L + d)))
        rows = [rope.get(names)]
        t = 0.0
        for k in range(200):  # at rest
            rope.fmu.doStep(t, h)
            t += h
            rows.append(rope.get(names))
        # from the static point: 6 mm up (slack at the top of the stroke) and down again, twice
        for k in range(2001):
            s = k * h
            rope.set(dict(y_hook=-(L + d) + amp * 0.5 * (1.0 - math.cos(w * s)),
                          vy_hook=amp * 0.5 * w * math.sin(w * s)))
            rope.fmu.doStep(t, h)
            t += h
            rows.append(rope.get(names))
        return dict(rows=np.array(rows), d=d, load=load)


def test_bouc_wen_rope_fmu_rest_loops_and_slack(built):
    from cranefmu_support.fmu_child import in_child

    res = in_child(_fmu_bouc_wen_run)
    rows, load = res["rows"], res["load"]
    tension, delta, z, slack = rows.T
    assert tension[0] == pytest.approx(load, rel=1e-9)
    assert np.all(tension[:201] == tension[0]) and np.all(z[:201] == z[0])   # at rest stays at rest
    moving = rows[201:]
    bw = RopeModel(P).bouc_wen_at(L)
    # the FMU's z follows the path integration of eq. 1 along the same elongations (ZOH error O(h))
    _, f_path = boucwen.simulate_path(np.concatenate([[delta[200]], moving[:, 1]]), bw, z0=z[200])
    assert np.max(np.abs(moving[:, 0] - f_path[1:])) < 0.01 * load
    assert np.all(np.abs(z) <= boucwen.z_bound(bw) * (1 + 1e-6))
    # slack at the top of each stroke: no force, flag set, z back to the virgin state
    loose = moving[:, 1] < 0.0
    assert loose.any() and np.all(moving[loose, 0] == 0.0) and np.all(moving[loose, 3] == 1.0)
    assert np.all(moving[loose, 2] == 0.0)
    # re-tightened: back at the start elongation, back on the static load (virgin curve)
    assert moving[-1, 1] == pytest.approx(delta[0], abs=1e-9)
    assert moving[-1, 0] == pytest.approx(load, rel=5e-3)
    # the second cycle dissipates: the work done on the rope around the closed path is positive
    second = moving[1000:]
    work = np.trapezoid(second[:, 0], second[:, 1])
    assert work > 0.0
