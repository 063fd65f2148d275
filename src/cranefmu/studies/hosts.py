"""Run a built scene in another master (libcosim through libcosimpy, ecos through ecospy, fmpy's
``simulate_ssp``) and read back what it applied; shared by the interop tests, the speed study and the benchmarks (benchmarks/
speed_accuracy.py, interop_difference.py).  Each run belongs in a child
process (:func:`cranefmu_support.fmu_child.in_child`): pythonfmu FMUs do not survive a second instantiation in one
process.  libcosim's facts and pitfalls: docs/interop.md."""
from __future__ import annotations

import math
import time as clock
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cranefmu.settled_start import settled_inputs  # noqa: F401  (re-exported for the speed study)

NS = 1_000_000_000  # libcosim's time unit: integer nanoseconds (EccoParams alone takes seconds)


def _text(name) -> str:
    return name.decode() if isinstance(name, bytes) else str(name)


def _catalogue(ex) -> tuple[dict, dict]:
    """(instance name -> slave index, instance name -> {variable name -> description}) of an execution."""
    slaves = {_text(s.name): s.index for s in ex.slave_infos()}
    return slaves, {name: {_text(v.name): v for v in ex.slave_variables(i)} for name, i in slaves.items()}


@dataclass(frozen=True)
class EccoSettings:
    """libcosim's ECCO parameters (``EccoParams``; Sadjina and Pedersen 2020), times in seconds.

    Defaults: libcosim's own multi-bond test (change rates 0.2 / 1.5, safety 0.8, gains 0.2 / 0.15),
    not libcosimpy's defaults (0.01 / 0.2), which only ever shrink the step.  libcosim's error
    is sqrt(mean_k (dE_k / (abs_tolerance + rel_tolerance * max_k dE_k))^2) with dE_k = |P_a - P_b| dt
    per scalar bond: the relative term scales with the residual itself, so ``abs_tolerance`` [J per
    step] decides."""

    step: float                  # first step [s]
    min_step: float              # [s]
    max_step: float              # [s]
    abs_tolerance: float         # [J]
    rel_tolerance: float = 1e-4
    safety: float = 0.8
    min_change: float = 0.2
    max_change: float = 1.5
    p_gain: float = 0.2
    i_gain: float = 0.15

    def __post_init__(self) -> None:
        for name in ("step", "min_step", "max_step", "abs_tolerance", "safety", "min_change", "max_change"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"EccoSettings.{name} = {v!r} is not allowed: a finite number > 0")
        if not self.min_step <= self.step <= self.max_step:
            raise ValueError(f"EccoSettings: min_step {self.min_step:g} <= step {self.step:g} <= max_step "
                             f"{self.max_step:g} is required (libcosim refuses it with a bare input check)")

    def params(self):
        from libcosimpy.CosimAlgorithm import EccoParams

        return EccoParams(safety_factor=self.safety, step_size=self.step, min_step_size=self.min_step,
                          max_step_size=self.max_step, min_change_rate=self.min_change,
                          max_change_rate=self.max_change, abs_tolerance=self.abs_tolerance,
                          rel_tolerance=self.rel_tolerance, p_gain=self.p_gain, i_gain=self.i_gain)


def scalar_bonds(bonds: list[tuple[str, list[dict]]]) -> list[tuple[str, tuple[str, str, str], tuple[str, str, str]]]:
    """Our power bonds (``Scene.bonds``: force/velocity vectors per side, a sign per side) as libcosim's
    scalar bonds, one per axis: (name, (component, force, velocity) of side a, ... of side b).

    libcosim compares |F_a v_a - F_b v_b| per pair and has no sign: a bond whose two sides carry
    different signs cannot be expressed and is refused."""
    out = []
    for name, (a, b) in bonds:
        if float(a.get("sign", "1")) != float(b.get("sign", "1")):
            raise ValueError(f"power bond {name!r}: sides with different signs ({a.get('sign')}, {b.get('sign')}) "
                             "cannot be a libcosim bond (it compares |P_a - P_b| of plain products)")
        fa, va, fb, vb = (side[key].split() for side in (a, b) for key in ("force", "velocity"))
        for i, parts in enumerate(zip(fa, va, fb, vb)):
            label = name if len(fa) == 1 else f"{name}[{i}]"
            out.append((label, (a["component"], parts[0], parts[1]), (b["component"], parts[2], parts[3])))
    return out


