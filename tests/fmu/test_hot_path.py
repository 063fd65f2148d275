"""The FMU's fast paths compute the same numbers as the plain ones, to the last bit: rk4 on lists of
floats against rk4 on arrays, a model's output list against its output array, and the adapter's
cached input vector and rates against the values last set (benchmarks/fmu_floor.py measures the speed)."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from cranefmu.adapter.fmi_adapter import advance
from cranefmu.adapter.integrators import integrate, rk4_list
from cranefmu_support.model_cases import CASES

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("case", [c for c in CASES if c.make().list_rhs and not c.make().frozen],
                         ids=lambda c: c.id)
def test_rk4_on_lists_gives_the_bits_of_rk4_on_arrays(case):
    m, u = case.make(), case.u()
    x = m.initial_state(m.default_inputs())
    for k in range(round(case.t_end / 2e-2)):   # macro steps of 20 ms, 1e-4 s sub-steps over the case
        t = k * 2e-2
        on_arrays = integrate(lambda tt, xx: m.derivatives(tt, xx, u), t, x, 2e-2, "rk4", max_step=1e-4)
        on_lists = rk4_list(lambda tt, xx: m.derivatives_list(tt, xx, u), t, x.tolist(), 2e-2, max_step=1e-4)
        assert np.array_equal(np.array(on_lists), on_arrays)
        x = on_arrays
    assert not np.array_equal(x, m.initial_state(m.default_inputs()))   # the state did move


@pytest.mark.parametrize("case", [c for c in CASES if c.make().list_rhs and not c.make().frozen],
                         ids=lambda c: c.id)
def test_step_with_input_rates_on_lists_gives_the_bits_of_rk4_on_arrays(case):
    """Inputs moving as u0 + s r1 + s^2/2 r2 (an extrapolating master sets the rates): advance()
    steps on plain floats and gives the state rk4 on arrays gives, to the last bit."""
    m, u = case.make(), case.u()
    x = m.initial_state(m.default_inputs())
    r1 = np.linspace(0.3, 1.1, u.size) * (1.0 + np.abs(u))
    r2 = np.linspace(-2.0, 0.7, u.size) * (1.0 + np.abs(u))
    h, sub = 2e-3, 1e-4
    for k in range(5):   # macro steps of 2 ms, 0.1 ms sub-steps (the drive's shafts are stiff)
        t = 0.37 + k * h

        def rhs(tt, xx):
            s = tt - t
            return m.derivatives(tt, xx, u + s * (r1 + 0.5 * s * r2))
        on_arrays = m.after_step(t + h, integrate(rhs, t, x, h, "rk4", max_step=sub), u + h * (r1 + 0.5 * h * r2))
        on_lists = advance(m, t, x, h, u, r1, r2, "rk4", 1e-6, sub)
        assert np.array_equal(on_lists, on_arrays), f"step {k}"
        assert not np.array_equal(on_lists, advance(m, t, x, h, u, None, None, "rk4", 1e-6, sub))  # rates used
        x = on_arrays


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.id)
def test_output_list_is_output_values_as_floats(case):
    m, u = case.make(), case.u()
    x = m.initial_state(u)
    for t in (0.0, 0.37, 2.5):
        values, listed = m.output_values(t, x, u), m.output_list(t, x, u)
        assert values.dtype == float and np.array_equal(values, np.array(listed, dtype=float))


def _slave(fmu: str):
    spec = importlib.util.spec_from_file_location(f"_hot_path_{fmu}", ROOT / "fmus" / f"{fmu}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    s = getattr(mod, fmu)(instance_name=fmu.lower(), resources=None)
    vr = {v.name: v.value_reference for v in s.vars.values()}
    return s, vr


def test_adapter_steps_with_the_inputs_and_rates_last_set():
    """A lone hook (closed-form step): the adapter's cached input vector and rates follow every set,
    and its step equals advance() fed the values directly."""
    s, vr = _slave("Pendulum")
    s.setup_experiment(0.0, None, None)
    s.enter_initialization_mode()
    s.set_real([vr["Fy_rope"]], [9810.0])
    s.exit_initialization_mode()
    model, x, h = s._model, s._x.copy(), 1e-2
    names = [sig.name for sig in model.inputs]
    u = np.zeros(len(names))
    r1, r2 = np.zeros(len(names)), np.zeros(len(names))
    t = 0.0
    for k, (fx, fy, dfx, ddfy) in enumerate([(0.0, 9810.0, 0.0, 0.0), (120.0, 9900.0, 0.0, 0.0),
                                            (120.0, 9900.0, 50.0, -3.0), (-40.0, 9700.0, 0.0, 0.0)]):
        s.set_real([vr["Fx_rope"], vr["Fy_rope"]], [fx, fy])
        s.set_real([vr["Fx_rope_dt"], vr["Fy_rope_dt2"]], [dfx, ddfy])
        u[0], u[1], r1[0], r2[1] = fx, fy, dfx, ddfy
        assert s.do_step(t, h)
        moving = dfx != 0.0 or ddfy != 0.0
        x = advance(model, t, x, h, u.copy(), r1.copy() if moving else None, r2.copy() if moving else None,
                    "exact", 1e-6, 1e-3)
        t += h
        assert np.array_equal(s._x, x), f"step {k}"
        vx = s.get_real([vr["vx"]])[0]
        assert vx == x[3]
    assert x[3] != 0.0   # the hook did swing
