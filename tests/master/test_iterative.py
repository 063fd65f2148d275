"""Iterative (strong) coupling: converges where Jacobi is unstable, IQN-ILS faster than Aitken,
the coupling satisfied at every communication point, energy error bounded (no drift), and a clear
report when it does not converge."""
import numpy as np
import pytest

from cranefmu.errors import SimulationError
from cranefmu.master.run import run
from cranefmu_support.oscillator.runs import DAMPED, UNDAMPED, X0, Z0, go, jacobi_limit


def error(res, osc):
    exact = osc.solution(res["time"], Z0)
    return np.max(np.abs(res["mass.x"] - exact[:, 0]))


def test_converges_beyond_the_jacobi_stability_limit(oscillator_ssp):
    h1, h2 = 1.7 * jacobi_limit(), 1.15 * jacobi_limit()
    jac = go(oscillator_ssp, h1, DAMPED, stop=60 * h1, instability_alarm=False).result
    amp = np.abs(jac["mass.x"])
    assert amp[-15:].max() > amp[:15].max()              # Jacobi grows at h1
    it1 = go(oscillator_ssp, h1, DAMPED, algorithm="iterative", extrapolation=2)
    it2 = go(oscillator_ssp, h2, DAMPED, algorithm="iterative", extrapolation=2)
    assert it1.stats.iterations / it1.stats.steps < 5   # IQN-ILS, reusing past steps
    e1, e2 = error(it1.result, DAMPED), error(it2.result, DAMPED)
    # degree-2 interpolation of the inputs: third order in H, measured 2.6 between these steps
    assert np.log(e1 / e2) / np.log(h1 / h2) > 2.3
    assert e1 < 0.15 * X0


def test_iqn_ils_needs_fewer_iterations_than_aitken(oscillator_ssp):
    h = 1.5 * jacobi_limit()
    iqn = go(oscillator_ssp, h, DAMPED, algorithm="iterative", extrapolation=2, accelerator="iqn-ils").stats
    ait = go(oscillator_ssp, h, DAMPED, algorithm="iterative", extrapolation=2, accelerator="aitken").stats
    assert iqn.iterations < 0.5 * ait.iterations
    assert iqn.iterations / iqn.steps < 4.0


def test_undamped_energy_error_is_bounded_and_second_order(oscillator_ssp):
    """Linear interpolation (extrapolation=1): the energy error oscillates, it does not drift, and
    falls as H^2; Jacobi ZOH at the same step gains energy without bound."""
    errs = []
    for h in (0.02, 0.01):
        r = go(oscillator_ssp, h, UNDAMPED, stop=5.0, algorithm="iterative", extrapolation=1).result
        z = np.column_stack([r["mass.x"], r["mass.v"], r["spring.x"], r["spring.v"]])
        e = UNDAMPED.energy(z)
        errs.append(np.max(np.abs(e - e[0])) / e[0])
        half = len(e) // 2
        assert np.max(np.abs(e[half:] - e[0])) < 1.5 * np.max(np.abs(e[:half] - e[0]))   # no drift
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.25)
    assert errs[1] < 2e-3
    jac = go(oscillator_ssp, 0.01, UNDAMPED, stop=5.0).result
    zj = np.column_stack([jac["mass.x"], jac["mass.v"], jac["spring.x"], jac["spring.v"]])
    assert UNDAMPED.energy(zj)[-1] > 10 * UNDAMPED.energy(zj)[0]


def test_a_step_the_fixed_point_fails_is_solved_by_newton(oscillator_ssp):
    """Plain fixed-point steps (no acceleration) cannot converge in 3 iterations at 0.15 s; Newton's
    method (master/newton.py) then solves the same fixed point: the run equals the IQN-ILS one to the
    coupling tolerance (1e-8 of the values' size; measured 3e-9 of the amplitude)."""
    plain = go(oscillator_ssp, 0.15, DAMPED, algorithm="iterative", accelerator="none", max_iterations=3).result
    iqn = go(oscillator_ssp, 0.15, DAMPED, algorithm="iterative").result
    assert np.max(np.abs(plain["mass.x"] - iqn["mass.x"])) < 1e-7 * X0


def test_non_convergence_is_reported_with_connection_time_and_advice():
    """With the rescue off (and where Newton fails too: its own message is the same)."""
    from cranefmu.master.algorithms import Iterative
    algo = Iterative(_StallingCoupling(1.5), degree=0, tolerance=1e-8, max_iterations=3, accelerator="none",
                     rescue=False)
    with pytest.raises(SimulationError) as info:
        algo.step(0.0, 0.15, None)
    msg = str(info.value)
    assert "did not converge" in msg and "t = 0 s" in msg and "after 3 iterations" in msg
    assert "->" in msg and "smaller --step" in msg


