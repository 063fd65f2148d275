"""Units as engineers write them in experiment files (issue 37): quantities with units in limits, times and
moves, checked against the column's or input's declared unit; luff and slew angles outside the crane's
range refused before the run (a target typed in degrees as if radians)."""
from __future__ import annotations

import math
import re

import pytest

from cranefmu.adapter import units
from cranefmu.experiments.reader import ExperimentError, load

ASSERT = '[[assert]]\ncolumn = "rope.tension"\nmax = 1e9\n'


def test_a_quantity_is_its_value_in_si():
    assert units.quantity("15 kN") == (15000.0, "kN")
    assert units.quantity("90 deg") == (90 * 0.017453292519943295, "deg")
    assert units.quantity("2.5 t") == (2500.0, "t")
    assert units.quantity("300 ms") == (0.3, "ms")
    assert units.quantity("-1.5e2 N.m") == (-150.0, "N.m")
    assert not units.is_quantity("pendulum.mass * g") and not units.is_quantity("radians(90)")
    assert units.same_dimension("rpm", "rad/s") and not units.same_dimension("deg", "1")


def test_limits_times_and_moves_take_units(tmp_path):
    f = tmp_path / "q.toml"
    f.write_text('scene = "elastic_pendulum"\n[[assert]]\ncolumn = "rope.tension"\nat = "300 ms"\nmax = "15 kN"\n'
                 '[[commands]]\ninputs = "rope.payout"\nmoves = [{start = "1 s", to = "50 cm", speed = "0.2 m/s", '
                 'accel_time = "100 ms"}]\n')
    case = load(f)[0]
    a, c = case.assertions[0], case.commands[0]
    assert (a.at, a.max, a.quantities) == (0.3, 15000.0, {"max": "kN"})
    assert c.moves[0] == {"start": 1.0, "to": 0.5, "speed": 0.2, "accel_time": 0.1}
    assert c.quantities == {"to": "cm", "speed": "m/s"}


def test_a_move_value_may_be_an_expression_of_constants(tmp_path):
    f = tmp_path / "e.toml"
    f.write_text('scene = "elastic_pendulum"\n' + ASSERT +
                 '[[commands]]\ninputs = "rope.payout"\nmoves = [{to = "radians(90) / 10", speed = 1}]\n')
    assert load(f)[0].commands[0].moves[0]["to"] == math.radians(90) / 10


@pytest.mark.parametrize("text, line, message", [
    ('[[assert]]\ncolumn = "rope.tension"\nmax = "15 m"\n', 4, "max in 'm' does not fit column rope.tension, which is in N"),
    ('[[assert]]\ncolumn = "rope.tension"\nat = "3 N"\nmax = 1\n', 4, "at = '3 N' is not allowed: at is in s"),
    ('[[assert]]\ncolumn = "rope.tension"\nmetric = "frequency"\nequals = "1.5 m"\nrel = 0.1\n', 5,
     "equals in 'm' does not fit metric frequency of column rope.tension, which is in Hz"),
    (ASSERT + '[[commands]]\ninputs = "rope.payout"\nmoves = [{to = "50 deg", speed = 1}]\n', 7,
     "to in 'deg' does not fit input rope.payout, which is in m"),
    (ASSERT + '[[commands]]\ninputs = "rope.payout"\nmoves = [{to = 1, speed = "1 m"}]\n', 7,
     "speed in 'm' does not fit input rope.payout, which is in m per s"),
])
def test_a_unit_that_does_not_fit_is_one_line(built, tmp_path, text, line, message):
    from cranefmu.experiments.runner import prepare

    f = tmp_path / "u.toml"
    f.write_text('scene = "elastic_pendulum"\n' + text)
    with pytest.raises(ExperimentError) as err:
        prepare([f])
    assert str(err.value).startswith(f"{f}:{line}: ") and re.search(re.escape(message), str(err.value)), err.value


@pytest.mark.parametrize("scene, kind, to, message", [
    ("truck_telescope", "luff", "45.0", "luff angle 45 rad (2578.31 deg) is outside the boom's luffing range"),
    ("truck_telescope", "luff", '"105 deg"', "luff angle 1.8326 rad (105 deg) is outside the boom's luffing range"),
    ("truck_slewing", "slew", "90", "slew angle 90 rad (5156.62 deg) is outside one turn either way"),
])
def test_an_angle_typed_in_degrees_as_radians_is_refused_before_the_run(built, tmp_path, scene, kind, to, message):
    from cranefmu.experiments.runner import prepare

    f = tmp_path / "a.toml"
    f.write_text(f'scene = "{scene}"\nstop_time = 1.0\n[[commands]]\nkind = "{kind}"\n'
                 f'moves = [{{to = {to}, speed = 0.1}}]\n[[assert]]\ncolumn = "pendulum.x"\nmax = 1e9\n')
    with pytest.raises(ExperimentError) as err:
        prepare([f])
    assert str(err.value).startswith(f"{f}:5: moves: ") and message in str(err.value), err.value


def test_the_report_table_shows_units(built, tmp_path):
    import subprocess
    import sys

    f = tmp_path / "t.toml"
    f.write_text('scene = "elastic_pendulum"\nstop_time = 0.05\n[[assert]]\ncolumn = "rope.tension"\nmax = "15 kN"\n')
    out = subprocess.run([sys.executable, "-m", "cranefmu.cli", "check", str(f), "--quiet"], capture_output=True,
                         text=True, timeout=120).stdout
    assert re.search(r"\d N @ 0.05 s\s+<= 15000 N\s+\d+(\.\d+)? N\s+pass", out), out
