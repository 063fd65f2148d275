"""An algorithm is added with the coupling's public operations only (:class:`~cranefmu.master.coupled.Coupling`):
a damped fixed-point iteration defined here, registered by name, runs the two-mass oscillator and
shows the order of the scheme it is (an implicit zero-order hold: first order in H); one that retries
every step from a snapshot reproduces Jacobi bit for bit."""
import numpy as np
import pytest

from cranefmu.master import algorithm_table
from cranefmu.master.algorithms import Algorithm
from cranefmu.master.run import run
from cranefmu_support.oscillator.exact import Oscillator

OSC = Oscillator(d1=0.5, dc=2.0)          # omega = 7.0 and 15.8 rad/s, lightly damped
X0 = 0.1
STEPS = [2e-3, 2e-3 * 10 ** 0.5, 2e-2]     # a decade of H


class DampedFixedPoint(Algorithm):
    """Each step repeated from the snapshot with every input held at the iterate u (its end value);
    u <- u + omega (G(u) - u) until |G(u) - u| <= tolerance |u| (+ a floor)."""

    name = "damped-fixed-point"
    needs_snapshot = True

    def __init__(self, coupling, omega: float = 0.7, tolerance: float = 1e-10, max_iterations: int = 200):
        self.c, self.omega, self.tolerance, self.max_iterations = coupling, omega, tolerance, max_iterations

    def step(self, t, h, snapshot=None):
        c = self.c
        u = c.values()
        floor = 1e-12 * max(1.0, float(np.max(c.sizes(), initial=0.0)))
        for k in range(1, self.max_iterations + 1):
            if k > 1:
                c.restore(snapshot)
            c.feed(t, h, u, degree=0)
            c.step(t, h)
            gu = c.image()
            if np.all(np.abs(gu - u) <= self.tolerance * np.abs(u) + floor):
                c.commit(t + h)
                return h, k
            u = u + self.omega * (gu - u)
        raise AssertionError(f"no convergence at t = {t}")


@pytest.fixture
def registered(monkeypatch):
    monkeypatch.setitem(algorithm_table.ALGORITHMS, DampedFixedPoint.name, algorithm_table.Entry(DampedFixedPoint))


def test_a_new_algorithm_runs_a_scene_and_has_its_order(oscillator_ssp, registered):
    errors, iterations = [], []
    for h in STEPS:
        res = run(oscillator_ssp, stop_time=1.0, step_size=h, algorithm=DampedFixedPoint.name,
                  parameters={**OSC.parameters(), "mass.x0": X0})
        r = res.result
        exact = OSC.solution(r["time"], np.array([X0, 0.0, 0.0, 0.0]))
        errors.append(max(np.max(np.abs(r["mass.x"] - exact[:, 0])), np.max(np.abs(r["spring.x"] - exact[:, 2]))))
        iterations.append(res.stats.iterations / res.stats.steps)
    order = np.polyfit(np.log(STEPS), np.log(errors), 1)[0]
    assert order == pytest.approx(1.0, abs=0.3), errors
    assert errors[0] < 0.02 * X0
    assert min(iterations) > 2    # it did iterate (the loop counted what step() returned)


class RetriedJacobi(Algorithm):
    """Jacobi, but every step is taken, read, rolled back and taken again: through the coupling's
    snapshot, restore, image and commit, the run must be bit for bit plain Jacobi's."""

    name = "retried-jacobi"
    needs_snapshot = False

    def __init__(self, coupling):
        self.c, self.differences = coupling, 0

    def step(self, t, h, snapshot=None):
        c = self.c
        snap = c.snapshot()
        try:
            c.step(t, h)
            first = c.image()
            c.restore(snap)
            c.step(t, h)
            self.differences += int(not np.array_equal(first, c.image()))
        finally:
            c.release(snap)
        c.commit(t + h)
        return h, 2


def test_a_step_retried_from_a_snapshot_gives_jacobi_bit_for_bit(oscillator_ssp, monkeypatch):
    made = []
    monkeypatch.setattr(RetriedJacobi, "from_settings", classmethod(lambda cls, c, s: made.append(cls(c)) or made[-1]))
    monkeypatch.setitem(algorithm_table.ALGORITHMS, RetriedJacobi.name, algorithm_table.Entry(RetriedJacobi))
    kw = dict(stop_time=0.5, step_size=0.01, extrapolation=0, parameters={**OSC.parameters(), "mass.x0": X0})
    retried = run(oscillator_ssp, algorithm=RetriedJacobi.name, **kw)
    plain = run(oscillator_ssp, algorithm="jacobi", **kw)
    assert made[0].differences == 0 and retried.stats.iterations == 2 * retried.stats.steps == 100
    for name in plain.result.dtype.names:
        assert np.array_equal(retried.result[name], plain.result[name]), name
