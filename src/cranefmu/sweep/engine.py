"""Run a sweep on Dask's distributed scheduler: a LocalCluster of worker processes by default (one per
core, one thread each) or an existing cluster by address; rows written as runs finish, resumable.

Each task runs one or several runs (:func:`.worker.execute_runs`; several short ones share a task, :mod:`.feed`):
the worker process runs the simulations in-process, so a worker loads the scene's FMUs once and reuses
them for every later run.  A run whose task
raises something unexpected is submitted once more; the second failure is recorded with its message.
A run lost with its worker (or with the scheduler) is submitted once more while the cluster lives,
else recorded as ``lost``: a resumed sweep runs it again.  The sweep itself never stops on a failed
run; losing the scheduler ends it with :class:`ClusterLost`, saying how to resume.

On a cluster given by address the scene's ``.ssp`` reaches every worker through a worker plugin, so a
worker that joins later (restarted after a crash) gets it too.  A local cluster keeps its Dask scratch
space and its workers' temporary files in one private folder, removed when the sweep ends, however
it ends (Ctrl-C included).
"""
from __future__ import annotations

import hashlib
import logging
import os
import shutil
import signal
import sys
import tempfile
import time as clock
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import CraneFmuError, ParameterSetError, SettingsError
from . import table as tables
from .metrics import Custom, Metric, check, parse_metric
from .request import digest as request_digest
from .spec import Run, design as make_design
from .feed import TaskFeed
from .worker import SspFile, execute_runs

MAX_ATTEMPTS = 2   # a run is retried at most once


@dataclass
class SweepResult:
    """What a sweep did: its table (every row, this session's and earlier ones), the rows of this
    design (one per point, in the design's order: what a study reads) and counts."""

    path: Path
    rows: list[dict]
    design: list[dict] = field(default_factory=list)   # the row of each point of this design, in order
    ran: int = 0                 # runs finished in this session
    failed: int = 0              # of those, failed (or lost)
    lost: int = 0                # of those, lost with their worker or the scheduler (rerun on resume)
    outside: int = 0             # rows of the table outside this design (an earlier design or request; kept unless pruned)
    skipped: int = 0             # already in the table (resumed)
    wall_time: float = 0.0       # [s] of this session, cluster start-up included
    workers: int = 0
    retried: list[str] = field(default_factory=list)   # keys of runs tried twice
    tasks: int = 0               # Dask tasks submitted (several short runs share one: .feed)


class ClusterLost(CraneFmuError):
    """The client lost the Dask scheduler mid-sweep; finished rows are kept and the same call resumes."""


@dataclass(frozen=True)
class SceneFacts:
    """What a sweep checks before anything runs: the scene's name, outputs and settable variables."""

    name: str
    ssp: Path
    columns: list[str]
    variables: dict[str, set[str]]   # component -> its variable names
    parameter_sets: tuple[str, ...]
    stop_time: float | None


def scene_facts(scene: str | Path, fmus: str | None = None) -> SceneFacts:
    """Build the scene (with FMUs of kind ``fmus``) if needed (on the client, once) and read its outputs
    and variables."""
    from ..master.run import preview

    p = preview(scene, fmus)
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


def check_units(facts: SceneFacts, given: dict[str, str]) -> None:
    """Refuse a unit an input's values are given in (``given``: name -> unit) that does not measure what the
    parameter measures (its declared unit), before anything runs."""
    if not given:
        return
    from ..experiments.scene_check import interface
    from ..parameter_units import refusal

    declared = interface(str(facts.ssp)).units or {}
    for name, unit in given.items():
        line = refusal(name, f"[{unit}]", unit, declared.get(name))
        if line is not None:
            raise SettingsError(line)


def default_metrics(scene: str) -> list[str]:
    """The scene's key metrics and the range of its key outputs."""
    from ..scenes import METRICS, SCENES

    keys = SCENES[scene].key_outputs if scene in SCENES else ()
    return (["scene"] if scene in METRICS else []) + [f"{k}:{c}" for c in keys for k in ("min", "max")]


