"""cranefmu.sweep on a real Dask LocalCluster of two worker processes: rows equal the same runs made one
by one (bit for bit), a failing run is recorded while the others finish, a resumed sweep skips
finished runs, a metric on an unknown column is refused before anything runs."""
from __future__ import annotations

import math
import os

import numpy as np
import pytest

import cranefmu
from cranefmu.errors import ParameterSetError, SettingsError
from cranefmu.sweep.engine import connect
from cranefmu.sweep.metrics import measure, parse_metric
from cranefmu.sweep.spec import design, parse_factor

STOP = 0.3
METRICS = ["max:rope.tension", "min:pendulum.theta", "final:pendulum.x", "mean:rope.tension", "ptp:rope.elongation",
           "cross:pendulum.theta<0", "dynamic_factor:rope.tension", "scene"]


@pytest.fixture(scope="module")
def client():
    client, cluster = connect(workers=2)
    yield client
    client.close()
    cluster.close()


def test_rows_equal_the_runs_made_one_by_one(client, tmp_path):
    from cranefmu.master.run import run

    res = cranefmu.sweep("elastic_pendulum", ["rope.E=5e10,1e11", "step_size=1e-3,2e-3"], METRICS,
                         tmp_path / "s.csv", results=tmp_path / "runs", client=client, stop_time=STOP)
    assert res.ran == 4 and res.failed == 0 and len(res.rows) == 4
    assert {r["worker"] for r in res.rows} == {"0", "1"}   # both worker processes ran
    wanted = [parse_metric(m) for m in METRICS]
    for row in res.rows:
        alone = run("elastic_pendulum", stop_time=STOP, step_size=row["step_size"],
                    parameters={"rope.E": row["rope.E"]}, isolate=False, progress=False)
        expect = measure(wanted, "elastic_pendulum", alone.result)
        assert len(expect) == 10
        for name, value in expect.items():   # the CSV holds repr(float): the identical double
            assert row[name] == value or (math.isnan(value) and math.isnan(row[name])), name
        assert row["steps"] == alone.stats.steps == round(STOP / row["step_size"])
        full = np.load(tmp_path / "runs" / f"{row['key']}.npy")
        assert full.dtype == alone.result.dtype and full.tobytes() == alone.result.tobytes()


def test_a_bad_parameter_fails_its_run_only(client, tmp_path):
    res = cranefmu.sweep("elastic_pendulum", {"rope.E": [1e11, -1.0, 2e11]}, ["max:rope.tension"],
                         tmp_path / "s.csv", client=client, stop_time=0.2, step_size=1e-3)
    by_e = {r["rope.E"]: r for r in res.rows}
    assert res.ran == 3 and res.failed == 1
    assert by_e[-1.0]["status"] == "failed" and "rope.E = -1.0 is out of range" in by_e[-1.0]["error"]
    assert by_e[-1.0]["max:rope.tension"] is None and by_e[-1.0]["attempts"] == 1   # a refusal is not retried
    assert all(by_e[e]["status"] == "ok" and by_e[e]["steps"] == 200 for e in (1e11, 2e11))
    # released at rest from 5 deg (the default start is in equilibrium for E = 1e11): T = m g cos 5 deg
    assert by_e[1e11]["max:rope.tension"] == pytest.approx(1000.0 * 9.81 * math.cos(math.radians(5.0)), rel=1e-3)


def test_resume_skips_finished_runs(client, tmp_path):
    out = tmp_path / "s.csv"
    first = cranefmu.sweep("elastic_pendulum", ["rope.zeta=0.05,0.1"], ["max:rope.tension"], out, client=client,
                           stop_time=0.2)
    again = cranefmu.sweep("elastic_pendulum", ["rope.zeta=0.05,0.1,0.2"], ["max:rope.tension"], out,
                           client=client, stop_time=0.2)
    assert (first.ran, again.ran, again.skipped, len(again.rows)) == (2, 1, 2, 3)
    assert again.rows[:2] == first.rows   # untouched: same task times, not run again
    assert out.read_text().count("\n") == 4
    with pytest.raises(SettingsError, match="holds a different sweep"):
        cranefmu.sweep("elastic_pendulum", ["rope.zeta=0.05"], ["min:rope.tension"], out, client=client)


def test_unknown_column_or_input_refused_before_anything_runs(tmp_path):
    out = tmp_path / "s.csv"
    with pytest.raises(SettingsError, match="column 'rope.nonsense' is not an output of scene elastic_pendulum"):
        cranefmu.sweep("elastic_pendulum", ["rope.E=1e11"], ["max:rope.nonsense"], out)
    with pytest.raises(ParameterSetError, match="rope has no variable 'Ee'"):
        cranefmu.sweep("elastic_pendulum", ["rope.Ee=1e11"], ["max:rope.tension"], out)
    with pytest.raises(SettingsError, match="input 'stepsize' is not allowed"):
        cranefmu.sweep("elastic_pendulum", ["stepsize=1e-3"], ["max:rope.tension"], out)
    assert not out.exists()   # refused before the table (or a cluster) was made


