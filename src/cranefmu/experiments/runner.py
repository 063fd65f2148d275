"""Run experiments: every case of every file checked first, then run, then judged.

:func:`prepare` reads and checks every file (nothing runs if one is bad: :class:`ExperimentError`),
resolving each case into a :class:`~cranefmu.master.runspec.RunSpec` with its commands;
:func:`run_cases` runs them (in this process, on a process pool, or on the sweep engine's Dask
cluster: :func:`choose_engine`) keeping only the columns the assertions read; :func:`judge_all`
gives one :class:`~.assertions.Verdict` per assertion, after every case of an experiment ran (a limit may name another case's result
``case.assertion``).
"""
from __future__ import annotations

import math
import time as clock
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import CraneFmuError
from .assertions import Verdict, judge, measured
from .expressions import evaluate
from .reader import Case, CommandSpec, ExperimentError, load
from .scene_check import SceneInterface, check, columns_of, measured_unit, set_in_declared_units


@dataclass
class Planned:
    """A case ready to run: its spec, its scene's interface and the parameter values of its expressions."""

    case: Case
    spec: object                     # RunSpec
    scene: SceneInterface
    values: dict
    columns: list[str]
    rows: dict = field(default_factory=dict)   # column -> array after the run ("time" too)
    error: str = ""                  # the run failed: why
    wall: float = 0.0
    stopped: str = ""                # the run ended before its stop time (a stop condition): why

    @property
    def stop_time(self) -> float:
        """The time [s] the case's run was to reach."""
        return float(self.spec.settings.stop_time)

    @property
    def end_time(self) -> float | None:
        """The last row's time [s], None without rows."""
        t = self.rows.get("time") if self.rows else None
        return float(t[-1]) if t is not None and len(t) else None


def experiment_files(paths: list[str | Path]) -> list[Path]:
    """The .toml files given, a directory giving its *.toml (sorted, not recursive)."""
    out = []
    for p in map(Path, paths):
        if p.is_dir():
            found = sorted(p.glob("*.toml"))
            if not found:
                raise ExperimentError(f"{p}: a directory without experiment files (*.toml)")
            out += found
        elif p.is_file():
            out.append(p)
        else:
            raise ExperimentError(f"{p}: no such file or directory")
    return out


def prepare(paths: list[str | Path], overrides: dict | None = None) -> list[Planned]:
    """Every case of the files, checked against its scene and resolved (``overrides``: run settings
    over every case's, e.g. from the command line)."""
    planned = []
    for path in experiment_files(paths):
        cases = load(path)
        results = {f"{c.name}.{a.name}" for c in cases for a in c.assertions}
        planned += [prepare_case(case, results, overrides or {}) for case in cases]
    return planned


def commands_of(specs: tuple[CommandSpec, ...], values: dict, emergency: tuple | None = None) -> list:
    """The master's :class:`~cranefmu.master.commands.Command` objects of a case's commands; a command with
    ``when`` and the case's ``emergency`` stop (condition, ramp, where) become event sources (:mod:`.events`)."""
    from ..master.commands import Command
    from .events import RateOf, Trigger, Triggered
    from .profiles import ProfileError, moves, shaped, shifted, table

    out = []
    stop_all = Trigger(emergency[0], values, "emergency stop") if emergency else None
    for c in specs:
        try:
            if c.moves:
                profile = moves(c.initial, list(c.moves))
            else:
                profile = table(list(c.table), c.interpolation)
            if c.shaper:
                profile = shaped(profile, c.shaper, evaluate(c.frequency, values), evaluate(c.damping, values))
            if c.offset:   # a boom motion: its input is the change from the start value
                profile = shifted(profile, -c.offset)
        except (ProfileError, CraneFmuError) as err:
            raise ExperimentError(f"{c.where}: {err}") from None
        rate = profile.derivative() if c.rate_inputs else None
        if c.when is not None or stop_all is not None:
            source = profile
            if c.when is not None:
                source = Triggered(source, Trigger(c.when, values, c.where), c.action, c.stop_ramp)
            if stop_all is not None:
                source = Triggered(source, stop_all, "stop", emergency[1])
            profile, rate = source, RateOf(source) if c.rate_inputs else None
        out += [Command(target, profile) for target in c.inputs]
        if c.rate_inputs:
            out += [Command(target, rate) for target in c.rate_inputs]
    return out



def _run_one(spec, columns: list[str]) -> tuple[dict, str, float, str]:
    """(kept columns, error text, wall s, why it stopped early or '') of one case's run (also in a pool's
    worker process)."""
    from ..errors import SimulationError
    from ..master.run import run

    wall = clock.perf_counter()
    error = stopped = ""
    try:
        res = run(spec)
        rows, stopped = res.result, res.stats.stopped or ""
    except SimulationError as err:
        rows, error = err.result, f"the run failed: {err}"
    except CraneFmuError as err:
        rows, error = None, f"the run was refused: {err}"
    kept = {}
    if rows is not None and len(rows):
        kept = {name: np.array(rows[name]) for name in ["time", *columns] if name in rows.dtype.names}
    return kept, error, clock.perf_counter() - wall, stopped


