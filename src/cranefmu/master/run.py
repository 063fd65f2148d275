"""Run a scene: load, initialize, step with an algorithm under step control, observe; nothing lost on failure.

The pieces: :mod:`.system` (the FMUs and the values between them), :mod:`.initialization`,
:mod:`.algorithms` (Jacobi, Gauss-Seidel, iterative), :mod:`.step_control` (error estimate, PI
controller), observers that never steer (:mod:`.results` recorder, :mod:`.power_bonds` monitor,
:mod:`.progress`) and one that stops (:mod:`.interrupt`).  A run executes in the caller's process
(as fmpy's do); ``isolate=True`` runs it in a worker process (:mod:`.isolated`).  Settings are
defined once in :mod:`.settings`.
"""
from __future__ import annotations

import inspect
import math
import tempfile
import time as clock
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from .algorithms import GaussSeidel, Iterative, Jacobi
from .divergence import Watch
from ..errors import CraneFmuError, ParameterSetError, SceneError, SettingsError, SimulationError
from .extracted import discard, extracted_scene, fresh_fmu_dirs
from .fmu import forget_extracted
from .initialization import initialize
from .interrupt import Interrupt, RunInterrupted, signal_name
from .output_file import OutputFile
from .power_bonds import BondMonitor, read_bonds, resolve
from .progress import Progress
from .results import Recorder
from .scene import Scene
from .settings import ALGORITHMS, STEP_CONTROLS, Settings, describe
from .step_control import PIController, coupling_error, ecco_error
from .stop_conditions import StopWatch, read_stop_conditions
from .system import CoSystem, RunStats
from .waveform import WaveformIterative

__all__ = ["run", "simulate", "preview", "RunResult", "RunStats", "Settings", "ALGORITHMS", "RunInterrupted"]


@dataclass
class RunResult:
    result: np.ndarray           # the rows kept in memory (empty with keep=False)
    stats: RunStats
    output: Path | None          # the CSV holding the rows, if one was asked for
    scene: str
    settings: Settings | None = None
    rows: int = 0                # rows recorded (also those not kept in memory)
    end_time: float = math.nan   # simulated time of the last row [s]


def resolve_scene(scene: str | Path) -> Path:
    """An .ssp path as given, or a scene name under ssp/ (built first if missing or stale)."""
    path = Path(scene)
    if path.suffix == ".ssp":
        if not path.is_file():
            raise SceneError(f"scene file {path} does not exist")
        return path
    from .. import build as b

    names = [d.name for d in b.scene_dirs()]
    if str(scene) not in names:
        raise SceneError(f"scene {str(scene)!r} is unknown: one of {', '.join(names)} or a path to an .ssp file")
    b.build(verbose=False, only=[str(scene)])
    return b.SSP_DIR / f"{scene}.ssp"


@dataclass
class ScenePreview:
    """What a scene's run will record, known before it starts: result columns and their units."""

    path: Path
    name: str
    stop_time: float | None
    columns: list[str]
    units: dict[str, str]


def preview(scene: str | Path) -> ScenePreview:
    """Columns (in the order of a run's result) and units of a scene, read without instantiating it."""
    from .extracted import fmu_dir
    from .fmu import FmuComponent

    ssp = resolve_scene(scene)
    workdir, loaded = extracted_scene(ssp)
    reals, flags, units = [], [], {}
    for c in loaded.components:
        md = FmuComponent(c.name, c.fmu, fmu_dir(workdir, c.name)).md
        for v in md.modelVariables:
            if v.causality != "output":
                continue
            name = f"{c.name}.{v.name}"
            (reals if v.type == "Real" else flags).append(name)
            unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
            if unit:
                units[name] = unit
    bonds = [f"bond.{n}.{e}" for n, _ in read_bonds(workdir / "SystemStructure.ssd") for e in ("dE", "E")]
    units.update({b: "J" for b in bonds})
    return ScenePreview(ssp, loaded.name, loaded.stop_time, reals + flags + bonds, units)


