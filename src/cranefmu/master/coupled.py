"""The coupling as an algorithm sees it: whole vectors of coupling values and a handful of operations.

A coupling value is one connection's value (source output times the connection's factor plus its
offset), as the destination input receives it; the vector of all of them is in exchange order
(:attr:`Coupling.names`).  An algorithm (:mod:`.algorithms`) drives the FMUs only through:

- :meth:`Coupling.values`, :meth:`~Coupling.past`, :meth:`~Coupling.sizes`: the values at the last
  communication point, the last few points, each value's largest magnitude so far;
- :meth:`~Coupling.predict`: the values extrapolated from the past;
- :meth:`~Coupling.feed`, :meth:`~Coupling.feed_polynomial`: what the inputs follow over the coming step;
- :meth:`~Coupling.read`, :meth:`~Coupling.image`: what the FMUs give now (``image`` also passes each
  value on, so that outputs fed through by their inputs are read with the partner's new value);
- :meth:`~Coupling.step`: FMUs step from t to t + h;
- :meth:`~Coupling.snapshot`, :meth:`~Coupling.restore`, :meth:`~Coupling.release`: state of all FMUs or
  of a subset;
- :meth:`~Coupling.commit`: the step is done; the values at its end move (the next step's inputs).

Subsets are :class:`Part` objects made by the coupling (:meth:`~Coupling.part`); a vector handed
with a part has the part's length.  The connection groups, exchange phases, batched FMI calls and
the fed / rates / read-buffer bookkeeping stay inside :class:`~.system.CoSystem` and this module.
"""
from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from .bond_inference import scene_bonds
from .coupling import feedthrough, lagrange_weights, rates
from .system import CoSystem


class Part:
    """Some coupling values: those fed into some components (or among them).  Made by
    :meth:`Coupling.part`; ``at`` are their positions in the whole vector, ``names`` theirs."""

    def __init__(self, system: CoSystem, groups: list, batched: bool = False):
        self._groups, n = [], 0
        for g in groups:
            m = g.sl.stop - g.sl.start
            self._groups.append((g, slice(n, n + m)))
            n += m
        self.n = n
        self.at = (np.concatenate([np.arange(g.sl.start, g.sl.stop) for g in groups]) if groups
                   else np.zeros(0, dtype=np.intp))
        self.names = [system.variable_names[i] for i in self.at]
        # rates of the whole part in one product (fewer calls; per connection they may differ in the last bit)
        self._batched = batched

    def __len__(self) -> int:
        return self.n


