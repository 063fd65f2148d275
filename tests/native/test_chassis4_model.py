"""The native Chassis4 (native/models/Chassis4.c) against its Python twin (cranefmu.physics.chassis4), called
directly through the cffi harness: derivatives and outputs (pads in contact, a pad lifting, tipping) and the
initial statics (four pads, three, the tipping rest) to 1e-12 relative, and the parameter checks."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu.native.harness import load
from cranefmu.physics.chassis4 import Chassis4Model, Chassis4Params
from cranefmu.physics.params import ParameterError

from structural_cases import random_params

pytest.importorskip("cffi")


def random_chassis4(rng, boom_inertia) -> Chassis4Params:
    v = random_params(Chassis4Params, rng, boom_inertia=boom_inertia, pads_per_outrigger=2)
    v["x_slew"] = float(rng.uniform(0.0, v["outrigger_base"]))
    v["h_foot"] *= 3.0
    return Chassis4Params(**v)


def random_inputs(rng, scale=1.0):
    loads = rng.normal(size=5) * [1e4, 3e4, 1e4, 1e5, 1e5] * scale
    carried = np.concatenate((rng.uniform(0.0, 1.0, 1) * 5e3, rng.normal(size=2) * 1e4,
                              rng.uniform(0.5, 1.0, 2) * 1e5, rng.normal(size=1) * 1e3))
    return np.concatenate((loads, carried))


def assert_close(got, want, rtol=1e-12, floor=0.0):
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    assert np.all(np.abs(got - want) <= rtol * np.maximum(np.abs(want), floor)), (got, want)


def test_derivatives_outputs_and_statics_agree_bit_for_bit_in_every_contact_case():
    """Both sides invert, solve and multiply the 3x3 mass and statics matrices in the fixed order of
    cranefmu.physics.small_linalg (C: cf_dense.h cf_inverse3/cf_solve3/cf_matvec3): the same bits.  (Before,
    numpy's LAPACK inverse, solve, lstsq and BLAS products differed from C's in the last bits: the initial
    roll came out -1.5e-21 against 0, the accelerations some 1e-16 relative apart.)"""
    rng = np.random.default_rng(0)
    seen = set()
    for i in range(40):
        p = random_chassis4(rng, ("neglected", "carried")[i % 2])
        nat, py = load("Chassis4", p), Chassis4Model(p)
        for scale in (0.3, 3.0, 30.0):   # up to loads that tip the crane
            u = random_inputs(rng, scale)
            x0, ref0 = nat.initial_state(u), py.initial_state(u)
            assert np.array_equal(x0, ref0), (x0, ref0)
            for x in (ref0, ref0 + rng.normal(size=6) * [1e-3, 1e-3, 1e-3, 1e-2, 1e-2, 1e-2]):
                t = float(rng.uniform(0.0, 5.0))
                a, b = nat.derivatives(t, x, u), py.derivatives(t, x, u)
                assert np.array_equal(a, b), (a, b)
                y, yp = nat.outputs(t, x, u), py.output_list(t, x, u)
                assert np.array_equal(y, yp)
                seen.add(int(y[14]))   # pads lifted
    assert {0, 1, 2} <= seen, seen     # all pads loaded, one lifting, tipping over an edge


def test_a_rocking_chassis_steps_bit_for_bit_over_many_steps():
    """rk4 over 400 steps of 2 ms (the truck_slewing step) with the boom's inertia carried and a sideways
    moment swinging through the tipping line of the lighter side: a pad lifts and lands again, and the C and
    the Python model stay the same to the last bit all the way (the carried inertia moves, so the mass
    matrix is inverted again every step)."""
    from cranefmu.adapter.integrators import integrate

    p = Chassis4Params(boom_inertia="carried")
    nat, py = load("Chassis4", p), Chassis4Model(p)
    w = 2.0 * np.pi * 1.5

    def inputs(t):
        u = np.array([2e3, -8e4, 1e3, 0.0, -3e5, 4e3, 2e4, 0.0, 9e4, 3e4, 5e2])
        u[3] = 1.6e6 * np.sin(w * t)            # Mx: rolls the crane over one side, then the other
        u[7] = 5e3 * np.sin(0.5 * w * t)       # Sz: the carried boom slews
        return u

    x_nat, x_py = nat.initial_state(inputs(0.0)), py.initial_state(inputs(0.0))
    assert np.array_equal(x_nat, x_py)
    lifted, h = set(), 2e-3
    for k in range(400):
        t, u = k * h, inputs(k * h)
        x_nat = nat.rk4_step(t, x_nat, h, u, None, None, h)
        x_py = integrate(lambda ti, xi: py.derivatives(ti, xi, u), t, x_py, h, "rk4", max_step=h)
        assert np.array_equal(x_nat, x_py), (k, x_nat, x_py)
        lifted.add(int(nat.outputs(t + h, x_nat, u)[14]))
    assert 0 in lifted and 1 in lifted, lifted   # it rocked: a pad off and back on


def _force_terms(py: Chassis4Model, x, u) -> np.ndarray:
    """The sizes of the terms that Chassis4Model.derivatives sums into its generalised force (at a static
    equilibrium they cancel to round-off; its mass matrix carried at u)."""
    py.carry(u)
    w, mg, mbeta = py.applied_loads(u)
    n = np.abs(py.pads(x)[1])
    return np.array([n.sum() + abs(w), abs(mg) + n @ np.abs(py.xs), abs(mbeta) + n @ np.abs(py.zs)])


def test_cross_field_checks_say_what_python_says():
    for fields, bad in ((dict(x_slew=4.0), "x_slew"), (dict(pads_per_outrigger=3), "pads_per_outrigger")):
        with pytest.raises(ParameterError) as err:
            Chassis4Params(**fields)
        p = Chassis4Params()
        object.__setattr__(p, bad, fields[bad])
        with pytest.raises(ValueError) as native_err:
            load("Chassis4", p)
        assert str(native_err.value) == str(err.value)


def test_no_exact_step_and_no_load_rests_at_zero():
    nat = load("Chassis4", Chassis4Params())
    assert nat.lib.cf_has_exact_step == 0
    u = np.zeros(11)
    u[1] = 1e7
    assert np.array_equal(nat.initial_state(u), np.zeros(6))
    assert nat.exact_step(0.0, np.zeros(6), 1e-3, u, np.zeros(11), np.zeros(11), 1e-3) is None
