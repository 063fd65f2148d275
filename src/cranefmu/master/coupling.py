"""The connection graph: who feeds whom, in which order values must move, and input extrapolation.

Values move along connections at every communication point.  An output that depends directly on
an input (declared in the FMU's ModelStructure) must be read only after that input was set, so
components are visited in topological order of the feedthrough graph; a cycle in that graph is
an algebraic loop.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
import weakref

import numpy as np

from ..errors import SceneError
from .discrete_links import check_discrete
from .fmu import FmuComponent
from .graph import DependencyLoop, topological_order
from .scene import ConnectionSpec


@dataclass
class InputGroup:
    """The connections from one source component into one destination component (one get, one set):
    wiring only, built by :func:`input_groups` and completed by :class:`~.coupled.Coupling` (the values
    themselves live in the coupling's arrays, at :attr:`sl`)."""

    src: int
    dst: int
    src_vrs: list[int]
    dst_vrs: list[int]
    factor: np.ndarray
    offset: np.ndarray
    dt_vrs: list[int] | None = None    # the destination's <input>_dt inputs, if it offers them
    dt2_vrs: list[int] | None = None
    src_names: list[str] = field(default_factory=list)
    dst_names: list[str] = field(default_factory=list)
    fmi_derivatives: bool = False  # no rate inputs, but the FMU can interpolate: fmi2SetRealInputDerivatives
    # set by the Coupling: positions of src_vrs in the source's read vector; ctypes arrays of the
    # destination's value (and rate) references and values for one fmi2SetReal
    src_pos: np.ndarray | None = None
    set_vrs: object = None
    set_values: object = None
    set_view: np.ndarray | None = None
    keeps_outputs: bool = False  # no output of the destination depends on these inputs (Outputs dependencies)
    keeps_fresh: bool = False    # the same, and in step mode: setting them leaves the destination's read valid
    sl: slice | None = None      # this group's part of the vector of all coupling values
    plain: bool = False          # factor 1 and offset 0: values pass unchanged
    set_at: int = 0              # where set_values starts in the coupling's array of all of them


def feedthrough(comp: FmuComponent) -> dict[str, set[str]]:
    """Output name -> names of the inputs it depends on directly (FMI 2 ModelStructure/Outputs).
    Read once per model description (a process keeps those across runs, :mod:`.process`): the
    callers only read it (do not modify)."""
    md = comp.md
    try:
        hit = _FEEDTHROUGH.get(md)
        if hit is None:
            hit = _FEEDTHROUGH[md] = _feedthrough(md)
    except TypeError:   # a description that cannot be a weak key (a test's stand-in): read each time
        return _feedthrough(md)
    return hit


_FEEDTHROUGH: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()   # model description -> feedthrough


def _feedthrough(md) -> dict[str, set[str]]:
    result = {}
    for unknown in md.outputs:
        deps = unknown.dependencies
        if deps is None:  # not declared: FMI says it may depend on every input
            result[unknown.variable.name] = {v.name for v in md.modelVariables if v.causality == "input"}
        else:
            result[unknown.variable.name] = {d.name for d in deps if d.causality == "input"}
    return result


def check_connection(c: ConnectionSpec, comps: dict[str, FmuComponent]) -> ConnectionSpec:
    """Refuse a connection whose ends do not exist or do not fit (causality, type, unit); return it
    with the conversion it needs: its LinearTransformation if it has one, else the conversion
    between the two ends' units from the FMUs' UnitDefinitions (e.g. mm -> m)."""
    src, dst = comps[c.src], comps[c.dst]
    a = src.variables.get(c.src_var)
    b = dst.variables.get(c.dst_var)
    if a is None:
        raise SceneError(f"connection {c}: {c.src} has no variable {c.src_var!r}")
    if b is None:
        raise SceneError(f"connection {c}: {c.dst} has no variable {c.dst_var!r}")
    if a.causality != "output":
        raise SceneError(f"connection {c}: start {c.src}.{c.src_var} is a {a.causality}, must be an output")
    if b.causality != "input":
        raise SceneError(f"connection {c}: end {c.dst}.{c.dst_var} is a {b.causality}, must be an input")
    if a.type != "Real" or b.type != "Real":   # Integer, Boolean, Enumeration: held as read (.discrete_links)
        check_discrete(c, a.type, b.type)
        return c
    ua, ub = a.unit or "", b.unit or ""
    if ua == ub or c.transformed or c.factor != 1.0 or c.offset != 0.0:
        return c
    sa, sb = _si(src, ua), _si(dst, ub)
    if sa is None or sb is None or sa[0] != sb[0]:
        raise SceneError(f"connection {c}: unit {ua or 'none'!r} -> {ub or 'none'!r} differ and the connection "
                         "has no LinearTransformation to convert")
    (_, fa, oa), (_, fb, ob) = sa, sb
    return replace(c, factor=fa / fb, offset=(oa - ob) / fb)


_BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def _si(comp: FmuComponent, unit: str) -> tuple[tuple, float, float] | None:
    """(base-unit exponents, factor, offset) of ``unit`` in ``comp``'s UnitDefinitions: SI = factor * v + offset."""
    if not unit:
        return (0,) * len(_BASE), 1.0, 0.0
    for u in comp.md.unitDefinitions:
        if u.name == unit and u.baseUnit is not None:
            b = u.baseUnit
            return tuple(getattr(b, k) for k in _BASE), float(b.factor), float(b.offset)
    return None


def visit_order(comps: list[FmuComponent], connections: list[ConnectionSpec]) -> list[int]:
    """Component indices so that every feedthrough source is visited before its destination."""
    index = {c.name: i for i, c in enumerate(comps)}
    ft = [feedthrough(c) for c in comps]
    graph: dict[int, set[int]] = {i: set() for i in range(len(comps))}
    for c in connections:
        s, d = index[c.src], index[c.dst]
        if ft[s].get(c.src_var):
            graph[d].add(s)
    try:
        order = topological_order(graph)
    except DependencyLoop as err:
        names = " -> ".join(comps[i].name for i in err.cycle)
        raise SceneError(f"algebraic loop through direct feedthrough: {names}; break it with a component that "
                         "has internal state, or remove a connection") from None
    return order


def exchange_order(comps: list[FmuComponent], groups: list[InputGroup]) -> list[InputGroup]:
    """The groups in an order where each is read only after every input its outputs depend on
    directly was set (variable-level feedthrough).  Raises DependencyLoop for a loop among the groups."""
    ft = [feedthrough(c) for c in comps]
    feeder = {(g.dst, n): i for i, g in enumerate(groups) for n in g.dst_names}
    graph: dict[int, set[int]] = {i: set() for i in range(len(groups))}
    for i, g in enumerate(groups):
        for out in g.src_names:
            for inp in ft[g.src].get(out, ()):
                if (g.src, inp) in feeder:
                    graph[i].add(feeder[(g.src, inp)])
    return [groups[i] for i in topological_order(graph)]


def ordered_links(comps: list[FmuComponent], connections: list[ConnectionSpec]
                  ) -> tuple[list[list[InputGroup]], list[InputGroup]]:
    """(groups per destination, all groups in exchange order).  Groups of one source and one
    destination are kept whole (one get, one set) unless that makes a false loop; then each
    connection is its own group.  A loop of single connections is an algebraic loop: refused."""
    for split in (False, True):
        groups = input_groups(comps, connections, split)
        flat = [g for gs in groups for g in gs]
        try:
            return groups, exchange_order(comps, flat)
        except DependencyLoop as err:
            cycle = err.cycle
    names = " -> ".join(comps[flat[i].src].name for i in cycle)
    via = ", ".join(f"{comps[flat[i].src].name}.{flat[i].src_names[0]} -> {comps[flat[i].dst].name}."
                    f"{flat[i].dst_names[0]}" for i in cycle[:-1])
    raise SceneError(f"algebraic loop through direct feedthrough: {names} (via {via}); break it with a component "
                     "that has internal state, or remove a connection")


def input_groups(comps: list[FmuComponent], connections: list[ConnectionSpec],
                 split: bool = False) -> list[list[InputGroup]]:
    """Per destination component, its incoming connections grouped by source component (with
    ``split``, one group per connection)."""
    index = {c.name: i for i, c in enumerate(comps)}
    seen: dict[tuple[str, str], ConnectionSpec] = {}
    per_dst: list[dict] = [dict() for _ in comps]
    for c in connections:
        key = (c.dst, c.dst_var)
        if key in seen:
            raise SceneError(f"connection {c}: input {c.dst}.{c.dst_var} is already fed by {seen[key]}")
        seen[key] = c
        s, d = index[c.src], index[c.dst]
        g = per_dst[d].setdefault((s, c.dst_var) if split else s, InputGroup(s, d, [], [], np.zeros(0), np.zeros(0)))
        g.src_names.append(c.src_var)
        g.dst_names.append(c.dst_var)
        g.src_vrs.append(comps[s].variables[c.src_var].valueReference)
        g.dst_vrs.append(comps[d].variables[c.dst_var].valueReference)
        g.factor = np.append(g.factor, c.factor)
        g.offset = np.append(g.offset, c.offset)
        dt = comps[d].variables.get(c.dst_var + "_dt")
        dt2 = comps[d].variables.get(c.dst_var + "_dt2")
        if g.dt_vrs is not None or len(g.dst_vrs) == 1:
            if dt is not None and dt2 is not None:
                g.dt_vrs = (g.dt_vrs or []) + [dt.valueReference]
                g.dt2_vrs = (g.dt2_vrs or []) + [dt2.valueReference]
            else:
                g.dt_vrs = g.dt2_vrs = None
    groups = [list(d.values()) for d in per_dst]
    for g in (g for gs in groups for g in gs):
        # an FMU without our rate inputs gets the slopes through the FMI call, if it declares that it can
        g.fmi_derivatives = g.dt_vrs is None and bool(comps[g.dst].md.coSimulation.canInterpolateInputs)
    return groups


def lagrange_weights(ts: list[float], t: float) -> tuple[np.ndarray, np.ndarray]:
    """Weights w1, w2 such that sum(w1 * u_i), sum(w2 * u_i) are the first and second derivative
    at ``t`` of the polynomial through the points (ts[i], u_i); at most three points, any spacing.
    Remembered per (ts, t): every connection group of a step asks for the same times (do not
    modify the arrays returned)."""
    key = (t, *ts)
    w = _WEIGHTS.get(key)
    if w is None:
        if len(_WEIGHTS) > 64:
            _WEIGHTS.clear()
        w = _WEIGHTS[key] = _lagrange_weights(ts, t)
    return w


_WEIGHTS: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}


def _lagrange_weights(ts: list[float], t: float) -> tuple[np.ndarray, np.ndarray]:
    k = len(ts)
    if k == 2:   # a line (the loop below gives the same numbers: den = 1.0 * (t_i - t_j))
        t0, t1 = ts
        return np.array((1.0 / (t0 - t1), 1.0 / (t1 - t0))), np.zeros(2)
    w1, w2 = np.zeros(k), np.zeros(k)
    for i in range(k):
        others = [ts[j] for j in range(k) if j != i]
        den = 1.0
        for tj in others:
            den *= ts[i] - tj
        if k == 2:
            w1[i] = 1.0 / den
        elif k == 3:
            w1[i] = ((t - others[0]) + (t - others[1])) / den
            w2[i] = 2.0 / den
    return w1, w2


def rates(points: list[tuple[float, np.ndarray]], t: float) -> tuple[np.ndarray, np.ndarray]:
    """First and second time derivative at ``t`` of the polynomial through ``points`` (t_i, u_i)."""
    if len(points) < 2:
        zero = np.zeros_like(points[-1][1])
        return zero, zero
    w1, w2 = lagrange_weights([p[0] for p in points], t)
    values = np.array([p[1] for p in points])
    return w1 @ values, w2 @ values
