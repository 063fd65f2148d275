"""Experiment files: expressions, command profiles and shapers, inheritance, bad input, each assertion kind
passing and failing on purpose (on rows whose answer is known in closed form)."""
from __future__ import annotations

import cmath
import math
from pathlib import Path

import numpy as np
import pytest

from cranefmu.experiments.assertions import judge, measured
from cranefmu.experiments.expressions import ExpressionError, evaluate
from cranefmu.experiments.profiles import moves, shaped, shaper_impulses, table
from cranefmu.experiments.reader import AssertionSpec, ExperimentError, load


# --- expressions -------------------------------------------------------------------------------------
def test_expression_of_parameters_and_constants():
    values = {"pendulum.mass": 1000.0, "pendulum.theta0": 0.1}
    assert evaluate("pendulum.mass * g * cos(pendulum.theta0)", values) == 1000.0 * 9.81 * math.cos(0.1)
    assert evaluate("-2 ** 2 + max(1, 3) % 2 + sqrt(16) / 4", {}) == -4 + 1 + 1
    assert evaluate(2, {}) == 2.0
    col = np.array([0.0, 3.0, 4.0])
    assert np.array_equal(evaluate("hypot(a.x, 4) - 4", {"a.x": col}, vector=True), np.hypot(col, 4) - 4)


@pytest.mark.parametrize("text, what", [
    ("__import__('os').system('true')", "only calls of"),
    ("().__class__", "allowed only in a name"),
    ("a.__class__", "unknown name"),
    ("(lambda: 1)()", "only calls of"),
    ("'a' * 3", "only numbers"),
    ("1 if 1 else 2", "IfExp is not allowed"),
    ("a.x[0]", "Subscript is not allowed"),
    ("1 < 2", "Compare is not allowed"),
    ("math.pi", "unknown name 'math.pi'"),
    ("1 +", "is not valid"),
    ("1 / 0", "cannot be evaluated"),
    ("sqrt(x=1)", "only calls of"),
])
def test_expression_refuses(text, what):
    with pytest.raises(ExpressionError, match=what.replace("(", r"\(").replace(")", r"\)")):
        evaluate(text, {})


# --- profiles ---------------------------------------------------------------------------------------
def test_moves_trapezoid_and_triangle_in_closed_form():
    p = moves(1.0, [{"start": 2.0, "to": 4.0, "speed": 0.5, "accel_time": 1.0},
                    {"start": 10.0, "to": 3.9, "speed": 0.5, "accel_time": 1.0}])
    a = 0.5
    assert p.at(1.0) == (1.0, 0.0, 0.0)
    assert p.at(2.5) == pytest.approx((1.0 + a * 0.5 ** 2 / 2, a * 0.5, a), abs=1e-15)
    # cruise: 3 m minus the ramps' 0.5 m at 0.5 m/s: 5 s; then the deceleration ramp
    assert p.at(5.0) == pytest.approx((1.25 + 0.5 * 2.0, 0.5, 0.0), abs=1e-15)
    assert p.at(8.5) == pytest.approx((4.0 - a * 0.5 ** 2 / 2, a * 0.5, -a), abs=1e-15)
    assert p.at(9.0) == (4.0, 0.0, 0.0)
    # 0.1 m back is shorter than the ramps' 0.5 m: a triangle of sqrt(d / a) each way
    ta = math.sqrt(0.1 / a)
    assert p.at(10.0 + ta) == pytest.approx((3.95, -a * ta, a), abs=1e-14)   # braking the way back
    assert p.at(10.0 + 2 * ta) == pytest.approx((3.9, 0.0, 0.0), abs=1e-14)
    assert p.derivative().at(2.5) == pytest.approx((0.25, 0.5, 0.0))
    with pytest.raises(ExperimentError.__mro__[1], match="before the previous move ends"):
        moves(0.0, [{"start": 0.0, "to": 1.0, "speed": 1.0, "accel_time": 0.0},
                    {"start": 0.5, "to": 0.0, "speed": 1.0, "accel_time": 0.0}])


