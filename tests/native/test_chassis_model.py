"""The native Chassis (native/models/Chassis.c) against its Python twin (cranefmu.physics.chassis), called
directly through the cffi harness: derivatives, outputs, initial state (also tipping and lifted-off
states) and the parameter check to 1e-12 relative (measured: bitwise equal); the exact step to the
tolerance of its matrix exponential (boom inertia neglected) or bitwise (carried: the two modes, plain libm
arithmetic as Python's), its refusal at lift-off, and a fine rk4 reference."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu.native.harness import load
from cranefmu.physics.chassis import ChassisModel, ChassisParams
from cranefmu.physics.linear_step import LinearPropagator, step_key
from cranefmu.physics.params import ParameterError

from structural_cases import random_params, reference_expm, relative_error, rk4_reference

pytest.importorskip("cffi")

#: as test_girder_model: both exponentials within 1e-14 max(1, omega h) of the exact one (measured)
EXPM_TOLERANCE = 1e-14


def random_chassis(rng, boom_inertia) -> ChassisParams:
    v = random_params(ChassisParams, rng, boom_inertia=boom_inertia)
    v["x_slew"] = float(rng.uniform(0.0, v["outrigger_base"]))
    v["h_foot"] *= 3.0
    return ChassisParams(**v)


def random_inputs(rng, scale=1.0):
    loads = rng.normal(size=3) * [1e4, 3e4, 1e5] * scale
    carried = rng.uniform(0.0, 1.0, 3) * [5e3, 2e4, 1e5]
    return np.concatenate((loads, carried))


def cases(seed, n=10):
    rng = np.random.default_rng(seed)
    for i in range(n):
        yield rng, random_chassis(rng, ("neglected", "carried")[i % 2])


def assert_close(got, want, rtol=1e-12):
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    assert np.all(np.abs(got - want) <= rtol * np.abs(want)), (got, want)


def test_derivatives_outputs_and_initial_state_agree_in_contact_lifted_and_tipping():
    lifted = tipped = 0
    for rng, p in cases(0, 20):
        nat, py = load("Chassis", p), ChassisModel(p)
        for scale in (1.0, 30.0):   # 30x the loads: the resultant outside the base, pads lifting
            u = random_inputs(rng, scale)
            x0 = nat.initial_state(u)
            assert_close(x0, py.initial_state(u))
            for x in (x0, x0 + rng.normal(size=4) * [1e-3, 1e-3, 1e-2, 1e-2]):
                t = float(rng.uniform(0.0, 5.0))
                assert_close(nat.derivatives(t, x, u), py.derivatives(t, x, u))
                y = nat.outputs(t, x, u)
                assert_close(y, py.output_list(t, x, u))
                lifted += y[-1] == 1.0
            tipped += nat.initial_state(u)[0] != 0.0 and min(py.static_reactions(u)) < 0.0
        assert [nat.state_name(i) for i in range(4)] == list(py.state_names())
    assert lifted > 0 and tipped > 0   # the event cases were reached


def test_no_load_starts_at_rest():
    p = ChassisParams()
    u = np.array([0.0, 1e7, 0.0, 0.0, 0.0, 0.0])   # the boom lifts more than the chassis weighs
    assert np.array_equal(load("Chassis", p).initial_state(u), np.zeros(4))


def test_the_slewing_centre_check_says_what_python_says():
    for x_slew, base in ((-0.1, 3.08), (3.5, 3.08), (5e-5, 1e-5)):
        with pytest.raises(ParameterError) as err:
            ChassisParams(x_slew=x_slew, outrigger_base=base)
        p = ChassisParams(x_slew=0.0, outrigger_base=base)
        object.__setattr__(p, "x_slew", x_slew)
        with pytest.raises(ValueError) as native_err:
            load("Chassis", p)
        assert str(native_err.value) == str(err.value)


def _step_both(nat, py, x, h, u0, r1, r2, max_step):
    return nat.exact_step(0.0, x, h, u0, r1, r2, max_step), py.exact_step(0.0, x, h, u0, r1, r2, max_step)


def test_exact_step_agrees_with_python_and_the_exact_exponential_in_contact():
    taken = 0
    for rng, p in cases(1, 12):
        nat, py = load("Chassis", p), ChassisModel(p)
        py.prepare_exact_step()
        for h, max_step in ((2e-3, 1e-3), (5e-3, 5e-3), (float(10 ** rng.uniform(-4, -1.5)), 1e-3)):
            u0 = random_inputs(rng)
            r1, r2 = random_inputs(rng) * 10.0, random_inputs(rng) * 100.0
            x = py.initial_state(u0) + rng.normal(size=4) * [1e-6, 1e-7, 1e-5, 1e-5]
            c, y = _step_both(nat, py, x, h, u0, r1, r2, max_step)
            assert (c is None) == (y is None)
            if c is None:
                continue
            taken += 1
            # the same bits: carried, both through the two modes operation by operation; neglected, both through
            # the exponential and the products in one order (cranefmu.physics.expm, cf_linear_step.c; before
            # issue 33's change scipy's expm and numpy's products were ~1e-16 of the summed terms away)
            assert np.array_equal(c, y), (p.boom_inertia, h, c - y)
            z = np.concatenate((x, [1.0], u0[:3], r1[:3], r2[:3]))
            py.carry(u0)   # the generator of the mass matrix in use (with the boom carried)
            generator = LinearPropagator(*py.linear_system()).generator
            ref = reference_expm(generator * step_key(h))[:4]
            exact = (ref @ z.astype(np.longdouble)).astype(float)
            terms = np.abs(ref.astype(float) * z).sum(axis=1)
            bound = EXPM_TOLERANCE * max(1.0, LinearPropagator(*py.linear_system()).spectral_radius * h)
            assert np.all(np.abs(c - exact) <= bound * terms)
    assert taken >= 20


def test_exact_step_is_refused_where_a_pad_lifts_off_as_in_python():
    refused = 0
    for rng, p in cases(2, 10):
        nat, py = load("Chassis", p), ChassisModel(p)
        u0 = random_inputs(rng)
        x = py.initial_state(u0)
        x = x + np.array([0.0, 0.0, 0.3, 0.0])   # O2 rising at 0.3 m/s: the pads unload within the step
        zero = np.zeros(6)
        c, y = _step_both(nat, py, x, 0.01, u0, zero, zero, 1e-3)
        assert c is None and y is None
        refused += 1
        x = py.initial_state(u0) + np.array([0.01, 0.0, 0.0, 0.0])   # both pads in the air
        assert nat.exact_step(0.0, x, 1e-3, u0, zero, zero, 1e-3) is None
    assert refused == 10


def test_exact_step_matches_a_fine_rk4_reference():
    taken = 0
    for rng, p in cases(3, 8):
        nat, py = load("Chassis", p), ChassisModel(p)
        u0 = random_inputs(rng)
        r1, r2 = random_inputs(rng) * 10.0, np.zeros(6)
        r1[3:] = 0.0   # the carried inertia held (the exact step takes it at the step's start)
        x = py.initial_state(u0)
        c = nat.exact_step(0.0, x, 2e-3, u0, r1, r2, 1e-3)
        assert (c is None) == (py.exact_step(0.0, x, 2e-3, u0, r1, r2, 1e-3) is None)
        if c is None:   # a pad unloads within the step (the loads drawn tip this chassis)
            continue
        taken += 1
        ref = rk4_reference(py.derivatives, x, 2e-3, u0, r1, r2, n=400)
        assert relative_error(c, ref) < 1e-9
    assert taken >= 3


def test_a_new_carried_inertia_rebuilds_the_propagator():
    rng = np.random.default_rng(5)
    p = random_chassis(rng, "carried")
    nat = load("Chassis", p)
    u_a, u_b = random_inputs(rng), random_inputs(rng)
    u_b[:3] = u_a[:3]
    x = ChassisModel(p).initial_state(u_a)
    zero = np.zeros(6)
    a1 = nat.exact_step(0.0, x, 2e-3, u_a, zero, zero, 1e-3)
    b1 = nat.exact_step(0.0, x, 2e-3, u_b, zero, zero, 1e-3)
    a2 = nat.exact_step(0.0, x, 2e-3, u_a, zero, zero, 1e-3)
    fresh = load("Chassis", p).exact_step(0.0, x, 2e-3, u_b, zero, zero, 1e-3)
    assert not np.array_equal(a1, b1) and np.array_equal(a1, a2) and np.array_equal(b1, fresh)