def _overrides(scene: Scene, parameter_set: str | None, parameters: dict | None) -> dict[tuple[str, str], object]:
    values: dict[str, object] = dict(scene.parameters)
    if parameter_set is not None and parameter_set != "default":
        if parameter_set not in scene.parameter_sets:
            raise ParameterSetError(f"parameter set {parameter_set!r} is not in scene {scene.name}: one of "
                                    f"{', '.join(['default', *scene.parameter_sets])}")
        values.update(scene.parameter_sets[parameter_set])
    values.update(parameters or {})
    names = {c.name for c in scene.components}
    out = {}
    for key, value in values.items():
        comp, _, var = str(key).partition(".")
        if comp not in names or not var:
            raise ParameterSetError(f"parameter {key!r} must be 'component.variable' with a component of "
                                    f"{scene.name}: {', '.join(sorted(names))}")
        out[(comp, var)] = value
    return out


def run(scene: str | Path, *, parameter_set: str | None = None, parameters: dict | None = None,
        output: str | Path | None = None, keep: bool = True, isolate: bool = False, **settings) -> RunResult:
    """Run a scene (name or .ssp path) and return its results and statistics.

    parameter_set: a .ssv of the scene; parameters: {"comp.var": value} overrides; output: CSV
    written as the run goes (into ``output + '.part'``, renamed into place at the end; a second run
    on the same file refuses); keep: hold the rows in memory (the result array); isolate: run in
    a worker process (a crash inside an FMU then raises here instead of ending the caller).
    A signal that stops the run (SIGINT, e.g. Ctrl-C or a notebook's interrupt) is handled
    between steps, never inside an FMU: the run is closed and :class:`RunInterrupted` (a
    KeyboardInterrupt) carries the rows so far.  Settings (keywords, see :class:`Settings`):
{settings}
    Raises a :class:`~cranefmu.errors.CraneFmuError` subclass naming what is wrong.
    """
    options = Settings.from_options(**settings)
    ssp = resolve_scene(scene)  # build in the caller, once
    claim = OutputFile.claim(output, ssp) if output is not None else None  # before anything runs
    try:
        if isolate:
            from .isolated import run_isolated

            return run_isolated(ssp, options, parameter_set, parameters, claim, keep)
        return _run_here(ssp, options, parameter_set, parameters, claim, keep)
    finally:
        if claim is not None:
            claim.release()


def _run_here(ssp: Path, settings: Settings, parameter_set: str | None, parameters: dict | None,
              claim: OutputFile | None, keep: bool, interrupt: Interrupt | None = None) -> RunResult:
    """The run in this process: a signal of ``interrupt`` (default SIGINT, main thread) stops it between steps."""
    interrupt = interrupt or Interrupt()
    with interrupt:
        return _run_observed(ssp, settings, parameter_set, parameters, claim, keep, interrupt)


def _run_observed(ssp: Path, settings: Settings, parameter_set: str | None, parameters: dict | None,
                  claim: OutputFile | None, keep: bool, interrupt: Interrupt) -> RunResult:
    system = recorder = progress = fmu_dirs = None
    wall0 = clock.perf_counter()
    try:
        workdir, loaded = extracted_scene(ssp)
        fmu_dirs = Path(tempfile.mkdtemp(prefix="run_", dir=workdir))
        fresh_fmu_dirs(workdir, loaded, fmu_dirs)   # never instantiate twice from one directory
        if settings.stop_time is None:
            settings.stop_time = loaded.stop_time or 10.0
        settings.check()
        overrides = _overrides(loaded, parameter_set, parameters)
        system = CoSystem(loaded, fmu_dirs, settings.extrapolation)
        _refuse_connected_inputs(system, parameters)
        bonds = BondMonitor(system, resolve(system, read_bonds(workdir / "SystemStructure.ssd")))
        _check_capabilities(system, settings, bonds)
        watch = Watch(system, bonds, settings.adaptive) if settings.instability_alarm else None
        recorder = Recorder(system.columns + bonds.columns, claim.fd if claim else None,
                            str(claim.target) if claim else "", keep=keep,
                            path=str(claim.part or claim.target) if claim else "")
        conditions = read_stop_conditions(workdir / "SystemStructure.ssd") if settings.stop_when is None \
            else {v: "" for v in settings.stop_when}
        stopper = StopWatch(system.columns + bonds.columns, conditions) if conditions else None
        system.stats.init_iterations = initialize(system, settings.start_time, overrides, settings.init_tolerance)
        progress = Progress(settings.start_time, settings.stop_time, settings.progress)
        if interrupt.signum is None:
            _loop(system, settings, recorder, bonds, progress, watch, stopper, (interrupt,))
        system.stats.wall_time = clock.perf_counter() - wall0
        system.stats.master_time = system.stats.wall_time - sum(system.stats.fmu_time.values())
        system.stats.bond_energy = bonds.totals()
        recorder.close()
        where = _finish(claim, recorder)
        result = RunResult(recorder.result(), system.stats, where, loaded.name, settings, recorder.count,
                           recorder.last_time)
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


