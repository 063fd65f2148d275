"""Conformance of a native FMU with its pythonfmu twin: both driven through the same FMI call sequence.

A :class:`Case` is one call sequence: parameters (a switch by name or code), inputs that move as
``base + amp sin(w t + phi)`` with their exact rates set on ``<input>_dt``/``_dt2`` (or held), doSteps,
a tunable parameter changed mid-run, and an FMU-state rollback: the state saved at one third of the run
is restored at two thirds (once from memory, once serialized and deserialized) and the rest is run again.
:func:`drive_all` runs a list of cases on one FMU (the pythonfmu FMU in a spawned child: it cannot be
instantiated again in a process after an instance was freed) and records every output after every step,
and every message; :func:`check_agreement` asserts that the two FMUs agree to ``rtol`` relative to each
output's largest magnitude, refuse the same parameters with the same message, and that each one replays
its own rollback to the last bit.

Use (porters and the wiring add cases here or in their tests)::

    from conformance import Case, conform
    conform("Girder", [Case({"solver": "rk4"}, wiggle={"Fy_rope": 1e4})], tmp_path)
"""
from __future__ import annotations

import math
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

RTOL = 1e-12
#: rk45 (scipy's RK45 in C, plain sums for BLAS's dot products) while both FMUs take the same steps
RK45_RTOL = 1e-11


@dataclass
class Case:
    """One FMI call sequence (see the module docstring)."""

    params: dict[str, Any] = field(default_factory=dict)
    inputs: dict[str, float] = field(default_factory=dict)    # base values (default: the start values)
    wiggle: dict[str, float] = field(default_factory=dict)    # amplitude of each input's sine
    steps: int = 30
    h: float = 1e-3
    t0: float = 0.0
    rates: bool = True            # set <input>_dt, _dt2 to the sine's derivatives (else they stay 0)
    tunable: dict[str, Any] = field(default_factory=dict)    # set after half the steps
    rollback: bool = True
    refused: bool = False         # the parameters must be refused at fmi2ExitInitializationMode
    label: str = ""


def _input_value(case: Case, i: int, name: str, base: float, t: float) -> tuple[float, float, float]:
    """(u, du/dt, d2u/dt2) of input ``name`` (the i-th wiggled one) at ``t``."""
    amp = case.wiggle.get(name, 0.0)
    w = 2.0 * math.pi * (3.0 + 1.7 * i)
    phi = 0.3 + 0.9 * i
    s, c = math.sin(w * t + phi), math.cos(w * t + phi)
    return base + amp * s, amp * w * c, -amp * w * w * s


class _Driven:
    """One instance of an FMU with name-based access (fmpy's FMU2Slave) and its messages."""

    def __init__(self, fmu: str, unzipdir: str, instance: str):
        from xml.etree import ElementTree

        from fmpy import calloc, free, read_model_description
        from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                               fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)

        self.md = read_model_description(unzipdir, validate=False)
        self.vars = {v.name: v for v in self.md.modelVariables}
        root = ElementTree.parse(Path(unzipdir) / "modelDescription.xml").getroot()
        self.switches = {v.get("name"): {i.get("name"): int(i.get("value")) for i in v}
                         for v in root.iter("Variable") if v.find("Item") is not None}
        self.messages: list[str] = []

        def logger(env, name, status, category, message):
            if status >= 2:
                self.messages.append(message.decode(errors="replace"))

        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance)
        self.fmu.instantiate(callbacks=self.callbacks, loggingOn=True)
        self.outputs = [v.name for v in self.md.modelVariables if v.causality == "output"]
        self.failed = self.fatal = False

    def fail(self, err: Exception) -> None:
        self.failed = True
        self.fatal = getattr(err, "status", None) == 4   # fmi2Fatal

    def set(self, values: dict[str, Any]) -> None:
        for name, value in values.items():
            var = self.vars[name]
            if var.type == "Real":
                self.fmu.setReal([var.valueReference], [float(value)])
            else:
                code = self.switches.get(name, {}).get(value, value) if isinstance(value, str) else value
                self.fmu.setInteger([var.valueReference], [int(code)])

    def get_outputs(self) -> list[float]:
        out = []
        for name in self.outputs:
            var = self.vars[name]
            vr = [var.valueReference]
            out.append(float(self.fmu.getReal(vr)[0] if var.type == "Real" else self.fmu.getInteger(vr)[0]))
        return out

    def free(self) -> None:
        """Terminate (unless a call failed: FMI 2.0 then allows only the free) and free the instance; the
        library stays loaded (fmpy's freeInstance would unload it under the other instances)."""
        if self.fatal:   # FMI 2.0: no call at all after fmi2Fatal (pythonfmu's status for an exception)
            return
        try:
            if not self.failed:
                self.fmu.terminate()
        finally:
            self.fmu.fmi2FreeInstance(self.fmu.component)


