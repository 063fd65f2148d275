"""The native Boom (models/Boom.c over models/cf_boom.c) against its Python twin cranefmu.physics.boom,
function by function through the cffi harness (no FMI): random parameter sets within their ranges with
every switch, random states and inputs, times inside and outside every motion law's phases, whole
communication steps, and the same refusals in the same words.

Every comparison is exact (bit for bit; -0.0 counts as 0.0): the C code does the Python model's
operations in the same order, calls the same libm for cos, sin, atan2 and remainder, and replaces
libm's hypot by models/cf_pymath.c's cf_py_hypot, which gives CPython's math.hypot (glibc's hypot
differs from CPython's in the last bit for about 0.5 % of arguments; test_py_hypot_is_pythons)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from boom_cases import SWITCHES, assert_same, boom_fields, law_times, native_step, random_inputs, rates
from cranefmu.adapter.fmi_adapter import advance
from cranefmu.native.harness import HERE, load
from cranefmu.physics.boom import BoomModel, BoomParams
from cranefmu.physics.params import ParameterError
from structural_cases import refused_as_in_python, unchecked

def configured_sets(seed: int, per_switch: int):
    """(fields, BoomParams or None, the Python refusal or None) for per_switch random sets of every switch."""
    rng = np.random.default_rng(seed)
    for switches in SWITCHES:
        for _ in range(per_switch):
            f = boom_fields(rng, *switches)
            try:
                yield f, BoomParams(**f), None
            except ParameterError as err:
                yield f, None, str(err)


def test_random_sets_every_switch_outputs_derivatives_initial_state():
    rng = np.random.default_rng(7)
    counts = {s: 0 for s in SWITCHES}
    refused = 0
    for f, p, refusal in configured_sets(11, 30):
        if p is None:
            with pytest.raises(ValueError) as err:
                load("Boom", unchecked(BoomParams, f))
            assert str(err.value) == refusal
            refused += 1
            continue
        counts[(p.tip, p.cylinder, p.telescope_source, p.luff_source)] += 1
        py, c = BoomModel(p), load("Boom", p)
        assert c.frozen() == py.frozen and c.exact_applies() == py.exact_applies()
        assert [c.state_name(i) for i in range(3)] == list(py.state_names())
        for t in law_times(f, rng):
            u = random_inputs(rng)
            x0 = py.initial_state(u)
            assert_same(x0, c.initial_state(u), f"initial_state {f}")
            x = x0 + np.array([rng.normal(0, 0.02), rng.normal(0, 0.2), rng.normal(0, 1e-4)])
            assert_same(py.output_list(t, x, u), c.outputs(t, x, u), f"outputs t={t!r} {f}")
            assert_same(py.derivatives(t, x, u), c.derivatives(t, x, u), f"derivatives t={t!r} {f}")
            assert_same(py.after_step(t, x, u), c.after_step(t, x, u), "after_step")
            assert py.exact_step(t, x, 0.01, u, u * 0, u * 0, 1e-3) is None
            assert c.exact_step(t, x, 0.01, u, u * 0, u * 0, 1e-3) is None
    assert min(counts.values()) >= 15, counts   # every switch combination compared on many sets
    assert refused >= 10


def test_whole_steps_equal_the_python_advance():
    rng = np.random.default_rng(3)
    elastic_steps = 0
    for f, p, _ in configured_sets(5, 8):
        if p is None:
            continue
        py, c = BoomModel(p), load("Boom", p)
        u0 = random_inputs(rng)
        x = py.initial_state(u0)
        xc = c.initial_state(u0)
        t = float(rng.uniform(0.0, 3.0))
        for _ in range(12):
            h, max_step = float(rng.choice([1e-3, 5e-3, 0.0137, 0.02])), float(rng.choice([1e-3, 2e-3, 5e-3]))
            r1, r2 = rates(rng)
            x = advance(py, t, x, h, u0, r1, r2, "rk4", 1e-6, max_step)
            xc = native_step(c, t, xc, h, u0, r1, r2, max_step)
            assert_same(x, xc, f"state after the step to t={t + h!r} {f}")
            t += h
            u0 = u0 + h * (r1 + 0.5 * h * r2)
            assert_same(py.output_list(t, x, u0), c.outputs(t, xc, u0), f"outputs at t={t!r}")
            elastic_steps += not py.frozen
    assert elastic_steps >= 100


def test_scene_sets_over_their_runs():
    """The stored scenes' boom sets (truck_telescope default and luffing, hook_sway default and crane_motion):
    2 s of 5 ms steps across the laws' phases, outputs at every step."""
    base = dict(luff_angle=1.0471975511965976, boom_length_start=10.5, boom_length_end=22.4, t_acc=3.0)
    sets = [dict(base), dict(base, telescope_speed=0.55),
            dict(base, cylinder="spring_damper", luff_delta=-0.2617993877991494, luff_rate=0.05, luff_t_acc=1.0,
                 luff_start=1.0, boom_length_end=10.5),
            dict(base, tip="kinematic", boom_length_end=10.5),
            dict(base, tip="kinematic", boom_length_end=10.5, travel_distance=1.0, travel_speed=0.3,
                 travel_t_acc=1.0, steer_delta=0.7853981633974483, steer_rate=0.2, steer_t_acc=1.0, steer_start=0.5)]
    rng = np.random.default_rng(1)
    for f in sets:
        p = BoomParams(**f)
        py, c = BoomModel(p), load("Boom", p)
        u = np.zeros(len(BoomModel.inputs))
        u[5] = -3.5e4
        x, xc = py.initial_state(u), c.initial_state(u)
        assert_same(x, xc, f"initial_state {f}")
        t = 0.0
        for _ in range(400):
            r1, r2 = rates(rng)
            r1 *= 0.1
            r2 *= 0.0
            x = advance(py, t, x, 0.005, u, r1, r2, "rk4", 1e-6, 1e-3)
            xc = native_step(c, t, xc, 0.005, u, r1, r2, 1e-3)
            t += 0.005
            u = u + 0.005 * r1
            assert_same(py.output_list(t, x, u), c.outputs(t, xc, u), f"outputs at t={t!r} {f}")