def _refuse_connected_inputs(system: CoSystem, parameters: dict | None) -> None:
    """An override of a connected input is overwritten at every step: refuse it by name."""
    driven = {f"{c.dst}.{c.dst_var}": f"{c.src}.{c.src_var}" for c in system.scene.connections}
    for key in parameters or {}:
        if str(key) in driven:
            source = driven[str(key)]
            raise ParameterSetError(f"{key} is not allowed as a parameter: it is an input connected to {source}, "
                                    f"which overwrites it at every step; set a parameter of "
                                    f"{source.partition('.')[0]} instead")


def _check_capabilities(system: CoSystem, s: Settings, bonds: BondMonitor) -> None:
    if s.adaptive or s.algorithm == "iterative":
        cannot = [c.name for c in system.comps if not c.can_get_state]
        if cannot:
            what = "adaptive" if s.adaptive else "algorithm = 'iterative'"
            raise SettingsError(f"{what} is not allowed for this scene: component(s) {', '.join(cannot)} cannot save "
                                "and restore their state (canGetAndSetFMUstate is false); use a fixed step with "
                                "jacobi or gauss-seidel")
    if s.adaptive and s.step_control == "ecco" and not bonds.bonds:
        raise SettingsError("step_control = 'ecco' is not allowed for this scene: it declares no power bonds "
                            "(see README, 'Power bonds')")


def _algorithm(system: CoSystem, s: Settings):
    if s.algorithm == "jacobi":
        return Jacobi(system)
    if s.algorithm == "gauss-seidel":
        return GaussSeidel(system, s.order)
    if s.substeps > 1:
        return WaveformIterative(system, s.substeps, tolerance=s.coupling_tolerance,
                                 max_iterations=s.max_iterations, accelerator=s.accelerator)
    return Iterative(system, degree=max(1, s.extrapolation), tolerance=s.coupling_tolerance,
                     max_iterations=s.max_iterations, accelerator=s.accelerator)


def _loop(system: CoSystem, s: Settings, recorder: Recorder, bonds: BondMonitor, progress: Progress,
          watch: Watch | None, stopper: StopWatch | None = None, observers: tuple = ()) -> None:
    """Step from start to stop: fixed steps, or adaptive with rejection, rollback and event location.

    Start-up: an explicit scheme of extrapolation order p takes its first p steps with iterative
    coupling (degree p), so the extrapolation starts from exact past values and the order is kept;
    FMUs that cannot roll back start from a past at rest instead.
    """
    stats = system.stats
    algo = _algorithm(system, s)
    p = s.extrapolation
    startup = None
    if p > 0 and algo.name != "iterative":
        if system.can_rollback:
            startup = Iterative(system, degree=p, tolerance=min(s.coupling_tolerance, 1e-10),
                                max_iterations=max(s.max_iterations, 50))
        else:
            for g in system.links:
                t0, u0 = g.history[-1]
                g.history[:] = [(t0 - 2 * s.step_size, u0), (t0 - s.step_size, u0), (t0, u0)]
            system.exchange(s.start_time)
    t, stop = s.start_time, s.stop_time
    ecco = s.adaptive and s.step_control == "ecco"
    controller = PIController(p + 1 if not ecco else 2, s.h_min, s.h_max) if s.adaptive else None
    flags = system.flags() if s.adaptive else None
    row = _row(system, bonds, s.adaptive)
    recorder.record(t, row)
    if stopper is not None:
        stats.stopped = stopper.check(t, row) or ""
        if stats.stopped:
            return
    n_fixed = max(1, round((stop - t) / s.step_size))
    h = s.step_size
    locating = False
    n = 0
    while True:
        if s.adaptive:
            remaining = stop - t
            if remaining <= 1e-12 * max(1.0, abs(stop)):
                break
            if h >= remaining or remaining - h < 0.1 * h:
                h = remaining
        else:
            if n >= n_fixed:
                break
            t_next = stop if n == n_fixed - 1 else s.start_time + (n + 1) * s.step_size
            h = t_next - t
        use = startup if startup is not None and n < p else algo
        snap = system.save() if (s.adaptive or use.needs_snapshot) else None
        predicted = system.predicted(t, h) if (s.adaptive and not ecco) else None
        try:
            iterations = use.step(t, h, snap)
            err = 0.0
            if s.adaptive:
                new_flags = system.flags()
                event = new_flags != flags
                if event and h > s.h_min * (1 + 1e-9):
                    _reject(system, snap, stats)
                    h, locating = max(0.5 * h, s.h_min), True
                    continue
                if not ecco and use is algo:
                    err, worst = coupling_error(predicted, system.coupling_values(), system.scale, s.tolerance)
                    if err > 1.0 and h > s.h_min * (1 + 1e-9) and not locating:
                        _reject(system, snap, stats)
                        h = controller.rejected(h, err)
                        continue
                flags = new_flags
        finally:
            system.release(snap)
        t = t + h if s.adaptive else t_next
        n += 1
        stats.steps += 1
        stats.iterations += iterations
        stats.max_iterations = max(stats.max_iterations, iterations)
        stats.min_step = h if stats.steps == 1 else min(stats.min_step, h)
        stats.max_step = max(stats.max_step, h)
        if bonds.bonds:
            bonds.measure(h)
        row = _row(system, bonds, s.adaptive)
        recorder.record(t, row)   # the failing row too: it shows what went wrong
        _check(system, bonds, row, t, s)
        if watch is not None:
            alarm = watch.update(t, h)
            if alarm is not None:
                raise SimulationError(alarm)
        if stopper is not None:
            stats.stopped = stopper.check(t, row) or ""
            if stats.stopped:
                break
        if _stop_asked(observers, t, h, row, stats):
            break
        progress.update(t)
        if s.adaptive:
            if locating and event:      # the switch is located to min_step: restart small
                locating = False
                h = s.h_min
            elif not locating:
                if ecco:
                    err = ecco_error(bonds.residual, bonds.carried, s.tolerance, 1e-3 * s.tolerance)
                h = controller.accepted(h, err)


