"""Dependency graphs, one representation for every use: ``graph[d]`` = the nodes d depends on.

Strongly connected blocks (Tarjan) give both the initialization's plan (which components' values
must be settled before which, and which groups must be iterated together) and the step's orders
(:func:`topological_order`, used by :mod:`.coupling` for the visit and exchange order, where a
block of more than one node is an algebraic loop).

A connection src -> dst makes dst's inputs depend on src's output; that output depends on src's
inputs at initialization if the FMU says so (ModelStructure/InitialUnknowns; an output not
listed, or listed without a dependencies attribute, may depend on every input).
"""
from __future__ import annotations

import weakref

from .fmu import FmuComponent
from .scene import ConnectionSpec


def init_feedthrough(comp: FmuComponent) -> dict[str, bool]:
    """Output name -> does it depend on some input at initialization.  Read once per model description
    (a process keeps those across runs, :mod:`.process`): the callers only read it (do not modify)."""
    try:
        hit = _INIT_FEEDTHROUGH.get(comp.md)
        if hit is None:
            hit = _INIT_FEEDTHROUGH[comp.md] = _init_feedthrough(comp.md)
    except TypeError:   # a description that cannot be a weak key (a test's stand-in): read each time
        return _init_feedthrough(comp.md)
    return hit


_INIT_FEEDTHROUGH: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()   # model description -> the above


def _init_feedthrough(md) -> dict[str, bool]:
    inputs = {v.name for v in md.modelVariables if v.causality == "input"}
    listed = {u.variable.name: u for u in getattr(md, "initialUnknowns", []) or []}
    out = {}
    for v in md.modelVariables:
        if v.causality != "output":
            continue
        u = listed.get(v.name)
        if u is None or u.dependencies is None:
            out[v.name] = bool(inputs)
        else:
            out[v.name] = any(d.name in inputs for d in u.dependencies)
    return out


def component_graph(comps: list[FmuComponent], connections: list[ConnectionSpec]) -> dict[int, set[int]]:
    """dst -> the sources whose connected output depends on their own inputs at initialization."""
    index = {c.name: i for i, c in enumerate(comps)}
    ft = [init_feedthrough(c) for c in comps]
    graph: dict[int, set[int]] = {i: set() for i in range(len(comps))}
    for c in connections:
        s, d = index[c.src], index[c.dst]
        if ft[s].get(c.src_var, True):
            graph[d].add(s)
    return graph


def strongly_connected(graph: dict[int, set[int]]) -> list[list[int]]:
    """Strongly connected components (Tarjan 1972), sources before the nodes that need them.

    ``graph[d]`` are the nodes d depends on.  A component of one node is a loop only if it
    depends on itself.
    """
    index: dict[int, int] = {}
    low: dict[int, int] = {}
    stack: list[int] = []
    on_stack: set[int] = set()
    out: list[list[int]] = []
    counter = [0]

    def visit(v: int) -> None:  # recursion depth = number of components: small
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            block = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                block.append(w)
                if w == v:
                    break
            out.append(sorted(block))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out  # Tarjan emits a block after every block it depends on


def is_loop(block: list[int], graph: dict[int, set[int]]) -> bool:
    return len(block) > 1 or block[0] in graph[block[0]]


class DependencyLoop(Exception):
    """A loop in a graph that must have none; ``cycle`` lists its nodes, the first repeated last."""

    def __init__(self, cycle: list[int]):
        super().__init__(cycle)
        self.cycle = cycle


def topological_order(graph: dict[int, set[int]]) -> list[int]:
    """Every node after the nodes it depends on (Kahn: the ready nodes in rounds, each round in the
    order the nodes were first named, as ``graphlib.TopologicalSorter.static_order``, so the exchange
    order is the one every earlier result was computed with); :class:`DependencyLoop` for a loop."""
    waiting: dict[int, int] = {}
    needed_by: dict[int, list[int]] = {}
    for node, deps in graph.items():
        waiting[node] = waiting.get(node, 0) + len(deps)
        needed_by.setdefault(node, [])
        for dep in deps:
            waiting.setdefault(dep, 0)
            needed_by.setdefault(dep, []).append(node)
    order, ready = [], [n for n, count in waiting.items() if count == 0]
    while ready:
        order += ready
        fresh = []
        for node in ready:
            for later in needed_by[node]:
                waiting[later] -= 1
                if waiting[later] == 0:
                    fresh.append(later)
        ready = fresh
    if len(order) < len(waiting):
        left = set(waiting) - set(order)
        rest = {n: graph.get(n, set()) & left for n in left}
        block = next(b for b in strongly_connected(rest) if is_loop(b, rest))
        raise DependencyLoop(_cycle(block, graph))
    return order


def _cycle(block: list[int], graph: dict[int, set[int]]) -> list[int]:
    """A closed path through the loop ``block`` starting at its first node (depth first)."""
    members, start = set(block), block[0]
    path, seen = [start], {start}
    while True:
        nxt = sorted(graph[path[-1]] & members)
        if start in nxt and (len(path) > 1 or start in graph[start]):
            return path + [start]
        step = next((w for w in nxt if w not in seen), None)
        if step is None:           # a dead end inside the block: back up
            path.pop()
            if not path:
                return [start, start]
            continue
        seen.add(step)
        path.append(step)