REFUSALS = [
    dict(t_acc=20.0),
    dict(luff_delta=0.1, luff_rate=0.05, luff_t_acc=3.0),
    dict(seg3_offset=5.0),
    dict(seg4_offset=3.0),
    dict(tip="kinematic", travel_distance=0.1, travel_speed=0.3, travel_t_acc=1.0),
    dict(tip="kinematic", steer_delta=-0.1, steer_rate=0.2, steer_t_acc=1.0),
    dict(tip="kinematic", aux_delta=0.05, aux_rate=0.1, aux_t_acc=1.0),
    dict(travel_distance=1.0),
    dict(aux_length=2.0),
    dict(cyl_base_angle=1.2),
    dict(luff_delta=-1.2, luff_rate=0.1, luff_t_acc=1.0, cyl_base_angle=0.0),
    dict(cyl_base_angle=1.0471975511965976 - math.pi - 1e-9),
]


@pytest.mark.parametrize("bad", REFUSALS, ids=[",".join(b) for b in REFUSALS])
def test_the_same_refusal_in_the_same_words(bad):
    refused_as_in_python("Boom", BoomParams, bad)


def test_py_hypot_is_pythons(tmp_path):
    """models/cf_pymath.c's cf_py_hypot gives math.hypot's bits (glibc's hypot does not, in ~0.5 % of cases)."""
    import cffi

    ffi = cffi.FFI()
    ffi.cdef("double cf_py_hypot(double a, double b);")
    models = HERE / "models"
    ffi.set_source("_cf_pymath_check", '#include "cf_pymath.h"', sources=[str(models / "cf_pymath.c")],
                   include_dirs=[str(models)], extra_compile_args=["-std=c99", "-O2", "-ffp-contract=off"],
                   libraries=["m"])
    lib_path = ffi.compile(tmpdir=str(tmp_path))
    lib = ffi.dlopen(lib_path)
    rng = np.random.default_rng(2)
    pairs = rng.normal(size=(100000, 2)) * np.exp(rng.uniform(-12.0, 12.0, size=(100000, 1)))
    specials = [0.0, -0.0, 1.0, 3.0, 1e-310, 5e-324, 2.2250738585072014e-308, 1e300, 1.7e308, math.inf, -math.inf,
                math.nan]
    pairs = pairs.tolist() + [[a, b] for a in specials for b in specials]
    bad = [(a, b) for a, b in pairs
           if not (math.hypot(a, b) == lib.cf_py_hypot(a, b) or math.isnan(math.hypot(a, b))
                   and math.isnan(lib.cf_py_hypot(a, b)))]
    assert bad == []
