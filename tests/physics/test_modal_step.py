"""The Chassis' exact step with the boom's inertia carried, by its two modes (cranefmu.physics.modal_step):
the same state as the matrix exponential of the augmented system to round-off, through under-, critically
and overdamped modes, and no matrix exponential per step while the carried inertia changes."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu.physics import chassis as chassis_module
from cranefmu.physics.chassis import ChassisModel, ChassisParams
from cranefmu.physics.linear_step import LinearPropagator
from cranefmu.physics.modal_step import TwoModes


def _augmented_state(m, k, r, q, v, f, s):
    """(q, q') at s by expm of Van Loan's augmented matrix (linear_step): the reference."""
    minv = np.linalg.inv(m)
    a = np.zeros((4, 4))
    a[0, 2] = a[1, 3] = 1.0
    a[2:, :2] = -minv @ k
    a[2:, 2:] = -r * minv @ k
    big_b = np.zeros((4, 2))
    big_b[2:] = minv
    lin = LinearPropagator(a, np.zeros(4), big_b)
    z = lin.augment(np.concatenate((q, v)), *f)
    return lin.maps(s)[-1] @ z, np.abs(lin.maps(s)[-1] * z).sum(axis=1)


@pytest.mark.parametrize("r", [0.0, 0.004, 0.05, 1.0])   # undamped .. overdamped modes
def test_two_modes_give_the_matrix_exponential_state(r):
    rng = np.random.default_rng(int(r * 1000))
    for _ in range(20):
        b = rng.normal(size=(2, 2))
        m = b @ b.T + np.diag(rng.uniform(0.1, 2.0, 2))
        m *= 10.0 ** rng.uniform(3, 5)
        b = rng.normal(size=(2, 2))
        k = (b @ b.T + np.diag(rng.uniform(0.1, 2.0, 2))) * 10.0 ** rng.uniform(6, 8)
        q, v = rng.normal(size=2) * 1e-3, rng.normal(size=2) * 1e-2
        f = [rng.normal(size=2) * 1e5, rng.normal(size=2) * 1e6, rng.normal(size=2) * 1e7]
        s = float(10.0 ** rng.uniform(-4, -2))
        modes = TwoModes(m[0, 0], m[0, 1], m[1, 1], k[0, 0], k[0, 1], k[1, 1], r)
        got = np.array(modes.state(modes.prepare(tuple(q), tuple(v), *map(tuple, f)), s))
        want, terms = _augmented_state(m, k, r, q, v, f, s)
        assert np.all(np.abs(got - want) <= 1e-11 * terms), (got, want)
        eig = np.linalg.eigvals(LinearPropagator(np.block([[np.zeros((2, 2)), np.eye(2)],
                                                           [-np.linalg.solve(m, k), -r * np.linalg.solve(m, k)]]),
                                                 np.zeros(4), np.zeros((4, 1))).generator[:4, :4])
        assert modes.spectral_radius() == pytest.approx(np.max(np.abs(eig)), rel=1e-7)


def test_critical_damping_has_no_zero_over_zero():
    # one mode exactly critical: lambda = 4 / r^2 (beta^2 / 4 = lambda)
    modes = TwoModes(1.0, 0.0, 1.0, 4.0, 0.0, 9.0, 1.0)
    prepared = modes.prepare((1.0, 1.0), (0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (0.0, 0.0))
    q1 = modes.state(prepared, 0.5)[0]
    assert q1 == pytest.approx((1.0 + 2.0 * 0.5) * np.exp(-2.0 * 0.5), rel=1e-14)   # (1 + w t) e^(-w t)


def _carried_inputs(rng):
    return np.array([rng.normal() * 1e3, -2e4 + rng.normal() * 1e3, -5e4 + rng.normal() * 1e4,
                     2000.0, 8000.0 + rng.normal() * 10.0, 6e4 + rng.normal() * 100.0])


def test_carried_step_equals_the_matrix_exponential_step_of_the_same_mass_matrix():
    rng = np.random.default_rng(1)
    p = ChassisParams(boom_inertia="carried")
    for _ in range(10):
        u = _carried_inputs(rng)
        r1 = np.concatenate((rng.normal(size=3) * [1e3, 1e4, 1e4], np.zeros(3)))
        r2 = np.concatenate((rng.normal(size=3) * [1e4, 1e5, 1e5], np.zeros(3)))
        model = ChassisModel(p)
        x = model.initial_state(u) + rng.normal(size=4) * [1e-6, 1e-7, 1e-4, 1e-4]
        got = model.exact_step(0.0, x, 0.005, u, r1, r2, 1e-3)
        model.carry(u)   # the mass matrix with the boom, then the expm path of the neglected inertia
        lin = LinearPropagator(*model.linear_system())
        z = np.concatenate((x, [1.0], u[:3], r1[:3], r2[:3]))
        want = lin.maps(0.005)[-1] @ z
        terms = np.abs(lin.maps(0.005)[-1] * z).sum(axis=1)
        assert np.all(np.abs(got - want) <= 1e-12 * terms), (got, want)


def test_carried_step_is_refused_at_lift_off():
    p = ChassisParams(boom_inertia="carried")
    u = _carried_inputs(np.random.default_rng(2))
    model = ChassisModel(p)
    x = model.initial_state(u) + np.array([0.0, 0.0, 0.3, 0.0])   # rising at 0.3 m/s: the pads unload
    assert model.exact_step(0.0, x, 0.01, u, np.zeros(6), np.zeros(6), 1e-3) is None


def test_a_telescoping_boom_builds_no_matrix_exponential_per_step(monkeypatch):
    """Regression (issue 33): with the carried inertia changing at every step (telescoping; S cos psi follows
    the tilt) the chassis built a LinearPropagator and a scipy expm per step: 393 us of CPU, 1.7 ms with
    OpenBLAS' threads (benchmarks/chassis_carried_step.py)."""
    built = []
    original = LinearPropagator.__init__

    def counting(self, *args, **kwargs):
        built.append(1)
        original(self, *args, **kwargs)

    monkeypatch.setattr(chassis_module.LinearPropagator, "__init__", counting)
    model = ChassisModel(ChassisParams(boom_inertia="carried"))
    rng = np.random.default_rng(3)
    u = _carried_inputs(rng)
    x = model.initial_state(u)
    for i in range(50):
        u = u.copy()
        u[4] += 1.0     # Sx_boom and J_boom grow as the boom telescopes
        u[5] += 30.0
        x = model.exact_step(0.005 * i, x, 0.005, u, np.zeros(6), np.zeros(6), 1e-3)
        assert x is not None
    assert built == []