def _inputs_at(d: _Driven, case: Case, t: float) -> dict[str, float]:
    values = {}
    names = [v.name for v in d.md.modelVariables if v.causality == "input" and not v.name.endswith(("_dt", "_dt2"))]
    for i, name in enumerate(names):
        base = case.inputs.get(name, d.vars[name].start)
        base = 0.0 if base is None else float(base)
        u, du, ddu = _input_value(case, i, name, base, t)
        values[name] = u
        if case.rates and f"{name}_dt" in d.vars and name in case.wiggle:
            values[f"{name}_dt"], values[f"{name}_dt2"] = du, ddu
    return values


def _run_case(d: _Driven, case: Case) -> dict:
    rows: list[list[float]] = []
    result = {"outputs": d.outputs, "rows": rows, "error": None, "replay_equal": True}

    def record(t: float) -> None:
        rows.append([t, *d.get_outputs()])

    try:
        d.fmu.setupExperiment(startTime=case.t0)
        d.set(case.params)
        d.fmu.enterInitializationMode()
        d.set(_inputs_at(d, case, case.t0))
        d.fmu.exitInitializationMode()
    except Exception as err:
        result["error"] = "initialization"
        d.fail(err)
        result["messages"] = list(d.messages)
        return result
    record(case.t0)
    k_save, k_restore = case.steps // 3, (2 * case.steps) // 3
    saved = serialized = None
    first_pass: list[list[float]] = []
    try:
        k = 0
        passes = 0
        while k < case.steps:
            t = case.t0 + k * case.h
            if case.rollback and k == k_save and saved is None:
                saved = d.fmu.getFMUstate()
                serialized = d.fmu.serializeFMUstate(saved)
            if case.tunable and k == case.steps // 2:
                d.set(case.tunable)
            d.set(_inputs_at(d, case, t))
            d.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=case.h)
            record(t + case.h)
            k += 1
            if case.rollback and k == k_restore and passes < 2:
                # restore the state saved at k_save (in memory, then deserialized) and run again from there
                first_pass.append(rows[-(k_restore - k_save):])
                if passes == 0:
                    d.fmu.setFMUstate(saved)
                else:
                    state = d.fmu.deSerializeFMUstate(serialized)
                    d.fmu.setFMUstate(state)
                    d.fmu.freeFMUstate(state)
                passes += 1
                k = k_save
        if saved is not None:
            d.fmu.freeFMUstate(saved)
    except Exception as err:
        result["error"] = f"step: {err}"
        d.fail(err)
    n = k_restore - k_save
    if case.rollback and len(first_pass) == 2 and n:
        # rows: ..., pass 0 [k_save, k_restore), replay 1 of it, replay 2 of it + the rest
        start = 1 + k_save
        runs = [rows[start + j * n: start + (j + 1) * n] for j in range(3)]
        result["replay_equal"] = runs[0] == runs[1] == runs[2]
    result["messages"] = list(d.messages)
    return result


def drive_all(fmu: str, cases: list[dict]) -> list[dict]:
    """Run every case (as dicts of :class:`Case` fields) on its own instance of ``fmu``; every instance
    is freed at the end only (pythonfmu: no new instance after a free in the same process)."""
    import tempfile

    from fmpy import extract

    unzipdir = extract(fmu, tempfile.mkdtemp(prefix="cf_conformance_"))
    results, alive = [], []
    try:
        for i, c in enumerate(cases):
            d = _Driven(fmu, unzipdir, f"inst{i}")
            alive.append(d)
            results.append(_run_case(d, Case(**c)))
    finally:
        for d in alive:
            d.free()
    return results


def in_child(func, *args):
    """``func(*args)`` in a fresh spawned process."""
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        return pool.submit(func, *args).result(timeout=600)


