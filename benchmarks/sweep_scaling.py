"""Sweep engine scaling: speed-up from 1 to 2 workers, per-run engine overhead, worker memory over a
long sweep, and an extrapolation to 10,000 runs on 64 and 1,024 workers.

    .venv/bin/python benchmarks/sweep_scaling.py              # 40 runs of ~2 s, 200-run memory sweep
    .venv/bin/python benchmarks/sweep_scaling.py --runs 10 --run-seconds 0.5 --memory-runs 60   # small
    .venv/bin/python benchmarks/sweep_scaling.py --smoke      # CI: seconds, writes sweep_scaling_smoke.md

Runs: elastic_pendulum at H = 1 ms, the stop time calibrated so that one run's own work (its master
loop) takes --run-seconds on this machine; the runs differ in rope.E (equal cost).
Own work of a run: its wall time minus that of a one-step run (scene load, FMU instantiation and
initialization: the per-run set-up).  Engine overhead per run: workers x sweep wall / runs - own work
(scheduler, transfer, set-up, metrics, writing the row).  Writes benchmarks/results/sweep_scaling.md.
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time as clock
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
SCENE = "elastic_pendulum"
H = 1e-3
PROBE = 5.0   # [s] simulated by the calibration runs


def rss_mb(result, inputs) -> dict:
    """Resident memory [MiB] of the worker process right after its run (a sweep metric)."""
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return {"rss_mb": pages * os.sysconf("SC_PAGE_SIZE") / 2 ** 20, "pid": float(os.getpid())}


def cpu_clock(result, inputs) -> dict:
    """The worker process's CPU time [s] so far, right after a run (a sweep metric): the difference
    between a process's consecutive rows is the CPU its task got, to set against the task's wall."""
    return {"cpu_s": clock.process_time(), "cpu_pid": float(os.getpid())}


def timed_sweep(client, n: int, stop: float, out: Path, metrics=None) -> tuple[float, list[dict]]:
    from cranefmu.sweep import sweep
    from cranefmu.sweep.metrics import Custom

    t0 = clock.perf_counter()
    metrics = metrics or ["max:rope.tension", Custom(("cpu_s", "cpu_pid"), cpu_clock)]
    res = sweep(SCENE, [f"rope.E=log:1e10:1e11:{n}"], metrics, out, client=client,
                stop_time=stop, step_size=H, progress=False)
    wall = clock.perf_counter() - t0
    assert res.failed == 0 and res.ran == n, (res.failed, res.ran)
    return wall, res.rows


def calibrate(client, seconds: float, tmp: Path) -> tuple[float, float]:
    """(stop time [s] whose run's own work takes ``seconds``, set-up [s] of one run) on a worker."""
    _, setup = timed_sweep(client, 4, H, tmp / "setup.csv")
    _, probe = timed_sweep(client, 4, PROBE, tmp / "probe.csv")
    t_setup = statistics.median(r["wall_time"] for r in setup)
    # wall per simulated second from the loop's share; the probe is long enough that the set-up
    # (about 0.15 s) is a small part of it
    per_second = (statistics.median(r["wall_time"] for r in probe) - t_setup) / PROBE
    return max(H, round(seconds / per_second, 3)), t_setup


def main(argv: list[str] | None = None) -> None:
    from cranefmu.master.run import resolve_scene
    from cranefmu.sweep.engine import connect
    from cranefmu.sweep.metrics import Custom

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=40)
    ap.add_argument("--run-seconds", type=float, default=2.0)
    ap.add_argument("--memory-runs", type=int, default=200)
    ap.add_argument("--smoke", action="store_true", help="CI: 2 runs, a short calibration, 4 memory runs; writes "
                    "sweep_scaling_smoke.md (the numbers mean nothing)")
    args = ap.parse_args(argv)
    global PROBE
    if args.smoke:
        args.runs, args.run_seconds, args.memory_runs, PROBE = 2, 0.05, 4, 0.2
    args.argv = list(sys.argv[1:] if argv is None else argv)
    resolve_scene(SCENE)
    tmp = Path(tempfile.mkdtemp(prefix="sweep_scaling_"))
    load0 = os.getloadavg()[0]
    rows, walls, startup = {}, {}, {}
    for w in (1, 2):
        t0 = clock.perf_counter()
        client, cluster = connect(workers=w)
        startup[w] = clock.perf_counter() - t0
        try:
            if w == 1:
                stop, t_setup = calibrate(client, args.run_seconds, tmp)
            walls[w], rows[w] = timed_sweep(client, args.runs, stop, tmp / f"w{w}.csv")
            if w == 2:
                memory = timed_sweep(client, args.memory_runs, 0.5, tmp / "memory.csv",
                                     [Custom(("rss_mb", "pid"), rss_mb)])[1]
        finally:
            client.close()
            cluster.close()
    load1 = os.getloadavg()[0]
    lines = write(args, stop, t_setup, walls, rows, startup, memory, (load0, load1))
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / ("sweep_scaling_smoke.md" if args.smoke else "sweep_scaling.md")).write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def cpu_share(rows: list[dict]) -> tuple[float, float] | None:
    """(mean CPU [s], mean task wall [s]) per task of the rows (completion order), each process's first
    task left out (its CPU clock started with the process)."""
    by_pid: dict[float, list[dict]] = {}
    for r in rows:
        by_pid.setdefault(r["cpu_pid"], []).append(r)
    pairs = [(b["cpu_s"] - a["cpu_s"], b["task_time"]) for runs in by_pid.values() for a, b in zip(runs, runs[1:])]
    if not pairs:
        return None
    return statistics.mean(c for c, _ in pairs), statistics.mean(t for _, t in pairs)


