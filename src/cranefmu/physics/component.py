"""The contract every subsystem model fulfils, so one FMI adapter serves them all.

A model owns a validated parameter set and describes its interface with :class:`Signal` tables.
Its numerics are pure functions of (t, x, u): ``derivatives`` is the right-hand side of the
internal ODE, ``output_values`` the algebraic outputs.  ``u`` is a float array in the order of
``inputs``; outputs come back in the order of ``outputs``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .params import Params


@dataclass(frozen=True)
class Signal:
    """One input or output of a model.

    depends_on: for an output, the inputs it depends on *directly* (algebraic feedthrough);
      an empty tuple means it is a function of the internal state only.
    coupling: for an input, True if a master may extrapolate it inside a macro step (the FMU
      then also offers ``<name>_dt`` and ``<name>_dt2`` inputs, which default to 0).
    discrete: for an output, True for a 0/1 or counting signal (an Integer, discrete, in FMI).
    """

    name: str
    unit: str
    description: str
    start: float = 0.0
    depends_on: tuple[str, ...] = ()
    coupling: bool = False
    discrete: bool = False


@dataclass(frozen=True)
class Port:
    """One mechanical interface of a model: the force, velocity and position variables of one
    point (or axis), one name per axis, in the same axis order.

    Which side gives what follows from the signal tables: a port whose force variables are outputs
    gives force (it takes the motion as inputs, e.g. the rope at the hook); one whose position and
    velocity are outputs gives motion (it takes the force, e.g. the hook).  A port may lack a part:
    no force (it follows a motion and exerts nothing back, e.g. the hook's view of the suspension
    point), no velocity (a reaction on a fixed axis).  Two connected ports with force and velocity
    form a power bond P = sign * sum(force_i * velocity_i) (docs/power_bonds.md).

    kind: "linear" (force N, velocity m/s, position m) or "angular" (moment N.m, rad/s, rad).
    sign: -1 where the model's velocity turns against its force (a tilt opposite to the moment).
    """

    name: str
    description: str
    force: tuple[str, ...] = ()
    velocity: tuple[str, ...] = ()
    position: tuple[str, ...] = ()
    kind: str = "linear"
    sign: int = 1

    def __post_init__(self):
        if self.kind not in PORT_UNITS:
            raise ValueError(f"port {self.name}: kind = {self.kind!r} is not allowed: one of {', '.join(PORT_UNITS)}")
        if self.sign not in (1, -1):
            raise ValueError(f"port {self.name}: sign = {self.sign!r} is not allowed: 1 or -1")
        sizes = {len(part) for part in (self.force, self.velocity, self.position) if part}
        if len(sizes) != 1:
            raise ValueError(f"port {self.name}: force, velocity and position need one variable per axis "
                             f"(sizes {len(self.force)}, {len(self.velocity)}, {len(self.position)})")

    def parts(self) -> tuple[tuple[str, tuple[str, ...]], ...]:
        """(part, variables) in the order a connection of two ports lists them: position, velocity, force."""
        return (("position", self.position), ("velocity", self.velocity), ("force", self.force))


#: the unit of each part of a port, by kind
PORT_UNITS = {"linear": {"force": "N", "velocity": "m/s", "position": "m"},
              "angular": {"force": "N.m", "velocity": "rad/s", "position": "rad"}}


def check_ports(model: type["Model"]) -> None:
    """Raise ``ValueError`` naming the port if one names an unknown signal, a unit that is not its
    part's, or mixes directions (its motion must all be inputs and its force outputs, or the reverse)."""
    signals = {s.name: ("input", s) for s in model.inputs} | {s.name: ("output", s) for s in model.outputs}
    for port in model.ports:
        kinds = set()
        for part, names in port.parts():
            for name in names:
                if name not in signals:
                    raise ValueError(f"{model.__name__} port {port.name}: {part} {name} is not an input or output")
                causality, signal = signals[name]
                if signal.unit != PORT_UNITS[port.kind][part]:
                    raise ValueError(f"{model.__name__} port {port.name}: {part} {name} has unit {signal.unit}, "
                                     f"a {port.kind} port's {part} needs {PORT_UNITS[port.kind][part]}")
                gives_force = (causality == "output") == (part == "force")
                kinds.add(gives_force)
        if len(kinds) != 1:
            raise ValueError(f"{model.__name__} port {port.name}: its motion must all be inputs and its force "
                             "outputs (it gives force), or the reverse (it gives motion)")


def port_takes(model: type["Model"], port: Port) -> str:
    """"motion" if ``port``'s position and velocity are inputs (it gives force, or nothing: a follower),
    "force" if its force is an input (it gives motion)."""
    outputs = {s.name for s in model.outputs}
    for part, names in port.parts():
        if names:
            return "motion" if (names[0] in outputs) == (part == "force") else "force"
    return "motion"


