"""Run a sweep on Dask's distributed scheduler: a LocalCluster of worker processes by default (one per
core, one thread each) or an existing cluster by address; rows written as runs finish, resumable.

Each run is one task (:func:`.worker.execute`): the worker process runs the simulation in-process, so a
worker loads the scene's Python FMU code once and reuses it for every later run.  A run whose task
raises something unexpected or whose worker dies is submitted once more; the second failure is
recorded with its message.  The sweep itself never stops on a failed run.
"""
from __future__ import annotations

import logging
import os
import sys
import time as clock
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ParameterSetError, SettingsError
from . import table as tables
from .metrics import Custom, Metric, check, parse_metric
from .spec import Run, design as make_design
from .worker import SspFile, execute

MAX_ATTEMPTS = 2   # a run is retried at most once


@dataclass
class SweepResult:
    """What a sweep did: its table (every row, this session's and earlier ones) and counts."""

    path: Path
    rows: list[dict]
    ran: int = 0                 # runs finished in this session
    failed: int = 0              # of those, failed
    skipped: int = 0             # already in the table (resumed)
    wall_time: float = 0.0       # [s] of this session, cluster start-up included
    workers: int = 0
    retried: list[str] = field(default_factory=list)   # keys of runs tried twice


@dataclass(frozen=True)
class SceneFacts:
    """What a sweep checks before anything runs: the scene's name, outputs and settable variables."""

    name: str
    ssp: Path
    columns: list[str]
    variables: dict[str, set[str]]   # component -> its variable names
    parameter_sets: tuple[str, ...]
    stop_time: float | None


def scene_facts(scene: str | Path) -> SceneFacts:
    """Build the scene if needed (on the client, once) and read its outputs and variables."""
    from ..master.run import preview

    p = preview(scene)
    return SceneFacts(p.name, p.path, p.columns, p.variables, p.parameter_sets, p.stop_time)


def check_inputs(facts: SceneFacts, runs: list[Run]) -> None:
    """Refuse an input the scene does not have (a typo would otherwise fail every run)."""
    for name in dict.fromkeys(k for r in runs for k in r.inputs):
        if "." in name:
            comp, _, var = name.partition(".")
            if comp not in facts.variables:
                raise ParameterSetError(f"parameter {name!r}: component {comp!r} is not in scene {facts.name}: one of "
                                        f"{', '.join(facts.variables)}")
            if var not in facts.variables[comp]:
                raise ParameterSetError(f"parameter {name!r}: {comp} has no variable {var!r} (cranefmu info "
                                        f"{facts.name} lists them)")
    for r in runs:
        if r.parameter_set is not None and r.parameter_set not in facts.parameter_sets:
            raise ParameterSetError(f"parameter_set = {r.parameter_set!r} is not in scene {facts.name}: one of "
                                    f"{', '.join(facts.parameter_sets)}")


def default_metrics(scene: str) -> list[str]:
    """The scene's key metrics and the range of its key outputs."""
    from ..scenes import METRICS, SCENES

    keys = SCENES[scene].key_outputs if scene in SCENES else ()
    return (["scene"] if scene in METRICS else []) + [f"{k}:{c}" for c in keys for k in ("min", "max")]


def sweep(scene: str | Path, vary: list[str] | dict | None = None, metrics: list[str] | None = None,
          output: str | Path = "sweep.csv", *, parameters: dict | None = None, parameter_set: str | None = None,
          design: str = "factorial", samples: int | None = None, seed: int = 0, results: str | Path | None = None,
          workers: int | None = None, scheduler: str | None = None, client=None, progress: bool | None = None,
          **settings) -> SweepResult:
    """Run ``scene`` for every point of a design and write one row per run to the CSV ``output``.

    vary: ``["comp.var=1,2,3", "step_size=log:1e-4:1e-2:5", ...]``, ``{"comp.var": [values]}`` or a list
    of points ``[{"step_size": 1e-3, "rope.E": 1e11}, ...]`` run as given (see :mod:`.spec`); metrics: ``["max:rope.tension", "scene", ...]`` (see :mod:`.metrics`;
    default: the scene's key metrics and the range of its key outputs); parameters, parameter_set and
    further keyword run settings (``stop_time``, ``step_size``, ``algorithm``, ...) are fixed for every
    run; design: factorial | lhs | sobol (``samples`` points, ``seed``); results: a folder for each
    run's full result (``<key>.npy``, a structured array).  An existing ``output`` of the same sweep
    is resumed: its runs are skipped.  workers: processes of the local cluster (default: the cores);
    scheduler: address of an existing cluster; client: an existing ``distributed.Client``.
    Ctrl-C cancels the runs still going and keeps every finished row.
    """
    fixed = {**settings, **(parameters or {})}
    if parameter_set is not None:
        fixed["parameter_set"] = parameter_set
    plan = make_design(vary, fixed, design, samples, seed)
    facts = scene_facts(scene)
    wanted = [parse_metric(m) for m in (metrics if metrics is not None else default_metrics(facts.name))]
    metric_names = check(wanted, facts.name, facts.columns)
    runs = list({r.key: r for r in plan.runs(facts.name)}.values())
    check_inputs(facts, runs)
    inputs = plan.names + sorted(plan.fixed)
    table = tables.Table(output, tables.header(inputs, metric_names))
    todo = [r for r in runs if r.key not in table.done]
    out = SweepResult(table.path, [], skipped=len(runs) - len(todo))
    results_dir = None
    if results is not None:
        Path(results).mkdir(parents=True, exist_ok=True)
        results_dir = str(Path(results).resolve())
    t0 = clock.perf_counter()
    try:
        if todo:
            _distribute(todo, facts, wanted, results_dir, table, out, workers, scheduler, client, progress)
    finally:
        table.close()
        out.wall_time = clock.perf_counter() - t0
    out.rows = tables.read(table.path)
    return out


