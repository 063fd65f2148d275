"""truck_slewing over its whole 30 s slew, against the monolith: the macro step the scene stores.

Runs the default set (slewing 90 deg, 2 t at 60 deg, 10.5 m) with plain-coupling Jacobi (extrapolation 1, no
implicit bond) at several macro steps and the monolithic reference, and writes
benchmarks/results/truck_slewing.md: largest sway, smallest and largest pad reaction, tipping, and the
static closed-form reactions over the side for comparison.

    nice -n 10 .venv/bin/python benchmarks/truck_slewing.py [step ...]      (default 0.005 0.002 0.001)
"""
from __future__ import annotations

import sys

import numpy as np

from result_table import save, stamp

from cranefmu.master.run import run
from cranefmu.reference import solve
from cranefmu.scenes import metrics, pad_tipping_load, static_pad_reactions

STOP = 30.0
KEYS = ("max_sway_deg", "N_min", "N_max", "tipping")


def row(engine: str, m: dict) -> str:
    return f"| {engine} | " + " | ".join(f"{m[k]:.6g}" for k in KEYS) + " |"


def main(steps: list[float]) -> None:
    lines = [f"# truck_slewing: 90 deg slew over {STOP:g} s", "",
             f"{stamp('truck_slewing.py')}).", "",
             "| engine | " + " | ".join(KEYS) + " |", "|" + " --- |" * (len(KEYS) + 1)]
    ref = solve("truck_slewing", STOP, np.linspace(0.0, STOP, 6001), rtol=1e-7)
    lines.append(row("monolithic (Radau, rtol 1e-7)", metrics("truck_slewing", ref)))
    print(lines[-1], flush=True)
    for h in steps:
        res = run("truck_slewing", stop_time=STOP, step_size=h, algorithm="jacobi", extrapolation=1, implicit=[],
                  progress=False).result
        lines.append(row(f"jacobi x1, H = {h:g} s", metrics("truck_slewing", res)))
        print(lines[-1], flush=True)
    static = static_pad_reactions(10.5, 60.0, 2000.0, 90.0)
    lines += ["", "Static pad reactions over the side (closed form, scenes.static_pad_reactions): "
              + ", ".join(f"N{i} {n:.6g} N" for i, n in enumerate(static, 1))
              + f"; tipping load over the side {pad_tipping_load(10.5, 60.0, 90.0):.6g} kg, over the rear "
              f"{pad_tipping_load(10.5, 60.0, 0.0):.6g} kg (scenes.pad_tipping_load)."]
    save("truck_slewing", lines)


if __name__ == "__main__":
    main([float(a) for a in sys.argv[1:]] or [0.005, 0.002, 0.001])
