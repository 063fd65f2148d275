"""Signals on real processes: SIGINT/SIGTERM to the CLI (alone or its whole group) end the run, keep
every row computed so far in a well-formed CSV, exit 130/143; no worker outlives its parent; no
temporary directory is left behind.  (Time from signal to exit: benchmarks/startup.py.)"""
from __future__ import annotations

import os
import re
import signal
import time
from pathlib import Path

import numpy as np
import pytest

from cranefmu.master.results import read_csv

from cli_process import STEP, start, wait_for_rows


def children(pid: int) -> list[int]:
    return [int(x) for x in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]


def alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except FileNotFoundError:
        return False


def assert_rows_up_to(out: Path, seen: int, message: str) -> np.ndarray:
    """The CSV is whole (same columns in every row), its times are every step from 0 without a gap,
    it holds at least the rows seen before the signal, and its last row is the time the message gives."""
    lines = out.read_text().splitlines()
    assert len({line.count(",") for line in lines}) == 1
    rows = read_csv(out)
    assert len(rows) >= seen
    assert np.allclose(rows["time"], STEP * np.arange(len(rows)), rtol=0, atol=1e-9)
    said = re.search(r"at t = ([0-9.e+-]+) s", message)
    if said:
        assert float(said.group(1)) == pytest.approx(rows["time"][-1], abs=1e-9)
    assert f"{len(rows)} rows" in message and str(out) in message
    return rows


@pytest.mark.parametrize("signum, to_group, mode", [
    (signal.SIGINT, False, "worker"), (signal.SIGTERM, False, "worker"),
    (signal.SIGINT, True, "worker"), (signal.SIGTERM, True, "worker"),
    (signal.SIGINT, False, "in-process"), (signal.SIGTERM, True, "in-process")])
def test_signal_ends_the_run_keeping_every_row(built, tmp_path, signum, to_group, mode):
    proc, out, tmpdir = start(tmp_path, "--in-process" if mode == "in-process" else "--isolate")
    seen = wait_for_rows(proc, out)
    workers = children(proc.pid)
    assert len(workers) == (1 if mode == "worker" else 0)
    (os.killpg if to_group else os.kill)(proc.pid, signum)
    _, err = proc.communicate(timeout=30)   # how soon: benchmarks/startup.py; here: that it ends
    assert proc.returncode == 128 + signum, err
    assert err.count("\n") == 1 and f"interrupted by {signal.Signals(signum).name}" in err
    assert_rows_up_to(out, seen, err)
    assert not any(alive(pid) for pid in workers)
    assert list(tmpdir.iterdir()) == [] and not out.with_name(out.name + ".part").exists()


def test_a_second_sigint_never_hangs(built, tmp_path):
    proc, out, tmpdir = start(tmp_path, "--isolate")   # native FMUs run in the command by default
    seen = wait_for_rows(proc, out)
    workers = children(proc.pid)
    os.killpg(proc.pid, signal.SIGINT)
    time.sleep(0.005)
    os.killpg(proc.pid, signal.SIGINT)
    os.kill(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, err
    rows = read_csv(out)
    assert len(rows) >= seen and np.allclose(rows["time"], STEP * np.arange(len(rows)), rtol=0, atol=1e-9)
    assert not any(alive(pid) for pid in workers) and list(tmpdir.iterdir()) == []


def test_a_killed_worker_is_reported_and_cleaned_up_by_the_parent(built, tmp_path):
    proc, out, tmpdir = start(tmp_path, "--isolate")   # native FMUs run in the command by default
    seen = wait_for_rows(proc, out)
    (worker,) = children(proc.pid)
    os.kill(worker, signal.SIGKILL)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 2
    assert "was killed by SIGKILL" in err and "crash inside an FMU" not in err and "Traceback" not in err
    rows = read_csv(out)
    assert len(rows) >= seen and f"{len(rows)} rows written before are in {out}" in err
    assert list(tmpdir.iterdir()) == []


def test_no_worker_outlives_a_killed_parent(built, tmp_path):
    """SIGKILL to the CLI: its worker reads end-of-file on its stdin, stops, puts the rows in place and
    removes its temporary directory."""
    proc, out, tmpdir = start(tmp_path, "--isolate")   # native FMUs run in the command by default
    seen = wait_for_rows(proc, out)
    (worker,) = children(proc.pid)
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=30)
    end = time.monotonic() + 10
    while alive(worker) and time.monotonic() < end:
        time.sleep(0.05)
    assert not alive(worker)
    rows = read_csv(out)
    assert len(rows) >= seen and np.allclose(rows["time"], STEP * np.arange(len(rows)), rtol=0, atol=1e-9)
    assert list(tmpdir.iterdir()) == []
