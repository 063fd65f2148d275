"""CPU of the whole cold ``cranefmu run SCENE`` (native FMUs, stored settings, natural length): a base commit's
package against this checkout, alternating, at the same machine load.

The base commit's ``src/cranefmu`` and pyproject.toml are unpacked with ``git archive`` beside copies of this
checkout's built ``fmus/`` and ``ssp/`` (modification times kept, so nothing is rebuilt), and run through
``PYTHONPATH`` (which goes before the editable install), the worker of an isolated run included.  CPU = user +
system of the command and its children (``RUSAGE_CHILDREN``); Python's bytecode cache on (PYTHONDONTWRITEBYTECODE
removed, one untimed run per tree and scene first).  The table gives the least and the median of the rounds.

Usage: .venv/bin/python benchmarks/cold_run_ab.py [--before 7697f7f] [--rounds 3] [--scenes a,b]
Writes benchmarks/results/cold_run_ab.md.
"""
from __future__ import annotations

import argparse
import io
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

from result_table import save, stamp

REPO = Path(__file__).resolve().parents[1]
SCENES = ("elastic_pendulum", "overhead_lift", "hook_sway", "truck_telescope", "truck_slewing")
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def base_tree(commit: str, tmp: Path) -> Path:
    """A checkout-like folder of ``commit``'s package with this checkout's built FMUs and scenes."""
    data = subprocess.run(["git", "archive", commit, "src/cranefmu", "pyproject.toml"], cwd=REPO,
                          capture_output=True, check=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(tmp, filter="data")
    for folder in ("fmus", "ssp"):
        shutil.copytree(REPO / folder, tmp / folder, symlinks=True)   # copy2: times kept, nothing stale
    return tmp / "src"


def cpu(env: dict, scene: str, cwd: str) -> float:
    """CPU [s] of ``cranefmu run SCENE`` and its children."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run([sys.executable, "-m", "cranefmu.cli", "run", scene, "--no-progress"], env=env,
                          capture_output=True, text=True, cwd=cwd)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"cranefmu run {scene} failed: {done.stderr.strip()[-500:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="7697f7f")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--scenes", default=",".join(SCENES))
    a = ap.parse_args()
    t0 = time.time()
    head = stamp("cold_run_ab.py")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        src = base_tree(a.before, Path(tmp) / "base")
        trees = {a.before: {**ENV, "PYTHONPATH": str(src)}, "this checkout": ENV}
        for scene in a.scenes.split(","):
            from cranefmu.master.runspec import resolve

            stop = resolve(scene, fmus="native").settings.stop_time
            for env in trees.values():
                cpu(env, scene, tmp)   # untimed: bytecode written, files in the page cache
            got: dict[str, list[float]] = {t: [] for t in trees}
            for _ in range(a.rounds):
                for t, env in trees.items():
                    got[t].append(cpu(env, scene, tmp))
            (b_min, b_med), (n_min, n_med) = [(min(v), statistics.median(v)) for v in got.values()]
            print(f"{scene}: {got}", flush=True)
            rows.append(f"| {scene} | {stop:g} | {b_min:.3f} / {b_med:.3f} | {n_min:.3f} / {n_med:.3f} | "
                        f"{stop / b_min:.1f}x | {stop / n_min:.1f}x | {n_min / b_min:.2f} |")
    lines = [f"# Cold `cranefmu run SCENE`, native FMUs: {a.before} against this checkout", "", head,
             f"{os.cpu_count()} cores shared, load at the end {os.getloadavg()[0]:.1f}; {a.rounds} alternating "
             "rounds; CPU = user + system of the command and its children; bytecode cached.", "",
             f"| scene | T [s] | CPU {a.before}, least / median [s] | CPU this checkout, least / median [s] | "
             f"RTF {a.before} | RTF this checkout | this / {a.before} |",
             "| --- | --- | --- | --- | --- | --- | --- |", *rows]
    save("cold_run_ab", lines, t0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