# Boom and SlewingBoom: the scenes' sets (ssp/truck_telescope, hook_sway, truck_slewing) across their laws' phases
_TELESCOPE = {"luff_angle": 1.0471975511965976, "boom_length_start": 10.5, "boom_length_end": 22.4, "t_acc": 3.0}
_TIP_LOAD = {"Fy_tip": -3.5e4, "Fx_tip": 1e3}
_BOOM_WIGGLE = {"Fy_tip": 5e3, "Fx_tip": 2e3, "gamma": 2e-3, "y_base": 1e-3, "vy_base": 1e-2, "gamma_rate": 1e-2}
_SLEWING = {"luff_angle": 1.0471975511965976, "boom_length_start": 10.5, "boom_length_end": 10.5,
            "slew_angle_start": 0.0, "slew_angle": 1.5707963267948966, "slew_speed": 0.1, "slew_t_acc": 2.0,
            "slew_start": 1.0}
_SLEWING_WIGGLE = dict(_BOOM_WIGGLE, Fz_tip=2e3, beta=2e-3, beta_rate=1e-2)


# Rope and Drive: the scenes' sets (ssp/elastic_pendulum, hook_sway, overhead_lift, truck_telescope) and the events
_G = 9.81
#: overhead_lift's fitted Bouc-Wen reeving (ssp/overhead_lift/default.ssv), taken up taut at the start
_LIFT_ROPE = {"model": "bouc_wen", "start": "taut", "E": 1.155e11, "A": 5.53e-5, "n_lines": 4, "zeta": 0.07,
              "rho": 7850.0, "k1": 6761493.757911944, "k2": 0.4155514384229589, "k3": 3.1686334600173973,
              "b": 2.0, "c": -130.77152626502237, "alpha": 2177145.2587497463, "beta": 1.2696565576625083,
              "gamma": -1.2238469436969202, "n": 2.868752363232895}
_TELESCOPE_ROPE = {"E": 1.4e11, "run_length": 9.0, "A": 0.00031415926535897936, "zeta": 0.07, "length": 9.09,
                   "n_lines": 2}


def _hanging(length: float, stretch: float, mass: float = 1000.0, n_lines: int = 1, payout: float = 0.0,
             **extra: float) -> dict[str, float]:
    """Rope inputs: top at the origin, the hook ``stretch`` [m] below the unstretched length, load m g."""
    return {"y_hook": -(length + payout / n_lines + stretch), "m_load": mass, "load": mass * _G, "payout": payout,
            **extra}


#: hook bobbing, swinging and the drum paying out: sines on every kinematic input (with their rates)
_ROPE_WIGGLE = {"y_hook": 3e-3, "vy_hook": 0.05, "x_hook": 0.05, "vx_hook": 0.1, "z_hook": 0.02, "y_top": 5e-4,
                "vy_top": 0.01, "payout": 1e-3, "payout_rate": 0.01}


# Girder, Chassis, Chassis4: the scenes' sets (ssp/overhead_lift, truck_telescope, truck_slewing) and the events
#: overhead_lift default and loose (the same girder): the beam's reduced mass, Table 6's stiffnesses
_LIFT_GIRDER = {"mass_model": "beam", "girder_mass": 5000.0, "c1": 4.6e6, "b1": 2.3e4, "c3": 1.8e8, "m3": 280.0,
                "height": 11.005884098464119}
#: the boom's loads and carried inertia on the chassis in truck_telescope (its 40 s run: early, retracted
#: boom; extended boom), swaying with the load
_TT_EARLY = {"Fx_base": 0.0, "Fy_base": -31939.4, "M_base": -149314.8, "m_boom": 755.8, "Sx_boom": 2090.9,
             "J_boom": 32079.3}
_TT_LATE = {"Fx_base": 340.8, "Fy_base": -31953.3, "M_base": -329841.7, "m_boom": 755.8, "Sx_boom": 4877.9,
            "J_boom": 161072.0}
_TT_WIGGLE = {"Fx_base": 300.0, "Fy_base": 3e3, "M_base": 3e4, "Sx_boom": 20.0, "J_boom": 800.0}
#: truck_slewing: the slewing boom's loads on the four pads (roll moment and lateral force while slewing)
_TS = {"Fx_base": 500.0, "Fy_base": -32000.0, "Fz_base": 300.0, "Mx_base": 2e4, "Mz_base": -1.5e5,
       "m_boom": 755.8, "Sx_boom": 2090.9, "Sz_boom": 500.0, "Jp_boom": 3.2e4, "Jr_boom": 5e3, "Jpr_boom": 2e3}
