"""One pythonfmu slave base class that turns any :class:`~.physics.component.Model` into an FMU.

An FMU script in ``fmus/`` only names its model::

    class Rope(CraneSlave):
        physics = RopeModel

From the model's parameter dataclass and signal tables this class registers the FMI variables
(parameters ``fixed``/``tunable`` with ``initial="exact"``, inputs, and for every coupling input
the extrapolation inputs ``<name>_dt`` and ``<name>_dt2``, outputs), writes units, unit
definitions and the real ``ModelStructure`` (output dependencies, initial unknowns) into the
model description, integrates the internal states with the solver chosen by the ``solver``
parameter, computes feedthrough outputs lazily after inputs change, saves and restores every
internal state, and turns every failure into a logged error status instead of an exception.
"""
from __future__ import annotations

import ctypes
import os
import sys
from operator import itemgetter
from threading import get_ident
from typing import Any, ClassVar
from xml.etree.ElementTree import Element, SubElement

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Integer, Real, String
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

from . import units
from .integrators import ADAPTIVE, AUTO, EXACT, METHODS, integrate, rk4_list
from .pythonfmu_exit import binary_of, release_guard_at_exit
from ..physics.component import Model, check_ports, port_takes
from ..physics.params import ParameterError, allowed_text, check_value, enumeration_text

EXTRAPOLATION_SUFFIXES = ("_dt", "_dt2")  # d/dt and d2/dt2 of a coupling input
ENUMERATIONS_TOOL = "org.cranefmu.enumerations"  # VendorAnnotations tool listing each switch's names
PORTS_TOOL = "org.cranefmu.ports"  # VendorAnnotations tool declaring the mechanical ports (docs/composition.md)
PYTHON_HOST_TOOL = "org.cranefmu.pythonhost"   # VendorAnnotations tool: what a host needs to run this FMU


def scipy_solvers() -> tuple[str, ...]:
    """The ``solver`` values that import scipy (its ``solve_ivp``, at the first step): the adaptive ones.
    Nothing else in an FMU imports scipy (tests/fmu/test_scipy_free.py runs every FMU with scipy blocked)."""
    return ADAPTIVE


def _or_list(names: tuple[str, ...]) -> str:
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} or {names[-1]}"


def python_host_note(physics: type[Model]) -> str:
    """What a host needs to run the pythonfmu FMU of ``physics``, said in its model description (a host
    reads there first; the native FMU drops it): scipy only where an adaptive solver has a moving state."""
    when = physics.state_moves_when
    if when is None:
        scipy = "no setting imports scipy"
    else:
        scipy = f"scipy only with solver = {_or_list(scipy_solvers())}" + (f" and {when}" if when else "")
    return (f"pythonfmu FMU: the host process needs a shared CPython 3.10-3.13 with numpy ({scipy}; a C host "
            "preloads libpython3.X.so, LD_PRELOAD); the native FMU of the same model needs none (cranefmu "
            "docs/fmus.md)")


def python_host_scipy(physics: type[Model]) -> str:
    """The vendor annotation's ``scipy`` attribute: when the FMU of ``physics`` imports scipy."""
    when = physics.state_moves_when
    if when is None:
        return "never"
    return "only with solver = " + " | ".join(scipy_solvers()) + (f" and {when}" if when else "")


_PINNED_LIBRARIES: set[str] = set()   # BLAS/OpenMP libraries of this process already pinned to one thread


def one_blas_thread() -> None:
    """Pin every BLAS and OpenMP thread pool loaded in this process to one thread (threadpoolctl, where
    the host's Python has it; else nothing).  The FMUs' matrices are small: with OpenBLAS's default
    threads the Chassis's matrix exponential cost 3.7x the CPU of one thread (issue 33).  A library
    loaded later (scipy's own OpenBLAS on a first scipy import) is pinned by the next call; a call
    that finds nothing new costs only the scan of the loaded libraries."""
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:
        return
    controller = ThreadpoolController()
    fresh = [lib for lib in controller.lib_controllers if lib.filepath not in _PINNED_LIBRARIES]
    for lib in fresh:
        if lib.num_threads != 1:
            lib.set_num_threads(1)
        _PINNED_LIBRARIES.add(lib.filepath)


