"""Per-run overhead of a sweep worker with native FMUs: each run's FMUs loaded afresh from directories of
their own (before) against the instances kept between runs of the scene and reset (after, master/fmu.py).
The whole sweep path (Dask, table) with its stages: benchmarks/sweep_overhead.py.

    .venv/bin/python benchmarks/sweep_reuse.py            # 30 one-step runs and 5 runs of 2 s per mode
    .venv/bin/python benchmarks/sweep_reuse.py --runs 10  # smaller

What a sweep worker runs (sweep.worker.execute: resolve, run, metric, row), in this process, warm.
Overhead per run: median task time of a one-step run (set-up, metric, row).  Integration of a 2 s run:
median task time of a run to 2 s (H = 1 ms) minus the overhead.  Writes benchmarks/results/sweep_reuse.md.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import time as clock
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def main(argv: list[str] | None = None) -> None:
    from cranefmu.master import execution
    from cranefmu.master.runspec import resolve
    from cranefmu.sweep.metrics import parse_metric
    from cranefmu.sweep.spec import Run
    from cranefmu.sweep.worker import SspFile, execute

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--long", type=int, default=5)
    args = ap.parse_args(argv)
    ssp = SspFile.of(resolve("elastic_pendulum", fmus="native").ssp, "elastic_pendulum", False)
    metrics = [parse_metric("max:rope.tension")]
    in_place = execution.instantiates_in_place

    def task(i: int, stop: float) -> float:
        row = execute(ssp, Run("elastic_pendulum", {"rope.E": 2e10 * (1 + i / 100), "stop_time": stop,
                                                    "step_size": 1e-3, "fmus": "native"}), metrics)
        assert row["status"] == "ok", row
        return row["task_time"]

    rows = []
    for mode in ("fresh (before)", "kept, fmi2Reset (after)"):
        execution.instantiates_in_place = (lambda w, s: False) if mode.startswith("fresh") else in_place
        for i in range(3):
            task(i, 1e-3)   # warm
        setup = statistics.median(task(i, 1e-3) for i in range(args.runs))
        whole = statistics.median(task(i, 2.0) for i in range(args.long))
        rows.append((mode, setup, whole - setup))
    execution.instantiates_in_place = in_place
    load = os.getloadavg()[0]
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    lines = ["# Sweep worker per-run overhead, native FMUs (benchmarks/sweep_reuse.py)", "",
             f"Commit {commit}, {clock.strftime('%Y-%m-%d %H:%M UTC', clock.gmtime())}, load {load:.1f} "
             f"(2 cores shared), {args.runs} one-step runs and {args.long} runs of 2 s (H = 1 ms) per mode, "
             "elastic_pendulum, in one warm process as a sweep worker runs them.", "",
             "| FMUs between runs | overhead per run [ms] | integration of a 2 s run [ms] | overhead / integration |",
             "| --- | --- | --- | --- |"]
    for mode, setup, work in rows:
        lines.append(f"| {mode} | {setup * 1e3:.1f} | {work * 1e3:.1f} | {100 * setup / work:.1f} % |")
    text = "\n".join(lines) + "\n"
    print(text)
    (ROOT / "benchmarks" / "results" / "sweep_reuse.md").write_text(text)


if __name__ == "__main__":
    main()