def libcosim_execution(scene_dir: str, fmu_dir: str, ecco: EccoSettings | None = None, step: float | None = None):
    """An execution built from our scene reader (components, connections, default parameter set), with
    libcosim's ECCO algorithm and the scene's bonds split per axis (``ecco``) or its fixed-step
    algorithm (``step`` [s]).  libcosimpy loads an .ssp only into a fixed-step execution, so ECCO
    needs this hand-built one; with a fixed step it equals ``from_ssp_file`` (tested).
    Returns (execution, keep-alive objects)."""
    from libcosimpy.CosimAlgorithm import CosimAlgorithm
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimSlave import CosimLocalSlave

    from cranefmu.master.extracted import extracted_scene
    from cranefmu.master.scene import read_scene_folder

    scene = read_scene_folder(Path(scene_dir), Path(fmu_dir))
    # the values libcosim's own loader applies: the built .ssp's default set with its settled start
    parameters = extracted_scene(Path(scene_dir).with_suffix(".ssp"))[1].parameters
    if ecco is not None:
        algorithm = CosimAlgorithm.create_ecco_algorithm(ecco.params())
        ex = CosimExecution.from_algorithm(algorithm)
    else:
        algorithm = None
        ex = CosimExecution.from_step_size(int(round(step * NS)))
    keep = [algorithm]
    index = {}
    for comp in scene.components:
        slave = CosimLocalSlave(str(comp.fmu), comp.name)
        keep.append(slave)
        index[comp.name] = ex.add_local_slave(slave)
    _, variables = _catalogue(ex)
    real = CosimVariableType.REAL.value

    def ref(comp: str, var: str):
        try:
            return variables[comp][var]
        except KeyError:
            raise ValueError(f"libcosim: component {comp!r} has no variable {var!r}") from None

    for c in scene.connections:
        if c.factor != 1.0 or c.offset != 0.0:
            raise ValueError(f"connection {c}: a linear transformation is not built here (libcosim needs a "
                             "function for it)")
        out, inp = ref(c.src, c.src_var), ref(c.dst, c.dst_var)
        connect = ex.connect_real_variables if out.type == real else ex.connect_integer_variables
        if connect(index[c.src], out.reference, index[c.dst], inp.reference) != 0:   # the C status: 0 = success
            raise ValueError(f"libcosim refused the connection {c}")
    for key, value in parameters.items():
        comp, _, var = key.partition(".")
        v = ref(comp, var)
        setter = {real: ex.real_initial_value, CosimVariableType.INTEGER.value: ex.integer_initial_value,
                  CosimVariableType.BOOLEAN.value: ex.boolean_initial_value}.get(v.type, ex.string_initial_value)
        if not setter(index[comp], v.reference, value):                               # a bool: True = success
            raise ValueError(f"libcosim refused the initial value {key} = {value!r}")
    if ecco is not None:
        for label, (ca, fa, va), (cb, fb, vb) in scalar_bonds(scene.bonds):
            if algorithm.add_power_bond(index[ca], ref(ca, fa).reference, ref(ca, va).reference,
                                        index[cb], ref(cb, fb).reference, ref(cb, vb).reference) != 0:
                raise ValueError(f"libcosim refused power bond {label}")
    return ex, keep


