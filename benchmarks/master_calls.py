"""The per-step cost of the loop before and after a change to the master, in two measures that a loaded
machine disturbs little: Python function calls per macro step (a count) and CPU time per macro step.

    python benchmarks/master_calls.py [--before COMMIT] [--rounds N] [--scenes a,b] [--out FILE]

Each case (scene, algorithm, extrapolation; 0.5 s at H = 1 ms, no implicit group) runs once under
cProfile with the master of ``COMMIT`` (as :mod:`master_overhead` builds it: this checkout's package
with ``cranefmu/master`` of the commit) and once with this checkout's, each in a fresh process.  The
count includes the pythonfmu FMUs' own Python calls (the same on both sides) and the start (load,
initialization) spread over the steps.  Then, without the profiler, the CPU time per step of the
stepping (FMUs and master): ``time.process_time`` around a public ``run()`` of 2 s minus one of 0.5 s,
``N`` alternating rounds per side, the median.  Wall time (:mod:`master_overhead`) on a machine shared by many processes
varies by tens of percent between rounds; CPU time of one process far less.  Prints and saves a table.
"""
from __future__ import annotations

import argparse
import datetime
import os
import statistics
import subprocess
import tempfile
from pathlib import Path

from master_overhead import HERE, REPO, _package_with_master_of, run_child

# overhead_lift runs Gauss-Seidel without extrapolation (the scene's stored extrapolation, 0): with
# extrapolation 1 at H = 1 ms its hook bond (rope - pendulum) grows unstable since the physics merge (the
# instability alarm stops the 2 s run at t = 1.26 s; the SSD's settings note finds extrapolation 1 and 2
# unstable at 2-5 ms through the drum and hook bonds); x0 at 1 ms runs the scene's 6 s (measured 2026-11-26)
CASES = [("elastic_pendulum", "jacobi", 1), ("hook_sway", "jacobi", 1), ("overhead_lift", "gauss-seidel", 0),
         ("truck_telescope", "iterative", 1)]

CHILD = """
import cProfile, json, pstats
from cranefmu.master.run import run
out = {{}}
for scene, algorithm, p in {cases!r}:
    profile = cProfile.Profile()
    profile.enable()
    res = run(scene, stop_time=0.5, step_size=1e-3, algorithm=algorithm, extrapolation=p, implicit=[],
              progress=False, isolate=False)
    profile.disable()
    out[scene] = dict(calls=pstats.Stats(profile).total_calls, steps=res.stats.steps)
print("RESULT " + json.dumps(out))
"""


CPU_CHILD = """
import json, time
from cranefmu.master.run import run
scene, algorithm, p, stop = {case!r}
c0 = time.process_time()
res = run(scene, stop_time=stop, step_size=1e-3, algorithm=algorithm, extrapolation=p, implicit=[],
          progress=False, isolate=False, keep=False)
print("RESULT " + json.dumps([time.process_time() - c0, res.stats.steps]))
"""


def cpu_per_step(src: Path | None, case: tuple) -> float:
    """CPU seconds per macro step of the stepping alone: a run of 2 s minus a run of 0.5 s (the same
    loading and initialization), each in a fresh process, over the steps between."""
    long, n_long = run_child(CPU_CHILD.format(case=(*case, 2.0)), src)
    short, n_short = run_child(CPU_CHILD.format(case=(*case, 0.5)), src)
    return (long - short) / (n_long - n_short)


def count(src: Path | None, case: tuple) -> dict:
    """Calls and steps of one case with the master from ``src`` (None: this checkout), in a fresh process
    (pythonfmu FMUs do not survive a second instantiation in one process)."""
    return run_child(CHILD.format(cases=[case]), src)[case[0]]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="7bdeec9", help="commit whose master is 'before' (default 7bdeec9)")
    ap.add_argument("--rounds", type=int, default=3, help="CPU-time runs per side and case (default 3)")
    ap.add_argument("--scenes", default=",".join(c[0] for c in CASES),
                    help="comma-separated scenes of CASES to run (default all)")
    ap.add_argument("--out", default=str(HERE / "results" / "master_calls.md"))
    a = ap.parse_args()
    known = {c[0] for c in CASES}
    chosen = a.scenes.split(",")
    if not set(chosen) <= known:
        ap.error(f"--scenes {a.scenes!r}: allowed {', '.join(sorted(known))}")
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True).stdout
    dirty = " + uncommitted changes" if subprocess.run(["git", "diff", "--quiet", "HEAD", "--", "src"],
                                                       cwd=REPO).returncode else ""
    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    lines = [f"Per macro step: Python calls (cProfile total / steps; 0.5 s at H = 1 ms) and CPU time of the "
             f"stepping ((2 s - 0.5 s) / steps between, median of {a.rounds} alternating rounds per side): before = "
             f"master of "
             f"{a.before}, after = this checkout ({head.strip()}{dirty}); {when}, load {os.getloadavg()[0]:.1f} "
             "(the count does not depend on the load, the CPU time little).", "",
             "| scene | algorithm | extrapolation | steps | calls/step before | calls/step after | after - before | "
             "CPU us/step before (min-max) | CPU us/step after (min-max) | after/before |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as tmp:
        before_src = _package_with_master_of(a.before, Path(tmp))
        for case in (c for c in CASES if c[0] in chosen):
            b, f = count(before_src, case), count(None, case)
            per_b, per_f = b["calls"] / b["steps"], f["calls"] / f["steps"]
            cpu = {"before": [], "after": []}
            for _ in range(a.rounds):
                cpu["before"].append(cpu_per_step(before_src, case))
                cpu["after"].append(cpu_per_step(None, case))
            cb, cf = statistics.median(cpu["before"]) * 1e6, statistics.median(cpu["after"]) * 1e6
            spread = {k: f"{min(v) * 1e6:.0f}-{max(v) * 1e6:.0f}" for k, v in cpu.items()}
            lines.append(f"| {case[0]} | {case[1]} | {case[2]} | {f['steps']} | {per_b:.1f} | {per_f:.1f} | "
                         f"{per_f - per_b:+.1f} | {cb:.1f} ({spread['before']}) | {cf:.1f} ({spread['after']}) | "
                         f"{cf / cb:.3f} |")
    text = "\n".join(lines)
    print(text)
    Path(a.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
