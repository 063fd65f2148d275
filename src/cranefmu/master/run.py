"""Run a scene: load, initialize, step with an algorithm under step control, observe; nothing lost on failure.

The pieces: :mod:`.system` (the FMUs and the values between them), :mod:`.initialization`,
:mod:`.algorithms` (Jacobi, Gauss-Seidel, iterative), :mod:`.step_control` (error estimate, PI
controller), observers that never steer (:mod:`.results` recorder, :mod:`.power_bonds` monitor,
:mod:`.progress`).  Each run executes in a fresh child process (see :func:`run`).
"""
from __future__ import annotations

import math
import shutil
import tempfile
import time as clock
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .acceleration import ACCELERATORS
from .algorithms import GaussSeidel, Iterative, Jacobi
from .divergence import Watch
from ..errors import CraneFmuError, ParameterSetError, SettingsError, SimulationError
from .initialization import initialize
from .power_bonds import BondMonitor, resolve
from .progress import Progress
from .results import Recorder
from .scene import Scene, load_scene
from .scene_names import resolve_scene
from .step_control import PIController, coupling_error, ecco_error
from .stop_conditions import StopWatch
from .system import CoSystem, RunStats
from .waveform import WaveformIterative

ALGORITHMS = ("jacobi", "gauss-seidel", "iterative")
STEP_CONTROLS = ("extrapolation", "ecco")

__all__ = ["run", "simulate", "RunResult", "RunStats", "Settings", "ALGORITHMS"]


@dataclass
class RunResult:
    result: np.ndarray
    stats: RunStats
    output: Path | None
    scene: str


@dataclass
class Settings:
    """Every run setting (see :func:`run` for their meaning); checked by :meth:`check`."""

    stop_time: float | None = None
    step_size: float = 1e-3
    algorithm: str = "jacobi"
    extrapolation: int = 0
    start_time: float = 0.0
    adaptive: bool = False
    tolerance: float = 1e-3
    min_step: float | None = None
    max_step: float | None = None
    step_control: str = "extrapolation"
    coupling_tolerance: float = 1e-8
    max_iterations: int = 50
    accelerator: str = "iqn-ils"
    order: list[str] | None = None
    energy_alarm: float | None = None
    init_tolerance: float = 1e-10
    progress: bool | None = None
    substeps: int = 1
    instability_alarm: bool = True
    stop_when: list[str] | None = None

    def check(self) -> None:
        if not isinstance(self.instability_alarm, bool):
            raise SettingsError(f"instability_alarm = {self.instability_alarm!r} is not allowed: True or False")
        if self.stop_when is not None and (isinstance(self.stop_when, str) or
                                           not all(isinstance(v, str) for v in self.stop_when)):
            raise SettingsError(f"stop_when = {self.stop_when!r} is not allowed: a list of output names "
                                "'component.variable' (empty: run on)")
        for name in ("start_time", "stop_time", "step_size", "tolerance", "coupling_tolerance", "init_tolerance"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise SettingsError(f"{name} = {value!r} is not allowed: a finite number")
        if self.stop_time <= self.start_time:
            raise SettingsError(f"stop_time = {self.stop_time!r} is not allowed: must be > start_time = "
                                f"{self.start_time!r} s")
        span = self.stop_time - self.start_time
        if self.step_size <= 0:
            raise SettingsError(f"step_size = {self.step_size!r} is not allowed: must be > 0 s")
        if self.step_size > span:
            raise SettingsError(f"step_size = {self.step_size!r} is not allowed: must be <= stop_time - start_time "
                                f"= {span!r} s")
        if self.algorithm not in ALGORITHMS:
            raise SettingsError(f"algorithm = {self.algorithm!r} is not allowed: one of {', '.join(ALGORITHMS)}")
        if isinstance(self.extrapolation, bool) or self.extrapolation not in (0, 1, 2):
            raise SettingsError(f"extrapolation = {self.extrapolation!r} is not allowed: 0, 1 or 2")
        for name in ("tolerance", "coupling_tolerance", "init_tolerance"):
            if not 0 < getattr(self, name) < 1:
                raise SettingsError(f"{name} = {getattr(self, name)!r} is not allowed: between 0 and 1 (relative)")
        if self.step_control not in STEP_CONTROLS:
            raise SettingsError(f"step_control = {self.step_control!r} is not allowed: one of "
                                f"{', '.join(STEP_CONTROLS)}")
        if self.accelerator not in ACCELERATORS:
            raise SettingsError(f"accelerator = {self.accelerator!r} is not allowed: one of {', '.join(ACCELERATORS)}")
        if isinstance(self.max_iterations, bool) or not isinstance(self.max_iterations, int) or self.max_iterations < 1:
            raise SettingsError(f"max_iterations = {self.max_iterations!r} is not allowed: an integer >= 1")
        if isinstance(self.substeps, bool) or not isinstance(self.substeps, int) or self.substeps < 1:
            raise SettingsError(f"substeps = {self.substeps!r} is not allowed: an integer >= 1")
        if self.substeps > 1 and self.algorithm != "iterative":
            raise SettingsError(f"substeps = {self.substeps!r} is not allowed with algorithm = {self.algorithm!r}: "
                                "only with 'iterative' (waveform iteration); use 1")
        for name in ("min_step", "max_step", "energy_alarm"):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))
                                      or not math.isfinite(value) or value <= 0):
                raise SettingsError(f"{name} = {value!r} is not allowed: a number > 0 (or None)")
        if self.adaptive and self.h_min > self.step_size:
            raise SettingsError(f"min_step = {self.h_min!r} is not allowed: must be <= step_size = {self.step_size!r} s")
        if self.adaptive and self.h_max < self.step_size:
            raise SettingsError(f"max_step = {self.h_max!r} is not allowed: must be >= step_size = {self.step_size!r} s")

    @property
    def h_min(self) -> float:
        return self.min_step if self.min_step is not None else 1e-3 * self.step_size

    @property
    def h_max(self) -> float:
        span = self.stop_time - self.start_time
        return self.max_step if self.max_step is not None else min(span, 100 * self.step_size)


