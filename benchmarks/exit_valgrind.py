"""Invalid heap accesses at process exit under valgrind, with and without the master's release of pythonfmu's
interpreter guard (:func:`cranefmu.master.fmu.release_pythonfmu_libraries`, issue 23).

One in-process run of a scene per case in ``valgrind --error-limit=no`` (``PYTHONMALLOC=malloc`` so that
valgrind sees Python's own blocks).  "without" replaces the master's hold of each pythonfmu binary by a no-op
for that process: the behaviour of main before the fix.  The table counts valgrind's "Invalid read/write"
reports whose top frame lies in an FMU binary (``/binaries/``), and all of them (glibc's dynamic loader
reads a few bytes past its rpath strings with an SSE strncmp; valgrind reports those in every process).

Usage: .venv/bin/python benchmarks/exit_valgrind.py [--scene elastic_pendulum] [--stop-time 0.05] [--smoke]
Writes benchmarks/results/exit_valgrind.md (commit, date, load, the table); ``--smoke`` (CI: the numbers mean
nothing) runs the "with" case only, 0.01 s, into exit_valgrind_smoke.md.  About 30 s per case on an idle
machine; skipped with a message when valgrind is not installed.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from result_table import save, stamp
_WITHOUT = "import cranefmu.master.fmu as f; f._hold_pythonfmu_library = lambda dll: None\n"
_RUN = "import cranefmu, sys; cranefmu.simulate(sys.argv[1], stop_time=float(sys.argv[2]))\n"


def _invalid(log: str) -> tuple[int, int, str]:
    """(invalid accesses in FMU binaries, all invalid accesses, the top function of the first in a binary)."""
    blocks = re.split(r"==\d+== (?=Invalid (?:read|write))", log)[1:]
    tops = [re.search(r"at 0x[0-9A-F]+: (\S+) \(in ([^)]*)\)", b) for b in blocks]
    in_fmu = [t.group(1) for t in tops if t and "/binaries/" in t.group(2)]
    return len(in_fmu), len(blocks), (in_fmu[0] if in_fmu else "")


def _case(code: str, scene: str, stop_time: float) -> tuple[int, int, str, int]:
    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / "valgrind.txt"
        env = dict(os.environ, PYTHONMALLOC="malloc")
        out = subprocess.run(["valgrind", "--error-limit=no", f"--log-file={log}", sys.executable, "-c", code,
                              scene, str(stop_time)], cwd=tmp, env=env, capture_output=True, text=True)
        return (*_invalid(log.read_text()), out.returncode)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="elastic_pendulum")
    ap.add_argument("--stop-time", type=float, default=0.05)
    ap.add_argument("--smoke", action="store_true", help="the 'with' case only, 0.01 s (CI; the numbers mean nothing)")
    a = ap.parse_args()
    if a.smoke:
        a.stop_time = 0.01
    if shutil.which("valgrind") is None:
        print("valgrind is not installed: nothing measured")
        return
    cases = [("without the release (main before the fix)", _WITHOUT + _RUN), ("with the release", _RUN)]
    rows = [(name, _case(code, a.scene, a.stop_time)) for name, code in (cases[1:] if a.smoke else cases)]
    lines = [f"# Invalid heap accesses at exit: cranefmu.simulate({a.scene!r}, stop_time={a.stop_time}) in-process "
             "under valgrind", "", f"{stamp('exit_valgrind.py')}; valgrind --error-limit=no, PYTHONMALLOC=malloc.", "",
             "| case | invalid accesses in FMU binaries | where (top frame) | all invalid accesses | exit code |",
             "| --- | --- | --- | --- | --- |"]
    lines += [f"| {name} | {fmu} | {top or '-'} | {total} | {rc} |" for name, (fmu, total, top, rc) in rows]
    save("exit_valgrind_smoke" if a.smoke else "exit_valgrind", lines)


if __name__ == "__main__":
    main()
