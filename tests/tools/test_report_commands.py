"""Operator commands in the HTML report (issue 37: "operator commands are not plotted in the report"): each
command plotted as the operator commanded it, in the quantity's unit, beside the output it drives; events and
emergency stops marked where the run found them; headless Chromium shows the command's value at the slider's
time equal to the closed form of the move and to the CSV's output."""
import html as html_text
import json
import math
import re

import numpy as np
import pytest

from cli_process import cranefmu
from cranefmu.experiments.events import RateOf, Trigger, Triggered
from cranefmu.experiments.profiles import moves, shifted
from cranefmu.master.commands import Command
from cranefmu.master.results import read_csv
from cranefmu.report.commands import command_columns, command_plots
from cranefmu.report.page import plot_specs

from test_report import CHROMIUM, _data, _open, needs_chromium


def _trapezoid(t, t0, x0, dist, v, ramp):
    """A symmetric speed trapezoid from x0 at t0 over dist with speed v and ramps of ``ramp`` s (value, rate)."""
    a = v / ramp
    cruise = dist / v - ramp
    s = t - t0
    if s <= 0:
        return x0, 0.0
    if s < ramp:
        return x0 + a * s * s / 2, a * s
    if s < ramp + cruise:
        return x0 + a * ramp ** 2 / 2 + v * (s - ramp), v
    if s < 2 * ramp + cruise:
        r = 2 * ramp + cruise - s
        return x0 + dist - a * r * r / 2, a * r
    return x0 + dist, 0.0


def _stopped(t, te, xe, ve, ramp):
    """Brought to rest from (xe, ve) at te with constant deceleration over ``ramp`` s."""
    s = min(t - te, ramp)
    return xe + ve * s - ve * s * s / (2 * ramp)


def test_a_slew_command_stopped_by_an_emergency_stop_is_plotted_in_degrees_beside_the_slewing_angle():
    """The input is sigma - slew_angle_start: the start (0.3 rad) is added back; the emergency stop's event is
    found again on the rows (the first row where the angle passes 0.35 rad: 1.21 s) and marked."""
    start, t = 0.3, np.arange(401) * 0.01
    law = np.array([_trapezoid(x, 0.5, start, 0.5, 0.2, 1.0)[0] for x in t])
    te = float(t[np.argmax(law > 0.35)])
    assert te == pytest.approx(1.21, abs=1e-12)
    xe, ve = _trapezoid(te, 0.5, start, 0.5, 0.2, 1.0)
    sigma = np.where(t < te, law, [_stopped(x, te, xe, ve, 0.5) for x in t])
    rows = np.zeros(len(t), dtype=[("time", float), ("boom.slew_angle_out", float), ("chassis.N3", float)])
    rows["time"], rows["boom.slew_angle_out"] = t, sigma   # a kinematic slewing boom follows its command
    profile = shifted(moves(start, [{"start": 0.5, "to": start + 0.5, "speed": 0.2, "accel_time": 1.0}]), -start)
    source = Triggered(profile, Trigger("boom.slew_angle_out > 0.35", {}, "emergency stop"), "stop", 0.5)
    commands = [Command("boom.slew_command", source)]
    assert command_columns(commands, list(rows.dtype.names)) == ["boom.slew_angle_out"]
    cp = command_plots(commands, rows, {"boom.slew_command": "rad", "boom.slew_angle_out": "rad"},
                       {"boom.slew_angle_start": start})
    assert source.watcher.t_event is None   # the caller's source is left as it was
    (title, names), = cp.groups
    assert names == ["command: boom.slew_angle_start + boom.slew_command", "boom.slew_angle_out"]
    assert np.max(np.abs(cp.values[names[0]] - sigma)) < 1e-12
    assert cp.marks[title] == [(te, "emergency stop: boom.slew_angle_out > 0.35")]
    spec, = plot_specs(rows, cp.groups, cp.units, extra=cp.values, dashed=cp.dashed, marks=cp.marks)
    assert spec["ylabel"] == "angle [deg]" and spec["marks"] == [{"t": 1.21, "label": cp.marks[title][0][1]}]
    command, output = spec["series"]
    assert command["dash"] is True and "dash" not in output
    assert command["v"] == pytest.approx(np.degrees(sigma), rel=1e-5, abs=1e-12)   # 6 digits
    assert command["v"][-1] == pytest.approx(math.degrees(xe + ve * 0.25), rel=1e-5)   # at rest after the ramp


