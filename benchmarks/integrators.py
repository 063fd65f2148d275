"""Cost and accuracy of the FMUs' internal solvers (cranefmu.adapter.integrators) on every physics model.

For each model configuration of cranefmu_support.model_cases (initialized at rest, then a step of its
inputs) and each solver setting: the model is stepped like an FMU does it (macro step H, constant
inputs, ``integrate`` per step, ``after_step``), timed over the whole span, and compared with a
tight Radau solve (rtol 1e-10).  Error: largest |x - x_ref| of each state over the trajectory,
relative to that state's largest value.  "unstable" marks a non-finite state.  Times are wall
seconds per macro step on this machine, in one run: compare them as ratios.

Writes benchmarks/results/integrators.{csv,md}.

    .venv/bin/python benchmarks/integrators.py [--macro-step 1e-2] [--cases drive-motor,rope-bouc-wen]
"""
from __future__ import annotations

import argparse
import csv
import sys
import time as clock
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "support"))   # cranefmu_support: scaffolding outside the wheel
from cranefmu_support.model_cases import CASES, trajectory  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

# (solver, max_step [s], rtol): explicit fixed steps at and above the stiff limit, the implicit
# fixed-step TR-BDF2 at large steps, and the adaptive scipy methods at a working tolerance
SETTINGS = [("euler", 1e-5, 0.0), ("rk4", 1e-4, 0.0), ("rk4", 1e-3, 0.0), ("trbdf2", 1e-4, 0.0),
            ("trbdf2", 1e-3, 0.0), ("trbdf2", 1e-2, 0.0), ("rk45", 1e-2, 1e-6), ("radau", 1e-2, 1e-6),
            ("bdf", 1e-2, 1e-6)]


def rel_error(xs: np.ndarray, ref: np.ndarray) -> float:
    scale = np.max(np.abs(ref), axis=0)
    scale[scale == 0.0] = 1.0
    return float(np.max(np.abs(xs - ref) / scale))


def measure(case, solver: str, max_step: float, rtol: float, h: float, ref: np.ndarray) -> tuple[float, str]:
    t0 = clock.perf_counter()
    try:
        with np.errstate(all="ignore"):
            _, xs = trajectory(case, solver, max_step=max_step, rtol=rtol or 1e-6, h=h)
    except FloatingPointError as err:
        return clock.perf_counter() - t0, f"failed: {err}"[:60]
    wall = clock.perf_counter() - t0
    if not np.all(np.isfinite(xs)):
        return wall, "unstable"
    return wall, f"{rel_error(xs, ref):.2e}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--macro-step", type=float, default=1e-2, help="communication step H [s] (default 1e-2)")
    ap.add_argument("--cases", default="", help="comma-separated case ids (default: all with internal states)")
    args = ap.parse_args(argv)
    h = args.macro_step
    chosen = [c for c in CASES if c.make().initial_state(c.model.default_inputs()).size]
    if args.cases:
        chosen = [c for c in chosen if c.id in args.cases.split(",")]
    rows = []
    for case in chosen:
        _, ref = trajectory(case, "radau", max_step=h, rtol=1e-10, h=h)
        n_steps = round(case.t_end / h)
        for solver, max_step, rtol in SETTINGS:
            wall, err = measure(case, solver, max_step, rtol, h, ref)
            row = dict(case=case.id, states=ref.shape[1], solver=solver, max_step=max_step, rtol=rtol or "",
                       ms_per_macro_step=round(1e3 * wall / n_steps, 3), error=err)
            rows.append(row)
            print(f"{case.id:24s} {solver:7s} max_step {max_step:<7g} rtol {rtol or '-':<6} "
                  f"{row['ms_per_macro_step']:9.3f} ms/step  error {err}", flush=True)
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "integrators.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with open(out / "integrators.md", "w") as fh:
        fh.write(f"# Internal solvers: wall time per macro step H = {h:g} s and state error vs Radau rtol 1e-10\n\n")
        fh.write("| case | states | solver | max_step [s] | rtol | ms per macro step | error |\n")
        fh.write("| --- | --- | --- | --- | --- | --- | --- |\n")
        for r in rows:
            fh.write(f"| {r['case']} | {r['states']} | {r['solver']} | {r['max_step']:g} | {r['rtol']} | "
                     f"{r['ms_per_macro_step']} | {r['error']} |\n")
    print(f"written {out / 'integrators.csv'} and {out / 'integrators.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
