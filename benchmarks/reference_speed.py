"""Wall time of the monolithic reference (cranefmu.analysis.reference.solve) per scene and solver method.

    .venv/bin/python benchmarks/reference_speed.py [--quick] [--methods Radau LSODA]

Prints a table and writes benchmarks/results/reference_speed.md.  Each case is solved at rtol 1e-6
(the validation report's tolerance); 'error' is the largest deviation of the key outputs from the
first method's solution, relative to each output's amplitude (a check that a faster method is not
a less accurate one).  Timings on a shared machine are noisy: compare the rows of one run.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from cranefmu.analysis.reference import solve

OUT = Path(__file__).resolve().parent / "results" / "reference_speed.md"
CASES = [  # (label, scene, parameter set, parameters, stop time [s], key outputs)
    ("overhead_lift tight KV", "overhead_lift", "default", None, 4.0, ("rope.tension", "pendulum.y_payload")),
    ("overhead_lift loose Bouc-Wen", "overhead_lift", "loose", {"rope.model": "bouc_wen"}, 4.0,
     ("rope.tension", "pendulum.y_payload")),
    ("hook_sway", "hook_sway", "default", None, 4.0, ("pendulum.theta_payload", "pendulum.phi_payload")),
]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="stop times / 4")
    ap.add_argument("--methods", nargs="+", default=["Radau", "LSODA"])
    args = ap.parse_args(argv)
    lines = ["| case | stop [s] | method | wall [s] | error vs first method |", "| --- | --- | --- | --- | --- |"]
    for label, scene, pset, params, stop, keys in CASES:
        stop = stop / 4 if args.quick else stop
        times = np.linspace(0.0, stop, 2001)
        first = None
        for method in args.methods:
            t0 = time.perf_counter()
            r = solve(scene, stop, times, parameter_set=pset, parameters=params, rtol=1e-6, method=method)
            wall = time.perf_counter() - t0
            first = first or r
            err = max(float(np.max(np.abs(r[k] - first[k])) / np.max(np.abs(first[k]))) for k in keys)
            lines.append(f"| {label} | {stop:g} | {method} | {wall:.1f} | {err:.2e} |")
            print(lines[-1], flush=True)
    OUT.parent.mkdir(exist_ok=True)
    OUT.write_text("# Monolithic reference: wall time\n\n" + "\n".join(lines) + "\n")
    print(f"wrote {OUT}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
