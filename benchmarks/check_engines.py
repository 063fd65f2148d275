"""What `cranefmu check` pays to start each engine: the same cases (elastic_pendulum, 5 s each) run
inline (one after the other), on a process pool and on a local Dask cluster of two workers, whole wall
time (start-up, runs, shutdown) measured in one run of this script, so the ratios compare.

    nice -n 10 .venv/bin/python benchmarks/check_engines.py [CASES ...]   (default 2 4 8 16)
    .venv/bin/python benchmarks/check_engines.py --smoke                  (2 cases, into check_engines_smoke.md)

Prints and writes benchmarks/results/check_engines.md: the threshold of `--engine auto` (32 cases with
--jobs > 1: Dask; fewer: the pool) is read against it.
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from result_table import save, stamp

JOBS = 2
CASE = """
[cases.c{i}]
set = {{"rope.E" = {e!r}}}
"""
HEAD = """
name = "engines"
scene = "elastic_pendulum"
stop_time = 5.0
assert = [{name = "hangs", column = "rope.tension", at = 0.0, min = 0.0}]
"""


def main(sizes: list[int], result: str) -> int:
    from cranefmu import build as b
    from cranefmu.experiments.runner import judge_all, prepare, run_cases

    t0 = time.time()
    b.build(verbose=False)
    lines = ["# cranefmu check: wall time of each engine for the same cases", "", stamp("check_engines.py"), "",
             f"elastic_pendulum, 5 s a case (rope.E varied), {JOBS} workers for pool and dask; whole wall time "
             "[s]: start-up, runs, shutdown; the verdicts of every engine compared bit for bit.", "",
             "| cases | inline | pool | dask (local cluster) | verdicts |", "| ---: | ---: | ---: | ---: | --- |"]
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            path = Path(tmp) / f"engines_{n}.toml"
            path.write_text(HEAD + "".join(CASE.format(i=i, e=5e10 + 1e10 * i) for i in range(n)))
            walls, verdicts = [], []
            for engine in ("inline", "pool", "dask"):
                planned = prepare([path])
                start = time.perf_counter()
                run_cases(planned, jobs=JOBS, engine=engine)
                walls.append(time.perf_counter() - start)
                verdicts.append([(v.case, repr(v.value), repr(v.margin), v.passed) for v in judge_all(planned)])
            same = "the same" if verdicts[0] == verdicts[1] == verdicts[2] else "DIFFERENT"
            lines.append(f"| {n} | " + " | ".join(f"{w:.2f}" for w in walls) + f" | {same} |")
            print(lines[-1], flush=True)
    save(result, lines, t0)
    return 0


if __name__ == "__main__":
    if sys.argv[1:] == ["--smoke"]:
        sys.exit(main([2], "check_engines_smoke"))
    sys.exit(main([int(a) for a in sys.argv[1:]] or [2, 4, 8, 16], "check_engines"))
