"""Operator commands on the boom (issue 27): telescope, luff and slew fed into the boom's command inputs
through the master's command source: exact at a coarse macro step, the whole run bit for bit the law's
when fed the law's values, and the experiment kinds' bad input in one line."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cranefmu.experiments.reader import ExperimentError
from cranefmu.physics.motion_laws import trapezoid_motion


class LawSource:
    """A command source (at(t) -> value, rate, acceleration) giving a trapezoid law's change: what the
    boom's own law adds to its start value (picklable, for the isolated run)."""

    def __init__(self, start: float, distance: float, speed: float, t_acc: float, copies: int = 1):
        self.args, self.copies = (start, distance, speed, t_acc), copies

    def at(self, t: float) -> tuple[float, float, float]:
        # the telescoping law moves two segments by the same trapezoid (V20 = V10): their sum
        v, r, a = trapezoid_motion(t, *self.args)
        return (v + v, r + r, a + a) if self.copies == 2 else (v, r, a)


def test_commanded_telescope_and_luff_are_exact_at_a_coarse_step(built):
    """truck_telescope's boom telescoped and luffed at once by two commands at H = 20 ms, every bond implicit
    (breakpoints between communication points): the boom length and angle equal the closed form
    L = L0 + e(t), phi1 = phi0 + d(t) at every row, and the tip foot + L (cos psi, sin psi) with
    psi = phi1 - gamma on the chassis' own tilt and heave, position and velocity, to round-off."""
    import cranefmu
    from cranefmu.experiments.profiles import moves
    from cranefmu.master.commands import Command

    ext = moves(0.0, [dict(start=0.513, to=1.2, speed=0.3, accel_time=0.7)])
    luff = moves(0.0, [dict(start=0.25, to=-0.3, speed=0.1, accel_time=0.55)])
    # the implicit group at 20 ms (the scene's stored setting when this test was written): the commands must be
    # exact inside an implicit group's iterations too
    r = cranefmu.simulate("truck_telescope", stop_time=6.0, step_size=0.02, isolate=True, algorithm="jacobi",
                          extrapolation=1, implicit=["foot_heave", "foot_tilt", "tip", "hook", "drum"],
                          coupling_tolerance=1e-3,
                          commands=[Command("boom.extension_command", ext), Command("boom.luff_command", luff)],
                          parameters={"boom.telescope_source": "input", "boom.luff_source": "input"})
    e = np.array([ext.at(t) for t in r["time"]])
    d = np.array([luff.at(t) for t in r["time"]])
    L, phi = 10.5 + e[:, 0], math.radians(60.0) + d[:, 0]   # the default set's boom_length_start, luff_angle
    assert np.max(np.abs(r["boom.boom_length"] - L)) < 1e-14
    assert np.max(np.abs(r["boom.luff_angle_out"] - phi)) < 1e-15
    psi, psi_rate = phi - r["chassis.gamma"], d[:, 1] - r["chassis.gamma_rate"]
    assert np.max(np.abs(r["boom.x_tip"] - L * np.cos(psi))) < 1e-13   # the foot at x = 0, y = y_base
    assert np.max(np.abs(r["boom.y_tip"] - r["chassis.y_base"] - L * np.sin(psi))) < 1e-13
    vx = e[:, 1] * np.cos(psi) - L * psi_rate * np.sin(psi)
    vy = r["chassis.vy_base"] + e[:, 1] * np.sin(psi) + L * psi_rate * np.cos(psi)
    assert np.max(np.abs(r["boom.vx_tip"] - vx)) < 1e-14 and np.max(np.abs(r["boom.vy_tip"] - vy)) < 1e-14
    assert r["boom.extension"][-1] == pytest.approx(1.2, abs=1e-14)
    assert r["boom.luff_angle_out"][-1] - math.radians(60.0) == pytest.approx(-0.3, abs=1e-15)
    assert np.max(np.abs(vx)) > 0.5   # the tip moved


