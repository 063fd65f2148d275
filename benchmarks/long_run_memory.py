"""Memory of a long streamed run: one simulated hour of elastic_pendulum at H = 1 ms, keep=False.

The master runs the scene in a worker process (``run(..., isolate=True)``: ``python -m
cranefmu.master.worker``); this script finds that child (a child of this one whose command line names
the worker module) and samples
its resident set size (VmRSS in /proc/<pid>/status) every ``--every`` seconds of wall time, next
to the simulated time of the newest row on disk (the last complete line of the streamed CSV).
Peak RSS: the largest of the samples, of VmHWM (the kernel's high-water mark of the child) and of
getrusage(RUSAGE_CHILDREN).ru_maxrss after the child has been reaped.

Writes benchmarks/results/long_run_memory.{md,csv} (the .csv: every sample).  The streamed result
CSV (about 2.5 GB for the hour) is removed at the end unless --keep-csv.

    .venv/bin/python benchmarks/long_run_memory.py              # 3600 s at 1 ms: 3.6 million steps
    .venv/bin/python benchmarks/long_run_memory.py --stop 60    # a quick look
"""
from __future__ import annotations

import argparse
import os
import resource
import signal
import tempfile
import threading
import time as clock
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"


def spawned_children() -> list[int]:
    """Pids of this process's children that run the master's worker (cranefmu.master.worker)."""
    me = os.getpid()
    out = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
            ppid = int(stat.rpartition(")")[2].split()[1])
            if ppid == me and b"cranefmu.master.worker" in Path(f"/proc/{entry}/cmdline").read_bytes():
                out.append(int(entry))
        except (OSError, ValueError, IndexError):
            continue   # gone in between
    return out


def memory_kib(pid: int) -> tuple[int, int]:
    """(VmRSS, VmHWM) of a process [KiB]; (0, 0) once it is gone."""
    rss = hwm = 0
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                rss = int(line.split()[1])
            elif line.startswith("VmHWM:"):
                hwm = int(line.split()[1])
    except OSError:
        pass
    return rss, hwm


def newest_time(csv_path: Path) -> float:
    """Simulated time of the last complete row on disk [s] (nan before the first one).  While the
    run goes the rows are in ``<csv>.part`` (renamed into place at the end)."""
    part = csv_path.with_name(csv_path.name + ".part")
    try:
        with open(part if part.exists() else csv_path, "rb") as f:
            f.seek(0, os.SEEK_END)
            size = f.tell()
            f.seek(max(0, size - 16384))
            tail = f.read()
    except OSError:
        return float("nan")
    lines = tail.split(b"\n")[:-1]   # the piece after the last newline may be a partial row
    for line in reversed(lines):
        try:
            return float(line.split(b",", 1)[0])
        except ValueError:
            continue
    return float("nan")


def count_rows(csv_path: Path) -> int:
    n = 0
    with open(csv_path, "rb") as f:
        while chunk := f.read(1 << 24):
            n += chunk.count(b"\n")
    return n - 1   # the header


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="elastic_pendulum")
    ap.add_argument("--stop", type=float, default=3600.0, help="simulated time [s]")
    ap.add_argument("--step", type=float, default=1e-3, help="macro step [s]")
    ap.add_argument("--every", type=float, default=2.0, help="sampling period, wall seconds")
    ap.add_argument("--csv", type=Path, default=None, help="where the run streams its rows (default: a temp dir)")
    ap.add_argument("--keep-csv", action="store_true")
    ap.add_argument("--results", type=Path, default=RESULTS)
    ap.add_argument("--wall-limit", type=float, default=None,
                    help="seconds: then stop the run (kill the child) and report the part it simulated")
    args = ap.parse_args(argv)

    from cranefmu.master.run import run

    tmp = Path(tempfile.mkdtemp(prefix="long_run_"))
    out = args.csv or tmp / f"{args.scene}.csv"
    box: dict = {}

    def target():
        try:
            box["result"] = run(args.scene, stop_time=args.stop, step_size=args.step, output=out, keep=False,
                                progress=False, isolate=True)
        except BaseException as err:   # reported below, after the sampling stops
            box["error"] = err

    wall0 = clock.perf_counter()
    worker = threading.Thread(target=target)
    worker.start()
    samples: list[tuple[float, float, int]] = []   # (wall [s], simulated time [s], RSS [KiB])
    pid, hwm, note = None, 0, ""
    while worker.is_alive():
        if args.wall_limit is not None and pid is not None and clock.perf_counter() - wall0 > args.wall_limit:
            note = (f"Partial: stopped by --wall-limit {args.wall_limit:g} s at t = {newest_time(out):.0f} s "
                    f"simulated of {args.stop:g} s (a 2-core machine shared with other jobs).")
            os.kill(pid, signal.SIGKILL)
            worker.join()
            break
        if pid is None:
            found = spawned_children()
            pid = found[0] if found else None
        if pid is not None:
            rss, h = memory_kib(pid)
            if rss:
                hwm = max(hwm, h)
                samples.append((clock.perf_counter() - wall0, newest_time(out), rss))
        worker.join(args.every)
    wall = clock.perf_counter() - wall0
    reaped = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss   # KiB on Linux
    if "error" in box and not note:
        raise SystemExit(f"the run failed: {box['error']}")
    res = box.get("result")
    rows = count_rows(out)
    size = out.stat().st_size
    if not args.keep_csv:
        out.unlink()
        tmp.rmdir() if args.csv is None else None
    write(args, samples, max(hwm, reaped, max((s[2] for s in samples), default=0)), hwm, reaped, rows, size,
          wall, res.stats if res is not None else None, note)


