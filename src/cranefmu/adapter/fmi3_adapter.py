"""FMI 3.0 co-simulation binding (pythonfmu3) over the FMI 2.0 adapter of the same FMU.

No physics and no adapter logic of its own: an instance of the FMU's FMI 2.0 class
(:class:`~.fmi_adapter.CraneSlave` subclass, pure Python, never loaded through pythonfmu's binary)
does the work — parameter validation, internal solver, input extrapolation, lazy feedthrough
outputs, state save/restore — and this class only translates the FMI 3.0 calls and types:
Real -> Float64, Integer -> Int32, value reference + 1 (FMI 3 wants the independent variable
``time`` first), ``do_step`` -> :class:`Fmi3StepResult`, log messages with their status.

An FMU script names the FMI 2.0 class::

    class Rope(CraneSlave3, Fmi3Slave):
        fmi2_class = _Rope2

:func:`cranefmu.build.build_fmi3` writes that script and builds ``<Name>3.fmu`` with pythonfmu3's builder.
"""
from __future__ import annotations

from typing import Any, ClassVar
from xml.etree.ElementTree import Element, SubElement

from pythonfmu3 import (DefaultExperiment, Fmi3Causality, Fmi3Initial, Fmi3Slave, Fmi3Status, Fmi3StepResult,
                        Fmi3Variability, Float64, Int32, String)

from . import units

_CAUSALITY = {"parameter": Fmi3Causality.parameter, "input": Fmi3Causality.input, "output": Fmi3Causality.output}
_VARIABILITY = {"fixed": Fmi3Variability.fixed, "tunable": Fmi3Variability.tunable,
                "continuous": Fmi3Variability.continuous, "discrete": Fmi3Variability.discrete}
_STATUS = {0: Fmi3Status.ok, 1: Fmi3Status.warning, 2: Fmi3Status.discard, 3: Fmi3Status.error, 4: Fmi3Status.fatal}


class CraneSlave3(Fmi3Slave):
    """FMI 3.0 co-simulation slave delegating to the FMU's FMI 2.0 adapter (set ``fmi2_class``)."""

    fmi2_class: ClassVar[type]

    def __init__(self, **kwargs: Any):
        super().__init__(**kwargs)
        core = type(self).fmi2_class(instance_name=kwargs["instance_name"], resources=kwargs.get("resources"),
                                     visible=kwargs.get("visible", False), logger=None)
        self._core = core
        self.description = core.description
        self.author = core.author
        de = type(core).default_experiment
        self.default_experiment = DefaultExperiment(start_time=de.start_time, stop_time=de.stop_time,
                                                    step_size=de.step_size)
        self.time = 0.0
        self.register_variable(Float64("time", causality=Fmi3Causality.independent,
                                       variability=Fmi3Variability.continuous, description="simulation time"))
        self._kind: dict[int, str] = {}
        for vr, v in core.vars.items():
            kind = type(v).__name__  # Real, Integer, String
            cls = {"Real": Float64, "Integer": Int32, "String": String}[kind]
            extra = {}
            unit = core._units.get(v.name, "")
            if kind == "Real" and not units.dimensionless(unit):
                extra["unit"] = unit
            initial = Fmi3Initial.exact if v.causality.name == "parameter" else None
            if v.causality.name == "output":
                initial = Fmi3Initial.calculated
            var = cls(v.name, causality=_CAUSALITY[v.causality.name], variability=_VARIABILITY[v.variability.name],
                      initial=initial, description=v.description,
                      getter=(lambda n=v.name: getattr(self._core, n)),
                      setter=(lambda value, n=v.name: setattr(self._core, n, value)), **extra)
            self.register_variable(var)
            self._kind[vr + 1] = kind

    # --- values: through the FMI 2.0 adapter, so its bookkeeping (stale outputs, tunable changes) runs
    def _core_vrs(self, vrs: list[int]) -> list[int]:
        return [vr - 1 for vr in vrs]

    def _forward_log(self) -> None:
        for msg in self._core.log_queue:
            self.log(msg.msg, _STATUS.get(int(msg.status), Fmi3Status.error), msg.category)
        self._core.log_queue.clear()

    def get_float64(self, vrs: list[int]) -> list[float]:
        out = [self.time if vr == 0 else None for vr in vrs]
        rest = [vr for vr in vrs if vr != 0]
        values = iter(self._core.get_real(self._core_vrs(rest)) if rest else [])
        return [v if v is not None else next(values) for v in out]

    def set_float64(self, vrs: list[int], values: list[float]) -> None:
        self._core.set_real(self._core_vrs(vrs), values)
        self._forward_log()

    def get_int32(self, vrs: list[int]) -> list[int]:
        return self._core.get_integer(self._core_vrs(vrs))

    def set_int32(self, vrs: list[int], values: list[int]) -> None:
        self._core.set_integer(self._core_vrs(vrs), values)
        self._forward_log()

    def get_string(self, vrs: list[int]) -> list[str]:
        return self._core.get_string(self._core_vrs(vrs))

    def set_string(self, vrs: list[int], values: list[str]) -> None:
        self._core.set_string(self._core_vrs(vrs), values)
        self._forward_log()

    # --- life cycle -------------------------------------------------------------------------------
    def enter_initialization_mode(self) -> None:
        self._core.setup_experiment(self.time, None, None)
        self._core.enter_initialization_mode()
        self._forward_log()

    def setup_experiment(self, start_time: float) -> None:
        self.time = float(start_time)

    def exit_initialization_mode(self) -> None:
        try:
            self._core.exit_initialization_mode()
        finally:
            self._forward_log()

    def do_step(self, current_time: float, step_size: float) -> Fmi3StepResult:
        ok = self._core.do_step(current_time, step_size)
        self._forward_log()
        if ok:
            self.time = current_time + step_size
        return Fmi3StepResult(status=Fmi3Status.ok if ok else Fmi3Status.discard)

    def terminate(self) -> None:
        self._core.terminate()

    def _get_fmu_state(self) -> dict[str, Any]:
        return {"core": self._core._get_fmu_state(), "time": self.time}

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        self._core._set_fmu_state(state["core"])
        self.time = float(state["time"])

    # --- model description ----------------------------------------------------------------------------
    def to_xml(self, model_options: dict[str, str] = dict()) -> Element:
        """pythonfmu3's description plus unit definitions and output dependencies from the FMI 2.0 one."""
        root = super().to_xml(model_options)
        used = sorted({u for u in (getattr(v, "unit", None) for v in self.vars.values()) if u})
        if used:
            defs = Element("UnitDefinitions")
            for name in used:
                factor, exps = units.parse(name)
                u = SubElement(defs, "Unit", name=name)
                attrs = {k: str(e) for k, e in exps.items()}
                if factor != 1.0:
                    attrs["factor"] = repr(factor)
                SubElement(u, "BaseUnit", attrs)
            after = root.find("CoSimulation")
            root.insert(list(root).index(after) + 1, defs)
        # outputs depend on the inputs the FMI 2.0 adapter declares (value references + 1)
        index = {v.name: vr for vr, v in self.vars.items()}
        deps = {s.name: [index[d] for d in s.depends_on] for s in self._core.physics.outputs}
        params = [vr for vr, v in self.vars.items() if v.causality == Fmi3Causality.parameter]
        for el in root.find("ModelStructure"):
            name = self.vars[int(el.get("valueReference"))].name
            if name in deps:
                own = deps[name] if el.tag == "Output" else sorted(set(deps[name]) | set(params))
                el.set("dependencies", " ".join(str(d) for d in own))
        return root