def _stop_asked(observers: tuple, t: float, h: float, row: np.ndarray, stats: RunStats) -> bool:
    """Ask each observer's ``step_complete``; the first reason given stops the run (``stats.stopped``)."""
    for observer in observers:
        reason = observer.step_complete(t, h, row)
        if reason:
            stats.stopped = reason
            return True
    return False


def _reject(system: CoSystem, snap, stats: RunStats) -> None:
    system.restore(snap)
    stats.rejections += 1


def _row(system: CoSystem, bonds: BondMonitor, adaptive: bool) -> np.ndarray:
    if not adaptive and system.flag_names:
        system.flags()   # the adaptive loop read them already
    values = system.outputs()
    return np.concatenate((values, bonds.row)) if bonds.bonds else values


def _check(system: CoSystem, bonds: BondMonitor, row: np.ndarray, t: float, s: Settings) -> None:
    """Stop on a non-finite value or a power bond over its energy alarm, naming what and where."""
    if not np.all(np.isfinite(row)):
        i = int(np.flatnonzero(~np.isfinite(row))[0])
        names = system.columns + bonds.columns
        what = (f"component {names[i].partition('.')[0]}, variable {names[i].partition('.')[2]}"
                if i < len(system.columns) else f"the energy residual of power bond {bonds.names[(i - len(system.columns)) // 2]}")
        big = np.abs(row[:len(system.columns)])
        j = int(np.argmax(np.where(np.isfinite(big), big, -1.0)))
        grown = f" ({names[j]} = {row[j]:.3g})" if i >= len(system.columns) else ""
        raise SimulationError(f"{what} became non-finite at t = {t:.9g} s{grown}: the coupling is unstable at this "
                              "step size. Try a smaller --step, --adaptive, or --algorithm iterative.")
    if s.energy_alarm is not None and bonds.bonds:
        k = int(np.argmax(bonds.total))
        if bonds.total[k] > s.energy_alarm:
            raise SimulationError(f"power bond {bonds.names[k]} has put {bonds.total[k]:.6g} J of coupling error into "
                                  f"the scene by t = {t:.9g} s (energy alarm {s.energy_alarm:g} J): the coupling is "
                                  "unstable or too coarse. Try a smaller --step, --adaptive, or --algorithm "
                                  "iterative.")


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
