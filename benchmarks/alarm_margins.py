"""Margins of the default instability alarm (src/cranefmu/master/divergence.py).

Stable: every scene and parameter set at the default step (1 ms, jacobi, order 0) over its default
stop time, alarm on: no alarm, and the largest window ratio r of the imbalance detector per bond
(the alarm needs r > 0.5 in 3 consecutive windows).  Unstable: the 1-D pendulum of elastic_pendulum
(load 30 % of the static stretch below rest, rope axial mode only) and the 2-D scene beyond the
Jacobi zero-order-hold limit omega H = 4 z (cranefmu.analysis.stability): where the alarm stops the run,
and the peak rope tension against static with the alarm and without it.

Writes benchmarks/results/alarm_margins.md.

    .venv/bin/python benchmarks/alarm_margins.py             # everything (about 15 min alone)
    .venv/bin/python benchmarks/alarm_margins.py --unstable  # the unstable cases only (1 min)
"""
from __future__ import annotations

import argparse
import math
import multiprocessing
import time as clock
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
G = 9.81
STABLE = [("elastic_pendulum", None), ("overhead_lift", None), ("overhead_lift", "loose"), ("hook_sway", None),
          ("truck_telescope", None), ("truck_telescope", "slow"), ("truck_telescope", "fast"),
          ("truck_telescope", "load3500"), ("truck_telescope", "luff30"), ("truck_telescope", "luff45")]
FACTORS = (0.9, 1.3, 2.0, 3.0)   # H / the analytic limit


def one_run(scene: str, parameter_set: str | None, kw: dict, alarm: bool) -> dict:
    """One run in this (spawned) process; what the watch saw."""
    from cranefmu.master import execution as run_mod   # build_execution makes the Watch
    from cranefmu.master.run import run
    from cranefmu.errors import SimulationError

    watches = []

    class Recording(run_mod.Watch):
        def __init__(self, *a, **k):
            super().__init__(*a, **k)
            watches.append(self)

    run_mod.Watch = Recording
    t0 = clock.perf_counter()
    out = {"alarm": ""}
    try:
        r = run(scene, parameter_set=parameter_set, isolate=False, progress=False,
                        instability_alarm=alarm, **kw)
        res, out["steps"] = r.result, r.stats.steps
    except SimulationError as err:
        res, out["alarm"] = err.result, str(err)
        out["steps"] = len(res) - 1 if res is not None else 0
    out["wall"] = clock.perf_counter() - t0
    out["t_end"] = float(res["time"][-1]) if res is not None and len(res) else math.nan
    out["tension"] = float(res["rope.tension"].max()) if res is not None and len(res) else math.nan
    w = watches[0] if watches else None
    out["peaks"] = dict(zip(w.bonds.names, w.imbalance.peak)) if w is not None and w.imbalance else {}
    return out


def child(*args) -> dict:
    # a fresh process per run: pythonfmu FMUs cannot be instantiated again in one process
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        return pool.apply(one_run, args)


def pendulum_cases() -> list[tuple[str, dict, float]]:
    """(label, run keywords, static tension [N]) beyond the limit of the rope's axial mode."""
    from cranefmu.physics.rope import RopeParams, damping, stiffness
    from cranefmu.analysis.stability import stability_limit

    mass, length = 1000.0, 10.0
    p = RopeParams(length=length, E=1e11, A=5.655e-5, zeta=0.07)
    c = stiffness(p, length)
    omega, z = math.sqrt(c / mass), damping(p, c, length, mass) / (2.0 * math.sqrt(c * mass))
    h_lim = stability_limit(z, 0) / omega
    stretch = mass * G / c
    one_d = {"pendulum.dimension": 1, "pendulum.start": "position", "pendulum.theta0": 0.0, "pendulum.x0": 0.0,
             "pendulum.y0": -(length + 1.3 * stretch)}
    cases = [(f"1-D, H = {f:g} x limit", {"stop_time": 20.0, "step_size": f * h_lim, "parameters": one_d}, mass * G)
             for f in FACTORS]
    cases.append(("2-D (5 deg swing), H = 2 x limit", {"stop_time": 20.0, "step_size": 2.0 * h_lim}, mass * G))
    return cases


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--unstable", action="store_true", help="only the unstable cases")
    ap.add_argument("--smoke", action="store_true", help="one short case of each kind (CI; the numbers mean nothing)")
    args = ap.parse_args(argv)
    stable, unstable = STABLE, pendulum_cases()
    if args.smoke:
        stable, unstable = [(s, p, {"stop_time": 0.2}) for s, p in STABLE[:1]], unstable[:1]
        unstable[0][1]["stop_time"] = 1.0
    else:
        stable = [(s, p, {}) for s, p in stable]
    t0 = clock.perf_counter()
    lines = ["# Margins of the default instability alarm", "",
             "Measured by `benchmarks/alarm_margins.py`.  Detector 2 (src/cranefmu/master/divergence.py): per "
             "window of 50 steps r = |sum (P_a - P_b) h| / sum |f| |v| h per power bond; alarm when r > 0.5 in 3 "
             "consecutive windows.  Detector 1 (geometric growth of the residual) also runs at a fixed step.", ""]
    if not args.unstable:
        lines += ["## Stable runs: every scene and parameter set at the default step (1 ms, jacobi, order 0)", "",
                  "| scene | parameter set | stop [s] | steps | alarm | largest window r per bond | wall [s] |",
                  "|---|---|---|---|---|---|---|"]
        for scene, pset, kw in stable:
            o = child(scene, pset, kw, True)
            peaks = ", ".join(f"{k} {v:.3g}" for k, v in o["peaks"].items())
            lines.append(f"| {scene} | {pset or 'default'} | {o['t_end']:g} | {o['steps']} | "
                         f"{'**' + o['alarm'][:80] + '**' if o['alarm'] else 'none'} | {peaks} | {o['wall']:.0f} |")
            print(lines[-1], flush=True)
        lines.append("")
    lines += ["## Unstable: elastic_pendulum beyond the Jacobi zero-order-hold limit (omega H = 4 z, E = 1e11 Pa)", "",
              "| case | H [s] | alarm on: stopped at t [s] | peak tension / static, alarm on | "
              "alarm off: peak tension / static | largest window r | first words of the alarm |",
              "|---|---|---|---|---|---|---|"]
    for label, kw, static in unstable:
        on, off = child("elastic_pendulum", None, kw, True), child("elastic_pendulum", None, kw, False)
        stopped = f"{on['t_end']:.3f}" if on["alarm"] else "not stopped"
        r = max(on["peaks"].values(), default=math.nan)
        lines.append(f"| {label} | {kw['step_size']:.4g} | {stopped} | {on['tension'] / static:.2f} | "
                     f"{off['tension'] / static:.2f} | {r:.3g} | {on['alarm'][:60]} |")
        print(lines[-1], flush=True)
    lines += ["", f"Wall time {clock.perf_counter() - t0:.0f} s (a busy 2-core machine)."]
    RESULTS.mkdir(parents=True, exist_ok=True)
    name = "alarm_margins_smoke.md" if args.smoke else "alarm_margins_unstable.md" if args.unstable else \
        "alarm_margins.md"
    (RESULTS / name).write_text("\n".join(lines) + "\n")
    print(f"wrote {RESULTS / name}")


if __name__ == "__main__":
    main()
