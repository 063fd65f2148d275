"""An Execution a caller drives (master/execution.py): step() and simulate_until() give the rows of the
one-call run() bit for bit, values are read and set between steps, bad names are refused by name."""
import numpy as np
import pytest

from cranefmu.errors import ParameterSetError, SceneError, SettingsError
from cranefmu.master.run import Execution, RunResult, run

SETTINGS = dict(stop_time=0.2, step_size=1e-3, algorithm="jacobi", extrapolation=1, parameters={"mass.x0": 0.1},
                progress=False)


def _equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and len(a) == len(b) and all(np.array_equal(a[n], b[n]) for n in a.dtype.names)


@pytest.fixture(scope="module")
def reference(oscillator_ssp):
    return run(oscillator_ssp, **SETTINGS)


def test_step_by_step_equals_run(oscillator_ssp, reference):
    with Execution.start(oscillator_ssp, **SETTINGS) as ex:
        taken = 0
        while ex.step():
            taken += 1
        assert ex.done and taken == 200 and ex.time == pytest.approx(0.2, abs=1e-15)
        result = ex.finish()
    assert isinstance(result, RunResult) and result.stats.steps == reference.stats.steps == 200
    assert _equal(result.result, reference.result)


def test_simulate_until_then_steps_equals_run_and_reads_values(oscillator_ssp, reference):
    with Execution.start(oscillator_ssp, **SETTINGS) as ex:
        assert ex.simulate_until(0.05)
        assert ex.time == pytest.approx(0.05, abs=1e-15)
        # the mass's position now is the row's at t = 0.05 s (the 51st row of the one-call run)
        assert ex.get("mass.x") == reference.result["mass.x"][50] == ex.row()["mass.x"]
        assert ex.step() and ex.time == pytest.approx(0.051, abs=1e-15)
        assert not ex.simulate_until(0.5)   # the run ends at its stop time, before 0.5 s
        result = ex.finish()
    assert _equal(result.result, reference.result)


def test_set_refuses_connected_inputs_fixed_parameters_and_unknown_names(oscillator_ssp, reference):
    with Execution.start(oscillator_ssp, **SETTINGS) as ex:
        ex.simulate_until(0.1)
        with pytest.raises(ParameterSetError, match="mass.f = 5.0 was refused by the FMU.*fixed parameter"):
            ex.set("mass.f", 5.0)
        with pytest.raises(SettingsError, match="spring.x_in.*fed by the connection mass.x -> spring.x_in"):
            ex.set("spring.x_in", 0.0)
        with pytest.raises(SceneError, match="'crane.x' is not a variable.*mass, spring"):
            ex.get("crane.x")
        result = ex.finish()
    assert _equal(result.result, reference.result[:101])   # finished where it was: 101 rows to 0.1 s
    with pytest.raises(SettingsError, match="closed"):
        ex.step()


def test_isolate_is_refused(oscillator_ssp):
    with pytest.raises(SettingsError, match="isolate=True is not allowed for an Execution"):
        Execution.start(oscillator_ssp, isolate=True, **SETTINGS)