ENGINES = ("auto", "inline", "pool", "dask")
# cases: from this many (with jobs > 1) ``auto`` runs them on a local Dask cluster, whose start costs 0.9-2.7 s
# more than a pool's (benchmarks/results/check_engines.md): worth it beside many runs, where a lost worker
# then fails one case instead of breaking the pool
DASK_FROM = 32


def choose_engine(engine: str, cases: int, jobs: int, scheduler: str | None) -> str:
    """The engine that runs ``cases`` cases: ``engine`` unless it is ``auto``, which takes the Dask cluster
    at ``scheduler`` if given, else this process for one case or one job, else a process pool for fewer
    than :data:`DASK_FROM` cases (it starts in a fraction of a second), else a local Dask cluster
    (``cranefmu sweep``'s engine: a lost worker fails its case only, after one more attempt)."""
    if engine not in ENGINES:
        raise ExperimentError(f"--engine {engine!r} is not allowed: one of {', '.join(ENGINES)}")
    if not isinstance(jobs, int) or isinstance(jobs, bool) or jobs < 1:
        raise ExperimentError(f"--jobs {jobs!r} is not allowed: 1 or more")
    if scheduler is not None and engine not in ("auto", "dask"):
        raise ExperimentError(f"--engine {engine} is not allowed with --scheduler {scheduler}: the cluster "
                              "runs the cases on Dask (--engine dask or auto)")
    if engine != "auto":
        return engine
    if scheduler is not None:
        return "dask"
    if jobs == 1 or cases <= 1:
        return "inline"
    return "dask" if cases >= DASK_FROM else "pool"


def run_cases(planned: list[Planned], jobs: int = 1, say=None, engine: str = "auto",
              scheduler: str | None = None) -> str:
    """Run every case, filling ``rows``/``error``/``wall``; returns the engine that ran them
    (:func:`choose_engine`: ``inline`` in this process, ``pool`` on ``jobs`` worker processes, ``dask``
    on a local Dask cluster of ``jobs`` workers or the cluster at ``scheduler``).  A case whose run
    fails, or whose worker is lost, gets its reason in ``error``; the others still run."""
    chosen = choose_engine(engine, len(planned), jobs, scheduler)
    if not planned:
        return chosen

    def finished(i: int, got) -> None:
        p = planned[i]
        p.rows, p.error, p.wall, p.stopped = got
        if say:
            say(_ran(p))

    if chosen == "inline":
        for i, p in enumerate(planned):
            finished(i, _run_one(p.spec, p.columns))
    elif chosen == "pool":
        _on_pool(planned, jobs, finished)
    else:
        _on_dask(planned, None if scheduler else jobs, scheduler, finished)
    return chosen


def _on_pool(planned: list[Planned], jobs: int, finished) -> None:
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(_run_one, p.spec, p.columns) for p in planned]
        for i, f in enumerate(futures):
            try:
                got = f.result()
            except Exception as err:  # noqa: BLE001 - a worker process died (the pool is broken): the case
                text = " ".join(f"{type(err).__name__}: {err}".split())   # fails, not the report
                got = {}, f"the run was lost with its worker process: {text}", 0.0, ""
            finished(i, got)


def _run_shipped(ssp, spec, columns: list[str]) -> tuple[dict, str, float]:
    """:func:`_run_one` on a Dask worker, the scene file found where :func:`~cranefmu.sweep.tasks.ship_ssp`
    put it on this worker."""
    return _run_one(replace(spec, ssp=ssp.local()), columns)


def _on_dask(planned: list[Planned], workers: int | None, scheduler: str | None, finished) -> None:
    from ..sweep.tasks import TaskLost, run_tasks, ship_ssp

    def ship(client) -> list[tuple]:
        shipped = {}
        for p in planned:   # a scene file once, however many cases run it
            if p.spec.ssp not in shipped:
                shipped[p.spec.ssp] = ship_ssp(client, Path(p.spec.ssp), p.scene.name)
        return [(shipped[p.spec.ssp], p.spec, p.columns) for p in planned]

    def done(i: int, got) -> None:
        finished(i, ({}, f"the run was {got.reason}", 0.0, "") if isinstance(got, TaskLost) else got)

    run_tasks(_run_shipped, [()] * len(planned), workers=workers, scheduler=scheduler, prepare=ship, done=done,
              name="cranefmu-check")