_TS_WIGGLE = {"Fx_base": 300.0, "Fy_base": 3e3, "Fz_base": 300.0, "Mx_base": 3e4, "Mz_base": 3e4, "Sx_boom": 20.0,
              "Sz_boom": 50.0, "Jp_boom": 800.0, "Jr_boom": 500.0, "Jpr_boom": 100.0}
_STRUCTURE_CASES: dict[str, list[Case]] = {
    "Girder": [
        Case(dict(_LIFT_GIRDER), inputs={"Fy_rope": 9810.0}, wiggle={"Fy_rope": 3e3, "Fx_rope": 500.0}, h=2e-3,
             steps=45, label="Girder overhead_lift"),
        Case(dict(_LIFT_GIRDER, solver="rk4", max_step=1e-4), inputs={"Fy_rope": 9810.0},
             wiggle={"Fy_rope": 3e3}, h=2e-3, steps=30, label="Girder overhead_lift rk4"),
        Case({"damping_model": "decrement", "girder_height": 0.5, "span": 20.0}, refused=True,
             label="Girder eq. 10 decrement refused"),
        Case({"mass_model": "beam", "m1": 4000.0}, refused=True, label="Girder m1 with beam refused"),
    ],
    "Chassis": [
        Case({"boom_inertia": "carried"}, inputs=_TT_LATE, wiggle=_TT_WIGGLE, h=0.005, steps=45,
             tunable={"damping": 3e5}, label="Chassis truck_telescope extended (modal exact step)"),
        Case({"boom_inertia": "carried"}, inputs=_TT_EARLY, wiggle=_TT_WIGGLE, h=0.005, steps=45,
             label="Chassis truck_telescope retracted"),
        Case({}, inputs=_TT_LATE, wiggle=_TT_WIGGLE, h=0.005, steps=45, tunable={"damping": 3e5},
             label="Chassis boom inertia neglected (expm exact step)"),
        Case({"boom_inertia": "carried", "solver": "rk4", "h_foot": 2.5}, inputs=_TT_LATE, wiggle=_TT_WIGGLE,
             h=0.005, steps=30, label="Chassis rk4"),
        # the front pad lifting off and touching down (M_base about -3.9e5 unloads it): rk4 around lift-off
        Case({"boom_inertia": "carried"}, inputs=dict(_TT_LATE, M_base=-3.8e5),
             wiggle=dict(_TT_WIGGLE, M_base=4e4), h=0.005, steps=60, label="Chassis front pad lifting"),
        Case({"x_slew": 4.0}, refused=True, label="Chassis x_slew refused"),
        Case({"boom_inertia": 2}, refused=True, label="Chassis boom_inertia code refused"),
    ],
    "Chassis4": [
        Case({"boom_inertia": "carried"}, inputs=_TS, wiggle=_TS_WIGGLE, h=0.005, steps=45,
             tunable={"damping": 3e5}, label="Chassis4 truck_slewing"),
        Case({}, inputs=_TS, wiggle=_TS_WIGGLE, h=0.005, steps=30, label="Chassis4 boom inertia neglected"),
        # the left pads lifting off under the roll moment while the boom is over the side (tipping = 1)
        Case({"boom_inertia": "carried"}, inputs=dict(_TS, Mx_base=2.3e5), wiggle=dict(_TS_WIGGLE, Mx_base=6e4),
             h=0.005, steps=60, label="Chassis4 pads lifting"),
        Case({"pads_per_outrigger": 3}, refused=True, label="Chassis4 pads_per_outrigger refused"),
        Case({"x_slew": -0.5}, refused=True, label="Chassis4 x_slew refused"),
    ],
}