class Coupling:
    """The FMUs of a :class:`~.system.CoSystem` and the values between them, as whole vectors."""

    def __init__(self, system: CoSystem):
        self._s = system
        self.n = system.n_coupling
        self.names: list[str] = system.variable_names
        self.components: list[str] = [c.name for c in system.comps]
        self.order: list[int] = list(system.order)   # feedthrough order of the components
        self.extrapolation: int = system.order_of_extrapolation   # the run's order (commit, predict)
        self.scene_name: str = system.scene.name
        self.can_rollback = system.can_rollback
        self.stats = system.stats
        self.whole = Part(system, system.links)
        self._all = range(len(system.comps))

    # --- what there is --------------------------------------------------------------------------
    def part(self, into: Iterable[int] | None = None, among: Iterable[int] | None = None,
             after: Iterable[int] | None = None, batched: bool = False) -> Part:
        """The values fed into the components ``into`` (in the order of their inputs), or exchanged
        among the components ``among`` (in exchange order); ``after``: only those whose source is one
        of these."""
        s = self._s
        if into is not None:
            first = None if after is None else set(after)
            groups = [g for d in into for g in s.groups[d] if first is None or g.src in first]
        else:
            inside = set(among or ())
            groups = [g for g in s.links if g.src in inside and g.dst in inside]
        return Part(s, groups, batched)

    def can_save(self, i: int) -> bool:
        """Component i can save and restore its state (FMI canGetAndSetFMUstate)."""
        return self._s.comps[i].can_get_state

    def feeds_through(self, i: int) -> bool:
        """Some output of component i depends directly on one of its inputs (FMI ModelStructure)."""
        return any(feedthrough(self._s.comps[i]).values())

    def bonds(self) -> dict[str, list[str]]:
        """Power bond name -> the components of its two sides: declared in the scene, or inferred from
        the connections' units where it declares none (:mod:`.bond_inference`)."""
        s = self._s
        declared_or_inferred = scene_bonds(s.scene, {c.name: c.md for c in s.comps})[0]   # settled when read
        return {name: [side.get("component", "") for side in sides] for name, sides in declared_or_inferred}

    def _sources(self):
        """Per value, in exchange order: (the source output's model variable, the connection's factor)."""
        s = self._s
        for g in s.links:
            by_vr = {v.valueReference: v for v in s.comps[g.src].md.modelVariables}
            yield from ((by_vr[vr], factor) for vr, factor in zip(g.src_vrs, g.factor))

    def units(self) -> list[str]:
        """Per value, the unit its source output declares ('' where none)."""
        return [v.unit or (v.declaredType.unit if v.declaredType else None) or "" for v, _ in self._sources()]

    def nominals(self, part: Part | None = None) -> np.ndarray:
        """Per value, the nominal its source output declares (times the connection's factor), NaN where
        none is declared."""
        out = np.array([abs(float(v.nominal) * factor) if v.nominal is not None else np.nan
                        for v, factor in self._sources()])
        return out if part is None else out[part.at]

    # --- values -------------------------------------------------------------------------------
    def values(self, part: Part | None = None) -> np.ndarray:
        """The values at the last communication point (a new array)."""
        v = self._s.coupling_values()
        return v if part is None else v[part.at]

    def past(self, part: Part, count: int) -> list[tuple[float, np.ndarray]]:
        """The last ``count`` communication points (fewer if there are not as many) as (t, values), oldest first."""
        groups = part._groups
        k = min(len(g.history) for g, _ in groups) if groups else 0
        return [(groups[0][0].history[-j][0], np.concatenate([g.history[-j][1] for g, _ in groups]))
                for j in range(min(count, k), 0, -1)]

    def sizes(self, part: Part | None = None) -> np.ndarray:
        """Each value's largest magnitude so far (not a copy: do not modify)."""
        return self._s.scale if part is None else self._s.scale[part.at]

    def predict(self, t: float, h: float, order: int | None = None) -> np.ndarray:
        """Every value extrapolated from its past to t + h (polynomial of ``order``, default the run's)."""
        return self._s.predicted(t, h, order)

    # --- inputs -------------------------------------------------------------------------------
    def feed(self, t: float, h: float, u: np.ndarray, degree: int, part: Part | None = None) -> None:
        """Over the step from t, the inputs follow the polynomial through their last ``degree`` values
        and ``u`` at t + h (degree 0: ``u`` held over the step)."""
        part = part or self.whole
        s = self._s
        if degree == 0:
            for g, sl in part._groups:
                zero = g.zero if part._batched else np.zeros(sl.stop - sl.start)
                s.push(g, u[sl], zero, zero)
            return
        groups = part._groups
        if part._batched and degree <= 2 and len(groups[0][0].history) >= degree + 1:
            past = [np.concatenate([g.history[-j][1] for g, _ in groups]) for j in range(degree, 0, -1)]
            times = [groups[0][0].history[-j][0] for j in range(degree, 0, -1)]
            w1, w2 = lagrange_weights([*times, t + h], t)
            stack = np.array([*past, u])
            d1, d2 = w1 @ stack, w2 @ stack
            now = past[-1]
            for g, sl in groups:
                s.push(g, now[sl], d1[sl], d2[sl])
            return
        for g, sl in groups:
            d1, d2 = rates([*g.history[-degree:], (t + h, u[sl])], t)
            s.push(g, g.history[-1][1], d1, d2)

    def feed_polynomial(self, value: np.ndarray, d1: np.ndarray, d2: np.ndarray, part: Part | None = None) -> None:
        """Over the coming step the inputs follow value + s d1 + s^2/2 d2 (s: time since the step's start)."""
        s = self._s
        for g, sl in (part or self.whole)._groups:
            s.push(g, value[sl], d1[sl], d2[sl])

    def hold_ends(self, part: Part, h: float) -> None:
        """The inputs hold, from now on, the value their fed polynomial reaches after h."""
        s = self._s
        for g, _ in part._groups:
            u, d1, d2 = g.fed
            zero = np.zeros_like(u)
            s.push(g, u + h * (d1 + 0.5 * h * d2), zero, zero)

    # --- outputs ------------------------------------------------------------------------------
    def read(self, part: Part | None = None) -> np.ndarray:
        """What the sources give now (nothing fed)."""
        s = self._s
        groups = (part or self.whole)._groups
        if len(groups) == 1:   # pull() gives a new array
            return s.pull(groups[0][0])
        if not groups:
            return np.zeros(0)
        return np.concatenate([s.pull(g) for g, _ in groups])

    def image(self, part: Part | None = None, fed_through_only: bool = False) -> np.ndarray:
        """G: what the sources give now, read in exchange order, each value passed on to its input
        as held (so that an output fed through by that input is read with it); ``fed_through_only``:
        passed on only where the destination has an output that depends on it directly (the other
        inputs are fed anew before they are used)."""
        s = self._s
        part = part or self.whole
        out = np.empty(part.n)
        for g, sl in part._groups:
            value = s.pull(g)
            out[sl] = value
            if fed_through_only:
                if not g.keeps_outputs:
                    s.push(g, value, g.zero, g.zero)
            else:
                zero = np.zeros_like(value)
                s.push(g, value, zero, zero)
        return out

    # --- stepping -----------------------------------------------------------------------------
    def step(self, t: float, h: float, members: Iterable[int] | None = None, ends: bool = True) -> None:
        """The FMUs ``members`` (default all, in component order) step from t to t + h [s]; ``ends``:
        the inputs' values at t + h as fed are noted (for the power bonds; pass False while a step is
        still being fed, then call :meth:`note_ends`)."""
        s = self._s
        for i in self._all if members is None else members:
            s.do_step(i, t, h)
        if ends:
            s.capture_input_ends(h)

    def note_ends(self, h: float, values: np.ndarray | None = None, part: Part | None = None) -> None:
        """The inputs' values at the end of the step of h, as fed; with ``values``: those of ``part`` are these."""
        if values is None:
            self._s.capture_input_ends(h)
        else:
            self._s.input_end[part.at] = values

    def commit(self, t1: float) -> None:
        """The step to t1 is done: every value moves (recorded as the value at t1) and the inputs are
        fed for the next step (extrapolated from the past, at the run's order)."""
        self._s.exchange(t1)

    def commit_as_read(self, t1: float) -> None:
        """libcosim's exchange: every output read once, now, and held by its input over the next step
        (no re-read after inputs that it depends on directly were set); the values recorded at t1."""
        self._s.exchange_as_read(t1)

    def rest(self, t0: float, h: float) -> None:
        """Give every value a past at rest (its value at t0 also at t0 - h and t0 - 2 h), and feed
        the inputs from it."""
        self._s.rest(t0, h)

    # --- state --------------------------------------------------------------------------------
    def snapshot(self, members: list[int] | None = None) -> list:
        """Save the state of the FMUs ``members`` (default all: also the values' past) for a retry."""
        return self._s.save(members)

    def restore(self, snap: list) -> None:
        """Back to the snapshot (it stays valid for another restore until released)."""
        self._s.restore(snap)

    def release(self, snap: list | None) -> None:
        """Free the snapshot's FMU states."""
        self._s.release(snap)