def _overrides(scene: Scene, parameter_set: str | None, parameters: dict | None) -> dict[tuple[str, str], object]:
    values: dict[str, object] = scene.values(parameter_set)
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


def run(scene: str | Path, stop_time: float | None = None, step_size: float = 1e-3, algorithm: str = "jacobi",
        extrapolation: int = 0, parameter_set: str | None = None, parameters: dict | None = None,
        output: str | Path | None = None, start_time: float = 0.0, keep: bool = True,
        isolate: bool = True, *, adaptive: bool = False, tolerance: float = 1e-3, min_step: float | None = None,
        max_step: float | None = None, step_control: str = "extrapolation", coupling_tolerance: float = 1e-8,
        max_iterations: int = 50, accelerator: str = "iqn-ils", order: list[str] | None = None,
        energy_alarm: float | None = None, init_tolerance: float = 1e-10,
        progress: bool | None = None, substeps: int = 1, instability_alarm: bool = True,
        stop_when: list[str] | None = None) -> RunResult:
    """Run a scene and return its results and statistics (arguments as :func:`simulate`, plus):

    keep: hold the rows in memory (the result array); isolate: run in a child process.
    min_step, max_step [s]: bounds of the adaptive step (default step_size/1000 and 100 step_size);
    step_control: "extrapolation" (error of the extrapolated coupling values, rejecting) or "ecco"
    (power-bond energy residuals, never rejecting); coupling_tolerance, max_iterations, accelerator
    ("iqn-ils", "aitken", "none"): the iterative algorithm; order: Gauss-Seidel order of component
    names; energy_alarm [J]: stop when a power bond's total residual exceeds it; instability_alarm:
    stop a run whose explicit coupling is unstable: a power bond's residual grows geometrically,
    or its coupling creates as much energy as the bond carries, or (no bonds) a coupling value's
    change per step grows geometrically (see :mod:`.divergence`; on by default); init_tolerance:
    relative agreement of the connections after initialization; progress: bar on/off (default: on a
    terminal, after 3 s); substeps: iterative only, waveform iteration on this many sub-intervals
    of each macro step (1: inputs are one polynomial over the step; see :mod:`.waveform`);
    stop_when: outputs ("component.variable") that end the run at the first communication point
    where one is non-zero, as a result (``stats.stopped`` says why); default: the scene's own list
    (SSD annotation, see :mod:`.stop_conditions`), [] to run on.

    With ``isolate`` (the default) the FMUs run in a fresh child process.  pythonfmu FMUs share the
    host's interpreter and do not survive being instantiated again after a previous run in the same
    process was freed (measured: a hang or a segmentation fault in fmi2Instantiate), nor a crash of
    their own; a child process keeps the caller safe from both.
    """
    settings = Settings(stop_time, step_size, algorithm, extrapolation, start_time, adaptive, tolerance, min_step,
                        max_step, step_control, coupling_tolerance, max_iterations, accelerator, order, energy_alarm,
                        init_tolerance, progress, substeps)
    settings.instability_alarm = instability_alarm
    settings.stop_when = stop_when
    ssp = resolve_scene(scene)  # build in the parent, once
    args = (ssp, settings, parameter_set, parameters, output, keep)
    if not isolate:
        return _run_here(*args)
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    # an executor, not Pool.apply: a child that dies (a segfault inside an FMU) raises here instead of
    # leaving the caller waiting forever
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        try:
            return pool.submit(_run_here, *args).result()
        except BrokenProcessPool:
            where = f" The rows flushed before the crash are in {output}." if output else ""
            raise SimulationError(f"the process running scene {ssp.name} died (a crash inside an FMU, or it was "
                                  f"killed) before the run finished.{where}") from None


