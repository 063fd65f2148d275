"""Python function calls per macro step, before and after a change to the master (a count, not a timing:
it does not depend on the machine's load).

    python benchmarks/master_calls.py [--before COMMIT] [--out FILE]

Each case (scene, algorithm, extrapolation; 0.5 s at H = 1 ms, no implicit group) runs once under
cProfile with the master of ``COMMIT`` (as :mod:`master_overhead` builds it: this checkout's package
with ``cranefmu/master`` of the commit) and once with this checkout's, each in a fresh process.  The
count includes the pythonfmu FMUs' own Python calls (the same on both sides) and the start (load,
initialization) spread over the steps.  Prints and saves a table.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from master_overhead import HERE, REPO, _package_with_master_of

CASES = [("elastic_pendulum", "jacobi", 1), ("hook_sway", "jacobi", 1), ("overhead_lift", "gauss-seidel", 1),
         ("truck_telescope", "iterative", 1)]

CHILD = """
import cProfile, json, pstats
from cranefmu.master.run import run
out = {{}}
for scene, algorithm, p in {cases!r}:
    profile = cProfile.Profile()
    profile.enable()
    res = run(scene, stop_time=0.5, step_size=1e-3, algorithm=algorithm, extrapolation=p, implicit=[],
              progress=False, isolate=False)
    profile.disable()
    out[scene] = dict(calls=pstats.Stats(profile).total_calls, steps=res.stats.steps)
print("RESULT " + json.dumps(out))
"""


def count(src: Path | None, case: tuple) -> dict:
    """Calls and steps of one case with the master from ``src`` (None: this checkout), in a fresh process
    (pythonfmu FMUs do not survive a second instantiation in one process)."""
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src) + os.pathsep + env.get("PYTHONPATH", "")
    done = subprocess.run([sys.executable, "-c", CHILD.format(cases=[case])], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=1800)
    line = next((x for x in done.stdout.splitlines() if x.startswith("RESULT ")), None)
    if line is None:
        raise RuntimeError(f"run failed ({'before' if src else 'after'}): {done.stderr[-2000:]}")
    return json.loads(line[len("RESULT "):])[case[0]]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="7bdeec9", help="commit whose master is 'before' (default 7bdeec9)")
    ap.add_argument("--out", default=str(HERE / "results" / "master_calls.md"))
    a = ap.parse_args()
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True).stdout
    dirty = " + uncommitted changes" if subprocess.run(["git", "diff", "--quiet", "HEAD", "--", "src"],
                                                       cwd=REPO).returncode else ""
    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    lines = [f"Python calls per macro step (cProfile total / steps; 0.5 s at H = 1 ms): before = master of "
             f"{a.before}, after = this checkout ({head.strip()}{dirty}); {when}, load {os.getloadavg()[0]:.1f} "
             "(a count: the load does not change it).", "",
             "| scene | algorithm | extrapolation | steps | calls/step before | calls/step after | after - before |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as tmp:
        before_src = _package_with_master_of(a.before, Path(tmp))
        for case in CASES:
            b, f = count(before_src, case), count(None, case)
            per_b, per_f = b["calls"] / b["steps"], f["calls"] / f["steps"]
            lines.append(f"| {case[0]} | {case[1]} | {case[2]} | {f['steps']} | {per_b:.1f} | {per_f:.1f} | "
                         f"{per_f - per_b:+.1f} |")
    text = "\n".join(lines)
    print(text)
    Path(a.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
