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
from .algorithms import ALGORITHMS, make_algorithm
from .divergence import ValueCheck, Watch
from ..errors import CraneFmuError, ParameterSetError, SettingsError, SimulationError
from .initialization import initialize
from .power_bonds import BondMonitor, resolve
from .progress import Progress
from .results import Recorder
from .scene import Scene, load_scene
from .loop import Sampler, march
from .scene_names import resolve_scene
from .step_control import make_step_control
from .stop_conditions import StopWatch
from .system import CoSystem, RunStats
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


def _loop(system: CoSystem, s: Settings, recorder: Recorder, bonds: BondMonitor, progress: Progress,
          watch: Watch | None, stopper: StopWatch | None = None) -> None:
    """Step from start to stop (:func:`.loop.march`): the algorithm and its start-up, the step
    controller and the observers the settings ask for, in the order they see each row."""
    algorithm = make_algorithm(system, s)
    control = make_step_control(system, s, bonds)
    observers = [recorder, ValueCheck(system, bonds, s.energy_alarm), watch, stopper, progress]
    system.stats.stopped = march(system, algorithm, control, Sampler(system, bonds, s.adaptive),
                                 [o for o in observers if o is not None], s.start_time)


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
