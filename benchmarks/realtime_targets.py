"""Issue 16's real-time targets, one invocation: each scene with the settings it stores (what
`cranefmu run SCENE` does with no settings) against explicit Jacobi x1, error against the monolithic
solve, wall time of a warm run.

    .venv/bin/python benchmarks/realtime_targets.py [--repeats 3] [--scenes a,b] [--output DIR]

Targets: truck_telescope 30 s within 1 % of range at >= 50x real time; elastic_pendulum and
hook_sway (10 s) at >= 40x.  Each setting runs in its own spawned child pinned to one core: a
5-step run of the same settings first (imports, the scene's extraction), then ``--repeats`` timed runs
(wall = load + instantiate + initialize + steps, ``RunStats.wall_time``; the median is reported, and
the stepping alone = wall - the run's start-up, measured as the wall of a 1-step run in the same child).
The error is the worst over the scene's key outputs of max|y - y_ref| / range(y_ref) against one
monolithic solve (scipy, rtol 1e-10) at the union of the runs' communication times.  Prints the table
and writes ``DIR/realtime_targets.md``.
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import time as clock
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from speed_accuracy import ChildFailed, in_child, load_average, machine  # noqa: E402

TARGETS = {"truck_telescope": (30.0, 50.0), "elastic_pendulum": (10.0, 40.0), "hook_sway": (10.0, 40.0)}
LEVEL = 1e-2
RESULTS = Path(__file__).resolve().parent / "results"
# the explicit baseline each scene is compared with: (label, settings)
EXPLICIT = {"truck_telescope": ("jacobi x1, 10 ms (explicit)", dict(algorithm="jacobi", extrapolation=1, step_size=0.01,
                                                                    implicit=[])),
            "elastic_pendulum": ("jacobi x1, 4 ms", dict(algorithm="jacobi", extrapolation=1, step_size=0.004,
                                                         implicit=[])),
            "hook_sway": ("jacobi x0, 1 ms (the old default)", dict(algorithm="jacobi", extrapolation=0,
                                                                    step_size=0.001, implicit=[]))}


def timed_runs(scene: str, stop: float, settings: dict, repeats: int) -> dict:
    """In a child: a warm-up, a 1-step run (start-up), ``repeats`` timed runs; the rows of the last."""
    from cranefmu.master.run import run

    h = settings["step_size"]
    run(scene, stop_time=5 * h, isolate=False, progress=False, keep=False, **settings)
    start = run(scene, stop_time=h, isolate=False, progress=False, keep=False, **settings)
    walls, res = [], None
    for _ in range(repeats):
        res = run(scene, stop_time=stop, isolate=False, progress=False, **settings)
        walls.append(res.stats.wall_time)
    s = res.settings
    used = f"{s.algorithm} x{s.extrapolation}, H = {s.step_size * 1e3:g} ms" + (
        f", implicit {','.join(s.implicit)} (tol {s.coupling_tolerance:g})" if s.implicit else "")
    return {"walls": walls, "start": start.stats.wall_time, "steps": res.stats.steps, "used": used,
            "iterations": res.stats.iterations, "rows": res.result, "stopped": res.stats.stopped}


def stored_step(scene: str) -> dict:
    from cranefmu.master.run import preview

    return dict(preview(scene).settings)


def measure_scene(scene: str, repeats: int, say) -> dict:
    from cranefmu.analysis import converge as cv

    stop, target = TARGETS[scene]
    keys = cv.key_outputs(scene)
    # the stored step given (the warm-up and 1-step runs need it); every other setting is the scene's
    cases = [("the scene's stored settings", {"step_size": in_child(stored_step, scene)["step_size"]}),
             EXPLICIT[scene]]
    rows = []
    for label, settings in cases:
        say(f"{scene}: {label} ...")
        try:
            out = in_child(timed_runs, scene, stop, settings, repeats, timeout=1800)
        except (ChildFailed, Exception) as err:  # one failing setting must not lose the others
            rows.append({"label": label, "failure": f"{type(err).__name__}: {str(err)[:200]}"})
            continue
        rows.append({"label": label, **out})
    say(f"{scene}: monolithic reference ...")
    results = [r["rows"] for r in rows if "rows" in r]
    ref = in_child(cv.Reference.monolithic, scene, keys, stop, results, timeout=1800)
    for r in rows:
        if "rows" not in r:
            continue
        exact = ref.at(r["rows"]["time"])
        worst, worst_key = 0.0, ""
        for k in keys:
            span = float(exact[k].max() - exact[k].min())
            err = float(abs(r["rows"][k] - exact[k]).max()) / span
            if err > worst:
                worst, worst_key = err, k
        wall = statistics.median(r["walls"])
        r.update(worst=worst, worst_key=worst_key, wall=wall, rtf=stop / wall,
                 stepping_rtf=stop / max(wall - r["start"], 1e-9))
        del r["rows"]
    return {"scene": scene, "stop": stop, "target": target, "rows": rows, "ref_wall": ref.wall_time}


def report(done: list[dict], argv: list[str], repeats: int, load0: str) -> list[str]:
    out = ["# Real-time targets of issue 16 (one invocation)", "",
           f"Command: `.venv/bin/python benchmarks/realtime_targets.py {' '.join(argv)}` "
           f"({datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC); " + "; ".join(machine()[1:]).replace("- ", ""),
           f"Load at the start: {load0}; at the end: {load_average()}.", "",
           "Wall = a warm run's load + instantiate + initialize + steps (`RunStats.wall_time`, median of "
           f"{repeats}); start-up = the wall of a 1-step run in the same child; stepping RTF = simulated / "
           "(wall - start-up). Error: worst key output, max|y - y_ref| / range against the monolithic solve "
           "(rtol 1e-10).", "",
           "| scene | setting | H, algorithm | error (% of range) | worst key | steps | coupling evaluations / step "
           "| wall [s] | start-up [ms] | RTF | stepping RTF | target RTF | met |",
           "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for s in done:
        for r in s["rows"]:
            if "failure" in r:
                out.append(f"| {s['scene']} | {r['label']} | FAILED: {r['failure']} | | | | | | | | | | |")
                continue
            met = r["worst"] <= LEVEL and r["rtf"] >= s["target"]
            out.append(f"| {s['scene']} ({s['stop']:g} s) | {r['label']} | {r['used']} | {r['worst'] * 100:.3g} | "
                       f"{r['worst_key']} | {r['steps']} | {r['iterations'] / max(r['steps'], 1):.2f} | "
                       f"{r['wall']:.3f} | {r['start'] * 1e3:.0f} | **{r['rtf']:.1f}** | {r['stepping_rtf']:.1f} | "
                       f"{s['target']:g} | {'yes' if met else 'no'} |")
    return out + [""]


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--scenes", default=",".join(TARGETS))
    ap.add_argument("--output", default=str(RESULTS))
    args = ap.parse_args(argv)
    os.sched_setaffinity(0, {max(os.sched_getaffinity(0))})  # one core; the children inherit it
    load0 = load_average()
    done = []
    say = lambda text: print(f"[{clock.strftime('%H:%M:%S')}] {text}", file=sys.stderr, flush=True)  # noqa: E731
    for scene in args.scenes.split(","):
        done.append(measure_scene(scene, args.repeats, say))
    text = "\n".join(report(done, argv, args.repeats, load0))
    print(text)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    (out / "realtime_targets.md").write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