def sweep(scene: str | Path, vary: list[str] | dict | None = None, metrics: list[str] | None = None,
          output: str | Path = "sweep.csv", *, parameters: dict | None = None, parameter_set: str | None = None,
          design: str = "factorial", samples: int | None = None, seed: int = 0, results: str | Path | None = None,
          workers: int | None = None, scheduler: str | None = None, client=None, progress: bool | None = None,
          prune: bool = False, warn_outside: bool = True, **settings) -> SweepResult:
    """Run ``scene`` for every point of a design and write one row per run to the CSV ``output``.

    vary: ``["comp.var=1,2,3", "step_size=log:1e-4:1e-2:5", ...]``, ``{"comp.var": [values]}`` or a list
    of points ``[{"step_size": 1e-3, "rope.E": 1e11}, ...]`` run as given (see :mod:`.spec`); metrics: ``["max:rope.tension", "scene", ...]`` (see :mod:`.metrics`;
    default: the scene's key metrics and the range of its key outputs); parameters, parameter_set and
    further keyword run settings (``stop_time``, ``step_size``, ``algorithm``, ...) are fixed for every
    run; design: factorial | lhs | sobol (``samples`` points, ``seed``); results: a folder for each
    run's full result (``<key>.npy``, a structured array).  An existing ``output`` of the same sweep
    is resumed: its runs are skipped.  workers: processes of the local cluster (default: the cores);
    scheduler: address of an existing cluster; client: an existing ``distributed.Client``.
    Rows of ``output`` outside this design (an earlier ``vary``) are kept with a warning, or dropped
    with ``prune`` (``warn_outside=False``: kept silently, for a search whose rounds share one table).
    Ctrl-C cancels the runs still going and keeps every finished row.
    """
    _refuse_bootstrapping()
    _check_table_target(output)
    fixed = {**settings, **(parameters or {})}
    if parameter_set is not None:
        fixed["parameter_set"] = parameter_set
    plan = make_design(vary, fixed, design, samples, seed)
    facts = scene_facts(scene, fixed.get("fmus"))
    wanted = [parse_metric(m) for m in (metrics if metrics is not None else default_metrics(facts.name))]
    metric_names = check(wanted, facts.name, facts.columns)
    points = plan.runs(facts.name)
    check_inputs(facts, points)
    check_units(facts, plan.units)
    ssp_sha = hashlib.sha256(Path(facts.ssp).read_bytes()).hexdigest()
    # the key covers the whole request (scene file, code, effective settings), not the inputs alone
    points = [replace(r, request=request_digest(facts.ssp, ssp_sha, r)) for r in points]
    runs = list({r.key: r for r in points}.values())
    inputs = [plan.label(n) for n in plan.names + sorted(plan.fixed)]   # with the unit a value was given in
    table = tables.Table(output, tables.header(inputs, metric_names))
    keys = {r.key for r in runs}
    outside = table.keys - keys
    if outside and prune:
        table.drop(outside)
    elif outside and warn_outside:
        print(f"cranefmu: warning: {table.path} holds {len(outside)} row(s) outside this design (an earlier "
              "--vary, other fixed inputs, or another build of the scene or the code); they are kept; --prune "
              "(prune=True) drops them", file=sys.stderr)
    todo = [r for r in runs if r.key not in table.done]
    out = SweepResult(table.path, [], skipped=len(runs) - len(todo), outside=0 if prune else len(outside))
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
        tables.reorder(table.path, [r.key for r in points])   # the design's order, not the runs' completion
    out.rows = tables.read(table.path)
    by_key = {r["key"]: r for r in out.rows}
    out.design = [by_key[r.key] for r in points]
    return out