def _ran(p: Planned) -> str:
    state = f"failed: {p.error}" if p.error else f"stopped early: {p.stopped}" if p.stopped else "ran"
    return f"{p.case.experiment} / {p.case.name}: {state} ({p.wall:.1f} s)"


def judge_all(planned: list[Planned]) -> list[Verdict]:
    """One verdict per assertion of every case (a failed run fails its assertions, with the reason)."""
    found: dict[tuple[str, str], object] = {}   # (experiment file, "case.assertion") -> what it measured
    for p in planned:
        for a in p.case.assertions:
            found[(str(p.case.file), f"{p.case.name}.{a.name}")] = _measure(p, a)
    out = []
    for p in planned:
        c = p.case
        out += stop_verdicts(p)
        results = {name: got for (file, name), got in found.items() if file == str(c.file) and isinstance(got, float)}
        for a in c.assertions:
            got = found[(str(c.file), f"{c.name}.{a.name}")]
            unit = "" if a.expression else (measured_unit(a, (p.scene.units or {}).get(a.column)) or "")
            if isinstance(got, str):
                out.append(Verdict(c.experiment, c.name, a.name, a.column, float("nan"), "", float("-inf"), False,
                                   note=got, source=a.source, unit=unit))
                continue
            try:
                value, limit, margin, t = judge(a, got, {**results, **p.values})
            except CraneFmuError as err:
                out.append(Verdict(c.experiment, c.name, a.name, a.column, float("nan"), "", float("-inf"), False,
                                   note=str(err), source=a.source, unit=unit))
                continue
            out.append(Verdict(c.experiment, c.name, a.name, a.column, value, limit, margin, margin >= 0, t,
                               source=a.source, unit=unit))
    return out


def early_stop(p: Planned) -> str:
    """Why the case's run ended before its stop time ('' if it ran to the end): a stop condition
    (tipping, a lifted load, ...), or rows that end early."""
    if p.stopped:
        return p.stopped
    end = p.end_time
    step = float(getattr(p.spec.settings, "step_size", 0.0) or 0.0)
    if end is not None and end < p.stop_time - max(0.5 * step, 1e-9 * max(1.0, p.stop_time)):
        return f"the rows end at t = {end:.9g} s"
    return ""


def stop_verdicts(p: Planned) -> list[Verdict]:
    """The verdict of the case's ``expect_stop`` ([] without one): its run must stop early, for a reason
    naming the expected text, inside the expected window."""
    c, expect = p.case, p.case.expect_stop
    if expect is None:
        return []
    stop = early_stop(p)
    t = p.end_time
    window = f"stop on {expect.reason!r} in [{expect.after:g}, {expect.before:g}] s"
    if p.error:
        note = p.error
    elif not stop:
        note = f"the run reached its stop time {p.stop_time:g} s without stopping"
    elif expect.reason not in stop:
        note = f"it stopped for another reason: {stop}"
    elif t is None or not expect.after - 1e-12 <= t <= expect.before + 1e-12:
        note = f"it stopped at t = {t:.6g} s, outside the window" if t is not None else "no rows"
    else:
        return [Verdict(c.experiment, c.name, "expect_stop", expect.reason, t, window, min(t - expect.after,
                        expect.before - t), True, t, source=expect.where, unit="s")]
    return [Verdict(c.experiment, c.name, "expect_stop", expect.reason, t if t is not None else float("nan"), window,
                    float("-inf"), False, t, note=note, source=expect.where, unit="s")]


def _measure(p: Planned, a):
    """What the assertion measures in the case's rows, or the text of why there is nothing."""
    if p.error:   # a failed run fails every assertion of its case
        return p.error
    stop = early_stop(p)
    if stop and p.case.expect_stop is None:   # a run that ended early passes nothing (issue 37)
        return (f"the run stopped before its stop time {p.stop_time:g} s ({stop}); "
                "give expect_stop if that stop is what the experiment tests")
    if not p.rows or not columns_of(a, p.scene) <= set(p.rows):
        return f"no rows of {a.column}"
    t = p.rows["time"]
    try:
        y = evaluate(a.column, {**p.values, **p.rows}, vector=True) if a.expression else p.rows[a.column]
        if np.ndim(y) == 0:
            y = np.full(len(t), float(y))
        got = measured(a, t, y, p.values)
    except (ValueError, CraneFmuError) as err:
        return str(err)
    return got


def _check_events(case: Case, scene: SceneInterface, values: dict) -> None:
    """Refuse, before the run, an event condition naming what is neither a result column nor a parameter."""
    from .events import Trigger

    found = [(c.when, c.keys.get("when", c.where)) for c in case.commands if c.when is not None]
    if case.emergency_stop is not None:
        found.append((case.emergency_stop[0], case.emergency_stop[2]))
    for condition, where in found:
        try:
            Trigger(condition, values).watch(list(scene.columns))
        except CraneFmuError as err:
            raise ExperimentError(f"{where}: {err}") from None


