"""CPU time of a run with the BLAS/OpenMP pools as the machine sets them (the master of ``--before``, which
did not pin them) and pinned to one thread (this checkout: master/threads.py).

    .venv/bin/python benchmarks/blas_threads.py [--scene truck_telescope] [--stop 1.0] [--before COMMIT] [--rounds 2]

Each case in a fresh process (``time.process_time`` of the whole ``run()`` in the process: every thread's CPU,
the pythonfmu FMUs run in it), the scene's stored settings, the best of ``--rounds``.  The "before" side is
this checkout with ``cranefmu/master`` of the commit (as benchmarks/master_overhead.py builds it).  Prints
and saves benchmarks/results/blas_threads.md.  Not a test.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

CHILD = """
import json, time
from threadpoolctl import threadpool_info
from cranefmu.master.run import run
c = time.process_time()
r = run({scene!r}, stop_time={stop}, progress=False, keep=False)
print("RESULT " + json.dumps([time.process_time() - c, r.stats.steps,
                              max(i["num_threads"] for i in threadpool_info())]))
"""


def measure(scene: str, stop: float, src: Path | None) -> tuple[float, int, int]:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src) + os.pathsep + env.get("PYTHONPATH", "")
    done = subprocess.run([sys.executable, "-c", CHILD.format(scene=scene, stop=stop)], capture_output=True,
                          text=True, env=env, cwd=HERE.parent, timeout=1800)
    line = next((x for x in done.stdout.splitlines() if x.startswith("RESULT ")), None)
    if line is None:
        raise RuntimeError(done.stderr[-1500:])
    return tuple(json.loads(line[7:]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="truck_telescope")
    ap.add_argument("--stop", type=float, default=1.0)
    ap.add_argument("--before", default="cedec42")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    a = ap.parse_args()
    from master_overhead import _package_with_master_of

    with tempfile.TemporaryDirectory() as tmp:
        before = _package_with_master_of(a.before, Path(tmp))
        best = {}
        for label, src in ((f"before ({a.before}), pools as set", before), ("pinned to one thread", None)):
            runs = [measure(a.scene, a.stop, src) for _ in range(a.rounds)]
            best[label] = min(runs)
            print(label, best[label], flush=True)
    lines = [f"# BLAS/OpenMP threads: {a.scene}, {a.stop:g} s at its stored settings", "",
             f"`python benchmarks/blas_threads.py --scene {a.scene} --stop {a.stop:g} --before {a.before} "
             f"--rounds {a.rounds}` on {os.cpu_count()} cores (best of the rounds; CPU of every thread of the process).",
             "", "| master | CPU [s] | steps | BLAS threads after the run |", "| --- | --- | --- | --- |"]
    lines += [f"| {k} | {v[0]:.2f} | {v[1]} | {v[2]} |" for k, v in best.items()]
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "blas_threads.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
