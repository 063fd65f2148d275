"""Monolithic models of the scenes: the same physics models, all equations in one ODE, solved by
scipy (Radau) at tight tolerance.  The co-simulation converges to these as the macro step falls.

The monolith is built from a scene's own sources (``ssp/<scene>/SystemStructure.ssd`` and its .ssv
parameter sets), so it wires exactly what the co-simulation wires: every component becomes its
physics :class:`~cranefmu.physics.component.Model`, every connection an assignment of an output to
an input.  The right-hand side evaluates the outputs in feedthrough order (repeating the sweep
until no input changes, which is exact for any scene without a true algebraic loop) and stacks
the components' derivatives.  Initialization mirrors the master's: the inputs are exchanged with
every state at ``initial_state(u)`` until they agree.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from ..errors import ParameterSetError, SceneError, SimulationError
from ..master.scene import Scene, read_scene_folder, typed_value
from ..physics.boom import BoomModel
from ..physics.chassis import ChassisModel
from ..physics.chassis4 import Chassis4Model
from ..physics.component import Model
from ..physics.drive import DriveModel
from ..physics.girder import GirderModel
from ..physics.pendulum import PendulumModel
from ..physics.rope import RopeModel
from ..physics.slewing import SlewingBoomModel
from ..sources import FMU_SOURCES as FMU_DIR  # the checkout's fmus/ or the wheel's copy
from ..sources import SSP_SOURCES as SSP_DIR  # the checkout's ssp/ or the wheel's copy

MODELS: dict[str, type[Model]] = {"Rope": RopeModel, "Pendulum": PendulumModel, "Drive": DriveModel,
                                  "Girder": GirderModel, "Boom": BoomModel, "Chassis": ChassisModel,
                                  "SlewingBoom": SlewingBoomModel, "Chassis4": Chassis4Model}
ADAPTER_PARAMETERS = ("solver", "rtol", "max_step")   # the FMU's own solver settings, not physics
INIT_MAX_SWEEPS = 400
INIT_RELAXATION = 0.5
INIT_TOLERANCE = 1e-14   # largest relative input change of the last initialization sweep


def source_scene(scene: str | Scene) -> Scene:
    """Scene ``scene`` read from its sources under ssp/ (the one scene reader); a :class:`Scene` as it
    is (e.g. the one a run read from its .ssp: the monolith then wires and starts what the run does)."""
    if isinstance(scene, Scene):
        return scene
    folder = SSP_DIR / scene
    if not (folder / "SystemStructure.ssd").is_file():
        known = sorted(p.name for p in SSP_DIR.iterdir() if (p / "SystemStructure.ssd").is_file())
        raise SceneError(f"scene {scene!r} is unknown: one of {', '.join(known)}")
    return read_scene_folder(folder, FMU_DIR)


def build_params(cls, component: str, values: dict) -> object:
    """The validated parameter dataclass ``cls`` of ``component`` from 'comp.var' -> value entries
    (values typed, or text converted as the scene reader converts it)."""
    specs = {name: (default, meta) for name, default, meta in cls.field_specs()}
    kw = {}
    for key, value in values.items():
        comp, _, var = key.partition(".")
        if comp != component or var in ADAPTER_PARAMETERS:
            continue
        if var not in specs:
            raise ParameterSetError(f"parameter {key!r}: {component} has no parameter {var!r}; allowed "
                                    f"{', '.join(specs)}")
        default, meta = specs[var]
        kw[var] = field_value(key, value, default, meta)
    return cls(**kw)


def field_value(key: str, value: object, default: object, meta: dict) -> object:
    """``value`` for a parameter field whose default is ``default``: numbers converted like the
    scene reader does (an Integer must be whole), a switch's code (as the FMU takes it) turned into
    its name."""
    if isinstance(default, str):
        choices = meta.get("choices") or ()
        code = value if isinstance(value, int) and not isinstance(value, bool) else \
            int(value) if isinstance(value, str) and value.isdigit() else None
        return choices[code] if code is not None and code < len(choices) else value
    if isinstance(default, bool):
        return value
    kind = "Integer" if isinstance(default, int) else "Real"
    return typed_value(str(value), kind, f"parameter {key}")


@dataclass(frozen=True)
class Link:
    """Output ``src_out`` of component ``src`` feeds input ``dst_in`` of component ``dst`` (indices)."""

    src: int
    src_out: int
    dst: int
    dst_in: int


class Monolith:
    """All components of a scene as one ODE x' = f(t, x); outputs as in the co-simulation."""

    def __init__(self, scene: str | Scene, parameter_set: str = "default", parameters: dict | None = None):
        source = source_scene(scene)
        self.scene = scene = source.name
        from ..derived import derive

        base = source.model_values(parameter_set)
        values = {**base, **derive(scene, base, parameters or {})}   # with the parameters that follow (as a run)
        self.names: list[str] = []
        self.models: list[Model] = []
        for comp in source.components:
            fmu = comp.fmu.stem
            if fmu not in MODELS:
                raise SceneError(f"scene {scene}: component {comp.name!r} uses {fmu}.fmu, which has no "
                                 f"physics model here (known: {', '.join(MODELS)})")
            cls = MODELS[fmu]
            self.names.append(comp.name)
            self.models.append(cls(build_params(cls.Params, comp.name, values)))
        unknown = {k.partition(".")[0] for k in values} - set(self.names)
        if unknown:
            raise ParameterSetError(f"parameters for {', '.join(sorted(unknown))}: no such component in {scene} "
                                    f"({', '.join(self.names)})")
        index = {n: i for i, n in enumerate(self.names)}
        self.links: list[Link] = []
        for c in source.connections:
            if (c.factor, c.offset) != (1.0, 0.0):
                raise SceneError(f"scene {scene}: connection {c} has a LinearTransformation, which the monolith "
                                 "does not apply")
            s, d = index[c.src], index[c.dst]
            outs = [sig.name for sig in self.models[s].outputs]
            ins = [sig.name for sig in self.models[d].inputs]
            self.links.append(Link(s, outs.index(c.src_var), d, ins.index(c.dst_var)))
        self.incoming = [[lk for lk in self.links if lk.dst == i] for i in range(len(self.models))]
        # per component and source: (source, source output indices, input indices) for one fancy-index copy
        self.feeds = [self._feeds(lks) for lks in self.incoming]
        self.acyclic = True
        self.order = self._order()
        # evaluated before the ordered pass: components whose (state-only) outputs feed a component
        # that comes earlier in the order
        pos = {i: k for k, i in enumerate(self.order)}
        self.early = sorted({lk.src for lk in self.links if pos[lk.dst] <= pos[lk.src]})
        self.u = [m.default_inputs() for m in self.models]
        self.y = [np.zeros(len(m.outputs)) for m in self.models]
        self.sizes: list[int] = []
        self._slices: list[slice] = []
        self.columns = [f"{n}.{s.name}" for n, m in zip(self.names, self.models) for s in m.outputs]

    @staticmethod
    def _feeds(incoming: list[Link]) -> list[tuple[int, np.ndarray, np.ndarray]]:
        """(source, its output indices, the input indices they feed) for each source of one component."""
        by_src: dict[int, list[Link]] = {}
        for lk in incoming:
            by_src.setdefault(lk.src, []).append(lk)
        return [(src, np.array([lk.src_out for lk in lks]), np.array([lk.dst_in for lk in lks]))
                for src, lks in sorted(by_src.items())]

    def _order(self) -> list[int]:
        """Components whose outputs feed others directly first (component-level feedthrough graph;
        a cycle there is resolved by repeated sweeps, see :meth:`evaluate`)."""
        from graphlib import CycleError, TopologicalSorter

        graph: dict[int, set[int]] = {i: set() for i in range(len(self.models))}
        for lk in self.links:
            if self.models[lk.src].outputs[lk.src_out].depends_on:
                graph[lk.dst].add(lk.src)
        try:
            return list(TopologicalSorter(graph).static_order())
        except CycleError:
            self.acyclic = False
            return list(range(len(self.models)))

    def _gather(self, i: int) -> bool:
        """Copy the current outputs into component i's inputs; True if any input changed."""
        u = self.u[i]
        changed = False
        for lk in self.incoming[i]:
            v = self.y[lk.src][lk.src_out]
            if u[lk.dst_in] != v:
                u[lk.dst_in] = v
                changed = True
        return changed

    def evaluate(self, t: float, xs: list[np.ndarray], initial: bool = False) -> list[np.ndarray]:
        """Outputs of every component at (t, xs), with consistent inputs; with ``initial`` the states
        are re-derived from the inputs (xs is filled in place), as an FMU does in initialization mode.

        Without an algebraic loop between components one pass in feedthrough order is exact: the
        outputs computed first (with the previous inputs) are right wherever they depend on the
        state only, and every feedthrough output is recomputed after its sources."""
        if not initial:
            ys, us, models = self.y, self.u, self.models
            if self.acyclic:
                for i in self.early:
                    ys[i] = models[i].output_values(t, xs[i], us[i])
                for i in self.order:
                    u = us[i]
                    for src, outs, ins in self.feeds[i]:
                        u[ins] = ys[src][outs]
                    ys[i] = models[i].output_values(t, xs[i], u)
                return ys
            for i, m in enumerate(models):
                ys[i] = m.output_values(t, xs[i], us[i])
        else:
            for i, m in enumerate(self.models):
                xs[i] = m.initial_state(self.u[i])
                self.y[i] = m.output_values(t, xs[i], self.u[i])
        for sweep in range(INIT_MAX_SWEEPS if initial else len(self.models) + 1):
            change = 0.0
            for i in self.order:
                old = self.u[i].copy() if initial else None
                if self._gather(i):
                    if not initial:   # any change means another sweep
                        change = math.inf
                        self.y[i] = self.models[i].output_values(t, xs[i], self.u[i])
                        continue
                    # relative to each input's own size: newtons and metres side by side, and an
                    # equilibrium start needs every position to round-off (a stiff rope turns 1e-9 m
                    # into a visible force)
                    diff = float(np.max(np.abs(self.u[i] - old) / (1.0 + np.abs(old))))
                    change = max(change, diff) if math.isfinite(diff) else math.inf
                    if initial:
                        # under-relaxed: a stiff rope on soft supports makes the plain exchange
                        # oscillate with a gain above 1 (truck crane at 30 deg: about -1.25)
                        self.u[i] = old + INIT_RELAXATION * (self.u[i] - old)
                        xs[i] = self.models[i].initial_state(self.u[i])
                    self.y[i] = self.models[i].output_values(t, xs[i], self.u[i])
            if not initial and change == 0.0:
                return self.y
            if initial and change <= INIT_TOLERANCE:
                return self.y
        if initial:
            raise SimulationError(f"reference {self.scene}: initialization did not converge "
                                  f"(last input change {change:.3g})")
        raise SimulationError(f"reference {self.scene}: the outputs do not settle (algebraic loop?)")

    def split(self, x: np.ndarray) -> list[np.ndarray]:
        return [x[sl] for sl in self._slices]

    def initial_state(self, t0: float = 0.0) -> np.ndarray:
        xs = [np.zeros(0) for _ in self.models]
        self.evaluate(t0, xs, initial=True)
        self.sizes = [len(x) for x in xs]
        ends = np.cumsum(self.sizes)
        self._slices = [slice(int(e - n), int(e)) for e, n in zip(ends, self.sizes)]
        return np.concatenate(xs)

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """x' at (t, x).  A state outside a model's domain (a Newton trial of the implicit solver, e.g.
        more rope wound in than exists) gives NaN, which Radau/BDF treat as a failed iteration and
        answer with a smaller step."""
        xs = self.split(x)
        dx = np.empty(len(x))
        try:
            with np.errstate(all="ignore"):
                self.evaluate(t, xs)
                for m, xi, ui, sl in zip(self.models, xs, self.u, self._slices):
                    if sl.stop > sl.start:
                        dx[sl] = m.derivatives(t, xi, ui)
        except (FloatingPointError, OverflowError, SimulationError):
            dx[:] = np.nan
        return dx

    def output_row(self, t: float, x: np.ndarray) -> np.ndarray:
        return np.concatenate(self.evaluate(t, self.split(x)))


