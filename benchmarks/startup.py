"""Start-up cost of a run, cold and warm, the cost of many short runs, and how fast a signal ends a run.

1. Per scene, in a fresh process (``python -c``): the import of cranefmu.master.run, then three runs of
   one macro step each (scene loaded and extracted, FMUs instantiated and initialized, one step,
   everything freed): the first is "cold", the later ones "warm" (the extraction is kept for the
   process, see cranefmu.master.extracted).  One run with ``isolate=True`` (a worker process) too.
2. elastic_pendulum: N short runs of length T in a loop against one run of N*T (the same simulated
   work): ratio = wall(N short) / wall(one long), for T = 0.1, 0.3, 1 s at H = 1 ms.
3. The CLI on a long run: SIGINT or SIGTERM to it once 1000 rows are on disk; seconds to its exit.

Usage: .venv/bin/python benchmarks/startup.py [--repeat 3] [--runs 100]
Writes benchmarks/results/startup.md.  Times are medians of --repeat processes (the machine is shared).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import signal
import statistics
import subprocess
import sys
import tempfile
import time as clock
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
SCENES = ("elastic_pendulum", "hook_sway", "overhead_lift", "truck_telescope")

STARTUP = """
import json, sys, time
t0 = time.perf_counter()
import cranefmu.master.execution as m
from cranefmu.master.run import run
t1 = time.perf_counter()
inner, spent = m.initialize, []
def timed(*a, **k):   # the equilibrium solve of initialization: physics, not start-up overhead
    b = time.perf_counter()
    try:
        return inner(*a, **k)
    finally:
        spent.append(time.perf_counter() - b)
m.initialize = timed
scene, h = sys.argv[1], float(sys.argv[2])
walls = []
for i in range(3):
    a = time.perf_counter()
    run(scene, stop_time=h, step_size=h, progress=False)
    walls.append(time.perf_counter() - a)
m.initialize = inner
warm = min(range(1, 3), key=lambda i: walls[i])
a = time.perf_counter()
run(scene, stop_time=h, step_size=h, progress=False, isolate=True)
iso = time.perf_counter() - a
print(json.dumps({"import": t1 - t0, "cold": walls[0], "warm": walls[warm], "init": spent[warm],
                  "warm_no_init": walls[warm] - spent[warm], "isolated": iso}))
"""

LOOP = """
import json, sys, time
from cranefmu.master.run import run
n, short, h = int(sys.argv[1]), float(sys.argv[2]), 1e-3
run("elastic_pendulum", stop_time=h, step_size=h, progress=False)          # cold start paid once
a = time.perf_counter()
run("elastic_pendulum", stop_time=n * short, step_size=h, keep=False, progress=False)
long_wall = time.perf_counter() - a
a = time.perf_counter()
for _ in range(n):
    run("elastic_pendulum", stop_time=short, step_size=h, progress=False)
print(json.dumps({"long": long_wall, "short": time.perf_counter() - a}))
"""


CRASHES: list[str] = []   # processes that printed their measurement and then died at exit


def python(code: str, *args: str) -> dict:
    p = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True)
    if p.returncode != 0:
        if not p.stdout.strip():
            raise RuntimeError(f"{args}: exit {p.returncode}: {p.stderr[-2000:]}")
        last = (p.stderr.strip().splitlines() or ["(no output)"])[-1]
        CRASHES.append(f"{' '.join(args)}: exit {p.returncode} after the measurement ({last})")
        print("crash at exit:", CRASHES[-1], flush=True)
    return json.loads(p.stdout.splitlines()[-1])


def signal_to_exit(signum: int, extra: list[str]) -> float:
    """Seconds from the signal to the CLI's exit, on a long elastic_pendulum run with 1000 rows on disk."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out.csv"
        part = Path(tmp) / "out.csv.part"
        proc = subprocess.Popen([sys.executable, "-m", "cranefmu.cli", "run", "elastic_pendulum", "--stop-time",
                                 "200", "--output", str(out), *extra], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        while not (part.exists() and part.read_bytes().count(b"\n") > 1000):
            clock.sleep(0.01)
        t0 = clock.perf_counter()
        proc.send_signal(signum)
        proc.wait()
        return clock.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--runs", type=int, default=100)
    a = ap.parse_args()
    from cranefmu.build import build

    build(verbose=False)
    lines = ["# Start-up cost of a run", "",
             f"`benchmarks/startup.py --repeat {a.repeat} --runs {a.runs}` on {platform.node()} "
             f"({os.cpu_count()} cores, shared), Python {platform.python_version()}; medians of {a.repeat} processes.",
             "", "## One-step runs (ms): cold = first in a process, warm = later ones, isolated = worker process",
             "", "warm = start-up (load, instantiate, free) + initialization (the FMUs' static equilibrium, "
             "iterated by cranefmu.master.initialization) + one step.", "",
             "| scene | import | cold | warm | of which initialization | warm without it | isolated |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for scene in SCENES:
        got = [python(STARTUP, scene, "1e-3") for _ in range(a.repeat)]
        med = {k: 1e3 * statistics.median(g[k] for g in got) for k in got[0]}
        lines.append(f"| {scene} | {med['import']:.0f} | {med['cold']:.0f} | {med['warm']:.1f} | "
                     f"{med['init']:.1f} | {med['warm_no_init']:.1f} | {med['isolated']:.0f} |")
        print(lines[-1], flush=True)
    lines += ["", f"## {a.runs} short runs in a loop against one run of the same simulated time "
              "(elastic_pendulum, H = 1 ms)", "",
              "| short run [s] | one long run [s] | short runs [s] | ratio | start-up per run [ms] |",
              "| ---: | ---: | ---: | ---: | ---: |"]
    for short in (0.1, 0.3, 1.0):
        got = [python(LOOP, str(a.runs), str(short)) for _ in range(a.repeat)]
        long_wall = statistics.median(g["long"] for g in got)
        short_wall = statistics.median(g["short"] for g in got)
        lines.append(f"| {short:g} | {long_wall:.2f} | {short_wall:.2f} | {short_wall / long_wall:.2f} | "
                     f"{1e3 * (short_wall - long_wall) / a.runs:.1f} |")
        print(lines[-1], flush=True)
    lines += ["", "## Signal to exit of `cranefmu run` (s), 1000 rows on disk", "",
              "| signal | worker (default) | --in-process |", "| --- | ---: | ---: |"]
    for signum in (signal.SIGINT, signal.SIGTERM):
        cells = [statistics.median(signal_to_exit(signum, extra) for _ in range(a.repeat))
                 for extra in ([], ["--in-process"])]
        lines.append(f"| {signal.Signals(signum).name} | {cells[0]:.3f} | {cells[1]:.3f} |")
        print(lines[-1], flush=True)
    lines += ["", f"Processes that died at exit after printing their measurement: {len(CRASHES)}"]
    lines += [f"- {c}" for c in CRASHES]
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "startup.md").write_text("\n".join(lines) + "\n")
    print(f"wrote {RESULTS / 'startup.md'}")


if __name__ == "__main__":
    main()
