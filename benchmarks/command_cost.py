"""What commanded inputs cost a run: elastic_pendulum (20 s at its stored 5 ms, released at rest) without
commands, and with the trolley travel of experiments/anti_sway_trolley.toml (four commanded inputs: the
suspension point's x and its velocity in rope and pendulum, fed with their rates at every step), and the
same through the ZV shaper.  In-process runs in alternating rounds, each in a fresh spawned child (the
pythonfmu FMUs are instantiated once per process); the table gives the median wall time of each and the
ratio to the run without commands.

    python benchmarks/command_cost.py [--rounds N] [--smoke]

``--smoke`` (CI: the numbers mean nothing): one round of 2 s runs into command_cost_smoke.md.
Writes benchmarks/results/command_cost.md (commit, date, load, the table).  Not a test: nothing asserted.
"""
from __future__ import annotations

import argparse
import multiprocessing
import statistics
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from result_table import save, stamp  # noqa: E402

CASES = ("none", "travel", "travel_zv")
STOP = 20.0   # [s] of elastic_pendulum


def _commands(case: str) -> list:
    from cranefmu.experiments.profiles import moves, shaped
    from cranefmu.master.commands import Command

    if case == "none":
        return []
    profile = moves(0.0, [{"start": 1.0, "to": 3.0, "speed": 0.5, "accel_time": 1.0}])
    if case == "travel_zv":
        profile = shaped(profile, "zv", (9.81 / 10.0) ** 0.5 / (2 * 3.141592653589793))
    rate = profile.derivative()
    return [Command(f"{c}.x_top", profile) for c in ("rope", "pendulum")] + \
           [Command(f"{c}.vx_top", rate) for c in ("rope", "pendulum")]


def _one(case: str, stop: float) -> float:
    from cranefmu.master.run import run

    t0 = time.perf_counter()
    run("elastic_pendulum", stop_time=stop, progress=False, parameters={"pendulum.theta0": 0.0},
        commands=_commands(case))
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--smoke", action="store_true", help="one round of 2 s runs (CI; the numbers mean nothing)")
    args = parser.parse_args()
    rounds, stop = (1, 2.0) if args.smoke else (args.rounds, STOP)
    t0 = time.time()
    walls: dict[str, list[float]] = {c: [] for c in CASES}
    ctx = multiprocessing.get_context("spawn")
    for _ in range(rounds):
        for case in CASES:
            with ProcessPoolExecutor(1, mp_context=ctx) as pool:
                walls[case].append(pool.submit(_one, case, stop).result())
    base = statistics.median(walls["none"])
    lines = ["# Cost of commanded inputs", "", stamp("command_cost.py") + f", {rounds} rounds", "",
             f"elastic_pendulum, {stop:g} s at the stored 5 ms ({round(stop / 0.005)} steps), in-process, median "
             "wall time of the run.", "",
             "| commands | median wall [s] | ratio to none |", "| --- | --- | --- |"]
    for case in CASES:
        m = statistics.median(walls[case])
        lines.append(f"| {case} | {m:.3f} | {m / base:.3f} |")
    save("command_cost_smoke" if args.smoke else "command_cost", lines, t0)


if __name__ == "__main__":
    main()