#: the cases every model's native FMU must pass against its pythonfmu FMU (tests/native/test_fmi_layer.py);
#: a porter adds a model here once its harness test passes
MODEL_CASES: dict[str, list[Case]] = {
    "Girder": [
        Case({}, inputs={"Fy_rope": 2e4}, wiggle={"Fy_rope": 1e4}, tunable={"b1": 1e4}, label="exact"),
        Case({"solver": "rk4"}, inputs={"Fy_rope": 2e4}, wiggle={"Fy_rope": 1e4}, tunable={"b1": 1e4}),
        Case({"solver": "rk4", "bearing": "rigid", "mass_model": "beam", "damping_model": "decrement"},
             inputs={"Fy_rope": 2e4}, wiggle={"Fy_rope": 1e4}, rates=False),
        Case({"solver": "euler", "max_step": 2e-4}, inputs={"Fy_rope": 2e4}, wiggle={"Fy_rope": 1e4}),
        Case({"solver": "rk45", "rtol": 1e-9}, inputs={"Fy_rope": 2e4}, wiggle={"Fy_rope": 1e4}, steps=60),
        Case({"c1": -1.0}, refused=True),
        Case({"bearing": 7}, refused=True),
    ],
    "Boom": [
        # truck_telescope default, fast and luff30 across the telescoping law's phase ends (3 s; 20 s, 13.8 s)
        Case(dict(_TELESCOPE), inputs=_TIP_LOAD, wiggle=_BOOM_WIGGLE, t0=2.9, h=0.005, steps=40,
             label="Boom telescoping at t_acc"),
        Case(dict(_TELESCOPE), inputs=_TIP_LOAD, wiggle=_BOOM_WIGGLE, t0=19.9, h=0.005, steps=40,
             label="Boom telescoping end"),
        Case(dict(_TELESCOPE, telescope_speed=0.55), inputs=_TIP_LOAD, wiggle=_BOOM_WIGGLE, t0=13.7, h=0.005,
             steps=40, label="Boom fast"),
        Case(dict(_TELESCOPE, luff_angle=0.5235987755982988), inputs=_TIP_LOAD, wiggle=_BOOM_WIGGLE, h=0.01,
             steps=30, label="Boom luff30"),
        # truck_telescope luffing: the spring-damper cylinder through the luffing law's start, damping tuned
        Case(dict(_TELESCOPE, cylinder="spring_damper", luff_delta=-0.2617993877991494, luff_rate=0.05,
                  luff_t_acc=1.0, luff_start=1.0, boom_length_end=10.5), inputs=_TIP_LOAD, wiggle=_BOOM_WIGGLE,
             t0=0.95, h=0.005, steps=45, tunable={"cylinder_damping": 5e4}, label="Boom luffing"),
        Case(dict(_TELESCOPE, cylinder="spring_damper", solver="euler", max_step=2e-4), inputs=_TIP_LOAD,
             wiggle=_BOOM_WIGGLE, t0=2.95, h=0.005, steps=30, label="Boom elastic euler"),
        # hook_sway default and crane_motion: the kinematic tip, commanded travel, across the steering's start
        Case(dict(_TELESCOPE, tip="kinematic", boom_length_end=10.5), inputs=_TIP_LOAD,
             wiggle={"x_travel": 0.2, "vx_travel": 0.1, "Fy_tip": 5e3}, label="Boom kinematic"),
        Case(dict(_TELESCOPE, tip="kinematic", boom_length_end=10.5, travel_distance=1.0, travel_speed=0.3,
                  travel_t_acc=1.0, steer_delta=0.7853981633974483, steer_rate=0.2, steer_t_acc=1.0,
                  steer_start=6.0), inputs=_TIP_LOAD, t0=5.9, h=0.01, steps=30, label="Boom crane motion"),
        # operator commands (extension_command, luff_command and their rates) on the elastic cylinder
        Case(dict(_TELESCOPE, telescope_source="input", luff_source="input", cylinder="spring_damper"),
             inputs=dict(_TIP_LOAD, extension_command=2.0),
             wiggle=dict(_BOOM_WIGGLE, extension_command=0.5, luff_command=0.05), h=0.005, steps=30,
             label="Boom commanded"),
        Case(dict(_TELESCOPE, t_acc=20.0), refused=True, label="Boom t_acc refused"),
        Case({"cyl_base_angle": 1.2}, refused=True, label="Boom cylinder lever refused"),
        Case({"travel_distance": 1.0}, refused=True, label="Boom travel of a dynamic tip refused"),
        Case({"tip": 2}, refused=True, label="Boom tip code refused"),
    ],
    "SlewingBoom": [
        # truck_slewing default through the slewing law's phases (start 1 s, steady from 3 s, end 16.7 s)
        Case(dict(_SLEWING), inputs=_TIP_LOAD, wiggle=_SLEWING_WIGGLE, t0=0.9, h=0.005, steps=40,
             label="SlewingBoom start"),
        Case(dict(_SLEWING), inputs=_TIP_LOAD, wiggle=_SLEWING_WIGGLE, t0=2.9, h=0.005, steps=40,
             label="SlewingBoom steady"),
        Case(dict(_SLEWING), inputs=_TIP_LOAD, wiggle=_SLEWING_WIGGLE, t0=16.6, h=0.005, steps=40,
             label="SlewingBoom end"),
        Case(dict(_SLEWING, boom_length_end=22.4, t_acc=3.0, luff_delta=0.1, luff_t_acc=1.0), inputs=_TIP_LOAD,
             wiggle=_SLEWING_WIGGLE, t0=2.95, h=0.005, steps=30, label="SlewingBoom telescoping and luffing"),
        Case(dict(_SLEWING, slew_source="input", telescope_source="input", luff_source="input"),
             inputs=dict(_TIP_LOAD, slew_command=0.5),
             wiggle=dict(_SLEWING_WIGGLE, slew_command=0.2, extension_command=0.5, luff_command=0.05),
             label="SlewingBoom commanded"),
        Case({"tip": "kinematic"}, refused=True, label="SlewingBoom kinematic tip refused"),
        Case({"slew_angle": 0.1, "slew_t_acc": 2.0}, refused=True, label="SlewingBoom slew_t_acc refused"),
    ],
    "Rope": [
        # elastic_pendulum: Kelvin-Voigt, the hook bobbing through the unstretched length (slack and re-tension)
        Case({"solver": "rk4"}, inputs=_hanging(10.0, 1e-3), wiggle=_ROPE_WIGGLE, steps=40, tunable={"zeta": 0.3},
             label="Rope Kelvin-Voigt slack and re-tension"),
        Case({"length": 0.4, "E": 1.0e9, "A": 2.0e-5}, inputs=_hanging(0.4, 2e-4), wiggle={"y_hook": 5e-4,
             "vy_hook": 0.02, "x_hook": 0.1}, rates=False, label="Rope hook_sway"),
        # truck_telescope: the series run along the boom, the run growing with the telescoping
        Case(dict(_TELESCOPE_ROPE), inputs=_hanging(9.09, 2e-3, 3500.0, 2, run_extension=1.0),
             wiggle=dict(_ROPE_WIGGLE, run_extension=0.5), label="Rope truck_telescope run"),
        Case(dict(_TELESCOPE_ROPE, start="taut", length=10.0, start_slack=3e-4),
             inputs=_hanging(9.5, 0.0, 2000.0, 2, x_top=1.0), wiggle=_ROPE_WIGGLE, label="Rope Kelvin-Voigt taut"),
        # Bouc-Wen: reversals in the loop, slack and re-tension with z reset, unloading on the zero-force line
        Case({"model": "bouc_wen"}, inputs=_hanging(10.0, 2e-3), wiggle=dict(_ROPE_WIGGLE, y_hook=4e-3), steps=60,
             label="Rope Bouc-Wen reversals and slack"),
        Case({"model": "bouc_wen", "n_lines": 3, "run_length": 4.0}, inputs=_hanging(10.0, 3e-3, 2500.0, 3),
             wiggle={"y_hook": 1e-3, "vy_hook": 0.3, "payout_rate": 0.05}, h=2e-3, steps=45,
             label="Rope Bouc-Wen unloading fast"),
        Case({"model": "bouc_wen", "solver": "euler", "max_step": 1e-4}, inputs=_hanging(10.0, 1e-3),
             wiggle=_ROPE_WIGGLE, label="Rope Bouc-Wen euler"),
        # overhead_lift default and loose: the fitted reeving taken up taut (loose: 0.1 m paid out beyond it)
        Case(dict(_LIFT_ROPE), inputs=_hanging(12.0, 0.0, 1000.0, 4), wiggle=dict(_ROPE_WIGGLE, y_hook=1e-3),
             label="Rope overhead_lift"),
        Case(dict(_LIFT_ROPE, start_slack=0.1), inputs=_hanging(12.0, 0.0, 1000.0, 4),
             wiggle={"y_hook": 0.3, "vy_hook": 0.5, "payout": 0.05}, h=5e-3, steps=40,
             label="Rope overhead_lift loose"),
        Case({"start": "taut", "length": 12.0}, refused=True, label="Rope length with taut refused"),
        Case({"start_slack": 0.1}, refused=True, label="Rope start_slack refused"),
        Case({"model": "bouc_wen", "gamma": 80.0}, refused=True, label="Rope gamma > beta refused"),
        Case({"model": "bouc_wen", "beta": 1.0, "gamma": -1.0}, refused=True, label="Rope beta + gamma refused"),
        Case({"model": 2}, refused=True, label="Rope model code refused"),
    ],
    "Drive": [
        # overhead_lift: the motor starts at 0.2 s with a 0.5 s ramp; steps across the start and into the ramp
        Case({"R_3": 0.25, "n_drum_lines": 2, "start_time": 0.2, "ramp_time": 0.5}, inputs={"drum_force": 2453.0},
             wiggle={"drum_force": 500.0}, t0=0.18, steps=40, tunable={"b_3n": 3e4}, label="Drive overhead_lift"),
        Case({"start_time": 0.01, "ramp_time": 0.0, "brake_delay": 0.012, "start_fraction": 0.2},
             inputs={"drum_force": 1e4}, wiggle={"drum_force": 2e3}, steps=40, rates=False,
             label="Drive direct on line, brake delay"),
        Case({"solver": "euler", "max_step": 2e-5, "start_time": 0.005}, inputs={"drum_force": 5e3},
             wiggle={"drum_force": 1e3}, label="Drive euler"),
        # truck_telescope: the kinematic payout law through all its phases (scaled to fit the run)
        Case({"mode": "kinematic", "n_drum_lines": 1, "payout_speed": 1.212435565298214, "duration": 0.03,
              "t_acc": 0.01, "start_time": 0.002}, inputs={"drum_force": 1.7e4}, wiggle={"drum_force": 3e3},
             steps=40, label="Drive kinematic phases"),
        Case({"mode": "kinematic", "n_drum_lines": 1, "payout_speed": 1.212435565298214, "duration": 20.0,
              "t_acc": 3.0}, inputs={"drum_force": 1.7e4}, t0=2.98, h=0.005, steps=30,
             label="Drive truck_telescope at t_acc"),
        Case({"mode": "kinematic", "payout_speed": -0.35}, inputs={"drum_force": 1e4}, t0=1.0,
             label="Drive kinematic hoisting"),
        Case({"duration": 5.0, "t_acc": 3.0}, refused=True, label="Drive duration refused"),
        Case({"M_k": 100.0}, refused=True, label="Drive M_k refused"),
        Case({"s_k": 0.05}, refused=True, label="Drive s_k refused"),
        Case({"mode": 2}, refused=True, label="Drive mode code refused"),
    ],
    # Chassis4 under a lateral moment whose rest is on three pads: pushed by the wiggle it rocks, the -z pad
    # lifting and landing (pads_lifted 0/1, not tipping); the tipping rest (the resultant 0.2 m beyond the +z
    # edge: two pads off, tipping 1); the carried boom inertia; a refusal
    "Chassis4": [
        Case({}, inputs={"Fy_base": -3.0e4, "Mx_base": 2.3e5, "Mz_base": -1.0e5}, wiggle={"Mx_base": 4e4},
             steps=60, h=2e-3, tunable={"damping": 1e5}, label="Chassis4 rocking on three pads"),
        Case({"boom_inertia": "carried"}, inputs={"Fy_base": -3.0e4, "Mx_base": 2.72e5, "Mz_base": -1.0e5,
                                                   "m_boom": 3000.0, "Sx_boom": 8000.0, "Sz_boom": 4000.0,
                                                   "Jp_boom": 6e4, "Jr_boom": 5e4, "Jpr_boom": 1e3},
             wiggle={"Mz_base": 3e4, "Sz_boom": 500.0}, steps=40, h=2e-3, label="Chassis4 carried, three pads"),
        Case({}, inputs={"Fy_base": -3.0e4, "Mx_base": 2.82e5, "Mz_base": 1.6e5}, steps=20, h=2e-3,
             label="Chassis4 tipping rest"),
        Case({"pads_per_outrigger": 3}, refused=True, label="Chassis4 pads_per_outrigger refused"),
    ],
}
for _name, _cases in _STRUCTURE_CASES.items():
    MODEL_CASES.setdefault(_name, []).extend(_cases)
