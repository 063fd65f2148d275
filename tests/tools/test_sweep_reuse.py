"""Runs of a native scene in one process keep the FMUs' loaded libraries (master/fmu.py ``_LOADED``)
and instantiate from the extracted scene itself; their results are bit for bit those of runs that
load every FMU afresh from directories of their own, whatever ran before (other parameter values, a
refused run)."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu.errors import CraneFmuError
from cranefmu.master import execution, fmu
from cranefmu.master.run import run

RUNS = [{"rope.E": 2e10}, {"rope.E": 7e10}, {"rope.E": -1.0}, {"rope.E": 2e10}, {"pendulum.m": 2.5}]


def _results(monkeypatch, reuse: bool) -> list:
    if not reuse:
        monkeypatch.setattr(execution, "instantiates_in_place", lambda workdir, scene: False)
    fmu._LOADED.clear()
    out = []
    for params in RUNS:
        try:
            out.append(run("elastic_pendulum", fmus="native", parameters=params, stop_time=0.05,
                           step_size=1e-3, progress=False).result)
        except CraneFmuError as err:   # a refused value: the run fails, the next one must not notice
            out.append(type(err).__name__)
    return out


def test_kept_libraries_give_the_bits_of_fresh_ones(monkeypatch):
    reused = _results(monkeypatch, reuse=True)
    assert sum(len(v) for v in fmu._LOADED.values()) == 2   # the pool was used: rope and pendulum kept
    fresh = _results(monkeypatch, reuse=False)
    assert not fmu._LOADED
    assert [type(r) for r in reused] == [type(r) for r in fresh]
    for a, b in zip(reused, fresh):
        if isinstance(a, str):
            assert a == b
            continue
        assert a.dtype.names == b.dtype.names and a.shape == b.shape
        for name in a.dtype.names:
            assert np.array_equal(a[name], b[name]), name
    assert not np.array_equal(reused[0]["rope.tension"], reused[1]["rope.tension"])   # E changed the run


def test_python_fmus_never_kept():
    fmu._LOADED.clear()
    run("elastic_pendulum", fmus="python", stop_time=0.005, step_size=1e-3, progress=False)
    assert not fmu._LOADED


def _sweep_point_after_others(monkeypatch, tmp_path, reuse: bool, resets: list) -> np.ndarray:
    """The point ``rope.E = 3e10`` run by a sweep worker after other points (another E, a refused E, another
    pendulum mass), each through sweep.worker.execute as a Dask task runs it; its full result."""
    from cranefmu.master.runspec import resolve
    from cranefmu.sweep.metrics import parse_metric
    from cranefmu.sweep.spec import Run
    from cranefmu.sweep.worker import SspFile, execute

    if not reuse:
        monkeypatch.setattr(execution, "instantiates_in_place", lambda workdir, scene: False)
    fmu._LOADED.clear()
    ssp = SspFile.of(resolve("elastic_pendulum", fmus="native").ssp, "elastic_pendulum", False)
    out = tmp_path / ("reused" if reuse else "fresh")
    out.mkdir()
    others = [{"rope.E": 9e10}, {"rope.E": -1.0}, {"pendulum.mass": 2500.0, "rope.zeta": 0.05}]
    rows = [execute(ssp, Run("elastic_pendulum", {**p, "stop_time": 0.2, "step_size": 1e-3, "fmus": "native"}),
                    [parse_metric("max:rope.tension")], str(out))
            for p in [*others, {"rope.E": 3e10}]]
    assert [r["status"] for r in rows] == ["ok", "failed", "ok", "ok"], rows
    assert len(resets) == (6 if reuse else 0)   # rope and pendulum reset before each of the 3 later runs
    return np.load(out / f"{rows[-1]['key']}.npy")


def test_a_sweep_point_after_others_on_reset_fmus_is_bitwise_a_fresh_one(monkeypatch, tmp_path):
    resets: list = []
    cls = fmu._slave_class()
    reset = cls.reset

    def counting(self, *a, **kw):
        resets.append(self.instanceName)
        return reset(self, *a, **kw)

    monkeypatch.setattr(cls, "reset", counting, raising=False)
    reused = _sweep_point_after_others(monkeypatch, tmp_path, True, resets)
    resets.clear()
    fresh = _sweep_point_after_others(monkeypatch, tmp_path, False, resets)
    assert reused.dtype.names == fresh.dtype.names and reused.shape == fresh.shape == (201,)
    for name in reused.dtype.names:
        assert np.array_equal(reused[name], fresh[name]), name


def test_an_fmu_refusing_the_reset_is_instantiated_afresh(monkeypatch):
    """fmi2Reset refused (an FMU whose reset fails): the kept instance is freed and a new one made; the run
    gives the bits of a fresh one."""
    from fmpy.fmi1 import FMICallException

    cls = fmu._slave_class()

    def refuse(self):
        raise FMICallException(function="fmi2Reset", status=3)

    fmu._LOADED.clear()
    first = run("elastic_pendulum", fmus="native", parameters={"rope.E": 3e10}, stop_time=0.05, step_size=1e-3,
                progress=False).result
    assert sum(len(v) for v in fmu._LOADED.values()) == 2
    monkeypatch.setattr(cls, "reset", refuse, raising=False)
    again = run("elastic_pendulum", fmus="native", parameters={"rope.E": 3e10}, stop_time=0.05, step_size=1e-3,
                progress=False).result
    assert sum(len(v) for v in fmu._LOADED.values()) == 2   # the refused ones dropped, the new ones kept
    for name in first.dtype.names:
        assert np.array_equal(first[name], again[name]), name


def test_a_reset_instance_stops_its_calls_on_a_fatal(monkeypatch):
    """A kept instance taken by fmi2Reset is watched for fmi2Fatal as a fresh one is: once it returns fatal no
    call reaches it (master/fatal_status.py), the run fails, and the instance is not kept for another run."""
    fmu._LOADED.clear()
    run("elastic_pendulum", fmus="native", stop_time=0.01, step_size=1e-3, progress=False)
    reset = fmu.FmuComponent._reset

    def fatal_after_reset(self, *entry):
        taken = reset(self, *entry)
        if taken and self.name == "rope":
            assert self.fmu.on_fatal == self.stop_calls
            self.fmu.mark_fatal()   # as if its last call had returned fmi2Fatal
        return taken

    monkeypatch.setattr(fmu.FmuComponent, "_reset", fatal_after_reset)
    with pytest.raises(Exception, match="fmi2Fatal before"):   # its next call (fmi2SetupExperiment) is refused
        run("elastic_pendulum", fmus="native", stop_time=0.01, step_size=1e-3, progress=False)
    kept = [entry[0].instanceName for entries in fmu._LOADED.values() for entry in entries]
    assert kept == ["pendulum"]
