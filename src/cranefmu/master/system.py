"""The FMUs of one scene and the values between them: batched exchange, extrapolation, snapshots.

An algorithm (:mod:`.algorithms`) decides when FMUs step and when values move, through the
vector operations of :class:`~.coupled.Coupling`; this class only moves them.  Every connection
group (one source -> one destination component) is read with one ``getReal`` and written with one
``setReal``; inputs that offer ``<input>_dt``/``<input>_dt2`` get the slope and curvature of the
polynomial through the last values (extrapolation order 0-2).
"""
from __future__ import annotations

import ctypes
import time as clock
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .coupling import InputGroup, check_connection, feedthrough, lagrange_weights, ordered_links, rates, visit_order
from ..errors import CraneFmuError, ParameterSetError, SceneError, SimulationError
from .fmu import FmuComponent
from .scene import Scene


@dataclass
class RunStats:
    """What a run cost: steps, rejections, coupling iterations, calls and seconds per FMU."""

    steps: int = 0
    wall_time: float = 0.0
    init_iterations: int = 0
    fmu_time: dict[str, float] = field(default_factory=dict)   # seconds inside each FMU's doStep
    fmu_calls: dict[str, int] = field(default_factory=dict)    # doStep calls per FMU
    rejections: int = 0              # adaptive steps rolled back (error or discrete event)
    iterations: int = 0              # coupling iterations of the iterative algorithm (all steps)
    max_iterations: int = 0          # most iterations one macro step needed
    min_step: float = 0.0            # smallest and largest accepted macro step [s]
    max_step: float = 0.0
    master_time: float = 0.0         # wall time outside the FMUs' doStep [s]
    bond_energy: dict[str, float] = field(default_factory=dict)  # ECCO residual total per power bond [J]
    bond_carried: dict[str, float] = field(default_factory=dict)  # energy through each bond [J] (sum max|P| h)
    stopped: str = ""                # why a stop condition ended the run early ('' = ran to the end)

    def real_time_factor(self, simulated: float) -> float:
        return simulated / self.wall_time if self.wall_time > 0 else float("inf")


class _Phase:
    """Consecutive connection groups (in exchange order) whose reads no input set among them changes."""

    def __init__(self, groups: list[InputGroup], read_at: list[int], read_view: np.ndarray):
        self.read_view = read_view
        self.sources = list(dict.fromkeys(g.src for g in groups))
        self.sl = slice(groups[0].sl.start, groups[-1].sl.stop)
        self.members, gather, factor, offset, set_values = [], [], [], [], []
        rate_sel, set_d1, set_d2 = [], [], []
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
        index = lambda xs: np.array(xs, dtype=np.intp)
        self.gather, self.set_values = index(gather), index(set_values)
        self.rate_sel, self.set_d1, self.set_d2 = index(rate_sel), index(set_d1), index(set_d2)
        self.factor, self.offset = np.array(factor), np.array(offset)
        self.plain = all(g.plain for g in groups)
        self.zero = np.zeros(self.sl.stop - self.sl.start)
        self.all_rates = len(rate_sel) == len(self.zero)
        self.d2_zero = False   # the set array holds zero curvatures for every group of the phase
        # what the last exchange fed the phase's groups: (values, d1 or None, d2) of the whole phase, and
        # each group's ``fed`` tuple then (a group fed since by push() no longer holds its tuple)
        self.fed: tuple | None = None
        self.feds: list[tuple] = []
        self.wants_end = True   # some input of the phase has its end value kept (need_input_ends)


def _shares_past(members: list, arrays: list) -> bool:
    """Every group's last len(arrays) history values are slices of ``arrays`` (the phase's past
    gathers, oldest first; the newest was just appended to every group by the caller): the phase may
    extrapolate all its groups in one product."""
    k = len(arrays)
    for arr in arrays:
        if arr is None:
            return False
    if k == 2:   # extrapolation 1: only the one past value to check
        past = arrays[0]
        for g, _, _ in members:
            hist = g.history
            if len(hist) < 2 or hist[-2][1].base is not past:
                return False
        return True
    for g, _, _ in members:
        hist = g.history
        if len(hist) < k:
            return False
        for q, arr in zip(hist[-k:], arrays):
            if q[1].base is not arr:
                return False
    return True


