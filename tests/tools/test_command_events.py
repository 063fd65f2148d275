"""Commands started or stopped by an event on a result column, and emergency stops (issue 37): the command
changes at the communication point where the condition is first found true, with exact values and rates."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu.experiments.events import EventError, RateOf, Trigger, Triggered, parse_condition
from cranefmu.experiments.profiles import moves
from cranefmu.experiments.reader import ExperimentError, load

LOWER = [{"start": 0.0, "to": 0.5, "speed": 0.2, "accel_time": 0.5}]


def test_a_condition_reads_a_unit_and_refuses_what_is_not_one_comparison():
    assert parse_condition("chassis.N3 < 10 kN") == ("chassis.N3", "<", 10000.0)
    assert parse_condition("pendulum.theta >= radians(2)") == ("pendulum.theta", ">=", "radians(2)")
    for bad in ("chassis.N3", "a < b < c", "< 3", 5):
        with pytest.raises(EventError):
            parse_condition(bad)


def test_a_started_profile_runs_from_the_event_and_a_stopped_one_comes_to_rest_over_its_ramp():
    trigger = Trigger("pendulum.theta < 0")
    trigger.watch(["pendulum.theta"])
    start = Triggered(moves(0.0, LOWER), trigger, "start")
    stop = Triggered(moves(0.0, LOWER), trigger, "stop", stop_ramp=0.5)
    assert start.at(1.0) == (0.0, 0.0, 0.0) and stop.at(1.0) == moves(0.0, LOWER).at(1.0)
    for t, theta in ((0.9, 0.01), (1.0, 0.0), (1.1, -0.002)):   # found at the first row where it holds
        trigger.step_complete(t, 0.1, np.array([theta]))
    assert trigger.t_event == 1.1
    assert start.at(1.1 + 0.3) == pytest.approx(moves(0.0, LOWER).at(0.3), abs=1e-15)
    x, v, _, _ = moves(0.0, LOWER).taylor(1.1)
    a = -v / 0.5
    assert stop.at(1.1 + 0.2) == pytest.approx((x + 0.2 * v + a * 0.04 / 2, v + a * 0.2, a), abs=1e-15)
    assert stop.at(5.0) == pytest.approx((x + v * 0.5 / 2, 0.0, 0.0), abs=1e-15)
    assert RateOf(stop).at(1.3) == pytest.approx((v + a * 0.2, a, 0.0), abs=1e-15)


def _run_with(commands):
    from cranefmu.master.execution import Execution

    ex = Execution.start("elastic_pendulum", stop_time=5.0, step_size=0.01, commands=commands, progress=False)
    rows = []
    try:
        while ex.step():
            rows.append((ex.time, ex.get("pendulum.theta"), ex.get("rope.payout")))
    finally:
        ex.close()
    return np.array(rows)


def test_a_command_started_by_an_event_in_a_run_starts_at_the_row_where_the_event_is_found(built):
    """elastic_pendulum swings from 5 deg; lowering starts when the sway first crosses zero: at every
    communication point after that row the payout input is the profile at (t - t_e), exactly; before, 0."""
    from cranefmu.master.commands import Command

    trigger = Trigger("pendulum.theta < 0")
    rows = _run_with([Command("rope.payout", Triggered(moves(0.0, LOWER), trigger, "start"))])
    t, theta, payout = rows.T
    k = int(np.flatnonzero(theta < 0)[0])
    assert trigger.t_event == pytest.approx(t[k], abs=1e-12) and 1.0 < t[k] < 2.0   # a quarter period: 1.6 s
    assert np.all(payout[:k + 1] == 0.0)
    expected = np.array([moves(0.0, LOWER).at(s - t[k])[0] for s in t[k + 1:]])
    assert np.allclose(payout[k + 1:], expected, rtol=0, atol=1e-12)
    assert payout[-1] == 0.5


def test_an_emergency_stop_in_an_experiment_brings_every_command_to_rest(built, tmp_path):
    f = tmp_path / "e.toml"
    f.write_text('scene = "elastic_pendulum"\nstop_time = 4.0\nstep_size = 0.01\n'
                 'emergency_stop = {when = "pendulum.theta < 0", ramp = "0.5 s"}\n'
                 '[[commands]]\nkind = "lower"\ninputs = "rope.payout"\nrate_inputs = "rope.payout_rate"\n'
                 'moves = [{to = 2.0, speed = 0.2, accel_time = 0.5}]\n'
                 '[[assert]]\ncolumn = "rope.rope_length"\nfinally = true\nmax = 10.5\n')
    from cranefmu.experiments.runner import commands_of, judge_all, prepare, run_cases

    planned = prepare([f])
    case = planned[0].case
    assert case.emergency_stop[:2] == ("pendulum.theta < 0", 0.5)
    run_cases(planned)
    verdicts = judge_all(planned)
    assert verdicts[0].passed, verdicts
    # the lowering (2 m) stopped after about a quarter swing: far less paid out than commanded
    length = verdicts[0].value
    assert 10.0 < length < 10.5
    sources = [c.source for c in commands_of(case.commands, {}, case.emergency_stop)]
    assert isinstance(sources[1], RateOf) and sources[0].watchers() == sources[1].watchers()


@pytest.mark.parametrize("text, message", [
    ('when = "pendulum.theta"\n', "one comparison"),
    ('when = "pendulum.thetaa < 0"\n', "'pendulum.thetaa' is not a result column or a parameter"),
    ('when = "pendulum.theta < 0"\naction = "pause"\n', "action = 'pause' is not allowed"),
    ('action = "stop"\n', "action needs when"),
])
def test_bad_events_are_one_line_before_the_run(built, tmp_path, text, message):
    from cranefmu.experiments.runner import prepare

    f = tmp_path / "b.toml"
    f.write_text('scene = "elastic_pendulum"\n[[assert]]\ncolumn = "rope.tension"\nmax = 1e9\n'
                 '[[commands]]\ninputs = "rope.payout"\nmoves = [{to = 1, speed = 1}]\n' + text)
    with pytest.raises(ExperimentError, match=message) as err:
        prepare([f])
    assert str(err.value).startswith(str(f)) and "\n" not in str(err.value)


@pytest.mark.parametrize("line, message", [
    ('emergency_stop = {when = "pendulum.theta < 0", rmap = "0.5 s"}\n',
     r":\d+: emergency_stop: rmap: unknown key; allowed description, ramp, when$"),
    ('expect_stop = {reason = "rope.slack", during = [0, 1], durign = 1}\n',
     r":\d+: expect_stop: durign: unknown key; allowed during, reason$"),
])
def test_an_unknown_key_of_a_stop_table_is_one_line(tmp_path, line, message):
    f = tmp_path / "k.toml"
    f.write_text('scene = "elastic_pendulum"\n' + line + '[[assert]]\ncolumn = "rope.tension"\nmax = 1e9\n')
    with pytest.raises(ExperimentError, match=message) as err:
        load(f)
    assert str(err.value).startswith(str(f)) and "\n" not in str(err.value)
