"""Size of the HTML run report and the time to write it and to open it in headless Chromium, by rows.

The rows are a real 2 s elastic_pendulum run (all 40 columns) repeated end to end, time renumbered
at 1 ms.  "open" is the wall time of ``chromium --headless --dump-dom`` until the page's script has run
(browser start included, after one unmeasured start), so the page's own cost is at most that.

Writes benchmarks/results/report_size.md.

    .venv/bin/python benchmarks/report_size.py
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time as clock
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
CHROMIUM = "/usr/bin/chromium"
ROWS = (2_001, 100_000, 1_000_000)


def _open_seconds(html: Path, profile: Path) -> float:
    start = clock.perf_counter()
    out = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                          "--disable-component-update", "--disable-sync", "--no-first-run", f"--user-data-dir={profile}",
                          "--dump-dom", html.as_uri()], capture_output=True, text=True, timeout=300)
    took = clock.perf_counter() - start
    if 'data-ready="1"' not in out.stdout:
        raise RuntimeError(f"{html}: the page's script did not finish: {out.stderr[-500:]}")
    return took


def main(name: str = "report_size.md") -> None:
    import cranefmu
    from cranefmu.report import write_report

    base = cranefmu.run("elastic_pendulum", stop_time=2.0, step_size=1e-3)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        warm = Path(tmp) / "warm.html"
        if os.path.exists(CHROMIUM):   # the first start of a browser profile is slower: not counted
            _open_seconds(write_report(warm, base), Path(tmp) / "profile")
        for n in ROWS:
            data = np.resize(base.result, n)
            data["time"] = np.arange(n) * 1e-3
            path = Path(tmp) / f"r{n}.html"
            start = clock.perf_counter()
            write_report(path, data, scene="elastic_pendulum")
            write = clock.perf_counter() - start
            opened = _open_seconds(path, Path(tmp) / "profile") if os.path.exists(CHROMIUM) else float("nan")
            rows.append((n, path.stat().st_size / 1e6, write, opened))
            print(f"{n:>9} rows: {rows[-1][1]:.2f} MB, written in {write:.2f} s, opened in {opened:.2f} s")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=ROOT).stdout.strip()
    lines = [f"# HTML report size and time by rows (benchmarks/report_size.py)", "",
             f"commit {commit}, {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, load {os.getloadavg()[0]:.1f} "
             f"on {os.cpu_count()} cores, warm (second and later Chromium starts)", "",
             "| rows | HTML [MB] | write [s] | Chromium open, browser start included [s] |",
             "| --- | --- | --- | --- |"]
    lines += [f"| {n} | {mb:.2f} | {w:.2f} | {o:.2f} |" for n, mb, w, o in rows]
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / name).write_text("\n".join(lines) + "\n")
    print(f"wrote {RESULTS / name}")


if __name__ == "__main__":
    if sys.argv[1:] == ["--smoke"]:   # CI: the smallest report only (the numbers mean nothing)
        ROWS = ROWS[:1]
        main("report_size_smoke.md")
    else:
        main()
