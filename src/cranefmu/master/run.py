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
import math
import tempfile
import time as clock
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from .algorithm_table import make_algorithm
from .bond_inference import scene_bonds
from .coupled import Coupling
from .divergence import ValueCheck, Watch
from ..errors import CraneFmuError, SettingsError, SimulationError
from .extracted import extracted_scene, fresh_fmu_dirs
from .initialization import initialize
from .interrupt import Interrupt, RunInterrupted, signal_name
from .loop import Sampler, march
from .output_file import OutputFile
from .process import discard, forget_extracted
from .power_bonds import BondMonitor, resolve as resolve_bonds
from .progress import Progress
from .results import Recorder
from .scene_names import resolve_scene
from .runspec import RunSpec, resolve
from .settings import ALGORITHMS, Settings, describe
from .step_control import ESTIMATES, make_step_control
from .stop_conditions import StopWatch
from .threads import one_thread
from .system import RunStats

__all__ = ["run", "simulate", "preview", "execute", "build_execution", "resolve", "RunSpec", "RunResult", "RunStats", "Settings",
           "ALGORITHMS", "RunInterrupted"]


@dataclass
class RunResult:
    result: np.ndarray           # the rows kept in memory (empty with keep=False)
    stats: RunStats
    output: Path | None          # the CSV holding the rows, if one was asked for
    scene: str
    settings: Settings | None = None
    rows: int = 0                # rows recorded (also those not kept in memory)
    end_time: float = math.nan   # simulated time of the last row [s]
    warnings: list[str] = field(default_factory=list)   # what the run found suspicious (also on stderr)
    spec: RunSpec | None = None  # the request run: settings with where each came from


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


def preview(scene: str | Path) -> ScenePreview:
    """Columns (in the order of a run's result) and units of a scene, read without instantiating it."""
    from .extracted import fmu_dir
    from .fmu import FmuComponent

    ssp = resolve_scene(scene)
    workdir, loaded = extracted_scene(ssp)
    reals, flags, units, variables, mds = [], [], {}, {}, {}
    for c in loaded.components:
        md = mds[c.name] = FmuComponent(c.name, c.fmu, fmu_dir(workdir, c.name)).md
        variables[c.name] = {v.name for v in md.modelVariables}
        for v in md.modelVariables:
            if v.causality != "output":
                continue
            name = f"{c.name}.{v.name}"
            (reals if v.type == "Real" else flags).append(name)
            unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
            if unit:
                units[name] = unit
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
    settings = spec.settings
    system = recorder = progress = fmu_dirs = None
    wall0 = clock.perf_counter()
    try:
        workdir, loaded = extracted_scene(spec.ssp)
        fmu_dirs = Path(tempfile.mkdtemp(prefix="run_", dir=workdir))
        fresh_fmu_dirs(workdir, loaded, fmu_dirs)   # never instantiate twice from one directory
        execution = build_execution(spec, loaded, fmu_dirs, claim)
        system, bonds, recorder = execution.system, execution.bonds, execution.recorder
        starts = spec.overrides if system.commands is None else \
            {**spec.overrides, **system.commands.start_values(settings.start_time)}
        system.stats.init_iterations = initialize(system, settings.start_time, starts, settings.init_tolerance)
        progress = Progress(settings.start_time, settings.stop_time, settings.progress)
        if interrupt.signum is None:
            _loop(system, settings, recorder, bonds, progress, execution.watch, execution.stopper,
                  (interrupt, *observers))
        system.stats.wall_time = clock.perf_counter() - wall0
        system.stats.master_time = system.stats.wall_time - sum(system.stats.fmu_time.values())
        system.stats.bond_energy = bonds.totals()
        system.stats.bond_carried = bonds.carried_totals()
        recorder.close()
        where = _finish(claim, recorder)
        result = RunResult(recorder.result(), system.stats, where, loaded.name, settings, recorder.count,
                           recorder.last_time, bonds.warnings(), spec)
    except CraneFmuError as err:
        where = _finish(claim, recorder)
        if recorder is not None and isinstance(err, SimulationError) and recorder.count:
            if recorder.write_error:
                raise SimulationError(str(err), recorder.result(), where) from None
            kept = f" The {recorder.count} rows computed so far are in {where}." if where \
                else f" {recorder.count} rows were computed before the failure."
            raise SimulationError(str(err) + kept, recorder.result(), where) from None
        raise
    finally:
        if progress is not None:
            progress.close()
        if system is not None:
            system.free()
        if fmu_dirs is not None:
            forget_extracted(fmu_dirs)
            discard(fmu_dirs)
        _finish(claim, recorder)
    if interrupt.signum is not None:
        raise RunInterrupted(_interrupted(interrupt.signum, result), result.result, where, interrupt.signum)
    return result


