"""Group steps a macro step of the implicit group (every bond of truck_telescope implicit), with the boom's
loads on the chassis interpolated over the step (the build as it is) and held at the step's start (as before
the chassis' carried-inertia inputs took rates; benchmarks/truck_modes.py ``held``): the figure
src/cranefmu/master/implicit_group.py quotes.  The runs of tests/master/test_implicit_group.py's 40 ms test:
13 s, jacobi x1, coupling tolerance 1e-5.

    nice -n 10 .venv/bin/python benchmarks/implicit_group_steps.py [--steps 0.01,0.02,0.04] [--stop 13] [--output FILE]

Prints and writes benchmarks/results/implicit_group_steps.md.
"""
from __future__ import annotations

import argparse
import contextlib
import datetime
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from result_table import write  # noqa: E402
from truck_modes import held  # noqa: E402

from cranefmu.master.run import run  # noqa: E402

BONDS = ["foot_heave", "foot_tilt", "tip", "hook", "drum"]
RESULTS = Path(__file__).parent / "results" / "implicit_group_steps.md"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", default="0.01,0.02,0.04", help="macro steps [s], comma separated")
    ap.add_argument("--stop", type=float, default=13.0, help="stop time [s]")
    ap.add_argument("--output", default=str(RESULTS))
    args = ap.parse_args(argv)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=Path(__file__).parent).stdout.strip()
    lines = ["# The implicit group's steps a macro step (truck_telescope, every bond implicit)", "",
             f"- date: {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, commit {commit}, load "
             f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (no walls)",
             "- command: `nice -n 10 .venv/bin/python benchmarks/implicit_group_steps.py "
             f"{' '.join(argv if argv is not None else sys.argv[1:])}`",
             f"- runs: {args.stop:g} s, jacobi x1, implicit {', '.join(BONDS)}, coupling tolerance 1e-5", "",
             "| step | boom -> chassis | macro steps | group steps | group steps a macro step |", "| --- | --- | --- | --- | --- |"]
    for h in (float(s) for s in args.steps.split(",")):
        for hold in (False, True):
            with held("boom", "chassis") if hold else contextlib.nullcontext():
                s = run("truck_telescope", stop_time=args.stop, step_size=h, algorithm="jacobi", extrapolation=1,
                        implicit=BONDS, coupling_tolerance=1e-5, progress=False, isolate=False).stats
            lines.append(f"| {h * 1e3:g} ms | {'held' if hold else 'interpolated'} | {s.steps} | {s.iterations} | "
                         f"{s.iterations / s.steps:.2f} |")
            print(lines[-1], flush=True)
    return write(args.output, lines)


if __name__ == "__main__":
    sys.exit(main())
