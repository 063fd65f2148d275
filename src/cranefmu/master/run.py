"""Run a scene: instantiate, initialize, couple step by step, record; nothing lost on failure.

The algorithm (how far each FMU steps and when values move) lives here; recording is an observer
(:mod:`.results`); parameter overrides are applied once before initialization.
"""
from __future__ import annotations

import math
import shutil
import tempfile
import time as clock
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .coupling import InputGroup, check_connection, input_groups, rates, visit_order
from .errors import CraneFmuError, ParameterSetError, SceneError, SettingsError, SimulationError
from .fmu import FmuComponent
from .results import Recorder
from .scene import Scene, load_scene

ALGORITHMS = ("jacobi", "gauss-seidel")
INIT_MAX_ITERATIONS = 100
INIT_TOLERANCE = 1e-12


@dataclass
class RunStats:
    steps: int = 0
    wall_time: float = 0.0
    init_iterations: int = 0
    fmu_time: dict[str, float] = field(default_factory=dict)   # seconds inside each FMU's doStep
    fmu_calls: dict[str, int] = field(default_factory=dict)

    def real_time_factor(self, simulated: float) -> float:
        return simulated / self.wall_time if self.wall_time > 0 else math.inf


@dataclass
class RunResult:
    result: np.ndarray
    stats: RunStats
    output: Path | None
    scene: str


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


