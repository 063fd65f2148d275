"""Where overhead_lift with the Bouc-Wen rope (tight lift, default set) is stable, and how accurate: the
scene's stored setting, jacobi x0 at 1 ms (the stored setting before issue 24) and smaller explicit steps, and
every power bond implicit at 1 ms, each
against the monolithic solve (rtol 1e-7) over 6 s: dynamic factor, worst error of range of the key
outputs, the alarm's message or the bond warning.  Prints and writes benchmarks/results/bouc_wen_step.md.

    nice .venv/bin/python benchmarks/bouc_wen_step.py
"""
from __future__ import annotations

import datetime
import subprocess
import sys
from pathlib import Path

import numpy as np

from cranefmu.analysis.converge import key_outputs
from cranefmu.errors import SimulationError
from cranefmu.master.run import run
from scene_defaults import publish   # benchmarks/ is on the path of a script run from it
from cranefmu.analysis.reference import solve
from cranefmu.scenes import overhead_lift_metrics

STOP = 6.0
BOUC_WEN = {"rope.model": "bouc_wen"}
X0 = {"algorithm": "jacobi", "extrapolation": 0}
CASES = (("the scene's stored setting", {}), ("jacobi x0, 1 ms", {**X0, "step_size": 1e-3}),
         ("jacobi x0, 0.5 ms", {**X0, "step_size": 5e-4}), ("jacobi x0, 0.25 ms", {**X0, "step_size": 2.5e-4}),
         ("jacobi x0, 1 ms, every bond implicit", {**X0, "step_size": 1e-3, "implicit": ["hook", "drum", "trolley"]}))
RESULTS = Path(__file__).parent / "results" / "bouc_wen_step.md"


def main() -> int:
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=Path(__file__).parent).stdout.strip()
    rows, results = [], {}
    for label, settings in CASES:
        try:
            res = run("overhead_lift", stop_time=STOP, parameters=BOUC_WEN, progress=False, **settings)
        except SimulationError as err:
            rows.append((label, str(err).splitlines()[0][:200]))
            print(label, rows[-1][1], flush=True)
            continue
        results[label] = res
        print(label, "ran", flush=True)
    # the reference on the union of the runs' times (the 1 ms grid where every run stopped)
    t = (np.unique(np.concatenate([r.result["time"] for r in results.values()])) if results
         else np.arange(0.0, STOP + 5e-4, 1e-3))
    ref = solve("overhead_lift", STOP, t, parameters=BOUC_WEN, rtol=1e-7)
    df_ref = overhead_lift_metrics(ref)["dynamic_factor"]
    lines = ["# overhead_lift with the Bouc-Wen rope (tight): where it is stable", "",
             f"- date: {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, commit {commit}; shared 2-core machine",
             "- command: `nice .venv/bin/python benchmarks/bouc_wen_step.py`", "",
             f"Monolithic dynamic factor {df_ref:.4f} (rtol 1e-7, {STOP:g} s).", "",
             "| setting | outcome | dynamic factor | worst error of range (key output) | bond warning |",
             "| --- | --- | --- | --- | --- |"]
    for label, outcome in rows:
        lines.append(f"| {label} | stopped: {outcome} | | | |")
    for label, res in results.items():
        r = res.result
        idx = np.searchsorted(t, r["time"])
        errs = {k: float(np.max(np.abs(r[k] - ref[k][idx])) / np.ptp(ref[k])) for k in key_outputs("overhead_lift")}
        worst = max(errs, key=errs.get)
        lines.append(f"| {label} | ran | {overhead_lift_metrics(r)['dynamic_factor']:.4f} | {errs[worst]:.3g} ({worst}) | "
                     f"{res.warnings[0][:120] if res.warnings else 'none'} |")
    return publish(lines, RESULTS)


if __name__ == "__main__":
    if sys.argv[1:] == ["--smoke"]:   # CI: the stored setting and the implicit bonds over 0.3 s (numbers mean nothing)
        STOP, CASES, RESULTS = 0.3, (CASES[0], CASES[-1]), RESULTS.with_name("bouc_wen_step_smoke.md")
    sys.exit(main())
