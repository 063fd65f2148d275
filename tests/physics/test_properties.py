"""Property-based tests over the parameter spaces (hypothesis).

Physics level: every parameter dataclass, drawn from its declared ranges around the defaults,
constructs, and the model integrates 0.1 s (L-stable trbdf2 at the FMU's sub-step) with finite
states and outputs; a draw with one field out of its range (below min, above max, NaN, inf, not
a choice, not a number) raises ParameterError naming that field and its value.
Scene level (few examples, each run ~0.5 s): elastic_pendulum through the master either
finishes with finite results or fails with a CraneFmuError; never a crash, hang or NaN.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cranefmu.adapter.integrators import integrate
from cranefmu.errors import CraneFmuError, SimulationError
from cranefmu.master.run import run
from cranefmu.physics.boom import BoomModel
from cranefmu.physics.boucwen import BoucWenParams
from cranefmu.physics.chassis import ChassisModel
from cranefmu.physics.drive import DriveModel
from cranefmu.physics.girder import GirderModel
from cranefmu.physics.params import ParameterError
from cranefmu.physics.pendulum import PendulumModel
from cranefmu.physics.rope import RopeModel

# model -> internal sub-step [s] (the FMU's default max_step)
MODELS = {RopeModel: 1e-3, PendulumModel: 1e-3, DriveModel: 1e-4, GirderModel: 1e-3, BoomModel: 1e-3,
          ChassisModel: 1e-3}
PARAMS = [m.Params for m in MODELS] + [BoucWenParams]


def _near_default(default, meta: dict):
    """A valid value: a choice, or the default scaled by 0.5 ... 2 and kept inside [min, max]."""
    if meta.get("choices"):
        return st.sampled_from(meta["choices"])
    if isinstance(default, str):
        return st.just(default)
    if default == 0 or isinstance(default, bool):
        return st.just(default)
    lo, hi = meta.get("min"), meta.get("max")

    def clip(v):
        if lo is not None:
            v = max(v, lo) if not meta.get("min_open") else (v if v > lo else default)
        if hi is not None:
            v = min(v, hi) if not meta.get("max_open") else (v if v < hi else default)
        return type(default)(round(v)) if isinstance(default, int) else v
    return st.floats(0.5, 2.0).map(lambda f: clip(default * f))


def valid_params(cls):
    fields = {name: _near_default(default, meta) for name, default, meta in cls.field_specs()}
    return st.fixed_dictionaries(fields)


def _bad_values(default, meta: dict) -> list:
    """Values that break one field's declared range (each must be refused)."""
    if meta.get("choices"):
        return ["no-such-choice", 12345]
    if isinstance(default, str):
        return []
    bad = [math.nan, "abc"]
    lo, hi = meta.get("min"), meta.get("max")
    if lo is not None:
        bad += [lo - 1.0, -math.inf] + ([lo] if meta.get("min_open") else [])
    if hi is not None:
        bad += [hi + 1.0, math.inf] + ([hi] if meta.get("max_open") else [])
    if lo is None and hi is None:
        bad += [math.inf]
    return bad


def invalid_field(cls):
    cases = [(name, v) for name, default, meta in cls.field_specs() for v in _bad_values(default, meta)]
    return st.sampled_from(cases)


def _construct_or_reject(cls, kw):
    """Cross-field checks may refuse a combination of in-range values: then it names a field."""
    from hypothesis import reject

    try:
        return cls(**kw)
    except ParameterError as err:
        assert any(f"{cls.component}.{name}" in str(err) for name in kw), str(err)
        reject()


@pytest.mark.parametrize("model", list(MODELS), ids=lambda m: m.__name__)
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(data=st.data())
def test_valid_parameters_integrate_to_finite_values(model, data):
    params = _construct_or_reject(model.Params, data.draw(valid_params(model.Params)))
    m = model(params)
    u = m.default_inputs()
    x = m.initial_state(u)
    y = m.output_values(0.0, x, u)
    assert np.all(np.isfinite(x)) and np.all(np.isfinite(y))
    t = 0.0
    for _ in range(10):
        x = integrate(lambda tt, xx: m.derivatives(tt, xx, u), t, x, 0.01, "trbdf2", max_step=MODELS[model])
        t += 0.01
        x = m.after_step(t, x, u)
        assert np.all(np.isfinite(x)), (t, x)
    assert np.all(np.isfinite(m.output_values(t, x, u)))


@pytest.mark.parametrize("cls", PARAMS, ids=lambda c: c.__name__)
@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_one_field_out_of_range_is_refused_naming_it(cls, data):
    name, bad = data.draw(invalid_field(cls))
    with pytest.raises(ParameterError) as err:
        cls(**{name: bad})
    assert f"{cls.component}.{name} = {bad!r}" in str(err.value)


scene_draws = st.fixed_dictionaries({
    "rope.E": st.floats(1e9, 1e13),            # 1/100 ... 100 x the scene's rope
    "rope.zeta": st.floats(0.0, 1.0),
    "rope.length": st.floats(1.0, 40.0),       # the load starts off its rest length: a jolt
    "pendulum.mass": st.floats(1.0, 2e4),
    "pendulum.vx0": st.floats(-5.0, 5.0),
})


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(p=scene_draws, h=st.sampled_from([1e-3, 5e-3, 2e-2]), algorithm=st.sampled_from(["jacobi", "gauss-seidel"]),
       order=st.integers(0, 2))
def test_scene_runs_finish_finite_or_fail_clearly(built, p, h, algorithm, order):
    try:
        res = run("elastic_pendulum", stop_time=1.0, step_size=h, algorithm=algorithm, extrapolation=order,
                  parameters=p, keep=True).result
    except SimulationError as err:
        assert "t = " in str(err) and err.result is not None
        for name in err.result.dtype.names:  # the failing row, recorded last, may hold the non-finite value
            assert np.all(np.isfinite(err.result[name][:-1])), name
        return
    except CraneFmuError as err:  # a clear refusal naming the item
        assert any(k in str(err) for k in p), str(err)
        return
    assert len(res) == round(1.0 / h) + 1
    for name in res.dtype.names:
        assert np.all(np.isfinite(res[name])), name
