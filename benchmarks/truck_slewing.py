"""truck_slewing over its whole 30 s slew, against the monolith: the macro step the scene stores.

Runs the default set (slewing 90 deg, 2 t at 60 deg, 10.5 m) with plain-coupling Jacobi (extrapolation 1, no
implicit bond) at several macro steps and the monolithic reference, and writes
benchmarks/results/truck_slewing.md: largest sway, smallest and largest pad reaction, tipping, and the
static closed-form reactions over the side for comparison.

    nice -n 10 .venv/bin/python benchmarks/truck_slewing.py [step ...]      (default 0.005 0.002 0.001)
    .venv/bin/python benchmarks/truck_slewing.py --smoke     (CI: 1 s at 0.005 s into truck_slewing_smoke.md;
                                                              the numbers mean nothing)
"""
from __future__ import annotations

import math
import sys

import numpy as np

from result_table import save, stamp

from cranefmu.master.run import run
from cranefmu.analysis.reference import Monolith, solve
from cranefmu.scenes import metrics, pad_tipping_load_tilt_free, static_pad_reactions

STOP = 30.0
FREE = 19.0   # [s] the slew is over: free swing after it
KEYS = ("max_sway_deg", "N_min", "N_max", "tipping")


def row(engine: str, m: dict) -> str:
    return f"| {engine} | " + " | ".join(f"{m[k]:.6g}" for k in KEYS) + " |"


def main(steps: list[float], stop: float = STOP, result: str = "truck_slewing") -> None:
    lines = [f"# truck_slewing: 90 deg slew over {stop:g} s", "",
             f"{stamp('truck_slewing.py')}).", "",
             "| engine | " + " | ".join(KEYS) + " |", "|" + " --- |" * (len(KEYS) + 1)]
    ref = solve("truck_slewing", stop, np.linspace(0.0, stop, int(round(200 * stop)) + 1), rtol=1e-7)
    lines.append(row("monolithic (Radau, rtol 1e-7)", metrics("truck_slewing", ref)))
    print(lines[-1], flush=True)
    for h in steps:
        res = run("truck_slewing", stop_time=stop, step_size=h, algorithm="jacobi", extrapolation=1, implicit=[],
                  progress=False).result
        lines.append(row(f"jacobi x1, H = {h:g} s", metrics("truck_slewing", res)))
        print(lines[-1], flush=True)
    lines += ["", "Free swing after the slew (t > 19 s, stored settings): period of each horizontal component "
              "(upward zero crossings) against 2 pi sqrt(l / g) of the hanging length l at rest: "
              + (free_swing(run("truck_slewing", stop_time=stop, progress=False).result) if stop > FREE
                 else f"not measured (a run of {stop:g} s)") + ".", "",
              "## At rest: pad reactions [N], closed form (scenes.static_pad_reactions) and the scene (monolith at its "
              "initial state), 2 t, 60 deg, 10.5 m", "",
              "| slewing angle [deg] | N1 | N2 | N3 | N4 | largest relative difference |", "| --- | --- | --- | --- | --- | --- |"]
    for deg in (0.0, 45.0, 90.0, 180.0):
        closed = static_pad_reactions(10.5, 60.0, 2000.0, deg)
        mono = Monolith("truck_slewing", parameters={"boom.slew_angle_start": math.radians(deg), "boom.slew_angle": 0.0})
        y = dict(zip(mono.columns, mono.output_row(0.0, mono.initial_state(0.0))))
        scene = np.array([y[f"chassis.N{i}"] for i in range(1, 5)])
        lines.append(f"| {deg:g} | " + " | ".join(f"{n:.6g}" for n in closed)
                     + f" | {np.max(np.abs(scene / closed - 1.0)):.2g} |")
    lines += ["", "Tipping loads (rigid statics, tilt-free: scenes.pad_tipping_load_tilt_free; with the settled tilt, "
              "the scene's own: benchmarks/truck_slewing_tipping.py), 60 deg, 10.5 m: "
              + ", ".join(f"{name} {pad_tipping_load_tilt_free(10.5, 60.0, deg):.6g} kg"
                          for name, deg in (("over the rear", 0.0), ("at 45 deg", 45.0), ("over the side", 90.0),
                                            ("over the front", 180.0))) + "."]
    save(result, lines)


def free_swing(res) -> str:
    t = res["time"]
    drop = res["boom.y_tip"][0] - res["pendulum.y"][0]
    closed = 2.0 * math.pi * math.sqrt(drop / 9.81)
    out = [f"closed form {closed:.6g} s (l = {drop:.6g} m)"]
    free = t > FREE
    for c in ("x", "z"):
        d = (res[f"pendulum.{c}"] - res[f"boom.{c}_tip"])[free]
        d, tf = d - d.mean(), t[free]
        i = np.flatnonzero((d[:-1] < 0.0) & (d[1:] >= 0.0))
        ups = tf[i] - d[i] * (tf[i + 1] - tf[i]) / (d[i + 1] - d[i])
        period = (ups[-1] - ups[0]) / (len(ups) - 1)
        out.append(f"{c}: {period:.6g} s ({100 * (period / closed - 1):+.3f} %)")
    return ", ".join(out)


if __name__ == "__main__":
    if sys.argv[1:] == ["--smoke"]:
        main([0.005], stop=1.0, result="truck_slewing_smoke")
    else:
        main([float(a) for a in sys.argv[1:]] or [0.005, 0.002, 0.001])
