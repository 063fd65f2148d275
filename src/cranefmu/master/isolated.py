"""A run in a worker process (``run(..., isolate=True)``, the CLI's default).

The worker is a fresh ``python -m cranefmu.master.worker``: it never imports the caller's
``__main__`` (multiprocessing's spawn and forkserver do, which breaks guard-less scripts and
``python -``).  The job (the resolved :class:`.runspec.RunSpec`, pickled whole: the worker decides
no setting again) goes in on the worker's stdin, which the parent holds open for the whole
run: when the parent dies, the worker reads end-of-file and stops, so no worker outlives its
parent.  The worker writes into the CSV claim the parent holds (the file descriptor is inherited,
so is the lock), keeps its temporary files in a directory of the parent's, and reports through a
pickle there.  A signal to the parent is passed on; a worker that does not stop within
``GRACE`` seconds, or dies, is ended and its CSV cut to whole rows by the parent.
"""
from __future__ import annotations

import os
import pickle
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time as clock
from dataclasses import replace
from pathlib import Path

from ..errors import SimulationError
from .interrupt import STOP_SIGNALS, RunInterrupted, signal_name
from .output_file import OutputFile
from .runspec import RunSpec

GRACE = 0.7        # seconds a signalled worker gets to close its run before it is killed
TAIL_BYTES = 8192  # of the worker's stderr, kept for the message if it dies


def run_isolated(spec: RunSpec, claim: OutputFile | None, signals: tuple[int, ...] | None = None):
    """Run ``spec`` in a worker; returns its RunResult or raises what it raised (a death as SimulationError).
    ``signals`` (default :data:`.interrupt.STOP_SIGNALS`) received meanwhile are passed on to it."""
    if spec.settings.progress is None:   # the worker's stderr is a pipe: decide for it
        spec = replace(spec, settings=replace(spec.settings,
                                              progress=bool(getattr(sys.stderr, "isatty", lambda: False)())))
    ssp = spec.ssp
    jobdir = Path(tempfile.mkdtemp(prefix="cranefmu_run_"))
    outcome = jobdir / "outcome.pickle"
    job = dict(spec=spec, outcome=str(outcome), claim=(str(claim.target), str(claim.part) if claim.part else None, claim.fd)
               if claim is not None else None)
    proc = None
    try:
        env = {**os.environ, "TMPDIR": str(jobdir), "PYTHONFAULTHANDLER": "1"}
        proc = subprocess.Popen([sys.executable, "-m", "cranefmu.master.worker"], stdin=subprocess.PIPE,
                                stderr=subprocess.PIPE, env=env, pass_fds=(claim.fd,) if claim else ())
        relay = _Relay(proc.stderr)
        proc.stdin.write(pickle.dumps(job))
        proc.stdin.flush()          # kept open: its end-of-file tells the worker the parent is gone
        got = _wait(proc, tuple(STOP_SIGNALS) if signals is None else signals)
        relay.join(2.0)
        if outcome.is_file():
            kind, value = pickle.loads(outcome.read_bytes())
            if kind == "ok":
                if got is not None:   # the worker finished before it saw the signal: report the interrupt
                    raise RunInterrupted(f"interrupted by {signal_name(got)} after the run ended", value.result,
                                         value.output, got)
                return value
            raise value
        rows = claim.salvage() if claim is not None else 0
        where = claim.finish(rows) if claim is not None else None
        if got is not None:
            kept = f"the {rows} rows written before are in {where}" if rows else "no rows were written"
            raise RunInterrupted(f"interrupted by {signal_name(got)}: {kept}", None, where, got)
        raise SimulationError(_death(ssp, proc.returncode, relay.tail(), rows, where))
    finally:
        if proc is not None:
            if proc.poll() is None:
                proc.kill()
            proc.wait()
            for stream in (proc.stdin, proc.stderr):
                try:
                    stream.close()
                except OSError:
                    pass
        shutil.rmtree(jobdir, ignore_errors=True)


def _wait(proc: subprocess.Popen, signals: tuple[int, ...]) -> int | None:
    """Wait for the worker, passing on the first of ``signals`` and killing it on a second one or
    after :data:`GRACE`; returns the signal received, or None."""
    got: list[int] = []

    def handler(signum, frame):
        got.append(signum)
        try:
            proc.send_signal(signum if len(got) == 1 else signal.SIGKILL)
        except OSError:
            pass

    old = {}
    if threading.current_thread() is threading.main_thread():
        for s in signals:
            old[s] = signal.signal(s, handler)
    try:
        deadline = None
        while True:
            try:
                proc.wait(timeout=0.05)
                break
            except subprocess.TimeoutExpired:
                pass
            if got and deadline is None:
                deadline = clock.monotonic() + GRACE
            if deadline is not None and clock.monotonic() > deadline:
                proc.kill()
    finally:
        for s, h in old.items():
            signal.signal(s, h)
    return got[0] if got else None


def _death(ssp: Path, code: int, tail: str, rows: int, where: Path | None) -> str:
    """What happened to a worker that ended without a report: signal or exit code, the component a
    fatal-error traceback names, its last line of output, and where the rows are."""
    how = f"was killed by {signal_name(-code)}" if code < 0 else f"exited with code {code}"
    lines = [line.strip() for line in tail.splitlines() if line.strip()]
    comps = re.findall(r"[/\\]fmu_([^/\\]+)[/\\]", tail)   # an FMU's Python frame in faulthandler's dump
    inside = f", inside component {comps[0]}" if comps else ""   # most recent call first
    fatal = [line for line in lines if line.startswith("Fatal Python error")]
    last = f"; its last output: {(fatal or lines)[-1]!r}" if lines else "; it wrote no output"
    kept = f" The {rows} rows written before are in {where}." if rows else " No rows were written."
    return f"the worker process running scene {ssp.name} {how}{inside} before the run finished{last}.{kept}"


class _Relay(threading.Thread):
    """Pass the worker's stderr on to ours (progress bar, warnings) and keep its last bytes."""

    def __init__(self, stream):
        super().__init__(daemon=True)
        self.stream = stream
        self._tail = b""
        self.start()

    def run(self) -> None:
        fd = self.stream.fileno()
        while True:
            try:
                chunk = os.read(fd, 4096)
            except OSError:
                return
            if not chunk:
                return
            self._tail = (self._tail + chunk)[-TAIL_BYTES:]
            try:
                if sys.stderr is not None:
                    sys.stderr.write(chunk.decode(errors="replace"))
                    sys.stderr.flush()
            except (OSError, ValueError):
                pass

    def tail(self) -> str:
        return self._tail.decode(errors="replace")
