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


def test_derivatives_outputs_and_statics_agree_in_every_contact_case():
    rng = np.random.default_rng(0)
    seen = set()
    worst = 0.0
    for i in range(40):
        p = random_chassis4(rng, ("neglected", "carried")[i % 2])
        nat, py = load("Chassis4", p), Chassis4Model(p)
        for scale in (0.3, 3.0, 30.0):   # up to loads that tip the crane
            u = random_inputs(rng, scale)
            x0, ref0 = nat.initial_state(u), py.initial_state(u)
            # statics: LAPACK's solve / lstsq against C's LU / normal equations: round-off of the size
            # of the largest component (a component that is 0 in exact arithmetic comes out ~1e-19)
            assert_close(x0, ref0, rtol=1e-12, floor=float(np.max(np.abs(ref0))))
            for x in (ref0, ref0 + rng.normal(size=6) * [1e-3, 1e-3, 1e-3, 1e-2, 1e-2, 1e-2]):
                t = float(rng.uniform(0.0, 5.0))
                a, b = nat.derivatives(t, x, u), py.derivatives(t, x, u)
                assert np.array_equal(a[:3], b[:3])
                # the accelerations: M^-1 force with numpy's inverse and BLAS product against C's; to 1e-12
                # of the terms summed (an acceleration that cancels to ~0 keeps only round-off)
                terms = np.abs(py.inverse_mass) @ _force_terms(py, x, u)
                assert np.all(np.abs(a[3:] - b[3:]) <= 1e-12 * terms), (a, b, terms)
                worst = max(worst, float(np.max(np.abs(a[3:] - b[3:]) / terms)))
                y, yp = nat.outputs(t, x, u), py.output_list(t, x, u)
                assert np.array_equal(y, yp)
                seen.add(int(y[14]))   # pads lifted
    assert {0, 1, 2} <= seen, seen     # all pads loaded, one lifting, tipping over an edge
    assert worst < 1e-14, worst   # measured: see the report


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