def _check_settings(start_time: float, stop_time: float, step_size: float, algorithm: str,
                    extrapolation: int) -> None:
    for name, value in (("start_time", start_time), ("stop_time", stop_time), ("step_size", step_size)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise SettingsError(f"{name} = {value!r} is not allowed: a finite number of seconds")
    if stop_time <= start_time:
        raise SettingsError(f"stop_time = {stop_time!r} is not allowed: must be > start_time = {start_time!r} s")
    if step_size <= 0:
        raise SettingsError(f"step_size = {step_size!r} is not allowed: must be > 0 s")
    if step_size > stop_time - start_time:
        raise SettingsError(f"step_size = {step_size!r} is not allowed: must be <= stop_time - start_time = "
                            f"{stop_time - start_time!r} s")
    if algorithm not in ALGORITHMS:
        raise SettingsError(f"algorithm = {algorithm!r} is not allowed: one of {', '.join(ALGORITHMS)}")
    if extrapolation not in (0, 1, 2):
        raise SettingsError(f"extrapolation = {extrapolation!r} is not allowed: 0, 1 or 2")


def _overrides(scene: Scene, parameter_set: str | None, parameters: dict | None) -> dict[tuple[str, str], object]:
    values: dict[str, object] = dict(scene.parameters)
    if parameter_set is not None and parameter_set != "default":
        if parameter_set not in scene.parameter_sets:
            raise ParameterSetError(f"parameter set {parameter_set!r} is not in scene {scene.name}: one of "
                                    f"{', '.join(['default', *scene.parameter_sets]) }")
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


class Master:
    """Fixed-step master over the FMUs of one scene (Jacobi or Gauss-Seidel, extrapolation 0-2)."""

    def __init__(self, scene: Scene, workdir: Path, algorithm: str, extrapolation: int):
        self.scene = scene
        self.algorithm = algorithm
        self.order_of_extrapolation = extrapolation
        self.comps = [FmuComponent(c.name, c.fmu, workdir / f"fmu_{c.name}") for c in scene.components]
        by_name = {c.name: c for c in self.comps}
        for c in scene.connections:
            check_connection(c, by_name)
        self.order = visit_order(self.comps, scene.connections)
        self.groups = input_groups(self.comps, scene.connections)
        # what is recorded: every Real output of every component
        self.out_vrs, self.columns = [], []
        for comp in self.comps:
            reals = [v for v in comp.md.modelVariables if v.causality == "output" and v.type == "Real"]
            self.out_vrs.append([v.valueReference for v in reals])
            self.columns += [f"{comp.name}.{v.name}" for v in reals]
        self.stats = RunStats(fmu_time={c.name: 0.0 for c in self.comps}, fmu_calls={c.name: 0 for c in self.comps})

    # --- values -----------------------------------------------------------------------------
    def _pull(self, g: InputGroup) -> np.ndarray:
        try:
            return self.comps[g.src].get_real(g.src_vrs) * g.factor + g.offset
        except Exception:
            raise self._refused(self.comps[g.src], "reading its outputs") from None

    def _push(self, g: InputGroup, value: np.ndarray, d1: np.ndarray | None, d2: np.ndarray | None) -> None:
        fmu = self.comps[g.dst].fmu
        try:
            fmu.setReal(g.dst_vrs, value.tolist())
            if g.dt_vrs is not None and d1 is not None:
                fmu.setReal(g.dt_vrs + g.dt2_vrs, d1.tolist() + d2.tolist())
        except Exception:
            raise self._refused(self.comps[g.dst], "setting its inputs") from None

    @staticmethod
    def _refused(comp: FmuComponent, what: str) -> CraneFmuError:
        msg = comp.last_error()
        cls = ParameterSetError if "ParameterError" in msg else SimulationError
        return cls(f"component {comp.name} failed {what}: {msg}")

    def exchange(self, t: float, dst_only: int | None = None) -> float:
        """Move values along every connection at time t, in feedthrough order; returns the largest change."""
        change = 0.0
        for d in self.order:
            if dst_only is not None and d != dst_only:
                continue
            for g in self.groups[d]:
                value = self._pull(g)
                if g.history:
                    change = max(change, float(np.max(np.abs(value - g.history[-1][1]), initial=0.0)))
                if g.history and g.history[-1][0] == t:
                    g.history[-1] = (t, value)
                else:
                    g.history.append((t, value))
                    del g.history[:-3]
                d1, d2 = rates(g.history[-(self.order_of_extrapolation + 1):], t)
                self._push(g, value, d1, d2)
        return change

    def outputs(self) -> np.ndarray:
        try:
            return np.concatenate([c.get_real(v) for c, v in zip(self.comps, self.out_vrs)])
        except Exception:
            bad = next(c for c in self.comps if c.messages) if any(c.messages for c in self.comps) else self.comps[0]
            raise self._refused(bad, "reading its outputs") from None

    # --- life cycle -----------------------------------------------------------------------------
    def initialize(self, start_time: float, overrides: dict, h: float) -> None:
        by_name = {c.name: c for c in self.comps}
        for comp in self.comps:
            comp.instantiate()
            comp.fmu.setupExperiment(startTime=start_time)
        for (comp, var), value in overrides.items():
            by_name[comp].set_start(var, value)
        for comp in self.comps:
            self._call(comp, "enterInitializationMode", start_time)
        # iterate the exchange until the connections agree (values of outputs that depend on inputs)
        for it in range(1, INIT_MAX_ITERATIONS + 1):
            change = self.exchange(start_time)
            self.stats.init_iterations = it
            if it > 1 and change <= INIT_TOLERANCE * (1.0 + self._scale()):
                break
        else:
            raise SimulationError(f"initialization did not converge in {INIT_MAX_ITERATIONS} exchanges "
                                  f"(last change {change:.3g}); the connections do not agree at t = {start_time}")
        for comp in self.comps:
            self._call(comp, "exitInitializationMode", start_time)
        for g in (g for gs in self.groups for g in gs):
            # before the start the scene is taken to be at rest: the past equals the initial values,
            # so extrapolation starts at its full order with exact (constant) history
            g.history.clear()
        self.exchange(start_time)
        for g in (g for gs in self.groups for g in gs):
            t0, u0 = g.history[-1]
            g.history[:] = [(t0 - 2 * h, u0), (t0 - h, u0), (t0, u0)]

    def _scale(self) -> float:
        vals = [np.max(np.abs(g.history[-1][1]), initial=0.0) for gs in self.groups for g in gs if g.history]
        return max(vals, default=0.0)

    def _call(self, comp: FmuComponent, what: str, t: float) -> None:
        try:
            getattr(comp.fmu, what)()
        except Exception:
            raise self._refused(comp, f"in {what} at t = {t:.6g} s") from None

    def step(self, t: float, h: float) -> None:
        """One macro step from t to t + h (inputs at t already set by the previous exchange)."""
        if self.algorithm == "jacobi":
            for i, comp in enumerate(self.comps):
                self._do_step(comp, t, h)
            self.exchange(t + h)
        else:  # gauss-seidel: each component sees the new outputs of those stepped before it
            stepped = set()
            for d in self.order:
                for g in self.groups[d]:
                    if g.src in stepped:
                        self._interpolate(g, t, t + h)
                self._do_step(self.comps[d], t, h)
                stepped.add(d)
            self.exchange(t + h)

    def _interpolate(self, g: InputGroup, t: float, t1: float) -> None:
        """Gauss-Seidel: the source already reached t1; feed the destination the polynomial through
        the past values and the new one, evaluated over [t, t1] (value at t, rates at t)."""
        new = self._pull(g)
        points = [*g.history[-self.order_of_extrapolation:], (t1, new)] if self.order_of_extrapolation else \
            [(t, g.history[-1][1])]
        if self.order_of_extrapolation:
            d1, d2 = rates(points, t)
        else:  # zero-order hold of the newest value
            d1 = d2 = np.zeros_like(new)
            self._push(g, new, d1, d2)
            return
        self._push(g, g.history[-1][1], d1, d2)

    def _do_step(self, comp: FmuComponent, t: float, h: float) -> None:
        t0 = clock.perf_counter()
        try:
            comp.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        except Exception:
            raise SimulationError(f"component {comp.name} failed in the step from t = {t:.6g} s (H = {h:.3g} s): "
                                  f"{comp.last_error()}. Try a smaller --step or another --algorithm.") from None
        finally:
            self.stats.fmu_time[comp.name] += clock.perf_counter() - t0
            self.stats.fmu_calls[comp.name] += 1

    def check_finite(self, values: np.ndarray, t: float) -> None:
        if not np.all(np.isfinite(values)):
            bad = self.columns[int(np.flatnonzero(~np.isfinite(values))[0])]
            raise SimulationError(f"{bad} became non-finite at t = {t:.6g} s: the coupling is unstable at this "
                                  "step size. Try a smaller --step, or --algorithm gauss-seidel.")

    def free(self) -> None:
        for comp in self.comps:
            comp.free()


def run(scene: str | Path, stop_time: float | None = None, step_size: float = 1e-3, algorithm: str = "jacobi",
        extrapolation: int = 0, parameter_set: str | None = None, parameters: dict | None = None,
        output: str | Path | None = None, start_time: float = 0.0, keep: bool = True,
        isolate: bool = True) -> RunResult:
    """Run a scene and return its results and statistics (see :func:`simulate`).

    With ``isolate`` (the default) the FMUs run in a fresh child process.  pythonfmu FMUs share the
    host's interpreter and do not survive being instantiated again after a previous run in the same
    process was freed (measured: a hang or a segmentation fault in fmi2Instantiate), nor a crash of
    their own; a child process keeps the caller safe from both.
    """
    ssp = resolve_scene(scene)  # build in the parent, once
    args = (ssp, stop_time, step_size, algorithm, extrapolation, parameter_set, parameters, output,
            start_time, keep)
    if not isolate:
        return _run_here(*args)
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1) as pool:
        return pool.apply(_run_here, args)


