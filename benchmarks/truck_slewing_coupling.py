"""truck_slewing (Chassis4 under a SlewingBoom): the boom's loads on the chassis held over each step or
interpolated, measured against the monolith (cranefmu.analysis.reference.solve, rtol 1e-10) at the scene's stored
setting (jacobi x1) and at 20, 10, 5, 2.5 ms.

Chassis4's carried boom inertia inputs (m_boom, Sx_boom, Sz_boom, Jp_boom, Jr_boom, Jpr_boom) took no rates;
the master feeds rates to a connection group only if every input in it takes them, so the whole group
boom -> chassis (forces and moments too) was held at its value at the step's start.  "held" reproduces that
by dropping the group's rates (benchmarks/truck_modes.py ``held``); "interpolated" is the build as it is.
Probe: the default slewing manoeuvre with the load sent up at 5 cm/s, 3 s; the error is the largest absolute
difference over the macro steps of each pad reaction and of the hook's position.

    nice -n 10 .venv/bin/python benchmarks/truck_slewing_coupling.py [--steps 0.02,0.01,0.005,0.0025] [--output FILE]

Prints and writes benchmarks/results/truck_slewing_coupling.md.
"""
from __future__ import annotations

import argparse
import contextlib
import datetime
import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from result_table import write  # noqa: E402
from truck_modes import held, order  # noqa: E402

from cranefmu.master import coupling as coupling_module  # noqa: E402
from cranefmu.master.run import run  # noqa: E402
from cranefmu.analysis.reference import solve  # noqa: E402

SCENE = "truck_slewing"
SPAN = 3.0
PROBE = {"pendulum.vy0": 0.05}
COLUMNS = ["chassis.N1", "chassis.N2", "chassis.N3", "chassis.N4", "pendulum.x", "pendulum.y", "pendulum.z"]
RESULTS = Path(__file__).parent / "results" / "truck_slewing_coupling.md"


def errors(h: float, hold: bool, ref: dict) -> dict[str, float]:
    """Largest |co-simulation - monolith| over the macro steps per column [N, m]."""
    with held("boom", "chassis") if hold else contextlib.nullcontext():
        res = run(SCENE, stop_time=SPAN, step_size=h, parameters=PROBE, progress=False, isolate=False).result
    t = res["time"]
    return {c: float(np.max(np.abs(res[c] - np.interp(t, ref["time"], ref[c])))) for c in COLUMNS}


def rates_of_boom_to_chassis() -> bool:
    """Whether the master feeds the group boom -> chassis rates (the build as it is)."""
    seen = []
    original = coupling_module.input_groups

    def spy(comps, connections, split=False):
        groups = original(comps, connections, split)
        seen.extend(bool(g.dt_vrs) for gs in groups for g in gs
                    if (comps[g.src].name, comps[g.dst].name) == ("boom", "chassis"))
        return groups

    coupling_module.input_groups = spy
    try:
        run(SCENE, stop_time=0.02, step_size=0.01, progress=False, isolate=False)
    finally:
        coupling_module.input_groups = original
    return all(seen) and bool(seen)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", default="0.02,0.01,0.005,0.0025", help="macro steps [s], comma separated, coarse first")
    ap.add_argument("--output", default=str(RESULTS))
    args = ap.parse_args(argv)
    steps = [float(s) for s in args.steps.split(",")]
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=Path(__file__).parent).stdout.strip()
    ref = solve(SCENE, SPAN, np.linspace(0.0, SPAN, int(round(SPAN / min(steps))) + 1), parameters=PROBE)
    lines = ["# truck_slewing: the boom's loads on Chassis4 held over each step or interpolated", "",
             f"- date: {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, commit {commit} (plus the working tree), "
             f"load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (no walls)",
             f"- machine: {platform.platform()}, python {platform.python_version()}",
             "- command: `nice -n 10 .venv/bin/python benchmarks/truck_slewing_coupling.py "
             f"{' '.join(argv if argv is not None else sys.argv[1:])}`",
             f"- probe: the default set's slewing manoeuvre, {PROBE}, {SPAN:g} s, stored setting jacobi x1; error = "
             "max |co-simulation - monolith (rtol 1e-10)| over the macro steps",
             f"- the group boom -> chassis takes rates in this build: {'yes' if rates_of_boom_to_chassis() else 'no'}",
             "", "| step | boom -> chassis | " + " | ".join(COLUMNS) + " |", "| --- | --- |" + " --- |" * len(COLUMNS)]
    table = {}
    for h in steps:
        for hold in (True, False):
            how = "held" if hold else "interpolated"
            e = table[(h, how)] = errors(h, hold, ref)
            lines.append(f"| {h * 1e3:g} ms | {how} | " + " | ".join(f"{e[c]:.3e}" for c in COLUMNS) + " |")
            print(lines[-1], flush=True)
    lines += ["", "Observed order p = log(e(h) / e(h/2)) / log 2:", "",
              "| steps | boom -> chassis | " + " | ".join(COLUMNS) + " |", "| --- | --- |" + " --- |" * len(COLUMNS)]
    for a, b in zip(steps, steps[1:]):
        for how in ("held", "interpolated"):
            lines.append(f"| {a * 1e3:g} -> {b * 1e3:g} ms | {how} | " + " | ".join(
                order(table[(a, how)][c], table[(b, how)][c], a / b) for c in COLUMNS) + " |")
    return write(args.output, lines)


if __name__ == "__main__":
    sys.exit(main())