def test_a_payout_started_by_an_event_and_its_rate_are_plotted_from_the_event():
    """A lowering command with asymmetric ramps started when the sway first crosses zero: the payout [m] beside
    the rope length's change, its rate [m/s] alone (no output shows it), both zero before the event."""
    t = np.arange(301) * 0.01
    rows = np.zeros(len(t), dtype=[("time", float), ("pendulum.theta", float), ("rope.rope_length", float)])
    rows["time"], rows["pendulum.theta"] = t, 0.1 * np.cos(math.pi / 2 * t / 1.0)   # crosses zero at 1 s
    rows["rope.rope_length"] = 10.0
    profile = moves(0.0, [{"start": 0.2, "to": 0.3, "speed": 0.2, "accel_time": 0.5, "decel_time": 0.25}])
    source = Triggered(profile, Trigger("pendulum.theta < 0", {}, "lower.toml:7"))
    commands = [Command("rope.payout", source), Command("rope.payout_rate", RateOf(source))]
    cp = command_plots(commands, rows, {"rope.payout": "m", "rope.payout_rate": "m/s", "rope.rope_length": "m"})
    te = float(t[np.argmax(rows["pendulum.theta"] < 0)])
    assert te == pytest.approx(1.01, abs=1e-12)
    (t1, n1), (t2, n2) = cp.groups
    assert n1 == ["command: rope.payout", "rope.rope_length - its start"] and n2 == ["command: rope.payout_rate"]
    assert cp.marks[t1] == cp.marks[t2] == [(te, "event: pendulum.theta < 0")]
    # 0.3 m at 0.2 m/s, 0.5 s up (0.4 m/s2), 0.25 s down (0.8 m/s2): 0.05 + 0.025 on the ramps, 1.125 s cruise
    s = t - te - 0.2
    rate = np.where(s < 0, 0.0, np.where(s < 0.5, 0.4 * s, np.where(s < 1.625, 0.2,
                                                                    np.maximum(0.0, 0.2 - 0.8 * (s - 1.625)))))
    pay = np.where(s < 0, 0.0, np.where(s < 0.5, 0.2 * s * s, np.where(
        s < 1.625, 0.05 + 0.2 * (s - 0.5), np.where(s < 1.875, 0.3 - 0.4 * (1.875 - s) ** 2, 0.3))))
    assert np.max(np.abs(cp.values[n1[0]] - pay)) < 1e-12 and np.max(np.abs(cp.values[n2[0]] - rate)) < 1e-12
    assert cp.units == {n1[0]: "m", n1[1]: "m", n2[0]: "m/s"}
    assert any("rope.payout_rate: no output" in n for n in cp.notes)
    assert command_columns(commands, ["rope.tension", "pendulum.theta", "rope.rope_length"]) == [
        "pendulum.theta", "rope.rope_length"]


def test_one_profile_fed_to_two_inputs_is_one_plot_and_a_slewing_boom_luff_is_shown_from_its_radius():
    """anti_sway_trolley feeds rope.x_top and pendulum.x_top one profile: one plot, beside the suspension point;
    a SlewingBoom has no luff_angle_out: the luff command beside acos(radius / length)."""
    t = np.arange(201) * 0.01
    names = ("time", "pendulum.x_suspension", "boom.radius", "boom.boom_length")
    rows = np.zeros(len(t), dtype=[(c, float) for c in names])
    phi = math.radians(60.0) + 0.1 * t
    rows["time"], rows["boom.boom_length"], rows["boom.radius"] = t, 10.5, 10.5 * np.cos(phi)
    travel = moves(0.0, [{"start": 0.5, "to": 1.0, "speed": 1.0, "accel_time": 0.5}])
    rows["pendulum.x_suspension"] = [travel.at(x)[0] for x in t]
    luff = shifted(moves(math.radians(60.0), [{"start": 0.0, "to": math.radians(62.0), "speed": 0.1,
                                               "accel_time": 0.0}]), -math.radians(60.0))
    commands = [Command("rope.x_top", travel), Command("pendulum.x_top", travel), Command("boom.luff_command", luff)]
    assert command_columns(commands, list(names)) == list(names[1:])
    cp = command_plots(commands, rows, {"rope.x_top": "m", "boom.luff_command": "rad"},
                       {"boom.luff_angle": math.radians(60.0)})
    (_, trolley), (_, boom) = cp.groups
    assert trolley == ["command: rope.x_top, pendulum.x_top", "pendulum.x_suspension"]
    assert boom == ["command: boom.luff_angle + boom.luff_command", "acos(boom.radius / boom.boom_length)"]
    assert np.max(np.abs(cp.values[boom[1]] - phi)) < 1e-12
    assert np.max(np.abs(cp.values[boom[0]] - np.minimum(phi, math.radians(62.0)))) < 1e-12   # 0.1 rad/s to 62 deg
    assert cp.units[boom[0]] == cp.units[boom[1]] == "rad"


