"""The HTML run report: decimation keeps the extremes, the file needs no network, a 1e6-row run gives a few MB,
the command line writes it, and headless Chromium draws the hook where the CSV says it is."""
import json
import math
import re

import numpy as np
import pytest

from cli_process import cranefmu
from cranefmu.master.results import read_csv
from cranefmu.report import write_report
from cranefmu.report.decimate import extremes, frames

SVG_NAMESPACE = "http://www.w3.org/2000/svg"   # an XML name createElementNS needs; never fetched


def _data(text: str) -> dict:
    blob = re.search(r'<script type="application/json" id="report-data">(.*?)</script>', text, re.S).group(1)
    return json.loads(blob.replace("<\\/", "</"))


def test_extremes_keep_every_bucket_min_and_max():
    rng = np.random.default_rng(1)
    v = rng.normal(size=100_003)
    v[[17, 50_000, 99_999]] = [40.0, -55.0, 33.0]   # one-row spikes
    v[70_000] = np.nan
    keep = extremes(v, buckets=100)
    assert len(keep) <= 2 * 100 + 2 and keep[0] == 0 and keep[-1] == len(v) - 1
    assert {17, 50_000, 99_999} <= set(keep.tolist())
    size = -(-len(v) // 100)
    for b in range(100):   # each bucket's smallest and largest value is among the kept rows
        part = v[b * size:(b + 1) * size]
        kept = v[keep[(keep >= b * size) & (keep < (b + 1) * size)]]
        assert np.nanmax(kept) == np.nanmax(part) and np.nanmin(kept) == np.nanmin(part)
    assert np.array_equal(extremes(v[:150], buckets=100), np.arange(150))   # short: every row


def test_frames_are_every_row_up_to_the_limit_then_evenly_spaced():
    assert np.array_equal(frames(10, limit=20), np.arange(10))
    f = frames(1_000_000, limit=2000)
    assert len(f) == 2000 and f[0] == 0 and f[-1] == 999_999
    assert np.ptp(np.diff(f)) <= 1


def _synthetic(n: int) -> np.ndarray:
    """An elastic_pendulum-shaped result: a 10 m pendulum swinging at its own period, with a tension spike."""
    t = np.linspace(0.0, 1000.0, n)
    theta = 0.1 * np.cos(math.sqrt(9.81 / 10) * t)
    cols = {"time": t, "rope.tension": 9810 * (1 + 0.01 * np.cos(2 * t)), "pendulum.x": 10 * np.sin(theta),
            "pendulum.y": -10 * np.cos(theta), "pendulum.theta": theta, "bond.hook.E": 1e-3 * t}
    cols["rope.tension"][n // 3] = 20000.0
    for a in "xyz":
        cols[f"pendulum.{a}_suspension"] = np.zeros(n)
        cols[f"pendulum.{a}_payload"] = cols.get(f"pendulum.{a}", np.zeros(n))
    cols["pendulum.rest_tension"] = np.full(n, 9810.0)
    out = np.zeros(n, dtype=[(c, float) for c in cols])
    for c, v in cols.items():
        out[c] = v
    return out


def test_report_of_a_million_rows_is_a_few_mb_and_keeps_the_peak(tmp_path):
    units = {"rope.tension": "N", "pendulum.theta": "rad", "bond.hook.E": "J"}
    path = write_report(tmp_path / "big.html", _synthetic(1_000_000), scene="elastic_pendulum", units=units)
    size = path.stat().st_size
    assert size < 3e6, size
    data = _data(path.read_text())
    tension = next(p for p in data["plots"] if p["series"][0]["name"] == "rope.tension")["series"][0]
    assert max(tension["v"]) == 20.0   # kN
    theta = next(p for p in data["plots"] if p["series"][0]["name"] == "pendulum.theta")
    assert theta["unit"] == "deg" and max(theta["series"][0]["v"]) == pytest.approx(0.1 * 180 / math.pi, rel=1e-5)
    assert 2000 <= len(data["frames"]["t"]) <= 20_000


def test_hoisting_a_grounded_load_draws_the_en13001_phi2_band():
    from cranefmu.report import _reference_lines

    r = np.zeros(3, dtype=[(c, float) for c in ("time", "rope.tension", "pendulum.rest_tension", "pendulum.N_ground",
                                                "drive.payout_rate")])
    r["pendulum.rest_tension"], r["pendulum.N_ground"], r["drive.payout_rate"] = 100.0, [900.0, 0, 0], [0, -0.5, -1]
    lines = dict(_reference_lines(r)["rope.tension"][i][::-1] for i in range(3))
    assert sorted(lines) == pytest.approx([1000.0, (1.05 + 0.17) * 1000.0, (1.20 + 0.68) * 1000.0])
    from cranefmu.report import report_columns   # a report from a CSV reads the columns the band needs

    assert set(report_columns("overhead_lift", [c for c in r.dtype.names if c != "time"])) >= set(r.dtype.names[1:])


def test_the_phi2_band_takes_the_hook_speed_not_the_rope_speed_at_the_drum():
    """Four falls: the drum pays out 0.874 m/s of rope for a 0.2185 m/s hook (issue 37: HC4 was drawn at 1.79
    for overhead_lift's loose lift, it is 1.20 + 0.68 * 0.2185 = 1.349)."""
    from cranefmu.report import _reference_lines

    names = ("time", "rope.tension", "rope.drum_force", "pendulum.rest_tension", "pendulum.N_ground", "drive.payout_rate")
    r = np.zeros(3, dtype=[(c, float) for c in names])
    r["pendulum.rest_tension"], r["pendulum.N_ground"], r["drive.payout_rate"] = 100.0, [900.0, 0, 0], [0, -0.4, -0.874]
    r["rope.tension"], r["rope.drum_force"] = [100.0, 400.0, 1000.0], [25.0, 100.0, 250.0]
    lines = {label: value for label, value in _reference_lines(r)["rope.tension"]}
    hc4 = next(v for k, v in lines.items() if "HC4" in k)
    assert hc4 == pytest.approx((1.20 + 0.68 * 0.874 / 4) * 1000.0, rel=1e-12)
    assert any("hook v_h 0.218 m/s" in k for k in lines)


def test_axes_say_the_unit_in_degrees_or_that_it_is_not_known():
    from cranefmu.report.page import plot_specs

    r = np.zeros(3, dtype=[("time", float), ("a.F", float), ("b.theta", float), ("c.n", float)])
    r["b.theta"] = [0.0, math.pi / 2, 0.0]
    specs = plot_specs(r, [("g", ["a.F", "b.theta", "c.n"])], {"b.theta": "rad", "c.n": ""})
    assert [p["ylabel"] for p in specs] == ["value [unit unknown]", "angle [deg]", "ratio [1]"]
    assert max(specs[1]["series"][0]["v"]) == 90.0


def test_forces_in_kn_moments_in_kn_m_and_drive_speeds_in_rpm_with_their_quantity():
    """Issue 37: force axes showed 100000-N ticks without a quantity; motor speed was in deg/s."""
    from cranefmu.report.page import plot_specs

    names = ("time", "rope.tension", "boom.Mz_base", "drive.motor_speed", "boom.slew_rate")
    r = np.zeros(2, dtype=[(c, float) for c in names])
    r["rope.tension"], r["boom.Mz_base"], r["drive.motor_speed"], r["boom.slew_rate"] = (
        [109128.0, 72800.0], [2.0e5, 0.0], [2 * math.pi * 25.0, 0.0], [0.1, 0.0])
    units = {"rope.tension": "N", "boom.Mz_base": "N.m", "drive.motor_speed": "rad/s", "boom.slew_rate": "rad/s"}
    specs = {p["series"][0]["name"]: p for p in plot_specs(r, [(c, [c]) for c in names[1:]], units)}
    assert specs["rope.tension"]["ylabel"] == "force [kN]" and specs["rope.tension"]["series"][0]["v"] == [109.128, 72.8]
    assert specs["boom.Mz_base"]["ylabel"] == "moment [kN.m]" and specs["boom.Mz_base"]["series"][0]["v"][0] == 200.0
    assert specs["drive.motor_speed"]["ylabel"] == "rotational speed [rpm]"
    assert specs["drive.motor_speed"]["series"][0]["v"][0] == pytest.approx(1500.0, rel=1e-12)
    assert specs["boom.slew_rate"]["ylabel"] == "angular speed [deg/s]"   # not a drive: degrees


def test_truck_slewing_draws_the_slewing_boom_and_four_pads_from_their_own_outputs():
    """SlewingBoom has no luff_angle_out and Chassis4 no N_front (issue 37: the boom was drawn as a horizontal
    bar at the tip's height, no chassis): the foot from the radius and slewing angle, the pads from q1-q4."""
    from cranefmu.physics.chassis4 import Chassis4Params, pad_positions
    from cranefmu.report.drawing import LEG, draw

    names = ["time", "boom.x_tip", "boom.y_tip", "boom.z_tip", "boom.boom_length", "boom.radius",
             "boom.slew_angle_out", "chassis.y_base", "chassis.gamma", "chassis.beta"]
    names += [f"chassis.{v}{i}" for v in "qN" for i in range(1, 5)]
    r = np.zeros(1, dtype=[(c, float) for c in names])
    L, psi, sig, yb = 10.5, math.radians(60.0), math.radians(40.0), -0.002
    r["boom.boom_length"], r["boom.radius"], r["boom.slew_angle_out"], r["chassis.y_base"] = L, L * math.cos(psi), sig, yb
    r["boom.x_tip"], r["boom.z_tip"] = L * math.cos(psi) * math.cos(sig), L * math.cos(psi) * math.sin(sig)
    r["boom.y_tip"] = yb + L * math.sin(psi)
    for i in range(1, 5):
        r[f"chassis.q{i}"], r[f"chassis.N{i}"] = 0.001 * i, 1000.0 * i
    d = draw(r)
    foot = [float(v[0]) for v in d.points["boom_foot"]]
    assert foot == pytest.approx([0.0, yb, 0.0], abs=1e-12)   # the slewing axis, at the chassis' heave
    xs, zs = pad_positions(Chassis4Params())
    for i in range(1, 5):
        assert [float(v[0]) for v in d.points[f"pad{i}"]] == pytest.approx([xs[i - 1], -LEG - 0.001 * i, zs[i - 1]])
        assert d.forces[f"N{i}"][0] == 1000.0 * i
    kinds = [(e["kind"], e.get("cls")) for e in d.elements]
    assert kinds.count(("pad", None)) == 4 and kinds.count(("arrow", None)) == 4 and ("line", "boom") in kinds
    assert d.elements[0] == {"kind": "ground", "y": -LEG} and d.three_d


def _no_external_reference(text: str) -> None:
    assert set(re.findall(r"https?://[^\s\"'<>)]*", text)) <= {SVG_NAMESPACE}
    assert not re.search(r"\b(src|href)\s*=|url\(|@import", text, re.I)


@pytest.fixture(scope="module")
def pendulum_run(built, tmp_path_factory):
    """elastic_pendulum for 2 s through the CLI, with --report; and the CSV's report by ``cranefmu report``."""
    where = tmp_path_factory.mktemp("report")
    csv_path, html = where / "ep.csv", where / "ep.html"
    p = cranefmu("run", "elastic_pendulum", "--stop-time", "2", "--step", "1e-3", "--output", str(csv_path),
                 "--report", str(html))
    assert p.returncode == 0, p.stderr
    q = cranefmu("report", str(csv_path), "--output", str(where / "from_csv.html"))
    assert q.returncode == 0, q.stderr
    return csv_path, html, where / "from_csv.html"


def test_run_and_csv_reports_are_self_contained_and_draw_the_same_crane(pendulum_run):
    csv_path, html, from_csv = pendulum_run
    run_text, csv_text = html.read_text(), from_csv.read_text()
    for text in (run_text, csv_text):
        _no_external_reference(text)
    a, b = _data(run_text), _data(csv_text)
    assert a["frames"] == b["frames"] and a["elements"] == b["elements"]
    rows = read_csv(csv_path)
    assert len(a["frames"]["t"]) == len(rows)
    assert a["frames"]["points"]["hook"][0][700] == float(f"{rows['pendulum.x'][700]:.6g}")
    assert "<td>step_size</td><td>0.001</td><td>given</td>" in run_text   # each setting with where it came from
    assert "<td>start_time</td><td>0.0</td><td>default</td>" in run_text
    assert "power bond hook" in run_text and "not known (the report was made from a result file)" in csv_text


def test_bad_report_input_exits_2_naming_it(built, tmp_path):
    no_time = tmp_path / "no_time.csv"
    no_time.write_text("a,b\n1,2\n")
    for args, needle in [(["report", str(tmp_path / "absent.csv")], "absent.csv cannot be read"),
                         (["report", str(no_time)], "no time column"),
                         (["report", str(no_time), "--output", str(tmp_path / "nodir" / "r.html")], "nodir"),
                         (["run", "elastic_pendulum", "--stop-time", "0.1", "--report",
                           str(tmp_path / "nodir" / "r.html")], "--report")]:
        p = cranefmu(*args)
        assert p.returncode == 2, (args, p.stderr)
        assert needle in p.stderr and "Traceback" not in p.stderr, p.stderr


def test_a_run_streamed_to_its_csv_is_reported_from_the_csv(pendulum_run, tmp_path):
    """More than 1e6 rows are not kept in memory: the report reads them back from the run's CSV."""
    from types import SimpleNamespace

    from cranefmu.master.run import preview
    from cranefmu.report.command import report_after_run

    csv_path, html, _ = pendulum_run
    streamed = SimpleNamespace(result=np.zeros(0, dtype=[("time", float)]), output=csv_path, scene="elastic_pendulum",
                               settings=None, stats=None, warnings=["a warning"])
    text = report_after_run(tmp_path / "s.html", streamed, preview("elastic_pendulum")).read_text()
    assert _data(text)["frames"] == _data(html.read_text())["frames"] and "a warning" in text


CHROMIUM = "/usr/bin/chromium"
# scene -> (stop time [s], what its drawing must hold: (element class, count), --set values)
DRAWN = {"elastic_pendulum": (None, [("rope", 1), ("anchor", 1)], ()),
         "hook_sway": (0.5, [("rope", 4), ("boom", 4), ("payload", 4)], ()),   # side, top, two close-ups
         "overhead_lift": (0.5, [("rope", 1), ("girder", 2), ("trolley", 1), ("ground", 1)], ()),
         "truck_telescope": (0.5, [("rope", 1), ("boom", 1), ("body", 1), ("arrow", 2), ("pad", 2), ("leg", 2)], ()),
         # slewed to 40 deg and luffed at 60: side and top views, four pads and their reactions in the side view
         "truck_slewing": (0.3, [("rope", 2), ("boom", 2), ("body", 2), ("arrow", 4), ("pad", 8), ("leg", 8),
                                 ("beam", 4)], ("boom.slew_angle_start=0.6981317007977318",))}


def _open(html, t: float, profile) -> str:
    import subprocess

    p = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                        "--disable-component-update", "--disable-sync", "--no-first-run", f"--user-data-dir={profile}",
                        "--enable-logging=stderr", "--v=0", "--dump-dom", f"{html.as_uri()}#t={t}"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-2000:]
    assert "CONSOLE" not in p.stderr and "Uncaught" not in p.stderr, p.stderr[-2000:]   # the page logs nothing
    assert 'data-ready="1"' in p.stdout
    return p.stdout


def _check_hook(dom: str, rows, t: float) -> None:
    """The hook drawn for the slider's frame is where the CSV row at that time puts it."""
    side = re.search(r'<svg[^>]*id="view-side"[^>]*>', dom).group(0)
    attr = dict(re.findall(r'data-([a-z-]+)="([^"]*)"', side))
    i = int(np.argmin(np.abs(rows["time"] - t)))
    assert float(attr["t"]) == pytest.approx(rows["time"][i], abs=1e-12)
    assert float(attr["hook-x"]) == pytest.approx(rows["pendulum.x"][i], rel=1e-5, abs=1e-6)
    assert float(attr["hook-y"]) == pytest.approx(rows["pendulum.y"][i], rel=1e-5, abs=1e-6)
    assert 'id="drawn-hook"' in dom
    plots = re.findall(r'<svg[^>]*id="plot-\d+".*?</svg>', dom, re.S)
    assert plots and all("time [s]</text>" in p and re.search(r">[a-z ]+ \[[^\]]+\]</text>", p) for p in plots)
    assert "[rad]" not in dom and "[N]" not in dom   # angles in degrees, forces in kN
    for p in plots:   # the legend inside the plot (issue 37: an entry was cut at its edge)
        svg = re.search(r"<svg[^>]*>", p).group(0)
        assert float(re.search(r'data-legend-right="([^"]+)"', svg).group(1)) <= float(
            re.search(r'width="([^"]+)"', svg).group(1))
        ticks = re.findall(r'class="ytick">(-?[\d.]+)</text>', p)   # uniform number formatting per axis
        assert ticks and len({len(t.partition(".")[2]) for t in ticks}) == 1, ticks
    views = re.findall(r'<svg[^>]*class="view"', dom)
    assert len(re.findall(r'class="scalebar"', dom)) == len(views)   # a scale bar in every crane view


needs_chromium = pytest.mark.skipif(not __import__("os").path.exists(CHROMIUM),
                                    reason="no /usr/bin/chromium (Debian package chromium; .ci/run installs it)")


@needs_chromium
def test_headless_chromium_draws_the_hook_at_the_csv_position(pendulum_run, tmp_path):
    csv_path, html, _ = pendulum_run
    rows = read_csv(csv_path)
    for t in (0.0, 1.0, 1.537):
        dom = _open(html, t, tmp_path / "profile")
        _check_hook(dom, rows, t)
        assert dom.count("<polyline") >= 3   # tension, sway, bond energy plots drawn


@needs_chromium
@pytest.mark.parametrize("scene", [s for s in DRAWN if s != "elastic_pendulum"])
def test_headless_chromium_draws_each_scene(built, scene, tmp_path):
    stop, parts, sets = DRAWN[scene]
    csv_path, html = tmp_path / "r.csv", tmp_path / "r.html"
    p = cranefmu("run", scene, "--stop-time", str(stop), "--output", str(csv_path), "--report", str(html),
                 *(a for v in sets for a in ("--set", v)))
    assert p.returncode == 0, p.stderr
    rows = read_csv(csv_path)
    i = len(rows) // 2
    t = float(rows["time"][i])
    dom = _open(html, t, tmp_path / "profile")
    _check_hook(dom, rows, t)
    for cls, count in parts:
        assert len(re.findall(rf'class="{cls}"', dom)) == count, cls
    assert dom.count("<polyline") >= 2
    views = {v: dict(re.findall(r'data-([a-z-]+)="([^"]*)"', re.search(rf'<svg[^>]*id="view-{v}"[^>]*>', dom).group(0)))
             for v in ("side", "top", "close", "close-top") if f'id="view-{v}"' in dom}
    if "boom" in dict(parts):   # the boom's tip drawn where the CSV row puts it, in every view
        for v, a in (("side", "y"), ("top", "z"), ("close", "y"), ("close-top", "z")):
            if v in views:
                x, y = (float(c) for c in views[v]["boom-tip"].split(","))
                assert x == pytest.approx(rows["boom.x_tip"][i], rel=1e-5, abs=1e-6), v
                assert y == pytest.approx(rows[f"boom.{a}_tip"][i], rel=1e-5, abs=1e-6), v
    if scene == "truck_slewing":   # slewed: the top view turns with it, the foot on the slewing axis
        assert float(views["top"]["boom-tip"].split(",")[1]) > 3.0
        assert [float(c) for c in views["top"]["boom-foot"].split(",")] == pytest.approx([0.0, 0.0], abs=1e-4)
    side = re.search(r'<svg[^>]*id="view-side".*?</svg>', dom, re.S).group(0)
    labels = re.findall(r"<text[^>]*>(N\d? ?[a-z-]*) (-?[\d.]+) kN</text>", side)
    assert len(labels) == dict(parts).get("arrow", 0)
    for label, value in labels:
        column = {"N front": "chassis.N_front", "N rear": "chassis.N_rear"}.get(label, f"chassis.{label.split()[0]}")
        assert value == f"{rows[column][i] / 1e3:.1f}", label   # the arrows' reactions at the slider's row
    if scene in ("truck_telescope", "truck_slewing"):   # the load hangs above the ground line
        ground = float(re.search(r'<line class="ground"[^>]*y1="([^"]+)"', side).group(1))
        box = re.search(r'<rect class="payload"[^>]*>', side).group(0)
        bottom = float(re.search(r' y="([^"]+)"', box).group(1)) + float(re.search(r'height="([^"]+)"', box).group(1))
        assert bottom < ground - 1.0   # svg y points down
    if scene == "hook_sway":   # the close-up: the payload box smaller than the sling it hangs on
        assert "close" in views and "close-top" in views
        sling = float(np.hypot(rows["pendulum.x_payload"][i] - rows["pendulum.x"][i],
                               rows["pendulum.y_payload"][i] - rows["pendulum.y"][i]))
        widths = {float(w) for w in re.findall(r'<rect class="payload"[^>]*width="([^"]+)"', dom)}
        assert len(widths) == 1 and widths.pop() < 0.5 * sling


FAILING = ('name = "tips_on_a_long_boom"\nscene = "truck_telescope"\nstop_time = 0.04\n'
           'set = {"boom.luff_angle" = 1.0471975511965976, "boom.boom_length_start" = 26.96, '
           '"boom.boom_length_end" = 26.96, "boom.seg4_offset" = 8.23, "boom.seg3_offset" = 16.46, '
           '"pendulum.mass" = 3500.0}\n'
           'expect_stop = {reason = "chassis.tipping", during = [0.0, 0.04]}\n'
           '[[assert]]\nname = "front_loaded"\ncolumn = "chassis.N_front"\nat = 0.0\nmin = "1 kN"\n')


def test_the_report_of_a_failed_experiment_shows_its_verdict_first(built, tmp_path):
    """Issue 37: verdict at the top (experiment, case, FAIL in colour, value/limit/unit, why the run stopped)."""
    f = tmp_path / "tips.toml"
    f.write_text(FAILING)
    html = tmp_path / "r.html"
    p = cranefmu("run", str(f), "--report", str(html))
    assert p.returncode == 1, p.stderr
    text = html.read_text()
    assert "<title>FAIL: experiment tips_on_a_long_boom, case base (truck_telescope, native FMUs)</title>" in text
    verdict, crane = text.index("id='verdict'"), text.index("<h2>The crane</h2>")
    assert verdict < crane   # before the drawing and the plots
    assert "class='verdict fail'" in text and "<tr class='fail'>" in text
    assert "The run stopped early: stopped at t = 0 s: chassis.tipping = 1" in text
    assert re.search(r"<td>[-\d.e+]+ N @ 0 s</td><td>&gt;= 1000 N</td>", text), text[verdict:verdict + 2000]
    assert "<tr class='pass'><td>expect_stop</td>" in text


@needs_chromium
def test_headless_chromium_shows_the_fail_in_red_above_the_crane(built, tmp_path):
    f = tmp_path / "tips.toml"
    f.write_text(FAILING)
    html = tmp_path / "r.html"
    cranefmu("run", str(f), "--report", str(html))
    dom = _open(html, 0.0, tmp_path / "profile")
    assert dom.index('id="verdict"') < dom.index('id="views"')
    assert re.search(r'class="verdict fail"[^>]*><b>FAIL</b>: 1 of 2 assertion', dom)
