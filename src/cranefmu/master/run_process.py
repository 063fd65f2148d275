"""Where ``cranefmu run`` runs a scene's FMUs: in the command's own process or in a worker process.

The worker (:mod:`.isolated`) exists for FMUs whose failures the command cannot survive in its own
process: pythonfmu's FMUs (a Python interpreter inside each, an abort at process exit in C hosts,
docs/fmus.md) and FMUs of other tools (unknown code: a crash inside one is reported instead of ending
the command).  cranefmu's native FMUs are C99 with libm only, conformance-tested against the pythonfmu
ones and valgrind-clean over instantiate/free cycles (issue 33): they run in the command's own process,
which saves a second interpreter importing numpy and fmpy (about a third of a cold command's CPU,
benchmarks/results/kinds_speed.md).  ``--isolate`` and ``--in-process`` choose either way.
"""
from __future__ import annotations

IN_PROCESS_KINDS = ("native",)   # FMU kinds (:mod:`.fmu_kind`) run in the command's own process by default


def choose(kind: str | None, isolate: bool = False, in_process: bool = False) -> tuple[bool, str]:
    """(run in a worker process?, the header's line saying where and why) for a scene whose FMUs are of
    ``kind`` (``native``, ``python``, or None: another tool's or mixed); ``isolate``/``in_process``: the
    command line asked for one (``--isolate``, ``--in-process``; not both)."""
    if isolate and in_process:
        raise ValueError("isolate and in_process exclude each other")
    if isolate:
        return True, "process: a worker process (--isolate)"
    if in_process:
        return False, "process: this one (--in-process)"
    if kind in IN_PROCESS_KINDS:
        return False, f"process: this one ({kind} FMUs; --isolate runs them in a worker process)"
    what = "pythonfmu FMUs" if kind == "python" else "FMUs of another tool, or of mixed kinds"
    return True, (f"process: a worker process ({what}: a crash inside one is reported instead of ending the "
                  "command; --in-process runs them here)")
