"""Run a scene: load, initialize, step with an algorithm under step control, observe; nothing lost on failure.

The pieces: :mod:`.system` (the FMUs and the values between them), :mod:`.initialization`,
:mod:`.algorithms` (Jacobi, Gauss-Seidel, iterative), :mod:`.step_control` (error estimate, PI
controller), observers that never steer (:mod:`.results` recorder, :mod:`.power_bonds` monitor,
:mod:`.progress`) and one that stops (:mod:`.interrupt`).  A run executes in the caller's process
(as fmpy's do); ``isolate=True`` runs it in a worker process (:mod:`.isolated`).  Settings are
defined once in :mod:`.settings`; a run request is resolved once into a :class:`.runspec.RunSpec`
(:func:`.runspec.resolve`), which every path below takes.
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from .bond_inference import scene_bonds
from ..errors import SettingsError
from .extracted import extracted_scene
from .interrupt import Interrupt, RunInterrupted, signal_name
from .output_file import OutputFile
from .scene_names import resolve_scene
from .runspec import RunSpec, resolve
from .execution import Execution, RunResult, build_execution
from .loop import Observer
from .commands import Command, Source
from .settings import ALGORITHMS, Settings, describe
from .threads import one_thread
from .system import RunStats
from .results import read_csv

__all__ = ["run", "simulate", "preview", "execute", "build_execution", "resolve", "RunSpec", "RunResult", "RunStats", "Settings",
           "Execution", "Observer", "Command", "Source",
           "ALGORITHMS", "RunInterrupted", "read_csv"]


@dataclass
class ScenePreview:
    """What a scene's run will record, known before it starts: result columns and their units."""

    path: Path
    name: str
    stop_time: float | None
    columns: list[str]
    units: dict[str, str]
    variables: dict[str, set[str]]   # component -> the names of all its variables
    parameter_sets: tuple[str, ...]  # "default" first
    settings: dict[str, object]      # the scene's stored run settings


def preview(scene: str | Path, fmus: str | None = None) -> ScenePreview:
    """Columns (in the order of a run's result) and units of a scene (a name resolved with FMUs of kind
    ``fmus``, see :mod:`.scene_names`), read without instantiating it."""
    from .extracted import fmu_dir
    from .fmu import FmuComponent

    ssp = resolve_scene(scene, fmus)
    workdir, loaded = extracted_scene(ssp)
    reals, flags, units, variables, mds = [], [], {}, {}, {}
    for c in loaded.components:
        md = mds[c.name] = FmuComponent(c.name, c.fmu, fmu_dir(workdir, c.name)).md
        variables[c.name] = {v.name for v in md.modelVariables}
        discrete = []
        for v in md.modelVariables:
            if v.causality != "output":
                continue
            name = f"{c.name}.{v.name}"
            if v.type == "Real":
                reals.append(name)
            elif v.type in ("Integer", "Enumeration", "Boolean"):
                discrete.append((v.type == "Boolean", name))   # as the run records them (coupled.py)
            unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
            if unit:
                units[name] = unit
        flags += [name for _, name in sorted(discrete, key=lambda x: x[0])]
    bonds = [f"bond.{n}.{e}" for n, _ in scene_bonds(loaded, mds)[0] for e in ("dE", "E")]
    units.update({b: "J" for b in bonds})
    return ScenePreview(ssp, loaded.name, loaded.stop_time, reals + flags + bonds, units, variables,
                        ("default", *loaded.parameter_sets), dict(loaded.settings))


def run(scene: str | Path | RunSpec, *, parameter_set: str | None = None, parameters: dict | None = None,
        output: str | Path | None = None, keep: bool = True, isolate: bool = False, observers: tuple = (),
        **settings) -> RunResult:
    """Run a scene (name, .ssp path, or a :class:`RunSpec` from :func:`resolve`, then with no other
    argument) and return its results and statistics.

    parameter_set: a .ssv of the scene; parameters: {"comp.var": value} overrides; output: CSV
    written as the run goes (into ``output + '.part'``, renamed into place at the end; a second run
    on the same file refuses); keep: hold the rows in memory (the result array); isolate: run in
    a worker process (a crash inside an FMU then raises here instead of ending the caller);
    observers: more :class:`~.loop.Observer` objects that see every row (see :func:`execute`).
    A signal that stops the run (SIGINT, e.g. Ctrl-C or a notebook's interrupt) is handled
    between steps, never inside an FMU: the run is closed and :class:`RunInterrupted` (a
    KeyboardInterrupt) carries the rows so far.  Settings (keywords, see :class:`Settings`; one not
    given is the scene's stored setting if it has one, unless the run names another algorithm than
    the scene's, else the default below; see :mod:`.runspec`; ``cranefmu info`` shows a scene's):
{settings}
    Raises a :class:`~cranefmu.errors.CraneFmuError` subclass naming what is wrong.
    """
    if isinstance(scene, RunSpec):
        given = dict(settings, parameter_set=parameter_set, parameters=parameters, output=output)
        if any(v is not None for v in given.values()) or not keep or isolate:
            raise SettingsError("run(spec) takes no other argument: give them to resolve()")
        spec = scene
    else:
        spec = resolve(scene, parameter_set=parameter_set, parameters=parameters, output=output, keep=keep,
                       isolate=isolate, **settings)
    return execute(spec, observers)


