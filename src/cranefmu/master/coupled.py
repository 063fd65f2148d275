"""The coupled FMUs of one scene and the values between them, as arrays: the one interface to them.

A coupling value is one connection's value (source output times the connection's factor plus its
offset), as the destination input receives it; the vector of all of them is in exchange order
(:attr:`Coupling.names`).  The coupling keeps, as arrays of that length:

- the past values: a ring buffer of the last three communication points (3 x n, and their times);
- what each input was fed for the coming step: value, rate and curvature (the polynomial
  value + s rate + s^2/2 curvature, s the time since the step's start), and where it was fed as a
  plain hold (:attr:`held`: its end value is the value itself);
- each input's value at the end of the last step as fed (:attr:`input_end`, for the power bonds) and
  each value's largest magnitude so far (:attr:`scale`);
- one read buffer (every component's outputs read with one fmi2GetReal into its part), one set
  buffer (every connection group's values and rates for one fmi2SetReal) and the per-phase index
  arrays between them (:mod:`.exchange_plan`).

Algorithms (:mod:`.algorithms`), initialization, power bonds, commands and the watches use only the
methods here:

- :meth:`values`, :meth:`past`, :meth:`sizes`, :meth:`predict`: the values now, the last points, their
  sizes, the values extrapolated from the past;
- :meth:`feed`, :meth:`feed_polynomial`, :meth:`hold_ends`: what the inputs follow over the coming step;
- :meth:`read`, :meth:`image`: what the FMUs give now (``image`` also passes each value on);
- :meth:`step`, :meth:`commit`, :meth:`commit_as_read`, :meth:`rest`: FMUs step; the values move;
- :meth:`snapshot`, :meth:`restore`, :meth:`release`: the state of all FMUs or of a subset.

Subsets are :class:`Part` objects (:meth:`part`); a vector handed with a part has the part's length.
Extrapolation uses the Lagrange weights of :func:`.coupling.lagrange_weights` in one product per phase
(per connection group where a part is fed group by group), so the numbers are those of the products
numpy computes on those shapes.
"""
from __future__ import annotations

import ctypes
import time as clock
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from .bond_inference import scene_bonds
from .coupling import (InputGroup, check_connection, feedthrough, lagrange_weights, ordered_links, rates,
                       visit_order)
from ..errors import CraneFmuError, ParameterSetError, SceneError, SimulationError
from .discrete_links import DiscreteLinks, is_discrete
from .exchange_plan import Phase, cut_phases, plan_writes
from .fmu import FmuComponent
from .scene import Scene
from .system import RunStats


class Part:
    """Some coupling values: those fed into some components (or among them).  Made by
    :meth:`Coupling.part`; ``at`` are their positions in the whole vector, ``names`` theirs."""

    def __init__(self, coupling: Coupling, groups: list[int], batched: bool = False):
        self._groups, n = [], 0
        for gi in groups:
            g = coupling.links[gi]
            m = g.sl.stop - g.sl.start
            self._groups.append((gi, slice(n, n + m)))
            n += m
        self.n = n
        self.at = (np.concatenate([np.arange(coupling.links[gi].sl.start, coupling.links[gi].sl.stop)
                                   for gi in groups]) if groups else np.zeros(0, dtype=np.intp))
        self.names = [coupling.names[i] for i in self.at]
        # rates of the whole part in one product (fewer calls; per connection they may differ in the last bit)
        self._batched = batched

    def __len__(self) -> int:
        return self.n


