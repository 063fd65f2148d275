"""``cranefmu check`` on the sweep engine (Dask): the same verdicts and rows to the bit as in process and
on the process pool, a failing run fails its case only, a lost worker fails its task only (after one more
attempt), the engine chosen by the number of cases, bad options refused in one line."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

from cli_process import cranefmu
from cranefmu.experiments.reader import ExperimentError
from cranefmu.experiments.runner import DASK_FROM, choose_engine, judge_all, prepare, run_cases
from cranefmu.sweep.engine import connect
from test_experiments_check import PASSING   # two assertions on elastic_pendulum, 0.5 s

ROOT = Path(__file__).resolve().parents[2]

CASES = PASSING.replace('name = "small"', 'name = "three_ropes"') + """
[cases.stiff]
set = {"rope.E" = 2e11}
[cases.soft]
set = {"rope.E" = 5e10}
[cases.refused]
set = {"rope.E" = -1.0}
"""


@pytest.fixture(scope="module")
def cluster():
    """(client, address) of a LocalCluster of two workers, reached by address as a remote one is."""
    client, local = connect(workers=2)
    yield client, local.scheduler_address
    client.close()
    local.close()


def _files(tmp_path: Path) -> list[Path]:
    path = tmp_path / "three_ropes.toml"
    path.write_text(CASES)
    return [path, ROOT / "experiments" / "lower_and_stop.toml"]   # the second commands the rope's payout


def _checked(files: list[Path], **how):
    planned = prepare(files)
    engine = run_cases(planned, **how)
    verdicts = [(v.experiment, v.case, v.name, repr(v.value), v.limit, repr(v.margin), v.passed, repr(v.time), v.note)
                for v in judge_all(planned)]
    rows = {(p.case.experiment, p.case.name): {k: a.tobytes() for k, a in p.rows.items()} for p in planned}
    return engine, verdicts, rows, {p.case.name: p.error for p in planned}


def test_the_verdicts_and_rows_are_bitwise_the_same_on_every_engine(built, cluster, tmp_path):
    files = _files(tmp_path)
    inline = _checked(files)
    pool = _checked(files, jobs=2, engine="pool")
    dask_local = _checked(files, jobs=2, engine="dask")
    dask_remote = _checked(files, scheduler=cluster[1])   # the scene files reach the workers by a plugin
    assert [inline[0], pool[0], dask_local[0], dask_remote[0]] == ["inline", "pool", "dask", "dask"]
    for other in (pool, dask_local, dask_remote):
        assert other[1:] == inline[1:]
    engine, verdicts, rows, errors = dask_remote
    passed = {(case, name): ok for _, case, name, _, _, _, ok, _, _ in verdicts}
    assert len(verdicts) == 9 and sum(passed.values()) == 7
    # the refused run fails its case with the reason; the others ran and pass
    assert not passed[("refused", "tension_at_release")] and not passed[("refused", "sway_bounded")]
    assert "rope.E = -1.0 is out of range" in errors["refused"] and errors["stiff"] == errors["soft"] == ""
    assert rows[("three_ropes", "refused")] == {}
    assert len(rows[("three_ropes", "stiff")]["time"]) == 101 * 8   # 0.5 s at the stored 5 ms: 101 float64 rows


def test_a_task_whose_worker_dies_is_tried_once_more_then_lost_the_others_run(cluster):
    from cranefmu.sweep.tasks import TaskLost, run_tasks

    def square_or_die(x: float) -> float:   # a crash inside the worker process (as a segfault in an FMU)
        if x == 2.0:
            os._exit(1)
        return x * x

    ended = []
    got = run_tasks(square_or_die, [(1.0,), (2.0,), (3.0,)], client=cluster[0], done=lambda i, r: ended.append(i))
    assert got[0] == 1.0 and got[2] == 9.0 and sorted(ended) == [0, 1, 2]
    assert isinstance(got[1], TaskLost) and "after 2 attempt(s)" in got[1].reason and "KilledWorker" in got[1].reason


def test_auto_runs_one_case_in_process_few_on_a_pool_many_on_dask():
    assert choose_engine("auto", 1, 4, None) == "inline"
    assert choose_engine("auto", 20, 1, None) == "inline"
    assert choose_engine("auto", DASK_FROM - 1, 2, None) == "pool"
    assert choose_engine("auto", DASK_FROM, 2, None) == "dask"
    assert choose_engine("auto", 1, 1, "tcp://10.0.0.5:8786") == "dask"
    assert choose_engine("pool", 1, 1, None) == "pool"


@pytest.mark.parametrize("engine, jobs, scheduler, message", [
    ("pool", 2, "tcp://10.0.0.5:8786", "--engine pool is not allowed with --scheduler tcp://10.0.0.5:8786"),
    ("auto", 0, None, "--jobs 0 is not allowed: 1 or more"),
    ("threads", 2, None, "--engine 'threads' is not allowed: one of auto, inline, pool, dask"),
])
def test_bad_engine_options_are_one_line(engine, jobs, scheduler, message):
    with pytest.raises(ExperimentError, match="^" + message.replace("+", r"\+")):
        choose_engine(engine, 3, jobs, scheduler)


def test_the_cli_names_an_unreachable_scheduler_in_one_line_and_runs_nothing(built, tmp_path):
    path = _files(tmp_path)[0]
    out = cranefmu("check", str(path), "--scheduler", "tcp://127.0.0.1:9", "--report", str(tmp_path / "r.json"))
    assert out.returncode == 2 and out.stdout == "", out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "scheduler 'tcp://127.0.0.1:9': cannot reach a Dask scheduler there" in lines[0]
    assert not (tmp_path / "r.json").exists()


def test_the_cli_on_dask_reports_as_inline_and_names_the_engine(built, tmp_path):
    import json

    path = _files(tmp_path)[0]
    reports = {}
    for engine in ("inline", "dask"):
        out = cranefmu("check", str(path), "--engine", engine, "--jobs", "2", "--quiet", "--report",
                       str(tmp_path / f"{engine}.json"))
        assert out.returncode == 1, out.stderr   # the refused case fails
        assert "6 assertions in 3 cases: 4 passed, 2 failed" in out.stdout and f"engine {engine})" in out.stdout
        reports[engine] = json.loads((tmp_path / f"{engine}.json").read_text())
    assert reports["dask"]["engine"] == "dask" and reports["inline"]["engine"] == "inline"
    assert reports["dask"]["verdicts"] == reports["inline"]["verdicts"]