def _distribute(todo: list[Run], facts: SceneFacts, metrics: list[Metric | Custom], results_dir: str | None,
                table: tables.Table, out: SweepResult, workers: int | None, scheduler: str | None, client,
                progress: bool | None) -> None:
    from distributed import as_completed

    own, cluster = client is None, None
    if own:
        client, cluster = connect(workers, scheduler)
    futures: dict = {}
    bar = interrupted = None
    # a lost scheduler is reported once, below, with how to resume: not by the client's reconnect tracebacks
    quiet = logging.getLogger("distributed.client")
    level = quiet.level
    quiet.setLevel(logging.CRITICAL)
    try:
        # every remote worker, also one that joins later, gets the bytes once through a plugin
        ssp = ship_ssp(client, facts.ssp, facts.name, local=cluster is not None or _is_local(client))
        out.workers = len(client.scheduler_info().get("workers", {}))

        feed = TaskFeed(todo, out.workers)
        counted = clock.monotonic()

        def submit(runs: list[Run], attempt: int):
            fut = client.submit(execute_runs, ssp, runs, metrics, results_dir,
                                key=f"cranefmu-sweep-{runs[0].key}-x{len(runs)}-{attempt}")
            futures[fut] = (runs, attempt)
            out.tasks += 1
            return fut

        pending = as_completed([submit(runs, 1) for runs in feed.take(0)])
        bar = _bar(len(todo), progress, out.skipped)
        for fut in pending:
            runs, attempt = futures.pop(fut)
            try:
                rows = fut.result()
            except Exception as err:  # noqa: BLE001 - the worker died, the task or the scheduler was lost
                error = " ".join(f"worker lost the run: {type(err).__name__}: {err}".split())
                rows = [{"key": run.key, **run.row, "status": "lost", "retry": True, "error": error} for run in runs]
            alive = client.status == "running"
            for run, row in zip(runs, rows):
                if row.pop("retry", False) and attempt < MAX_ATTEMPTS and alive:   # alone in its task
                    out.retried.append(run.key)
                    pending.add(submit([run], attempt + 1))
                    continue
                row["attempts"] = attempt
                table.write(row)
                feed.observe(row.get("task_time"))
                out.ran += 1
                out.failed += row["status"] not in tables.FINISHED
                out.lost += row["status"] == "lost"
                if bar is not None:
                    bar.set_postfix_str(f"done {out.ran - out.failed}, failed {out.failed}", refresh=False)
                    bar.update(1)
            if alive:
                if clock.monotonic() - counted > 1.0:   # workers may join or leave (an RPC: once a second at most)
                    try:
                        feed.set_workers(len(client.scheduler_info().get("workers", {})))
                    except Exception:  # noqa: BLE001 - a scheduler going away: the loop's own checks report it
                        pass
                    counted = clock.monotonic()
                for more in feed.take(len(futures)):
                    pending.add(submit(more, 1))
        if client.status != "running":
            raise ClusterLost(f"lost the Dask scheduler{' at ' + scheduler if scheduler else ''} after {out.ran} "
                              f"run(s); {out.lost} run(s) recorded as lost, {len(feed.queue)} not started, and every finished row kept in "
                              f"{table.path}: start the cluster again and run the same command to resume")
    except KeyboardInterrupt as err:
        from ..master.interrupt import RunInterrupted, signal_name

        interrupted = _ignore_sigint()   # a second Ctrl-C must not break the clean-up (restored below)
        try:
            client.cancel(list(futures))
        except Exception:  # noqa: BLE001 - a closing client may refuse; the cluster is closed below
            pass
        signum = getattr(err, "signum", signal.SIGINT)   # SIGTERM, SIGHUP: the CLI's handler (exit 143, 129)
        by = "" if signum == signal.SIGINT else f" by {signal_name(signum)}"
        raise RunInterrupted(f"sweep interrupted{by}: {out.ran} run(s) of this session kept in {table.path} "
                             f"({len(table.done)} in all); the same command resumes the rest", signum=signum) from None
    finally:
        if bar is not None:
            bar.close()
        if own:
            close(client, cluster)
        quiet.setLevel(level)
        if interrupted is not None:
            signal.signal(signal.SIGINT, interrupted)


def _check_table_target(output: str | Path) -> None:
    """The sweep table ``output`` is a file this process can write and read back (to resume): an empty
    name, a directory or a stream (``-``, a FIFO) is one line, before any work (a missing folder is made)."""
    from ..master.output_file import descriptor, is_stream

    if not str(output).strip():
        raise SettingsError(f"output {str(output)!r} is not allowed: an empty name; give a file path")
    if Path(output).is_dir():
        raise SettingsError(f"output {str(output)!r} is not allowed: it is an existing directory; give a file path")
    if descriptor(str(output)) is not None or is_stream(str(output)):
        raise SettingsError(f"output {str(output)!r} is not allowed: a sweep table is read back to resume; "
                            "give a file path")


