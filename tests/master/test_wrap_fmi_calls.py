"""cranefmu.master.fmu.wrap_fmi_calls: the public way to see every FMI C call of a run (it replaced
benchmarks/speed_accuracy.py's patch of fmpy's private _FMU._loadFunctions)."""
from __future__ import annotations

import numpy as np

from cranefmu.master.fmu import wrap_fmi_calls
from cranefmu.master.run import run
from cranefmu_support.oscillator.runs import UNDAMPED, X0

H, STOP = 0.01, 0.2


def _go(ssp):
    return run(ssp, stop_time=STOP, step_size=H, algorithm="jacobi", extrapolation=0, isolate=False,
               parameters={**UNDAMPED.parameters(), "mass.x0": X0}, progress=False)


def test_each_instance_s_calls_pass_through_the_wrapper_and_the_results_stay(oscillator_ssp):
    calls: dict[tuple[str, str], int] = {}

    def counting(instance, name, f):
        def call(*args):
            calls[instance, name] = calls.get((instance, name), 0) + 1
            return f(*args)

        for attr in ("argtypes", "restype", "argnames"):   # fmpy's own wrappers read them
            setattr(call, attr, getattr(f, attr, None))
        return call

    with wrap_fmi_calls(counting):
        wrapped = _go(oscillator_ssp)
    steps = wrapped.stats.steps
    assert steps == round(STOP / H)
    for instance in ("mass", "spring"):
        assert calls[instance, "fmi2Instantiate"] == 1
        assert calls[instance, "fmi2DoStep"] == steps   # Jacobi, fixed step: one doStep per macro step
    n = sum(calls.values())
    plain = _go(oscillator_ssp)   # the wrapper is gone after the block, and it changed nothing
    assert sum(calls.values()) == n
    for name in wrapped.result.dtype.names:
        np.testing.assert_array_equal(wrapped.result[name], plain.result[name])
