"""The native Girder (native/models/Girder.c) against its Python twin (cranefmu.physics.girder), called
directly through the cffi harness: derivatives, outputs, initial state and parameter checks to 1e-12
relative; the exact step (scipy's matrix exponential algorithm, in C and in cranefmu.physics.expm in one order
of operations) bit for bit, and to the tolerance measured against an extended-precision exponential and a fine
rk4 reference."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from cranefmu.native.harness import load
from cranefmu.physics.girder import GirderModel, GirderParams
from cranefmu.physics.linear_step import step_key
from cranefmu.physics.params import ParameterError

from structural_cases import random_params, reference_expm, relative_error, rk4_reference

pytest.importorskip("cffi")

SWITCHES = list(itertools.product(("elastic", "rigid"), ("table", "decrement"), ("table", "beam")))
#: measured (benchmarks/results/native_exact_step.md, 60 random cases, omega h up to 85): C within 1e-14 and
#: scipy within 4.7e-14 of the summed terms of the exact map, growing with omega h (the squarings)
EXPM_TOLERANCE = 1e-14


def random_girder(rng, bearing, damping, mass) -> GirderParams:
    v = random_params(GirderParams, rng, bearing=bearing, damping_model=damping, mass_model=mass)
    if mass == "beam":
        v["m1"] = 5000.0
    if damping == "decrement":
        v["girder_height"] = max(v["girder_height"], 0.05 * v["span"])
    v["b3"] *= 1e4
    return GirderParams(**v)


def cases(seed=0, per_switch=4):
    rng = np.random.default_rng(seed)
    for switches in SWITCHES:
        for _ in range(per_switch):
            yield rng, random_girder(rng, *switches)


def random_io(rng):
    x = rng.normal(size=4) * [1e-2, 1e-1, 1e-2, 1e-1]
    u0, r1, r2 = rng.normal(size=3) * 3e4, rng.normal(size=3) * 1e5, rng.normal(size=3) * 1e6
    return x, u0, r1, r2


def assert_close(got, want, rtol=1e-12):
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    assert np.all(np.abs(got - want) <= rtol * np.maximum(np.abs(want), 1e-300) + 0.0), (got, want)


def test_derivatives_outputs_and_initial_state_agree():
    for rng, p in cases():
        nat, py = load("Girder", p), GirderModel(p)
        assert nat.m.n_states == 4
        for _ in range(5):
            x, u, _, _ = random_io(rng)
            t = float(rng.uniform(0, 10))
            assert_close(nat.derivatives(t, x, u), py.derivatives(t, x, u))
            assert_close(nat.outputs(t, x, u), py.output_list(t, x, u))
            assert_close(nat.initial_state(u), py.initial_state(u))
            assert_close(nat.after_step(t, x, u), py.after_step(t, x, u))
        assert not nat.frozen() and nat.exact_applies()
        assert [nat.state_name(i) for i in range(4)] == list(py.state_names())


def test_cross_field_checks_say_what_python_says():
    bad = [dict(mass_model="beam", m1=4999.5),
           dict(damping_model="decrement", girder_height=0.05, span=20.0),
           dict(damping_model="decrement", girder_height=1e-5, span=33.3)]
    for fields in bad:
        with pytest.raises(ParameterError) as err:
            GirderParams(**fields)
        p = GirderParams(**{**fields, **dict(mass_model="table", damping_model="table")})
        object.__setattr__(p, "mass_model", fields.get("mass_model", "table"))
        object.__setattr__(p, "damping_model", fields.get("damping_model", "table"))
        with pytest.raises(ValueError) as native_err:
            load("Girder", p)
        assert str(native_err.value) == str(err.value)


def test_exact_step_agrees_with_python_bit_for_bit_and_with_the_exact_exponential():
    checked = 0
    for rng, p in cases(seed=1):
        nat, py = load("Girder", p), GirderModel(p)
        py.prepare_exact_step()
        for h in (1e-3, float(10 ** rng.uniform(-4, -1))):
            x, u0, r1, r2 = random_io(rng)
            c = nat.exact_step(0.0, x, h, u0, r1, r2, 1e-3)
            y = py.exact_step(0.0, x, h, u0, r1, r2, 1e-3)
            z = np.concatenate((x, [1.0], u0, r1, r2))
            ref = reference_expm(py._linear.generator * step_key(h))[:4]
            exact = (ref @ z.astype(np.longdouble)).astype(float)
            terms = np.abs(ref.astype(float) * z).sum(axis=1)   # the size of what the map sums
            bound = EXPM_TOLERANCE * max(1.0, py._linear.spectral_radius * h)
            assert np.all(np.abs(c - exact) <= bound * terms), (p, h)
            assert np.all(np.abs(y - exact) <= bound * terms), (p, h)
            # the same bits: Python's exponential and products in C's order (cranefmu.physics.expm); before,
            # scipy's expm and numpy's BLAS product were up to ~1e-15 of the summed terms away from C's
            assert np.array_equal(c, y), (p, h, c - y)
            checked += 1
    assert checked == 2 * len(SWITCHES) * 4


def test_exact_step_matches_a_fine_rk4_reference():
    for rng, p in cases(seed=2, per_switch=1):
        nat, py = load("Girder", p), GirderModel(p)
        h = 2e-3
        x, u0, r1, r2 = random_io(rng)
        ref = rk4_reference(py.derivatives, x, h, u0, r1, r2, n=400)
        assert relative_error(nat.exact_step(0.0, x, h, u0, r1, r2, 1e-3), ref) < 1e-9


def test_the_cache_of_two_step_sizes_gives_what_a_fresh_model_gives():
    rng = np.random.default_rng(3)
    p = random_girder(rng, "elastic", "table", "table")
    cached = load("Girder", p)
    x, u0, r1, r2 = random_io(rng)
    t, h = 0.3, 0.002
    h_again = (t + h) - t   # what a fixed-step master passes: h in its last bits
    assert h_again != h and step_key(h_again) == h
    for step in (h, 0.005, h_again, 0.001, 0.005, h, 0.007, 0.001):
        fresh = load("Girder", p)
        assert np.array_equal(cached.exact_step(0.0, x, step, u0, r1, r2, 1e-3),
                              fresh.exact_step(0.0, x, step, u0, r1, r2, 1e-3))


def test_rigid_bearing_keeps_the_drum_on_the_girder():
    rng = np.random.default_rng(4)
    p = random_girder(rng, "rigid", "table", "table")
    nat = load("Girder", p)
    x = nat.initial_state(np.array([0.0, 2e4, 0.0]))
    assert x[0] == x[2]
    x1 = nat.exact_step(0.0, x, 0.01, np.array([0.0, 4e4, 0.0]), np.zeros(3), np.zeros(3), 1e-3)
    assert x1[0] == pytest.approx(x1[2], rel=1e-13) and x1[1] == pytest.approx(x1[3], rel=1e-13)
