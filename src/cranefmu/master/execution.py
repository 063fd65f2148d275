"""A run a caller drives: :class:`Execution` (libcosim's ``execution``: ``step``, ``simulate_until``;
ecos's ``simulation``), with values read and set between steps.  :func:`.run.run` and
:func:`.run.simulate` are the one-call form on top of it.

    from cranefmu.master.execution import Execution

    with Execution.start("elastic_pendulum", stop_time=10.0) as ex:
        ex.simulate_until(2.0)
        print(ex.time, ex.get("rope.tension"))
        ex.set("pendulum.m_payload", 500.0)      # a parameter or unconnected input the FMU accepts now
        while ex.step():                           # one macro step at a time, to the stop time
            pass
        result = ex.finish()                       # a RunResult (rows, statistics)
"""
from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, field
import tempfile
import time as clock
from pathlib import Path

from .algorithm_table import make_algorithm
from .exchange_label import exchange_label
from .coupled import Coupling
from .divergence import ValueCheck
from ..errors import CraneFmuError, SceneError, SettingsError, SimulationError
from .extracted import extracted_scene, fresh_fmu_dirs, instantiates_in_place
from .initialization import initialize
from .loop import March, Sampler
from .output_file import OutputFile
from .process import discard, forget_extracted
from .progress import Progress
from .step_control import make_step_control
from .threads import one_thread
from .bond_inference import scene_bonds
from .divergence import Watch
from .power_bonds import BondMonitor, resolve as resolve_bonds
from .results import Recorder
from .runspec import RunSpec
from .settings import Settings
from .step_control import ESTIMATES
from .stop_conditions import StopWatch
from .system import RunStats


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
class Parts:
    """One run's parts, built from its :class:`RunSpec` by :func:`build_execution`: the coupled system,
    its power bonds and the observers the settings ask for (recorder, instability watch, stop watch)."""

    system: Coupling
    bonds: BondMonitor
    recorder: Recorder
    watch: Watch | None
    stopper: StopWatch | None


def build_execution(spec: RunSpec, loaded, fmu_dirs: Path, claim: OutputFile | None = None) -> Parts:
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
    return Parts(system, bonds, recorder, watch, stopper)


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
    if s.adaptive:   # what the FMU's author declared (FMI 2.0 4.3.1, FMI 3.0 canHandleVariableCommunicationStepSize)
        fixed = [f"{c.name} (model {c.md.coSimulation.modelIdentifier})" for c in system.comps
                 if not getattr(getattr(c.md, "coSimulation", None), "canHandleVariableCommunicationStepSize", True)]
        if fixed:
            raise SettingsError(f"adaptive is not allowed for this scene: component(s) {', '.join(fixed)} declare "
                                "canHandleVariableCommunicationStepSize=\"false\" (a fixed communication step only); "
                                "run with a fixed --step")
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