def test_tables_linear_and_cubic():
    lin = table([(0.0, 0.0), (1.0, 2.0), (3.0, 0.0)], "linear")
    assert lin.at(0.5) == (1.0, 2.0, 0.0)
    assert lin.at(2.0) == (1.0, -1.0, 0.0)
    assert lin.at(5.0) == (0.0, 0.0, 0.0)
    points = [(t, math.sin(t)) for t in np.linspace(0, 3, 31)]
    cub = table(points, "cubic")
    for t in (0.55, 1.234, 2.9):
        v, d1, d2 = cub.at(t)
        assert v == pytest.approx(math.sin(t), abs=1e-5)
        assert d1 == pytest.approx(math.cos(t), abs=1e-3)
        assert d2 == pytest.approx(-math.sin(t), abs=2e-2)


@pytest.mark.parametrize("kind, zeta", [("zv", 0.0), ("zv", 0.1), ("zvd", 0.0), ("zvd", 0.05)])
def test_shapers_cancel_the_mode(kind, zeta):
    """Singer and Seering 1990: the impulses' responses A_i exp(-zeta w (t - tau_i)) sin(w_d (t - tau_i))
    of the mode cancel after the last, sum A_i exp(-s tau_i) = 0 with s = -zeta w + i w_d; ZVD also
    their derivative in w (sum A_i tau_i exp(-s tau_i) = 0)."""
    f = 0.37
    w = 2 * math.pi * f
    s = complex(-zeta * w, w * math.sqrt(1 - zeta * zeta))
    imp = shaper_impulses(kind, f, zeta)
    assert sum(a for a, _ in imp) == pytest.approx(1.0, abs=1e-15)
    assert abs(sum(a * cmath.exp(-s * tau) for a, tau in imp)) < 1e-12
    if kind == "zvd":
        assert abs(sum(a * tau * cmath.exp(-s * tau) for a, tau in imp)) < 1e-12
    p = moves(0.0, [{"start": 1.0, "to": 2.0, "speed": 0.4, "accel_time": 0.5}])
    q = shaped(p, kind, f, zeta)
    for t in np.linspace(0, 20, 97):
        expect = sum(a * np.array(p.at(t - tau)) for a, tau in imp)
        assert np.allclose(q.at(t), expect, atol=1e-13)
    assert q.at(30.0) == (2.0, 0.0, 0.0)


# --- the file format --------------------------------------------------------------------------------
BASE = """
name = "inherit"
scene = "elastic_pendulum"
stop_time = 1.0
set = {"pendulum.mass" = 900.0, "rope.zeta" = 0.05}

[[commands]]
inputs = "rope.x_top"
moves = [{start = 0.0, to = 1.0, speed = 1.0}]

[[assert]]
name = "a"
column = "rope.tension"
min = 0

[[assert]]
name = "b"
column = "rope.tension"
max = 1e6

[cases.one]

[cases.two]
step_size = 0.002
set = {"pendulum.mass" = 1100.0}
[[cases.two.commands]]
inputs = "pendulum.x_top"
table = [[0, 0], [1, 1]]
[[cases.two.assert]]
name = "b"
column = "rope.tension"
max = 2e6
[[cases.two.assert]]
name = "c"
column = "pendulum.theta"
finally = true
max = 1
"""


def test_cases_inherit_and_override(tmp_path):
    path = tmp_path / "inherit.toml"
    path.write_text(BASE)
    one, two = load(path)
    assert (one.experiment, one.name, two.name) == ("inherit", "one", "two")
    assert one.parameters == {"pendulum.mass": 900.0, "rope.zeta": 0.05}
    assert two.parameters == {"pendulum.mass": 1100.0, "rope.zeta": 0.05}     # merged key by key
    assert one.settings == {"stop_time": 1.0} and two.settings == {"stop_time": 1.0, "step_size": 0.002}
    assert [c.inputs for c in one.commands] == [("rope.x_top",)]
    assert [c.inputs for c in two.commands] == [("pendulum.x_top",)]          # replaced
    assert [a.name for a in one.assertions] == ["a", "b"]
    assert [(a.name, a.max) for a in two.assertions] == [("a", None), ("b", 2e6), ("c", 1.0)]   # b replaced
    assert two.assertions[2].when == "finally"


