"""Bad input: one clear error naming the item, its value and what is allowed.

Every case is checked twice: the API raises the specific :class:`CraneFmuError` subclass, and
``cranefmu run`` (``cranefmu.cli.main``) returns 2 with one line on stderr and no traceback.
Broken scenes are altered copies of the built elastic_pendulum.ssp written to a tmp dir.
"""
from __future__ import annotations


import pytest

from cranefmu.cli import main as cli
from cranefmu.errors import ParameterSetError, SceneError, SettingsError, SimulationError
from cranefmu.master.run import run

from scene_edit import edit_ssp


def _swap(old: str, new: str):
    def edit(text: str) -> str:
        assert text.count(old) == 1, old
        return text.replace(old, new)
    return edit


_LOOP = '<ssd:Connection startElement="rope" startConnector="elongation" endElement="rope" endConnector="payout"/>'

# name -> (edit of the scene, exception type, fragments the message must contain)
SCENES = {
    "missing_fmu": (dict(replace={"resources/Rope.fmu": None}), SceneError,
                    ["component 'rope'", "resources/Rope.fmu", "not in the archive"]),
    "unknown_component": (dict(ssd=_swap('startElement="rope" startConnector="Fx_hook"',
                                         'startElement="hoist" startConnector="Fx_hook"')), SceneError,
                          ["hoist.Fx_hook -> pendulum.Fx_rope", "'hoist'", "components: pendulum, rope"]),
    "unknown_variable": (dict(ssd=_swap('endConnector="Fx_rope"', 'endConnector="F_rope_x"')), SceneError,
                         ["rope.Fx_hook -> pendulum.F_rope_x", "no variable 'F_rope_x'"]),
    "wrong_causality": (dict(ssd=_swap('startConnector="x" endElement="rope"', 'startConnector="mass" endElement="rope"')),
                        SceneError, ["pendulum.mass -> rope.x_hook", "is a parameter", "must be an output"]),
    "type_mismatch": (dict(ssd=_swap('startConnector="x" endElement="rope"',
                                     'startConnector="lifted" endElement="rope"')), SceneError,
                      ["pendulum.lifted -> rope.x_hook", "Integer -> Real", "do not fit; allowed: Real -> Real, Integer -> Integer"]),
    "unit_mismatch": (dict(ssd=_swap('startConnector="x" endElement="rope"', 'startConnector="vx" endElement="rope"')),
                      SceneError, ["pendulum.vx -> rope.x_hook", "'m/s' -> 'm'", "LinearTransformation"]),
    "algebraic_loop": (dict(ssd=_swap("</ssd:Connections>", _LOOP + "</ssd:Connections>")), SceneError,
                       ["algebraic loop", "rope -> rope"]),
    "malformed_ssd": (dict(replace={"SystemStructure.ssd": b"<not-xml"}), SceneError, ["SystemStructure.ssd"]),
}


def _one_line_error(capsys, args: list[str]) -> str:
    code = cli(args)
    err = capsys.readouterr().err
    assert code == 2, err
    assert "Traceback" not in err and err.count("\n") == 1 and err.startswith("cranefmu: error: ")
    return err


@pytest.mark.parametrize("case", sorted(SCENES))
def test_broken_scene(built, tmp_path, capsys, case):
    edit, cls, needles = SCENES[case]
    ssp = edit_ssp(tmp_path / f"{case}.ssp", **edit)
    with pytest.raises(cls) as err:
        run(ssp, stop_time=0.01, step_size=1e-3)
    for needle in needles:
        assert needle in str(err.value), (needle, str(err.value))
    line = _one_line_error(capsys, ["run", str(ssp), "--stop-time", "0.01", "--step", "1e-3"])
    assert needles[0] in line


def test_missing_ssp_file_and_unknown_scene(built, tmp_path, capsys):
    with pytest.raises(SceneError, match="does not exist"):
        run(tmp_path / "nowhere.ssp", stop_time=0.01)
    with pytest.raises(SceneError, match="'no_such_scene' is unknown: one of .*elastic_pendulum"):
        run("no_such_scene", stop_time=0.01)
    assert "no_such_scene" in _one_line_error(capsys, ["run", "no_such_scene"])