def solvers(model: type[Model]) -> tuple[str, ...]:
    """The internal solvers an FMU of ``model`` offers: every integrator, ``exact`` where the model has a
    closed-form step (:meth:`Model.exact_step` overridden), and ``auto`` where that step applies to some
    configurations only (the model's default: ``exact`` where :meth:`Model.exact_applies`, else rk4)."""
    exact = (EXACT,) if model.exact_step is not Model.exact_step else ()
    # "auto" last, so the integer codes of the others (in .ssv files) stay what they were
    return METHODS + exact + ((AUTO,) if model.default_solver == AUTO else ())


class CraneSlave(Fmi2Slave):
    """FMI 2.0 co-simulation adapter over a physics model (set ``physics`` in the subclass)."""

    physics: ClassVar[type[Model]]
    default_solver: ClassVar[str] = "rk4"
    default_max_step: ClassVar[float] = 1e-3
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=10.0, step_size=1e-3)
    author = "cranefmu"

    def __init_subclass__(cls, **kwargs: Any):
        """Work around pythonfmu 0.7.0's fmi2Instantiate, which re-runs the FMU script in its module's
        namespace and then releases one reference to that namespace it never owned: with a script
        that defines no functions (ours), the second instance in a process used a freed dict and
        crashed.  The script's class statement runs at import and at every such re-run, so one
        reference here per class creation balances it (tests/fmu/test_instances.py)."""
        super().__init_subclass__(**kwargs)
        module = sys.modules.get(cls.__module__)
        if module is not None:
            ctypes.pythonapi.Py_IncRef(ctypes.py_object(module.__dict__))

    def __init__(self, **kwargs: Any):
        super().__init__(**kwargs)
        cls = type(self)
        # a C host aborted at exit after pythonfmu's guard was released twice (adapter/pythonfmu_exit.py)
        release_guard_at_exit(binary_of(self.resources, self.modelName))
        self.description = cls.physics.description
        self._units: dict[str, str] = {}
        self._param_names: list[str] = []
        self._param_vrs: set[int] = set()
        self._param_meta: dict[str, dict] = {}
        self._switches: dict[str, tuple] = {}   # switch parameter -> its names (the FMU holds the code)
        # solver settings first, then the model's parameters
        methods = solvers(cls.physics)
        scope = f"; exact: {cls.physics.exact_scope}" if EXACT in methods and cls.physics.exact_scope else ""
        self._add_param("solver", cls.physics.default_solver or cls.default_solver, "",
                        "internal solver: " + ", ".join(methods) + scope, dict(choices=methods), str)
        self._add_param("rtol", 1e-6, "1", "relative tolerance of the adaptive solvers",
                        dict(min=0, min_open=True, max=1), float)
        self._add_param("max_step", cls.default_max_step, "s", "largest internal step (fixed-step: sub-step size)",
                        dict(min=0, min_open=True), float)
        for name, default, meta in cls.physics.Params.field_specs():
            self._add_param(name, default, meta.get("unit", ""), meta.get("description", ""), meta, type(default))
        self._input_names = [s.name for s in cls.physics.inputs]
        self._coupling = [i for i, s in enumerate(cls.physics.inputs) if s.coupling]
        for s in cls.physics.inputs:
            self._add_real(s.name, s.start, s.unit, s.description, Fmi2Causality.input)
        for i in self._coupling:
            s = cls.physics.inputs[i]
            clash = {s.name + x for x in EXTRAPOLATION_SUFFIXES} & set(self._input_names)
            if clash:
                raise ValueError(f"{cls.__name__}: input {clash.pop()} clashes with an extrapolation input")
            rate_unit = _per_second(s.unit)
            self._add_real(s.name + "_dt", 0.0, rate_unit, f"time derivative of {s.name} for input extrapolation "
                           "inside a step (0 = zero-order hold)", Fmi2Causality.input)
            self._add_real(s.name + "_dt2", 0.0, _per_second(rate_unit), f"second time derivative of {s.name} "
                           "for input extrapolation inside a step (0 = no curvature)", Fmi2Causality.input)
        self._output_names = [s.name for s in cls.physics.outputs]
        for s in cls.physics.outputs:
            setattr(self, s.name, 0 if s.discrete else 0.0)
            if s.discrete:
                self.register_variable(Integer(s.name, causality=Fmi2Causality.output,
                                               variability=Fmi2Variability.discrete, description=s.description))
            else:
                self._add_real(s.name, None, s.unit, s.description, Fmi2Causality.output)
        # the hot path reads and writes values by name in the instance dict: pythonfmu's own
        # set_real/get_real call a lambda and an isinstance per variable (measured 3-4x slower)
        self._real_name = {vr: v.name for vr, v in self.vars.items() if isinstance(v, Real)}
        self._rate_names = [self._input_names[i] + x for i in self._coupling for x in EXTRAPOLATION_SUFFIXES]
        self._discrete_outputs = [i for i, s in enumerate(cls.physics.outputs) if s.discrete]
        self._model: Model | None = None
        self._x = np.zeros(0)
        self._t = 0.0
        self._initialized = False
        self._outputs_stale = True
        self._pin_after_step = False
        self._init_error: Exception | None = None
        # per-step caches of the hot path: the input vector and the input rates, rebuilt only after
        # a set touches them; a set that touches no parameter and no rate input (the master's
        # value exchange) skips the parameter checks
        self._u: np.ndarray | None = None
        self._input_values = _values_getter(self._input_names)
        self._rates_now: tuple | None = None
        rate_names = set(self._rate_names)
        self._param_or_rate_vrs = frozenset(self._param_vrs) | {
            vr for vr, n in self._real_name.items() if n in rate_names}

    # --- registration ------------------------------------------------------------------------
    def _add_real(self, name: str, start: float | None, unit: str, description: str,
                  causality: Fmi2Causality) -> None:
        if start is not None:
            setattr(self, name, float(start))
        self._units[name] = unit
        variability = Fmi2Variability.continuous
        self.register_variable(Real(name, causality=causality, variability=variability, description=description))

    def _add_param(self, name: str, default: Any, unit: str, description: str, meta: dict, kind: type) -> None:
        """Register a parameter.  A text switch (choices) becomes an Integer: the position of the name
        in its choices.  libcosim and fmpy's simulate_ssp set no String parameters, and libcosim
        ignores FMI Enumeration variables; the names are listed in the description and in the
        model description's VendorAnnotations (:data:`ENUMERATIONS_TOOL`), where hosts of ours map them."""
        allowed = allowed_text(meta)
        if kind is str and meta.get("choices"):
            self._switches[name] = tuple(meta["choices"])
            default, kind, allowed = self._switches[name].index(default), int, enumeration_text(meta["choices"])
        setattr(self, name, default)
        variability = Fmi2Variability.tunable if meta.get("tunable") else Fmi2Variability.fixed
        desc = f"{description} (allowed {allowed})" if description else f"allowed {allowed}"
        var_cls = {float: Real, int: Integer, str: String}[kind]
        self.register_variable(var_cls(name, causality=Fmi2Causality.parameter, variability=variability,
                                       initial=Fmi2Initial.exact, description=desc))
        self._units[name] = unit if kind is float else ""
        self._param_names.append(name)
        self._param_vrs.add(len(self.vars) - 1)
        self._param_meta[name] = meta

    # --- model and values ---------------------------------------------------------------------
    def _named(self, name: str) -> Any:
        """A parameter's value as the physics takes it: a switch's code turned into its name."""
        value = getattr(self, name)
        names = self._switches.get(name)
        if names is None:
            return value
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < len(names):
            raise ParameterError(f"{self.physics.Params.component}.{name} = {value!r} is not allowed: "
                                 f"{enumeration_text(names)}")
        return names[value]

    def parameter_value(self, name: str) -> Any:
        """Parameter ``name`` as the physics takes it (a switch's name, not its integer code), for tools
        that inspect an instance (benchmarks/fmu_floor.py)."""
        return self._named(name)

    def physics_state(self) -> tuple[Model | None, np.ndarray, float]:
        """The instance's physics model (None before initialization), a copy of its state vector and its
        time [s]: what :func:`advance` takes, for profiling one step outside the FMI calls."""
        return self._model, self._x.copy(), self._t

    def solver_in_use(self) -> str:
        """The internal solver :meth:`do_step` integrates with: the ``solver`` parameter, ``auto`` resolved
        for the built model (``exact`` where its closed-form step applies, else rk4)."""
        return self._solver

    def _build_model(self) -> Model:
        """Validated parameters -> model; raises ParameterError naming the parameter."""
        for name in ("solver", "rtol", "max_step"):
            check_value(self.instance_name, name, self._named(name), self._param_meta[name])
        self._solver = self._named("solver")
        model = self.physics(self.physics.Params(**self._param_fields()))
        if self._solver == AUTO:
            self._solver = EXACT if model.exact_applies() else "rk4"
        return model

    def _param_fields(self) -> dict:
        fields = {n: self._named(n) for n, _, _ in self.physics.Params.field_specs()}
        for n, default, _ in self.physics.Params.field_specs():
            if isinstance(default, float) and isinstance(fields[n], int) and not isinstance(fields[n], bool):
                fields[n] = float(fields[n])
        return fields

    def _inputs(self) -> np.ndarray:
        """The inputs as a read-only float array, built once per change of the inputs."""
        u = self._u
        if u is None:
            u = np.array(self._input_values(self.__dict__), dtype=float)
            u.flags.writeable = False  # shared by the calls until the next set: no model may change it
            self._u = u
        return u

    def _rates(self) -> tuple[np.ndarray, np.ndarray] | tuple[None, None]:
        """First and second time derivatives of the inputs, or (None, None) when all are 0."""
        d = self.__dict__
        values = [d[n] for n in self._rate_names]
        if not any(values):
            return None, None
        n = len(self._input_names)
        r1, r2 = np.zeros(n), np.zeros(n)
        for k, i in enumerate(self._coupling):
            r1[i], r2[i] = values[2 * k], values[2 * k + 1]
        r1.flags.writeable = r2.flags.writeable = False  # kept over the steps until a rate is set again
        return r1, r2

    def _refresh_outputs(self) -> None:
        if self._init_error is not None:
            return  # reported at exit_initialization_mode
        try:
            if self._model is None or not self._initialized:
                self._model = self._build_model()
                self._x = self._model.initial_state(self._inputs())
            values = self._model.output_list(self._t, self._x, self._inputs())
        except Exception as err:
            self._fail("cannot compute the outputs", err)
            raise
        for i in self._discrete_outputs:
            values[i] = int(round(values[i]))
        self.__dict__.update(zip(self._output_names, values))
        self._outputs_stale = False

    def _fail(self, what: str, err: Exception) -> bool:
        self.log(f"{self.instance_name}: {what}: {type(err).__name__}: {err}", Fmi2Status.error)
        return False

    # --- FMI ----------------------------------------------------------------------------------
    def setup_experiment(self, start_time: float, stop_time: float | None, tolerance: float | None) -> None:
        self._t = float(start_time)

    def enter_initialization_mode(self) -> None:
        # Refused parameters are reported by exit_initialization_mode: pythonfmu forwards the log
        # of a failing exitInitializationMode to the host, but not that of a failing
        # enterInitializationMode or getReal.  Until then outputs keep their start values.
        try:
            self._model = self._build_model()
            self._init_error = None
        except (ParameterError, ValueError, TypeError) as err:
            self._init_error = err

    def exit_initialization_mode(self) -> None:
        try:
            self._model = self._build_model()
            self._x = self._model.initial_state(self._inputs())
            self._model.check_state(self._t, self._x)
            if self._solver == "exact":
                self._model.prepare_exact_step()
        except (ParameterError, FloatingPointError, ValueError) as err:
            self._fail("initialization refused", err)
            raise
        self._init_error = None   # a value refused in initialization mode and corrected before its end
        one_blas_thread()   # after the model is built: its libraries (scipy's expm) are loaded
        self._pin_after_step = True   # a solver may load one at its first step (scipy's solve_ivp)
        self._initialized = True
        self._fixed_values = self._fixed_parameters()
        self._outputs_stale = True

    def _fixed_parameters(self) -> dict[str, Any]:
        return {n: getattr(self, n) for n in self._param_names if not self._param_meta[n].get("tunable")}

    def set_real(self, vrs: list[int], values: list[float]) -> None:
        d, names = self.__dict__, self._real_name
        try:
            for vr, value in zip(vrs, values):
                d[names[vr]] = value
        except KeyError:  # not a Real: pythonfmu raises the error naming the value reference
            self._u = self._rates_now = None
            super().set_real(vrs, values)
        self._u = None
        self._outputs_stale = True
        if not self._param_or_rate_vrs.isdisjoint(vrs):
            self._after_set(vrs)

    def set_integer(self, vrs: list[int], values: list[int]) -> None:
        super().set_integer(vrs, values)
        self._after_set(vrs)

    def set_string(self, vrs: list[int], values: list[str]) -> None:
        super().set_string(vrs, values)
        self._after_set(vrs)

    def _after_set(self, vrs: list[int]) -> None:
        self._outputs_stale = True
        self._rates_now = None
        if self._initialized and not self._param_vrs.isdisjoint(vrs):
            try:
                for name, old in self._fixed_values.items():
                    new = getattr(self, name)
                    if not (new == old or (new != new and old != old)):
                        raise ParameterError(f"{self.physics.Params.component}.{name} = {new!r} is refused: a fixed "
                                             f"parameter cannot change after initialization (it is {old!r})")
                self._model = self._build_model()  # a tunable parameter changed
            except ParameterError as err:
                self._fail("parameter refused", err)
                raise

    def get_real(self, vrs: list[int]) -> list[float]:
        if self._outputs_stale:
            self._refresh_outputs()
        d, names = self.__dict__, self._real_name
        try:
            return [d[names[vr]] for vr in vrs]
        except KeyError:  # not a Real: pythonfmu raises the error naming the value reference
            return super().get_real(vrs)

    def get_integer(self, vrs: list[int]) -> list[int]:
        if self._outputs_stale:
            self._refresh_outputs()
        return super().get_integer(vrs)

    def do_step(self, current_time: float, step_size: float) -> bool:
        if get_ident() not in _THREADS_KEPT:
            _keep_thread_state()
        try:
            rates = self._rates_now
            if rates is None:
                rates = self._rates_now = self._rates()
            self._x = advance(self._model, current_time, self._x, step_size, self._inputs(), rates[0], rates[1],
                              self._solver, self.rtol, self.max_step)
            self._t = current_time + step_size
            self._outputs_stale = True
            if self._pin_after_step:
                self._pin_after_step = False
                one_blas_thread()
            return True
        except Exception as err:  # never let an exception escape into the C layer
            return self._fail(f"step at t = {current_time:.9g} s failed", err)

    # --- state ----------------------------------------------------------------------------------
    def _get_fmu_state(self) -> dict[str, Any]:
        names = self.__dict__.get("_state_names")
        if names is None:   # every variable but the outputs, listed once
            names = self._state_names = [v.name for v in self.vars.values() if v.causality != Fmi2Causality.output]
        d = self.__dict__
        try:   # the values live in the instance's attributes: read them directly (a getter call each cost 2x)
            state = {n: d[n] for n in names}
        except KeyError:
            state = {n: getattr(self, n) for n in names}
        state["__x"] = [float(v) for v in self._x]
        state["__t"] = self._t
        state["__initialized"] = self._initialized
        return state

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        values = dict(state)
        self._x = np.array(values.pop("__x"), dtype=float)
        self._t = float(values.pop("__t"))
        was_initialized = self._initialized
        self._initialized = bool(values.pop("__initialized"))
        # the model holds only the parameters (and caches keyed by their arguments, e.g. the chassis's
        # matrix exponentials): with the same parameters it is kept, a rollback then costs no rebuild
        # (measured: the rebuild was 3/4 of a chassis rollback's cost)
        same = was_initialized and self._model is not None and all(
            values[n] == getattr(self, n) for n in self._param_names if n in values)
        for name, value in values.items():
            setattr(self, name, value)
        self._u = self._rates_now = None
        if self._initialized and not same:
            self._model = self._build_model()
            self._fixed_values = self._fixed_parameters()
        self._outputs_stale = True

    # --- model description ------------------------------------------------------------------------
    def to_xml(self, model_options: dict[str, str] = dict()) -> Element:
        """pythonfmu's description plus units, unit definitions and the real ModelStructure."""
        root = super().to_xml(model_options)
        used: dict[str, tuple[float, dict[str, int]]] = {}
        index = {}
        for i, v in enumerate(self.vars.values()):
            index[v.name] = i + 1
        for sv in root.find("ModelVariables"):
            unit = self._units.get(sv.get("name"), "")
            real = sv.find("Real")
            if real is not None and not units.dimensionless(unit):
                real.set("unit", unit)
                used[unit] = units.parse(unit)
        annotations = Element("VendorAnnotations")
        root.set("description", f"{root.get('description', '')} [{python_host_note(self.physics)}]".lstrip())
        host = SubElement(annotations, "Tool", name=PYTHON_HOST_TOOL)
        SubElement(host, "PythonHost", python="CPython 3.10-3.13, shared library (libpython3.X.so)",
                   packages="numpy", scipy=python_host_scipy(self.physics),
                   optional="threadpoolctl (pins BLAS/OpenMP threads to one)",
                   preload="a C host: LD_PRELOAD=<libdir>/libpython3.X.so, the environment's bin first on PATH",
                   exit="terminate and free every instance before the process exits; the FMU empties pythonfmu "
                   "0.7.0's interpreter guard in an exit handler of its own (docs/fmus.md)")
        if self._switches:
            listing = SubElement(SubElement(annotations, "Tool", name=ENUMERATIONS_TOOL), "Enumerations")
            for name, names in self._switches.items():
                var = SubElement(listing, "Variable", name=name)
                for code, item in enumerate(names):
                    SubElement(var, "Item", name=item, value=str(code))
        if self.physics.ports:
            check_ports(self.physics)
            listing = SubElement(SubElement(annotations, "Tool", name=PORTS_TOOL), "Ports")
            for port in self.physics.ports:
                attrs = {"name": port.name, "kind": port.kind, "takes": port_takes(self.physics, port),
                         "description": port.description}
                attrs |= {part: " ".join(names) for part, names in port.parts() if names}
                if port.sign != 1:
                    attrs["sign"] = str(port.sign)
                SubElement(listing, "Port", attrs)
        if len(annotations):
            root.insert(list(root).index(root.find("ModelVariables")), annotations)
        if used:
            defs = Element("UnitDefinitions")
            for name, (factor, exps) in sorted(used.items()):
                u = SubElement(defs, "Unit", name=name)
                attrs = {k: str(v) for k, v in exps.items()}
                if factor != 1.0:
                    attrs["factor"] = repr(factor)
                SubElement(u, "BaseUnit", attrs)
            root.insert(list(root).index(root.find("CoSimulation")) + 1, defs)
        structure = root.find("ModelStructure")
        for child in list(structure):
            structure.remove(child)
        outputs = SubElement(structure, "Outputs")
        initial = SubElement(structure, "InitialUnknowns")
        for s in self.physics.outputs:
            deps = " ".join(str(index[d]) for d in s.depends_on)
            SubElement(outputs, "Unknown", index=str(index[s.name]), dependencies=deps)
            # at initialization an output depends on its feedthrough inputs, and through the initial
            # state on the parameters and the inputs the state is computed from; listing no
            # dependencies attribute would claim "all"
            init_deps = sorted({index[d] for d in s.depends_on + self.physics.initial_state_inputs}
                               | {index[p] for p in self._param_names})
            SubElement(initial, "Unknown", index=str(index[s.name]),
                       dependencies=" ".join(str(d) for d in init_deps))
        return root