def execute(spec: RunSpec, observers: tuple = ()) -> RunResult:
    """Run a resolved request: its output claimed first, then here or in a worker process.

    ``observers``: :class:`~.loop.Observer` objects (``simulation_initialized`` and ``step_complete``)
    that see every row after the run's own (recorder, checks, stop conditions), e.g. to time the
    stepping loop; they run in this process, so not with ``spec.isolate``."""
    if observers and spec.isolate:
        raise SettingsError("observers are not allowed with isolate=True: they run in the caller's process")
    claim = OutputFile.claim(spec.output, spec.ssp) if spec.output is not None else None  # before anything runs
    try:
        if spec.isolate:
            from .isolated import run_isolated

            result = run_isolated(spec, claim)
        else:
            result = _run_here(spec, claim, observers=tuple(observers))
    finally:
        if claim is not None:
            claim.abandon()   # rows not yet in place (an early interrupt, a failed rename): again, or removed
            claim.release()
    if claim is not None:
        claim.check_placed(result.result)   # the target could not be replaced: one error naming both files
    return result


def _run_here(spec: RunSpec, claim: OutputFile | None, interrupt: Interrupt | None = None,
              observers: tuple = ()) -> RunResult:
    """The run in this process: a signal of ``interrupt`` (default SIGINT, main thread) stops it between steps."""
    interrupt = interrupt or Interrupt()
    with interrupt, one_thread():
        return _run_observed(spec, claim, interrupt, observers)


def _run_observed(spec: RunSpec, claim: OutputFile | None, interrupt: Interrupt, observers: tuple = ()) -> RunResult:
    """The run as one :class:`~.execution.Execution` stepped to its end (unless a signal came while it loaded)."""
    from .execution import Execution

    execution = Execution(spec, claim, observers, interrupt)
    try:
        if interrupt.signum is None:
            execution._to_end()
        result = execution.finish()
    finally:
        execution.close()
    if interrupt.signum is not None:
        raise RunInterrupted(_interrupted(interrupt.signum, result), result.result, result.output, interrupt.signum)
    return result


def _interrupted(signum: int, result: RunResult) -> str:
    """What an interrupted run left: how far it got and where its rows are."""
    if not result.rows:
        return f"interrupted by {signal_name(signum)} before the first step: no rows were written"
    where = f"in {result.output}" if result.output else "in memory only (no output file)"
    return (f"interrupted by {signal_name(signum)} at t = {result.end_time:.9g} s: the {result.rows} rows "
            f"computed so far are {where}")


def simulate(scene: str | Path, **options) -> np.ndarray:
    """Run a scene (name or path to an .ssp) and return a structured array with fields ``time``,
    ``component.variable`` for every output and ``bond.<name>.dE``/``.E`` per power bond.
    Keywords as :func:`run` (parameter_set, parameters, output, isolate and every setting).
    Raises a :class:`~cranefmu.errors.CraneFmuError` subclass naming what is wrong.
    """
    return run(scene, **options).result


def _signature(fn, drop: tuple[str, ...] = ()) -> inspect.Signature:
    """``fn``'s signature with every setting as a keyword (default from :class:`Settings`)."""
    sig = inspect.signature(fn)
    params = [p for p in sig.parameters.values() if p.kind is not p.VAR_KEYWORD and p.name not in drop]
    names = {p.name for p in params}
    if fn is simulate:
        params += [p for p in inspect.signature(run).parameters.values() if p.name not in names and p.name != "scene"]
    else:
        params += [inspect.Parameter(f.name, inspect.Parameter.KEYWORD_ONLY, default=f.default, annotation=f.type)
                   for f in fields(Settings)]
    return sig.replace(parameters=params)


run.__doc__ = run.__doc__.replace("{settings}", describe())
run.__signature__ = _signature(run)
simulate.__signature__ = _signature(simulate)