#: the tolerance of a model where libm or LAPACK and numpy differ (measured; default RTOL).  None now: the Girder's
#: matrix exponential was 1e-11 (scipy's expm against C's) until both took cranefmu.physics.expm's order (issue 33)
MODEL_RTOL: dict[str, float] = {}


# --- building the pair ----------------------------------------------------------------------------

def pythonfmu_fmu(name: str, dest: Path, script: Path | None = None) -> Path:
    """The pythonfmu FMU of ``name``: the checkout's fmus/<name>.fmu when it is current, else built into
    ``dest``."""
    from cranefmu import build as b

    script = script or b.FMU_SOURCES / f"{name}.py"
    current = b.FMU_DIR / f"{name}.fmu"
    if script.parent == b.FMU_SOURCES and current.exists() and not b.fmu_is_stale(script):
        return current
    target = Path(dest) / "python" / f"{name}.fmu"
    if not target.exists():
        target.parent.mkdir(parents=True, exist_ok=True)
        b.build_fmu(script, target)
    return target


def native_fmu(name: str, dest: Path, **kwargs) -> Path:
    """The native FMU of ``name`` built into ``dest``/native (once per ``dest``)."""
    from cranefmu.native.build import build_native_fmu

    target = Path(dest) / "native" / f"{name}.fmu"
    return target if target.exists() else build_native_fmu(name, target.parent, **kwargs)


