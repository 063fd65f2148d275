"""What the modal limits cost (issue 24): the warm wall time of elastic_pendulum's old stored setting
(jacobi x2, 20 ms) against the new one (jacobi x2, 5 ms) over the scene's 20 s, both in one process,
alternating, REPEATS times each, the least wall of each kept (the machine is shared).  Prints and writes
benchmarks/results/honesty_cost.md.

    nice .venv/bin/python benchmarks/honesty_cost.py
"""
from __future__ import annotations

import datetime
import os
import subprocess
import sys
from pathlib import Path

from cranefmu.master.run import run
from scene_defaults import publish   # benchmarks/ is on the path of a script run from it

SCENE, STOP, REPEATS = "elastic_pendulum", 20.0, 5
SETTINGS = {"old: jacobi x2, 20 ms": 0.02, "new: jacobi x2, 5 ms": 0.005}
RESULTS = Path(__file__).parent / "results" / "honesty_cost.md"


def main() -> int:
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=Path(__file__).parent).stdout.strip()
    run(SCENE, stop_time=0.1, step_size=0.01, isolate=False, progress=False)   # the one-time load, untimed
    walls: dict[str, list[float]] = {k: [] for k in SETTINGS}
    for _ in range(REPEATS):
        for label, h in SETTINGS.items():
            res = run(SCENE, stop_time=STOP, step_size=h, algorithm="jacobi", extrapolation=2, implicit=[],
                      isolate=False, progress=False)
            walls[label].append(res.stats.wall_time)
    best = {k: min(v) for k, v in walls.items()}
    old, new = best.values()
    lines = ["# What keeping the axial mode costs on elastic_pendulum", "",
             f"- date: {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, commit {commit}, load average "
             f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (shared)",
             "- command: `nice .venv/bin/python benchmarks/honesty_cost.py`", "",
             f"{STOP:g} s simulated, warm, in one process, least of {REPEATS} alternating runs each.", "",
             "| setting | least wall [s] | real-time factor | all walls [s] |", "| --- | --- | --- | --- |"]
    lines += [f"| {k} | {best[k]:.3f} | {STOP / best[k]:.1f} | {', '.join(f'{w:.3f}' for w in walls[k])} |"
              for k in SETTINGS]
    lines += ["", f"The new setting costs {new / old:.2f} times the old one's wall."]
    return publish(lines, RESULTS)


if __name__ == "__main__":
    if sys.argv[1:] == ["--smoke"]:   # CI: 0.2 s, once each (the numbers mean nothing)
        STOP, REPEATS, RESULTS = 0.2, 1, RESULTS.with_name("honesty_cost_smoke.md")
    sys.exit(main())