def _distribute(todo: list[Run], facts: SceneFacts, metrics: list[Metric | Custom], results_dir: str | None,
                table: tables.Table, out: SweepResult, workers: int | None, scheduler: str | None, client,
                progress: bool | None) -> None:
    from distributed import as_completed

    own, cluster = client is None, None
    if own:
        client, cluster = connect(workers, scheduler)
    futures: dict = {}
    bar = None
    try:
        local = cluster is not None or _is_local(client)
        ssp = SspFile.of(facts.ssp, facts.name, with_data=not local)
        if not local:   # the bytes go to every worker once, not with every task
            ssp = client.scatter(ssp, broadcast=True, hash=True)
        out.workers = len(client.scheduler_info().get("workers", {}))

        def submit(run: Run, attempt: int):
            fut = client.submit(execute, ssp, run, metrics, results_dir, key=f"cranefmu-sweep-{run.key}-{attempt}")
            futures[fut] = (run, attempt)
            return fut

        pending = as_completed([submit(r, 1) for r in todo])
        bar = _bar(len(todo), progress, out.skipped)
        for fut in pending:
            run, attempt = futures.pop(fut)
            try:
                row = fut.result()
            except Exception as err:  # noqa: BLE001 - the worker died or the task was lost
                row = {"key": run.key, **run.inputs, "status": "failed", "retry": True,
                       "error": " ".join(f"worker lost the run: {type(err).__name__}: {err}".split())}
            if row.pop("retry", False) and attempt < MAX_ATTEMPTS:
                out.retried.append(run.key)
                pending.add(submit(run, attempt + 1))
                continue
            row["attempts"] = attempt
            table.write(row)
            out.ran += 1
            out.failed += row["status"] != "ok"
            if bar is not None:
                bar.set_postfix_str(f"done {out.ran - out.failed}, failed {out.failed}", refresh=False)
                bar.update(1)
    except KeyboardInterrupt:
        client.cancel(list(futures))
        print(f"\ninterrupted: {out.ran} run(s) of this session kept in {table.path} "
              f"({len(table.done)} in all); the same command resumes the rest", file=sys.stderr)
        raise
    finally:
        if bar is not None:
            bar.close()
        if own:
            client.close()
            if cluster is not None:
                cluster.close()


def connect(workers: int | None = None, scheduler: str | None = None):
    """(client, cluster): a client of the cluster at ``scheduler``, or of a new LocalCluster of
    ``workers`` processes (default: the cores) with one thread each (cluster None for an address)."""
    import dask
    from distributed import Client, LocalCluster

    if scheduler is not None:
        if workers is not None:
            raise SettingsError(f"workers = {workers!r} is not allowed with a scheduler address: the cluster "
                                "at the address has its own workers")
        return Client(scheduler), None
    n = workers if workers is not None else (os.cpu_count() or 1)
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise SettingsError(f"workers = {n!r} is not allowed: an integer >= 1")
    # a dying worker fails its task at once (the engine retries it once itself), instead of the
    # scheduler trying it on three more workers
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                               silence_logs=logging.ERROR)
    return Client(cluster), cluster


def _is_local(client) -> bool:
    from distributed import LocalCluster

    return isinstance(getattr(client, "cluster", None), LocalCluster)


def _bar(total: int, progress: bool | None, skipped: int):
    if progress is False or (progress is None and not sys.stderr.isatty()):
        return None
    from tqdm import tqdm

    return tqdm(total=total, unit="run", desc="sweep" + (f" ({skipped} done before)" if skipped else ""),
                dynamic_ncols=True)