def test_designs():
    assert parse_factor("rope.E=log:1e9:1e15:7").levels == pytest.approx([10.0 ** k for k in range(9, 16)], rel=1e-12)
    assert parse_factor("rope.zeta=0:0.1:3").levels == pytest.approx([0.0, 0.05, 0.1])
    assert parse_factor("algorithm=jacobi,iterative").levels == ["jacobi", "iterative"]
    assert parse_factor("extrapolation=0,1,2").levels == [0, 1, 2]
    full = design(["rope.E=1,2,3", "extrapolation=0,1"]).points()
    assert len(full) == 6 and len({tuple(p.values()) for p in full}) == 6
    lhs = design(["rope.E=log:1e9:1e12", "rope.zeta=0:0.2"], kind="lhs", samples=8).points()
    e = sorted(math.log10(p["rope.E"]) for p in lhs)
    # a Latin hypercube puts exactly one point in each of the 8 strata of each input
    assert [int((x - 9.0) / 3.0 * 8) for x in e] == list(range(8))
    assert all(0.0 <= p["rope.zeta"] <= 0.2 for p in lhs)
    with pytest.raises(SettingsError, match="a factorial design needs the number of values"):
        design(["rope.E=1:2"]).points()
    with pytest.raises(SettingsError, match="extrapolation = '1.5' is not allowed: an integer"):
        parse_factor("extrapolation=0,1.5")


def test_a_run_that_kills_its_worker_is_retried_once_then_recorded_lost(client, tmp_path):
    from cranefmu.sweep.metrics import Custom

    def die_at_2e11(result, inputs):   # a crash inside the worker process (as a segfault in an FMU)
        if inputs["rope.E"] == 2e11:
            os._exit(1)
        return {"final_tension": float(result["rope.tension"][-1])}

    res = cranefmu.sweep("elastic_pendulum", {"rope.E": [1e11, 2e11, 3e11]},
                         [Custom(("final_tension",), die_at_2e11, ("rope.tension",))], tmp_path / "s.csv",
                         client=client, stop_time=0.1)
    by_e = {r["rope.E"]: r for r in res.rows}
    assert (res.ran, res.failed, res.retried) == (3, 1, [by_e[2e11]["key"]])
    assert by_e[2e11]["status"] == "lost" and by_e[2e11]["attempts"] == 2   # rerun by a resumed sweep
    assert "worker lost the run" in by_e[2e11]["error"] and "KilledWorker" in by_e[2e11]["error"]
    assert all(by_e[e]["status"] == "ok" and math.isfinite(by_e[e]["final_tension"]) for e in (1e11, 3e11))


def test_remote_workers_get_the_scene_bytes_once(built, tmp_path, monkeypatch):
    from cranefmu.master.run import resolve_scene
    from cranefmu.sweep import worker

    monkeypatch.setattr(worker.tempfile, "gettempdir", lambda: str(tmp_path))
    monkeypatch.setattr(worker, "_LOCAL", {})
    ssp = resolve_scene("elastic_pendulum")
    sent = worker.SspFile.of(ssp, "elastic_pendulum", with_data=True)
    local = sent.local()
    assert local != ssp and local.read_bytes() == ssp.read_bytes()
    local.write_bytes(b"")   # a second call reuses the copy, it does not write again
    assert sent.local() == local and local.read_bytes() == b""
    assert worker.SspFile.of(ssp, "elastic_pendulum", with_data=False).local() == ssp


def test_a_tipped_run_says_tipped_and_rows_follow_the_design(client, tmp_path):
    """Issue 37: a run the tipping flag ended is status 'tipped' (was 'ok' with nan metrics), the table's
    rows are in the design's order whatever order the runs finished in, and it still counts as finished."""
    from cranefmu.sweep.table import read

    masses = [3500.0, 500.0, 3000.0, 1000.0]   # on a 26.96 m boom at 60 deg: 3500 and 3000 kg tip at t = 0
    geometry = {"boom.luff_angle": 1.0471975511965976, "boom.boom_length_start": 26.96,
                "boom.boom_length_end": 26.96, "boom.seg4_offset": 8.23, "boom.seg3_offset": 16.46}
    res = cranefmu.sweep("truck_telescope", {"pendulum.mass": masses}, ["min:chassis.N_front"], tmp_path / "t.csv",
                         client=client, parameters=geometry, stop_time=0.02, step_size=5e-3)
    assert res.failed == 0
    rows = read(tmp_path / "t.csv")
    assert [r["pendulum.mass"] for r in rows] == masses
    assert [r["status"] for r in rows] == ["tipped", "ok", "tipped", "ok"]
    assert all("chassis.tipping" in r["stopped"] for r in rows if r["status"] == "tipped")
