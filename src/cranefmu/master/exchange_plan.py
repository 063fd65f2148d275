"""The exchange of a communication point as index arrays, built once per run (:func:`plan_phases`).

The connection groups in exchange order are cut into *phases*: consecutive groups whose reads no
input set among them changes (a phase ends where a group would read a component that an input set
of the phase makes stale), so that every source of a phase is read once, the phase's values are
taken from one read buffer with one gather, extrapolated with one product, and written into one set
buffer.  The FMI writes of a phase are also planned here: a run of consecutive groups into one
destination that all take rate inputs is written with one fmi2SetReal of values and rates.
"""
from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numpy as np

from .coupling import InputGroup


@dataclass
class Write:
    """One fmi2SetReal of a phase: ``count`` values of the set buffer at ``start`` into ``comp``."""

    comp: object                 # the destination FmuComponent
    vrs: object                  # ctypes array of value references
    count: int
    values: object               # ctypes view of the set buffer from ``start``
    start: int                   # offset in the set buffer
    stales: bool                 # some input written makes the destination's read stale
    derivatives: list            # (group, a, b): groups fed their slopes with fmi2SetRealInputDerivatives


class Phase:
    """Consecutive connection groups (in exchange order) whose reads no input set among them changes."""

    def __init__(self, groups: list[InputGroup], read_at: list[int]):
        self.groups = groups
        self.sources = list(dict.fromkeys(g.src for g in groups))
        self.sl = slice(groups[0].sl.start, groups[-1].sl.stop)
        gather, factor, offset, set_values = [], [], [], []
        rate_sel, set_d1, set_d2 = [], [], []
        self.members = []
        for g in groups:
            a = g.sl.start - self.sl.start
            n = len(g.dst_vrs)
            self.members.append((g, a, a + n))
            gather += [read_at[g.src] + int(i) for i in g.src_pos]
            factor += list(g.factor)
            offset += list(g.offset)
            set_values += range(g.set_at, g.set_at + n)
            if g.dt_vrs is not None:
                rate_sel += range(a, a + n)
                set_d1 += range(g.set_at + n, g.set_at + 2 * n)
                set_d2 += range(g.set_at + 2 * n, g.set_at + 3 * n)
        index = lambda xs: np.array(xs, dtype=np.intp)   # noqa: E731
        self.gather, self.set_values = index(gather), index(set_values)
        self.rate_sel, self.set_d1, self.set_d2 = index(rate_sel), index(set_d1), index(set_d2)
        self.factor, self.offset = np.array(factor), np.array(offset)
        self.plain = all(g.plain for g in groups)
        self.n = self.sl.stop - self.sl.start
        self.zero = np.zeros(self.n)
        self.all_rates = len(rate_sel) == self.n
        self.source_comps: list = []
        self.writes: list[Write] = []


def plan_writes(phase: Phase, comps: list, set_all) -> list[Write]:
    """The phase's fmi2SetReal calls: runs of consecutive groups into one destination that all take
    rate inputs (their parts of the set buffer are adjacent) in one call each, else group by group."""
    runs: list[list] = []
    for g, a, b in phase.members:
        if runs and runs[-1][0].dst == g.dst:
            runs[-1].append(g)
        else:
            runs.append([g])
    size = ctypes.sizeof(ctypes.c_double)
    out = []
    for run in runs:
        comp = comps[run[0].dst]
        merge = len(run) > 1 and all(g.dt_vrs is not None and not g.fmi_derivatives for g in run)
        pieces = [run] if merge else [[g] for g in run]
        for piece in pieces:
            vrs = [vr for g in piece for vr in g.set_vrs]
            start = piece[0].set_at
            derivatives = [(g, g.sl.start - phase.sl.start, g.sl.stop - phase.sl.start)
                           for g in piece if g.fmi_derivatives]
            out.append(Write(comp, (ctypes.c_uint * len(vrs))(*vrs), len(vrs),
                             (ctypes.c_double * len(vrs)).from_buffer(set_all, start * size), start,
                             any(not g.keeps_fresh for g in piece), derivatives))
    return out


def cut_phases(links: list[InputGroup]) -> list[list[InputGroup]]:
    """The groups in exchange order cut where a group would read a component made stale by an input
    set earlier in the same phase."""
    phases, current, stale = [], [], set()
    for g in links:
        if g.src in stale:
            phases.append(current)
            current, stale = [], set()
        current.append(g)
        if not g.keeps_outputs:
            stale.add(g.dst)
    phases.append(current)
    return [p for p in phases if p]