@pytest.mark.parametrize("scene, stop, switch, target, source, parameters", [
    # the default set's telescoping law (10.5 -> 22.4 m, 0.35 m/s each segment, T1 = 3 s)
    ("truck_telescope", 4.0, "boom.telescope_source", "boom.extension_command",
     LawSource(0.0, 0.35 * 17.0, 0.35, 3.0, copies=2), {}),
    # a luffing law on the rigid cylinder while the boom telescopes
    ("truck_telescope", 3.0, "boom.luff_source", "boom.luff_command", LawSource(0.5, 0.2, 0.1, 0.5),
     {"boom.luff_delta": 0.2, "boom.luff_rate": 0.1, "boom.luff_t_acc": 0.5, "boom.luff_start": 0.5}),
    # the default set's 90 deg slew (0.1 rad/s, 2 s ramps from t = 1 s)
    ("truck_slewing", 4.0, "boom.slew_source", "boom.slew_command", LawSource(1.0, math.pi / 2, 0.1, 2.0), {}),
])
def test_commanded_law_equals_the_parameter_law_bit_for_bit(built, scene, stop, switch, target, source, parameters,
                                                          monkeypatch):
    """The scene run with its motion law, and run with the law's values fed as a command into the input (the
    source switched to input): every column equal to the last bit.  truck_telescope's implicit groups read
    the boom's outputs inside the step: without the feed right after each step (CommandFeed.after_step)
    they saw the command of the step's start and both truck_telescope cases differed (regression test)."""
    import os

    import cranefmu
    from cranefmu.master.commands import Command
    from cranefmu.master.runspec import resolve

    # the isolated run's worker unpickles LawSource: it imports this module
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(Path(__file__).parent), os.environ.get("PYTHONPATH", "")]))

    law = cranefmu.simulate(scene, stop_time=stop, isolate=True, parameters=parameters)
    # a telescope command holds the hoist unless its payout is given (cranefmu.derived): the law's payout
    hoist = {"drive.payout_speed": resolve(scene, parameters=parameters).overrides[("drive", "payout_speed")]} \
        if switch == "boom.telescope_source" else {}
    commanded = cranefmu.simulate(scene, stop_time=stop, isolate=True, commands=[Command(target, source)],
                                  parameters={**parameters, switch: "input", **hoist})
    assert law.dtype.names == commanded.dtype.names and len(law) == len(commanded)
    for name in law.dtype.names:
        assert np.array_equal(law[name], commanded[name]), name
    column = {"boom.extension_command": "boom.extension", "boom.luff_command": "boom.luff_angle_out",
              "boom.slew_command": "boom.slew_angle_out"}[target]
    assert np.ptp(law[column]) > 0.01   # the motion ran


EXPERIMENT = 'scene = "{scene}"\nstop_time = 0.1\n{body}'


@pytest.mark.parametrize("scene, body, message", [
    ("elastic_pendulum", '[[commands]]\nkind = "luff"\nmoves = [{to = 1, speed = 0.1}]\n',
     r":4: kind = 'luff' is not allowed on scene elastic_pendulum: no component has the input luff_command "
     r"\(a Boom or SlewingBoom\); boom commands allowed there: none"),
    ("truck_telescope", '[[commands]]\nkind = "slew"\nmoves = [{to = 1, speed = 0.1}]\n',
     r":4: kind = 'slew' is not allowed on scene truck_telescope: no component has the input slew_command "
     r"\(a SlewingBoom\); boom commands allowed there: telescope, luff"),
    ("truck_telescope", '[[commands]]\nkind = "luff"\ninputs = "boom.x_travel"\nmoves = [{to = 1, speed = 0.1}]\n',
     r":5: inputs: boom.x_travel is not allowed for a luff command: it feeds a boom's luff_command"),
    ("truck_telescope", 'set = {"boom.luff_source" = "law"}\n[[commands]]\nkind = "luff"\nmoves = [{to = 1, speed = 0.1}]\n',
     r"set: boom.luff_source = 'law' is not allowed with a luff command .*: the command needs 'input'"),
    ("truck_telescope", '[[commands]]\nkind = "luff"\nmoves = [{to = -1.2, speed = 0.1}]\n',
     r":5: moves: luffing angle -1.2 rad is not allowed for boom: its cylinder needs 0 < phi1 - cyl_base_angle < pi, "
     r"i.e. -1.0472 < phi1 < 2.0944 rad"),
    ("elastic_pendulum", '[[commands]]\nkind = "travel"\nmoves = [{to = 1, speed = 0.1}]\n',
     r":3: inputs: missing"),
])
def test_boom_command_bad_input_is_one_line(built, tmp_path, scene, body, message):
    from cranefmu.experiments.runner import prepare

    path = tmp_path / "bad.toml"
    path.write_text(EXPERIMENT.format(scene=scene, body=body))
    with pytest.raises(ExperimentError, match=message) as err:
        prepare([path])
    assert str(err.value).startswith(str(path)) and "\n" not in str(err.value)


def test_telescope_command_in_experiment_units(built, tmp_path):
    """kind = telescope writes the boom length [m] from boom_length_start (the input gets the change) and
    switches the source; the run follows it exactly at the communication points."""
    from cranefmu.experiments.runner import judge_all, prepare, run_cases

    path = tmp_path / "telescope.toml"
    path.write_text('scene = "hook_sway"\nstop_time = 4.0\n'
                    '[[commands]]\nkind = "telescope"\nmoves = [{start = 0.5, to = 11.5, speed = 0.5, accel_time = 0.5}]\n'
                    '[[assert]]\nname = "length"\ncolumn = "boom.boom_length"\nfinally = true\nequals = 11.5\nabs = 1e-12\n'
                    '[[assert]]\nname = "mid"\ncolumn = "boom.boom_length"\nat = 1.5\n'
                    'equals = "boom.boom_length_start + 0.125 + 0.5 * 0.5"\nabs = 1e-12\n')
    planned = prepare([path])
    assert planned[0].case.parameters["boom.telescope_source"] == "input"
    assert planned[0].case.commands[0].inputs == ("boom.extension_command",)
    run_cases(planned)
    verdicts = judge_all(planned)
    assert [v.passed for v in verdicts] == [True, True], [(v.name, v.value, v.note) for v in verdicts]
