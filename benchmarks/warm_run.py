"""Wall time of a short run from the command line against the same run in-process: a base commit against
this checkout (issue 23 item 10: a warm CLI run cost 0.62-0.74 s against 14-114 ms in-process).

For each scene, ``--stop-time 0.1``: the whole ``cranefmu run`` command (a fresh process; the default
isolated run, i.e. a worker process, and ``--in-process``), and ``cranefmu.simulate`` in-process, warm (the
second run in one process, timed around the call).  The base commit is unpacked with ``git archive`` and
built once into a temporary folder; each tree runs with its own ``src`` first on ``PYTHONPATH`` (the worker
inherits it).  Rounds alternate the trees; the table gives medians.  "warm" for the commands means the files
are in the page cache; every command is a new process (nothing of a run survives it).

Usage: .venv/bin/python benchmarks/warm_run.py [--before 0cc7c7f] [--rounds 3] [--scenes a,b] [--smoke]
Writes benchmarks/results/warm_run.md (commits, date, load, the table); ``--smoke`` (CI: the numbers mean
nothing) is ``--before HEAD --rounds 1 --scenes elastic_pendulum`` into warm_run_smoke.md.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

from result_table import save, stamp

REPO = Path(__file__).resolve().parents[1]
SCENES = ("elastic_pendulum", "hook_sway", "overhead_lift", "truck_telescope")
STOP = "0.1"
_API = ("import sys, time, cranefmu\n"
        "cranefmu.simulate(sys.argv[1], stop_time=float(sys.argv[2]), progress=False)\n"
        "t0 = time.perf_counter(); cranefmu.simulate(sys.argv[1], stop_time=float(sys.argv[2]), progress=False)\n"
        "print(time.perf_counter() - t0)\n")


def _unpack(commit: str, tmp: Path) -> Path:
    data = subprocess.run(["git", "archive", "--format=tar", commit], cwd=REPO, capture_output=True, check=True).stdout
    tree = tmp / commit
    tree.mkdir()
    archive = tmp / "base.tar"
    archive.write_bytes(data)
    with tarfile.open(archive) as tar:
        tar.extractall(tree, filter="data")
    return tree


def _env(tree: Path, tmp: Path) -> dict:
    # bytecode written and reused as on a user's machine (this project's sessions set PYTHONDONTWRITEBYTECODE,
    # which made every command compile the package again); the FMUs' bundled modules are compiled in every run
    # regardless: each run extracts them afresh
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    return dict(env, PYTHONPATH=str(tree / "src"), CRANEFMU_CACHE_DIR=str(tmp / f"cache_{tree.name}"))


def _cli_seconds(tree: Path, tmp: Path, scene: str, *extra: str) -> float:
    cmd = [sys.executable, "-m", "cranefmu.cli", "run", scene, "--stop-time", STOP, "--output", str(tmp / "out.csv"),
           *extra]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, cwd=tmp, env=_env(tree, tmp))
    return time.perf_counter() - t0


def _api_seconds(tree: Path, tmp: Path, scene: str) -> float:
    out = subprocess.run([sys.executable, "-c", _API, scene, STOP], check=True, capture_output=True, text=True,
                         cwd=tmp, env=_env(tree, tmp))
    return float(out.stdout.split()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="0cc7c7f", help="the base commit (default 0cc7c7f)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--smoke", action="store_true",
                    help="--before HEAD --rounds 1 --scenes elastic_pendulum (CI; the numbers mean nothing)")
    a = ap.parse_args()
    if a.smoke:
        a.before, a.rounds, a.scenes = "HEAD", 1, "elastic_pendulum"
    scenes = a.scenes.split(",")
    load0 = os.getloadavg()
    kinds = ("cli", "cli --in-process", "api warm")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        trees = {"before": _unpack(a.before, tmp), "after": REPO}
        for tree in trees.values():   # FMUs and scenes built first, outside the timing
            subprocess.run([sys.executable, "-m", "cranefmu.cli", "build"], check=True, capture_output=True,
                           cwd=tree, env=_env(tree, tmp))
        times = {(t, s, k): [] for t in trees for s in scenes for k in kinds}
        for _ in range(a.rounds):
            for scene in scenes:
                for name, tree in trees.items():
                    times[(name, scene, "cli")].append(_cli_seconds(tree, tmp, scene))
                    times[(name, scene, "cli --in-process")].append(_cli_seconds(tree, tmp, scene, "--in-process"))
                    times[(name, scene, "api warm")].append(_api_seconds(tree, tmp, scene))
    lines = [f"# A {STOP} s run: command line against in-process, before = {a.before}, after = this checkout", "",
             f"{stamp('warm_run.py')} at the end, {load0[0]:.1f} at the start (2 cores, shared); warm page cache; "
             f"median of {a.rounds} alternating rounds, each command a fresh process.", "",
             "| scene | how | before [s] | after [s] | after / before |", "| --- | --- | --- | --- | --- |"]
    for scene in scenes:
        for kind in kinds:
            before, after = (statistics.median(times[(t, scene, kind)]) for t in ("before", "after"))
            lines.append(f"| {scene} | `{kind}` | {before:.3f} | {after:.3f} | {after / before:.2f} |")
    save("warm_run_smoke" if a.smoke else "warm_run", lines)


if __name__ == "__main__":
    main()