def at_fraction(samples: list[tuple[float, float, int]], stop: float, fraction: float) -> tuple[float, float, int]:
    """The first sample whose simulated time reached ``fraction`` of the run (else the last one)."""
    for s in samples:
        if s[1] == s[1] and s[1] >= fraction * stop:
            return s
    return samples[-1]


def write(args, samples, peak, hwm, reaped, rows, size, wall, stats, note: str = "") -> None:
    args.results.mkdir(parents=True, exist_ok=True)
    with open(args.results / "long_run_memory.csv", "w") as f:
        f.write("wall_s,sim_time_s,rss_kib\n")
        f.writelines(f"{w:.2f},{t:.3f},{r}\n" for w, t, r in samples)
    reached = max((s[1] for s in samples if s[1] == s[1]), default=0.0)
    steps = stats.steps if stats is not None else rows - 1
    own = stats.wall_time if stats is not None else wall
    simulated = args.stop if stats is not None else reached
    lines = ["# Long streamed run: memory", "",
             f"Scene {args.scene}, {args.stop:g} s simulated at H = {args.step:g} s (jacobi, order 0, "
             f"instability alarm on), keep=False, rows streamed to CSV.  Measured by "
             "`benchmarks/long_run_memory.py`: RSS of the spawned child that runs the master and the FMUs, "
             f"sampled every {args.every:g} s of wall time ({len(samples)} samples, all in long_run_memory.csv).", "",
             "| quantity | value |", "|---|---|",
             f"| rows written (without header) | {rows}" + (f" (expected {steps + 1}: {steps} steps + the initial row) |" if stats else " |"),
             f"| CSV size | {size / 1e6:.0f} MB |",
             f"| simulated | {simulated:.0f} s of {args.stop:g} s |",
             f"| wall time | {wall:.0f} s (" + (f"master's own: {own:.0f} s; " if stats else "")
             + f"real-time factor {simulated / own:.2f}) |",
             f"| peak RSS of the child | {peak / 1024:.1f} MiB (VmHWM {hwm / 1024:.1f}"
             + (f", ru_maxrss of reaped children {reaped / 1024:.1f}) |" if reaped else ") |")]
    for frac in (0.1, 0.5, 1.0):
        w, t, r = at_fraction(samples, simulated, frac) if samples else (0, 0, 0)
        lines.append(f"| RSS at {frac:.0%} of the run (t = {t:.0f} s simulated, {w:.0f} s wall) | {r / 1024:.1f} MiB |")
    if samples:
        first = at_fraction(samples, simulated, 0.1)[2]
        last = samples[-1][2]
        lines += ["", f"RSS from 10 % to the end of the run: {first / 1024:.1f} -> {last / 1024:.1f} MiB "
                      f"({(last - first) / 1024:+.1f} MiB over {rows} rows, "
                      f"{(last - first) * 1024 / max(1, rows):.2f} bytes per row)."]
    if note:
        lines += ["", note]
    (args.results / "long_run_memory.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