class Coupling:
    """Instantiated FMUs of a scene, their connections in exchange order, and the coupling values."""

    def __init__(self, scene: Scene, workdir: Path, extrapolation: int):
        self.scene = scene
        self.scene_name: str = scene.name
        self.extrapolation: int = extrapolation   # the run's order (commit, predict)
        self.comps = [FmuComponent(c.name, c.fmu, workdir / f"fmu_{c.name}") for c in scene.components]
        self.components: list[str] = [c.name for c in self.comps]
        self.by_name = {c.name: c for c in self.comps}
        checked = [check_connection(c, self.by_name) for c in scene.connections]
        # Integer, Boolean and Enumeration connections: a hold of the value read at each exchange, apart
        # from the Real values and their arrays (:mod:`.discrete_links`)
        self.discrete = DiscreteLinks(self.comps, [c for c in checked if is_discrete(c, self.by_name)])
        self.connections = [c for c in checked if not is_discrete(c, self.by_name)]
        # per destination its groups, and every group in exchange order
        per_dst, self.links = ordered_links(self.comps, self.connections)
        index = {id(g): i for i, g in enumerate(self.links)}
        self._into = [[index[id(g)] for g in gs] for gs in per_dst]
        try:
            self.order: list[int] = visit_order(self.comps, self.connections)
        except SceneError:  # components feed each other, but no variable does: any order steps
            first = list(dict.fromkeys(g.dst for g in self.links))
            self.order = first + [i for i in range(len(self.comps)) if i not in first]
        n = 0
        for g in self.links:
            g.sl = slice(n, n + len(g.dst_vrs))
            n += len(g.dst_vrs)
        self.n = n
        self.slices = [g.sl for g in self.links]
        self.names: list[str] = self._variable_names(scene)
        # the arrays (module doc)
        self._past = np.zeros((3, n))      # ring buffer of past values; rows in use: self._rows, oldest first
        self._rows: list[int] = []
        self._times: list[float] = []
        self.fed = np.zeros(n)             # what each input was fed for the coming step ...
        self.fed_rate = np.zeros(n)
        self.fed_curvature = np.zeros(n)
        self.held = np.ones(n, dtype=bool)   # ... as a plain hold (its end value is the value)
        self.input_end = np.zeros(n)       # each input's value at the end of the last step, as fed
        self.ends_wanted = False           # someone reads input_end (a power bond with a connected input)
        self.scale = np.zeros(n)           # running max |value| per coupling variable
        # recorded: every Real output; watched for events: every Integer/Boolean output
        self.out_vrs, self.columns, self.flag_vrs = [], [], []
        for comp in self.comps:
            reals = [v for v in comp.md.modelVariables if v.causality == "output" and v.type == "Real"]
            self.out_vrs.append([v.valueReference for v in reals])
            self.columns += [f"{comp.name}.{v.name}" for v in reals]
            # in the order flags() reads them: Integer and Enumeration (one fmi2GetInteger), then Boolean
            # (issue 35: in the model description's order a Boolean's column got an Enumeration's value)
            self.flag_vrs.append(sorted((v for v in comp.md.modelVariables if v.causality == "output"
                                         and v.type in ("Integer", "Boolean", "Enumeration")),
                                        key=lambda v: v.type == "Boolean"))
        self.flag_names = [f"{c.name}.{v.name}" for c, vs in zip(self.comps, self.flag_vrs) for v in vs]
        self.columns += self.flag_names   # recorded after the Real outputs, as floats
        self.flag_value = np.zeros(len(self.flag_names))
        self.stats = RunStats(fmu_time={c.name: 0.0 for c in self.comps}, fmu_calls={c.name: 0 for c in self.comps})
        self.can_rollback = all(c.can_get_state for c in self.comps)
        self.commands = None   # a .commands.CommandFeed: commanded inputs set at every exchange, before the reads
        self.compiled = True   # use the compiled exchange where it can run (:mod:`.kernel`); False: Python only
        self.python_reason = ""   # why the Python exchange runs ('' where the compiled one does, or not decided yet)
        # more values a stretch's rows carry after the outputs: positions in the read buffer and in input_end
        self.row_extra: tuple[list[int], list[int]] = ([], [])
        self._prepare_buffers()
        for comp in self.comps:   # a component that returned fmi2Fatal: the compiled exchange must not call it
            comp.fatal_listeners.append(self._drop_kernel)
        self.whole = Part(self, list(range(len(self.links))))
        self._all = range(len(self.comps))

    def _prepare_buffers(self) -> None:
        """The set buffer (every group's values and rates, one fmi2SetReal each) and the read order of
        each component (the recorded outputs first, so that a read's first entries are the row's)."""
        self.n_real = sum(len(v) for v in self.out_vrs)
        self._row = np.zeros(self.n_real + len(self.flag_names))
        self._out_slices = []
        a = 0
        for comp, vrs in zip(self.comps, self.out_vrs):
            comp.read_vrs = list(vrs)
            self._out_slices.append((a, a + len(vrs)))
            a += len(vrs)
        reads = [{v.name for v in c.md.modelVariables if v.causality == "output" and v.type == "Real"}
                 for c in self.comps]
        ft = [feedthrough(c) for c in self.comps]
        sizes = []
        for g in self.links:
            g.src_pos = self.comps[g.src].position(g.src_vrs)
            g.plain = bool(np.all(g.factor == 1.0) and np.all(g.offset == 0.0))   # x * 1.0 + 0.0 only turns -0.0 into 0.0
            vrs = g.dst_vrs + (g.dt_vrs + g.dt2_vrs if g.dt_vrs is not None else [])
            g.set_vrs = (ctypes.c_uint * len(vrs))(*vrs)
            sizes.append(len(vrs))
            # the destination's outputs stay valid after this group's inputs are set, if none depends on them
            inputs = set(g.dst_names)
            g.keeps_outputs = not any(ft[g.dst].get(o, set(inputs)) & inputs for o in reads[g.dst])
        self._set_all = (ctypes.c_double * max(1, sum(sizes)))()
        self._set_view = np.ctypeslib.as_array(self._set_all)
        off = 0
        for g, m in zip(self.links, sizes):
            g.set_values = (ctypes.c_double * m).from_buffer(self._set_all, off * ctypes.sizeof(ctypes.c_double))
            g.set_view = self._set_view[off:off + m]
            g.set_at = off
            off += m
        self._flag_reads = []
        for comp, vs in zip(self.comps, self.flag_vrs):
            for boolean in (False, True):
                vrs = [v.valueReference for v in vs if (v.type == "Boolean") == boolean]
                if vrs:
                    values = (ctypes.c_int * len(vrs))()
                    self._flag_reads.append((comp, (ctypes.c_uint * len(vrs))(*vrs), len(vrs), values, boolean))
        self.stepping(False)

    def stepping(self, on: bool) -> None:
        """In initialization mode an FMU's outputs may depend on more inputs than its Outputs
        dependencies list (its InitialUnknowns): there every input set makes the destination read again."""
        for g in self.links:
            g.keeps_fresh = on and g.keeps_outputs
        for c in self.comps:
            c.fresh = False
        self._stepping = on
        self._phases: list[Phase] | None = None   # planned at the first exchange in step mode
        self._kernel = None                        # the compiled exchange bound to those phases

    def _variable_names(self, scene: Scene) -> list[str]:
        """'src.out -> dst.in' for each coupling variable, in the order of the coupling vector."""
        by_dst = {(c.dst, c.dst_var): c for c in scene.connections}
        names = []
        for g in self.links:
            dst = self.comps[g.dst]
            vr_name = {v.valueReference: v.name for v in dst.md.modelVariables   # value references are per type
                       if v.causality == "input" and v.type == "Real"}
            names += [str(by_dst[(dst.name, vr_name[vr])]) for vr in g.dst_vrs]
        return names

    # --- what there is --------------------------------------------------------------------------
    def part(self, into: Iterable[int] | None = None, among: Iterable[int] | None = None,
             after: Iterable[int] | None = None, batched: bool = False) -> Part:
        """The values fed into the components ``into`` (in the order of their inputs), or exchanged
        among the components ``among`` (in exchange order); ``after``: only those whose source is one
        of these."""
        if into is not None:
            first = None if after is None else set(after)
            groups = [gi for d in into for gi in self._into[d] if first is None or self.links[gi].src in first]
        else:
            inside = set(among or ())
            groups = [gi for gi, g in enumerate(self.links) if g.src in inside and g.dst in inside]
        return Part(self, groups, batched)

    def can_save(self, i: int) -> bool:
        """Component i can save and restore its state (FMI canGetAndSetFMUstate)."""
        return self.comps[i].can_get_state

    def feeds_through(self, i: int) -> bool:
        """Some output of component i depends directly on one of its inputs (FMI ModelStructure)."""
        return any(feedthrough(self.comps[i]).values())

    def bonds(self) -> dict[str, list[str]]:
        """Power bond name -> the components of its two sides: declared in the scene, or inferred from
        the connections' units where it declares none (:mod:`.bond_inference`)."""
        declared_or_inferred = scene_bonds(self.scene, {c.name: c.md for c in self.comps})[0]
        return {name: [side.get("component", "") for side in sides] for name, sides in declared_or_inferred}

    def _sources(self):
        """Per value, in exchange order: (the source output's model variable, the connection's factor)."""
        for g in self.links:
            by_vr = {v.valueReference: v for v in self.comps[g.src].md.modelVariables if v.type == "Real"}
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

    # --- the past -------------------------------------------------------------------------------
    def clear_past(self) -> None:
        """Forget every past communication point."""
        self._rows, self._times = [], []

    def _new_point(self, t: float) -> np.ndarray:
        """The ring's row for the values at t (the newest row again if it is at t), as a view."""
        if self._times and self._times[-1] == t:
            return self._past[self._rows[-1]]
        if len(self._rows) < 3:
            row = next(r for r in range(3) if r not in self._rows)
        else:
            row = self._rows.pop(0)
            self._times.pop(0)
        self._rows.append(row)
        self._times.append(t)
        return self._past[row]

    def _last(self, k: int) -> tuple[list[float], list[int]]:
        """The times and ring rows of the last ``k`` points (fewer if there are not as many), oldest first."""
        k = min(k, len(self._rows))
        return self._times[len(self._times) - k:], self._rows[len(self._rows) - k:]

    # --- values -------------------------------------------------------------------------------
    def values(self, part: Part | None = None) -> np.ndarray:
        """The values at the last communication point (a new array)."""
        if not self._rows:
            return np.zeros(self.n if part is None else part.n)
        v = self._past[self._rows[-1]]
        return v.copy() if part is None else v[part.at]

    def past(self, part: Part, count: int) -> list[tuple[float, np.ndarray]]:
        """The last ``count`` communication points (fewer if there are not as many) as (t, values), oldest first."""
        if not part._groups:
            return []
        times, rows = self._last(count)
        return [(t, self._past[r][part.at]) for t, r in zip(times, rows)]

    def sizes(self, part: Part | None = None) -> np.ndarray:
        """Each value's largest magnitude so far (not a copy: do not modify)."""
        return self.scale if part is None else self.scale[part.at]

    def _rates(self, sl: slice, points: int, t: float) -> tuple[np.ndarray, np.ndarray]:
        """First and second derivative at t of the polynomial through the last ``points`` values of ``sl``."""
        times, rows = self._last(points)
        if len(rows) < 2:
            zero = np.zeros(sl.stop - sl.start)
            return zero, zero
        w1, w2 = lagrange_weights(times, t)
        stack = self._past[rows, sl]
        return w1 @ stack, w2 @ stack

    def predict(self, t: float, h: float, order: int | None = None) -> np.ndarray:
        """Every value extrapolated from its past to t + h (polynomial of ``order``, default the run's),
        connection group by connection group."""
        p = self.extrapolation if order is None else order
        out = np.empty(self.n)
        newest = self._past[self._rows[-1]]
        for sl in self.slices:
            d1, d2 = self._rates(sl, p + 1, t)
            out[sl] = newest[sl] + h * (d1 + 0.5 * h * d2)
        return out

    # --- inputs -------------------------------------------------------------------------------
    def feed(self, t: float, h: float, u: np.ndarray, degree: int, part: Part | None = None) -> None:
        """Over the step from t, the inputs follow the polynomial through their last ``degree`` values
        and ``u`` at t + h (degree 0: ``u`` held over the step)."""
        part = part or self.whole
        if degree == 0:
            for gi, sl in part._groups:
                zero = np.zeros(sl.stop - sl.start)
                self.feed_group(gi, u[sl], zero, zero, part._batched)
            return
        groups = part._groups
        times, rows = self._last(degree)
        newest = self._past[rows[-1]]
        if part._batched and degree <= 2 and len(self._rows) >= degree + 1:
            w1, w2 = lagrange_weights([*times, t + h], t)
            stack = np.empty((degree + 1, part.n))
            stack[:degree] = self._past[rows][:, part.at]
            stack[degree] = u
            d1, d2 = w1 @ stack, w2 @ stack
            now = stack[degree - 1]
            for gi, sl in groups:
                self.feed_group(gi, now[sl], d1[sl], d2[sl], False)
            return
        for gi, sl in groups:
            gsl = self.links[gi].sl
            w1, w2 = lagrange_weights([*times, t + h], t)
            stack = np.empty((len(rows) + 1, gsl.stop - gsl.start))
            stack[:-1] = self._past[rows, gsl]
            stack[-1] = u[sl]
            self.feed_group(gi, newest[gsl], w1 @ stack, w2 @ stack, False)

    def feed_polynomial(self, value: np.ndarray, d1: np.ndarray, d2: np.ndarray, part: Part | None = None) -> None:
        """Over the coming step the inputs follow value + s d1 + s^2/2 d2 (s: time since the step's start)."""
        for gi, sl in (part or self.whole)._groups:
            self.feed_group(gi, value[sl], d1[sl], d2[sl], False)

    def hold_ends(self, part: Part, h: float) -> None:
        """The inputs hold, from now on, the value their fed polynomial reaches after h."""
        for gi, _ in part._groups:
            sl = self.links[gi].sl
            u = self.fed[sl] + h * (self.fed_rate[sl] + 0.5 * h * self.fed_curvature[sl])
            zero = np.zeros(sl.stop - sl.start)
            self.feed_group(gi, u, zero, zero, False)

    def feed_group(self, gi: int, value: np.ndarray, d1: np.ndarray, d2: np.ndarray, held: bool = False) -> None:
        """Write connection group ``gi``'s inputs (``held``: as a plain hold): ``value`` at the step start and its first and second time derivative
        (into the rate inputs, or through fmi2SetRealInputDerivatives where the FMU takes those)."""
        g = self.links[gi]
        sl = g.sl
        n = sl.stop - sl.start
        view = g.set_view
        view[:n] = value
        count = n
        if g.dt_vrs is not None:
            view[n:2 * n] = d1
            view[2 * n:] = d2
            count = 3 * n
        comp = self.comps[g.dst]
        try:
            comp.write(g.set_vrs, count, g.set_values)
            if g.fmi_derivatives:
                input_derivatives(comp.fmu, g, d1, d2)
        except Exception:
            raise self.refused(comp, "setting its inputs") from None
        if not g.keeps_fresh:
            comp.fresh = False
        self.fed[sl] = value
        self.fed_rate[sl] = d1
        self.fed_curvature[sl] = d2
        self.held[sl] = held

    # --- outputs ------------------------------------------------------------------------------
    def read_component(self, i: int) -> np.ndarray:
        """Component i's read vector (its Real outputs first): one fmi2GetReal per change of the FMU."""
        comp = self.comps[i]
        try:
            return comp.read()
        except Exception:
            raise self.refused(comp, "reading its outputs") from None

    def pull(self, gi: int) -> np.ndarray:
        """What connection group ``gi``'s source gives now, converted (a new array)."""
        g = self.links[gi]
        return self.read_component(g.src)[g.src_pos] * g.factor + g.offset

    def read(self, part: Part | None = None) -> np.ndarray:
        """What the sources give now (nothing fed)."""
        groups = (part or self.whole)._groups
        if len(groups) == 1:   # pull() gives a new array
            return self.pull(groups[0][0])
        if not groups:
            return np.zeros(0)
        return np.concatenate([self.pull(gi) for gi, _ in groups])

    def image(self, part: Part | None = None, fed_through_only: bool = False) -> np.ndarray:
        """G: what the sources give now, read in exchange order, each value passed on to its input
        as held (so that an output fed through by that input is read with it); ``fed_through_only``:
        passed on only where the destination has an output that depends on it directly (the other
        inputs are fed anew before they are used)."""
        part = part or self.whole
        out = np.empty(part.n)
        for gi, sl in part._groups:
            value = self.pull(gi)
            out[sl] = value
            zero = np.zeros(len(value))
            if fed_through_only:
                if not self.links[gi].keeps_outputs:
                    self.feed_group(gi, value, zero, zero, True)
            else:
                self.feed_group(gi, value, zero, zero, False)
        return out

    def outputs(self) -> np.ndarray:
        """Every Real output, then the discrete outputs of the last :meth:`flags` call (a new array)."""
        return self.fill_outputs(self._row).copy()

    def fill_outputs(self, row: np.ndarray) -> np.ndarray:
        """:meth:`outputs` written into ``row`` (its first len(columns) entries); returns ``row``.
        In step mode one gather from the buffer every component reads into."""
        if self._phases is None:
            for i, (a, b) in enumerate(self._out_slices):
                row[a:b] = self.read_component(i)[:b - a]
        else:
            for i, comp in enumerate(self.comps):
                if not comp.fresh:
                    self.read_component(i)
            row[:self.n_real] = self._read_view[self._row_gather]
        row[self.n_real:len(self.columns)] = self.flag_value
        return row

    def flags(self) -> list[int]:
        """Every Integer/Boolean output (mode flags: slack, lifted, tipping, ...)."""
        out: list[int] = []
        for comp, vrs, n, values, boolean in self._flag_reads:
            try:
                comp.read_discrete(vrs, n, values, boolean)
            except Exception:
                raise self.refused(comp, "reading its discrete outputs") from None
            # a Boolean is 0 or 1 whatever non-zero value the FMU returns
            out += [1 if x else 0 for x in values] if boolean else list(values)
        self.flag_value[:] = out
        return out

    # --- the exchange ---------------------------------------------------------------------------
    def commit(self, t1: float) -> None:
        """The step to t1 is done: every value moves (recorded as the value at t1) and the inputs are
        fed for the next step (extrapolated from the past, at the run's order); in compiled code where
        it can run (the same numbers)."""
        kernel = self.kernel()
        if kernel is None:
            self.exchange(t1)
        else:
            kernel.exchange(t1, self.extrapolation)

    def exchange(self, t: float, order: int | None = None) -> None:
        """Move values along every connection at time t (step mode), phase by phase (:mod:`.exchange_plan`):
        every source of a phase is read, the phase's values taken in one gather, recorded in the ring,
        their rates computed in one product (the polynomial of ``order``, default the run's, through the
        last points), written to the set buffer and into the FMUs."""
        p = self.extrapolation if order is None else order
        if self.commands is not None:
            self.commands.feed(t)
        if self.discrete:
            self.discrete.move(self.refused)
        if self._phases is None:
            self._phases = self._plan_phases()
        new = self._new_point(t)
        times, rows = self._last(p + 1)
        weights = lagrange_weights(times, t) if p > 0 and len(rows) >= 2 else None
        for phase in self._phases:
            self._exchange_phase(phase, new, rows, weights, p)
        np.maximum(self.scale, np.abs(new), out=self.scale)

    def _exchange_phase(self, ph: Phase, new: np.ndarray, rows: list[int], weights, p: int) -> None:
        for comp in ph.source_comps:
            if not comp.fresh:
                try:
                    comp.read()
                except Exception:
                    raise self.refused(comp, "reading its outputs") from None
        values = self._read_view[ph.gather]
        if not ph.plain:
            values = values * ph.factor + ph.offset
        sl = ph.sl
        new[sl] = values
        sv = self._set_view
        sv[ph.set_values] = values
        if weights is None:
            d1 = d2 = ph.zero
            sv[ph.set_d1] = 0.0
            sv[ph.set_d2] = 0.0
        else:
            w1, w2 = weights
            stack = self._past[rows, sl]
            d1 = w1 @ stack
            d2 = w2 @ stack if p > 1 else ph.zero  # a line has no curvature
            sv[ph.set_d1] = d1 if ph.all_rates else d1[ph.rate_sel]
            sv[ph.set_d2] = d2 if ph.all_rates else d2[ph.rate_sel]
        for w in ph.writes:
            comp = w.comp
            try:
                status = comp._set_real(comp._c, w.vrs, w.count, w.values)
                if status > 1:
                    comp._failed("fmi2SetReal", status)
                for g, a, b in w.derivatives:
                    input_derivatives(comp.fmu, g, d1[a:b], d2[a:b])
            except Exception:
                raise self.refused(comp, "setting its inputs") from None
            if w.stales:
                comp.fresh = False
        self.fed[sl] = values
        self.fed_rate[sl] = d1
        self.fed_curvature[sl] = d2
        self.held[sl] = weights is None

    def _plan_phases(self) -> list[Phase]:
        """One read buffer for every component, the row's gather from it, and the phases."""
        total = sum(len(c.read_vrs) for c in self.comps)
        self._read_all = (ctypes.c_double * max(1, total))()
        read_view = np.ctypeslib.as_array(self._read_all)
        at, off = [], 0
        for comp in self.comps:
            n = len(comp.read_vrs)
            comp.use_buffer((ctypes.c_double * n).from_buffer(self._read_all, off * ctypes.sizeof(ctypes.c_double)),
                            read_view[off:off + n])
            at.append(off)
            off += n
        self._read_view = read_view
        self._read_at = at
        self._row_gather = np.array([at[i] + j for i, (a, b) in enumerate(self._out_slices) for j in range(b - a)],
                                    dtype=np.intp)
        out = [Phase(gs, at) for gs in cut_phases(self.links)]
        for ph in out:
            ph.source_comps = [self.comps[i] for i in ph.sources]
            ph.writes = plan_writes(ph, self.comps, self._set_all)
        return out

    def commit_as_read(self, t: float) -> None:
        """libcosim's exchange: every output read once, now, and held by its input over the next step
        (no re-read after inputs that it depends on directly were set); the values recorded at t."""
        if self.commands is not None:
            self.commands.feed(t)
        if self.discrete:
            self.discrete.move(self.refused)
        for i in self._all:
            self.read_component(i)
        values = [self.pull(gi) for gi in range(len(self.links))]
        new = self._new_point(t)
        for gi, value in enumerate(values):
            new[self.links[gi].sl] = value
            zero = np.zeros(len(value))
            self.feed_group(gi, value, zero, zero, True)
        for comp in self.comps:   # the row shows what was read right after the step, as libcosim's observers
            comp.fresh = True
        if values:
            np.maximum(self.scale, np.abs(new), out=self.scale)

    def rest(self, t0: float, h: float) -> None:
        """Give every value a past at rest (its value at t0 also at t0 - h and t0 - 2 h), and feed
        the inputs from it."""
        t = self._times[-1]
        u = self._past[self._rows[-1]].copy()
        self._rows, self._times = [0, 1, 2], [t - 2 * h, t - h, t]
        self._past[:] = u
        self.exchange(t0)

    # --- stepping -----------------------------------------------------------------------------
    def gauss_seidel_step(self, plan, t: float, h: float) -> bool:
        """The Gauss-Seidel step of ``plan`` (:class:`~.algorithms.GaussSeidel`) in compiled code, at the
        run's extrapolation order; False (nothing done) where the compiled exchange does not run."""
        kernel = self.kernel()
        if kernel is None or not self._rows:
            return False
        kernel.gauss_seidel_step(plan, t, h, self.extrapolation)
        return True

    def plain_step(self, t: float, h: float) -> bool:
        """libcosim's fixed-step Jacobi step (:class:`~.algorithms.PlainJacobi`: :meth:`step`, then
        :meth:`commit_as_read`) in compiled code; False (nothing done) where the compiled exchange does not run."""
        kernel = self.kernel()
        if kernel is None:
            return False
        kernel.plain_step(t, h)
        return True

    def jacobi_stretch(self, ts: np.ndarray):
        """Jacobi steps on the grid ``ts`` in one compiled call: (rows, steps done, failure or None), or
        None where the compiled exchange does not run."""
        kernel = self.kernel()
        if kernel is None or len(ts) < 2 or not self._commands_known_ahead():
            return None
        rows = np.empty((len(ts) - 1, 1 + len(self.columns) + sum(len(x) for x in self.row_extra)))
        try:
            done = kernel.jacobi_steps(ts, self.extrapolation, rows)
        except CraneFmuError as err:
            return rows, kernel.done, err
        return rows, done, None

    def _commands_known_ahead(self) -> bool:
        """Every command source's values over a stretch are known before it is stepped: none follows an
        event on the run's rows (a source with ``watchers()``, :mod:`cranefmu.experiments.events`, learns
        its event time from each row as the observers see it)."""
        if self.commands is None:
            return True
        return not any(getattr(source, "watchers", None) and source.watchers()
                       for *_, source in self.commands.bound)

    def evaluate(self, t: float, h: float, u: np.ndarray, degree: int, part: Part | None = None,
                 members: Iterable[int] | None = None, fed_through_only: bool = False) -> np.ndarray:
        """G(u) of a strongly coupled step: :meth:`feed` ``part`` (default all) along the polynomial through
        its last ``degree`` values and ``u``, :meth:`step` the components ``members`` (default all; the
        inputs' end values noted when all step), then :meth:`image` of ``part``; in compiled code where
        it can run (the same numbers)."""
        part = part or self.whole
        everyone = members is None
        members = self._all if everyone else members
        kernel = self.kernel()
        gu = kernel.evaluate(t, h, u, degree, part, members, fed_through_only, everyone) if kernel else None
        if gu is not None:
            return gu
        self.feed(t, h, u, degree, part)
        self.step(t, h, None if everyone else members, ends=everyone)
        return self.image(part, fed_through_only=fed_through_only)

    def _drop_kernel(self) -> None:
        """A component returned fmi2Fatal: no compiled exchange from now on (its plan holds the FMI C functions,
        which must not be called again; :meth:`.fmu.FmuComponent.stop_calls`)."""
        self._kernel = False

    def kernel(self):
        """The compiled exchange bound to this coupling (:class:`.kernel.plan.KernelPlan`), or None where
        the Python exchange runs (:attr:`python_reason` says why: not wanted, no compiler, discrete
        connections, wrapped FMI calls, ...)."""
        if self._kernel is None and self._phases is not None:
            self._kernel = False
            if not self.compiled:
                self.python_reason = "the compiled exchange was switched off for this run (compiled = False)"
            else:
                from .kernel import library
                from .kernel.plan import KernelPlan, python_reason

                lib = library()
                self.python_reason = python_reason(lib, self)
                self._kernel = (KernelPlan.make(lib, self) if not self.python_reason else None) or False
            self.stats.python_exchange = self.python_reason
        return self._kernel or None

    def jacobi_step(self, t: float, h: float) -> None:
        """Every FMU steps from t to t + h, then every value moves at t + h (:meth:`step`, :meth:`commit`),
        in compiled code where it can run (the same numbers)."""
        kernel = self.kernel()
        if kernel is None:
            self.step(t, h)
            self.exchange(t + h)
        else:
            kernel.jacobi_step(t, h, self.extrapolation)

    def step(self, t: float, h: float, members: Iterable[int] | None = None, ends: bool = True) -> None:
        """The FMUs ``members`` (default all, in component order) step from t to t + h [s]; ``ends``:
        the inputs' values at t + h as fed are noted (for the power bonds; pass False while a step is
        still being fed, then call :meth:`note_ends`)."""
        for i in self._all if members is None else members:
            self.do_step(i, t, h)
        if ends:
            self.note_ends(h)

    def do_step(self, i: int, t: float, h: float) -> None:
        comp = self.comps[i]
        t0 = clock.perf_counter()
        try:   # comp.step, inlined
            comp.fresh = False
            status = comp._do_step(comp._c, t, h, 1)
            if status > 1:
                comp._failed("fmi2DoStep", status)
            if self.commands is not None:   # outputs read before the next exchange see the command at t + h
                self.commands.after_step(comp, t + h)
        except Exception:
            raise SimulationError(f"component {comp.name} failed in the step from t = {t:.9g} s (H = {h:.3g} s): "
                                  f"{comp.last_error()}. Try a smaller --step, --adaptive, or --algorithm "
                                  "iterative.") from None
        finally:
            self.stats.fmu_time[comp.name] += clock.perf_counter() - t0
            self.stats.fmu_calls[comp.name] += 1

    def note_ends(self, h: float, values: np.ndarray | None = None, part: Part | None = None) -> None:
        """The inputs' values at the end of the step of h, as fed; with ``values``: those of ``part`` are these."""
        if values is not None:
            self.input_end[part.at] = values
            return
        if not self.ends_wanted:   # nobody reads them (no power bond takes a connected input)
            return
        moved = self.fed + h * (self.fed_rate + 0.5 * h * self.fed_curvature)
        np.copyto(self.input_end, np.where(self.held, self.fed, moved))

    # --- state --------------------------------------------------------------------------------
    def snapshot(self, members: list[int] | None = None) -> list:
        """Save the state of the FMUs ``members`` (default all: also the values' past) and what their
        inputs were fed, for a retry of the step."""
        index = list(range(len(self.comps)) if members is None else members)
        states = []
        try:
            for i in index:
                states.append(self.comps[i].fmu.getFMUstate())
        except Exception:
            self._free(index, states)
            raise self.refused(self.comps[index[len(states)]], "saving its state (getFMUstate)") from None
        inside = set(index)
        at = np.concatenate([np.arange(g.sl.start, g.sl.stop) for g in self.links if g.dst in inside] or
                            [np.zeros(0, dtype=np.intp)]).astype(np.intp)
        fed = (at, self.fed[at], self.fed_rate[at], self.fed_curvature[at], self.held[at])
        past = (self._past.copy(), list(self._rows), list(self._times)) if members is None else None
        return [states, past, fed, index]

    def restore(self, snap: list) -> None:
        """Back to the snapshot (it stays valid for another restore until released)."""
        states, past, fed, index = snap
        for i, s in zip(index, states):
            c = self.comps[i]
            c.fresh = False
            try:
                c.fmu.setFMUstate(s)
            except Exception:
                raise self.refused(c, "restoring its state (setFMUstate)") from None
        if past is not None:
            self._past[:] = past[0]
            self._rows, self._times = list(past[1]), list(past[2])
        at, u, d1, d2, held = fed
        self.fed[at], self.fed_rate[at], self.fed_curvature[at], self.held[at] = u, d1, d2, held

    def release(self, snap: list | None) -> None:
        """Free the snapshot's FMU states."""
        if snap is not None:
            self._free(snap[3], snap[0])

    def _free(self, index, states: list) -> None:
        for i, s in zip(index, states):
            try:
                self.comps[i].fmu.freeFMUstate(s)
            except Exception:
                pass

    def free(self) -> None:
        for comp in self.comps:
            comp.free()

    @staticmethod
    def refused(comp: FmuComponent, what: str) -> CraneFmuError:
        msg = comp.last_error()
        cls = ParameterSetError if "ParameterError" in msg else SimulationError
        return cls(f"component {comp.name} failed {what}: {msg}")


def input_derivatives(fmu, g: InputGroup, d1: np.ndarray, d2: np.ndarray) -> None:
    """FMI 2.0 sec. 4.2.1: derivatives of the inputs for the coming step."""
    n = len(g.dst_vrs)
    fmu.setRealInputDerivatives(g.dst_vrs, [1] * n, d1.tolist())
    fmu.setRealInputDerivatives(g.dst_vrs, [2] * n, d2.tolist())
