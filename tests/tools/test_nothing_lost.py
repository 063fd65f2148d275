"""Nothing lost: rows computed before a failure are on disk, temporary directories go, every FMU
instance is terminated and freed, on every path (success, user error, component failure, blow-up).

Each run happens in a spawned child (pythonfmu FMUs cannot be instantiated again in a process
that freed one) which counts the FMI life-cycle calls and points ``tempfile`` at a directory of
its own, so the test sees what the master left behind.
"""
from __future__ import annotations

import multiprocessing
import re
from pathlib import Path

import numpy as np
import pytest

from cranefmu.errors import ParameterSetError, SimulationError
from cranefmu.master.results import read_csv

STREAM_CHECK_AT = 1501  # rows recorded when the child looks at the CSV on disk (flushes every 1000)


def _counted_run(tmpdir: str, scene: str, kwargs: dict) -> dict:
    """In a child: run with every FMI life-cycle call counted; returns the counts, error and leftovers."""
    import tempfile

    from fmpy.fmi2 import FMU2Slave

    from cranefmu.errors import CraneFmuError
    from cranefmu.master.results import Recorder
    from cranefmu.master.run import run

    tempfile.tempdir = tmpdir
    calls = {"instantiate": 0, "terminate": 0, "freeInstance": 0}
    instances = []
    seen = {}

    def counting(name):
        original = getattr(FMU2Slave, name)

        def wrapper(self, *a, **kw):
            calls[name] += 1
            if name == "instantiate":
                instances.append(self)
            return original(self, *a, **kw)
        setattr(FMU2Slave, name, wrapper)

    for name in calls:
        counting(name)
    record = Recorder.record

    def watching(self, *a, **kw):
        record(self, *a, **kw)
        if self.count == STREAM_CHECK_AT and self.output is not None:
            seen["rows_on_disk_while_running"] = len(Path(self.path).read_text().splitlines()) - 1
    Recorder.record = watching
    block = Recorder.steps_complete

    def watching_blocks(self, *a, **kw):   # a compiled stretch's rows come in one call (master/loop.py)
        block(self, *a, **kw)
        if (self.count >= STREAM_CHECK_AT and self.output is not None
                and "rows_on_disk_while_running" not in seen):
            seen["rows_on_disk_while_running"] = len(Path(self.path).read_text().splitlines()) - 1
    Recorder.steps_complete = watching_blocks
    out = {"error": None, "message": "", "rows": None}
    try:
        res = run(scene, isolate=False, **kwargs)
        out["rows"] = len(res.result)
    except CraneFmuError as err:
        out["error"], out["message"] = type(err).__name__, str(err)
        partial = getattr(err, "result", None)
        out["rows"] = None if partial is None else len(partial)
        out["partial_time"] = None if partial is None else np.asarray(partial["time"]).tolist()
    # FMI 2.0: an instance that returned fmi2Fatal may not be called again, not even freed
    calls["fatal"] = sum(1 for fmu in instances if getattr(fmu, "fatal", False))
    # a native FMU of an extracted scene is terminated and kept alive for the next run's fmi2Reset
    # (cranefmu.master.fmu._LOADED: one entry per instance released that way, counted as freed)
    from cranefmu.master import fmu as master_fmu

    calls["freeInstance"] += sum(len(kept) for kept in master_fmu._LOADED.values())
    out["calls"] = calls
    from cranefmu.master.process import clear

    clear()   # the extracted scenes kept for the process (removed at its exit)
    out["leftovers"] = sorted(p.name for p in Path(tmpdir).iterdir())
    out.update(seen)
    return out


def counted_run(tmp_path: Path, scene, **kwargs) -> dict:
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        return pool.apply(_counted_run, (str(tmpdir), str(scene), kwargs))


def assert_clean(out: dict) -> None:
    calls = out["calls"]
    assert calls["instantiate"] >= 2, calls
    freed = calls["instantiate"] - calls["fatal"]
    assert calls["terminate"] == freed and calls["freeInstance"] == freed, calls
    assert out["leftovers"] == [], out["leftovers"]


def test_success_frees_every_instance_and_removes_the_extracted_fmus(built, tmp_path):
    out = counted_run(tmp_path, "elastic_pendulum", stop_time=0.05, step_size=1e-3, output=str(tmp_path / "ok.csv"))
    assert out["error"] is None and out["rows"] == 51
    assert out["calls"]["instantiate"] == 2
    assert_clean(out)
    assert len(read_csv(tmp_path / "ok.csv")) == 51


