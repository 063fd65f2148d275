"""Wall and CPU time of ``cranefmu --version`` and ``cranefmu run --help``: the package of a base commit against
this checkout.

Each command runs in a fresh ``python -c`` process with ``src/`` of one tree first on its path (the
base commit's ``src/cranefmu`` unpacked with ``git archive``), in alternating rounds, with Python's
bytecode cache (PYTHONDONTWRITEBYTECODE removed: an installed package has its .pyc); the table gives
the median of the rounds and the ratio.  The work of ``--version`` is printing one line, of ``run --help``
its page: everything else is start-up (the interpreter, the imports the CLI pulls in, argparse building
the subcommands: ``run`` builds only its own since s10).

Usage: .venv/bin/python benchmarks/cli_startup.py [--before 7697f7f] [--rounds 15]
Writes benchmarks/results/cli_startup.md (commit, date, load, the table).
"""
from __future__ import annotations

import argparse
import io
import os
import resource
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
COMMANDS = (["--version"], ["run", "--help"])


def _src_of(commit: str, tmp: Path) -> Path:
    data = subprocess.run(["git", "archive", commit, "src/cranefmu"], cwd=REPO, capture_output=True,
                          check=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(tmp, filter="data")
    return tmp / "src"


ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def _seconds(src: Path, args: list[str]) -> tuple[float, float]:
    """(wall, CPU) [s] of the command in a fresh process."""
    code = (f"import sys; sys.path.insert(0, {str(src)!r}); sys.argv = ['cranefmu', *{args!r}]\n"
            "from cranefmu.cli import main\nsys.exit(main())")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, cwd=tempfile.gettempdir(), env=ENV)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="7697f7f", help="the base commit (default 7697f7f, before s10's run path)")
    ap.add_argument("--rounds", type=int, default=15)
    a = ap.parse_args()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True).stdout
    dirty = subprocess.run(["git", "status", "--porcelain", "src"], cwd=REPO, capture_output=True, text=True).stdout
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        trees = {"before": _src_of(a.before, Path(tmp)), "after": REPO / "src"}
        times = {(t, " ".join(c)): [] for t in trees for c in COMMANDS}
        for _ in range(a.rounds):
            for command in COMMANDS:
                for tree, src in trees.items():
                    times[(tree, " ".join(command))].append(_seconds(src, command))
    lines = [f"# cranefmu start-up: before = {a.before}, after = {commit.strip()}{' + uncommitted src' if dirty else ''}",
             "", f"{datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, load average {load[0]:.1f} / {load[1]:.1f} / "
             f"{load[2]:.1f} (2 cores, shared), warm (files in the page cache), median of {a.rounds} alternating "
             "rounds of a fresh process each.", "",
             "| command | wall before [s] | wall after [s] | after / before | CPU before [s] | CPU after [s] | "
             "after / before |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for command in COMMANDS:
        name = " ".join(command)
        (wb, cb), (wa, ca) = [[statistics.median(x[i] for x in times[(t, name)]) for i in (0, 1)]
                              for t in ("before", "after")]
        lines.append(f"| `cranefmu {name}` | {wb:.3f} | {wa:.3f} | {wa / wb:.2f} | {cb:.3f} | {ca:.3f} | {ca / cb:.2f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "cli_startup.md").write_text(text)


if __name__ == "__main__":
    main()
