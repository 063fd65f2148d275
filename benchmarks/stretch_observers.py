"""What the observers cost after a compiled stretch: the rows one by one against in blocks (issue 34).

Every scene at its stored settings with native FMUs, warm (in one process: an untimed first run, then the
timed ones), CPU time (``process_time``) of ``cranefmu.simulate`` with the stretch's rows given to the
observers one by one (``cranefmu.master.loop.BATCH = False``: the bond monitor, the instability watch, the
value check, the recorder each called per row, as before blocks) and in blocks (``BATCH = True``: the bonds
measured over the block with numpy, the detectors on arrays, the recorder copying the block).  Rounds
alternate the two; the table gives the minimum over the rounds, the real-time factor (simulated time / CPU)
and whether the two results are equal bit for bit.

Usage: .venv/bin/python benchmarks/stretch_observers.py [--scenes a,b] [--rounds N] [--smoke]
Writes benchmarks/results/stretch_observers.md (``--smoke``: elastic_pendulum, 0.5 s, one round, into
stretch_observers_smoke.md; the numbers mean nothing).
"""
from __future__ import annotations

import argparse
import time

from result_table import save, stamp

SCENES = ("elastic_pendulum", "overhead_lift", "hook_sway", "truck_telescope", "truck_slewing")


def _cpu(scene: str, stop: float | None, batch: bool):
    """(CPU seconds, the result) of one warm run with the rows one by one or in blocks."""
    import cranefmu
    from cranefmu.master import loop

    loop.BATCH = batch
    try:
        t0 = time.process_time()
        result = cranefmu.simulate(scene, fmus="native", progress=False, **({"stop_time": stop} if stop else {}))
        return time.process_time() - t0, result
    finally:
        loop.BATCH = True


def _parts(scene: str, stop: float | None) -> tuple[float, float]:
    """CPU seconds of one warm run in blocks split in two: resolving the scene and starting the run (the
    scene's FMUs checked for staleness, the scene copied, the FMUs instantiated and initialized), and the
    march (the kernel's stretches and the observers) with its finish."""
    from cranefmu.master.execution import Execution
    from cranefmu.master.runspec import resolve

    t0 = time.process_time()
    spec = resolve(scene, fmus="native", progress=False, **({"stop_time": stop} if stop else {}))
    ex = Execution(spec)
    t1 = time.process_time()
    ex.simulate_until(spec.settings.stop_time)
    ex.finish()
    return t1 - t0, time.process_time() - t1


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--smoke", action="store_true")
    args = ap.parse_args()
    scenes, stop, name = args.scenes.split(","), None, "stretch_observers"
    if args.smoke:
        scenes, stop, args.rounds, name = ["elastic_pendulum"], 0.5, 1, "stretch_observers_smoke"
    from cranefmu.master.runspec import resolve

    t0 = time.time()
    lines = ["# Observers after a compiled stretch: rows one by one against in blocks", "", stamp("stretch_observers.py"),
             "", "Warm in-process runs, native FMUs, stored settings; CPU ms (minimum of "
             f"{args.rounds} rounds) and real-time factor (simulated s / CPU s).", "",
             "In blocks, split (separate runs, minimum of each part): resolve + start = the scene resolved (its "
             "native FMUs checked for staleness), copied, the FMUs instantiated and initialized; march = the "
             "compiled stretches, the observers and the finish.", "",
             "| scene | sim s | steps | one by one ms | in blocks ms | saved | RTF one by one | RTF in blocks | "
             "resolve + start ms | march ms | equal |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for scene in scenes:
        spec = resolve(scene, fmus="native")
        length = stop or spec.settings.stop_time
        _cpu(scene, min(length, 0.05), True)
        best = {False: float("inf"), True: float("inf")}
        results = {}
        for _ in range(args.rounds):
            for batch in (False, True):
                cpu, results[batch] = _cpu(scene, stop, batch)
                best[batch] = min(best[batch], cpu)
        equal = results[False].tobytes() == results[True].tobytes()
        a, b = best[False], best[True]
        start, march = (min(x) for x in zip(*(_parts(scene, stop) for _ in range(args.rounds))))
        lines.append(f"| {scene} | {length:g} | {len(results[True]) - 1} | {a * 1e3:.1f} | {b * 1e3:.1f} | "
                     f"{1 - b / a:.0%} | {length / a:.0f} | {length / b:.0f} | {start * 1e3:.1f} | "
                     f"{march * 1e3:.1f} | {'yes' if equal else 'NO'} |")
        print(lines[-1], flush=True)
    save(name, lines, t0)


if __name__ == "__main__":
    main()