class Model:
    """Base of every subsystem model.  Subclasses set the class attributes and override the
    numerics; a model without internal states returns an empty state vector."""

    Params: ClassVar[type[Params]]
    inputs: ClassVar[tuple[Signal, ...]] = ()
    outputs: ClassVar[tuple[Signal, ...]] = ()
    #: the model's mechanical ports (:class:`Port`): what a scene connects as one (docs/composition.md)
    ports: ClassVar[tuple[Port, ...]] = ()
    description: ClassVar[str] = ""
    #: inputs that ``initial_state`` reads: at initialization every output may depend on them
    initial_state_inputs: ClassVar[tuple[str, ...]] = ()
    #: the FMU's default internal solver, if not the adapter's ("exact": :meth:`exact_step`)
    default_solver: ClassVar[str | None] = None
    #: where :meth:`exact_step` has a closed form (said in the ``solver`` parameter's description)
    exact_scope: ClassVar[str] = ""
    #: where the state moves, so that the internal solver runs (an adaptive one imports scipy there,
    #: said in the pythonfmu FMU's host note): "" in every configuration, None in none (frozen), else the
    #: switch setting, e.g. "model = bouc_wen" (tests/fmu/test_scipy_free.py proves it per FMU)
    state_moves_when: ClassVar[str | None] = ""

    def __init__(self, params: Params):
        if not isinstance(params, self.Params):
            raise TypeError(f"{type(self).__name__} needs {self.Params.__name__}, got {type(params).__name__}")
        self.p = params

    # --- interface -------------------------------------------------------------------------
    @classmethod
    def input_index(cls) -> dict[str, int]:
        return {s.name: i for i, s in enumerate(cls.inputs)}

    @classmethod
    def default_inputs(cls) -> np.ndarray:
        return np.array([s.start for s in cls.inputs], dtype=float)

    def state_names(self) -> tuple[str, ...]:
        return ()

    @property
    def frozen(self) -> bool:
        """True when ``derivatives`` is identically zero in this configuration (a kinematic mode that
        keeps the state vector's size): the FMU then skips its integrator instead of sub-stepping zeros."""
        return False

    def initial_state(self, u: np.ndarray) -> np.ndarray:
        """State at the start time, given the inputs at the start time."""
        return np.zeros(0)

    def derivatives(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        return np.zeros(0)

    def derivatives_list(self, t: float, x: list[float], u: np.ndarray) -> list[float]:
        """:meth:`derivatives` on a list of floats.  A model whose right-hand side works on plain floats
        overrides this one (and derives ``derivatives`` from it): the FMU's rk4 then steps lists and
        builds no array per stage (:func:`cranefmu.adapter.integrators.rk4_list`)."""
        return self.derivatives(t, np.array(x), u).tolist()

    @property
    def list_rhs(self) -> bool:
        """True when the model has its own :meth:`derivatives_list`."""
        return type(self).derivatives_list is not Model.derivatives_list

    def output_values(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The outputs at (t, x, u) as an array, in the order of ``outputs``.  A model overrides this
        or :meth:`output_list`."""
        if type(self).output_list is Model.output_list:
            raise NotImplementedError(f"{type(self).__name__} defines neither output_values nor output_list")
        return np.array(self.output_list(t, x, u), dtype=float)

    def output_list(self, t: float, x: np.ndarray, u: np.ndarray) -> list[float]:
        """:meth:`output_values` as a list of floats, what the FMU adapter copies out at every read;
        the crane models compute their outputs on plain floats and override this one (an array built
        only to be turned back into a list cost about a microsecond per read)."""
        return np.asarray(self.output_values(t, x, u), dtype=float).tolist()

    def exact_step(self, t: float, x: np.ndarray, h: float, u0: np.ndarray, r1: np.ndarray,
                   r2: np.ndarray, max_step: float) -> np.ndarray | None:
        """State at t + h [s] in closed form for the inputs u0 + s r1 + s^2/2 r2 (s: time into the
        step), or None where there is none (the FMU then integrates ``derivatives`` with rk4 at
        ``max_step`` [s]).  A model that overrides it offers the solver ``exact``."""
        return None

    def exact_applies(self) -> bool:
        """Whether :meth:`exact_step` is this configuration's closed form (``solver = auto`` takes it then,
        rk4 otherwise)."""
        return True

    def prepare_exact_step(self) -> None:
        """Once-per-model work of :meth:`exact_step` (a propagator, its imports), done when the FMU
        leaves initialization so that the first step costs what every later step costs."""

    def after_step(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Hook for discrete updates at the end of a step (projection, mode switches)."""
        return x

    def check_state(self, t: float, x: np.ndarray) -> None:
        """Raise ``FloatingPointError`` naming the state if ``x`` is not finite."""
        total = sum(x.tolist())
        if total - total == 0.0:  # finite sum: every state finite (on plain floats: a numpy
            return                # reduction costs more than the whole sum of a few states)
        if not np.all(np.isfinite(x)):
            names = self.state_names()
            bad = [names[i] if i < len(names) else str(i) for i in np.flatnonzero(~np.isfinite(x))]
            raise FloatingPointError(f"non-finite state {', '.join(bad)} at t = {t:.6g} s")
