"""Initialization: instantiate, apply parameters, and settle the connections in initialization mode.

Blocks of the dependency graph (:mod:`.graph`) are settled in order: a block that is not a loop
needs one exchange of its incoming connections, a loop (strongly connected block) is iterated
u = G(u) with IQN-ILS acceleration until the connections agree to ``tolerance`` (relative to each
value's size).  A last sweep over every connection checks the result, because an FMU may
declare fewer initial dependencies than it has; if values still move, all connections are
iterated together.  Non-convergence raises an error naming the connection that disagrees most.
"""
from __future__ import annotations

import numpy as np

from .acceleration import IQNILS
from ..errors import SimulationError
from .graph import component_graph, is_loop, strongly_connected
from .residual import relative_residual
from .system import CoSystem

MAX_ITERATIONS = 200


def initialize(system: CoSystem, start_time: float, overrides: dict, tolerance: float,
               max_iterations: int = MAX_ITERATIONS) -> int:
    """Bring every FMU to the start of the run; returns the number of exchanges used.  ``tolerance``:
    the run's ``init_tolerance`` (its default lives in :class:`~.run.Settings`, the one place)."""
    for comp in system.comps:
        comp.instantiate()
        comp.fmu.setupExperiment(startTime=start_time)
    for (name, var), value in overrides.items():
        system.by_name[name].set_start(var, value)
    system.stepping(False)
    for comp in system.comps:
        _call(system, comp, "enterInitializationMode", start_time)
    used = settle(system, start_time, tolerance, max_iterations)
    for comp in system.comps:
        _call(system, comp, "exitInitializationMode", start_time)
    system.stepping(True)
    for g in system.links:
        g.history.clear()
    system.exchange(start_time, order=0)  # values after the FMUs computed their initial states
    return used


def settle(system: CoSystem, t: float, tolerance: float, max_iterations: int) -> int:
    graph = component_graph(system.comps, system.scene.connections)
    used = 0
    everything = list(range(len(system.links)))
    for block in strongly_connected(graph):
        members = [i for i, g in enumerate(system.links) if g.dst in block]
        if not members:
            continue
        if is_loop(block, graph):
            used += _iterate(system, members, t, tolerance, max_iterations, block)
        else:
            _evaluate(system, members, None)
            used += 1
    # the check sweep: FMUs may have more initial dependencies than they declare
    u = _values(system, everything)
    gu = _evaluate(system, everything, u)
    used += 1
    if _residual(system, everything, u, gu)[0] > tolerance:
        used += _iterate(system, everything, t, tolerance, max_iterations, None, start=gu)
    return used


def _values(system: CoSystem, members: list[int]) -> np.ndarray:
    """What the member connections currently carry (pulled now)."""
    return np.concatenate([system.pull(system.links[i]) for i in members])


def _evaluate(system: CoSystem, members: list[int], u: np.ndarray | None) -> np.ndarray:
    """Feed ``u`` (or, if None, the sources' current values) into the members; return G(u): what
    the sources give after that."""
    pos = 0
    for i in members:
        g = system.links[i]
        n = len(g.dst_vrs)
        value = system.pull(g) if u is None else u[pos:pos + n]
        zero = np.zeros(n)
        system.push(g, value, zero, zero)
        pos += n
    return _values(system, members)


def _residual(system: CoSystem, members: list[int], u: np.ndarray, gu: np.ndarray) -> tuple[float, int]:
    scale = np.maximum(np.maximum(np.abs(u), np.abs(gu)), 1e-300)
    return relative_residual(u, gu, scale, 1e-12 * max(1.0, float(np.max(scale, initial=0.0))))


def _iterate(system: CoSystem, members: list[int], t: float, tolerance: float, max_iterations: int,
             block: list[int] | None, start: np.ndarray | None = None) -> int:
    acc = IQNILS(omega0=0.5, reuse=0)
    u = _values(system, members) if start is None else start
    # the accelerator works on values scaled to order 1 (newtons and metres side by side)
    scale = np.maximum(np.abs(u), 1e-9 * max(1.0, float(np.max(np.abs(u), initial=0.0))))
    res, worst = np.inf, 0
    best, stalled, plain = np.inf, 0, False
    for k in range(1, max_iterations + 1):
        # accelerated: feed u, read G(u).  If that stalls (a non-smooth or inconsistent FMU), fall
        # back to plain Gauss-Seidel sweeps: each connection fed what its source gives now.
        gu = _evaluate(system, members, None if plain else u)
        res, worst = _residual(system, members, u, gu)
        if res <= tolerance:
            if not plain:
                _evaluate(system, members, gu)
            return k
        if res < 0.5 * best:
            best, stalled = res, 0
        else:
            stalled += 1
            plain = plain or stalled >= 5
        u = gu if plain else scale * acc.next(u / scale, gu / scale)
    names = [n for i in members for n in system.variable_names[system.slices[i]]]
    where = (" in the loop " + " -> ".join(system.comps[i].name for i in block)) if block else ""
    raise SimulationError(f"initialization did not converge{where} at t = {t:.6g} s: after {max_iterations} "
                          f"iterations connection {names[worst]} still changes by {res:.3g} (relative; tolerance "
                          f"{tolerance:g}). The initial values of the components contradict each other; check "
                          "the start values and parameters feeding this connection.")


def _call(system: CoSystem, comp, what: str, t: float) -> None:
    try:
        getattr(comp.fmu, what)()
    except Exception:
        raise system.refused(comp, f"in {what} at t = {t:.6g} s") from None