@pytest.mark.parametrize("fmus, fatal", [("python", 1), ("native", 0)])
def test_user_error_at_initialization_frees_every_instance(built, tmp_path, fmus, fatal):
    out = counted_run(tmp_path, "elastic_pendulum", stop_time=0.05, parameters={"pendulum.mass": -1.0}, fmus=fmus)
    assert out["error"] == ParameterSetError.__name__ and "pendulum.mass = -1.0" in out["message"]
    # the refusing pendulum: pythonfmu returns fmi2Fatal (never called again), the native one fmi2Error
    # (freed as the rope is)
    assert out["calls"]["fatal"] == fatal
    assert_clean(out)


def test_unknown_parameter_after_instantiation_frees_every_instance(built, tmp_path):
    out = counted_run(tmp_path, "elastic_pendulum", stop_time=0.05, parameters={"rope.nothing": 1.0})
    assert out["error"] == ParameterSetError.__name__
    assert_clean(out)


def test_component_failure_keeps_the_rows_streamed_so_far(faulty_ssp, tmp_path):
    """The faulty component fails in the step from 2.0 s: 2001 rows (t = 0 ... 2.0 s) are on disk,
    were already on disk while the run went on, and the message says where."""
    csv = tmp_path / "partial.csv"
    out = counted_run(tmp_path, faulty_ssp, stop_time=3.0, step_size=1e-3, output=str(csv),
                      parameters={"faulty.t_fail": 2.0005})
    assert out["error"] == SimulationError.__name__
    assert "component faulty" in out["message"] and str(csv) in out["message"] and "2001 rows" in out["message"] and "t = 2 s" in out["message"]
    assert out["rows_on_disk_while_running"] >= 1000  # streamed, not written at the end
    rows = read_csv(csv)
    assert len(rows) == out["rows"] == 2001
    assert rows["time"][0] == 0.0 and rows["time"][-1] == pytest.approx(2.0, abs=1e-12)
    assert np.allclose(rows["time"], out["partial_time"], rtol=0, atol=1e-12)
    assert np.all(np.isfinite(rows["rope.tension"])) and np.all(np.isfinite(rows["faulty.x"]))
    assert out["calls"]["instantiate"] == 3
    assert_clean(out)


def test_unstable_coupling_keeps_the_rows_before_the_blow_up(built, tmp_path):
    """Jacobi with zero-order hold at H = 1 ms on a rope 10^4 times stiffer (E = 1e15 Pa, zeta = 0):
    the axial mode (omega H ~ 2.4) grows until a value is non-finite; every row up to it is kept.  The
    load is released 17 mm beyond this rope's rest length (placed by hand, start = position): from the
    derived rest the mode grows from round-off only and the rope going slack bounds it."""
    csv = tmp_path / "unstable.csv"
    jolt = {"pendulum.start": "position", "pendulum.theta0": 0.0, "pendulum.x0": 0.8730636066303505,
            "pendulum.y0": -9.979162687422361}
    out = counted_run(tmp_path, "elastic_pendulum", stop_time=3.0, step_size=1e-3, output=str(csv),
                      parameters={"rope.E": 1e15, "rope.zeta": 0.0, **jolt}, instability_alarm=False)
    assert out["error"] == SimulationError.__name__, out
    msg = out["message"]
    assert "non-finite" in msg and "rope" in msg and "t = " in msg and "smaller --step" in msg
    rows = read_csv(csv)
    assert 10 < len(rows) == out["rows"] < 3001
    # the master records the failing row last (it shows what went wrong); every row before it is finite
    for name in rows.dtype.names:
        assert np.all(np.isfinite(rows[name][:-1])), name
    assert not all(np.isfinite(rows[name][-1]) for name in rows.dtype.names)
    t_fail = float(re.search(r"at t = ([0-9.e+-]+) s", msg).group(1))
    assert rows["time"][-1] == pytest.approx(t_fail, abs=1e-9)
    assert_clean(out)


def test_a_child_that_dies_raises_instead_of_hanging(faulty_ssp, tmp_path):
    """The worker hosting the FMUs dies at 1.5 s (os._exit(70) inside a step): run(isolate=True)
    raises a SimulationError saying how it ended and naming the CSV, which holds the rows flushed
    before (every 1000 rows), cut to whole rows."""
    from cranefmu.master.run import run

    csv = tmp_path / "crash.csv"
    with pytest.raises(SimulationError, match="exited with code 70") as info:
        run(faulty_ssp, stop_time=3.0, step_size=1e-3, output=str(csv), parameters={"faulty.t_crash": 1.5005},
            isolate=True)
    assert str(csv) in str(info.value) and "crash inside an FMU" not in str(info.value)
    rows = read_csv(csv)
    assert len(rows) >= 1000 and np.all(np.diff(rows["time"]) > 0) and rows["time"][-1] <= 1.5005