def _run_here(ssp: Path, settings: Settings, parameter_set: str | None, parameters: dict | None,
              output: str | Path | None, keep: bool) -> RunResult:
    workdir = Path(tempfile.mkdtemp(prefix="cranefmu_run_"))
    system = recorder = progress = None
    wall0 = clock.perf_counter()
    try:
        loaded = load_scene(ssp, workdir)
        if settings.stop_time is None:
            settings.stop_time = loaded.stop_time or 10.0
        settings.check()
        overrides = _overrides(loaded, parameter_set, parameters)
        system = CoSystem(loaded, workdir, settings.extrapolation)
        bonds = BondMonitor(system, resolve(system, loaded.bonds))
        _check_capabilities(system, settings, bonds)
        watch = Watch(system, bonds, settings.adaptive) if settings.instability_alarm else None
        recorder = Recorder(system.columns + bonds.columns, Path(output) if output else None, keep=keep)
        conditions = loaded.stop_conditions if settings.stop_when is None \
            else {v: "" for v in settings.stop_when}
        stopper = StopWatch(system.columns + bonds.columns, conditions) if conditions else None
        system.stats.init_iterations = initialize(system, settings.start_time, overrides, settings.init_tolerance)
        progress = Progress(settings.start_time, settings.stop_time, settings.progress)
        _loop(system, settings, recorder, bonds, progress, watch, stopper)
        system.stats.wall_time = clock.perf_counter() - wall0
        system.stats.master_time = system.stats.wall_time - sum(system.stats.fmu_time.values())
        system.stats.bond_energy = bonds.totals()
        recorder.close()
        return RunResult(recorder.result(), system.stats, recorder.output, loaded.name)
    except CraneFmuError as err:
        if recorder is not None:
            recorder.close()
            if isinstance(err, SimulationError) and recorder.count:
                where = f" The {recorder.count} rows computed so far are in {recorder.output}." if recorder.output \
                    else f" {recorder.count} rows were computed before the failure."
                raise SimulationError(str(err) + where, recorder.result(), recorder.output) from None
        raise
    finally:
        if progress is not None:
            progress.close()
        if recorder is not None:
            recorder.close()
        if system is not None:
            system.free()
        shutil.rmtree(workdir, ignore_errors=True)


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
          watch: Watch | None, stopper: StopWatch | None = None) -> None:
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
        progress.update(t)
        if s.adaptive:
            if locating and event:      # the switch is located to min_step: restart small
                locating = False
                h = s.h_min
            elif not locating:
                if ecco:
                    err = ecco_error(bonds.residual, bonds.carried, s.tolerance, 1e-3 * s.tolerance)
                h = controller.accepted(h, err)


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


def simulate(scene: str | Path, stop_time: float | None = None, step_size: float = 1e-3, algorithm: str = "jacobi",
             extrapolation: int = 0, parameter_set: str | None = None, parameters: dict | None = None,
             output: str | Path | None = None, start_time: float = 0.0, *, adaptive: bool = False,
             tolerance: float = 1e-3, **options) -> np.ndarray:
    """Run a scene (name under ssp/ or path to an .ssp) and return a structured array with fields
    ``time``, ``component.variable`` for every Real output and ``bond.<name>.dE``/``.E`` per power bond.

    stop_time, step_size [s] (the initial step when adaptive); algorithm: jacobi | gauss-seidel |
    iterative; extrapolation: 0, 1, 2 (order of the polynomial the coupling inputs follow inside a
    step; for iterative the degree of the interpolation, at least 1); adaptive: control the step so
    that the coupling values' local error stays below ``tolerance`` (relative); parameter_set: a
    .ssv in the scene; parameters: {"comp.var": value} overrides; output: CSV written as the run
    goes.  Further keyword options as :func:`run`.
    Raises a :class:`~cranefmu.errors.CraneFmuError` subclass naming what is wrong.
    """
    return run(scene, stop_time, step_size, algorithm, extrapolation, parameter_set, parameters, output,
               start_time, adaptive=adaptive, tolerance=tolerance, **options).result