def advance(model: Model, t: float, x: np.ndarray, h: float, u0: np.ndarray, r1: np.ndarray | None,
            r2: np.ndarray | None, solver: str, rtol: float, max_step: float) -> np.ndarray:
    """The model's state after one communication step of ``h`` [s] from ``t`` with the inputs
    u0 + s r1 + s^2/2 r2 (s: time into the step; r1 = r2 = None: constant inputs), as
    :meth:`CraneSlave.do_step` takes it (integration, the model's end-of-step update, the
    finite-state check).  ``solver = "exact"`` takes the model's own closed-form step
    (:meth:`Model.exact_step`) and integrates with rk4 at ``max_step`` where it does not apply."""
    moving = r1 is not None and r2 is not None and bool(r1.any() or r2.any())
    if solver == AUTO:   # as the FMU resolves it at initialization (a caller may pass the parameter as set)
        solver = EXACT if model.exact_applies() else "rk4"
    if x.size == 0 and solver != EXACT:   # no state (a stateless spring): nothing to integrate
        x1 = x
    elif model.frozen:  # derivatives identically 0: sub-stepping would only cost time
        x1 = x          # (the state arrays are never changed in place)
    else:
        if r1 is None or r2 is None:
            r1 = r2 = _zeros(u0.size)
        x1 = None
        if solver == EXACT:
            x1 = model.exact_step(t, x, h, u0, r1, r2, max_step)
            solver = "rk4"
        if x1 is None and solver == "rk4" and model.list_rhs:   # rk4 on plain floats
            x1 = np.array(rk4_list(_list_rhs(model, t, u0, r1, r2, moving), t, x.tolist(), h, max_step))
        if x1 is None:
            if moving:
                def rhs(ti: float, xi: np.ndarray) -> np.ndarray:
                    s = ti - t
                    return model.derivatives(ti, xi, u0 + s * (r1 + 0.5 * s * r2))
            else:
                def rhs(ti: float, xi: np.ndarray) -> np.ndarray:
                    return model.derivatives(ti, xi, u0)
            x1 = integrate(rhs, t, x, h, solver, rtol, 1e-3 * rtol, max_step)
    t1 = t + h
    x1 = model.after_step(t1, x1, u0 + h * (r1 + 0.5 * h * r2) if moving else u0)
    if x1 is not x:  # the unchanged state of a frozen or stateless model was checked when it was made
        model.check_state(t1, x1)
    return x1


