"""Verdicts that cannot lie (issue 37): a run that stops before its stop time fails its experiment unless
the experiment expects that stop (``expect_stop``); a file that asserts nothing is refused; the JSON says
why a run stopped; ``stop_when = "none"`` in a file as on the command line."""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from cranefmu.experiments.reader import ExperimentError, load

# truck_telescope with 3.5 t on a 26.96 m boom at 60 deg: past its tipping length, the run stops at t = 0
TIPS = ('scene = "truck_telescope"\nstop_time = 0.04\n'
        'set = {"boom.luff_angle" = 1.0471975511965976, "boom.boom_length_start" = 26.96, '
        '"boom.boom_length_end" = 26.96, "boom.seg4_offset" = 8.23, "boom.seg3_offset" = 16.46, '
        '"pendulum.mass" = 3500.0}\n')
# the 'finally' that the old code took at the last row computed (t = 0), where it holds
FINALLY = '[[assert]]\nname = "front_low"\ncolumn = "chassis.N_front"\nfinally = true\nmax = 1e9\n'


def _check(tmp_path: Path, text: str, name: str = "e.toml") -> tuple[int, str, dict]:
    f = tmp_path / name
    f.write_text(text)
    report = tmp_path / "r.json"
    p = subprocess.run([sys.executable, "-m", "cranefmu.cli", "check", str(f), "--quiet", "--report", str(report)],
                       capture_output=True, text=True, timeout=300)
    data = json.loads(report.read_text()) if report.exists() and report.stat().st_size else {}
    return p.returncode, p.stdout + p.stderr, data


def test_a_run_that_tips_and_stops_early_fails_its_finally_assertion(tmp_path):
    code, out, data = _check(tmp_path, TIPS + FINALLY)
    assert code == 1, out
    assert "the run stopped before its stop time 0.04 s" in out and "chassis.tipping = 1" in out
    case = data["cases"][0]
    assert "chassis.tipping" in case["stopped_early"] and case["end_time_s"] < case["stop_time_s"] == 0.04
    assert data["verdicts"][0]["passed"] is False


def test_an_expected_stop_passes_and_the_assertions_are_judged_on_its_rows(tmp_path):
    text = TIPS + 'expect_stop = {reason = "chassis.tipping", during = [0.0, 0.01]}\n' + FINALLY
    code, out, data = _check(tmp_path, text)
    assert code == 0, out
    names = {v["name"]: v for v in data["verdicts"]}
    assert names["expect_stop"]["passed"] and names["front_low"]["passed"]
    assert names["expect_stop"]["value"] == 0.0   # it stopped at t = 0


def test_an_expected_stop_outside_its_window_or_that_never_comes_fails(tmp_path):
    late = TIPS + 'expect_stop = {reason = "chassis.tipping", during = [0.02, 0.04]}\n' + FINALLY
    code, out, _ = _check(tmp_path, late)
    assert code == 1 and "outside the window" in out
    quiet = ('scene = "elastic_pendulum"\nstop_time = 0.01\n'
             'expect_stop = {reason = "pendulum.lifted", during = [0.0, 0.01]}\n'
             '[[assert]]\ncolumn = "rope.tension"\nmax = 1e9\n')
    code, out, _ = _check(tmp_path, quiet)
    assert code == 1 and "reached its stop time 0.01 s without stopping" in out


def test_a_file_that_asserts_nothing_is_refused_before_anything_runs(tmp_path):
    from cranefmu.experiments.runner import prepare

    f = tmp_path / "empty.toml"
    f.write_text('scene = "elastic_pendulum"\nstop_time = 0.01\n')
    with pytest.raises(ExperimentError, match="asserts nothing"):
        prepare([f])
    code, out, _ = _check(tmp_path, 'scene = "elastic_pendulum"\nstop_time = 0.01\n')
    assert code == 2 and "asserts nothing" in out