class RegimeEvents:
    """The switching functions of every component with regimes (``pin``/``regime``/``regime_events``/
    ``enter``, e.g. the slack-capable rope) as terminal events of solve_ivp: between two located
    events each such component stays pinned in one regime, so the right-hand side is smooth there."""

    def __init__(self, mono: Monolith):
        self.mono = mono
        self.switched = [i for i, m in enumerate(mono.models) if hasattr(m, "regime_events")]
        self._key: tuple | None = None
        self._values: list[tuple[float, int, str]] = []

    def pin_from_state(self, t: float, x: np.ndarray) -> None:
        xs = self.mono.split(x)
        for i in self.switched:
            self.mono.models[i].pin(None)
        self.mono.evaluate(t, xs)
        for i in self.switched:
            self.mono.models[i].pin(self.mono.models[i].regime(xs[i], self.mono.u[i]))
        self._key = None

    def _table(self, t: float, x: np.ndarray) -> list[tuple[int, float, int, str]]:
        key = (t, x.tobytes())
        if key != self._key:
            xs = self.mono.split(x)
            with np.errstate(all="ignore"):
                self.mono.evaluate(t, xs)
            self._values = [(i, *ev) for i in self.switched
                            for ev in self.mono.models[i].regime_events(xs[i], self.mono.u[i])]
            self._key = key
        return self._values

    def functions(self, t: float, x: np.ndarray) -> list:
        """One solve_ivp event function per way out of the current regimes."""
        fns = []
        for k, (_, _, direction, _) in enumerate(self._table(t, x)):
            def g(tt, xx, k=k):
                return self._table(tt, xx)[k][1]
            g.terminal, g.direction = True, direction
            fns.append(g)
        return fns

    def switch(self, t: float, x: np.ndarray, fired: int) -> np.ndarray:
        """State after the event ``fired`` (index into :meth:`functions`): that component enters its
        next regime (with its reset)."""
        i, _, _, regime = self._table(t, x)[fired]
        xs = [xi.copy() for xi in self.mono.split(x)]
        self.mono.evaluate(t, xs)
        xs[i] = self.mono.models[i].enter(regime, xs[i], self.mono.u[i])
        self._key = None   # the table belongs to the old regime
        return np.concatenate(xs)

    def pins(self) -> list[str | None]:
        return [self.mono.models[i].pinned for i in self.switched]

    def restore(self, pins: list[str | None]) -> None:
        for i, regime in zip(self.switched, pins):
            self.mono.models[i].pin(regime)
        self._key = None


