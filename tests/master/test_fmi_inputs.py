"""What the master feeds an input: the extrapolation slopes through fmi2SetRealInputDerivatives for an
FMU that declares canInterpolateInputs and has no rate inputs, and values converted between the units
of the connection's ends.  No pythonfmu FMU declares that capability and our FMUs share units, so the
components here are stand-ins with the attributes the master reads."""
from types import SimpleNamespace

import numpy as np

from cranefmu.master.coupling import input_groups, rates
from cranefmu.master.scene import ConnectionSpec
from cranefmu.master.coupled import Coupling


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


def _host(comps, g):
    """A Coupling wired to the stand-in components by hand: one group, its set buffer, its arrays."""
    import ctypes

    host = object.__new__(Coupling)
    host.comps, host.links = comps, [g]
    n = len(g.dst_vrs)
    vrs = g.dst_vrs + (g.dt_vrs + g.dt2_vrs if g.dt_vrs is not None else [])
    g.sl, g.set_vrs = slice(0, n), vrs
    g.set_values = (ctypes.c_double * len(vrs))()
    g.set_view = np.ctypeslib.as_array(g.set_values)
    for c in comps:   # comp.write(vrs, count, values): the stand-in records it as a setReal
        c.write = (lambda fmu: lambda vrs, count, values: fmu.setReal(list(vrs)[:count], list(values)[:count]))(c.fmu)
        c.fresh = False
    host.fed, host.fed_rate, host.fed_curvature = np.zeros(n), np.zeros(n), np.zeros(n)
    host.held = np.ones(n, dtype=bool)
    return host


def test_capable_fmu_without_rate_inputs_gets_fmi_input_derivatives():
    comps, groups = _scene(interpolate=True, with_rates=False)
    g = groups[1][0]
    assert g.fmi_derivatives and g.dt_vrs is None
    # the polynomial through (t, u) = (-2, 1), (-1, 3), (0, 7) is t^2 + 5 t + 7: u' = 5, u'' = 2 at t = 0
    d1, d2 = rates([(-2.0, np.array([1.0])), (-1.0, np.array([3.0])), (0.0, np.array([7.0]))], 0.0)
    _host(comps, g).feed_group(0, np.array([7.0]), d1, d2)
    assert comps[1].fmu.calls == [("setReal", [5], [7.0]), ("derivatives", [5], [1], [5.0]),
                                  ("derivatives", [5], [2], [2.0])]


def test_rate_inputs_win_and_incapable_fmus_get_a_zero_order_hold():
    for interpolate, with_rates, expected in ((True, True, False), (False, False, False)):
        comps, groups = _scene(interpolate, with_rates)
        g = groups[1][0]
        assert g.fmi_derivatives is expected
        _host(comps, g).feed_group(0, np.array([7.0]), np.array([6.0]), np.array([2.0]))
        assert not any(c[0] == "derivatives" for c in comps[1].fmu.calls)
        # the rate inputs (where offered) get the slope and curvature in the same fmi2SetReal
        assert comps[1].fmu.calls[0] == (("setReal", [5, 6, 7], [7.0, 6.0, 2.0]) if with_rates
                                         else ("setReal", [5], [7.0]))


# --- connection units (issue 4: "apply connection units") ------------------------------------------

def _unit(name, factor=1.0, offset=0.0, **exps):
    base = SimpleNamespace(kg=0, m=0, s=0, A=0, K=0, mol=0, cd=0, rad=0, factor=factor, offset=offset)
    for k, v in exps.items():
        setattr(base, k, v)
    return SimpleNamespace(name=name, baseUnit=base)


def _unit_comp(name, var, causality, unit, units):
    v = SimpleNamespace(name=var, valueReference=1, causality=causality, type="Real", unit=unit)
    return SimpleNamespace(name=name, variables={var: v}, md=SimpleNamespace(unitDefinitions=units))


def test_connection_units_convert_through_the_unit_definitions():
    from cranefmu.master.coupling import check_connection

    mm, m = _unit("mm", 1e-3, m=1), _unit("m", m=1)
    degc, kelvin = _unit("degC", 1.0, 273.15, K=1), _unit("K", K=1)
    comps = {"a": _unit_comp("a", "y", "output", "mm", [mm, degc]), "b": _unit_comp("b", "u", "input", "m", [m, kelvin])}
    c = check_connection(ConnectionSpec("a", "y", "b", "u"), comps)
    assert c.factor == 1e-3 and c.offset == 0.0            # 1500 mm -> 1.5 m
    comps["a"].variables["y"].unit, comps["b"].variables["u"].unit = "degC", "K"
    c = check_connection(ConnectionSpec("a", "y", "b", "u"), comps)
    assert c.factor * 20.0 + c.offset == 293.15            # 20 degC -> 293.15 K
    comps["b"].variables["u"].unit = "m"                    # temperature into a length: refused
    import pytest

    from cranefmu.errors import SceneError
    with pytest.raises(SceneError, match="'degC' -> 'm' differ"):
        check_connection(ConnectionSpec("a", "y", "b", "u"), comps)
