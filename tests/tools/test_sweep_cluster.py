"""Sweeps that survive their cluster: lost runs rerun on resume, a changed design warned about or pruned,
and a real ``dask scheduler`` with ``dask worker`` processes (loopback only) killed mid-sweep."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import cranefmu
from cranefmu.sweep import table as tables
from cranefmu.sweep.metrics import Custom

E_VALUES = [1e11, 2e11, 3e11]


def _die_if_flagged(flag: str):
    def metric(result, inputs):   # a worker lost mid-run (as a machine or a process killed from outside)
        if inputs["rope.E"] == 2e11 and os.path.exists(flag):
            os._exit(1)
        return {"final_tension": float(result["rope.tension"][-1])}
    return Custom(("final_tension",), metric, ("rope.tension",))


def test_a_lost_run_is_rerun_on_resume_not_skipped(built, tmp_path):
    flag = tmp_path / "kill"
    flag.touch()
    out = tmp_path / "s.csv"
    first = cranefmu.sweep("elastic_pendulum", {"rope.E": E_VALUES}, [_die_if_flagged(str(flag))], out,
                           workers=1, stop_time=0.05, progress=False)
    status = {r["rope.E"]: r["status"] for r in first.rows}
    # a run queued on the dying worker may be lost with it too (Dask counts it as processing there)
    assert first.ran == 3 and status[2e11] == "lost" and set(status.values()) <= {"ok", "lost"}
    flag.unlink()
    second = cranefmu.sweep("elastic_pendulum", {"rope.E": E_VALUES}, [_die_if_flagged(str(flag))], out,
                            workers=1, stop_time=0.05, progress=False)
    assert (second.ran, second.skipped, second.lost) == (first.lost, 3 - first.lost, 0)
    assert [r["status"] for r in tables.read(out)] == ["ok", "ok", "ok"]   # the lost row replaced, in place


def test_a_changed_design_warns_about_rows_outside_it_and_prune_drops_them(built, tmp_path, capsys):
    out = tmp_path / "s.csv"
    cranefmu.sweep("elastic_pendulum", {"rope.E": E_VALUES}, ["max:rope.tension"], out, workers=1, stop_time=0.05,
                   progress=False)
    capsys.readouterr()
    res = cranefmu.sweep("elastic_pendulum", {"rope.E": [1e11, 4e11]}, ["max:rope.tension"], out, workers=1,
                         stop_time=0.05, progress=False)
    assert "holds 2 row(s) outside this design" in capsys.readouterr().err
    assert (res.ran, res.skipped, res.outside, len(res.rows)) == (1, 1, 2, 4)
    res = cranefmu.sweep("elastic_pendulum", {"rope.E": [1e11, 4e11]}, ["max:rope.tension"], out, workers=1,
                         stop_time=0.05, progress=False, prune=True)
    assert (res.ran, res.outside) == (0, 0)
    assert sorted(r["rope.E"] for r in tables.read(out)) == [1e11, 4e11]


def test_the_command_exits_1_with_a_summary_when_a_run_failed(built, tmp_path):
    p = subprocess.run([sys.executable, "-m", "cranefmu.cli", "sweep", "elastic_pendulum", "--vary", "rope.E=1e11,-1",
                        "--stop-time", "0.05", "--workers", "1", "--output", str(tmp_path / "s.csv"), "--no-progress"],
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 1, p.stderr
    assert "cranefmu: 1 run(s) failed; the first: " in p.stderr and "Traceback" not in p.stderr


# --- a real cluster on loopback --------------------------------------------------------------------
def _start(args: list[str], log: Path) -> subprocess.Popen:
    return subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=open(log, "w"), start_new_session=True)


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)


def _scheduler(tmp: Path, name: str) -> tuple[subprocess.Popen, str]:
    file = tmp / f"{name}.json"
    proc = _start([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
                   "--dashboard-address", "127.0.0.1:0", "--scheduler-file", str(file), "--no-show"], tmp / f"{name}.log")
    for _ in range(600):
        if file.exists() and file.stat().st_size:
            try:
                return proc, json.loads(file.read_text())["address"]
            except ValueError:
                pass
        time.sleep(0.1)
    _stop(proc)
    pytest.fail("dask scheduler did not start in 60 s")


def _worker(tmp: Path, address: str, name: str) -> subprocess.Popen:
    return _start([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1", "--nworkers", "1",
                   "--host", "127.0.0.1", "--name", name, "--local-directory", str(tmp / name), "--no-dashboard"],
                  tmp / f"{name}.log")


def _wait_workers(address: str, n: int) -> None:
    from distributed import Client

    with Client(address, timeout=60) as c:
        c.wait_for_workers(n, timeout=120)


def _children(pid: int) -> list[int]:
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout.split()
    return [int(x) for x in out]


def _sweep_cmd(address: str, out: Path, n: int) -> list[str]:
    values = ",".join(repr(1e11 + 1e10 * i) for i in range(n))
    return [sys.executable, "-m", "cranefmu.cli", "sweep", "elastic_pendulum", "--vary", f"rope.E={values}",
            "--stop-time", "20", "--fmus", "python", "--metric", "max:rope.tension", "--scheduler", address,
            "--output", str(out), "--no-progress"]   # pythonfmu runs: ~0.8 s each, long enough to kill a worker
            # mid-sweep (16 native runs of 4 s took 0.7 s in all: the sweep ended before the kill)


def _rows_on_disk(out: Path) -> int:
    return max(0, len(out.read_text().splitlines()) - 1) if out.exists() else 0


def _wait_rows(out: Path, n: int, proc: subprocess.Popen, limit: float = 300.0) -> None:
    t0 = time.monotonic()
    while _rows_on_disk(out) < n and proc.poll() is None and time.monotonic() - t0 < limit:
        time.sleep(0.2)


def test_killing_both_workers_and_the_scheduler_loses_no_run(built, tmp_path):
    n = 16
    out = tmp_path / "s.csv"
    procs = []
    try:
        sched, address = _scheduler(tmp_path, "sched")
        procs.append(sched)
        nannies = [_worker(tmp_path, address, f"w{i}") for i in range(2)]
        procs += nannies
        _wait_workers(address, 2)
        sweep = subprocess.Popen(_sweep_cmd(address, out, n), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True)
        _wait_rows(out, 1, sweep)
        for nanny in nannies:   # both worker processes killed mid-run; their nannies start new ones
            for pid in _children(nanny.pid):
                os.kill(pid, signal.SIGKILL)
        _wait_rows(out, 3, sweep)
        _stop(sched)            # then the scheduler itself
        stdout, stderr = sweep.communicate(timeout=300)
        assert sweep.returncode != 0, stdout
        assert "the same command to resume" in stderr and "Traceback" not in stderr, stderr
        rows = tables.read(out)
        assert all(r["status"] in ("ok", "lost") for r in rows), rows   # never a false "failed"
        for p in nannies:
            _stop(p)
        sched, address = _scheduler(tmp_path, "sched2")   # a new cluster; the same command resumes
        procs.append(sched)
        procs.append(_worker(tmp_path, address, "w3"))
        _wait_workers(address, 1)
        done = subprocess.run(_sweep_cmd(address, out, n), capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr
        rows = tables.read(out)
        assert len(rows) == n and all(r["status"] == "ok" for r in rows), rows
    finally:
        for p in procs:
            _stop(p)


# --- Ctrl-C and scripts without a main guard (issue 23 item 5) -------------------------------------
def _local_sweep(tmp_path: Path) -> tuple[subprocess.Popen, Path, Path]:
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    out = tmp_path / "s.csv"
    values = ",".join(repr(1e11 + 1e10 * i) for i in range(12))
    proc = subprocess.Popen([sys.executable, "-m", "cranefmu.cli", "sweep", "elastic_pendulum", "--vary",
                             f"rope.E={values}", "--stop-time", "20", "--fmus", "python",   # ~0.8 s a run: time to press
                             "--metric", "max:rope.tension", "--workers", "2",
                             "--output", str(out), "--no-progress"], env={**os.environ, "TMPDIR": str(tmpdir)},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    return proc, out, tmpdir


@pytest.mark.parametrize("presses", [1, 2])
def test_ctrl_c_keeps_the_rows_cleans_the_temp_files_and_prints_one_line(built, tmp_path, presses):
    proc, out, tmpdir = _local_sweep(tmp_path)
    _wait_rows(out, 1, proc)
    for i in range(presses):   # a terminal's Ctrl-C reaches the whole process group
        if i:
            time.sleep(0.5)
        os.killpg(proc.pid, signal.SIGINT)
    _, stderr = proc.communicate(timeout=120)
    lines = [x for x in stderr.splitlines() if x.strip()]
    assert proc.returncode == 130
    assert len(lines) == 1 and "sweep interrupted" in lines[0] and "the same command resumes" in lines[0], stderr
    assert list(tmpdir.iterdir()) == []   # no cranefmu_sweep_*, no dask-scratch-space, no extracted scenes
    assert all(r["status"] == "ok" for r in tables.read(out)) and _rows_on_disk(out) >= 1


def test_a_sweep_script_without_a_main_guard_gets_one_line(built, tmp_path):
    script = tmp_path / "study.py"
    script.write_text("import cranefmu\ncranefmu.sweep('elastic_pendulum', {'rope.E': [1e11, 2e11]}, "
                      "['max:rope.tension'], 's.csv', workers=2, stop_time=0.05, progress=False)\n")
    p = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    lines = [x for x in p.stderr.splitlines() if x.strip()]
    assert p.returncode == 1
    assert len(lines) == 1 and 'if __name__ == "__main__":' in lines[0], p.stderr