def _run_here(ssp: Path, stop_time: float | None, step_size: float, algorithm: str, extrapolation: int,
              parameter_set: str | None, parameters: dict | None, output: str | Path | None,
              start_time: float, keep: bool) -> RunResult:
    workdir = Path(tempfile.mkdtemp(prefix="cranefmu_run_"))
    master = recorder = None
    wall0 = clock.perf_counter()
    try:
        loaded = load_scene(ssp, workdir)
        stop = stop_time if stop_time is not None else (loaded.stop_time or 10.0)
        _check_settings(start_time, stop, step_size, algorithm, extrapolation)
        overrides = _overrides(loaded, parameter_set, parameters)
        master = Master(loaded, workdir, algorithm, extrapolation)
        recorder = Recorder(master.columns, Path(output) if output else None, keep=keep)
        master.initialize(start_time, overrides, step_size)
        n_steps = max(1, round((stop - start_time) / step_size))
        t = start_time
        values = master.outputs()
        master.check_finite(values, t)
        recorder.record(t, values)
        for n in range(n_steps):
            h = min(step_size, stop - t) if n < n_steps - 1 else stop - t
            master.step(t, h)
            t = start_time + (n + 1) * step_size if n < n_steps - 1 else stop
            values = master.outputs()
            master.check_finite(values, t)
            recorder.record(t, values)
            master.stats.steps += 1
        master.stats.wall_time = clock.perf_counter() - wall0
        recorder.close()
        return RunResult(recorder.result(), master.stats, recorder.output, loaded.name)
    except CraneFmuError as err:
        if recorder is not None:
            recorder.close()
            if isinstance(err, SimulationError) and recorder.count:
                where = f" The {recorder.count} rows computed so far are in {recorder.output}." if recorder.output \
                    else f" {recorder.count} rows were computed before the failure."
                raise SimulationError(str(err) + where, recorder.result(), recorder.output) from None
        raise
    finally:
        if recorder is not None:
            recorder.close()
        if master is not None:
            master.free()
        shutil.rmtree(workdir, ignore_errors=True)


def simulate(scene: str | Path, stop_time: float | None = None, step_size: float = 1e-3, algorithm: str = "jacobi",
             extrapolation: int = 0, parameter_set: str | None = None, parameters: dict | None = None,
             output: str | Path | None = None, start_time: float = 0.0) -> np.ndarray:
    """Run a scene (name under ssp/ or path to an .ssp) and return a structured array with fields
    ``time`` and ``component.variable`` for every Real output.

    stop_time, step_size [s]; algorithm: jacobi | gauss-seidel; extrapolation: 0, 1, 2 (order of the
    polynomial the coupling inputs follow inside a step); parameter_set: a .ssv in the scene;
    parameters: {"comp.var": value} overrides; output: CSV written as the run goes.
    Raises a :class:`~cranefmu.master.errors.CraneFmuError` subclass naming what is wrong.
    """
    return run(scene, stop_time, step_size, algorithm, extrapolation, parameter_set, parameters, output,
               start_time).result