@dataclass
class Execution:
    """One run's parts, built from its :class:`RunSpec` by :func:`build_execution`: the coupled system,
    its power bonds and the observers the settings ask for (recorder, instability watch, stop watch)."""

    system: Coupling
    bonds: BondMonitor
    recorder: Recorder
    watch: Watch | None
    stopper: StopWatch | None


def build_execution(spec: RunSpec, loaded, fmu_dirs: Path, claim: OutputFile | None = None) -> Execution:
    """The parts of the run ``spec`` on the scene ``loaded`` (as read from ``spec.ssp``), its FMUs
    instantiated from ``fmu_dirs``, its rows into ``claim``; the system is freed if a part is refused."""
    settings = spec.settings
    system = Coupling(loaded, fmu_dirs, settings.extrapolation)
    try:
        if spec.commands:
            from .commands import CommandFeed

            system.commands = CommandFeed(system, spec.commands)
        bonds = BondMonitor(system, resolve_bonds(system, scene_bonds(loaded, {c.name: c.md for c in system.comps})[0]))
        _check_capabilities(system, settings, bonds)
        watch = Watch(system, bonds, settings.adaptive, _solved(system, settings)) if settings.instability_alarm else None
        conditions = loaded.stop_conditions if settings.stop_when is None \
            else {v: "" for v in settings.stop_when}
        stopper = StopWatch(system.columns + bonds.columns, conditions) if conditions else None
        recorder = Recorder(system.columns + bonds.columns, claim.fd if claim else None,
                            str(claim.target) if claim else "", keep=spec.keep,
                            path=str(claim.part or claim.target) if claim else "")
    except BaseException:
        system.free()
        raise
    return Execution(system, bonds, recorder, watch, stopper)


def _interrupted(signum: int, result: RunResult) -> str:
    """What an interrupted run left: how far it got and where its rows are."""
    if not result.rows:
        return f"interrupted by {signal_name(signum)} before the first step: no rows were written"
    where = f"in {result.output}" if result.output else "in memory only (no output file)"
    return (f"interrupted by {signal_name(signum)} at t = {result.end_time:.9g} s: the {result.rows} rows "
            f"computed so far are {where}")


def _finish(claim: OutputFile | None, recorder: Recorder | None) -> Path | None:
    """Close the CSV and put it in place (again on later calls): where its rows are, or None."""
    if recorder is not None and not recorder.write_error:
        try:
            recorder.close()
        except SimulationError:
            pass   # the caller reports the first failure
    if claim is None:
        return None
    return claim.finish(recorder.written if recorder is not None else 0)


def _check_capabilities(system: Coupling, s: Settings, bonds: BondMonitor) -> None:
    if s.adaptive or s.algorithm == "iterative":
        cannot = [c.name for c in system.comps if not c.can_get_state]
        if cannot:
            what = "adaptive" if s.adaptive else "algorithm = 'iterative'"
            raise SettingsError(f"{what} is not allowed for this scene: component(s) {', '.join(cannot)} cannot save "
                                "and restore their state (canGetAndSetFMUstate is false); use a fixed step with "
                                "jacobi or gauss-seidel")
    if s.adaptive:   # before initialization, not when the loop builds the controller
        ESTIMATES[s.step_control].refuse(bonds)


def _solved(c: Coupling, s: Settings) -> set[int]:
    """Components of the run's implicit group (none without one)."""
    if not s.implicit or s.algorithm != "jacobi":
        return set()
    from .implicit_group import group_members

    return set(group_members(c.components, c.bonds(), list(s.implicit), c.scene_name))


def _loop(coupling: Coupling, s: Settings, recorder: Recorder, bonds: BondMonitor, progress: Progress,
          watch: Watch | None, stopper: StopWatch | None = None, observers: tuple = ()) -> None:
    """Step from start to stop (:func:`.loop.march`): the algorithm and its start-up, the step
    controller and the observers the settings ask for (and ``observers``, e.g. an
    :class:`~.interrupt.Interrupt`), in the order they see each row."""
    algorithm = make_algorithm(coupling, s)
    control = make_step_control(coupling, s, bonds)
    everyone = [recorder, ValueCheck(coupling, bonds, s.energy_alarm), watch, stopper, *observers, progress]
    coupling.stats.stopped = march(coupling, algorithm, control, Sampler(coupling, bonds),
                                 [o for o in everyone if o is not None], s.start_time)


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
