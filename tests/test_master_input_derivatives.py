"""FMUs without the project's <input>_dt/_dt2 rate inputs that declare canInterpolateInputs get the
extrapolation slopes through fmi2SetRealInputDerivatives (issue 4: 'use the FMI calls where an FMU
supports them').  No pythonfmu FMU declares the capability, so the components here are stand-ins
with the attributes the master reads; the slopes themselves are the master's Lagrange rates."""
from types import SimpleNamespace

import numpy as np

from cranefmu.master.coupling import input_groups, rates
from cranefmu.master.scene import ConnectionSpec
from cranefmu.master.system import CoSystem


def _var(name, vr, causality):
    return SimpleNamespace(name=name, valueReference=vr, causality=causality, type="Real")


class _Fmu:
    def __init__(self):
        self.calls = []

    def setReal(self, vrs, values):
        self.calls.append(("setReal", list(vrs), list(values)))

    def setRealInputDerivatives(self, vrs, order, values):
        self.calls.append(("derivatives", list(vrs), list(order), list(values)))


def _comp(name, variables, interpolate):
    md = SimpleNamespace(coSimulation=SimpleNamespace(canInterpolateInputs=interpolate))
    return SimpleNamespace(name=name, md=md, variables={v.name: v for v in variables}, fmu=_Fmu())


def _scene(interpolate: bool, with_rates: bool):
    src = _comp("a", [_var("y", 1, "output")], False)
    dst_vars = [_var("u", 5, "input")] + ([_var("u_dt", 6, "input"), _var("u_dt2", 7, "input")] if with_rates else [])
    dst = _comp("b", dst_vars, interpolate)
    comps = [src, dst]
    return comps, input_groups(comps, [ConnectionSpec("a", "y", "b", "u")])


def test_capable_fmu_without_rate_inputs_gets_fmi_input_derivatives():
    comps, groups = _scene(interpolate=True, with_rates=False)
    g = groups[1][0]
    assert g.fmi_derivatives and g.dt_vrs is None
    # the polynomial through (t, u) = (-2, 1), (-1, 3), (0, 7) is t^2 + 5 t + 7: u' = 5, u'' = 2 at t = 0
    d1, d2 = rates([(-2.0, np.array([1.0])), (-1.0, np.array([3.0])), (0.0, np.array([7.0]))], 0.0)
    CoSystem.push(SimpleNamespace(comps=comps), g, np.array([7.0]), d1, d2)
    assert comps[1].fmu.calls == [("setReal", [5], [7.0]), ("derivatives", [5], [1], [5.0]),
                                  ("derivatives", [5], [2], [2.0])]


def test_rate_inputs_win_and_incapable_fmus_get_a_zero_order_hold():
    for interpolate, with_rates, expected in ((True, True, False), (False, False, False)):
        comps, groups = _scene(interpolate, with_rates)
        g = groups[1][0]
        assert g.fmi_derivatives is expected
        CoSystem.push(SimpleNamespace(comps=comps), g, np.array([7.0]), np.array([6.0]), np.array([2.0]))
        assert not any(c[0] == "derivatives" for c in comps[1].fmu.calls)