def libcosim_timed(columns: list[str], stop: float, ssp: str | None = None, step: float | None = None,
                   scene_dir: str | None = None, fmu_dir: str | None = None, ecco: dict | None = None,
                   initial_values: dict | None = None) -> dict:
    """One libcosim run to ``stop`` [s] in a single ``simulate_until``, values buffered in C++ by a
    time-series observer (no Python per step): fixed step ``step`` from the .ssp as libcosim loads
    it, or ECCO (``ecco``: EccoSettings fields) on the execution built from ``scene_dir``.

    Returns {"time", column...: arrays after every step up to ``stop`` (ECCO's last step overshoots
    and is cut), "wall": s from loading to the end of the run, "steps", "end": simulated end [s],
    ``initial_values``: as :func:`libcosim_run`'s (set before the run, inside the timed span),
    "ok"; "error" when it failed}."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    settings = EccoSettings(**ecco) if ecco is not None else None
    smallest = settings.min_step if settings else step
    capacity = int(stop / smallest * 1.05) + 16
    t0 = clock.perf_counter()
    if settings is None:
        ex, keep = CosimExecution.from_ssp_file(ssp, step_size=int(round(step * NS))), []
    else:
        ex, keep = libcosim_execution(scene_dir, fmu_dir, ecco=settings)
    slaves, variables = _catalogue(ex)
    _set_initial_values(ex, slaves, variables, initial_values)
    last = CosimObserver.create_last_value()     # ECCO reads its bond variables through it (else "not found")
    series = CosimObserver.create_time_series(buffer_size=capacity)
    ex.add_observer(last)
    ex.add_observer(series)
    real = CosimVariableType.REAL
    refs = {}
    for c in columns:
        comp, _, var = c.partition(".")
        refs[c] = (slaves[comp], variables[comp][var].reference)
        series.start_time_series(slaves[comp], refs[c][1], real)
    ok = ex.simulate_until(int(round(stop * NS)))
    wall = clock.perf_counter() - t0
    out = {"wall": wall, "ok": bool(ok), "end": ex.status().current_time / NS}
    # from step 1: libcosimpy trims its arrays by counting zero step numbers, so a sample at step 0
    # would cost the last one
    cols, times = {}, None
    for c, (i, vr) in refs.items():
        t, _steps, values = series.time_series_real_samples(i, vr, from_step=1, sample_count=capacity)
        if times is None:
            times = np.asarray(t, dtype=float) / NS
        cols[c] = np.asarray(values, dtype=float)
    n = min([len(times)] + [len(v) for v in cols.values()])
    keep_rows = times[:n] <= stop * (1 + 1e-9)
    out["time"] = times[:n][keep_rows]
    out.update({c: v[:n][keep_rows] for c, v in cols.items()})
    out["steps"] = int(n)
    if not ok:
        out["error"] = f"simulate_until returned False at t = {out['end']:g} s (a step failed)"
    del keep
    return out


def libcosim_run(ssp: str, step: float, steps: int, columns: list[str], scene_dir: str | None = None,
                 fmu_dir: str | None = None, initial_values: dict | None = None) -> dict:
    """Run ``ssp`` in libcosim (fixed step, plain Jacobi) for ``steps`` steps of ``step`` [s] (None: the
    file's own step, from its ``osp:FixedStepAlgorithm``; an OspSystemStructure.xml: its base step); with
    ``scene_dir`` the execution is built by :func:`libcosim_execution` instead of libcosim's SSP loader.
    ``initial_values`` ("component.variable" -> value) are set as libcosim initial values before the
    first step (e.g. the connected inputs as our initialization settled them: :func:`settled_inputs`).

    Returns {"time": [...], column: [...]} for "component.variable" columns read after every step
    (libcosim exposes no values before its first step), "parameters": every parameter's value
    after the run ("component.variable" -> value), and "ok" (False: a step failed)."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    if scene_dir is None and ssp.endswith(".xml"):   # an OspSystemStructure.xml: its own base step
        ex, keep = CosimExecution.from_osp_config_file(ssp), []
    elif scene_dir is None and step is None:        # the file's own fixed step (its osp:FixedStepAlgorithm)
        ex, keep = CosimExecution.from_ssp_file(ssp), []
    elif scene_dir is None:
        ex, keep = CosimExecution.from_ssp_file(ssp, step_size=int(round(step * NS))), []
    else:
        ex, keep = libcosim_execution(scene_dir, fmu_dir, step=step)
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    slaves, variables = _catalogue(ex)
    real = CosimVariableType.REAL.value
    _set_initial_values(ex, slaves, variables, initial_values)

    def read(comp: str, names: list[str]) -> list:
        vs = [variables[comp][n] for n in names]
        i = slaves[comp]
        return [obs.last_real_values(i, [v.reference])[0] if v.type == real else
                obs.last_integer_values(i, [v.reference])[0] for v in vs]

    out = {"time": [], **{c: [] for c in columns}}
    ok = True
    for k in range(1, steps + 1):
        if not ex.step(1):
            ok = False
            break
        out["time"].append(ex.status().current_time / NS)
        for c in columns:
            comp, _, var = c.partition(".")
            out[c].append(read(comp, [var])[0])
    params = {}
    for comp, vs in variables.items():
        names = [n for n, v in vs.items() if v.causality == 1]   # parameter
        params.update({f"{comp}.{n}": value for n, value in zip(names, read(comp, names))})
    out["parameters"] = params
    out["ok"] = ok
    return out


def _set_initial_values(ex, slaves: dict, variables: dict, initial_values: dict | None) -> None:
    """libcosim initial values ("component.variable" -> value) for the execution ``ex``."""
    from libcosimpy.CosimEnums import CosimVariableType

    real = CosimVariableType.REAL.value
    for key, value in (initial_values or {}).items():
        comp, _, var = key.partition(".")
        v = variables[comp][var]
        ok = (ex.real_initial_value(slaves[comp], v.reference, float(value)) if v.type == real else
              ex.integer_initial_value(slaves[comp], v.reference, int(round(value))))
        if not ok:                                                              # a bool: True = success
            raise ValueError(f"libcosim refused the initial value {key} = {value!r}")


def fmpy_run(ssp: str, step: float, stop: float, parameters: dict) -> dict:
    """fmpy's ``simulate_ssp`` with the scene's parameters passed as its ``parameter_set`` (it
    applies no binding of the SSD itself).  Returns the result columns and, read back from every
    FMU just before fmpy frees it, the values of ``parameters``."""
    import fmpy.ssp.simulation as sim
    from fmpy.ssp.ssd import Parameter, ParameterSet

    kinds = {bool: "Boolean", int: "Integer", float: "Real"}
    pset = ParameterSet(name="scene", parameters=[Parameter(name=k, type=kinds.get(type(v), "String"), value=v)
                                                  for k, v in parameters.items()])
    read_back = {}
    free = sim.free_fmu

    def free_after_reading(component):
        for key in parameters:
            comp, _, var = key.partition(".")
            if comp == component.name:
                read_back[key] = sim.get_value(component, var)
        free(component)

    sim.free_fmu = free_after_reading
    try:
        result = sim.simulate_ssp(ssp, stop_time=stop, step_size=step, parameter_set=pset)
    finally:
        sim.free_fmu = free
    return {"result": {n: np.asarray(result[n]) for n in result.dtype.names}, "parameters": read_back}


def fmpy_run_set(ssp: str, parameter_set: str, step: float, stop: float) -> dict:
    """fmpy's ``simulate_ssp`` given one parameter set of the file as fmpy reads it
    (``read_ssv(ssp, "resources/<set>.ssv")``): how an fmpy user chooses a set.  Returns the result columns."""
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import read_ssv

    pset = read_ssv(ssp, f"resources/{parameter_set}.ssv")
    result = simulate_ssp(ssp, stop_time=stop, step_size=step, parameter_set=pset)
    return {n: np.asarray(result[n]) for n in result.dtype.names}


def fmpy_run_until(ssp: str, parameter_set: str, step: float, stop: float) -> str:
    """:func:`fmpy_run_set` to ``stop`` [s]: "ran", or the time and the error where it stopped (an FMU's
    refusal of a step, of any kind, is the answer, not an exception)."""
    import fmpy.ssp.simulation as sim

    last = [0.0]
    do_step = sim.do_step

    def timed(component, t, size):
        last[0] = t
        return do_step(component, t, size)

    sim.do_step = timed
    try:
        fmpy_run_set(ssp, parameter_set, step, stop)
    except Exception as err:   # noqa: BLE001 (what stopped it is the result)
        return f"failed at t = {last[0]:.3g} s ({str(err)[:60]})"
    finally:
        sim.do_step = do_step
    return "ran"


def ecos_run(ssp: str, step: float, stop: float, columns: list[str], parameter_set: str = "default") -> dict:
    """Run ``ssp`` in ecos (fixed-step plain Jacobi) to ``stop`` [s]: ``init(parameter_set=...)`` names
    the set ecos applies ("default", or a named set of a built file: the build binds each set, complete
    with its settled start, on every component, where ecos reads sets), nothing else is handed over.
    Returns {"time", column...: values after every step, read in ecos's
    post-step callback; "parameters" is not read (ecos has no listing)}.  Column names
    "component.variable" (ecos: "component::variable")."""
    from ecospy import EcosLib, EcosSimulation, SimulationListener

    EcosLib.set_log_level("warn")
    out = {"time": [], **{c: [] for c in columns}}

    class Recorder(SimulationListener):
        def post(self, info) -> None:
            out["time"].append(info.time)
            for c in columns:
                out[c].append(sim.get_real(c.replace(".", "::", 1)))

    with EcosSimulation(ssp_path=ssp, step_size=step) as sim:
        sim.add_listener("recorder", Recorder())
        if not sim.init(parameter_set=parameter_set):
            raise RuntimeError(f"ecos could not initialize {ssp}: {EcosLib.get_last_error()}")
        sim.step(int(round(stop / step)))
        sim.terminate()
    return {k: np.asarray(v, dtype=float) for k, v in out.items()}


def output_dependencies(fmu: str) -> dict[str, set[str]]:
    """Output name -> the variables its value depends on, as the model description of ``fmu`` declares."""
    from fmpy import read_model_description

    md = read_model_description(fmu)
    return {o.variable.name: {d.name for d in o.dependencies or []} for o in md.outputs}


_EXPORTS: dict[tuple[str, str | None, tuple], str] = {}


def scene_file(scene: str, parameter_set: str | None = None, changes: dict | None = None) -> str:
    """The .ssp a host loads for one variant of ``scene``: the built file for the default set, else
    ``cranefmu export`` of the set and the changes (made once per process, removed at exit)."""
    from cranefmu import build as b

    if parameter_set in (None, "default") and not changes:
        return str(b.SSP_DIR / f"{scene}.ssp")
    key = (scene, parameter_set, tuple(sorted((changes or {}).items())))
    if key not in _EXPORTS:
        import atexit
        import shutil
        import tempfile

        from cranefmu.export import export_scene

        folder = tempfile.mkdtemp(prefix="cranefmu_variants_")
        atexit.register(shutil.rmtree, folder, True)
        _EXPORTS[key] = str(export_scene(scene, Path(folder) / f"{scene}.ssp", parameter_set, changes))
    return _EXPORTS[key]


def scene_variants() -> list[tuple[str, str]]:
    """(scene, parameter set) for every built scene and each of its sets, "default" first."""
    from cranefmu import build as b
    from cranefmu.master.scene import read_scene_folder

    return [(d.name, s) for d in b.scene_dirs() for s in ("default", *read_scene_folder(d, b.FMU_DIR).sets)]


# a step where every scene is stable with plain Jacobi: overhead_lift's stiff 4-line rope is not at
# 1 ms (our alarm stops it at 0.512 s; libcosim runs on to 1.48 MN), at 0.5 ms it is
AGREEMENT_STEP = {"overhead_lift": 5e-4}
AGREEMENT_SPAN = 2.0   # [s]


def agreement_step(scene: str) -> float:
    return AGREEMENT_STEP.get(scene, 1e-3)


def worst_relative(ours: dict, theirs: dict, columns: list[str], shift: int = 1,
                   units: dict[str, str] | None = None) -> dict[str, float]:
    """Per column, the largest |ours[k + shift] - theirs[k]| over the rows both have, relative to our
    largest |value| (``shift`` 1: the hosts report no row at t = 0, our row 0 is t = 0).  With
    ``units`` (column -> unit) the scale is the largest |value| among the columns of that unit: a
    chassis velocity that stays at round-off level is compared on the scene's velocity scale."""
    top = {c: max(float(np.max(np.abs(ours[c]))), 1e-300) for c in columns}
    if units:
        by_unit: dict[str, float] = {}
        for c in columns:
            by_unit[units.get(c, c)] = max(by_unit.get(units.get(c, c), 0.0), top[c])
        top = {c: by_unit[units.get(c, c)] for c in columns}
    out = {}
    for c in columns:
        a, b = np.asarray(ours[c])[shift:], np.asarray(theirs[c])
        n = min(len(a), len(b))
        out[c] = float(np.max(np.abs(a[:n] - b[:n]))) / top[c]
    return out


def split_feedthrough(scene: str) -> tuple[list[str], list[str]]:
    """(outputs compared as they are, feedthrough key outputs): every key output and every connected
    output that its FMU declares independent of its connected inputs; the key outputs that depend on
    a connected input."""
    from cranefmu import build as b
    from cranefmu.master.scene import read_scene_folder
    from cranefmu.scenes import SCENES

    loaded = read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR)
    depends = {c.name: output_dependencies(str(c.fmu)) for c in loaded.components}
    connected = {(c.dst, c.dst_var) for c in loaded.connections}
    wanted = list(SCENES[scene].key_outputs) + [f"{c.src}.{c.src_var}" for c in loaded.connections]
    plain, fed = [], []
    for name in dict.fromkeys(wanted):
        comp, _, var = name.partition(".")
        through = any((comp, d) in connected for d in depends[comp].get(var, ()))
        (fed if through else plain).append(name)
    return plain, [k for k in fed if k in SCENES[scene].key_outputs]