def _list_rhs(model: Model, t: float, u0: np.ndarray, r1: np.ndarray, r2: np.ndarray, moving: bool):
    """The model's right-hand side on plain floats with the inputs u0 + s r1 + s^2/2 r2 at s = ti - t:
    the same operations per component in the same order as the array form in :func:`advance` (so the
    same result to the last bit), without four numpy temporaries per stage (input rates set by an
    extrapolating master made each rk4 step cost 1.7x the step with still inputs)."""
    if not moving:
        return lambda ti, xi: model.derivatives_list(ti, xi, u0)
    u, d1, d2 = u0.tolist(), r1.tolist(), r2.tolist()

    def rhs(ti: float, xi: list[float]) -> list[float]:
        s = ti - t
        half = 0.5 * s
        return model.derivatives_list(ti, xi, [a + s * (b + half * c) for a, b, c in zip(u, d1, d2)])
    return rhs


def _values_getter(names: list[str]):
    """A function of a dict that returns the tuple of its values at ``names`` (in one C call for two
    or more names: cheaper than a comprehension on the hot path)."""
    if len(names) >= 2:
        return itemgetter(*names)
    return lambda d: tuple(d[n] for n in names)


_ZEROS: dict[int, np.ndarray] = {}


def _zeros(n: int) -> np.ndarray:
    """A read-only zero vector of length ``n``, made once (the rates of constant inputs)."""
    z = _ZEROS.get(n)
    if z is None:
        z = _ZEROS[n] = np.zeros(n)
        z.flags.writeable = False
    return z


