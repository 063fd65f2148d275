"""Speed against accuracy for every scene, on one core, in one run.

Sections of the report, in order: a summary against issue 6's targets; the hot path of every scene
(where a macro step's time goes: each FMU's doStep, the other FMI calls, the master's own work,
measured without a profiler by timing every FMI C call); the truck_telescope 30 s real-time target
(several algorithm/H settings against the finest run); then per scene the master at every algorithm
x extrapolation order x macro step H, fmpy's ``fmpy.ssp.simulate_ssp`` on the same .ssp (same FMUs)
at the same H, and the monolithic scipy solve at a sweep of tolerances; every error is the worst
over the scene's key outputs of max|y - y_ref| / range(y_ref), against one tight monolithic solve
(rtol 1e-10) or, where no monolithic model exists, the master's finest run; the equal-accuracy
comparison (cheapest of each method meeting an error level); with --profile a cProfile of one run
and the cost of one pythonfmu call; peak memory against simulated length with ``keep=False``.
Side by side with libcosim (when libcosimpy is installed): per scene libcosim's fixed-step Jacobi at
the same H and libcosim's ECCO with the scene's power bonds split per axis, against our fixed Jacobi
x1, adaptive (extrapolation error) and ECCO step control, each against the same monolithic
reference, with the wall ratios at 1 % of range (issue 16); walls are medians of --repeats runs
taken in alternation.  --libcosim-only runs just that block and replaces it in the results files.

Writes benchmarks/results/speed_accuracy.{md,csv}, speed_accuracy_<scene>.png, profile.txt.
Every run executes in a spawned child (pythonfmu FMUs cannot be instantiated again in one process);
all processes are pinned to one core.  Compare later runs as ratios, never as absolute times.

    .venv/bin/python benchmarks/speed_accuracy.py [--quick] [--profile] [--scenes a,b] [--steps ...]
        [--algorithms jacobi,gauss-seidel] [--extrapolations 0,1] [--no-target] [--cpu 0]
        [--libcosim-only | --no-libcosim] [--repeats 3]
"""
from __future__ import annotations

import argparse
import csv
import importlib.util
import math
import multiprocessing
import os
import platform
import subprocess
import sys
import tempfile
import statistics
import time as clock
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
LEVELS = (1e-2, 1e-3)  # error levels (fraction of the signal's range) for the equal-accuracy comparison
MONO_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


class ChildFailed(Exception):
    """The child process died (e.g. a segmentation fault inside an FMU) or ran past its time limit."""


def in_child(fn, *args, timeout: float = 900.0, **kwargs):
    """fn(*args, **kwargs) in a fresh spawned process (inherits the CPU pinning).  A child that dies or
    hangs raises ChildFailed instead of blocking the benchmark (a multiprocessing.Pool waits forever)."""
    from concurrent.futures import ProcessPoolExecutor, TimeoutError as FutureTimeout
    from concurrent.futures.process import BrokenProcessPool

    ex = ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn"))
    try:
        return ex.submit(fn, *args, **kwargs).result(timeout=timeout)
    except BrokenProcessPool:
        raise ChildFailed("the child process died (crash inside an FMU?)") from None
    except FutureTimeout:
        for proc in list(getattr(ex, "_processes", {}).values()):  # our own child, by its process object
            proc.kill()
        raise ChildFailed(f"no result within {timeout:g} s; the child was killed") from None
    finally:
        ex.shutdown(wait=False, cancel_futures=True)


def warm_run_once(scene: str, stop: float, h: float, tol, algorithm: str, extrapolation: int, *args, **options):
    """converge.run_once after a run of 5 steps of the same settings in this process: the measured
    wall is a second run's (load, instantiate, initialize, step), with the process's imports and
    the scene's extraction done, as the monolithic sweep solves 0.01 s before it times a tolerance."""
    from cranefmu.analysis import converge as cv

    if algorithm is not None:   # a named algorithm means its explicit form, not the scene's stored implicit group
        options.setdefault("implicit", [])
    cv.run_once(scene, 5 * h, h, None, algorithm, extrapolation, *args,
                **{k: v for k, v in options.items() if k != "tolerance"})
    return cv.run_once(scene, stop, h, tol, algorithm, extrapolation, *args, **options)


def master_runs(scene: str, settings: list, stop: float, algorithm: str, extrapolation: int, say,
                **options) -> tuple[list, list]:
    """:func:`warm_run_once` for each (H, tolerance), each in a guarded child (isolate=False inside it)."""
    from cranefmu.analysis import converge as cv

    runs, results = [], []
    for h, tol in settings:
        say(f"run {algorithm} x{extrapolation} {'tol=%g' % tol if tol is not None else 'H=%g' % h} ...")
        try:
            row, res = in_child(warm_run_once, scene, stop, h, tol, algorithm, extrapolation, None, None,
                                isolate=False, timeout=max(120.0, 30 * stop), **options)
        except ChildFailed as err:
            row, res = cv.ConvergenceRun(h, tol, failure=str(err)), None
        except cv.CraneFmuError as err:
            row, res = cv.ConvergenceRun(h, tol, failure=str(err).splitlines()[0]), None
        runs.append(row)
        results.append(res)
    return runs, results


# --- fmpy's simulate_ssp ---------------------------------------------------------------------------
def _fmpy_parameter_set(scene: str, parameter_set: str | None):
    """The scene's parameter set as fmpy's ParameterSet, without the values fmpy cannot set.

    fmpy's set_value converts every value with float() and has no String branch ("Unsupported type"):
    non-numeric values are dropped (they stay at the FMU's default) and reported."""
    from fmpy.ssp.ssd import read_ssv

    ps = read_ssv(str(ROOT / "ssp" / scene / "default.ssv"))
    if parameter_set and parameter_set != "default":
        extra = read_ssv(str(ROOT / "ssp" / scene / f"{parameter_set}.ssv"))
        names = {p.name for p in extra.parameters}
        ps.parameters = [p for p in ps.parameters if p.name not in names] + list(extra.parameters)
    kept, dropped = [], []
    for p in ps.parameters:
        try:
            float(p.value)
            kept.append(p)
        except (TypeError, ValueError):
            dropped.append(f"{p.name}={p.value}")
    ps.parameters = kept
    return ps, dropped


def fmpy_run(ssp: str, scene: str, stop: float, h: float, keys: tuple[str, ...]) -> dict:
    """fmpy.ssp.simulate_ssp in this (child) process; times shifted to where the values belong."""
    from fmpy.ssp.simulation import simulate_ssp

    ps, dropped = _fmpy_parameter_set(scene, None)
    out = {"dropped": dropped}
    t0 = clock.perf_counter()
    try:
        res = simulate_ssp(ssp, stop_time=stop, step_size=h, parameter_set=ps)
    except Exception as err:  # measured and reported, whatever it is
        out.update(error=f"{type(err).__name__}: {err}"[:300], wall=clock.perf_counter() - t0)
        return out
    out["wall"] = clock.perf_counter() - t0
    # simulate_ssp records the values after the step from t to t+h under the label t, and never the
    # initial values; shift the label to the time the values belong to
    t = res["time"] + h
    keep = t <= stop * (1 + 1e-9)
    out["steps"] = len(res)
    out["time"] = t[keep]
    out["cols"] = {k: np.asarray(res[k])[keep] for k in keys if k in res.dtype.names}
    out["missing"] = [k for k in keys if k not in res.dtype.names]
    return out


# --- the monolithic solve at a sweep of tolerances ----------------------------------------------------
def mono_sweep(scene: str, stop: float, times: np.ndarray, reference, keys, rtols=MONO_RTOLS) -> list[dict]:
    from cranefmu.analysis.converge import monolithic_reference

    rows = []
    exact = reference.at(times)
    # one short solve first: the lazy imports and first-call set-up are not a tolerance's cost
    monolithic_reference(scene, min(stop, 0.01), times[times <= min(stop, 0.01)][:3], rtol=max(rtols))
    for rtol in rtols:
        t0 = clock.perf_counter()
        try:
            sol = monolithic_reference(scene, stop, times, rtol=rtol)
        except Exception as err:
            rows.append({"rtol": rtol, "error": str(err)[:200]})
            continue
        wall = clock.perf_counter() - t0
        rel = {}
        for k in keys:
            span = float(np.ptp(exact[k]))
            rel[k] = float(np.max(np.abs(np.asarray(sol[k]) - exact[k]))) / span if span > 0 else math.inf
        rows.append({"rtol": rtol, "wall": wall, "worst": max(rel.values()), "rel": rel})
    return rows


# --- profile of the hot path -----------------------------------------------------------------------
FMI_LOOP_CALLS = ("doStep", "setReal", "getReal", "setInteger", "getInteger", "getBoolean", "setBoolean",
                  "getFMUstate", "setFMUstate", "freeFMUstate", "setRealInputDerivatives")
SETUP_CALLS = ("load_scene", "instantiate", "enterInitializationMode", "exitInitializationMode", "initialize",
               "setupExperiment", "terminate", "freeInstance", "free", "__init__")


def _layer(path: str, func: str) -> str:
    """Which layer a profiled function belongs to (own time is summed per layer)."""
    if "/resources/" in path and ("_cranefmu_" in path or "pythonfmu" in path):
        return "inside the FMUs (pythonfmu + adapter + physics)"
    if "fmpy" in path:
        return "fmpy wrappers (ctypes conversion, status checks)"
    if "cranefmu" in path and "master" in path:
        return "master (cranefmu.master)"
    if "numpy" in path or "scipy" in path:
        return "numpy/scipy called from Python code"
    if path == "~":
        return "builtins (ctypes calls, numpy C functions, getattr...)"
    return "other Python (imports, multiprocessing, csv...)"