def write(args, stop, t_setup, walls, rows, startup, memory, load) -> list[str]:
    n = args.runs
    own = {w: statistics.mean(r["wall_time"] for r in rows[w]) - t_setup for w in rows}
    task = {w: statistics.mean(r["task_time"] for r in rows[w]) for w in rows}
    over = {w: w * walls[w] / n - own[w] for w in rows}
    speedup = walls[1] / walls[2]
    busy = {w: n * task[w] / (w * walls[w]) for w in rows}           # fraction of the time a worker ran a task
    sched = {w: w * walls[w] / n - task[w] for w in rows}             # scheduler, transfer, client per run
    side = {w: task[w] - own[w] - t_setup for w in rows}              # on the worker: metrics, result, row
    cpu = {w: cpu_share(rows[w]) for w in rows}
    by_pid: dict[float, list[float]] = {}
    for r in memory:   # table order = completion order
        by_pid.setdefault(r["pid"], []).append(r["rss_mb"])
    mem_lines = []
    for pid, rss in by_pid.items():
        k = max(1, len(rss) // 10)
        early, late = statistics.mean(rss[k:2 * k] or rss), statistics.mean(rss[-k:])   # a worker may run one
        mem_lines.append(f"| {int(pid)} | {len(rss)} | {rss[0]:.1f} | {early:.1f} | {late:.1f} | {late - early:+.1f} |")
    t_run = own[1] + over[1]   # cost of one run on one worker, engine included
    dispatch = 1e-3            # [s] scheduler time per task (Dask's documented order of magnitude)

    def extrapolate(workers: int, runs: int = 10_000) -> str:
        waves = -(-runs // workers)
        compute = waves * t_run
        sched = runs * dispatch
        return (f"| {workers} | {waves} | {compute:.0f} | {sched:.0f} | {startup[2]:.0f}+ | "
                f"{max(compute, sched) + startup[2]:.0f} |")

    from result_table import stamp   # benchmarks/ is the script's folder

    lines = ["# Sweep engine scaling (benchmarks/sweep_scaling.py)", "",
            f"{stamp('sweep_scaling.py ' + ' '.join(args.argv))} at the end; warm workers (each run after the "
            "first in its process).", "",
            f"Machine: {os.cpu_count()} cores shared with other jobs; load average {load[0]:.1f} before, "
            f"{load[1]:.1f} after (a load above the core count means the workers were not alone: the ratios "
            "below are lower bounds of what an idle machine gives).", "",
            f"Runs: {SCENE}, H = {H:g} s, stop time {stop:g} s (calibrated for {args.run_seconds:g} s of own work), "
            f"{n} runs differing in rope.E.  Per-run set-up (scene load, FMU instantiation, initialization: a "
            f"one-step run) {t_setup * 1e3:.0f} ms.", "",
            "| workers | cluster start [s] | sweep wall [s] | own work per run [s] | task on worker per run [s] | "
            "engine overhead per run [s] | overhead / own work |",
            "| --- | --- | --- | --- | --- | --- | --- |"]
    lines += [f"| {w} | {startup[w]:.1f} | {walls[w]:.2f} | {own[w]:.3f} | {task[w]:.3f} | {over[w]:.3f} | "
       f"{100 * over[w] / own[w]:.1f} % |" for w in (1, 2)]
    lines += [
            "", f"Speed-up 1 -> 2 workers: **{speedup:.2f}x** (target >= 1.7x).  Engine overhead per run on one "
            f"worker: **{100 * over[1] / own[1]:.1f} %** of the run's own work (target <= 5 %).  With two workers "
            "the own work per run itself grows when the two processes compete with other jobs for the 2 cores; "
            "the overhead column then also holds the time a worker waited for a core.", "",
            "Where the overhead goes (per run): "
            + "; ".join(f"{w} worker(s): scheduler, transfer and client {1e3 * sched[w]:.1f} ms, on the worker "
                        f"around the run (metrics, result, row) {1e3 * side[w]:.0f} ms, the run's set-up "
                        f"{1e3 * t_setup:.0f} ms; workers busy {100 * busy[w]:.1f} % of the sweep" for w in (1, 2))
            + ".  The set-up is the master's: every run extracts the .ssp and its FMUs into a fresh "
            "directory (hundreds of files) and removes it afterwards; Dask's own share is the first term.  "
            f"The speed-up is bounded by the slowdown of each run under contention: 2 x {own[1]:.3f} / "
            f"{own[2]:.3f} = {2 * own[1] / own[2]:.2f}x, measured {speedup:.2f}x.", "",
            "What a worker waits on: the CPU time its process got during a task (the difference of "
            "`time.process_time()` between its consecutive tasks, its first task left out) against the task's "
            "wall on the worker: "
            + "; ".join(f"{w} worker(s): CPU {cpu[w][0]:.3f} s of {cpu[w][1]:.3f} s wall per task, on a core "
                        f"{100 * cpu[w][0] / cpu[w][1]:.0f} % of it" for w in (1, 2) if cpu[w])
            + ".  The rest of a task's wall the process was runnable but off the cores (other processes held "
              "them) or waiting on I/O; the scheduler, serialization and the client's GIL are outside the task "
              "and in the 'scheduler, transfer and client' term above.", "",
            f"## Worker memory over a {args.memory_runs}-run sweep (2 workers, 0.5 s runs)", "",
            "Resident memory of each worker process right after each of its runs, in completion order.", "",
            "| worker pid | runs | after its first run [MiB] | runs 2nd tenth [MiB] | last tenth [MiB] | change |",
            "| --- | --- | --- | --- | --- | --- |", *mem_lines, "",
            "## Extrapolation to 10,000 runs", "",
            f"Assumptions: every run costs what it cost here on one worker, {t_run:.2f} s (own work + engine "
            "overhead), on every worker of the cluster (one core per worker, as here); runs are independent, "
            "so the sweep takes ceil(10,000 / workers) waves; the scheduler spends about 1 ms per task "
            "(Dask's documented order) serially, which bounds the sweep from below when the waves are short; "
            "the client writes a row in microseconds (flushed CSV, measured negligible here); cluster start-up "
            "as measured for 2 local workers (a real cluster's start-up, e.g. a job queue's wait, comes on top); "
            "the .ssp reaches each worker once (a few MB).  Not included: stragglers and worker failures "
            "(a retried run adds one run's time to its wave).", "",
            "| workers | waves | compute [s] | scheduler [s] | start [s] | sweep [s] |",
            "| --- | --- | --- | --- | --- | --- |", extrapolate(64), extrapolate(1024), "",
            "At 1,024 workers the waves (ten of them) are few and short: the estimate is dominated by the run "
            "time of a wave and the cluster's start-up; with runs much shorter than a second the scheduler's "
            "per-task cost (about 10 s for 10,000 tasks) becomes the limit: batch several runs per task then."]
    return lines


if __name__ == "__main__":
    main()