def test_a_command_whose_event_reads_a_column_the_result_lacks_is_said_not_plotted():
    rows = np.zeros(3, dtype=[("time", float), ("boom.slew_angle_out", float)])
    source = Triggered(moves(0.0, [{"start": 0.0, "to": 1.0, "speed": 1.0, "accel_time": 0.0}]),
                       Trigger("chassis.N3 < 10000", {}, "f.toml:3"), "stop")
    cp = command_plots([Command("boom.slew_command", source)], rows, {})
    assert cp.groups == [] and cp.notes == ["command on boom.slew_command not plotted: its event condition reads "
                                           "chassis.N3, which the result does not hold"]


SLEW = ('name = "slew_estop"\nscene = "truck_slewing"\nstop_time = 3.0\n'
        'emergency_stop = {when = "boom.slew_angle_out > 5 deg", ramp = "0.5 s"}\n'
        '[[commands]]\nkind = "slew"\nmoves = [{start = 0.5, to = "20 deg", speed = "10 deg/s", accel_time = 0.5}]\n'
        '[[assert]]\nname = "slewed"\ncolumn = "boom.slew_angle_out"\nfinally = true\nmax = "20 deg"\n')


@pytest.fixture(scope="module")
def slew_run(built, tmp_path_factory):
    """truck_slewing slewed from over the rear towards 20 deg at 10 deg/s, emergency-stopped over 0.5 s when the
    angle passes 5 deg (3 s, about 2 s of wall time)."""
    where = tmp_path_factory.mktemp("slew")
    (where / "slew.toml").write_text(SLEW)
    p = cranefmu("run", str(where / "slew.toml"), "--output", str(where / "s.csv"), "--report", str(where / "s.html"))
    assert p.returncode == 0, p.stderr
    return read_csv(where / "s.csv"), where / "s.html"


def _slew_command_deg(t: float, te: float) -> float:
    """The slew command [deg]: a trapezoid from 0.5 s (20 deg/s2 for 0.5 s, then 10 deg/s), stopped at te over
    0.5 s."""
    xe, ve = _trapezoid(te, 0.5, 0.0, 20.0, 10.0, 0.5)
    return _trapezoid(t, 0.5, 0.0, 20.0, 10.0, 0.5)[0] if t < te else _stopped(t, te, xe, ve, 0.5)


def test_the_report_plots_the_slew_command_at_every_row_where_the_boom_slewed(slew_run):
    rows, html = slew_run
    plot = next(p for p in _data(html.read_text())["plots"] if p["title"].startswith("Operator command"))
    assert plot["title"] == "Operator command on boom.slew_command beside the output it drives"
    assert plot["ylabel"] == "angle [deg]" and [s["name"] for s in plot["series"]] == [
        "command: boom.slew_angle_start + boom.slew_command", "boom.slew_angle_out"]
    te = float(rows["time"][np.argmax(rows["boom.slew_angle_out"] > math.radians(5.0))])
    assert te == pytest.approx(1.255, abs=1e-9)   # 2.5 deg by 1 s, then 10 deg/s: 5 deg at 1.25 s, passed at 1.255
    (mark,) = plot["marks"]
    assert mark["t"] == pytest.approx(te, abs=1e-9) and mark["label"] == "emergency stop: boom.slew_angle_out > 5 deg"
    command = np.array(plot["series"][0]["v"])
    assert len(command) == len(rows)
    # the kinematic slewing boom follows its command: the command is the CSV's angle at every row, and the
    # closed form of the move stopped at the event
    assert command == pytest.approx(np.degrees(rows["boom.slew_angle_out"]), rel=1e-5, abs=1e-9)
    assert command == pytest.approx([_slew_command_deg(x, te) for x in rows["time"]], rel=1e-5, abs=1e-6)
    assert command[-1] == pytest.approx(7.55, rel=1e-6)   # 5.05 deg at the event + 10 deg/s x 0.5 s / 2


