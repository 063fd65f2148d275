"""How a sweep cuts its runs into Dask tasks (sweep/feed.py): one run a task until a run's time is known,
then about TASK_SECONDS of runs a task, a long run alone, the last runs spread over the workers; and a real
sweep of short runs submits fewer tasks than runs, its rows those of the runs made one by one."""
from __future__ import annotations

import pytest

import cranefmu
from cranefmu.sweep import feed
from cranefmu.sweep.feed import TaskFeed


def test_one_run_a_task_until_a_time_is_known():
    f = TaskFeed(list(range(100)), workers=2)
    assert f.take(0) == [[0], [1], [2], [3]]   # two tasks per worker in flight
    assert f.take(4) == []


def test_short_runs_share_a_task_long_ones_do_not():
    f = TaskFeed(list(range(1000)), workers=2)
    f.observe(0.01)   # 10 ms a run: 25 runs make a task of 0.25 s
    assert f.size() == int(feed.TASK_SECONDS / 0.01) == 25
    f.observe(float("nan"))   # a row without a time is not counted
    f.observe(None)
    assert f.size() == 25
    for _ in range(feed.KEPT_TIMES):
        f.observe(1e-5)
    assert f.size() == feed.MAX_RUNS
    g = TaskFeed(list(range(1000)), workers=2)
    g.observe(2.0)   # a run of 2 s stays alone
    assert g.size() == 1
    assert [len(t) for t in g.take(1)] == [1, 1, 1]


def test_the_last_runs_are_spread_over_the_workers():
    f = TaskFeed(list(range(10)), workers=2)
    f.observe(0.001)   # 250 runs would make a task, but 10 runs are left for 2 workers
    tasks = f.take(0)
    assert [len(t) for t in tasks] == [5, 3, 1, 1]
    assert sorted(r for t in tasks for r in t) == list(range(10)) and not f.queue


def test_a_sweep_of_short_runs_submits_fewer_tasks_than_runs(built, tmp_path):
    from cranefmu.master.run import run
    from cranefmu.sweep.engine import connect

    client, cluster = connect(workers=1)
    try:
        values = [1e11 * (1 + i / 100) for i in range(12)]
        res = cranefmu.sweep("elastic_pendulum", {"rope.E": values}, ["max:rope.tension"], tmp_path / "s.csv",
                             results=tmp_path / "runs", client=client, stop_time=0.01, step_size=1e-3, fmus="native",
                             progress=False)
    finally:
        client.close()
        cluster.close()
    assert res.ran == 12 and res.failed == 0
    assert res.tasks < 12   # the old engine submitted one task per run
    assert [r["rope.E"] for r in res.design] == values
    for row in res.design[-3:]:
        alone = run("elastic_pendulum", stop_time=0.01, step_size=1e-3, fmus="native",
                    parameters={"rope.E": row["rope.E"]}, progress=False).result
        assert row["max:rope.tension"] == float(alone["rope.tension"].max())
        import numpy as np

        full = np.load(tmp_path / "runs" / f"{row['key']}.npy")
        assert full.tobytes() == alone.tobytes()


def test_workers_joining_later_get_tasks_too():
    f = TaskFeed(list(range(100)), workers=0)   # a cluster whose workers have not joined yet
    assert len(f.take(0)) == 2
    f.set_workers(8)
    assert len(f.take(2)) == 14   # two tasks in flight per worker


@pytest.mark.parametrize("bad", [-1, 0])
def test_a_feed_of_no_workers_still_feeds_one(bad):
    f = TaskFeed([1, 2], workers=bad)
    assert f.take(0) == [[1], [2]]