class CoSystem:
    """Instantiated FMUs, their connections in exchange order, and the coupling values' history."""

    def __init__(self, scene: Scene, workdir: Path, extrapolation: int):
        self.scene = scene
        self.order_of_extrapolation = extrapolation
        self.comps = [FmuComponent(c.name, c.fmu, workdir / f"fmu_{c.name}") for c in scene.components]
        self.by_name = {c.name: c for c in self.comps}
        self.connections = [check_connection(c, self.by_name) for c in scene.connections]
        # every group in exchange order, and its slice in the vector of all coupling values
        self.groups, self.links = ordered_links(self.comps, self.connections)
        try:
            self.order = visit_order(self.comps, self.connections)
        except SceneError:  # components feed each other, but no variable does: any order steps
            first = list(dict.fromkeys(g.dst for g in self.links))
            self.order = first + [i for i in range(len(self.comps)) if i not in first]
        self.slices: list[slice] = []
        n = 0
        for g in self.links:
            self.slices.append(slice(n, n + len(g.dst_vrs)))
            n += len(g.dst_vrs)
        self.n_coupling = n
        self.scale = np.full(n, 0.0)        # running max |value| per coupling variable
        self.input_end = np.zeros(n)        # each input's value at the end of the last step, as fed
        self._new = np.zeros(n)             # exchange: the values now
        self._d1 = np.zeros(n)              # exchange: their slopes, where a phase extrapolated them
        self.variable_names = self._variable_names(scene)
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
        self._prepare_hot_path()

    def _prepare_hot_path(self) -> None:
        """Arrays for the per-step calls, built once: each component's values are read with one
        fmi2GetReal into a buffer shared by the recorder, the exchange and the power bonds; each
        connection group is written with one fmi2SetReal of its values and their rates."""
        self.n_real = sum(len(v) for v in self.out_vrs)
        self._row = np.zeros(self.n_real + len(self.flag_names))
        self._out_slices = []
        a = 0
        for comp, vrs in zip(self.comps, self.out_vrs):
            comp.read_vrs = list(vrs)   # the recorded outputs first, so that read()[:n] is the row part
            self._out_slices.append((a, a + len(vrs)))
            a += len(vrs)
        reads = [{v.name for v in c.md.modelVariables if v.causality == "output" and v.type == "Real"}
                 for c in self.comps]
        ft = [feedthrough(c) for c in self.comps]
        for g, sl in zip(self.links, self.slices):
            g.sl = sl
            g.src_pos = self.comps[g.src].position(g.src_vrs)
            # x * 1.0 + 0.0 only turns -0.0 into 0.0
            g.plain = bool(np.all(g.factor == 1.0) and np.all(g.offset == 0.0))
            n = len(g.dst_vrs)
            vrs = g.dst_vrs + (g.dt_vrs + g.dt2_vrs if g.dt_vrs is not None else [])
            g.set_vrs = (ctypes.c_uint * len(vrs))(*vrs)
            g.zero = np.zeros(n)
        # the values of every group's fmi2SetReal are parts of one array, filled per phase (see exchange)
        sizes = [len(g.set_vrs) for g in self.links]
        self._set_all = (ctypes.c_double * max(1, sum(sizes)))()
        self._set_view = np.ctypeslib.as_array(self._set_all)
        off = 0
        for g, m in zip(self.links, sizes):
            g.set_values = (ctypes.c_double * m).from_buffer(self._set_all, off * ctypes.sizeof(ctypes.c_double))
            g.set_view = self._set_view[off:off + m]
            g.set_at = off
            off += m
            # the destination's outputs stay valid after this group's inputs are set, if none depends on them
            inputs = set(g.dst_names)
            g.keeps_outputs = not any(ft[g.dst].get(o, set(inputs)) & inputs for o in reads[g.dst])
        self._end_groups = list(self.links)   # groups whose inputs' end values are kept (need_input_ends)
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
        self._curvature_written = True
        self._phases = None   # built at the first exchange in step mode (every read position is known then)
        self._w_times, self._w_t, self._w = None, None, None   # the last extrapolation weights and their times

    def _variable_names(self, scene: Scene) -> list[str]:
        """'src.out -> dst.in' for each coupling variable, in the order of the coupling vector."""
        by_dst = {(c.dst, c.dst_var): c for c in scene.connections}
        names = []
        for g in self.links:
            dst = self.comps[g.dst]
            vr_name = {v.valueReference: v.name for v in dst.md.modelVariables if v.causality == "input"}
            names += [str(by_dst[(dst.name, vr_name[vr])]) for vr in g.dst_vrs]
        return names

    # --- values -----------------------------------------------------------------------------
    def read(self, i: int) -> np.ndarray:
        """Component i's read vector (its Real outputs first): one fmi2GetReal per change of the FMU."""
        comp = self.comps[i]
        try:
            return comp.read()
        except Exception:
            raise self.refused(comp, "reading its outputs") from None

    def pull(self, g: InputGroup) -> np.ndarray:
        return self.read(g.src)[g.src_pos] * g.factor + g.offset

    def push(self, g: InputGroup, value: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> None:
        """Feed ``value`` (at the step start) and its first and second time derivative."""
        count = -1                      # a group not prepared by a CoSystem: fmpy's calls
        if g.set_view is not None:
            view = g.set_view
            n = len(value)
            view[:n] = value
            count = n
            if g.dt_vrs is not None:
                moving = not (d1 is g.zero and d2 is g.zero) and bool(d1.any() or d2.any())
                if moving or g.rates_set:  # zero rates stay zero: values only for a zero-order hold
                    view[n:2 * n] = d1
                    view[2 * n:] = d2
                    count = 3 * n
                    g.rates_set = moving
                    self._curvature_written = True
        self._send(g, count, value, d1, d2)

    def _send(self, g: InputGroup, count: int, value: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> None:
        """Write the first ``count`` entries of the group's set array (-1: set value and rates with
        fmpy's calls), the FMI input derivatives where the FMU takes them, and note what was fed."""
        comp = self.comps[g.dst]
        try:
            if count < 0:
                CoSystem._push_lists(comp.fmu, g, value, d1, d2)
            else:
                comp.write(g.set_vrs, count, g.set_values)
                if g.fmi_derivatives:
                    CoSystem._input_derivatives(comp.fmu, g, d1, d2)
        except Exception:
            raise self.refused(comp, "setting its inputs") from None
        if not g.keeps_fresh:
            comp.fresh = False
        g.fed = (value, d1, d2)

    @staticmethod
    def _push_lists(fmu, g: InputGroup, value: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> None:
        fmu.setReal(g.dst_vrs, value.tolist())
        if g.dt_vrs is not None:
            moving = bool(d1.any() or d2.any())
            if moving or g.rates_set:
                fmu.setReal(g.dt_vrs + g.dt2_vrs, d1.tolist() + d2.tolist())
                g.rates_set = moving
        elif g.fmi_derivatives:
            CoSystem._input_derivatives(fmu, g, d1, d2)

    @staticmethod
    def _input_derivatives(fmu, g: InputGroup, d1: np.ndarray, d2: np.ndarray) -> None:
        """FMI 2.0 sec. 4.2.1: derivatives of the inputs for the coming step."""
        n = len(g.dst_vrs)
        fmu.setRealInputDerivatives(g.dst_vrs, [1] * n, d1.tolist())
        fmu.setRealInputDerivatives(g.dst_vrs, [2] * n, d2.tolist())

    @staticmethod
    def refused(comp: FmuComponent, what: str) -> CraneFmuError:
        msg = comp.last_error()
        cls = ParameterSetError if "ParameterError" in msg else SimulationError
        return cls(f"component {comp.name} failed {what}: {msg}")

    def record_history(self, g: InputGroup, t: float, value: np.ndarray) -> None:
        if g.history and g.history[-1][0] == t:
            g.history[-1] = (t, value)
        else:
            g.history.append((t, value))
            if len(g.history) > 3:
                del g.history[0]

    def exchange(self, t: float, order: int | None = None) -> None:
        """Move values along every connection at time t, in feedthrough order, feeding the rates of
        the extrapolation polynomial (of ``order``, default the run's).

        In step mode the groups go in phases (:meth:`_plan_phases`): every source of a phase is read,
        the phase's values taken from all of them in one gather, their rates computed in one product,
        written to the phase's part of the set array, then each group's fmi2SetReal.  A phase ends
        where a group would read a component that an input set of the phase makes stale, so the
        values are those a group-by-group exchange in feedthrough order reads."""
        p = self.order_of_extrapolation if order is None else order
        if self.commands is not None:
            self.commands.feed(t)
        if not self._stepping:
            self._exchange_groups(t, p)
        else:
            if self._phases is None:
                self._phases = self._plan_phases()
            if self._curvature_written:  # push() wrote rates: no phase may assume its zero curvatures
                for phase in self._phases:
                    phase.d2_zero = False
                self._curvature_written = False
            for phase in self._phases:
                self._exchange_phase(phase, t, p)
        np.maximum(self.scale, np.abs(self._new), out=self.scale)

    def exchange_as_read(self, t: float) -> None:
        """libcosim's exchange at t: every output read once, now, and held by its input over the next
        step (no re-read after inputs that it depends on directly were set)."""
        if self.commands is not None:
            self.commands.feed(t)
        for i in range(len(self.comps)):
            self.read(i)
        values = [self.pull(g) for g in self.links]
        for g, value in zip(self.links, values):
            self.record_history(g, t, value)
            self.push(g, value, g.zero, g.zero)
        for comp in self.comps:   # the row shows what was read right after the step, as libcosim's observers
            comp.fresh = True
        if values:
            np.maximum(self.scale, np.abs(np.concatenate(values)), out=self.scale)

    def rest(self, t0: float, h: float) -> None:
        """Give every connection a past at rest (its value at t0 also at t0 - h and t0 - 2 h), then exchange."""
        for g in self.links:
            t, u = g.history[-1]
            g.history[:] = [(t - 2 * h, u), (t - h, u), (t, u)]
        self.exchange(t0)

    def _plan_phases(self) -> list[_Phase]:
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
        self._row_gather = np.array([at[i] + j for i, (a, b) in enumerate(self._out_slices) for j in range(b - a)],
                                    dtype=np.intp)
        phases, current, stale = [], [], set()
        for g in self.links:
            if g.src in stale:
                phases.append(current)
                current, stale = [], set()
            current.append(g)
            if not g.keeps_outputs:
                stale.add(g.dst)
        phases.append(current)
        out = [_Phase(gs, at, read_view) for gs in phases if gs]
        for ph in out:
            ph.source_comps = [self.comps[i] for i in ph.sources]
            ph.runs = self._runs(ph)
        self._phases = out
        self._mark_end_phases()
        return out

    def _runs(self, ph: _Phase) -> list[tuple]:
        """The phase's groups in runs of consecutive groups into one destination, each run written
        with one fmi2SetReal of values and rates where it can be (every group takes our rate inputs
        and none the FMI derivatives: their parts of the set array are adjacent, in the order of
        ``links``), else group by group: (component, sends, merged vrs or None, values, count)."""
        runs: list[tuple] = []
        for g, a, b in ph.members:
            send = (g, a, b, self.comps[g.dst], b - a, g.dt_vrs is not None)
            if runs and runs[-1][0] is send[3]:
                runs[-1][1].append(send)
            else:
                runs.append((send[3], [send]))
        out = []
        for comp, sends in runs:
            if len(sends) < 2 or not all(s[5] and not s[0].fmi_derivatives for s in sends):
                out.append((comp, sends, None, None, 0))
                continue
            vrs = [vr for s in sends for vr in s[0].set_vrs]
            start = sends[0][0].set_at
            count = len(vrs)
            ends = [s[0].set_at + len(s[0].set_vrs) for s in sends]
            if [s[0].set_at for s in sends[1:]] != ends[:-1]:   # not adjacent: group by group
                out.append((comp, sends, None, None, 0))
                continue
            values = (ctypes.c_double * count).from_buffer(self._set_all, start * ctypes.sizeof(ctypes.c_double))
            out.append((comp, sends, (ctypes.c_uint * count)(*vrs), values, count))
        return out

    def _exchange_phase(self, ph: _Phase, t: float, p: int) -> None:
        for comp in ph.source_comps:
            if not comp.fresh:
                try:
                    comp.read()
                except Exception:
                    raise self.refused(comp, "reading its outputs") from None
        values = ph.read_view[ph.gather]
        if not ph.plain:
            values = values * ph.factor + ph.offset
        self._new[ph.sl] = values
        first = None
        for g, a, b in ph.members:
            hist = g.history
            if hist and hist[-1][0] == t:
                hist[-1] = (t, values[a:b])
            else:
                hist.append((t, values[a:b]))
                if len(hist) > 3:
                    del hist[0]
            if first is None:
                first = hist
        d1 = d2 = None
        if p > 0 and len(first) >= 2:
            points = first[-(p + 1):]
            arrays = [q[1].base for q in points]
            # the phase's past values are arrays of this method, unless a history was rewritten (rollback,
            # start-up): then group by group
            if _shares_past(ph.members, arrays):
                times = [q[0] for q in points]
                if times != self._w_times or t != self._w_t:   # the phases of one step share the weights
                    self._w_times, self._w_t = times, t
                    self._w = lagrange_weights(times, t)
                w1, w2 = self._w
                stack = np.array(arrays)
                d1 = w1 @ stack
                d2 = w2 @ stack if p > 1 else ph.zero  # a line has no curvature
            else:
                ph.fed = None
                for g, a, b in ph.members:
                    self.push(g, values[a:b], *rates(g.history[-(p + 1):], t))
                return
        sv = self._set_view
        sv[ph.set_values] = values
        if d1 is not None and len(ph.rate_sel):
            sv[ph.set_d1] = d1 if ph.all_rates else d1[ph.rate_sel]
            if d2 is not ph.zero or not ph.d2_zero:   # a line's zero curvature is written once
                sv[ph.set_d2] = d2 if ph.all_rates else d2[ph.rate_sel]
                ph.d2_zero = d2 is ph.zero
        for comp, sends, vrs, set_values, count in ph.runs:
            if vrs is not None and d1 is not None:   # the run's groups in one fmi2SetReal
                for g, a, b, _, _, _ in sends:
                    g.rates_set = True
                    g.fed = (values[a:b], d1[a:b], d2[a:b])
                self._write(comp, vrs, count, set_values)
                for g, _, _, _, _, _ in sends:
                    if not g.keeps_fresh:
                        comp.fresh = False
                continue
            for g, a, b, comp, n, has_rates in sends:
                count = n
                if has_rates:
                    if d1 is not None:
                        count, g.rates_set = 3 * n, True
                    elif g.rates_set:  # zero rates: sent once, then values only
                        g.set_view[n:] = 0.0
                        count, g.rates_set = 3 * n, False
                if d1 is None:
                    fed = (values[a:b], g.zero, g.zero)
                else:
                    fed = (values[a:b], d1[a:b], d2[a:b])
                self._write(comp, g.set_vrs, count, g.set_values)
                if g.fmi_derivatives:
                    try:
                        CoSystem._input_derivatives(comp.fmu, g, fed[1], fed[2])
                    except Exception:
                        raise self.refused(comp, "setting its inputs") from None
                if not g.keeps_fresh:
                    comp.fresh = False
                g.fed = fed
        ph.feds = [g.fed for g, _, _ in ph.members]
        if d1 is not None:
            self._d1[ph.sl] = d1
        ph.fed = (values, d1, d2)

    def _write(self, comp: FmuComponent, vrs, count: int, set_values) -> None:
        """comp.write, inlined: the hot path's fmi2SetReal."""
        try:
            status = comp._set_real(comp._c, vrs, count, set_values)
            if status > 1:
                comp._failed("fmi2SetReal", status)
        except Exception:
            raise self.refused(comp, "setting its inputs") from None

    def _exchange_groups(self, t: float, p: int) -> None:
        """Group by group (initialization mode, where any input set may change any output)."""
        new = self._new
        for g in self.links:
            value = self.pull(g)
            self.record_history(g, t, value)
            new[g.sl] = value
            hist = g.history
            if p == 0 or len(hist) < 2:
                d1 = d2 = g.zero
            else:
                d1, d2 = rates(hist[-(p + 1):], t)
            self.push(g, value, d1, d2)

    def capture_input_ends(self, h: float) -> None:
        """Remember each input's fed value at the end of a step of ``h`` (before the next exchange).
        A phase whose groups still hold what its exchange fed them is done in one expression (the same
        operations element by element as group by group, so the same numbers)."""
        if self._phases is None:
            self._capture_groups(self._end_groups, h)
            return
        ends = self.input_end
        valid = [self._fed_intact(ph) for ph in self._phases]
        lines = bool(valid)
        for ph, f in zip(self._phases, valid):
            if f is None or f[1] is None or f[2] is not ph.zero:
                lines = False
                break
        if lines:   # every phase fed a line (extrapolation 1): all at once, from the exchange's vectors
            np.add(self._new, h * (self._d1 + 0.0), out=ends)
            return
        for ph, fed in zip(self._phases, valid):
            if not ph.wants_end:
                continue
            if fed is None:
                self._capture_groups([g for g, _, _ in ph.members], h)
                continue
            u, d1, d2 = fed
            if d1 is None:
                ends[ph.sl] = u
            elif d2 is ph.zero:   # 0.5 h 0.0 is +0.0 (h > 0): the same sum, one product fewer
                ends[ph.sl] = u + h * (d1 + 0.0)
            else:
                ends[ph.sl] = u + h * (d1 + 0.5 * h * d2)

    @staticmethod
    def _fed_intact(ph: _Phase) -> tuple | None:
        """What the phase's last exchange fed, if every group of it still holds that (else None)."""
        fed = ph.fed
        if fed is not None:
            for (g, _, _), f in zip(ph.members, ph.feds):
                if g.fed is not f:
                    return None
        return fed

    def _capture_groups(self, groups: list[InputGroup], h: float) -> None:
        for g in groups:
            u, d1, d2 = g.fed
            self.input_end[g.sl] = u if d1 is g.zero and d2 is g.zero else u + h * (d1 + 0.5 * h * d2)

    def need_input_ends(self, indices: list[int]) -> None:
        """Only these coupling variables' end values are read from :attr:`input_end` (default: all)."""
        wanted = set(indices)
        self._end_groups = [g for g in self.links if wanted.intersection(range(g.sl.start, g.sl.stop))]
        self._mark_end_phases()

    def _mark_end_phases(self) -> None:
        ends = {id(g) for g in self._end_groups}
        for ph in self._phases or ():
            ph.wants_end = any(id(g) in ends for g, _, _ in ph.members)

    def coupling_values(self) -> np.ndarray:
        """The newest value of every coupling variable (the vector the iterative algorithm solves for)."""
        return np.concatenate([g.history[-1][1] for g in self.links]) if self.links else np.zeros(0)

    def predicted(self, t: float, h: float, order: int | None = None) -> np.ndarray:
        """Every coupling variable extrapolated from its history to t + h (polynomial of ``order``)."""
        p = self.order_of_extrapolation if order is None else order
        out = np.empty(self.n_coupling)
        for g, sl in zip(self.links, self.slices):
            d1, d2 = rates(g.history[-(p + 1):], t)
            out[sl] = g.history[-1][1] + h * (d1 + 0.5 * h * d2)
        return out

    def outputs(self) -> np.ndarray:
        """Every Real output, then the discrete outputs of the last :meth:`flags` call (a new array)."""
        return self.fill_outputs(self._row).copy()

    def fill_outputs(self, row: np.ndarray) -> np.ndarray:
        """:meth:`outputs` written into ``row`` (its first len(columns) entries); returns ``row``.
        In step mode one gather from the buffer every component reads into."""
        if self._phases is None:
            for i, (a, b) in enumerate(self._out_slices):
                row[a:b] = self.read(i)[:b - a]
        else:
            for i, comp in enumerate(self.comps):
                if not comp.fresh:
                    self.read(i)
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

    # --- stepping -----------------------------------------------------------------------------
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

    # --- rollback -------------------------------------------------------------------------------
    def save(self, members: list[int] | None = None) -> list:
        """Snapshot the state of the FMUs ``members`` (default all: also the coupling values' past)
        and what their inputs were fed, for a retry of the step."""
        index = range(len(self.comps)) if members is None else members
        states = []
        try:
            for i in index:
                states.append(self.comps[i].fmu.getFMUstate())
        except Exception:
            self._free(index, states)
            raise self.refused(self.comps[index[len(states)]], "saving its state (getFMUstate)") from None
        inside = set(index)
        fed_into = [g for g in self.links if g.dst in inside]
        histories = [list(g.history) for g in self.links] if members is None else None
        return [states, histories, [(g, g.fed) for g in fed_into], list(index)]

    def restore(self, snap: list) -> None:
        """Back to the snapshot (it stays valid for another restore until released)."""
        states, histories, fed, index = snap
        for i, s in zip(index, states):
            c = self.comps[i]
            c.fresh = False
            try:
                c.fmu.setFMUstate(s)
            except Exception:
                raise self.refused(c, "restoring its state (setFMUstate)") from None
        if histories is not None:
            for g, hist in zip(self.links, histories):
                g.history[:] = hist
        for g, f in fed:
            g.fed = f
            g.rates_set = True  # the restored FMU holds the rates of the snapshot

    def release(self, snap: list | None) -> None:
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