class _StallingCoupling:
    """One coupling value whose fixed-point map u -> 2 - u never contracts: fed u, the 'FMUs'
    return 2 - u.  Undamped fixed-point steps cycle between u0 and 2 - u0 forever (a stall).
    A stand-in for :class:`~cranefmu.master.coupled.Coupling`: the operations Iterative uses."""

    names = ["a.y -> b.u"]

    def __init__(self, u0: float):
        self.u0, self.fed, self.out = u0, None, None
        self.value = np.array([u0])
        self.steps = 0

    def nominals(self, part=None):
        return np.array([np.nan])

    def sizes(self, part=None):
        return np.array([abs(self.u0)])

    def predict(self, t, h, order=None):
        return np.array([self.u0])

    def values(self, part=None):
        return self.value

    def restore(self, snapshot):
        pass

    def feed(self, t, h, u, degree, part=None):
        self.fed = np.array(u, dtype=float)

    def step(self, t, h, members=None, ends=True):
        self.out = 2.0 - self.fed
        self.steps += 1

    def image(self, part=None, fed_through_only=False):
        return self.out

    def evaluate(self, t, h, u, degree, part=None, members=None, fed_through_only=False):
        self.feed(t, h, u, degree, part)
        self.step(t, h, members)
        return self.image(part, fed_through_only)

    def commit(self, t):
        self.value = self.out


def test_a_stalled_iteration_is_refused_not_accepted():
    """Regression: the step was accepted after a stall when residual * tolerance <= 1e-8, i.e. with
    the value still changing by up to 100 % at tolerance 1e-8.  Here every iterate changes by
    |2 - 2 u0| / u0 = 2/3 of its size: the step must be refused."""
    from cranefmu.master.algorithms import Iterative
    system = _StallingCoupling(1.5)
    algo = Iterative(system, degree=0, tolerance=1e-8, max_iterations=20, accelerator="none", rescue=False)
    with pytest.raises(SimulationError) as info:
        algo.step(0.0, 0.1, None)
    assert system.steps == 20                      # every iteration was tried, none accepted
    assert "after 20 iterations" in str(info.value) and "0.667 relative" in str(info.value)


def test_the_stalled_map_is_solved_by_newton_when_the_rescue_is_on():
    """The same map, the rescue on: 20 plain iterations stall, then Newton's method (its Jacobian -1 from
    one perturbed step) lands on the fixed point u = 1."""
    from cranefmu.master.algorithms import Iterative
    system = _StallingCoupling(1.5)
    algo = Iterative(system, degree=0, tolerance=1e-8, max_iterations=20, accelerator="none")
    h, k = algo.step(0.0, 0.1, None)
    assert h == 0.1 and k > 20 and algo.newton is not None
    assert system.values()[0] == pytest.approx(1.0, abs=1.5e-8)


def test_the_same_map_relaxed_converges_to_its_fixed_point():
    """The map of the regression test has the fixed point u = 1: relaxed (Aitken), the step is
    accepted there, to the tolerance."""
    from cranefmu.master.algorithms import Iterative
    system = _StallingCoupling(1.5)
    algo = Iterative(system, degree=0, tolerance=1e-8, max_iterations=20, accelerator="aitken")
    h, k = algo.step(0.0, 0.1, None)
    assert h == 0.1 and k < 20
    assert system.values()[0] == pytest.approx(1.0, abs=1.5e-8)


def test_criterion_floor_follows_the_signal_range_not_the_tolerance():
    """|G(u) - u| <= tol * size + NOISE * range: a signal of size 100 that ranged over 100 may change by
    up to 1e-8 (the floor) even at tolerance 1e-12, but not by 1e-7; a signal that never moved has
    no floor."""
    from cranefmu.master.residual import CouplingCriterion
    crit = CouplingCriterion(1e-12, np.array([np.nan]))
    crit.start(np.array([100.0]))
    assert crit.floor[0] == 0.0
    size = np.array([100.0])
    assert crit.error(np.array([100.0]), np.array([100.0 + 5e-9]), size)[0] > 1.0
    crit.start(np.array([0.0]))
    assert crit.floor[0] == pytest.approx(100.0 * CouplingCriterion.NOISE)
    assert crit.error(np.array([100.0]), np.array([100.0 + 5e-9]), size)[0] < 1.0
    assert crit.error(np.array([100.0]), np.array([100.0 + 1e-7]), size)[0] > 1.0
    declared = CouplingCriterion(1e-12, np.array([1e3]))   # a nominal above the range wins
    declared.start(np.array([1.0]))
    declared.start(np.array([101.0]))
    assert declared.floor[0] == pytest.approx(1e3 * CouplingCriterion.NOISE)


# elastic_pendulum with a rope 1400 times stiffer (E = 1.4e14 Pa: c = E A / L = 7.9e8 N/m, axial
# omega = sqrt(c / m) = 890 rad/s), started at its radial equilibrium, which the scene derives at
# initialization from the rope's stiffness (docs/equilibrium.md).
STIFF = {"rope.E": 1.4e14}