def profile_run(scene: str, stop: float, h: float, algorithm: str, extrapolation: int, top: int = 25) -> dict:
    """cProfile of one master run in this (child) process: time inside the FMI calls and in the master."""
    import cProfile
    import io
    import pstats

    from cranefmu.master.run import run

    prof = cProfile.Profile()
    t0 = clock.perf_counter()
    prof.enable()
    res = run(scene, stop_time=stop, step_size=h, algorithm=algorithm, extrapolation=extrapolation,
              keep=False, isolate=False, instability_alarm=False, implicit=[])
    prof.disable()
    total = clock.perf_counter() - t0
    st = pstats.Stats(prof)
    fmi = {name: 0.0 for name in FMI_LOOP_CALLS}
    ncalls = {name: 0 for name in FMI_LOOP_CALLS}
    setup = 0.0
    for (path, _line, func), (_cc, nc, _tt, ct, _callers) in st.stats.items():
        if path.endswith(os.path.join("fmpy", "fmi2.py")) and func in fmi:
            fmi[func] += ct
            ncalls[func] += nc
        if func in ("load_scene", "initialize", "free") and "cranefmu" in path and "master" in path:
            setup += ct
    inside = sum(fmi.values())
    loop = total - setup
    # own (not cumulative) time of the layers a value crosses: fmpy's generic call wrapper, pythonfmu's
    # per-variable set/get loops, the adapter's do_step
    layers = {"fmpy _call wrapper": [0.0, 0], "pythonfmu set_real": [0.0, 0], "pythonfmu get_real": [0.0, 0]}
    for (path, _line, func), (_cc, nc, tt, _ct, _callers) in st.stats.items():
        key = ("fmpy _call wrapper" if func == "_call" and "fmpy" in path else
               "pythonfmu set_real" if func == "set_real" and path.endswith("fmi2slave.py") else
               "pythonfmu get_real" if func == "get_real" and path.endswith("fmi2slave.py") else None)
        if key:
            layers[key][0] += tt
            layers[key][1] += nc
    by_layer: dict[str, float] = {}
    for (path, _line, func), (_cc, _nc, tt, _ct, _callers) in st.stats.items():
        by_layer[_layer(path, func)] = by_layer.get(_layer(path, func), 0.0) + tt
    buf = io.StringIO()
    pstats.Stats(prof, stream=buf).sort_stats("tottime").print_stats(top)
    return {"total": total, "setup": setup, "loop": loop, "fmi": fmi, "ncalls": ncalls, "inside": inside,
            "overhead": loop - inside, "steps": res.stats.steps, "fmu_time": dict(res.stats.fmu_time),
            "fmu_calls": dict(res.stats.fmu_calls), "layers": layers, "by_layer": by_layer,
            "text": buf.getvalue()}


class _TimedCall:
    """A ctypes FMI function that adds its wall time to a table (instance, function) -> [s, calls]."""

    __slots__ = ("f", "cell")

    def __init__(self, f, cell):
        self.f, self.cell = f, cell

    def __call__(self, *args):
        t0 = clock.perf_counter()
        try:
            return self.f(*args)
        finally:
            self.cell[0] += clock.perf_counter() - t0
            self.cell[1] += 1

    def __getattr__(self, name):  # restype, argtypes, argnames: fmpy's wrapper reads them
        return getattr(self.f, name)


class _LoopTimer:
    """An observer of the run (``run(..., observers=)``): the stepping loop's wall time, from the row at
    the start time to the row at ``stop``, and the FMI calls of ``table`` made in between."""

    def __init__(self, table: dict, stop: float):
        self.table, self.stop = table, stop
        self.wall, self.fmi = 0.0, {}

    def simulation_initialized(self, t: float, values) -> None:
        self.before = {k: tuple(v) for k, v in self.table.items()}
        self.t0 = clock.perf_counter()

    def step_complete(self, t: float, h: float, values) -> None:
        if t >= self.stop - 1e-9 * max(1.0, abs(self.stop)):
            self.wall = clock.perf_counter() - self.t0
            self.fmi = {k: (v[0] - self.before.get(k, (0.0, 0))[0], v[1] - self.before.get(k, (0.0, 0))[1])
                        for k, v in self.table.items()}


def fmi_split(scene: str, stop: float, h: float, algorithm: str, extrapolation: int, **options) -> dict:
    """Without a profiler: the stepping loop's wall time and the time inside the FMI C functions
    (each FMI C function of every instance is wrapped with a timer through the master's public
    :func:`cranefmu.master.fmu.wrap_fmi_calls`, so the master's direct calls and fmpy's wrappers are
    timed alike), per FMU instance and per function.  Master = loop - FMI."""
    from cranefmu.master.fmu import wrap_fmi_calls
    from cranefmu.master.run import run

    table: dict[tuple[str, str], list] = {}

    def timed(instance: str, name: str, f):
        return _TimedCall(f, table.setdefault((instance, name.replace("fmi2", "")), [0.0, 0]))

    loop = _LoopTimer(table, stop)
    with wrap_fmi_calls(timed):
        res = run(scene, stop_time=stop, step_size=h, algorithm=algorithm, extrapolation=extrapolation,
                  keep=False, isolate=False, observers=(loop,), **{"implicit": [], **options})
    loop_box = {"wall": loop.wall, "fmi": loop.fmi}
    # the timer's own cost per call, to say how much of "inside FMI" it adds
    cell = [0.0, 0]
    dummy = _TimedCall(lambda *a: 0, cell)
    t0 = clock.perf_counter()
    for _ in range(20000):
        dummy(1, 2)
    timer_us = ((clock.perf_counter() - t0) / 20000) * 1e6
    fmi = {k: v for k, v in loop_box["fmi"].items() if v[1]}
    return {"scene": scene, "h": h, "steps": res.stats.steps, "wall": res.stats.wall_time, "loop": loop_box["wall"],
            "fmi": fmi, "fmu_time": dict(res.stats.fmu_time), "timer_us": timer_us, "algorithm": algorithm,
            "extrapolation": extrapolation}