# --set / parameters: (overrides, exception type, fragments naming item, value and what is allowed)
PARAMETERS = [
    ({"rope.nothing": "1"}, ParameterSetError, ["rope.nothing", "does not exist"]),
    ({"nodot": "1"}, ParameterSetError, ["'nodot'", "component.variable", "pendulum, rope"]),
    ({"crane.mass": "1"}, ParameterSetError, ["'crane.mass'", "pendulum, rope"]),
    ({"pendulum.mass": "abc"}, ParameterSetError, ["pendulum.mass = 'abc'", "Real"]),
    ({"rope.n_lines": "1.5"}, ParameterSetError, ["rope.n_lines = '1.5'", "Integer"]),
    ({"rope.slack": "1"}, ParameterSetError, ["rope.slack", "cannot be set", "only parameters and inputs"]),
    ({"pendulum.dimension": "4"}, ParameterSetError, ["pendulum.dimension = 4", "one of 1, 2, 3"]),
    ({"pendulum.mass": "-1"}, ParameterSetError, ["pendulum.mass = -1.0", "(0, inf) kg"]),
    ({"pendulum.mass": "0"}, ParameterSetError, ["pendulum.mass = 0.0", "(0, inf) kg"]),
    ({"rope.length": "0"}, ParameterSetError, ["rope.length = 0.0", "(0, inf) m"]),
    ({"rope.length": "-2"}, ParameterSetError, ["rope.length = -2.0", "(0, inf) m"]),
    ({"rope.E": "nan"}, ParameterSetError, ["rope.E = nan", "not finite", "(0, inf) Pa"]),
    ({"rope.E": "inf"}, ParameterSetError, ["rope.E = inf", "not finite", "(0, inf) Pa"]),
    ({"rope.zeta": "-0.1"}, ParameterSetError, ["rope.zeta = -0.1", "[0, 10]"]),
    # more rope paid out than there is: the rope's unstretched length would be negative
    ({"rope.payout": "-20"}, SimulationError, ["rope.payout = -20", "must stay > 0"]),
]


@pytest.mark.parametrize("overrides,cls,needles", PARAMETERS, ids=[next(iter(p[0])) + "=" + next(iter(p[0].values()))
                                                                     for p in PARAMETERS])
def test_bad_parameter(built, capsys, overrides, cls, needles):
    with pytest.raises(cls) as err:
        run("elastic_pendulum", stop_time=0.01, step_size=1e-3, parameters=overrides)
    for needle in needles:
        assert needle in str(err.value), (needle, str(err.value))
    (key, value), = overrides.items()
    line = _one_line_error(capsys, ["run", "elastic_pendulum", "--stop-time", "0.01", "--step", "1e-3", "--set",
                                    f"{key}={value}"])
    assert needles[0] in line


def test_set_without_equals_sign(built, capsys):
    assert "--set 'rope.E'" in _one_line_error(capsys, ["run", "elastic_pendulum", "--set", "rope.E"])


SETTINGS = [
    (dict(stop_time=0.0), ["stop_time = 0.0", "> start_time"]),
    (dict(stop_time=-1.0), ["stop_time = -1.0", "> start_time"]),
    (dict(stop_time=float("nan")), ["stop_time = nan", "finite"]),
    (dict(step_size=0.0), ["step_size = 0.0", "> 0"]),
    (dict(step_size=-1e-3), ["step_size = -0.001", "> 0"]),
    (dict(step_size=float("nan")), ["step_size = nan", "finite"]),
    (dict(step_size=float("inf")), ["step_size = inf", "finite"]),
    (dict(algorithm="magic"), ["algorithm = 'magic'", "jacobi"]),
    (dict(extrapolation=3), ["extrapolation = 3", "0, 1"]),
]


@pytest.mark.parametrize("settings,needles", SETTINGS, ids=[f"{k}={v}" for s, _ in SETTINGS for k, v in s.items()])
def test_bad_run_setting(built, capsys, settings, needles):
    kw = dict(stop_time=1.0, step_size=1e-3) | settings
    with pytest.raises(SettingsError) as err:
        run("elastic_pendulum", **kw)
    for needle in needles:
        assert needle in str(err.value), (needle, str(err.value))
    flag = {"stop_time": "--stop-time", "step_size": "--step", "algorithm": "--algorithm",
            "extrapolation": "--extrapolation"}
    (key, value), = settings.items()
    args = ["run", "elastic_pendulum", "--stop-time", "1"] + [flag[key], str(value)]
    assert needles[0].split(" = ")[0] in _one_line_error(capsys, args)


def test_component_failing_inside_a_step(faulty_ssp, capsys):
    """A component error in doStep: SimulationError naming component, time, cause and advice."""
    ssp = faulty_ssp
    with pytest.raises(SimulationError) as err:
        run(ssp, stop_time=0.1, step_size=1e-3, parameters={"faulty.t_fail": 0.05})
    msg = str(err.value)
    for needle in ("component faulty", "t = 0.049 s", "injected failure", "Try a smaller --step"):
        assert needle in msg, (needle, msg)
    line = _one_line_error(capsys, ["run", str(ssp), "--stop-time", "0.1", "--set", "faulty.t_fail=0.05"])
    assert "component faulty" in line