def fmu_pair(name: str, dest: Path, script: Path | None = None, model_c: Path | None = None) -> tuple[Path, Path]:
    """(native, pythonfmu) FMUs of ``name``."""
    kwargs = {k: v for k, v in (("script", script), ("model_c", model_c)) if v is not None}
    return native_fmu(name, dest, **kwargs), pythonfmu_fmu(name, dest, script)


# --- comparison -----------------------------------------------------------------------------------

def check_agreement(native: dict, python: dict, rtol: float = RTOL, label: str = "") -> float:
    """Assert the two FMUs' records agree (module docstring); returns the largest relative difference."""
    assert (native["error"] is None) == (python["error"] is None), (
        f"{label}: native error {native['error']!r} {native['messages'][-1:]}, "
        f"pythonfmu error {python['error']!r} {python['messages'][-1:]}")
    if native["error"] == "initialization":
        refusal = [m for m in python["messages"] if "refused" in m]
        assert refusal, f"{label}: the pythonfmu FMU logged no refusal: {python['messages']}"
        assert refusal[-1].strip() in [m.strip() for m in native["messages"]], (
            f"{label}: native messages {native['messages']} lack the pythonfmu refusal {refusal[-1]!r}")
        return 0.0
    if native["error"]:   # a failed step: the same failure, the same line
        failed = [m for m in python["messages"] if " failed: " in m]
        assert failed and failed[-1].strip() in [m.strip() for m in native["messages"]], (
            f"{label}: native messages {native['messages']} lack the pythonfmu failure {failed[-1:]}")
    assert native["replay_equal"], f"{label}: the native FMU did not replay its rollback to the last bit"
    assert python["replay_equal"], f"{label}: the pythonfmu FMU did not replay its rollback to the last bit"
    assert native["outputs"] == python["outputs"]
    a, b = np.array(native["rows"]), np.array(python["rows"])
    assert a.shape == b.shape, f"{label}: {a.shape} native rows, {b.shape} pythonfmu rows"
    same = (a == b) | (np.isnan(a) & np.isnan(b))   # equal infinities and NaNs are equal
    finite = np.where(np.isfinite(b), np.abs(b), 0.0)
    scale = np.maximum(np.max(finite, axis=0), 1e-300)
    with np.errstate(invalid="ignore"):
        rel = np.max(np.where(same, 0.0, np.abs(a - b)), axis=0) / scale
    worst = float(np.max(rel)) if rel.size else 0.0
    bad = {name: float(r) for name, r in zip(["time", *native["outputs"]], rel) if not r <= rtol}
    assert not bad, f"{label}: native and pythonfmu differ by more than {rtol:g} relative: {bad}"
    return worst


def conform(name: str, cases: list[Case], dest: Path, rtol: float = RTOL, script: Path | None = None,
            model_c: Path | None = None) -> list[float]:
    """Build (or reuse) both FMUs of ``name`` under ``dest``, drive them through ``cases`` and assert
    agreement; returns each case's largest relative difference."""
    native, python = fmu_pair(name, dest, script, model_c)
    dicts = [asdict(c) for c in cases]
    got_native = in_child(drive_all, str(native), dicts)
    got_python = in_child(drive_all, str(python), dicts)
    return [check_agreement(n, p, rtol, c.label or f"{name} case {i}: {c.params}")
            for i, (c, n, p) in enumerate(zip(cases, got_native, got_python))]