@pytest.mark.parametrize("text, message", [
    ('scene = "elastic_pendulum"\n[[assert]\n', "malformed TOML: .*line 2"),
    ('scene = "elastic_pendulum"\nstop_tim = 1\n', r":2: stop_tim: unknown key"),
    ('scene = "elastic_pendulum"\n\n[[assert]]\ncolumn = "rope.tension"\nequals = 1\n',
     r":5: equals needs a tolerance"),
    ('scene = "elastic_pendulum"\n\n[[assert]]\ncolumn = "rope.tension"\nmetric = "median"\nmax = 1\n',
     r":5: metric = 'median' is not allowed"),
    ('scene = "elastic_pendulum"\n\n[[assert]]\ncolumn = "rope.tension"\nat = 1\nfinally = true\nmax = 1\n',
     r":5: at: an assertion takes one of always, finally, at, during, not finally and at"),
    ('scene = "elastic_pendulum"\n\n[[assert]]\ncolumn = "rope.tension"\nmax = "__import__(1)"\n',
     r":5: max: expression .* only calls of"),
    ('[[commands]]\ninputs = "rope.x_top"\nmoves = [{to = 1}]\n', r":3: moves: speed: missing"),
    ('[[commands]]\ninputs = "rope.x_top"\nmoves = [{to = 1, speed = 1}]\nshaper = "zz"\n',
     r":4: shaper = 'zz' is not allowed"),
    ('[scene]\ncomponents = ["rope"]\n', r":1: scene: a scene composed inline is not read yet"),
])
def test_bad_file_is_one_line_with_file_line_and_key(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ExperimentError, match=message) as err:
        load(path)
    assert str(err.value).startswith(str(path)) and "\n" not in str(err.value)


@pytest.mark.parametrize("text, message", [
    ('[[assert]]\ncolumn = "rope.tensio"\nmax = 1\n', r":4: column: 'rope.tensio' is not a column of scene "
                                                    r"elastic_pendulum: rope.tension"),
    ('set = {"crane.mass" = 1}\n', r"set: crane.mass: unknown component 'crane'"),
    ('set = {"rope.mass" = 1}\n', r"set: rope.mass: component rope has no variable 'mass'"),
    ('set = {"rope.x_hook" = 1}\n', r"set: rope.x_hook is an input connected to pendulum.x"),
    ('[[commands]]\ninputs = "rope.tension"\nmoves = [{to = 1, speed = 1}]\n',
     r":4: inputs: rope.tension is an output: a command takes inputs only"),
    ('[[commands]]\ninputs = "rope.x_hook"\nmoves = [{to = 1, speed = 1}]\n',
     r":4: inputs: rope.x_hook is connected to pendulum.x"),
    ('[[assert]]\ncolumn = "rope.tension"\nmax = "pendulum.weight * 2"\n', r":5: max: unknown name 'pendulum.weight'"),
    ('parameter_set = "heavy"\n', r"parameter_set = 'heavy' is not in scene elastic_pendulum"),
    ('step_size = -1\n', r"step_size"),
])
def test_file_against_its_scene(built, tmp_path, text, message):
    from cranefmu.experiments.runner import prepare

    path = tmp_path / "scene.toml"
    path.write_text('scene = "elastic_pendulum"\nstop_time = 0.1\n' + text)
    with pytest.raises(ExperimentError, match=message) as err:
        prepare([path])
    assert str(err.value).startswith(str(path)) and "\n" not in str(err.value)


# --- assertion kinds ---------------------------------------------------------------------------------
T = np.linspace(0.0, 10.0, 2001)
F, ZETA = 1.3, 0.02
Y = 5.0 + np.exp(-ZETA * 2 * np.pi * F * T) * np.cos(2 * np.pi * F * math.sqrt(1 - ZETA ** 2) * T)


