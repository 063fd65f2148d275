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
from .coupled import Coupling

MAX_ITERATIONS = 200
MAX_ROUNDS = 12   # initializations redone for outputs an FMU first sets at exitInitializationMode


def initialize(system: Coupling, start_time: float, overrides: dict, tolerance: float,
               max_iterations: int = MAX_ITERATIONS) -> int:
    """Bring every FMU to the start of the run; returns the number of exchanges used.  ``tolerance``:
    the run's ``init_tolerance`` (its default lives in :class:`~.run.Settings`, the one place).

    An FMU may set outputs only at exitInitializationMode (a foreign FMU that computes its start
    there; FMI 2.0 allows no later change before the first step).  The values each connection
    carries are read before and after the exit; where they differ, every FMU is reset
    (fmi2Reset) and initialized again with those connections pinned to the values the exit gave,
    the pinned values iterated with IQN-ILS over such rounds until the exit changes nothing."""
    for comp in system.comps:
        comp.instantiate()
    everything = list(range(len(system.links)))
    pinned: dict[int, np.ndarray] = {}
    acc, used = None, 0
    for round_ in range(MAX_ROUNDS + 1):
        if round_:
            for comp in system.comps:
                _call(system, comp, "reset", start_time)
        for comp in system.comps:
            comp.fmu.setupExperiment(startTime=start_time)
        for (name, var), value in overrides.items():
            system.by_name[name].set_start(var, value)
        system.stepping(False)
        for comp in system.comps:
            _call(system, comp, "enterInitializationMode", start_time)
        used += settle(system, start_time, tolerance, max_iterations, pinned)
        before = _values(system, everything, pinned)
        for comp in system.comps:
            _call(system, comp, "exitInitializationMode", start_time)
        system.stepping(True)
        after = _values(system, everything)
        late = _late_links(system, before, after, tolerance)
        if not late:
            break
        if round_ == MAX_ROUNDS:
            _inconsistent_exit(system, late, before, after, start_time)
        members = sorted(set(pinned) | set(late))
        u = np.concatenate([before[system.slices[i]] for i in members])
        gu = np.concatenate([after[system.slices[i]] for i in members])
        if acc is None or set(late) - set(pinned):   # new late connections: restart the accelerator
            acc = IQNILS(omega0=0.5, reuse=0)   # on values scaled to order 1, as in _iterate
            scale = np.maximum(np.abs(gu), 1e-9 * max(1.0, float(np.max(np.abs(gu), initial=0.0))))
        late_u = scale * acc.next(u / scale, gu / scale)
        pos = 0
        for i in members:
            n = len(system.links[i].dst_vrs)
            pinned[i] = late_u[pos:pos + n]
            pos += n
    system.clear_past()
    system.exchange(start_time, order=0)  # values after the FMUs computed their initial states
    return used


def _late_links(system: Coupling, before: np.ndarray, after: np.ndarray, tolerance: float) -> list[int]:
    """The connections whose source gives another value after exitInitializationMode than before."""
    out = []
    for i, sl in enumerate(system.slices):
        if _residual(before[sl], after[sl])[0] > tolerance:
            out.append(i)
    return out


def _inconsistent_exit(system: Coupling, late: list[int], before: np.ndarray, after: np.ndarray,
                       t: float) -> None:
    i = late[0]
    sl = system.slices[i]
    j = int(np.argmax(np.abs(after[sl] - before[sl])))
    raise SimulationError(f"initialization did not converge at t = {t:.6g} s: connection "
                          f"{system.names[sl][j]} still changes at exitInitializationMode after "
                          f"{MAX_ROUNDS} rounds ({before[sl][j]:.6g} in initialization mode, {after[sl][j]:.6g} "
                          "after it): the FMU sets this output only when it leaves initialization mode, and "
                          "its start contradicts the values it was given; check its start values and parameters.")


