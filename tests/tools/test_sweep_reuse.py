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