def verdict(**kw) -> tuple[float, float]:
    if "during" in kw:
        kw["when"] = "during"
    a = AssertionSpec(name="x", column="c", where="f:1", **kw)
    value, _, margin, _ = judge(a, measured(a, T, Y, {"p.v": 2.0}), {"p.v": 2.0})
    return value, margin


@pytest.mark.parametrize("kw, value", [
    (dict(min=4.0, max=6.0), None),                                         # always, both bounds
    (dict(when="finally", equals=float(Y[-1]), abs=1e-12), float(Y[-1])),
    (dict(when="at", at=0.0, equals="3 * p.v", rel=1e-12), 6.0),             # an expression of a parameter
    (dict(when="during", during=(9.0, 10.0), min=4.0, max=6.0), None),
    (dict(metric="max", equals=6.0, abs=1e-12), 6.0),
    (dict(metric="min", during=(0.0, 1.0), max=4.1), None),
    (dict(metric="max_abs", max=6.0), 6.0),
    (dict(metric="mean", equals=5.0, abs=0.01), None),
    (dict(metric="first_crossing", level=5.0, equals=1 / (4 * F * math.sqrt(1 - ZETA ** 2)), abs=1e-4), None),
    (dict(metric="dynamic_factor", equals=1.0, rel=1e-12), 1.0),            # max 6 over the first row, 6
    # the decaying oscillation's smallest peak is its last one, 5 + exp(-zeta w t_k) at t_k = k / f_d
    (dict(metric="smallest_peak", equals=5.0 + math.exp(-ZETA * 2 * math.pi * F * math.floor(
        10.0 * F * math.sqrt(1 - ZETA ** 2)) / (F * math.sqrt(1 - ZETA ** 2))), abs=1e-4), None),
    (dict(metric="dynamic_factor", during=(5.0, 10.0), equals=float(Y[T >= 5.0].max() / 6.0), rel=1e-12), None),
    (dict(metric="dynamic_factor", static="p.v", equals=3.0, rel=1e-12), 3.0),
    (dict(metric="frequency", equals=F, rel=1e-6), None),
    (dict(metric="damping", equals=ZETA, rel=1e-5), None),
])
def test_each_assertion_kind_passes_and_fails(kw, value):
    got, margin = verdict(**kw)
    assert margin >= 0
    if value is not None:
        assert got == pytest.approx(value, rel=1e-12, abs=1e-12)
    # the same assertion with its limit moved just past the value fails
    bad = dict(kw)
    if "equals" in kw:
        target = evaluate(kw["equals"], {"p.v": 2.0})
        tol = max(kw.get("abs", 0.0), kw.get("rel", 0.0) * abs(target))
        bad["equals"] = target + 3 * tol + 1e-9
    elif "max" in kw:
        bad["max"] = (got if kw.get("metric") else float(np.max(_rows(kw)))) - 1e-6
    else:
        bad["min"] = got + 1e-6
    assert verdict(**bad)[1] < 0


def _rows(kw):
    if kw.get("when") == "during":
        return Y[(T >= kw["during"][0]) & (T <= kw["during"][1])]
    return Y


def test_always_reports_the_worst_row_and_its_time():
    a = AssertionSpec(name="x", column="c", where="f:1", max=5.5)
    value, limit, margin, t = judge(a, measured(a, T, Y, {}), {})
    assert (value, t, limit) == (6.0, 0.0, "<= 5.5") and margin == pytest.approx(-0.5)
    with pytest.raises(ValueError, match="outside the run"):
        measured(AssertionSpec(name="x", column="c", where="f:1", when="at", at=11.0, max=1), T, Y, {})
    with pytest.raises(ValueError, match="never crosses"):
        measured(AssertionSpec(name="x", column="c", where="f:1", metric="first_crossing", level=9.0, max=1),
                 T, Y, {})
