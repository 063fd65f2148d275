"""Issue 37, sweeps: inputs keep the unit the user gave them (the table shows degrees under
``boom.luff_angle [deg]``, the run gets radians), and a varied boom length takes the parameters that follow it
(cranefmu.derived), so a sweep from the command line gives the load chart's API cases bit for bit."""
from __future__ import annotations

import math

import numpy as np
import pytest

import cranefmu
from cranefmu.errors import SettingsError
from cranefmu.sweep.engine import connect
from cranefmu.sweep.spec import design, parse_factor


@pytest.fixture(scope="module")
def client():
    client, cluster = connect(workers=1)
    yield client
    client.close()
    cluster.close()


def test_values_keep_their_unit_and_the_run_gets_si():
    for text in ("boom.luff_angle=30,45 deg", "boom.luff_angle=30 deg,45 deg", "boom.luff_angle=30:45:2 deg"):
        (a, b) = design([text]).runs("truck_telescope")
        assert (a.inputs, a.row) == ({"boom.luff_angle": 30.0}, {"boom.luff_angle [deg]": 30.0})
        assert (a.parameters, b.parameters) == ({"boom.luff_angle": math.radians(30.0)},
                                                {"boom.luff_angle": math.radians(45.0)})
    plain = design(["boom.luff_angle=30,45"]).runs("truck_telescope")[0]
    assert plain.row == {"boom.luff_angle": 30.0} and plain.parameters == {"boom.luff_angle": 30.0}
    assert plain.key != design(["boom.luff_angle=30,45 deg"]).runs("truck_telescope")[0].key
    fixed = design(["rope.E=1e11"], {"pendulum.mass": "2.5 t"}).runs("truck_telescope")[0]
    assert fixed.row["pendulum.mass [t]"] == 2.5 and fixed.parameters["pendulum.mass"] == 2500.0


@pytest.mark.parametrize("text, says", [("boom.luff_angle=30 deg,1 rad", "units deg, rad are not allowed together"),
                                        ("boom.luff_angle=30 deg,high", r"a unit \('deg'\) needs numbers")])
def test_a_unit_that_cannot_be_one_is_refused(text, says):
    with pytest.raises(SettingsError, match=says):
        parse_factor(text)


def test_inputs_varied_together():
    runs = design(["boom.boom_length_start,boom.boom_length_end=14,18", "pendulum.mass=1,2"]).runs("truck_telescope")
    assert [(r.inputs["boom.boom_length_start"], r.inputs["boom.boom_length_end"]) for r in runs] == \
        [(14.0, 14.0), (14.0, 14.0), (18.0, 18.0), (18.0, 18.0)]
    as_dict = design({"boom.boom_length_start,boom.boom_length_end": [14.0, 18.0]}).runs("truck_telescope")
    assert [r.inputs for r in as_dict] == [{"boom.boom_length_start": L, "boom.boom_length_end": L} for L in (14.0, 18.0)]
    with pytest.raises(SettingsError, match="each input at most once"):
        parse_factor("boom.t_acc,boom.t_acc=1,2")


def test_a_table_in_degrees(client, tmp_path, built):
    """elastic_pendulum released from 2 and 5 deg: the table's column is 'pendulum.theta0 [deg]' with 2.0 and
    5.0, each run's result bit for bit the run released from radians(5) given in SI."""
    from cranefmu.master.run import run
    from cranefmu.sweep.table import read

    res = cranefmu.sweep("elastic_pendulum", ["pendulum.theta0=2,5 deg"], ["max:pendulum.theta"], tmp_path / "d.csv",
                         client=client, results=tmp_path / "runs", stop_time=0.05, step_size=1e-3)
    assert res.failed == 0
    header = (tmp_path / "d.csv").read_text().splitlines()[0].split(",")
    assert header[:5] == ["key", "pendulum.theta0 [deg]", "step_size", "stop_time", "max:pendulum.theta"]
    rows = read(tmp_path / "d.csv")
    assert [r["pendulum.theta0 [deg]"] for r in rows] == [2.0, 5.0]
    alone = run("elastic_pendulum", parameters={"pendulum.theta0": math.radians(5.0)}, stop_time=0.05,
                step_size=1e-3, progress=False)
    assert np.load(tmp_path / "runs" / f"{rows[1]['key']}.npy").tobytes() == alone.result.tobytes()
    assert rows[1]["max:pendulum.theta"] == float(np.max(alone.result["pendulum.theta"]))
    with pytest.raises(SettingsError, match=r"pendulum.theta0 \[kN\] is not allowed: pendulum.theta0 is in rad"):
        cranefmu.sweep("elastic_pendulum", ["pendulum.theta0=2,5 kN"], ["max:pendulum.theta"], tmp_path / "k.csv",
                       client=client, stop_time=0.05)


def test_a_boom_length_sweep_gives_the_load_chart_cases(client, tmp_path, built):
    """From the command line's inputs alone: a boom held at each length (its start and end varied together)
    is the load chart's static case (segments out, hoist still), and a telescoping to a length at 45 deg (given
    in degrees) its dynamic case (payout following): every row's result bit for bit the API run of
    cranefmu.sweep.load_chart.static_parameters / dynamic_parameters.  Before, the sweep kept the segments
    retracted and the 60-deg payout of the default set."""
    from cranefmu.master.run import run
    from cranefmu.sweep.load_chart import dynamic_parameters, static_parameters

    stop, step = 0.05, 5e-3
    held = cranefmu.sweep("truck_telescope", ["boom.boom_length_start,boom.boom_length_end=14,18"],
                          ["initial:chassis.N_front"], tmp_path / "s.csv", client=client, results=tmp_path / "s",
                          parameters={"pendulum.mass": 2000.0}, stop_time=stop, step_size=step)
    moving = cranefmu.sweep("truck_telescope", ["boom.boom_length_end=14"], ["final:rope.tension"],
                            tmp_path / "d.csv", client=client, results=tmp_path / "d",
                            parameters={"pendulum.mass": 2000.0, "boom.luff_angle": "45 deg"}, stop_time=stop,
                            step_size=step)
    assert held.failed == moving.failed == 0
    cases = [(row, static_parameters(60.0, L, 2000.0), tmp_path / "s") for row, L in zip(held.design, (14.0, 18.0))]
    values = dynamic_parameters(45.0, 14.0, 0.35, 2000.0)
    del values["stop_time"]
    cases.append((moving.design[0], values, tmp_path / "d"))
    assert moving.design[0]["boom.luff_angle [deg]"] == 45.0
    for row, parameters, folder in cases:
        api = run("truck_telescope", parameters=parameters, stop_time=stop, step_size=step, progress=False)
        assert np.load(folder / f"{row['key']}.npy").tobytes() == api.result.tobytes(), parameters