def settle(system: Coupling, t: float, tolerance: float, max_iterations: int,
           pinned: dict[int, np.ndarray] | None = None) -> int:
    """Settle the connections in initialization mode; those in ``pinned`` (connection index ->
    values) carry the given values instead of what their source gives now."""
    pinned = pinned or {}
    everything = list(range(len(system.links)))
    if not everything:   # no Real connections: the discrete ones held once, nothing to settle
        if system.discrete:
            system.discrete.move(system.refused)
        return 0
    graph = component_graph(system.comps, system.scene.connections)
    used = 0
    for block in strongly_connected(graph):
        members = [i for i, g in enumerate(system.links) if g.dst in block]
        if not members:
            continue
        if is_loop(block, graph):
            used += _iterate(system, members, t, tolerance, max_iterations, block, pinned)
        else:
            _evaluate(system, members, None, pinned)
            used += 1
    # the check sweep: FMUs may have more initial dependencies than they declare
    u = _values(system, everything, pinned)
    gu = _evaluate(system, everything, u, pinned)
    used += 1
    if _residual(u, gu)[0] > tolerance:
        used += _iterate(system, everything, t, tolerance, max_iterations, None, pinned, start=gu)
    return used


def _values(system: Coupling, members: list[int], pinned: dict[int, np.ndarray] | None = None) -> np.ndarray:
    """What the member connections currently carry (pulled now; a pinned one its pinned values)."""
    if not members:
        return np.zeros(0)
    pinned = pinned or {}
    return np.concatenate([pinned[i] if i in pinned else system.pull(i) for i in members])


def _evaluate(system: Coupling, members: list[int], u: np.ndarray | None,
              pinned: dict[int, np.ndarray] | None = None) -> np.ndarray:
    """Feed ``u`` (or, if None, the sources' current values) into the members; return G(u): what
    the sources give after that."""
    pinned = pinned or {}
    if system.discrete:   # Integer/Boolean/Enumeration connections: each iteration holds the current values
        system.discrete.move(system.refused)
    pos = 0
    for i in members:
        n = len(system.links[i].dst_vrs)
        if u is not None:
            value = u[pos:pos + n]
        else:
            value = pinned[i] if i in pinned else system.pull(i)
        zero = np.zeros(n)
        system.feed_group(i, value, zero, zero)
        pos += n
    return _values(system, members, pinned)


def _residual(u: np.ndarray, gu: np.ndarray) -> tuple[float, int]:
    scale = np.maximum(np.maximum(np.abs(u), np.abs(gu)), 1e-300)
    return relative_residual(u, gu, scale, 1e-12 * max(1.0, float(np.max(scale, initial=0.0))))


def _iterate(system: Coupling, members: list[int], t: float, tolerance: float, max_iterations: int,
             block: list[int] | None, pinned: dict[int, np.ndarray], start: np.ndarray | None = None) -> int:
    acc = IQNILS(omega0=0.5, reuse=0)
    u = _values(system, members, pinned) if start is None else start
    # the accelerator works on values scaled to order 1 (newtons and metres side by side)
    scale = np.maximum(np.abs(u), 1e-9 * max(1.0, float(np.max(np.abs(u), initial=0.0))))
    res, worst = np.inf, 0
    best, stalled, plain = np.inf, 0, False
    for k in range(1, max_iterations + 1):
        # accelerated: feed u, read G(u).  If that stalls (a non-smooth or inconsistent FMU), fall
        # back to plain Gauss-Seidel sweeps: each connection fed what its source gives now.
        gu = _evaluate(system, members, None if plain else u, pinned)
        res, worst = _residual(u, gu)
        if res <= tolerance:
            if not plain:
                _evaluate(system, members, gu, pinned)
            return k
        if res < 0.5 * best:
            best, stalled = res, 0
        else:
            stalled += 1
            plain = plain or stalled >= 5
        u = gu if plain else scale * acc.next(u / scale, gu / scale)
    names = [n for i in members for n in system.names[system.slices[i]]]
    where = (" in the loop " + " -> ".join(system.comps[i].name for i in block)) if block else ""
    raise SimulationError(f"initialization did not converge{where} at t = {t:.6g} s: after {max_iterations} "
                          f"iterations connection {names[worst]} still changes by {res:.3g} (relative; tolerance "
                          f"{tolerance:g}). The initial values of the components contradict each other; check "
                          "the start values and parameters feeding this connection.")


def _call(system: Coupling, comp, what: str, t: float) -> None:
    try:
        getattr(comp.fmu, what)()
    except Exception:
        raise system.refused(comp, f"in {what} at t = {t:.6g} s") from None