_THREADS_KEPT: set[int] = set()


def _keep_thread_state() -> None:
    """Keep this OS thread's Python thread state alive across FMI calls (once per thread).

    pythonfmu wraps every FMI call in PyGILState_Ensure/Release.  A C host thread has no Python
    thread state, so each call creates one and destroys it on return (measured 20-40 us a call,
    benchmarks/native_host_cost.py).  One extra Ensure that is never released keeps the state, and
    later calls reuse it.  Harmless in Python hosts (their thread already has a state).  Called from
    do_step, not at instantiation: fmi2Instantiate runs Python under a state that is not this
    thread's GIL state, and an Ensure there deadlocks.  CRANEFMU_KEEP_THREAD_STATE=0 turns it off
    (for measuring the difference).
    """
    ident = get_ident()
    if ident in _THREADS_KEPT or os.environ.get("CRANEFMU_KEEP_THREAD_STATE") == "0":
        return
    ctypes.pythonapi.PyGILState_Ensure()
    _THREADS_KEPT.add(ident)


def _per_second(unit: str) -> str:
    if units.dimensionless(unit):
        return "1/s"
    if "/" in unit:
        num, den = unit.split("/")
        m = den.rstrip("0123456789")
        if m == "s":
            power = int(den[1:] or 1) + 1
            return f"{num}/s{power}"
        return f"{num}/{den}.s"
    return f"{unit}/s"
