"""Test helper: the CLI on a long elastic_pendulum run in a process of its own, and the rows it has
flushed so far; shared by the signal and output-file tests."""
from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

STEP = 1e-3


def cranefmu(*args: str, cwd: Path | None = None, timeout: float = 300) -> subprocess.CompletedProcess:
    """``cranefmu *args`` in a child process of this interpreter, its output captured (``timeout`` [s]
    guards against a hung child, not a speed claim)."""
    return subprocess.run([sys.executable, "-m", "cranefmu.cli", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=timeout)


def start(tmp_path: Path, *extra: str) -> tuple[subprocess.Popen, Path, Path]:
    """The CLI on a long run in a session of its own, its TMPDIR a directory of the test's."""
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir(exist_ok=True)
    out = tmp_path / "out.csv"
    env = {**os.environ, "TMPDIR": str(tmpdir)}
    proc = subprocess.Popen([sys.executable, "-m", "cranefmu.cli", "run", "elastic_pendulum", "--stop-time", "200",
                             "--step", str(STEP), "--output", str(out), *extra], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    return proc, out, tmpdir


def rows_on_disk(part: Path) -> int:
    try:
        return part.read_bytes().count(b"\n") - 1
    except FileNotFoundError:
        return -1


def wait_for_rows(proc: subprocess.Popen, out: Path, rows: int = 1000, timeout: float = 120.0) -> int:
    """Wait until the run has flushed ``rows`` rows to its .part file (a known time: t >= rows * STEP)."""
    part = out.with_name(out.name + ".part")
    end = time.monotonic() + timeout
    while rows_on_disk(part) < rows:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < end, "no rows appeared"
        time.sleep(0.02)
    return rows_on_disk(part)
