"""Test helper: run a built scene in another master (libcosim through libcosimpy, fmpy's
``simulate_ssp``) and read back what it applied.  Each function runs in a child process
(``fmu_child.in_child``): pythonfmu FMUs do not survive a second instantiation in one process."""
from __future__ import annotations

import numpy as np

NS = 1_000_000_000  # libcosim's time unit: integer nanoseconds


def _text(name) -> str:
    return name.decode() if isinstance(name, bytes) else str(name)


def libcosim_run(ssp: str, step: float, steps: int, columns: list[str]) -> dict:
    """Run ``ssp`` in libcosim (fixed step, plain Jacobi) for ``steps`` steps of ``step`` [s].

    Returns {"time": [...], column: [...]} for "component.variable" columns read after every step
    (libcosim exposes no values before its first step), "parameters": every parameter's value
    after the run ("component.variable" -> value), and "ok" (False: a step failed)."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(ssp, step_size=int(round(step * NS)))
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    slaves = {_text(s.name): s.index for s in ex.slave_infos()}
    variables = {name: {_text(v.name): v for v in ex.slave_variables(i)} for name, i in slaves.items()}
    real = CosimVariableType.REAL.value

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
