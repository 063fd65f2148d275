"""The master's own work per macro step, before and after a change, measured in one invocation.

    python benchmarks/master_overhead.py [--before COMMIT] [--rounds N] [--out FILE]

Runs the hot-path split of :mod:`speed_accuracy` (Jacobi x1, every ctypes FMI function timed; master =
loop wall - time inside FMI calls) on each scene, alternately with the master's code of ``COMMIT``
(its ``src`` extracted with ``git archive`` and put first on PYTHONPATH; the FMUs are the same) and
with this checkout's, ``N`` rounds each; per scene the median of each side and their ratio.  Not a
test: prints and saves a table.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
CASES = [("elastic_pendulum", 4, 0.001), ("hook_sway", 4, 0.001), ("overhead_lift", 2, 0.001),
         ("truck_telescope", 10, 0.01)]

CHILD = """
import json, sys
sys.path.insert(0, {bench!r})
import speed_accuracy as sa
_, res = sa.hot_path_report({cases!r}, lambda s: None)
out = {{}}
for scene, r in res.items():
    n = max(r["steps"], 1)
    fmi = sum(sec for sec, _ in r["fmi"].values())
    calls = sum(c for _, c in r["fmi"].values())
    out[scene] = dict(loop=r["loop"] / n * 1e6, fmi=fmi / n * 1e6, master=(r["loop"] - fmi) / n * 1e6,
                      calls=calls / n, h=r["h"])
print("RESULT " + json.dumps(out))
"""


def measure(src: Path | None) -> dict:
    """One hot-path run of every case with the master's code from ``src`` (None: this checkout)."""
    return run_child(CHILD.format(bench=str(HERE), cases=CASES), src)


def run_child(code: str, src: Path | None):
    """Run ``code`` in a fresh interpreter with the master from ``src`` (None: this checkout) first on
    the path; the JSON it printed after ``RESULT ``."""
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src) + os.pathsep + env.get("PYTHONPATH", "")
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, env=env, capture_output=True, text=True,
                          timeout=1800)
    line = next((x for x in done.stdout.splitlines() if x.startswith("RESULT ")), None)
    if line is None:
        raise RuntimeError(f"run failed ({'before' if src else 'after'}): {done.stderr[-2000:]}")
    return json.loads(line[len("RESULT "):])


def _package_with_master_of(commit: str, tmp: Path) -> Path:
    """A directory holding a ``cranefmu`` package that is this checkout's (scene sources, built FMUs,
    physics: linked) with the master (``cranefmu/master``) of ``commit``."""
    here = REPO / "src" / "cranefmu"
    pkg = tmp / "src" / "cranefmu"
    pkg.mkdir(parents=True)
    for entry in here.iterdir():
        if entry.name not in ("master", "__pycache__"):
            (pkg / entry.name).symlink_to(entry)
    archive = subprocess.run(["git", "archive", commit, "src/cranefmu/master"], cwd=REPO, capture_output=True,
                             check=True)
    subprocess.run(["tar", "-x", "--strip-components=2", "-C", str(pkg)], input=archive.stdout, check=True)
    return tmp / "src"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="a26ce44", help="commit whose master is 'before' (default a26ce44)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--out", default=str(HERE / "results" / "master_overhead_table.md"))
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        before = _package_with_master_of(a.before, Path(tmp))
        runs = {"before": [], "after": []}
        for k in range(a.rounds):
            runs["before"].append(measure(before))
            runs["after"].append(measure(None))
            print(f"round {k + 1}/{a.rounds} done", file=sys.stderr)
    med = lambda side, scene, key: statistics.median(r[scene][key] for r in runs[side])
    lines = [f"Before = commit {a.before}, after = this checkout; median of {a.rounds} alternating rounds each "
             "(us per macro step; master = loop - FMI).", "",
             "| scene | H [s] | loop before | loop after | FMI before | FMI after | master before | master after | "
             "master/FMI before | master/FMI after | FMI calls/step before | after | master after/before |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for scene, _, h in CASES:
        b = {k: med("before", scene, k) for k in ("loop", "fmi", "master", "calls")}
        f = {k: med("after", scene, k) for k in ("loop", "fmi", "master", "calls")}
        lines.append(f"| {scene} | {h:g} | {b['loop']:.0f} | {f['loop']:.0f} | {b['fmi']:.0f} | {f['fmi']:.0f} | "
                     f"{b['master']:.0f} | {f['master']:.0f} | {b['master'] / b['fmi']:.0%} | "
                     f"{f['master'] / f['fmi']:.0%} | {b['calls']:.1f} | {f['calls']:.1f} | "
                     f"{f['master'] / b['master']:.2f} |")
    text = "\n".join(lines)
    print(text)
    Path(a.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
