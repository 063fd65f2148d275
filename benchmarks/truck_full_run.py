"""Stability of truck_telescope's stored coupling settings over the whole 40 s run, against the monolith.

Runs the default set with the scene's stored settings at several macro steps (everything else as stored)
and the monolithic reference, and writes benchmarks/results/truck_full_run.md: end time reached (a run
that grows an oscillation unloads the front outrigger and stops there), front outrigger minimum, rear
maximum and largest sway.

    nice -n 10 .venv/bin/python benchmarks/truck_full_run.py [step ...]      (default 0.02 0.01 0.005)

A run the instability alarm stops is a row with the time it reached and its rows' metrics.
"""
from __future__ import annotations

import sys

import numpy as np

from result_table import save, stamp

from cranefmu.errors import SimulationError
from cranefmu.master.run import run
from cranefmu.analysis.reference import solve
from cranefmu.scenes import metrics

STOP = 40.0
KEYS = ("N_front_min", "N_rear_max", "max_sway_deg", "tipping_time")


def row(engine: str, end: float, m: dict) -> str:
    return f"| {engine} | {end:.2f} | " + " | ".join(f"{m[k]:.6g}" for k in KEYS) + " |"


def main(steps: list[float], name: str = "truck_full_run") -> None:
    lines = [f"# truck_telescope: stored settings over {STOP:g} s", "",
             f"{stamp('truck_full_run.py')}).", "",
             "| engine | end [s] | " + " | ".join(KEYS) + " |", "|" + " --- |" * (len(KEYS) + 2)]
    ref = solve("truck_telescope", STOP, np.linspace(0.0, STOP, 4001), rtol=1e-6)
    lines.append(row("monolithic (Radau, rtol 1e-6)", STOP, metrics("truck_telescope", ref)))
    for h in steps:
        label = f"stored settings, H = {h:g} s"
        try:
            res = run("truck_telescope", stop_time=STOP, step_size=h, progress=False).result
        except SimulationError as err:   # the alarm: keep the rows it had and say so
            res, label = err.result, label + f" (stopped: {str(err).splitlines()[0][:90]})"
        lines.append(row(label, float(res["time"][-1]), metrics("truck_telescope", res)))
        print(lines[-1], flush=True)
    save(name, lines)


if __name__ == "__main__":
    if sys.argv[1:] == ["--smoke"]:   # CI: 0.5 s at the stored step (the numbers mean nothing)
        STOP = 0.5
        main([0.005], "truck_full_run_smoke")
    else:
        main([float(a) for a in sys.argv[1:]] or [0.02, 0.01, 0.005])
