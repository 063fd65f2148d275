"""The implicit group (``implicit=foot_heave``) against explicit Jacobi on truck_telescope (issue 16).

Every run: truck_telescope, 30 s, in its own spawned child (pythonfmu FMUs cannot be instantiated
twice in one process), one at a time.  Error: the worst over the scene's key outputs of
max|y - y_ref| / range(y_ref) against the monolithic solve (rtol 1e-10, computed once and cached in
``--reference`` as an .npz on a 10 ms grid; every H here is a multiple of it).  Wall time is the run's
own (load, initialize, step); RTF = 30 s / wall.  Also per run: group evaluations (step of the group's
FMUs) per macro step and the cost of the group's getFMUstate / setFMUstate per call.

    .venv/bin/python benchmarks/implicit_bond.py [--stop 30] [--steps 0.01,0.02,0.03,0.04] [--reference FILE]

Prints and writes benchmarks/results/implicit_bond.md.  Compare the rows as ratios (the machine is shared).
"""
from __future__ import annotations

import argparse
import multiprocessing
import sys
import time as clock
from concurrent.futures import ProcessPoolExecutor
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
SCENE = "truck_telescope"
GRID = 0.01   # [s] the reference's grid


def reference(path: Path, stop: float) -> dict[str, np.ndarray]:
    """The monolithic solve on the 10 ms grid, from ``path`` if it holds this stop time, else computed and saved."""
    from cranefmu.converge import key_outputs, monolithic_reference

    if path.exists():
        data = dict(np.load(path))
        if float(data.pop("stop")) == stop:
            return data
    times = np.round(np.arange(0.0, stop + GRID / 2, GRID), 9)
    t0 = clock.perf_counter()
    ref = monolithic_reference(SCENE, stop, times)
    print(f"reference: monolithic solve of {stop:g} s in {clock.perf_counter() - t0:.1f} s -> {path}")
    data = {k: np.asarray(ref[k], dtype=float) for k in key_outputs(SCENE)}
    np.savez(path, stop=stop, **data)
    return data


def _timed(cls, name: str, totals: dict) -> None:
    """Wrap cls.name to add its calls and seconds to totals[name]."""
    inner = getattr(cls, name)

    def wrapper(self, *args, **kwargs):
        t0 = clock.perf_counter()
        try:
            return inner(self, *args, **kwargs)
        finally:
            calls, seconds = totals.get(name, (0, 0.0))
            totals[name] = (calls + 1, seconds + clock.perf_counter() - t0)

    setattr(cls, name, wrapper)


def one_run(settings: dict, stop: float) -> dict:
    """One run in this (child) process: its result columns, stats and the group's snapshot costs."""
    from cranefmu.errors import SimulationError
    from cranefmu.master.implicit_group import ImplicitGroup
    from cranefmu.master.run import run

    totals: dict = {}
    for name in ("_save", "_restore", "_evaluate", "_estimate"):
        _timed(ImplicitGroup, name, totals)
    out = {"totals": totals}
    try:
        res = run(SCENE, stop_time=stop, progress=False, **settings)
    except SimulationError as err:
        out["failure"] = str(err).split(". ")[0]
        return out
    s = res.stats
    out.update(result=res.result, steps=s.steps, iterations=s.iterations, max_iterations=s.max_iterations,
               wall=s.wall_time, fmu=sum(s.fmu_time.values()))
    return out


def error(result: np.ndarray, ref: dict[str, np.ndarray]) -> tuple[float, str]:
    """(worst max|y - y_ref| / range(y_ref) over the key outputs, that output)."""
    index = np.round(result["time"] / GRID).astype(int)
    worst = (0.0, "")
    for key, values in ref.items():
        r = values[index]
        span = float(np.max(values) - np.min(values))
        e = float(np.max(np.abs(result[key] - r))) / span
        worst = max(worst, (e, key))
    return worst


def cases(steps: list[float]) -> list[tuple[str, dict]]:
    out = [("jacobi x1", dict(algorithm="jacobi", extrapolation=1, step_size=0.01))]
    for h in steps:
        for x in (0, 1):
            for tol in (1e-5, 1e-8):
                out.append((f"implicit foot_heave x{x} tol {tol:g}",
                            dict(algorithm="jacobi", extrapolation=x, step_size=h, implicit=["foot_heave"],
                                 coupling_tolerance=tol)))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stop", type=float, default=30.0)
    ap.add_argument("--steps", default="0.01,0.02,0.03,0.04")
    ap.add_argument("--reference", type=Path, default=Path("/tmp/cranefmu_truck_telescope_reference.npz"))
    args = ap.parse_args()
    steps = [float(v) for v in args.steps.split(",")]
    ref = reference(args.reference, args.stop)
    ctx = multiprocessing.get_context("spawn")
    rows = []
    header = ("| setting | H [ms] | error (% of range) | worst output | wall [s] | RTF | group steps / step "
              "| getFMUstate [us/FMU] | setFMUstate [us/FMU] |")
    print(header)
    for label, settings in cases(steps):
        with ProcessPoolExecutor(1, mp_context=ctx) as pool:
            r = pool.submit(one_run, settings, args.stop).result()
        h = settings["step_size"] * 1e3
        t = r["totals"]
        members = 2
        get = 1e6 * t["_save"][1] / t["_save"][0] / members if "_save" in t else None
        put = 1e6 * t["_restore"][1] / t["_restore"][0] / members if "_restore" in t else None
        if "failure" in r:
            row = f"| {label} | {h:g} | unstable | {r['failure'][:90]} | | | | | |"
        else:
            e, key = error(r["result"], ref)
            per = r["iterations"] / r["steps"] if "implicit" in settings else 1.0
            row = (f"| {label} | {h:g} | {100 * e:.3g} | {key} | {r['wall']:.2f} | {args.stop / r['wall']:.1f} | "
                   f"{per:.2f} | {'' if get is None else f'{get:.0f}'} | {'' if put is None else f'{put:.0f}'} |")
        print(row, flush=True)
        rows.append(row)
    RESULTS.mkdir(parents=True, exist_ok=True)
    text = "\n".join([
        f"# Implicit group on truck_telescope ({args.stop:g} s), {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC", "",
        "Command: `.venv/bin/python benchmarks/implicit_bond.py`.  Error: worst key output, max|y - y_ref| / "
        "range(y_ref) against the monolithic solve (rtol 1e-10).  Group steps / step: evaluations of the "
        "group's FMUs per macro step (Newton iterations plus the Jacobian estimates).  One run at a time on a "
        "shared machine: compare as ratios.", "", header, "|" + " --- |" * 9, *rows, ""])
    (RESULTS / "implicit_bond.md").write_text(text)
    print(f"written {RESULTS / 'implicit_bond.md'}")


if __name__ == "__main__":
    sys.exit(main())