class Execution:
    """One run, loaded and initialized, stepped by the caller.  Made by :meth:`start` (a scene and the
    options of :func:`.run.run`) or from a resolved :class:`~.runspec.RunSpec`; always in this process.

    :meth:`step` takes one macro step, :meth:`simulate_until` steps to a time (where no observer needs the
    steps one by one, in compiled stretches); :attr:`time` is where the FMUs are; :meth:`get` and
    :meth:`set` read and set variables between steps; :meth:`finish` closes the run and returns its
    :class:`~.run.RunResult`; :meth:`close` (or leaving the ``with`` block) frees the FMUs.  A failure
    raises :class:`~cranefmu.errors.SimulationError` carrying the rows so far, as :func:`.run.run` does."""

    def __init__(self, spec, claim: OutputFile | None = None, observers: tuple = (), interrupt=None):
        self.spec = spec
        self.settings = s = spec.settings
        self._claim, self._own_claim = claim, False
        self._closed = False
        self._stack = contextlib.ExitStack()
        self.coupling = self.recorder = self.progress = self._fmu_dirs = None
        self._wall0 = clock.perf_counter()
        try:
            self._stack.enter_context(one_thread())
            workdir, self.scene = extracted_scene(spec.ssp)
            if instantiates_in_place(workdir, self.scene):   # native FMUs: loaded libraries kept between runs
                dirs = workdir
            else:   # never instantiate a pythonfmu FMU twice from one directory (process.py)
                dirs = self._fmu_dirs = Path(tempfile.mkdtemp(prefix="run_", dir=workdir))
                fresh_fmu_dirs(workdir, self.scene, self._fmu_dirs)
            parts = build_execution(spec, self.scene, dirs, claim)
            self.coupling, self.bonds, self.recorder = parts.system, parts.bonds, parts.recorder
            c = self.coupling
            starts = spec.overrides if c.commands is None else \
                {**spec.overrides, **c.commands.start_values(s.start_time)}
            c.stats.init_iterations = initialize(c, s.start_time, starts, s.init_tolerance)
            self.progress = Progress(s.start_time, s.stop_time, s.progress)
            algorithm = make_algorithm(c, s)
            control = make_step_control(c, s, self.bonds)
            from .commands import event_watchers

            # sources started or stopped by an event see each row before the next exchange feeds them
            events = event_watchers(spec.commands, c.columns + self.bonds.columns)
            everyone = [self.recorder, ValueCheck(c, self.bonds, s.energy_alarm), parts.watch, parts.stopper,
                        *events, *([interrupt] if interrupt is not None else []), *observers, self.progress]
            self._sample = Sampler(c, self.bonds)
            self._march = March(c, algorithm, control, self._sample, [o for o in everyone if o is not None],
                                s.start_time)
        except CraneFmuError as err:
            self._fail(err)
        except BaseException:
            self.close()
            raise

    @classmethod
    def start(cls, scene, *, parameter_set: str | None = None, parameters: dict | None = None,
              output: str | Path | None = None, keep: bool = True, observers: tuple = (), **settings) -> Execution:
        """Load and initialize a scene (name, .ssp path or :class:`~.runspec.RunSpec`) with the options
        of :func:`.run.run` (``isolate`` is not one: an execution runs in this process)."""
        from .runspec import resolve

        if settings.pop("isolate", False):
            raise SettingsError("isolate=True is not allowed for an Execution: it runs in this process "
                                "(use run(..., isolate=True) for a run in a worker)")
        spec = scene if isinstance(scene, RunSpec) else resolve(
            scene, parameter_set=parameter_set, parameters=parameters, output=output, keep=keep, **settings)
        claim = OutputFile.claim(spec.output, spec.ssp) if spec.output is not None else None
        try:
            ex = cls(spec, claim, tuple(observers))
        except BaseException:
            if claim is not None:
                claim.abandon()
                claim.release()
            raise
        ex._own_claim = True
        return ex

    # --- stepping ---------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Where the FMUs are [s]."""
        return self._march.t

    @property
    def stopped(self) -> str:
        """Why an observer (a stop condition, an interrupt, the caller's) ended the run ('' if none)."""
        return self._march.reason or ""

    @property
    def done(self) -> bool:
        """No step is left: the stop time is reached or an observer stopped the run."""
        return self._march.done or bool(self._march.reason)

    def step(self) -> bool:
        """Take one macro step (a rejected adaptive try is retried within it); False if the run is over."""
        return self._guarded(lambda: self._march.step())

    def simulate_until(self, t: float) -> bool:
        """Step until the FMUs are at ``t`` [s] or past it (a fixed step ends on its grid; an adaptive
        step is not shortened to meet ``t``); False if the run ended before ``t``."""
        self._guarded(lambda: _until(self._march, t))
        return self.time >= t - 1e-12 * max(1.0, abs(t))

    def _to_end(self) -> None:
        """Step to the end of the run (the loop of :func:`.loop.march`, stretches where they can run)."""
        self._guarded(lambda: _until(self._march, None))

    def _guarded(self, go):
        self._check_open()
        try:
            return go()
        except CraneFmuError as err:
            self._fail(err)

    # --- values -----------------------------------------------------------------------------------
    def get(self, name: str) -> float:
        """The value of ``component.variable`` now (any Real, Integer or Boolean variable of the FMU), or
        of a power bond's ``bond.<name>.dE`` / ``.E`` after the last step."""
        self._check_open()
        if name.startswith("bond.") and name in self.bonds.columns:
            return float(self.bonds.row[self.bonds.columns.index(name)])
        comp, var = self._variable(name)
        v = comp.variable(var)
        vr = [v.valueReference]
        try:
            if v.type == "Real":
                return float(comp.fmu.getReal(vr)[0])
            if v.type == "Boolean":
                return float(bool(comp.fmu.getBoolean(vr)[0]))
            if v.type in ("Integer", "Enumeration"):
                return float(comp.fmu.getInteger(vr)[0])
        except Exception:
            raise self.coupling.refused(comp, f"reading {name}") from None
        raise SettingsError(f"{name} is a {v.type} variable: get() reads Real, Integer and Boolean variables")

    def set(self, name: str, value) -> None:
        """Set ``component.variable`` (a parameter or an input the FMU accepts between steps) to ``value``
        for the coming steps; a connected input is refused (the next exchange would overwrite it)."""
        self._check_open()
        comp, var = self._variable(name)
        fed = {f"{c.dst}.{c.dst_var}": str(c) for c in self.scene.connections}
        if name in fed:
            raise SettingsError(f"set({name!r}) is not allowed: that input is fed by the connection {fed[name]} "
                                "(its value is overwritten at the next exchange); set an unconnected input or a parameter")
        comp.set_start(var, value)

    def row(self) -> dict[str, float]:
        """The last row the observers saw: every output, discrete output and power bond column."""
        self._check_open()
        return dict(zip(self.coupling.columns + self.bonds.columns, self._sample.row_.tolist()))

    def _variable(self, name: str):
        comp_name, _, var = str(name).partition(".")
        comp = self.coupling.by_name.get(comp_name)
        if comp is None or not var:
            raise SceneError(f"{name!r} is not a variable: write component.variable with a component of "
                             f"{self.scene.name}: {', '.join(self.coupling.components)}")
        return comp, var

    # --- the end ----------------------------------------------------------------------------------
    def finish(self):
        """Close the run where it is and return its :class:`~.run.RunResult` (rows, statistics, the CSV)."""
        self._check_open()
        c, recorder = self.coupling, self.recorder
        st = c.stats
        st.stopped = self.stopped
        st.wall_time = clock.perf_counter() - self._wall0
        st.master_time = st.wall_time - sum(st.fmu_time.values())
        st.bond_energy = self.bonds.totals()
        st.bond_carried = self.bonds.carried_totals()
        st.exchange = exchange_label(st, self._march.algorithm)
        try:
            recorder.close()
            where = _finish(self._claim, recorder)
            result = RunResult(recorder.result(), st, where, self.scene.name, self.settings, recorder.count,
                               recorder.last_time, self.bonds.warnings(), self.spec)
        except CraneFmuError as err:
            self._fail(err)
        self.close()
        if self._own_claim and self._claim is not None:
            self._claim.check_placed(result.result)
        return result

    def close(self) -> None:
        """Free the FMUs and the run's folders; the rows recorded so far stay in the CSV (idempotent)."""
        if self._closed:
            return
        self._closed = True
        try:
            if self.progress is not None:
                self.progress.close()
            if self.coupling is not None:
                self.coupling.free()
            if self._fmu_dirs is not None:
                forget_extracted(self._fmu_dirs)
                discard(self._fmu_dirs)
            _finish(self._claim, self.recorder)
            if self._own_claim and self._claim is not None:
                self._claim.abandon()
                self._claim.release()
        finally:
            self._stack.close()

    def __enter__(self) -> Execution:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _check_open(self) -> None:
        if self._closed:
            raise SettingsError("this execution is closed (finish() or close() was called, or it failed)")

    def _fail(self, err: CraneFmuError):
        """Raise ``err`` with the rows so far (as :func:`.run.run` does), the run closed."""
        recorder = self.recorder
        where = _finish(self._claim, recorder)
        try:
            if recorder is not None and isinstance(err, SimulationError) and recorder.count:
                if recorder.write_error:
                    raise SimulationError(str(err), recorder.result(), where) from None
                kept = f" The {recorder.count} rows computed so far are in {where}." if where \
                    else f" {recorder.count} rows were computed before the failure."
                raise SimulationError(str(err) + kept, recorder.result(), where) from None
            raise err
        finally:
            self.close()


def _until(march: March, t: float | None) -> None:
    while march.step(until=t, stretch=True):
        pass