MAX_EVENTS = 10000


def breakpoints(models: list[Model]) -> list[float]:
    """Times [s] at which a model's right-hand side jumps by its own clock: the motor drive's supply
    switching on, its brake letting go and the end of its frequency ramp (drive.py).  The solver
    restarts there instead of shrinking its step onto the jump (which fails at tight tolerances)."""
    times = []
    for m in models:
        if isinstance(m, DriveModel) and m.p.mode == "motor":
            p = m.p
            times += [p.start_time, p.start_time + p.brake_delay, p.start_time + p.ramp_time]
    return sorted(set(times))


def solve(scene: str | Scene, stop_time: float, times: np.ndarray | None = None, parameter_set: str = "default",
          parameters: dict | None = None, rtol: float = 1e-10, method: str = "Radau") -> dict[str, np.ndarray]:
    """Solve scene ``scene`` as one ODE from 0 to ``stop_time`` [s] with scipy (Radau or BDF).

    Returns ``{"time": times, "comp.var": values, ...}`` for every output of every component, the
    co-simulation's column names.  ``times`` defaults to 2001 points; ``parameters`` overrides
    'comp.var' values as ``--set`` does.  atol is 1e-3 rtol.  The run is cut into smooth segments,
    each solved by a fresh solver: at the models' clock breakpoints (:func:`breakpoints`) and at the
    located regime switches of the rope (slack, taut, on the zero-force line; :class:`RegimeEvents`).
    """
    mono = Monolith(scene, parameter_set, parameters)
    scene = mono.scene
    x = mono.initial_state(0.0)
    t_eval = np.asarray(times, dtype=float) if times is not None else np.linspace(0.0, stop_time, 2001)
    cuts = [b for b in breakpoints(mono.models) if 0.0 < b < stop_time] + [stop_time]
    events = RegimeEvents(mono)
    events.pin_from_state(0.0, x)
    t, ts, ys, pins = 0.0, [], [], []
    for _ in range(MAX_EVENTS):
        end = next(c for c in cuts if c > t)
        wanted = t_eval[((t_eval >= t) if not ts else (t_eval > t)) & (t_eval <= end)]
        # the segment sees the clock up to just before the cut: the jump belongs to the next segment
        left = float(np.nextafter(end, -np.inf))
        sol = solve_ivp(lambda tt, xx: mono.rhs(min(tt, left), xx), (t, end), x, method=method,
                        t_eval=np.union1d(wanted, [end]), rtol=rtol, atol=1e-3 * rtol,
                        events=events.functions(t, x) or None)
        if sol.status == -1:
            raise SimulationError(f"reference solve of {scene} failed at t = {sol.t[-1] if len(sol.t) else t:.6g} s: "
                                  f"{sol.message}")
        seg_t = np.asarray(sol.t, dtype=float)
        seg_y = np.asarray(sol.y, dtype=float).reshape(len(x), len(seg_t))
        keep = np.isin(seg_t, wanted)
        ts.append(seg_t[keep])
        ys.append(seg_y[:, keep])
        pins.append(events.pins())
        if sol.status == 0:
            if end >= stop_time:
                break
            t, x = end, seg_y[:, -1]
            continue
        fired = next(k for k, te in enumerate(sol.t_events) if len(te))
        t = float(sol.t_events[fired][0])
        x = events.switch(t, sol.y_events[fired][0], fired)
    else:
        raise SimulationError(f"reference solve of {scene}: more than {MAX_EVENTS} regime switches before "
                              f"t = {t:.6g} s (chattering?)")
    rows = []
    for seg_t, seg_y, seg_pins in zip(ts, ys, pins):
        events.restore(seg_pins)   # outputs in the regime each segment was solved in
        rows += [mono.output_row(tt, xx) for tt, xx in zip(seg_t, seg_y.T)]
    out = {"time": np.concatenate(ts)}
    rows = np.array(rows).reshape(len(out["time"]), len(mono.columns))
    out.update({c: rows[:, j] for j, c in enumerate(mono.columns)})
    return out


def elastic_pendulum(stop_time: float, times: np.ndarray | None = None, overrides: dict | None = None,
                     rtol: float = 1e-11) -> dict[str, np.ndarray]:
    """The elastic_pendulum scene as one ODE (the monolith the scene's tests compare against)."""
    return solve("elastic_pendulum", stop_time, times, parameters=overrides, rtol=rtol)
