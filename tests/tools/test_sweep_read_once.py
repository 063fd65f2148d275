"""What a sweep worker reads once per scene, not once per run: each FMU's feedthrough (initialization and
step) is read from its model description once, and the kind of FMU an extracted scene holds is read from
its files once; the runs' results are the same with the caches filled or emptied before every run."""
from __future__ import annotations

import numpy as np

from cranefmu.master import coupling, graph, runspec
from cranefmu.master.run import run

POINTS = [{"rope.E": 2e10}, {"rope.E": 5e10}]


def _run(params: dict) -> np.ndarray:
    return run("elastic_pendulum", fmus="native", parameters=params, stop_time=0.02, step_size=1e-3,
               progress=False).result


def _clear() -> None:
    coupling._FEEDTHROUGH.clear()
    graph._INIT_FEEDTHROUGH.clear()
    runspec._HELD.clear()


def test_second_run_reads_no_model_structure_again(monkeypatch):
    _run(POINTS[0])
    calls = {"step": 0, "init": 0, "kind": 0}
    step, init = coupling._feedthrough, graph._init_feedthrough

    def count(name, f):
        def wrapper(*args, **kwargs):
            calls[name] += 1
            return f(*args, **kwargs)
        return wrapper

    monkeypatch.setattr(coupling, "_feedthrough", count("step", step))
    monkeypatch.setattr(graph, "_init_feedthrough", count("init", init))
    from cranefmu.master import fmu_kind
    monkeypatch.setattr(fmu_kind, "scene_kind", count("kind", fmu_kind.scene_kind))
    _run(POINTS[1])
    assert calls == {"step": 0, "init": 0, "kind": 0}
    _clear()
    _run(POINTS[1])
    assert calls["step"] == 2 and calls["init"] == 2 and calls["kind"] == 1   # rope and pendulum, one scene


def test_cached_and_fresh_reads_give_the_same_bits():
    cached = [_run(p) for p in POINTS]
    fresh = []
    for p in POINTS:
        _clear()
        fresh.append(_run(p))
    for a, b in zip(cached, fresh):
        assert a.dtype.names == b.dtype.names
        for name in a.dtype.names:
            assert np.array_equal(a[name], b[name]), name
    assert not np.array_equal(cached[0]["rope.tension"], cached[1]["rope.tension"])