def test_stiff_rope_iterative_matches_the_monolith_at_the_tolerance_level(built):
    """Strong coupling (linear interpolation, H = 1 ms: omega H = 0.89, inside the scheme's limit
    2 sqrt(3) of the linear-acceleration method it amounts to) runs through and follows the monolithic
    solve: swing and hook position to 1e-6 of their range (measured 7.5e-8 over 1 s), tension to 1e-8 of
    its size."""
    from cranefmu.analysis.reference import solve
    stop = 0.5
    res = run("elastic_pendulum", stop_time=stop, step_size=1e-3, algorithm="iterative", extrapolation=1,
              parameters=STIFF).result
    ref = solve("elastic_pendulum", stop, np.linspace(0.0, stop, 501), parameters=STIFF, rtol=1e-10)
    assert res["time"][-1] == pytest.approx(stop) and np.all(np.isfinite(res["rope.tension"]))
    for key in ("pendulum.theta", "pendulum.x", "pendulum.y"):
        err = np.max(np.abs(np.interp(ref["time"], res["time"], res[key]) - ref[key]))
        assert err < 1e-6 * np.ptp(ref[key]), key
    err = np.max(np.abs(np.interp(ref["time"], res["time"], res["rope.tension"]) - ref["rope.tension"]))
    assert err < 1e-8 * np.max(ref["rope.tension"])


def test_issue_stiff_rope_at_10_ms_runs_through_and_converges_first_order(built):
    """The issue's case (``--step 1e-2 --algorithm iterative --set rope.E=1.4e14``, extrapolation 0):
    the rope's axial mode (890 rad/s, omega H = 8.9) is beyond any explicit or linear-interpolation
    scheme (limit 2 sqrt(3)); degree 0 (the end value held over the step: implicit, L-stable) damps
    it instead of following it, and follows what H resolves, the swing (1 rad/s) and the quasi-static
    tension m g cos(theta) + m v^2 / L.  The error is then the scheme's, first order in H, not the
    coupling tolerance's: measured over 3 s against the monolith (rtol 1e-8), swing 6.71e-4 rad at
    H = 10 ms and 3.36e-4 at 5 ms (3.9e-3 and 1.9e-3 of its range), tension 0.804 N and 0.402 N
    (7.2e-3 and 3.6e-3 of its range, 8e-5 of m g); 5 s runs through as well (6.8e-4 rad, 1.8 N).
    Bound: omega H of the swing amplitude (8.7e-4 rad) and of the tension's range (1.1 N) at 10 ms;
    order: the error ratio between 10 and 5 ms within 2 +- 0.3."""
    from cranefmu.analysis.reference import solve
    stop = 3.0
    ref = solve("elastic_pendulum", stop, np.linspace(0.0, stop, 601), parameters=STIFF, rtol=1e-8)
    errors = {}
    for h in (1e-2, 5e-3):
        res = run("elastic_pendulum", stop_time=stop, step_size=h, algorithm="iterative", extrapolation=0,
                  parameters=STIFF).result
        assert res["time"][-1] == pytest.approx(stop) and np.all(np.isfinite(res["rope.tension"]))
        errors[h] = {key: np.max(np.abs(np.interp(ref["time"], res["time"], res[key]) - ref[key]))
                     for key in ("pendulum.theta", "rope.tension")}
    omega_h = 1.0 * 1e-2   # swing angular frequency sqrt(g / L) ~ 1 rad/s times H
    assert errors[1e-2]["pendulum.theta"] < omega_h * np.max(np.abs(ref["pendulum.theta"]))
    assert errors[1e-2]["rope.tension"] < omega_h * np.ptp(ref["rope.tension"])
    for key in ("pendulum.theta", "rope.tension"):
        assert errors[1e-2][key] / errors[5e-3][key] == pytest.approx(2.0, abs=0.3), key


def test_issue_stiff_rope_at_10_ms_runs_past_where_reused_secants_diverged(built):
    """Past t = 6.7 s, where IQN-ILS with the secants of the last 3 steps diverged (the rope's force
    turns with the swing, old secants model a map that is gone); degree 0 keeps none.  The first-order
    phase error grows with time: measured over 10 s 2.03e-3 rad of swing and 2.91 N of tension
    (3.3 times the 3 s values); bound: the 3 s bound (omega H of the amplitude, of the tension's
    range) times stop / 3 s."""
    from cranefmu.analysis.reference import solve
    stop = 10.0
    res = run("elastic_pendulum", stop_time=stop, step_size=1e-2, algorithm="iterative", extrapolation=0,
              parameters=STIFF)
    r = res.result
    assert r["time"][-1] == pytest.approx(stop) and np.all(np.isfinite(r["rope.tension"]))
    assert res.stats.max_iterations <= 10   # measured 6
    ref = solve("elastic_pendulum", stop, np.linspace(0.0, stop, 2001), parameters=STIFF, rtol=1e-8)
    growth = 1e-2 * stop / 3.0
    for key, size in (("pendulum.theta", np.max(np.abs(ref["pendulum.theta"]))),
                      ("rope.tension", np.ptp(ref["rope.tension"]))):
        err = np.max(np.abs(np.interp(ref["time"], r["time"], r[key]) - ref[key]))
        assert err < growth * size, key