def hot_path_report(cases: list[tuple[str, float, float]], say) -> tuple[list[str], dict]:
    """Per scene: where one macro step's time goes (each FMU's doStep, the other FMI calls, the master)."""
    out = ["## Hot path: where a macro step's time goes (no profiler; Jacobi x1 or x0, keep=False, no CSV)", "",
           "Loop = wall time of the stepping loop; FMI = time inside the FMI C functions (the FMU's own code, "
           "pythonfmu included), timed around each ctypes call; master = loop - FMI (the master's own work: "
           "exchange, extrapolation, power bonds, recorder, checks).  Target: master <= 25 % of FMI at equal H.", "",
           "| scene | H [s] | steps | loop [us/step] | FMI [us/step] | doStep | getReal | setReal | other FMI | "
           "master [us/step] | master / FMI | FMI calls/step | RTF bound by doStep |",
           "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    per_fmu = []
    results = {}
    for scene, stop, h in cases:
        r = None
        for ex in (1, 0):  # extrapolation 1; 0 where the iterative start-up of 1 fails
            say(f"hot path {scene} H={h:g} x{ex} ...")
            try:
                r = in_child(fmi_split, scene, stop, h, "jacobi", ex, instability_alarm=False, timeout=900)
                break
            except Exception as err:  # reported, the other scenes still measured
                out.append(f"| {scene} x{ex} | {h:g} | failed: {type(err).__name__}: {str(err)[:160]} |")
        if r is None:
            continue
        results[scene] = r
        n = max(r["steps"], 1)
        by_fn: dict[str, float] = {}
        by_fmu: dict[str, dict[str, float]] = {}
        calls = 0
        for (inst, fn), (sec, nc) in r["fmi"].items():
            by_fn[fn] = by_fn.get(fn, 0.0) + sec
            by_fmu.setdefault(inst, {})[fn] = by_fmu.setdefault(inst, {}).get(fn, 0.0) + sec
            calls += nc
        fmi = sum(by_fn.values())
        step = by_fn.get("DoStep", 0.0)
        master = r["loop"] - fmi
        other = fmi - step - by_fn.get("GetReal", 0.0) - by_fn.get("SetReal", 0.0)
        us = lambda x: f"{x / n * 1e6:.0f}"
        out.append(f"| {scene} x{r['extrapolation']} | {h:g} | {n} | {us(r['loop'])} | {us(fmi)} | {us(step)} | {us(by_fn.get('GetReal', 0))} | "
                   f"{us(by_fn.get('SetReal', 0))} | {us(other)} | {us(master)} | **{master / fmi * 100:.0f} %** | "
                   f"{calls / n:.1f} | {h / (step / n):.1f} |")
        r["master_ratio"] = master / fmi
        r["rtf_bound"] = h / (step / n)
        per_fmu.append(f"- {scene} (H = {h:g} s), inside FMI per FMU [us/step]: " + ", ".join(
            f"{inst} {sum(f.values()) / n * 1e6:.0f} (doStep {f.get('DoStep', 0.0) / n * 1e6:.0f})"
            for inst, f in sorted(by_fmu.items(), key=lambda kv: -sum(kv[1].values()))))
    timer = next((r["timer_us"] for r in results.values()), float("nan"))
    out += ["", *per_fmu, "", f"The timer around each FMI call costs {timer:.2f} us per call (a dummy call timed the "
            "same way), counted partly on each side.", ""]
    return out, results


def unprofiled_split(scene: str, stop: float, h: float, algorithm: str, extrapolation: int) -> dict:
    """Without the profiler: wall time, time inside each FMU's doStep (the master's own count)."""
    from cranefmu.master.run import run

    res = run(scene, stop_time=stop, step_size=h, algorithm=algorithm, extrapolation=extrapolation,
              keep=False, isolate=False, implicit=[])
    return {"wall": res.stats.wall_time, "fmu_time": dict(res.stats.fmu_time), "steps": res.stats.steps}


def call_cost(fmu_path: str, n: int = 3000) -> dict:
    """Per-call cost [us] of setReal (all Real inputs) + doStep (1 ms) + getReal (all Real outputs) of
    one FMU alone, through fmpy's wrappers and through ctypes with preallocated arrays."""
    import ctypes

    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave, fmi2Real, fmi2ValueReference

    md = read_model_description(fmu_path)
    unzip = extract(fmu_path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="bench")
    ins = [v for v in md.modelVariables if v.causality == "input" and v.type == "Real"]
    outs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    vin = [v.valueReference for v in ins]
    vout = [v.valueReference for v in outs]
    start = [float(v.start) if v.start is not None else 0.0 for v in ins]
    fmu.instantiate()
    out = {"fmu": Path(fmu_path).stem, "inputs": len(vin), "outputs": len(vout)}
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        h, t = 1e-3, 0.0

        def timed(body) -> float:
            nonlocal t
            t0 = clock.perf_counter()
            for _ in range(n):
                body()
                t += h
            return (clock.perf_counter() - t0) / n * 1e6

        out["set+step+get"] = timed(lambda: (fmu.setReal(vin, start), fmu.doStep(t, h), fmu.getReal(vout)))
        out["doStep"] = timed(lambda: fmu.doStep(t, h))
        out["setReal"] = timed(lambda: fmu.setReal(vin, start))
        out["getReal"] = timed(lambda: fmu.getReal(vout))
        # the same calls on the raw ctypes functions with arrays allocated once (no fmpy wrapper logic)
        cvin, cvout = (fmi2ValueReference * len(vin))(*vin), (fmi2ValueReference * len(vout))(*vout)
        cstart, cres = (fmi2Real * len(vin))(*start), (fmi2Real * len(vout))()
        lib = fmu.dll
        raw_set, raw_get, raw_step = lib.fmi2SetReal, lib.fmi2GetReal, lib.fmi2DoStep
        raw_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
        comp = fmu.component
        out["raw set+step+get"] = timed(lambda: (raw_set(comp, cvin, len(vin), cstart),
                                                 raw_step(comp, t, h, 1), raw_get(comp, cvout, len(vout), cres)))
    except Exception as err:
        out["error"] = f"{type(err).__name__}: {err}"[:200]
    finally:
        try:
            fmu.terminate()
            fmu.freeInstance()
        except Exception:
            pass
    return out


# --- memory ---------------------------------------------------------------------------------------------
def memory_run(scene: str, stop: float, h: float) -> dict:
    """Peak RSS of this (child) process running the scene with keep=False and a streamed CSV."""
    import resource

    from cranefmu.master.run import run

    def rss_now_kb() -> int:
        with open("/proc/self/status") as f:
            return next(int(line.split()[1]) for line in f if line.startswith("VmRSS"))

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "long.csv"
        res = run(scene, stop_time=stop, step_size=h, keep=False, isolate=False, output=out)
        size = out.stat().st_size
        rows = len(res.result)
    return {"stop": stop, "steps": res.stats.steps, "wall": res.stats.wall_time, "rows_kept": rows,
            "csv_bytes": size, "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "end_rss_mb": rss_now_kb() / 1024}


# --- libcosim side by side ------------------------------------------------------------------------------
# libcosim's ECCO (change rates 0.2 / 1.5 and the other defaults of cranefmu.studies.hosts.EccoSettings, i.e.
# libcosim's own multi-bond test) swept over its absolute tolerance [J per step and scalar bond];
# both ECCO controllers start at the finest fixed H and stay within [H / ECCO_RANGE, H * ECCO_RANGE]
LIBCOSIM_ECCO_TOLERANCES = (1.0, 1e-1, 1e-2, 1e-3)
ECCO_RANGE = 10.0
SIDE_BEGIN, SIDE_END = "<!-- libcosim side by side: begin -->", "<!-- libcosim side by side: end -->"
SIDE_PREFIX = "side by side: "   # CSV method prefix of the block's rows (replaced by --libcosim-only)
REPEAT_MAX_WALL = 5.0  # [s] runs longer than this are not repeated (the noise is small against them)


def libcosim_available() -> bool:
    return importlib.util.find_spec("libcosimpy") is not None


def _table(time: np.ndarray, cols: dict) -> np.ndarray:
    """A structured result array (time + columns) as the master returns it."""
    return np.array(list(zip(time, *cols.values())), dtype=[("time", float)] + [(k, float) for k in cols])


def _ecco_bounds(h0: float) -> dict:
    return {"min_step": h0 / ECCO_RANGE, "max_step": h0 * ECCO_RANGE}


def libcosim_once(scene: str, keys, stop: float, h: float, abs_tolerance: float | None, start: dict | None = None):
    """One libcosim run in a guarded child: fixed step ``h`` from the .ssp, or ECCO from ``h`` with
    ``abs_tolerance`` [J]; ``start``: initial values of the connected inputs (our settled start,
    :func:`cranefmu.studies.timing.settled_start`); returns (ConvergenceRun, result array or None)."""
    from cranefmu import build as b
    from cranefmu.analysis.converge import ConvergenceRun
    from cranefmu.master.run import resolve_scene
    from cranefmu.studies.hosts import libcosim_timed

    row = ConvergenceRun(h, abs_tolerance)
    try:
        if abs_tolerance is None:
            out = in_child(libcosim_timed, list(keys), stop, str(resolve_scene(scene)), h,
                           initial_values=start, timeout=max(120.0, 30 * stop))
        else:
            ecco = {"step": h, "abs_tolerance": abs_tolerance, **_ecco_bounds(h)}
            out = in_child(libcosim_timed, list(keys), stop, None, None, str(b.SSP_DIR / scene), str(b.FMU_DIR),
                           ecco, initial_values=start, timeout=max(120.0, 60 * stop))
    except (ChildFailed, ValueError) as err:
        row.failure = str(err)[:200]
        return row, None
    row.wall_time, row.steps = out["wall"], out["steps"]
    row.simulated = float(out["time"][-1]) if len(out["time"]) else 0.0
    if "error" in out:
        row.failure = out["error"]
        return row, None
    return row, _table(out["time"], {k: out[k] for k in keys})


def libcosim_series(scene: str, keys, stop: float, steps: list[float], say, start: dict | None) -> dict:
    """libcosim fixed step at every H, libcosim ECCO at every tolerance from the finest H, both from
    ``start`` (:func:`cranefmu.studies.timing.settled_start`)."""
    out = {}
    for name, settings in (("libcosim fixed", [(h, None) for h in steps]),
                           ("libcosim ecco", [(min(steps), tol) for tol in LIBCOSIM_ECCO_TOLERANCES])):
        rows, results = [], []
        for h, tol in settings:
            say(f"{name} {'H=%g' % h if tol is None else 'abs_tol=%g J' % tol} ...")
            row, res = libcosim_once(scene, keys, stop, h, tol, start)
            rows.append(row)
            results.append(res)
        out[name] = (rows, results)
    return out


SIDE_MASTER = (("jacobi", 1), ("jacobi", 2), ("scene", None), ("jacobi adaptive", 1), ("jacobi ecco", 1))


def side_settings(key: tuple, h0: float) -> tuple[str | None, int | None, dict]:
    """(algorithm, extrapolation, options) of a SIDE_MASTER series (None: the scene's stored one)."""
    if key[0] == "scene":
        return None, None, {}
    options = {"step_control": "ecco", **_ecco_bounds(h0)} if key[0].endswith("ecco") else {}
    return key[0].split()[0], key[1], options


def repeat_walls(s: dict, repeats: int, say) -> None:
    """Run the side-by-side settings ``repeats - 1`` more times, alternating the methods setting by
    setting (ours, libcosim's, then the monolithic sweep), and keep each setting's median wall (the
    errors are deterministic).  Runs longer than REPEAT_MAX_WALL are measured once."""
    import itertools

    scene, stop, keys = s["scene"], s["stop"], s["keys"]
    methods = []  # one list of (row, rerun -> wall) per method
    for key in SIDE_MASTER:
        alg, ex, options = side_settings(key, min(s["steps"]))
        methods.append([(row, lambda row=row, alg=alg, ex=ex, options=options: master_runs(
            scene, [(row.step_size, row.tolerance)], stop, alg, ex, say, **options,
            **({"instability_alarm": False} if getattr(row, "alarm_off", False) else {}))[0][0].wall_time)
            for row in s["series"].get(key, ([], []))[0]])
    for rows, _ in s["libcosim"].values():
        methods.append([(row, lambda row=row: libcosim_once(scene, keys, stop, row.step_size, row.tolerance,
                                                               s["libcosim_start"])[0].wall_time)
                        for row in rows])
    jobs = [job for group in itertools.zip_longest(*methods) for job in group if job is not None]
    walls = {id(row): [row.wall_time] for row, _ in jobs}
    mono_walls = {m["rtol"]: [m["wall"]] for m in s["mono"] if "wall" in m}
    for k in range(repeats - 1):
        for row, rerun in jobs:
            if row.failure is None and row.wall_time <= REPEAT_MAX_WALL:
                walls[id(row)].append(rerun())
        if mono_walls:
            say(f"monolithic tolerance sweep, repeat {k + 2} ...")
            try:
                again = in_child(mono_sweep, scene, stop, s["mono_times"], s["reference"], keys, tuple(mono_walls),
                                 timeout=900)
            except ChildFailed:
                again = []
            for m in again:
                if "wall" in m:
                    mono_walls[m["rtol"]].append(m["wall"])
    for row, _ in jobs:
        row.walls = [x for x in walls[id(row)] if math.isfinite(x)]
        if row.walls:
            row.wall_time = statistics.median(row.walls)
    for m in s["mono"]:
        if m.get("rtol") in mono_walls:
            m["walls"] = mono_walls[m["rtol"]]
            m["wall"] = statistics.median(m["walls"])


def alarm_retries(scene: str, stop: float, series: dict, h0: float, say) -> list[str]:
    """Our side-by-side runs that the instability alarm stopped run again with the alarm off (as the
    real-time target does): the error then says whether the coupling really diverged."""
    notes = []
    for key in SIDE_MASTER:
        rows, results = series.get(key, ([], []))
        for i, row in enumerate(rows):
            if not (row.failure and "instability_alarm=False" in row.failure):
                continue
            alg, ex, options = side_settings(key, h0)
            again, res = master_runs(scene, [(row.step_size, row.tolerance)], stop, alg, ex, say,
                                     instability_alarm=False, **options)
            notes.append(f"{scene}: ours {key[0]} x{ex} {row.label} was stopped by the default instability alarm "
                         f"({row.failure[:140]}); shown with the alarm off")
            again[0].alarm_off = True
            rows[i], results[i] = again[0], res[0]
    return notes


def side_rows(s: dict) -> list[tuple[str, str, object]]:
    """(method, setting, ConvergenceRun) of the side-by-side block."""
    names = {("jacobi", 1): "ours, fixed Jacobi x1", ("jacobi", 2): "ours, fixed Jacobi x2",
             ("scene", None): "ours, the scene's stored settings at this H",
             ("jacobi adaptive", 1): "ours, adaptive (extrapolation error) x1",
             ("jacobi ecco", 1): "ours, ECCO step control x1"}
    out = []
    for key, name in names.items():
        for r in s["series"].get(key, ([], []))[0]:
            out.append((name, r.label, r))
    for name, (rows, _) in s.get("libcosim", {}).items():
        for r in rows:
            out.append(("libcosim, fixed-step Jacobi" if name == "libcosim fixed" else "libcosim, ECCO",
                        r.label if r.tolerance is None else f"abs_tol={r.tolerance:g} J", r))
    return out


def side_cheapest(s: dict, level: float) -> dict:
    """Cheapest run meeting ``level`` of each side: ours (any master setting of the block), libcosim
    fixed, libcosim ECCO, the monolithic solve."""
    ours = [r for key in SIDE_MASTER for r in s["series"].get(key, ([], []))[0]]
    ms = [m for m in s["mono"] if "worst" in m and m["worst"] <= level]
    return {"ours": cheapest(ours, level), "libcosim fixed": cheapest(s["libcosim"]["libcosim fixed"][0], level),
            "libcosim ecco": cheapest(s["libcosim"]["libcosim ecco"][0], level),
            "monolithic": min(ms, key=lambda m: m["wall"]) if ms else None}


def _ratio(other, ours, s: dict | None = None, rows=None) -> str:
    """other's wall / ours at the level; where other never reaches it (``rows`` given): the ratio at
    other's own best error instead, against ours' cheapest run at least as accurate."""
    if other is None and rows:
        ok = [r for r in rows if r.failure is None and math.isfinite(r.worst_rel)]
        if not ok:
            return "never reaches it (every run failed)"
        best = min(ok, key=lambda r: r.worst_rel)
        mine = cheapest([r for key in SIDE_MASTER for r in s["series"].get(key, ([], []))[0]], best.worst_rel)
        return (f"never reaches it; at its best error {best.worst_rel:.2g} ({best.label}, {best.wall_time:.3f} s): "
                + (f"**{best.wall_time / mine.wall_time:.2f}** (ours {mine.label}, {mine.wall_time:.3f} s)"
                   if mine else "ours misses that too"))
    if ours is None:
        return "ours misses it"
    if other is None:
        return "never reaches it"
    wall = other["wall"] if isinstance(other, dict) else other.wall_time
    return f"**{wall / ours.wall_time:.2f}**"


def side_summary(done: list[dict], level: float = LEVELS[0]) -> list[str]:
    out = [f"### Equal accuracy ({level:g} of range): wall of the cheapest run of each side meeting it", "",
           "Target (issue 16): libcosim / ours >= 5 (fixed and ECCO) and monolithic / ours >= 2.", "",
           "| scene | ours (method, setting, wall s) | libcosim fixed (H, wall s) | libcosim ECCO (abs_tol, wall s) | "
           "monolithic (rtol, wall s) | libcosim fixed / ours | libcosim ECCO / ours | monolithic / ours |",
           "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for s in done:
        if "libcosim" not in s:
            continue
        c = side_cheapest(s, level)
        o, fixed, ecco, mono = c["ours"], c["libcosim fixed"], c["libcosim ecco"], c["monolithic"]
        name = next((f"{n.split(', ')[-1]}, {setting}" for n, setting, r in side_rows(s) if r is o), "")
        cells = [f"{name}, {o.wall_time:.3f}" if o else "none",
                 f"{fixed.label}, {fixed.wall_time:.3f}" if fixed else "none",
                 f"{ecco.tolerance:g} J, {ecco.wall_time:.3f}" if ecco else "none",
                 f"{mono['rtol']:g}, {mono['wall']:.3f}" if mono else "none",
                 _ratio(fixed, o, s, s["libcosim"]["libcosim fixed"][0]),
                 _ratio(ecco, o, s, s["libcosim"]["libcosim ecco"][0]), _ratio(mono, o)]
        out.append(f"| {s['scene']} | " + " | ".join(cells) + " |")
    return out + [""]


def side_report(s: dict) -> list[str]:
    """One scene's side-by-side table: every run of the block against the monolithic reference."""
    out = [f"### {s['scene']} ({s['stop']:g} s simulated; key outputs {', '.join(s['keys'])})", "",
           "| method | setting | worst rel err | worst key | steps | wall median [s] | walls [s] | RTF |",
           "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for name, setting, r in side_rows(s):
        walls = ", ".join(f"{w:.3f}" for w in getattr(r, "walls", [r.wall_time]) if math.isfinite(w))
        out.append(f"| {name} | {setting} | {fmt(r.worst_rel)} | {r.worst_key or '-'} | {r.steps} | "
                   f"{fmt(r.wall_time, '.3f')} | {walls} | {fmt(r.real_time_factor, '.1f')} |"
                   + (f" FAILED: {r.failure[:120]}" if r.failure else ""))
    for m in s["mono"]:
        if "error" in m:
            out.append(f"| monolithic (scipy) | rtol={m['rtol']:g} | FAILED {m['error'][:80]} | | | | | |")
        else:
            walls = ", ".join(f"{w:.3f}" for w in m.get("walls", [m["wall"]]))
            out.append(f"| monolithic (scipy) | rtol={m['rtol']:g} | {fmt(m['worst'])} | - | - | {m['wall']:.3f} | "
                       f"{walls} | {s['stop'] / m['wall']:.1f} |")
    return out + [""]


def side_block(done: list[dict], notes: list[str]) -> list[str]:
    """The whole side-by-side block, between markers so that --libcosim-only can replace it."""
    h0 = {min(s["steps"]) for s in done}
    out = [SIDE_BEGIN, "## Side by side: libcosim (fixed step and ECCO), ours, the monolithic solve", "",
           "Same FMUs, same .ssp scenes, same monolithic reference (scipy, rtol 1e-10) at each run's own "
           "communication points; error = worst over the key outputs of max|y - y_ref| / range(y_ref). "
           "Wall = loading + instantiation + initialization + run, the median of the repeats (runs alternate "
           f"method by method; runs over {REPEAT_MAX_WALL:g} s are measured once; every run in its own spawned process pinned to one core, libcosim's worker threads "
           "included). Ours is timed as the second run in its process (a 5-step run of the same settings first: "
           "imports and the scene's extraction done), as the monolithic sweep solves 0.01 s before it times a "
           "tolerance; libcosim's wall is its child's load + run (its FMUs' embedded Python in that process).", "",
           f"- libcosim 0.11.2 (libcosimpy 0.0.6), both modes from our settled start (every connected input's value "
           "after our initialization handed over as a libcosim initial value, as tests/tools/test_interop_libcosim.py "
           "does; libcosim exchanges nothing in initialization mode): fixed step = the .ssp as libcosim loads it, plain Jacobi "
           "(outputs read once after each step); values buffered by a time-series observer, one "
           "`simulate_until` (no Python per step).",
           "- libcosim ECCO: the execution built from our scene reader (same components, connections, default "
           "parameters; libcosimpy loads an .ssp only with the fixed-step algorithm), every power bond of the "
           "scene split per axis into libcosim's scalar bonds (e.g. hook -> hook[0..2]: Fx_hook*vx_hook vs "
           "Fx_rope*vx); EccoParams safety 0.8, change rates **0.2 / 1.5** (libcosim's own multi-bond test; "
           "libcosimpy's defaults 0.01 / 0.2 only shrink the step), gains p 0.2 / i 0.15, rel_tolerance 1e-4 "
           "(it multiplies the largest residual, not the carried energy, so abs_tolerance decides), "
           f"abs_tolerance swept {', '.join(f'{t:g}' for t in LIBCOSIM_ECCO_TOLERANCES)} J; first step = the finest H "
           f"({', '.join(f'{h:g}' for h in sorted(h0))} s), bounds H/{ECCO_RANGE:g} .. {ECCO_RANGE:g} H. Its last step "
           "overshoots the stop time; rows after it are cut.",
           f"- ours: fixed Jacobi x1 at the same H; adaptive Jacobi x1 with the extrapolation error control "
           f"(tolerances {', '.join(f'{t:g}' for t in ADAPTIVE_TOLERANCES)}, default bounds); ECCO step control "
           "(`run(..., adaptive=True, step_control=\"ecco\")`, rtol = tol, atol = 1e-3 tol J, vector bonds, same "
           "first step and bounds as libcosim's ECCO).", "",
           *side_summary(done), *[line for s in done if "libcosim" in s for line in side_report(s)],
           *[f"- {n}" for s in done for n in s.get("notes", [])], *[f"- {n}" for n in notes], "", SIDE_END, ""]
    return out


# --- the study of one scene --------------------------------------------------------------------------
def parse_stop_times(text: str) -> dict:
    """'10' or '10,overhead_lift=2' -> {None: 10.0, 'overhead_lift': 2.0} (None: every other scene)."""
    out = {}
    for part in text.split(","):
        name, _, value = part.rpartition("=")
        try:
            out[name.strip() or None] = float(value)
        except ValueError:
            raise argparse.ArgumentTypeError(f"stop time {part!r} is not a number or scene=number") from None
    return out


def scene_stop(scene: str, quick: bool) -> float:
    full = {"truck_telescope": 30.0}.get(scene, 10.0)
    return min(full, 3.0) if quick else full


ADAPTIVE_TOLERANCES = (1e-3, 1e-4, 1e-5)


def study_scene(scene: str, quick: bool, say, stop: float | None = None, steps: list[float] | None = None,
                algorithms: tuple[str, ...] | None = None, extrapolations: tuple[int, ...] = (0, 1, 2), *,
                fmpy: bool = True, libcosim: bool = False, repeats: int = 1) -> dict:
    """Every run of one scene against one monolithic reference; ``fmpy``: fmpy's simulate_ssp at each
    H; ``libcosim``: the side-by-side runs (ours with ECCO step control, libcosim fixed and ECCO),
    their walls the median of ``repeats``."""
    from cranefmu.analysis import converge as cv
    from cranefmu.master.run import ALGORITHMS, resolve_scene

    keys = cv.key_outputs(scene)
    stop = stop or scene_stop(scene, quick)
    steps = steps or [4e-3, 2e-3, 1e-3]
    series: dict[tuple[str, int], tuple[list, list]] = {}
    for alg in algorithms or ALGORITHMS:
        # Jacobi x1 always (the adaptive comparison and libcosim's same H), x0 for the same-H fmpy comparison
        for ex in sorted(set(extrapolations) | (({0, 1} if fmpy else {1}) if alg == "jacobi" else set())):
            if alg == "jacobi-plain" and ex:   # zero-order hold only, like libcosim
                continue
            series[(alg, ex)] = master_runs(scene, [(h, None) for h in steps], stop, alg, ex, say)
    # adaptive Jacobi, extrapolation 1, started at the finest fixed H
    series[("jacobi adaptive", 1)] = master_runs(scene, [(min(steps), tol) for tol in ADAPTIVE_TOLERANCES],
                                                 stop, "jacobi", 1, say)
    lc = {}
    if libcosim:  # the scene's stored settings (algorithm, extrapolation, ...) at each H; ECCO; libcosim
        series[("scene", None)] = master_runs(scene, [(h, None) for h in steps], stop, None, None, say)
        h0 = min(steps)
        series[("jacobi ecco", 1)] = master_runs(scene, [(h0, tol) for tol in ADAPTIVE_TOLERANCES], stop, "jacobi",
                                                 1, say, step_control="ecco", **_ecco_bounds(h0))
        from cranefmu.studies.timing import settled_start

        start = in_child(settled_start, scene)
        lc = libcosim_series(scene, keys, stop, steps, say, start)
        notes = alarm_retries(scene, stop, series, h0, say)
    ssp = str(resolve_scene(scene))
    fm = []
    for h in steps if fmpy else ():
        say(f"fmpy simulate_ssp H={h:g} ...")
        try:
            fm.append(in_child(fmpy_run, ssp, scene, stop, h, keys, timeout=max(120.0, 30 * stop)))
        except ChildFailed as err:
            fm.append({"error": str(err)})
    all_results = [r for _, rs in [*series.values(), *lc.values()] for r in rs if r is not None]
    fm_results = [_table(f["time"], f["cols"]) if "time" in f and not f.get("missing") else None for f in fm]
    try:
        say("monolithic reference (child, 600 s limit) ...")
        ref = in_child(cv.Reference.monolithic, scene, keys, stop,
                       all_results + [r for r in fm_results if r is not None], timeout=600)
    except (cv.CraneFmuError, ChildFailed, NotImplementedError, KeyError) as err:
        say(f"no monolithic reference ({err}); the finest co-simulation instead")
        ref = cv.Reference.finest(scene, keys, stop, min(steps) / cv.FINEST_FACTOR, "jacobi", 2, progress=say)
    for runs, results in [*series.values(), *lc.values()]:
        cv.evaluate(runs, results, ref)
    fm_rows, fm_late = [], []
    settle = min(1.0, stop / 3)
    for h, f, r in zip(steps, fm, fm_results):
        row = cv.ConvergenceRun(h, None)
        row.wall_time = f.get("wall", math.nan)
        row.steps = f.get("steps", 0)
        row.simulated = stop
        if r is None:
            row.failure = f.get("error") or f"key outputs missing from simulate_ssp's result: {f.get('missing')}"
        else:
            try:
                cv.measure(row, r, ref.at(r["time"]), keys)
            except cv.CraneFmuError as err:
                row.failure = str(err)
        fm_rows.append(row)
        # the same run with the start-up transient left out: does simulate_ssp's jolt settle?
        late = cv.ConvergenceRun(h, None)
        late.wall_time, late.steps, late.simulated, late.failure = row.wall_time, row.steps, stop, row.failure
        if r is not None and row.failure is None:
            r_late = r[r["time"] >= settle]
            cv.measure(late, r_late, ref.at(r_late["time"]), keys)
        fm_late.append(late)
    cv.observed_orders(fm_rows)
    cv.observed_orders(fm_late)
    mono, mono_times = [], None
    if ref.kind == "monolithic":
        fixed = series[("jacobi", 0)] if ("jacobi", 0) in series else series[("jacobi", 1)]
        mono_times = next(r for r in fixed[1][::-1] if r is not None)["time"]
        say("monolithic tolerance sweep ...")
        try:
            mono = in_child(mono_sweep, scene, stop, mono_times, ref, keys,
                            MONO_RTOLS[:4] if quick else MONO_RTOLS, timeout=900)
        except ChildFailed as err:
            mono = [{"rtol": math.nan, "error": f"tolerance sweep: {err}"}]
    out = {"scene": scene, "stop": stop, "keys": keys, "steps": steps, "series": series, "fmpy": fm_rows,
           "fmpy_late": fm_late, "settle": settle,
           "fmpy_dropped": fm[0].get("dropped", []) if fm else [], "fmpy_first": _first_rows(fm, keys),
           "reference": ref, "mono": mono, "mono_times": mono_times}
    if libcosim:
        out["libcosim"], out["notes"], out["libcosim_start"] = lc, notes, start
        if repeats > 1:
            repeat_walls(out, repeats, say)
    return out


def _first_rows(fm: list[dict], keys) -> str:
    """What simulate_ssp's start from all-zero connectors does to the first recorded values."""
    f = next((f for f in fm if "cols" in f), None)
    if f is None:
        return "no result"
    return "; ".join(f"{k}: {', '.join(f'{v:.4g}' for v in f['cols'][k][:3])}" for k in f["cols"])


def cheapest(rows, level: float):
    ok = [r for r in rows if r.failure is None and r.worst_rel <= level]
    return min(ok, key=lambda r: r.wall_time) if ok else None


# --- report --------------------------------------------------------------------------------------------
def machine() -> list[str]:
    import fmpy
    import pythonfmu
    import scipy

    cpu = "unknown"
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "src"], cwd=ROOT, capture_output=True,
                           text=True).stdout.strip()
    return [f"- date: {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, commit {commit}"
            + (" (src/ has uncommitted changes of other engineers)" if dirty else ""),
            f"- machine: {platform.platform()}, {cpu}, {os.cpu_count()} cores, pinned to core(s) "
            f"{sorted(os.sched_getaffinity(0))}",
            f"- python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
            f"fmpy {fmpy.__version__}, pythonfmu {pythonfmu.__version__}"]


def fmt(x, spec=".3g"):
    return "-" if x is None or (isinstance(x, float) and (math.isnan(x))) else format(x, spec)


def scene_report(s: dict) -> list[str]:
    ref = s["reference"]
    out = [f"## {s['scene']} ({s['stop']:g} s simulated; key outputs {', '.join(s['keys'])})", "",
           f"Reference: {ref.kind} ({'scipy Radau/solve rtol 1e-10' if ref.kind == 'monolithic' else 'finest run'},"
           f" {ref.wall_time:.2f} s). Error = worst over the key outputs of max|y - y_ref| / range(y_ref).", "",
           "| method | H [s] | worst rel err | order | steps | wall [s] | RTF |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for (alg, ex), (runs, _) in s["series"].items():
        for r in runs:
            wk = r.worst_key
            out.append(f"| master {alg} x{ex} | {r.label[2:] if r.tolerance is None else r.label} | {fmt(r.worst_rel)} | "
                       f"{fmt(r.order.get(wk) if wk else None, '.2f')} | {r.steps} | {fmt(r.wall_time, '.3f')} | "
                       f"{fmt(r.real_time_factor, '.1f')} |" + (f" FAILED: {r.failure[:80]}" if r.failure else ""))
    for r in s["fmpy"]:
        wk = r.worst_key
        out.append(f"| fmpy simulate_ssp | {r.step_size:g} | {fmt(r.worst_rel)} | "
                   f"{fmt(r.order.get(wk) if wk else None, '.2f')} | {r.steps} | {fmt(r.wall_time, '.3f')} | "
                   f"{fmt(s['stop'] / r.wall_time if r.wall_time else None, '.1f')} |"
                   + (f" FAILED: {r.failure[:120]}" if r.failure else ""))
    for r in s["fmpy_late"]:
        wk = r.worst_key
        if r.failure is None:
            out.append(f"| fmpy simulate_ssp, t >= {s['settle']:g} s only | {r.step_size:g} | {fmt(r.worst_rel)} | "
                       f"{fmt(r.order.get(wk) if wk else None, '.2f')} | {r.steps} | {fmt(r.wall_time, '.3f')} | "
                       f"{fmt(s['stop'] / r.wall_time if r.wall_time else None, '.1f')} |")
    for m in s["mono"]:
        if "error" in m:
            out.append(f"| monolithic rtol {m['rtol']:g} | - | FAILED {m['error'][:80]} | | | | |")
        else:
            out.append(f"| monolithic rtol {m['rtol']:g} | - | {fmt(m['worst'])} | - | - | {m['wall']:.3f} | "
                       f"{s['stop'] / m['wall']:.1f} |")
    out += ["", f"fmpy simulate_ssp: starts every connector at 0.0 (first three recorded values: "
            f"{s['fmpy_first']}); parameters it cannot set (no String support, left at the FMU default): "
            f"{', '.join(s['fmpy_dropped']) or 'none'}; it labels the values after a step with the step's start "
            "time, so its times were shifted by +H before comparing.", "",
            "Equal accuracy (cheapest run of each method meeting the level):", "",
            "| level | master (setting, wall s) | fmpy (H, wall s) | monolithic (rtol, wall s) | fmpy / master | "
            "monolithic / master |", "| --- | --- | --- | --- | --- | --- |"]
    all_master = [(f"{a} x{e} {r.label}", r) for (a, e), (runs, _) in s["series"].items() for r in runs]
    settle = s["settle"]
    for level in LEVELS:
        ok = [(n, r) for n, r in all_master if r.failure is None and r.worst_rel <= level]
        best = min(ok, key=lambda p: p[1].wall_time) if ok else None
        f = cheapest(s["fmpy"], level)
        fl = cheapest(s["fmpy_late"], level)
        ms = [m for m in s["mono"] if "worst" in m and m["worst"] <= level]
        m = min(ms, key=lambda m: m["wall"]) if ms else None
        bw = best[1].wall_time if best else None
        out.append(f"| {level:g} | {best[0] + f', {bw:.3f}' if best else 'none'} | "
                   f"{f'H={f.step_size:g}, {f.wall_time:.3f}' if f else 'none'}"
                   f"{f' (t >= {settle:g} s only: H={fl.step_size:g}, {fl.wall_time:.3f})' if fl else ''} | "
                   f"{format(m['rtol'], 'g') + ', ' + format(m['wall'], '.3f') if m else 'none'} | "
                   f"{fmt(f.wall_time / bw if f and bw else None, '.2f')}"
                   f"{' (' + fmt(fl.wall_time / bw, '.2f') + ')' if fl and bw else ''} | "
                   f"{fmt(m['wall'] / bw if m and bw else None, '.2f')} |")
    same = []
    jac = {r.step_size: r for r in s["series"][("jacobi", 0)][0]}
    for f in s["fmpy"]:
        r = jac.get(f.step_size)
        if r and r.failure is None and f.failure is None:
            same.append(f"H={f.step_size:g}: wall fmpy/master {f.wall_time / r.wall_time:.2f}, "
                        f"error fmpy/master {f.worst_rel / r.worst_rel:.2f}")
    out += ["", "Same H, master Jacobi x0 against fmpy (the same algorithm): " + ("; ".join(same) or "no pair"), ""]
    adaptive = s["series"].get(("jacobi adaptive", 1), ([], []))[0]
    fixed = s["series"][("jacobi", 1)][0]
    for a in adaptive:
        if a.failure is None:
            f = [r for r in fixed if r.failure is None and r.worst_rel <= a.worst_rel]
            best = min(f, key=lambda r: r.steps) if f else None
            out.append(f"- adaptive Jacobi x1 {a.label}: error {a.worst_rel:.3g} in {a.steps} steps "
                       f"({a.rejections} rejected); cheapest fixed Jacobi x1 at least as accurate: "
                       + (f"{best.label}, {best.steps} steps" if best else "none of the fixed steps run"))
    out.append("")
    return out


def write_csv(scenes: list[dict], path: Path, target: dict | None = None) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "method", "setting", "worst_rel", "steps", "wall_time", "failure"])
        for r, label in zip(*(target or {}).get("runs", ([], []))):
            w.writerow([target["scene"], f"target {label} ({r.simulated:g} s)", r.step_size, r.worst_rel, r.steps,
                        r.wall_time, r.failure or ""])
        for s in scenes:
            for (alg, ex), (runs, _) in s["series"].items():
                for r in runs:
                    w.writerow([s["scene"], f"master {alg} x{ex}", r.step_size, r.worst_rel, r.steps, r.wall_time,
                                r.failure or ""])
            for r in s["fmpy"]:
                w.writerow([s["scene"], "fmpy simulate_ssp", r.step_size, r.worst_rel, r.steps, r.wall_time,
                            r.failure or ""])
            for m in s["mono"]:
                w.writerow([s["scene"], "monolithic", m["rtol"], m.get("worst"), "", m.get("wall"),
                            m.get("error", "")])
        w.writerows(side_csv_rows(scenes))


def side_csv_rows(scenes: list[dict]) -> list[list]:
    """The side-by-side block's rows (method prefixed with SIDE_PREFIX; walls are medians)."""
    rows = []
    for s in scenes:
        if "libcosim" not in s:
            continue
        for name, setting, r in side_rows(s):
            rows.append([s["scene"], f"{SIDE_PREFIX}{name} ({s['stop']:g} s)", setting, r.worst_rel, r.steps,
                         r.wall_time, r.failure or ""])
        for m in s["mono"]:
            rows.append([s["scene"], f"{SIDE_PREFIX}monolithic ({s['stop']:g} s)", f"rtol={m['rtol']:g}",
                         m.get("worst"), "", m.get("wall"), m.get("error", "")])
    return rows


def merge_side_results(done: list[dict], notes: list[str]) -> None:
    """--libcosim-only: replace the side-by-side block of speed_accuracy.md (or add it) and its rows
    of speed_accuracy.csv, leaving every other section's results as they were."""
    md, path = RESULTS / "speed_accuracy.md", RESULTS / "speed_accuracy.csv"
    block = "\n".join(side_block(done, notes))
    text = md.read_text() if md.exists() else "# Speed against accuracy\n\n"
    if SIDE_BEGIN in text and SIDE_END in text:
        before, rest = text.split(SIDE_BEGIN, 1)
        text = before + block.rstrip("\n") + rest.split(SIDE_END, 1)[1]
    else:
        text = text.rstrip("\n") + "\n\n" + block
    md.write_text(text)
    header, kept = ["scene", "method", "setting", "worst_rel", "steps", "wall_time", "failure"], []
    if path.exists():
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
        header, kept = rows[0], [r for r in rows[1:] if not r[1].startswith(SIDE_PREFIX)]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(kept + side_csv_rows(done))


def plot_scene(s: dict, path: Path) -> None:
    from cranefmu.analysis.converge import plot

    series = {f"master {a} x{e}": runs for (a, e), (runs, _) in s["series"].items()}
    series["fmpy simulate_ssp"] = s["fmpy"]
    from cranefmu.analysis.converge import ConvergenceRun

    mono = []
    for m in s["mono"]:
        if "worst" in m:
            r = ConvergenceRun(math.nan, m["rtol"])
            r.wall_time, r.rel_err = m["wall"], {"worst": m["worst"]}
            mono.append(r)
    if mono:
        series["monolithic (rtol)"] = mono
    plot(series, path, LEVELS[0], f"{s['scene']}: error against wall time (one core)")


def profile_report(scene: str, stop: float, h: float, say) -> list[str]:
    """cProfile of one run: the top functions by own time (profile.txt) and own time per layer."""
    say(f"profile {scene} H={h:g} ...")
    p = in_child(profile_run, scene, stop, h, "jacobi", 0)
    (RESULTS / "profile.txt").write_text(f"cProfile of cranefmu.master.run.run({scene!r}, stop_time={stop}, "
                                         f"step_size={h}, jacobi, extrapolation 0), sorted by own time\n\n"
                                         + p["text"])
    return [f"## Profile: {scene}, H = {h:g} s, {stop:g} s simulated, Jacobi x0 (cProfile)", "",
            f"cProfile inflates Python-side time and does not see the ctypes calls themselves (the hot-path table "
            f"above is the measurement); run {p['total']:.2f} s with setup {p['setup']:.2f} s. Own time by layer: "
            + "; ".join(f"{k} {v:.2f} s ({v / p['total'] * 100:.0f} %)"
                        for k, v in sorted(p["by_layer"].items(), key=lambda kv: -kv[1])) + ".",
            "", "Top functions by own time: benchmarks/results/profile.txt.", ""]


TARGET_SETTINGS = (("jacobi", 1, 2e-2), ("jacobi", 1, 1e-2), ("jacobi", 1, 5e-3), ("jacobi", 0, 1e-2),
                   ("jacobi", 0, 5e-3))


def rtf_target_report(say, hot: dict, scene: str = "truck_telescope", stop: float = 30.0,
                      settings: tuple = TARGET_SETTINGS, level: float = 1e-2) -> tuple[list[str], dict]:
    """Issue 6's speed target: the scene over ``stop`` s within ``level`` of each key output's range, as
    fast as possible (each (algorithm, extrapolation, H) of ``settings``; the error against the finest
    run, Jacobi x1 at the smallest H / 4)."""
    from cranefmu.analysis import converge as cv

    keys = cv.key_outputs(scene)
    runs, results, labels, notes = [], [], [], []
    for alg, ex, h in settings:
        row, res = master_runs(scene, [(h, None)], stop, alg, ex, say)
        if row[0].failure and "instability_alarm=False" in row[0].failure:  # stopped by the alarm, not a blow-up
            notes.append(f"{alg} x{ex} H={h:g} with the default instability alarm: {row[0].failure[:200]}; "
                         "run again with the alarm off")
            row, res = master_runs(scene, [(h, None)], stop, alg, ex, say, instability_alarm=False)
        runs.append(row[0])
        results.append(res[0])
        labels.append(f"{alg} x{ex}")
    h_ref = min(h for _, _, h in settings) / 2
    try:  # the monolithic solve: an error every co-simulation shares (e.g. first order in H) shows against it
        say("monolithic reference for the target runs (child, 900 s limit) ...")
        ref = in_child(cv.Reference.monolithic, scene, keys, stop, [r for r in results if r is not None],
                       timeout=900)
        ref_text = f"the monolithic solve (scipy, rtol 1e-10, {ref.wall_time:.1f} s wall)"
    except (cv.CraneFmuError, ChildFailed, NotImplementedError, KeyError) as err:
        say(f"no monolithic reference ({err}); the finest co-simulation instead")
        ref = cv.Reference.finest(scene, keys, stop, h_ref, "jacobi", 1, progress=say, instability_alarm=False)
        ref_text = f"the finest run (Jacobi x1, H = {h_ref:g} s, {ref.wall_time:.1f} s wall)"
    for r, res in zip(runs, results):
        if res is not None:
            cv.measure(r, res, ref.at(res["time"]), keys)
    out = [f"## Target: {scene}, {stop:g} s simulated, key outputs within {level:g} of their range, >= 20x real time",
           "", f"Error against {ref_text}. Wall time includes setup (load, instantiate, initialize).", "",
           "| method | H [s] | worst rel err | worst key | steps | wall [s] | RTF | meets 1 %? |",
           "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r, label in zip(runs, labels):
        ok = r.failure is None and r.worst_rel <= level
        out.append(f"| {label} | {r.step_size:g} | {fmt(r.worst_rel)} | {r.worst_key or '-'} | {r.steps} | "
                   f"{fmt(r.wall_time, '.2f')} | {fmt(r.real_time_factor, '.2f')} | {'yes' if ok else 'no'} |"
                   + (f" FAILED: {r.failure[:160]}" if r.failure else ""))
    good = [r for r in runs if r.failure is None and r.worst_rel <= level]
    best = max(good, key=lambda r: r.real_time_factor) if good else None
    out += [""] + [f"- {n}" for n in notes]
    summary = {"best": best, "runs": (runs, labels), "scene": scene}
    if best is not None:
        out.append(f"- Best: {labels[runs.index(best)]} at H = {best.step_size:g} s, error {best.worst_rel:.3g} of range, "
                   f"**RTF {best.real_time_factor:.2f}** (target 20).")
    hp = hot.get(scene)
    if hp is not None:
        n = max(hp["steps"], 1)
        fmi_step = sum(sec for sec, _ in hp["fmi"].values()) / n
        do_step = {}
        for (inst, fn), (sec, _) in hp["fmi"].items():
            if fn == "DoStep":
                do_step[inst] = sec / n
        need = hp["h"] / 20
        out.append(f"- What bounds it: at H = {hp['h']:g} s one macro step spends {fmi_step * 1e6:.0f} us inside the FMI "
                   f"calls (doStep per FMU: " + ", ".join(f"{k} {v * 1e6:.0f} us" for k, v in
                                                        sorted(do_step.items(), key=lambda kv: -kv[1]))
                   + f") and {hp['master_ratio'] * fmi_step * 1e6:.0f} us in the master; 20x real time at this H "
                   f"allows {need * 1e6:.0f} us per step in all. Even a master costing nothing stays at RTF "
                   f"{hp['h'] / fmi_step:.1f}; the FMUs' internal integration (doStep) dominates, see the call-cost "
                   "table for the cost of one pythonfmu call.")
        summary["fmi_step"] = fmi_step
    return out + [""], summary


def call_cost_report(scene: str, say) -> list[str]:
    from cranefmu.build import FMU_DIR

    out = ["## Cost of one pythonfmu call (setReal all inputs + doStep 1 ms + getReal all outputs)", "",
           "| FMU | inputs | outputs | set+step+get [us] | doStep | setReal | getReal | raw ctypes set+step+get |",
           "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    from fmpy import read_model_description

    for fmu in sorted(FMU_DIR.glob("*.fmu")):
        try:
            if read_model_description(str(fmu), validate=False).fmiVersion != "2.0":
                continue  # FMI 3 builds of the same components: not what the master runs
        except Exception:
            continue
        say(f"call cost {fmu.stem} ...")
        try:
            c = in_child(call_cost, str(fmu), timeout=300)
        except Exception as err:  # an FMU that does not load is one row, not the end of the table
            c = {"fmu": fmu.stem, "inputs": "-", "outputs": "-", "error": f"{type(err).__name__}: {err}"}
        if "error" in c:
            out.append(f"| {c['fmu']} | {c['inputs']} | {c['outputs']} | failed: {c['error'][:80]} | | | | |")
            continue
        out.append(f"| {c['fmu']} | {c['inputs']} | {c['outputs']} | {c['set+step+get']:.1f} | {c['doStep']:.1f} | "
                   f"{c['setReal']:.1f} | {c['getReal']:.1f} | {c['raw set+step+get']:.1f} |")
    return out + [""]


def memory_report(scene: str, quick: bool, say) -> list[str]:
    lengths = (2.0, 8.0) if quick else (5.0, 20.0, 40.0)
    rows = []
    for stop in lengths:
        say(f"memory {scene} {stop:g} s at 1 ms ...")
        rows.append(in_child(memory_run, scene, stop, 1e-3))
    out = [f"## Memory: {scene} at H = 1 ms, keep=False, CSV streamed", "",
           "| simulated [s] | steps | wall [s] | CSV [MB] | rows kept | peak RSS [MB] | RSS at end [MB] |",
           "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        out.append(f"| {r['stop']:g} | {r['steps']} | {r['wall']:.2f} | {r['csv_bytes'] / 1e6:.1f} | {r['rows_kept']} | "
                   f"{r['peak_rss_mb']:.1f} | {r['end_rss_mb']:.1f} |")
    slope = (rows[-1]["peak_rss_mb"] - rows[0]["peak_rss_mb"]) / (rows[-1]["stop"] - rows[0]["stop"])
    per_step = rows[-1]["wall"] / rows[-1]["steps"]
    out += ["", f"Peak RSS grows {slope * 1000:.2f} MB per 1000 s simulated (fit between the shortest and longest "
            f"run): one simulated hour at 1 ms (3.6e6 steps) extrapolates to {rows[-1]['peak_rss_mb'] + slope * (3600 - rows[-1]['stop']):.0f} MB "
            f"peak, {3.6e6 * per_step / 60:.0f} min wall and "
            f"{rows[-1]['csv_bytes'] / rows[-1]['stop'] * 3600 / 1e9:.2f} GB of CSV.", ""]
    return out


def targets_summary(done: list[dict], hot: dict, target: dict | None) -> list[str]:
    """Issue 6's targets against what this run measured (read from the sections below)."""
    out = ["## Summary against the targets of issue 6 (this run)", "", "| target | measured | met? |", "| --- | --- | --- |"]
    if target is not None:
        best = target.get("best")
        out.append(f"| truck_telescope 30 s within 1 % of range at >= 20x real time | "
                   + (f"RTF {best.real_time_factor:.2f} at H = {best.step_size:g} s (error {best.worst_rel:.2g} of range); "
                      if best else "no run met 1 %; ")
                   + (f"{target['fmi_step'] * 1e6:.0f} us per macro step inside the FMI calls (section 'Target') | "
                      if "fmi_step" in target else "| ")
                   + ("yes" if best and best.real_time_factor >= 20 else "no") + " |")
    if hot:
        ratios = ", ".join(f"{k} {v['master_ratio'] * 100:.0f} %" for k, v in hot.items())
        out.append(f"| master overhead <= 25 % of the time inside the FMI calls at equal H | {ratios} (hot-path table) | "
                   + ("yes" if all(v["master_ratio"] <= 0.25 for v in hot.values()) else
                      "partly" if any(v["master_ratio"] <= 0.25 for v in hot.values()) else "no") + " |")
    for level in LEVELS[:1] if done else ():
        fm, mo = [], []
        for s in done:
            all_master = [r for runs, _ in s["series"].values() for r in runs]
            best = cheapest(all_master, level)
            f = cheapest(s["fmpy"], level)
            ms = [m for m in s["mono"] if "worst" in m and m["worst"] <= level]
            m = min(ms, key=lambda m: m["wall"]) if ms else None
            fm.append(f"{s['scene']}: " + (f"fmpy/master {f.wall_time / best.wall_time:.2f}" if f and best else
                                          "fmpy reaches it at no H run" if best else "master does not reach it"))
            mo.append(f"{s['scene']}: " + (f"monolithic/master {m['wall'] / best.wall_time:.2f}" if m and best else
                                          "no monolithic run reaches it" if best else "master does not reach it"))
        out.append(f"| >= 5x less wall than fmpy simulate_ssp at equal accuracy ({level:g} of range) | {'; '.join(fm)} | "
                   "see the scene sections |")
        out.append(f"| no slower than the monolithic solve at equal accuracy ({level:g}) | {'; '.join(mo)} | "
                   "see the scene sections |")
    ad = []
    for s in done:
        for a in s["series"].get(("jacobi adaptive", 1), ([], []))[0]:
            if a.failure is None:
                f = [r for r in s["series"][("jacobi", 1)][0] if r.failure is None and r.worst_rel <= a.worst_rel]
                b = min(f, key=lambda r: r.steps) if f else None
                ad.append(f"{s['scene']} {a.label}: {a.steps} steps vs " + (f"{b.steps}" if b else "no fixed run as accurate"))
                break
    if ad:
        out.append(f"| adaptive: fewer macro steps than the cheapest fixed step that meets the tolerance | {'; '.join(ad)} | "
                   "see the scene sections |")
    return out + [""]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="3 s runs, 3 steps, 4 monolithic tolerances, short memory runs")
    ap.add_argument("--profile", action="store_true", help="cProfile of the hot path and the per-call cost")
    ap.add_argument("--scenes", default=None, help="comma-separated scenes (default: every scene with key outputs)")
    ap.add_argument("--stop-time", type=parse_stop_times, default={}, help="simulated length of every run [s] "
                    "(default 10 s, truck_telescope 30 s; --quick 3 s); per scene: e.g. 10,overhead_lift=2")
    ap.add_argument("--steps", default=None, help="macro steps, comma-separated (default 4e-3,2e-3,1e-3)")
    ap.add_argument("--algorithms", default=None, help="comma-separated (default all; jacobi is always run)")
    ap.add_argument("--extrapolations", default="0,1,2", help="orders, comma-separated (default 0,1,2)")
    ap.add_argument("--no-target", action="store_true", help="skip the truck_telescope 30 s real-time target runs")
    ap.add_argument("--cpu", type=int, default=None, help="core to pin to (default: the last allowed)")
    ap.add_argument("--output", default=None, help="results directory (default benchmarks/results)")
    ap.add_argument("--libcosim-only", action="store_true", help="only the side-by-side block (libcosim fixed and "
                    "ECCO, ours fixed/adaptive/ECCO, monolithic); replaces that block in the results files")
    ap.add_argument("--no-libcosim", action="store_true", help="skip the libcosim side-by-side runs")
    ap.add_argument("--repeats", type=int, default=None, help="runs per side-by-side setting, wall = median "
                    "(default 3 with --libcosim-only, else 1)")
    args = ap.parse_args(argv)
    global RESULTS
    RESULTS = Path(args.output) if args.output else RESULTS
    RESULTS.mkdir(parents=True, exist_ok=True)
    cpu = args.cpu if args.cpu is not None else max(os.sched_getaffinity(0))
    os.sched_setaffinity(0, {cpu})  # children inherit it

    from cranefmu.scenes import SCENES

    names = args.scenes.split(",") if args.scenes else [n for n in SCENES if (ROOT / "ssp" / n).is_dir()]
    algorithms = tuple(dict.fromkeys(["jacobi", *args.algorithms.split(",")])) if args.algorithms else None
    extrapolations = tuple(int(x) for x in args.extrapolations.split(","))

    def say(text: str) -> None:
        print(f"[{clock.strftime('%H:%M:%S')}] {text}", file=sys.stderr, flush=True)

    wall0 = clock.perf_counter()
    with_libcosim = not args.no_libcosim and libcosim_available()
    repeats = args.repeats or (3 if args.libcosim_only else 1)
    if args.libcosim_only:
        if not libcosim_available():
            print("--libcosim-only: libcosimpy is not installed (pip install -e '.[interop]')", file=sys.stderr)
            return 2
        return side_by_side_main(args, names, repeats, say, wall0, argv)
    head = ["# Speed against accuracy", "", *machine(), f"- mode: {'quick' if args.quick else 'full'}", "",
            "Command: `.venv/bin/python benchmarks/speed_accuracy.py " + " ".join(argv or sys.argv[1:]) + "`", "",
            "The machine is shared (2 cores, several engineers' jobs): absolute times are inflated and noisy; "
            "compare the ratios measured in one run.", ""]
    body: list[str] = []
    summary: list[str] = []

    def save() -> None:  # a cut-off run keeps what it had
        (RESULTS / "speed_accuracy.md").write_text("\n".join(head + summary + body) + "\n")

    # where the time goes, first: it is short and the other sections refer to it
    cases = [(n, 5.0 if n == "truck_telescope" else 2.0, 1e-2 if n == "truck_telescope" else 1e-3) for n in names]
    hot_lines, hot = hot_path_report(cases, say)
    body += hot_lines
    save()
    target = None
    if "truck_telescope" in names and not args.no_target:
        try:
            lines, target = rtf_target_report(say, hot)
        except Exception as err:
            lines = ["## Target: truck_telescope 30 s", "", f"FAILED: {type(err).__name__}: {str(err)[:300]}", ""]
        body += lines
    done: list[dict] = []
    summary = targets_summary(done, hot, target)
    write_csv(done, RESULTS / "speed_accuracy.csv", target)
    save()
    sections = []
    if args.profile and names:
        scene = "truck_telescope" if "truck_telescope" in names else names[0]
        h = 1e-2 if scene == "truck_telescope" else 1e-3
        sections += [("Profile", lambda scene=scene, h=h: profile_report(scene, 2.0 if args.quick else 5.0, h, say)),
                     ("Call cost", lambda scene=scene: call_cost_report(scene, say))]
    if names:
        mem = "elastic_pendulum" if "elastic_pendulum" in names else names[0]
        sections.append(("Memory", lambda: memory_report(mem, args.quick, say)))
    for title, section in sections:
        try:
            body += section()
        except Exception as err:  # reported, and the other sections still run
            body += [f"## {title}", "", f"FAILED: {type(err).__name__}: {str(err)[:300]}", ""]
        save()
    side_notes = [f"Load when measured (uptime at the start): {load_average()}."]
    for name in names:
        try:
            s = study_scene(name, args.quick, say, args.stop_time.get(name, args.stop_time.get(None)),
                            [float(x) for x in args.steps.split(",")] if args.steps else None,
                            algorithms, extrapolations, libcosim=with_libcosim, repeats=repeats)
        except Exception as err:  # one scene failing must not lose the others
            body += [f"## {name}", "", f"FAILED: {type(err).__name__}: {str(err)[:300]}", ""]
            continue
        done.append(s)
        body += scene_report(s)
        plot_scene(s, RESULTS / f"speed_accuracy_{name}.png")
        write_csv(done, RESULTS / "speed_accuracy.csv", target)
        summary = targets_summary(done, hot, target)
        save()
    summary = targets_summary(done, hot, target)
    if with_libcosim and done:
        body += side_block(done, side_notes + [f"Load at the end: {load_average()}."])
    body += [f"Benchmark wall time {clock.perf_counter() - wall0:.0f} s.", ""]
    save()
    print("\n".join(head + summary + body))
    return 0


def load_average() -> str:
    """The machine's load as `uptime` prints it (the machine is shared)."""
    try:
        return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    except OSError:
        return "load averages " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def side_by_side_main(args, names: list[str], repeats: int, say, wall0: float, argv) -> int:
    """--libcosim-only: the side-by-side runs of every scene, merged into the results files."""
    steps = [float(x) for x in args.steps.split(",")] if args.steps else None
    notes = [f"Command: `.venv/bin/python benchmarks/speed_accuracy.py {' '.join(argv or sys.argv[1:])}` "
             f"({datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, {repeats} repeat(s)); "
             + "; ".join(machine()[1:]).replace("- ", ""),
             f"Load when measured (uptime at the start): {load_average()}."]
    done = []
    for name in names:
        try:
            done.append(study_scene(name, args.quick, say, args.stop_time.get(name, args.stop_time.get(None)), steps, ("jacobi",), (1, 2), fmpy=False,
                                    libcosim=True, repeats=repeats))
        except Exception as err:  # one scene failing must not lose the others
            notes.append(f"{name} FAILED: {type(err).__name__}: {str(err)[:300]}")
        merge_side_results(done, notes + [f"Load so far: {load_average()}."])
    notes += [f"Load at the end: {load_average()}.",
              f"Side-by-side wall time {clock.perf_counter() - wall0:.0f} s."]
    merge_side_results(done, notes)
    print("\n".join(side_block(done, notes)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
