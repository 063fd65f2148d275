"""SSP handling (connection checks, LinearTransformation, parameter sets) and initialization
(loops settled in initialization mode: a system at rest stays at rest) on the oscillator FMUs."""
import numpy as np
import pytest

from cranefmu.errors import ParameterSetError, SceneError
from cranefmu.master.graph import is_loop, strongly_connected
from cranefmu.master.run import run
from cranefmu_support.oscillator import SSD, build_oscillator
from cranefmu_support.oscillator.exact import Oscillator

G = 9.81
X_CONN = '<ssd:Connection startElement="mass" startConnector="x" endElement="spring" endConnector="x_in"/>'
F_CONN = '<ssd:Connection startElement="spring" startConnector="F" endElement="mass" endConnector="F"/>'


def variant(ssp, name, old, new, resources=None):
    assert old in SSD
    return build_oscillator(ssp.parent, SSD.replace(old, new), name, resources)


@pytest.mark.parametrize("new, needle", [
    (X_CONN.replace('"x"', '"v"'), "connection mass.v -> spring.x_in: unit 'm/s' -> 'm' differ"),
    (X_CONN.replace('"x"', '"nope"'), "connection mass.nope -> spring.x_in: mass has no variable 'nope'"),
    (X_CONN.replace('startElement="mass" startConnector="x"', 'startElement="spring" startConnector="v_in"'),
     "connection spring.v_in -> spring.x_in: start spring.v_in is a input, must be an output"),
])
def test_every_connection_is_checked_and_named(oscillator_ssp, new, needle):
    ssp = variant(oscillator_ssp, "bad_connection", X_CONN, new)
    with pytest.raises(SceneError) as info:
        run(ssp, stop_time=0.1, step_size=1e-2)
    assert needle in str(info.value)


def test_linear_transformation_is_applied(oscillator_ssp):
    # factor 0, offset 5 N: the mass feels a constant 5 N, x = 5/k1 (1 - cos(w1 t)) from rest at 0
    lt = F_CONN.replace("/>", '><ssc:LinearTransformation factor="0" offset="5"/></ssd:Connection>')
    ssp = variant(oscillator_ssp, "transformed", F_CONN, lt)
    r = run(ssp, stop_time=1.0, step_size=1e-2).result
    k1 = 40.0
    expected = 5.0 / k1 * (1 - np.cos(np.sqrt(k1) * r["time"]))
    assert np.max(np.abs(r["mass.x"] - expected)) < 1e-8


def test_parameter_set_and_overrides(oscillator_ssp):
    ssv = ('<?xml version="1.0" encoding="UTF-8"?>\n<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/'
           'SystemStructureParameterValues" version="1.0" name="stiff"><ssv:Parameters>'
           '<ssv:Parameter name="mass.k"><ssv:Real value="160"/></ssv:Parameter>'
           '</ssv:Parameters></ssv:ParameterSet>')
    ssp = build_oscillator(oscillator_ssp.parent, SSD, "with_sets", {"stiff.ssv": ssv})
    # a(0) = (F - k x0) / m with F = kc (0 - x0) = -10 N at x0 = 0.1 m
    a0 = lambda **kw: run(ssp, stop_time=0.01, step_size=1e-2, parameters={"mass.x0": 0.1}, **kw).result["mass.a"][0]
    assert a0() == pytest.approx(-10 - 40 * 0.1)
    assert a0(parameter_set="stiff") == pytest.approx(-10 - 160 * 0.1)
    with pytest.raises(ParameterSetError, match="parameter set 'soft' is not in scene oscillator: one of default, stiff"):
        a0(parameter_set="soft")


def test_system_at_rest_under_gravity_stays_at_rest(oscillator_ssp):
    """Both masses start at static equilibrium for the inputs found in initialization mode: the
    loop mass.x -> spring.F -> mass.F is iterated until the connections agree."""
    osc = Oscillator(f1=G, f2=G)
    pars = {**osc.parameters(), "mass.start": "equilibrium", "spring.start": "equilibrium"}
    res = run(oscillator_ssp, stop_time=0.5, step_size=1e-3, parameters=pars)
    r = res.result
    assert res.stats.init_iterations > 2
    assert np.max(np.abs(r["mass.a"])) < 1e-9 * G and np.max(np.abs(r["spring.a"])) < 1e-9 * G
    k = np.array([[osc.k1 + osc.kc, -osc.kc], [-osc.kc, osc.kc + osc.k2]])
    x_static = np.linalg.solve(k, [G, G])
    assert r["mass.x"][-1] == pytest.approx(x_static[0], rel=1e-10)
    assert r["spring.x"][-1] == pytest.approx(x_static[1], rel=1e-10)


def test_strongly_connected_blocks_in_dependency_order():
    # 0 <- 1 <-> 2 <- 3, 4 alone with a self-loop
    graph = {0: {1}, 1: {2}, 2: {1, 3}, 3: set(), 4: {4}}
    blocks = strongly_connected(graph)
    assert sorted(map(tuple, blocks)) == [(0,), (1, 2), (3,), (4,)]
    pos = {tuple(b): i for i, b in enumerate(blocks)}
    assert pos[(3,)] < pos[(1, 2)] < pos[(0,)]
    assert is_loop([1, 2], graph) and is_loop([4], graph) and not is_loop([0], graph)


def test_topological_order_and_the_loop_it_refuses():
    """One graph representation for the step's orders too: dependencies first; a loop is reported as
    a closed path through it."""
    from cranefmu.master.graph import DependencyLoop, topological_order
    graph = {0: set(), 1: {0}, 2: {1, 0}, 3: {0}}
    order = topological_order(graph)
    assert sorted(order) == [0, 1, 2, 3]
    assert all(order.index(d) < order.index(n) for n, deps in graph.items() for d in deps)
    with pytest.raises(DependencyLoop) as info:
        topological_order({0: set(), 1: {0, 3}, 2: {1}, 3: {2}})
    cycle = info.value.cycle
    assert cycle[0] == cycle[-1] and sorted(set(cycle)) == [1, 2, 3]
    assert all(cycle[i + 1] in {0: set(), 1: {0, 3}, 2: {1}, 3: {2}}[cycle[i]] for i in range(len(cycle) - 1))
