"""A sweep's per-run overhead through the real sweep path, broken down, against the integration of a 2 s
elastic_pendulum run (native FMUs, H = 1 ms) measured in the same sweeps.

    .venv/bin/python benchmarks/sweep_overhead.py                # 30 one-step and 6 two-second runs a mode
    .venv/bin/python benchmarks/sweep_overhead.py --runs 10 --long 3 --modes in-process,local

Modes: ``in-process`` (sweep.worker.execute called here: the task alone), ``local`` (``cranefmu.sweep`` on
the LocalCluster the engine starts, 1 worker process), ``address`` (a LocalCluster of ``--workers``
processes reached by its address, as ``--scheduler``: the scene's bytes go to the workers by the plugin).
Every mode first sweeps a few runs to warm its workers, then one sweep of ``--runs`` one-step runs (the
overhead: everything a run costs but its integration) and one of ``--long`` runs to 2 s (the integration:
the time in the stepping loop, ``Execution._to_end``).  Each stage is timed by wrapping the function that
does it, in the worker processes (installed with ``client.run``) and on the client; means per run.
``transfer`` is the client's time per run in the engine's loop (``engine._distribute``, 1 worker: runs one
after another) minus the task's own time and the table's write.  Writes benchmarks/results/sweep_overhead.md.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import tempfile
import time as clock
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENE = "elastic_pendulum"

# (label, module, attribute, class or None): what each stage of a run is timed by
STAGES = [
    ("resolve (run request)", "cranefmu.master.runspec", "resolve", None),
    ("thread pinning", "cranefmu.master.run", "one_thread", None),
    ("thread pinning", "cranefmu.master.execution", "one_thread", None),
    ("scene (extracted, copied)", "cranefmu.master.execution", "extracted_scene", None),
    ("instantiate (FMUs, coupling, parts)", "cranefmu.master.execution", "build_execution", None),
    ("initialize", "cranefmu.master.execution", "initialize", None),
    ("integrate", "cranefmu.master.execution", "Execution", "_to_end"),
    ("finish and free", "cranefmu.master.execution", "Execution", "finish"),
    ("metrics", "cranefmu.sweep.worker", "measure", None),
    ("task (worker.execute)", "cranefmu.sweep.worker", "execute", None),
]
CLIENT_STAGES = [
    ("table write", "cranefmu.sweep.table", "Table", "write"),
    ("engine loop", "cranefmu.sweep.engine", "_distribute", None),
]


def install(stages=STAGES) -> None:
    """Wrap every stage's function in this process with a timer: (wall, CPU of the calling thread) [s] per
    call in ``cranefmu.sweep.worker._BENCH``."""
    import contextlib
    import importlib
    import time

    worker = importlib.import_module("cranefmu.sweep.worker")
    if getattr(worker, "_BENCH", None) is None:
        worker._BENCH, worker._BENCH_WRAPPED = {}, set()
    times, wrapped = worker._BENCH, worker._BENCH_WRAPPED
    times.clear()
    stages = [s for s in stages if s[1:] not in wrapped]   # each function wrapped once per process
    wrapped.update(s[1:] for s in stages)

    def timed(label, f):
        def wrapper(*args, **kwargs):
            t0, c0 = time.perf_counter(), time.thread_time()
            try:
                return f(*args, **kwargs)
            finally:
                times.setdefault(label, []).append((time.perf_counter() - t0, time.thread_time() - c0))
        return wrapper

    def timed_context(label, f):   # a context manager: time its entering and its leaving
        @contextlib.contextmanager
        def wrapper(*args, **kwargs):
            t0, c0 = time.perf_counter(), time.thread_time()
            cm = f(*args, **kwargs)
            cm.__enter__()
            spent = (time.perf_counter() - t0, time.thread_time() - c0)
            try:
                yield
            finally:
                t1, c1 = time.perf_counter(), time.thread_time()
                cm.__exit__(None, None, None)
                times.setdefault(label, []).append((spent[0] + time.perf_counter() - t1,
                                                    spent[1] + time.thread_time() - c1))
        return wrapper

    for label, module, name, method in stages:
        mod = importlib.import_module(module)
        if method is not None:
            cls = getattr(mod, name)
            setattr(cls, method, timed(label, getattr(cls, method)))
        elif name == "one_thread":
            setattr(mod, name, timed_context(label, getattr(mod, name)))
        else:
            setattr(mod, name, timed(label, getattr(mod, name)))


def collect() -> dict:
    import cranefmu.sweep.worker as worker

    out = dict(worker._BENCH)
    worker._BENCH.clear()
    return out


def process_cpu(client) -> dict:
    """CPU time [s] so far of the client, the scheduler and the workers (summed) processes."""
    import time

    return {"client": time.process_time(), "scheduler": client.run_on_scheduler(time.process_time),
            "workers": sum(client.run(time.process_time).values())}


def _merge(parts: list[dict]) -> dict:
    out: dict = {}
    for part in parts:
        for k, v in part.items():
            out.setdefault(k, []).extend(v)
    return out


def points(n: int, stop: float, offset: int) -> list[dict]:
    return [{"rope.E": 2e10 * (1 + (offset + i) / 1000), "stop_time": stop} for i in range(n)]


def in_process(runs: int, long: int, rounds: int) -> list[dict]:
    from cranefmu.master.runspec import resolve
    from cranefmu.sweep.metrics import parse_metric
    from cranefmu.sweep.spec import Run
    from cranefmu.sweep.worker import SspFile

    install()
    import cranefmu.sweep.worker as worker

    ssp = SspFile.of(resolve(SCENE, fmus="native").ssp, SCENE, False)
    metrics = [parse_metric("max:rope.tension")]

    def sweep(pts):
        for p in pts:
            row = worker.execute(ssp, Run(SCENE, {**p, "step_size": 1e-3, "fmus": "native"}), metrics)
            assert row["status"] == "ok", row

    sweep(points(3, 1e-3, 0))
    out = []
    for r in range(rounds):
        collect()
        sweep(points(runs, 1e-3, 1000 * r + 100))
        short = collect()
        sweep(points(long, 2.0, 1000 * r + 500))
        out.append(summary(short, collect(), runs))
    return out


def on_cluster(client, runs: int, long: int, folder: Path, rounds: int) -> list[dict]:
    """Each round: the stages of ``runs`` one-step runs and the integration of ``long`` 2 s runs swept on
    ``client`` (new points each round: nothing resumed)."""
    import cranefmu

    client.run(install)
    install(CLIENT_STAGES)

    def sweep(pts, name):
        res = cranefmu.sweep(SCENE, pts, ["max:rope.tension"], folder / name, client=client, progress=False,
                             step_size=1e-3, fmus="native")
        assert res.failed == 0, res.design[:1]

    sweep(points(4, 1e-3, 0), "warm.csv")
    return [_round(client, sweep, runs, long, r) for r in range(rounds)]


def _round(client, sweep, runs: int, long: int, r: int) -> dict:
    client.run(collect)
    collect()
    cpu0 = process_cpu(client)
    sweep(points(runs, 1e-3, 1000 * r + 100), f"short{r}.csv")
    cpu1 = process_cpu(client)
    short, short_client = _merge(list(client.run(collect).values())), collect()
    sweep(points(long, 2.0, 1000 * r + 500), f"long{r}.csv")
    out = summary(short, _merge(list(client.run(collect).values())), runs)
    collect()
    per = {k: (cpu1[k] - cpu0[k]) / runs for k in cpu0}
    loop_wall, loop_cpu = (sum(x[i] for x in short_client["engine loop"]) / runs for i in (0, 1))
    table = tuple(sum(x[i] for x in short_client["table write"]) / runs for i in (0, 1))
    task = out["task (worker.execute)"]
    out["table write (client)"] = table
    out["worker process besides the task"] = (None, per["workers"] - task[1])
    # a LocalCluster started here keeps its scheduler in this (the client's) process: its CPU then holds the
    # client's too (the sweep's set-up and the engine's loop), which is not added a second time
    shared = client.run_on_scheduler(os.getpid) == os.getpid()
    out["scheduler (and client, one process)" if shared else "scheduler"] = (None, per["scheduler"])
    out["client's engine loop besides the table"] = (None, loop_cpu - table[1])
    if len(client.scheduler_info()["workers"]) == 1:   # runs one after another: the rest of the loop is transfer
        out["transfer, scheduling, client (wall)"] = (loop_wall - task[0] - table[0], None)
    out["overhead per run"] = (loop_wall, per["workers"] + per["scheduler"] + (0.0 if shared else loop_cpu))
    return out


def summary(short: dict, long: dict, runs: int) -> dict:
    """Per run (wall, CPU) [s] of each stage of the one-step runs; the integration of the 2 s runs."""
    out = {label: tuple(sum(x[i] for x in short.get(label, [])) / runs for i in (0, 1)) for label, *_ in STAGES}
    out["overhead per run"] = out["task (worker.execute)"]
    out["integration of a 2 s run"] = tuple(statistics.mean(x[i] for x in long["integrate"]) for i in (0, 1))
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=30, help="one-step runs a mode (the overhead)")
    ap.add_argument("--long", type=int, default=6, help="runs of 2 s a mode (the integration)")
    ap.add_argument("--rounds", type=int, default=3, help="measurements a mode (the median round is shown)")
    ap.add_argument("--workers", type=int, default=1, help="worker processes of the address mode's cluster")
    ap.add_argument("--modes", default="in-process,local,address")
    ap.add_argument("--note", default="", help="a line on the code measured (e.g. an older commit's tree on PYTHONPATH)")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "sweep_overhead.md"))
    args = ap.parse_args(argv)
    modes = args.modes.split(",")
    load0 = os.getloadavg()[0]
    results: dict[str, dict] = {}
    with tempfile.TemporaryDirectory(prefix="sweep_overhead_") as tmp:
        if "local" in modes:   # the cluster cranefmu.sweep starts itself, of 1 worker
            from cranefmu.sweep.engine import close, connect

            client, cluster = connect(1)
            try:
                results["local (1 worker)"] = on_cluster(client, args.runs, args.long,
                                                         Path(tempfile.mkdtemp(dir=tmp)), args.rounds)
            finally:
                close(client, cluster)
        if "address" in modes:   # a cluster reached by its address, as --scheduler
            from distributed import Client, LocalCluster

            cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                   dashboard_address=":0", local_directory=tmp)
            client = Client(cluster.scheduler_address)
            try:
                results[f"address ({args.workers} worker{'s' * (args.workers > 1)})"] = \
                    on_cluster(client, args.runs, args.long, Path(tempfile.mkdtemp(dir=tmp)), args.rounds)
            finally:
                client.close()
                cluster.close()
        if "in-process" in modes:   # last: it wraps this process's worker.execute, which the clusters pickle
            results["in-process (the task alone)"] = in_process(args.runs, args.long, args.rounds)
    write(results, args, load0, Path(args.out))


def write(results: dict, args, load0: float, out: Path) -> None:
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "src"], cwd=ROOT,
                           capture_output=True, text=True).stdout.strip()
    ratios = {m: [100 * r["overhead per run"][1] / r["integration of a 2 s run"][1] for r in rounds]
              for m, rounds in results.items()}
    results = {m: sorted(rounds, key=lambda r: r["overhead per run"][1] / r["integration of a 2 s run"][1])[
        (len(rounds) - 1) // 2] for m, rounds in results.items()}   # the round of the median CPU ratio
    modes = list(results)
    keys = list(dict.fromkeys(label for label, *_ in STAGES)) + [
        "table write (client)", "worker process besides the task", "scheduler (and client, one process)", "scheduler",
        "client's engine loop besides the table",
        "transfer, scheduling, client (wall)", "overhead per run", "integration of a 2 s run"]
    lines = ["# A sweep's per-run overhead through the real sweep path (benchmarks/sweep_overhead.py)", "",
             f"Commit {commit}{' + uncommitted src changes' if dirty else ''}, "
             f"{clock.strftime('%Y-%m-%d %H:%M UTC', clock.gmtime())}, load average {load0:.1f} before and "
             f"{os.getloadavg()[0]:.1f} after (2 cores shared by several agents), {SCENE} with native FMUs, "
             f"H = 1 ms; `--runs {args.runs} --long {args.long} --workers {args.workers} --rounds {args.rounds}`."
             + (f" {args.note}" if args.note else ""), "",
             "Means per run [ms] of the one-step runs: everything a run costs but its integration (its one step "
             "included). `integration of a 2 s run` is the stepping loop (`Execution._to_end`) of the 2 s runs "
             "of the same mode. CPU: the stages' thread CPU; `overhead per run` in CPU is the CPU the workers "
             "and the scheduler processes used during the one-step sweep (plus the client's in the engine's loop "
             "where the scheduler is another process), "
             "over the runs (what the sweep costs the machine a run); in wall it is the client's loop over the "
             "runs (with 2 workers: runs overlap, so less than a run's latency). The wall column is at the "
             "mercy of the other agents' load; CPU is the steadier measure.", ""]
    for unit, i in (("CPU", 1), ("wall", 0)):
        lines += [f"| stage, {unit} [ms] | " + " | ".join(modes) + " |", "| --- |" + " --- |" * len(modes)]
        for k in keys:
            cells = []
            for m in modes:
                v = results[m].get(k)
                cells.append("" if v is None or v[i] is None else f"{v[i] * 1e3:.2f}")
            if any(cells):
                lines.append(f"| {k} | " + " | ".join(cells) + " |")
        lines.append("| **overhead / integration** | " + " | ".join(
            f"**{100 * results[m]['overhead per run'][i] / results[m]['integration of a 2 s run'][i]:.1f} %**"
            for m in modes) + " |")
        lines.append("| own computation (initialize + its one step) / integration | " + " | ".join(
            f"{100 * (results[m]['initialize'][i] + results[m]['integrate'][i]) / results[m]['integration of a 2 s run'][i]:.1f} %"
            for m in modes) + " |")
        lines.append("")
    lines += ["`own computation` is the part of the overhead every run computes whatever its length (the coupled "
              "start values settled, the FMUs' initialization, and here its one macro step), bitwise fixed by "
              "its results. `scheduler (and client, one process)`: the LocalCluster this script starts (either "
              "mode) runs its scheduler in the client's process; that CPU holds the client's sweep set-up and loop too (so the "
              "client's loop is not added again to the overhead).", "",
              "`task` holds the stages above it (resolve .. metrics) and the row. Each mode was measured "
              f"{args.rounds} times (new points each round); the tables show its round of the median CPU ratio. "
              "CPU overhead / integration of every round:", ""]
    lines += [f"- {m}: " + ", ".join(f"{x:.1f} %" for x in ratios[m]) for m in modes]
    text = "\n".join(lines) + "\n"
    print(text)
    out.write_text(text)


if __name__ == "__main__":
    main()
