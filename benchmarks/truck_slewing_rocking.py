"""truck_slewing with 2.5 t (seed 000's load) on four pads that rock: which pad lifts, when, for how long, and
that the run goes on to its end without tipping (a second pad off).  Three runs at the stored settings: the
default slew (0.1 rad/s), the whole slew at 0.15 rad/s and the short slew 60 -> 90 deg at 0.15 rad/s with 1 s
ramps (tests/scenes/test_truck_slewing.py); writes benchmarks/results/truck_slewing_rocking.md (quoted by
docs/validation.md).  About 2 min.

    nice -n 10 .venv/bin/python benchmarks/truck_slewing_rocking.py
    .venv/bin/python benchmarks/truck_slewing_rocking.py --smoke   (CI: the short case for 0.5 s into
                                                                     truck_slewing_rocking_smoke.md; meaningless)
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np

from result_table import save, stamp

from cranefmu.master.run import run

CASES = (
    ("default slew 0 -> 90 deg, 0.1 rad/s, 2 s ramps", {}, 30.0),
    ("slew 0 -> 90 deg, 0.15 rad/s, 2 s ramps", {"boom.slew_speed": 0.15}, 30.0),
    ("slew 60 -> 90 deg, 0.15 rad/s, 1 s ramps from 0.5 s",
     {"boom.slew_angle_start": math.radians(60.0), "boom.slew_angle": math.radians(30.0), "boom.slew_speed": 0.15,
      "boom.slew_t_acc": 1.0, "boom.slew_start": 0.5}, 8.0),
)


def main(smoke: bool = False) -> None:
    t0 = time.time()
    lines = ["# truck_slewing: 2.5 t on four pads that rock (stored settings)", "",
             f"{stamp('truck_slewing_rocking.py')}).", "",
             "| case | ran to [s] | stopped by | smallest N1..N4 [N] | pads lifted at most | tipping at most | "
             "lifted from [s] | to [s] | lifts | time lifted [s] |", "| --- |" + " --- |" * 9]
    for name, extra, stop in (CASES[-1:] if smoke else CASES):
        stop = 0.5 if smoke else stop
        r = run("truck_slewing", parameters={"pendulum.mass": 2500.0, **extra}, stop_time=stop, progress=False)
        res = r.result
        t, lifted = res["time"], res["chassis.pads_lifted"]
        rows = np.flatnonzero(lifted > 0.0)
        dt = float(np.diff(t).mean())
        first, last = (f"{t[rows[0]]:.3f}", f"{t[rows[-1]]:.3f}") if len(rows) else ("-", "-")
        mins = " / ".join(f"{res[f'chassis.N{i}'].min():.0f}" for i in range(1, 5))
        stopped = getattr(r.stats, "stopped", None) or "-"
        lines.append(f"| {name} | {t[-1]:.3f} | {stopped} | {mins} | {lifted.max():g} | "
                     f"{res['chassis.tipping'].max():g} | {first} | {last} | {int(np.count_nonzero(np.diff(lifted) > 0))} | "
                     f"{len(rows) * dt:.2f} |")
        print(lines[-1], flush=True)
    save("truck_slewing_rocking_smoke" if smoke else "truck_slewing_rocking", lines, t0)


if __name__ == "__main__":
    main("--smoke" in sys.argv[1:])
