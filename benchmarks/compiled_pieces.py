"""CPU time of runs that took the Python exchange before issue 34's second step and take compiled pieces
now: commanded inputs (compiled stretches), an event-started command (a kernel call a step), the implicit
group and the iterative algorithm (their evaluations of G(u) and closing exchange in the kernel), each run
with the Python exchange (``CRANEFMU_PYTHON_EXCHANGE=1``: every step as before) and with the compiled one.

    .venv/bin/python benchmarks/compiled_pieces.py [--rounds 2] [--scale 1.0] [--out DIR]

Each run in a fresh process (one BLAS thread), native FMUs where the scene has them (the default kind),
``keep=False``, no output file: CPU time (``time.process_time``) of ``run`` minus that of a run of a tenth
of the length (loading, initialization and the start-up cancel; a first short run before both pays the
one-time costs), per macro step, the best of ``rounds``.
``--scale`` multiplies every run's length.  Prints and saves benchmarks/results/compiled_pieces.md.
Not a test.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

from result_table import stamp

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"

LOWER = [{"start": 0.5, "to": 0.5, "speed": 0.2, "accel_time": 0.5}]
# label, scene, run settings, stop time [s], commands: None, "moves" or "event"
CASES = [
    ("elastic_pendulum, payout commanded (lower_and_stop)", "elastic_pendulum", {}, 4.0, "moves"),
    ("elastic_pendulum, payout started by an event", "elastic_pendulum", {}, 4.0, "event"),
    ("overhead_lift --parameter-set loose (implicit group of 3)", "overhead_lift", {"parameter_set": "loose"}, 1.0, None),
    ("truck_telescope --parameter-set luff30 (implicit group of 5)", "truck_telescope", {"parameter_set": "luff30"}, 1.0,
     None),
    ("elastic_pendulum, algorithm iterative x1", "elastic_pendulum", {"algorithm": "iterative", "extrapolation": 1}, 2.0,
     None),
]

CHILD = r"""
import json, sys, time
from cranefmu.master.run import run
from cranefmu.master.commands import Command
from cranefmu.experiments.profiles import moves
from cranefmu.experiments.events import Trigger, Triggered
scene, settings, stop, kind, lower = json.loads(sys.argv[1])
def commands():
    if kind == "moves":
        p = moves(0.0, lower)
        return [Command("rope.payout", p), Command("rope.payout_rate", p.derivative())]
    if kind == "event":
        return [Command("rope.payout", Triggered(moves(0.0, lower), Trigger("pendulum.theta < 0"), "start"))]
    return []
out = []
for t_end in (stop / 10, stop / 10, stop):   # the first pays the one-time costs (imports, loading the kernel)
    c0 = time.process_time()
    r = run(scene, stop_time=t_end, progress=False, keep=False, commands=commands(), **settings)
    out.append((time.process_time() - c0, r.stats.steps, r.stats.compiled_steps, r.stats.kernel_calls))
print(json.dumps(out))
"""


def measure(case, compiled: bool, scale: float) -> dict:
    _, scene, settings, stop, kind = case
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               CRANEFMU_PYTHON_EXCHANGE="0" if compiled else "1")
    arg = json.dumps([scene, settings, stop * scale, kind, LOWER])
    done = subprocess.run([sys.executable, "-c", CHILD, arg], capture_output=True, text=True, env=env, timeout=900)
    if done.returncode != 0:
        raise RuntimeError(done.stderr.strip().splitlines()[-1] if done.stderr.strip() else f"rc {done.returncode}")
    _, (c_short, s_short, _, _), (c_long, s_long, comp, calls) = json.loads(done.stdout.strip().splitlines()[-1])
    return dict(per_step=(c_long - c_short) / (s_long - s_short), steps=s_long, compiled=comp, calls=calls)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--out", type=Path, default=RESULTS)
    a = ap.parse_args()
    lines = [stamp(f"compiled_pieces.py --rounds {a.rounds} --scale {a.scale:g}"), "",
             "CPU per macro step (us), best of the rounds; `compiled steps / kernel calls` of the compiled run.", "",
             "| run | steps | Python exchange | compiled | ratio | compiled steps / kernel calls |",
             "|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    for case in CASES:
        best = {}
        for compiled in (False, True):
            runs = [measure(case, compiled, a.scale) for _ in range(a.rounds)]
            best[compiled] = min(runs, key=lambda r: r["per_step"])
        py, cc = best[False]["per_step"] * 1e6, best[True]["per_step"] * 1e6
        line = (f"| {case[0]} | {best[True]['steps']} | {py:.0f} | {cc:.0f} | {py / cc:.2f} | "
                f"{best[True]['compiled']} / {best[True]['calls']} |")
        lines.append(line)
        print(line, flush=True)
    lines += ["", f"Load while measuring: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (a shared machine: "
              "the ratios are the result, not the absolute times)."]
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "compiled_pieces.md").write_text("\n".join(lines) + "\n")
    print(f"saved {a.out / 'compiled_pieces.md'}", file=sys.stderr)


if __name__ == "__main__":
    main()