@needs_chromium
def test_headless_chromium_shows_the_command_at_the_slider_time(slew_run, tmp_path):
    rows, html = slew_run
    for t in (0.75, 1.255, 1.5, 2.9):
        dom = _open(html, t, tmp_path / "profile")
        svg = next(s for s in re.findall(r"<svg[^>]*id=\"plot-\d+\"[^>]*>.*?</svg>", dom, re.S)
                   if "command: boom.slew_angle_start + boom.slew_command" in s)
        head = re.search(r"<svg[^>]*>", svg).group(0)
        i = int(np.argmin(np.abs(rows["time"] - t)))
        assert float(re.search(r'data-cursor-t="([^"]+)"', head).group(1)) == pytest.approx(rows["time"][i], abs=1e-12)
        at = json.loads(html_text.unescape(re.search(r'data-cursor="([^"]+)"', head).group(1)))
        te = 1.255
        assert at["command: boom.slew_angle_start + boom.slew_command"] == pytest.approx(
            _slew_command_deg(float(rows["time"][i]), te), rel=1e-5, abs=1e-6), t
        assert at["boom.slew_angle_out"] == pytest.approx(math.degrees(rows["boom.slew_angle_out"][i]), rel=1e-5,
                                                          abs=1e-9)
        assert re.search(r'<polyline[^>]*stroke-dasharray="7 4"[^>]*class="command"', svg)   # dashed, drawn
        assert "emergency stop: boom.slew_angle_out &gt; 5 deg (t = 1.255 s)</text>" in svg
        assert "angle [deg]</text>" in svg
        assert float(re.search(r'data-legend-right="([^"]+)"', head).group(1)) <= float(
            re.search(r'width="([^"]+)"', head).group(1))   # the two long names inside the plot


TIPS = ('name = "tips"\nscene = "truck_telescope"\nstop_time = 0.04\n'
        'set = {"boom.luff_angle" = 1.0471975511965976, "boom.boom_length_start" = 26.96, '
        '"boom.boom_length_end" = 26.96, "boom.seg4_offset" = 8.23, "boom.seg3_offset" = 16.46, '
        '"pendulum.mass" = 3500.0}\n'
        'expect_stop = {reason = "chassis.tipping", during = [0.0, 0.04]}\n')


def test_every_plot_marks_where_a_run_stopped_early_and_why(built, tmp_path):
    (tmp_path / "tips.toml").write_text(TIPS)
    p = cranefmu("run", str(tmp_path / "tips.toml"), "--output", str(tmp_path / "t.csv"),
                 "--report", str(tmp_path / "t.html"))
    assert p.returncode == 0, p.stderr
    rows = read_csv(tmp_path / "t.csv")
    plots = _data((tmp_path / "t.html").read_text())["plots"]
    assert plots and all(len(p["marks"]) == 1 for p in plots)
    assert all(p["marks"][0]["t"] == pytest.approx(float(rows["time"][-1]), abs=1e-9) for p in plots)
    assert all(p["marks"][0]["label"].startswith("run stopped: chassis.tipping = 1") for p in plots)


def test_a_plain_run_that_stops_early_says_why_under_the_title(built, tmp_path):
    """Not only an experiment's verdict: a run of a scene that tips says so before the crane is drawn."""
    sets = ["boom.luff_angle=1.0471975511965976", "boom.boom_length_start=26.96", "boom.boom_length_end=26.96",
            "boom.seg4_offset=8.23", "boom.seg3_offset=16.46", "pendulum.mass=3500.0"]
    p = cranefmu("run", "truck_telescope", "--stop-time", "0.04", "--report", str(tmp_path / "r.html"),
                 *(a for v in sets for a in ("--set", v)))
    assert p.returncode == 0, p.stderr
    text = (tmp_path / "r.html").read_text()
    assert text.index("<p class='stop' id='stopped'>The run stopped early: stopped at t = 0 s: chassis.tipping = 1") \
        < text.index("<h2>The crane</h2>")
