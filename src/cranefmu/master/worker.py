"""The worker of an isolated run: ``python -m cranefmu.master.worker`` (see :mod:`.isolated`).

Reads the job (a pickle holding the resolved :class:`.runspec.RunSpec`) from stdin, runs it with SIGINT, SIGTERM
and SIGHUP stopping the run between steps,
and writes ("ok", RunResult) or ("error", exception) to the job's outcome file.  End-of-file on
stdin means the parent is gone: the run stops the same way, and the worker removes the parent's
temporary directory itself.
"""
import os
import signal
import sys

from .interrupt import Interrupt

# first of all: a signal from now on only asks the run to stop (never a KeyboardInterrupt inside an FMU)
STOPS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
INTERRUPT = Interrupt(STOPS)   # SIGHUP left out when inherited ignored (nohup)
for _s in INTERRUPT.signals:
    signal.signal(_s, INTERRUPT.handle)
signal.pthread_sigmask(signal.SIG_UNBLOCK, STOPS)   # blocked by the parent until now (isolated.py)

ORPHAN_GRACE = 5.0   # seconds an orphaned worker gets to close its run before it exits regardless


def _watch_parent(interrupt: Interrupt, orphaned: list) -> None:
    """Block on stdin until the parent closes it or dies; then stop the run."""
    import threading

    def watch():
        try:
            while os.read(0, 4096):   # the raw descriptor: a buffered read would block the exit
                pass
        except OSError:
            pass
        orphaned.append(True)
        interrupt.handle(signal.SIGHUP)
        timer = threading.Timer(ORPHAN_GRACE, os._exit, (1,))
        timer.daemon = True
        timer.start()

    threading.Thread(target=watch, daemon=True).start()


def main() -> int:
    import pickle
    import shutil
    from pathlib import Path

    from .output_file import OutputFile
    from .run import _run_here

    job = pickle.load(sys.stdin.buffer)
    if job.get("scene"):   # the parent's extraction, moved into the job folder (isolated._hand_over)
        from .extracted import adopt

        adopt(job["spec"].ssp, *job["scene"])
    orphaned: list = []
    _watch_parent(INTERRUPT, orphaned)
    claim = OutputFile(Path(job["claim"][0]), Path(job["claim"][1]) if job["claim"][1] else None, job["claim"][2]) \
        if job["claim"] else None
    try:
        outcome = ("ok", _run_here(job["spec"], claim, INTERRUPT))
    except BaseException as err:   # reported to the parent, which raises it
        outcome = ("error", err)
    try:
        data = pickle.dumps(outcome)
    except Exception as err:  # an exception that does not pickle: its text
        data = pickle.dumps(("error", RuntimeError(f"{type(outcome[1]).__name__}: {outcome[1]} ({err})")))
    report = Path(job["outcome"])
    partial = report.with_name(report.name + ".tmp")
    partial.write_bytes(data)
    os.replace(partial, report)   # whole or absent, even if the parent kills this process meanwhile
    jobdir = Path(job["outcome"]).parent
    if orphaned and jobdir.name.startswith("cranefmu_run_"):   # nobody else will remove it
        shutil.rmtree(jobdir, ignore_errors=True)
    return 0


if __name__ == "__main__":
    code = main()
    sys.stderr.flush()
    os._exit(code)   # every FMU is freed; skip the interpreter's teardown (and the watching thread)