def connect(workers: int | None = None, scheduler: str | None = None):
    """(client, cluster): a client of the cluster at ``scheduler``, or of a new LocalCluster of
    ``workers`` processes (default: the cores) with one thread each (cluster None for an address)."""
    import dask
    from distributed import Client, LocalCluster

    if scheduler is not None:
        if workers is not None:
            raise SettingsError(f"workers = {workers!r} is not allowed with a scheduler address: the cluster "
                                "at the address has its own workers")
        from .scheduler_probe import probe, timeout

        probe(scheduler)   # a port that never answers, or another service: one line within the timeout
        try:
            return Client(scheduler, timeout=timeout()), None
        except (OSError, MemoryError, ValueError, TypeError) as err:   # unreachable, refused, timed out, garbled
            raise SettingsError(f"scheduler {scheduler!r}: cannot reach the Dask scheduler there: "
                                + " ".join(str(err).split())) from None
    n = workers if workers is not None else (os.cpu_count() or 1)
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise SettingsError(f"workers = {n!r} is not allowed: an integer >= 1")
    _refuse_bootstrapping()
    # Dask's scratch space and the workers' temporary files (extracted scenes) in one private folder,
    # removed by close(); a dying worker fails its task at once (the engine retries it once itself),
    # instead of the scheduler trying it on three more workers
    scratch = tempfile.mkdtemp(prefix="cranefmu_sweep_")
    os.environ[_CHILD] = scratch   # inherited by the worker processes from their first instruction on
    # the workers start with Ctrl-C ignored (an ignored signal stays ignored in the child): a terminal's
    # Ctrl-C reaches the whole process group, and the client alone stops the sweep and closes them
    previous = _ignore_sigint()
    try:
        with dask.config.set({"distributed.scheduler.allowed-failures": 0, "temporary-directory": scratch}):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                   silence_logs=logging.CRITICAL, local_directory=scratch, env={"TMPDIR": scratch})
    except BaseException:
        unguarded = (Path(scratch) / _UNGUARDED).exists()
        shutil.rmtree(scratch, ignore_errors=True)
        if unguarded:
            print(f"cranefmu: error: {UNGUARDED_TEXT}", file=sys.stderr)
            raise SystemExit(1) from None
        raise
    finally:
        os.environ.pop(_CHILD, None)
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    cluster._cranefmu_scratch = scratch
    return Client(cluster), cluster


_CHILD = "CRANEFMU_SWEEP_SCRATCH"   # the local cluster's scratch folder, seen by its worker processes
_UNGUARDED = "unguarded-main"
UNGUARDED_TEXT = ("the sweep's worker processes import your script again and it starts a sweep at import: put "
                  "the call under `if __name__ == \"__main__\":` (as with multiprocessing)")


def _refuse_bootstrapping() -> None:
    """In a worker process importing a script without ``if __name__ == "__main__":`` (spawn runs the
    script again): leave a mark for the client, which says so in one line, and end this process."""
    import multiprocessing

    scratch = os.environ.get(_CHILD)
    if scratch and getattr(multiprocessing.current_process(), "_inheriting", False):
        try:
            (Path(scratch) / _UNGUARDED).touch()
        finally:
            os._exit(1)


def interrupt_once() -> None:
    """For a command line: the first Ctrl-C raises KeyboardInterrupt, every later one is ignored, so the
    clean-up and the one-line message run to the end (a second Ctrl-C must not kill the process)."""
    def once(signum, frame):
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        raise KeyboardInterrupt

    signal.signal(signal.SIGINT, once)


def _ignore_sigint():
    """Ignore SIGINT; the handler it had (None when not in the main thread, where nothing can be set)."""
    try:
        return signal.signal(signal.SIGINT, signal.SIG_IGN)
    except ValueError:
        return None


def close(client, cluster) -> None:
    """Close the client and a local cluster quietly (Ctrl-C ignored meanwhile) and remove its scratch."""
    previous = _ignore_sigint()
    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    try:
        try:
            client.close(timeout=10)
        except Exception:  # noqa: BLE001 - a client without its scheduler
            pass
        if cluster is not None:
            try:
                cluster.close(timeout=10)
            except Exception:  # noqa: BLE001 - workers already gone
                pass
            scratch = getattr(cluster, "_cranefmu_scratch", None)
            if scratch:
                shutil.rmtree(scratch, ignore_errors=True)
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)


def ship_ssp(client, path: Path, name: str, local: bool | None = None) -> SspFile:
    """The scene ``path`` as the tasks on ``client``'s workers find it: its path on a local cluster; else
    its bytes, written on every worker (also one that joins later) by a worker plugin, registered once
    per content."""
    local = _is_local(client) if local is None else local
    ssp = SspFile.of(Path(path), name, with_data=not local)
    if local:
        return ssp
    from .plugin import PluginSsp, SspPlugin

    client.register_plugin(SspPlugin(ssp), name=f"cranefmu-ssp-{ssp.sha256[:16]}")
    return PluginSsp(ssp.name, ssp.sha256, ssp.path)


def _is_local(client) -> bool:
    from distributed import LocalCluster

    return isinstance(getattr(client, "cluster", None), LocalCluster)


def _bar(total: int, progress: bool | None, skipped: int):
    if progress is False or (progress is None and not sys.stderr.isatty()):
        return None
    from tqdm import tqdm

    return tqdm(total=total, unit="run", desc="sweep" + (f" ({skipped} done before)" if skipped else ""),
                dynamic_ncols=True)