def test_stop_when_none_in_a_file_as_on_the_command_line(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text('scene = "overhead_lift"\nstop_when = "none"\n[[assert]]\ncolumn = "rope.tension"\nmax = 1e9\n')
    assert load(f)[0].settings["stop_when"] == []
    f.write_text('scene = "overhead_lift"\nstop_when = "pendulum.lifted, rope.slack"\n'
                 '[[assert]]\ncolumn = "rope.tension"\nmax = 1e9\n')
    assert load(f)[0].settings["stop_when"] == ["pendulum.lifted", "rope.slack"]


@pytest.mark.parametrize("value, what", [
    ('{reason = "chassis.tipping"}', "needs reason"),
    ('{reason = "chassis.tipping", during = [2.0, 1.0]}', "0 <= t1 <= t2"),
    ('{reason = "chassis.tipping", during = [0, 1], when = 3}', "unknown key"),
    ('"chassis.tipping"', "a table"),
])
def test_bad_expect_stop_gets_one_line_with_file_and_line(tmp_path, value, what):
    f = tmp_path / "b.toml"
    f.write_text(f'scene = "truck_telescope"\nexpect_stop = {value}\n')
    with pytest.raises(ExperimentError, match=what) as err:
        load(f)
    assert str(err.value).startswith(f"{f}:2: ")


ASSERT = '[[assert]]\ncolumn = "rope.tension"\nmax = 1e9\n'


@pytest.mark.parametrize("text, line, message", [
    ('stop_time = 1.0\n' + ASSERT + '[[assert]]\ncolumn = "rope.tension"\nat = 5.0\nmax = 1e9\n', 8,
     r"at = 5 s is outside the run \(0 to 1 s\)"),
    ('stop_time = 1.0\n[[assert]]\ncolumn = "rope.tension"\nmin = 10\nmax = 1\n', 5, "min = 10 is above max = 1"),
    ('set = {"pendulum.mass" = nan}\n' + ASSERT, 2, "pendulum.mass = nan is not allowed: a finite number"),
    ('set = {"rope.n_lines" = 2.5}\n' + ASSERT, 2, "rope.n_lines = 2.5 is not a valid Integer value"),
    ('stop_time = 1.0\n[[assert]]\ncolumn = "rope.tension"\nduring = [0.5, 3.0]\nmax = 1e9\n', 5,
     r"during = \[0.5, 3\] s is not inside the run"),
    ('stop_time = nan\n' + ASSERT, 2, "stop_time = nan is not allowed"),
    ('stop_time = -1\n' + ASSERT, 2, "stop_time = -1 is not allowed"),
    ('stop_time = "10"\n' + ASSERT, 2, r"stop_time = '10' is not allowed: a number \(without quotes\)"),
    (ASSERT + '[[assert]]\nname = "rope_tension_1"\ncolumn = "rope.tension"\nmax = 1e9\n', 6,
     "two assertions of case base are named 'rope_tension_1'"),
    ('stop_time = 1.0\nexpect_stop = {reason = "rope.slack", during = [2.0, 3.0]}\n' + ASSERT, 3,
     "begins after the run's stop time 1 s"),
    (ASSERT + '[[commands]]\ninputs = "rope.payout"\nmoves = [{start = -1, to = 1, speed = 1}]\n', 7,
     "start = -1 s is not allowed"),
])
def test_experiment_mistakes_are_one_line_before_the_run(built, tmp_path, text, line, message):
    from cranefmu.experiments.runner import prepare

    f = tmp_path / "m.toml"
    f.write_text('scene = "elastic_pendulum"\n' + text)
    with pytest.raises(ExperimentError) as err:
        prepare([f])
    text = str(err.value)
    assert text.startswith(f"{f}:{line}: ") and "\n" not in text
    assert re.search(message, text), text


def test_an_unknown_scene_names_its_line(tmp_path):
    from cranefmu.experiments.runner import prepare

    f = tmp_path / "u.toml"
    f.write_text('# a comment\nscene = "nosuch"\n' + ASSERT)
    with pytest.raises(ExperimentError, match=f"^{f}:2: scene: scene 'nosuch' is unknown"):
        prepare([f])


def test_a_shaper_slower_than_the_run_is_refused(built, tmp_path):
    from cranefmu.experiments.runner import prepare

    f = tmp_path / "s.toml"
    f.write_text('scene = "elastic_pendulum"\nstop_time = 1.0\n' + ASSERT +
                 '[[commands]]\ninputs = "rope.payout"\nmoves = [{to = 1, speed = 1}]\n'
                 'shaper = "zv"\nfrequency = 1e-300\n')
    with pytest.raises(ExperimentError, match=r"frequency = 1e-300 Hz is not allowed: the shaper delays the move"):
        prepare([f])
