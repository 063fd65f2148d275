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
from .interrupt import STOP_SIGNALS, RunInterrupted, note, signal_name, wanted
from .output_file import OutputFile
from .runspec import RunSpec

# ``python -m cranefmu.master.worker`` without the working directory on the import path: ``-c`` puts
# it first as '' (``-m`` as its full name), and a numpy.py, pickle.py or cranefmu/ there would shadow
# the real one.  (``-P`` does this from Python 3.11 on; ``-I`` would also drop the user's site-packages.)
WORKER_COMMAND = [sys.executable, "-c", "import sys\nif sys.path and sys.path[0] == '': del sys.path[0]\n"
                  "import runpy\nrunpy.run_module('cranefmu.master.worker', run_name='__main__', alter_sys=True)"]
# Move the caller's extraction of the scene to the worker (:func:`_hand_over`): only where nothing else in the
# process can be using it, i.e. the ``cranefmu run`` command (set by the CLI); an API caller may have runs in
# other threads instantiating from that folder, and keeps it.
HAND_OVER = False
GRACE = 0.7        # seconds a signalled worker gets to close its run before it is killed
TAIL_BYTES = 8192  # of the worker's stderr, kept for the message if it dies


def run_isolated(spec: RunSpec, claim: OutputFile | None, signals: tuple[int, ...] | None = None):
    """Run ``spec`` in a worker; returns its RunResult or raises what it raised (a death as SimulationError).
    ``signals`` (default :data:`.interrupt.STOP_SIGNALS`) received meanwhile are passed on to it."""
    if spec.settings.progress is None:   # the worker's stderr is a pipe: decide for it
        spec = replace(spec, settings=replace(spec.settings,
                                              progress=bool(getattr(sys.stderr, "isatty", lambda: False)())))
    stop = _Forward(tuple(STOP_SIGNALS) if signals is None else signals)
    jobdir = proc = None
    try:
        stop.install()   # from here every stop signal is recorded and passed on, never raised
        jobdir = Path(tempfile.mkdtemp(prefix="cranefmu_run_"))
        outcome = jobdir / "outcome.pickle"
        job = dict(spec=spec, outcome=str(outcome), claim=(str(claim.target), str(claim.part) if claim.part else None,
                                                           claim.fd) if claim is not None else None,
                   scene=_hand_over(spec.ssp, jobdir) if HAND_OVER else None)
        env = {**os.environ, "TMPDIR": str(jobdir), "PYTHONFAULTHANDLER": "1"}
        # the worker starts with the stop signals blocked (inherited mask) until its handlers are in place
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, stop.signals)
        try:
            proc = subprocess.Popen(WORKER_COMMAND, stdin=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                                    pass_fds=(claim.fd,) if claim else ())
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        stop.forward_to(proc)
        relay = _Relay(proc.stderr)
        try:
            proc.stdin.write(pickle.dumps(job))
            proc.stdin.flush()          # kept open: its end-of-file tells the worker the parent is gone
        except OSError:
            pass                        # the worker is gone already: reported below
        stop.wait()
        relay.join(2.0)
        got = stop.got[0] if stop.got else None
        kind, value = _outcome(outcome)
        if kind == "ok":
            if got is not None:   # the worker finished before it saw the signal: report the interrupt
                raise RunInterrupted(f"interrupted by {signal_name(got)} after the run ended", value.result,
                                     value.output, got)
            return value
        if kind == "error":
            raise value
        rows = claim.salvage() if claim is not None else 0
        where = claim.finish(rows) if claim is not None else None
        if got is not None:
            kept = f"the {rows} rows written before are in {where}" if rows else "no rows were written"
            raise RunInterrupted(f"interrupted by {signal_name(got)}: {kept}", None, where, got)
        raise SimulationError(_death(spec.ssp, proc.returncode, relay.tail(), rows, where))
    finally:
        try:
            if proc is not None:
                if proc.poll() is None:
                    proc.kill()
                proc.wait()
                for stream in (proc.stdin, proc.stderr):
                    try:
                        stream.close()
                    except OSError:
                        pass
            if jobdir is not None:
                shutil.rmtree(jobdir, ignore_errors=True)
        finally:
            stop.restore()


def _hand_over(ssp: Path, jobdir: Path):
    """This process's extraction of ``ssp`` moved into the job folder for the worker (which then extracts
    nothing), or None where it cannot be moved (another file system: the worker extracts its own, and this
    copy is removed now, as it would outlive a killed caller)."""
    from .extracted import hand_over
    from .process import clear

    try:
        return hand_over(ssp, jobdir)
    except OSError:
        clear()
        return None


def _outcome(path: Path) -> tuple[str, object]:
    """The worker's report: ("ok", RunResult), ("error", exception), or ("none", None) if it wrote none."""
    try:
        return pickle.loads(path.read_bytes())
    except (OSError, EOFError, pickle.UnpicklingError):
        return "none", None


class _Forward:
    """The parent's handler of stop signals during an isolated run: records each, passes the first
    on to the worker, kills it on a second one or :data:`GRACE` seconds after the first."""

    def __init__(self, signals: tuple[int, ...]):
        self.signals = wanted(signals)
        self.got: list[int] = []
        self.proc: subprocess.Popen | None = None
        self._old: dict[int, object] = {}

    def install(self) -> None:
        if threading.current_thread() is threading.main_thread():
            for s in self.signals:
                self._old[s] = signal.signal(s, self.handle)

    def restore(self) -> None:
        for s, h in self._old.items():
            signal.signal(s, h)
        self._old.clear()

    def handle(self, signum, frame=None) -> None:
        note(signum)
        self.got.append(signum)
        self._send()

    def forward_to(self, proc: subprocess.Popen) -> None:
        self.proc = proc
        if self.got:   # arrived while the worker was starting
            self._send()

    def _send(self) -> None:
        if self.proc is None:
            return
        try:
            self.proc.send_signal(self.got[0] if len(self.got) == 1 else signal.SIGKILL)
        except OSError:
            pass

    def wait(self) -> None:
        """Until the worker ends; it is killed :data:`GRACE` seconds after the first signal."""
        deadline = None
        while True:
            try:
                self.proc.wait(timeout=0.05)
                return
            except subprocess.TimeoutExpired:
                pass
            if self.got and deadline is None:
                deadline = clock.monotonic() + GRACE
            if deadline is not None and clock.monotonic() > deadline:
                self.proc.kill()


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