def _check_times(case: Case, start: float, stop: float, values: dict) -> None:
    """Refuse, before the run, what cannot be judged in its rows: an ``at`` or a ``during`` window outside
    [start, stop], an ``expect_stop`` window past the stop, ``min > max``, a shaper whose delay exceeds the
    run (one line FILE:LINE: key: ...)."""
    tol = 1e-9 * max(1.0, abs(stop))
    for a in case.assertions:
        if a.when == "at" and not start - tol <= a.at <= stop + tol:
            raise ExperimentError(f"{a.keys.get('at', a.where)}: at = {a.at:g} s is outside the run "
                                  f"({start:g} to {stop:g} s)")
        if a.when == "during" and (a.during[0] < start - tol or a.during[1] > stop + tol):
            raise ExperimentError(f"{a.keys.get('during', a.where)}: during = [{a.during[0]:g}, {a.during[1]:g}] s "
                                  f"is not inside the run ({start:g} to {stop:g} s)")
        if a.min is not None and a.max is not None:
            try:
                lo, hi = evaluate(a.min, values), evaluate(a.max, values)
            except CraneFmuError:   # a limit naming another case's result: judged after the runs
                continue
            if lo > hi:
                raise ExperimentError(f"{a.keys.get('min', a.where)}: min = {lo:g} is above max = {hi:g}: no value "
                                      "can pass")
    expect = case.expect_stop
    if expect is not None and expect.after > stop + tol:
        raise ExperimentError(f"{expect.where}: expect_stop: during = [{expect.after:g}, {expect.before:g}] s "
                              f"begins after the run's stop time {stop:g} s")
    for c in case.commands:
        if c.shaper and c.frequency is not None:
            f = evaluate(c.frequency, values)
            if not f > 0 or 0.5 / f > stop - start:
                raise ExperimentError(f"{c.keys.get('frequency', c.where)}: frequency = {f:g} Hz is not allowed: "
                                      f"the shaper delays the move by half a period, {0.5 / f if f > 0 else math.inf:g} s, "
                                      f"more than the run's {stop - start:g} s (a mode the run cannot show)")


def experiment_spec(path: Path, case_name: str | None, overrides: dict, parameters: dict, output, isolate: bool):
    """(RunSpec, Planned) of one case of one experiment file, for ``cranefmu run FILE.toml``:
    the command line's settings and ``--set`` over the file's."""
    cases = load(path)
    if case_name is None and len(cases) > 1:
        raise ExperimentError(f"{path}: has cases {', '.join(c.name for c in cases)}: give --case NAME "
                              "(cranefmu check runs them all)")
    chosen = [c for c in cases if case_name is None or c.name == case_name]
    if not chosen:
        raise ExperimentError(f"{path}: --case {case_name!r}: no such case; one of {', '.join(c.name for c in cases)}")
    case = chosen[0]
    case = replace(case, parameters={**case.parameters, **parameters})
    planned = prepare_case(case, {f"{c.name}.{a.name}" for c in cases for a in c.assertions}, overrides)
    spec = replace(planned.spec, output=Path(output) if output else None, isolate=isolate)
    return spec, planned


def prepare_case(case: Case, results: set[str], overrides: dict) -> Planned:
    """``case`` checked against its scene and resolved; ``results``: the names ``case.assertion`` of
    its experiment; ``overrides``: run settings over the case's (no progress bar unless asked)."""
    from ..master.runspec import resolve

    from .crane_commands import bind

    case = bind(set_in_declared_units(case))
    if overrides.get("fmus") is not None:   # the kind of FMU picks the scene file its checks read
        case = replace(case, settings={**case.settings, "fmus": overrides["fmus"]})
    scene = check(case, results)
    values = scene.parameter_values(case.parameter_set, case.parameters)
    settings = {"progress": False, **case.settings, **overrides}
    try:
        spec = resolve(str(scene.ssp), parameter_set=case.parameter_set, parameters=case.parameters,
                       commands=commands_of(case.commands, values, case.emergency_stop), **settings)
    except ExperimentError:
        raise
    except CraneFmuError as err:
        text = str(err)
        key = next((k for k in case.settings if text.startswith(f"{k} ") or f" {k} =" in text), None)
        raise ExperimentError(f"{case.keys.get(key, case.where) if key else case.where}: {text}") from None
    _check_times(case, float(spec.settings.start_time), float(spec.settings.stop_time), values)
    _check_events(case, scene, values)
    if not case.assertions and case.expect_stop is None:
        raise ExperimentError(f"{case.where}: case {case.name} asserts nothing: give [[assert]] tables or "
                              "expect_stop (a run with nothing asserted cannot pass)")
    return Planned(case, spec, scene, values, sorted(set().union(*(columns_of(a, scene) for a in case.assertions))))
