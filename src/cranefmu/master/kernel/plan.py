"""A :class:`~..coupled.Coupling`'s arrays and FMI function pointers handed to the compiled kernel
(``cf_plan`` of exchange.c): built once per run after the exchange is planned, synchronised with the
Python-side state (ring order, fresh reads, statistics) around each kernel call."""
from __future__ import annotations

import ctypes

import numpy as np

from ...errors import SimulationError

_P = ctypes.c_void_p
_I32P = ctypes.POINTER(ctypes.c_int32)


class CPlan(ctypes.Structure):
    _fields_ = [
        ("n_comps", ctypes.c_int), ("inst", _P), ("do_step", _P), ("get_real", _P), ("set_real", _P),
        ("read_vrs", _P), ("read_n", _P), ("read_at", _P), ("fresh", _P), ("fmu_time", _P), ("fmu_calls", _P),
        ("read_buf", _P),
        ("n", ctypes.c_int32), ("past", _P), ("ring", _P), ("times", _P), ("fed", _P), ("fed_rate", _P),
        ("fed_curv", _P), ("input_end", _P), ("scale", _P), ("held", _P),
        ("n_phases", ctypes.c_int32), ("ph_start", _P), ("ph_n", _P), ("ph_plain", _P),
        ("ph_src_off", _P), ("ph_src_n", _P), ("src", _P), ("gather", _P), ("factor", _P), ("offset", _P),
        ("set_values", _P), ("ph_rate_off", _P), ("ph_rate_n", _P), ("rate_sel", _P), ("set_d1", _P),
        ("set_d2", _P), ("set_buf", _P), ("ph_write_off", _P), ("ph_write_n", _P), ("w_comp", _P),
        ("w_count", _P), ("w_start", _P), ("w_stales", _P), ("w_vrs", _P), ("scratch", _P),
        ("n_real", ctypes.c_int32), ("row_gather", _P), ("n_flag_reads", ctypes.c_int32), ("f_comp", _P),
        ("f_n", _P), ("f_bool", _P), ("f_get", _P), ("f_vrs", _P), ("f_buf", _P), ("n_flags", ctypes.c_int32),
        ("n_extra_read", ctypes.c_int32), ("n_extra_end", ctypes.c_int32), ("extra_read", _P), ("extra_end", _P),
        ("n_groups", ctypes.c_int32), ("g_start", _P), ("g_n", _P), ("g_src", _P), ("g_dst", _P), ("g_set_at", _P),
        ("g_rates", _P), ("g_keeps_fresh", _P), ("g_gather", _P), ("g_vrs", _P),
        ("n_stages", ctypes.c_int32), ("s_comp", _P), ("s_fed_off", _P), ("s_fed_n", _P), ("s_held_off", _P),
        ("s_held_n", _P), ("s_groups", _P), ("ends_wanted", ctypes.c_int32),
        ("err_comp", ctypes.c_int32), ("err_status", ctypes.c_int32), ("err_what", ctypes.c_int32),
        ("n_cmd", ctypes.c_int32), ("cmd_width", ctypes.c_int32), ("cmd_comp", _P), ("cmd_count", _P),
        ("cmd_off", _P), ("cmd_vrs", _P), ("cmd_of", _P), ("cmd_values", _P),
        ("set_deriv", _P), ("g_deriv", _P), ("w_deriv_off", _P), ("w_deriv_n", _P), ("w_groups", _P),
        ("ones", _P), ("twos", _P), ("g_keeps_outputs", _P),
        ("n_transfers", ctypes.c_int32), ("t_src", _P), ("t_dst", _P), ("t_bool", _P), ("t_n", _P),
        ("t_src_vrs", _P), ("t_dst_vrs", _P), ("t_values", _P), ("d_get", _P), ("d_set", _P)]


def _address(f) -> int | None:
    """The C address of an fmpy FMI function (None for a Python wrapper, e.g. wrap_fmi_calls')."""
    if not isinstance(f, ctypes._CFuncPtr):
        return None
    return ctypes.cast(f, ctypes.c_void_p).value


def _derivative_functions(coupling) -> list:
    """Per component: its fmi2SetRealInputDerivatives where some group into it is fed its slopes that
    way (coupling.InputGroup.fmi_derivatives), else None."""
    wanted = {g.dst for g in coupling.links if g.fmi_derivatives}
    return [comp.fmu._functions.get("fmi2SetRealInputDerivatives") if i in wanted else None
            for i, comp in enumerate(coupling.comps)]


def _discrete_functions(t) -> tuple:
    """(the source's getter, the destination's setter) of a discrete_links transfer."""
    if t.boolean:
        return t.src._get_boolean, t.dst._set_boolean
    return t.src._get_integer, t.dst._set_integer


def python_reason(lib, coupling) -> str:
    """Why the Python exchange must run for this coupling ('' where the kernel can): no kernel library,
    the exchange not planned yet, wrapped FMI calls (no C function to call), or a product size whose
    bits the kernel does not reproduce here.  Commanded inputs, FMI input derivatives and Integer/Boolean/
    Enumeration connections run in the kernel."""
    from . import agrees_with_numpy, why_not

    if lib is None:
        return why_not or "no compiled exchange"
    if coupling._phases is None:
        return "the exchange is not planned yet (initialization)"
    if not _reads_fit(coupling):
        return "a component's outputs were added after the exchange was planned"
    functions = [f for comp in coupling.comps
                 for f in (comp._do_step, comp._get_real, comp._set_real, comp._get_integer, comp._get_boolean)]
    functions += [f for t in coupling.discrete.transfers for f in _discrete_functions(t)]
    functions += [f for f in _derivative_functions(coupling) if f is not None]
    if any(_address(f) is None for f in functions):
        return "wrapped FMI calls"
    sizes = {ph.n for ph in coupling._phases} | {g.sl.stop - g.sl.start for g in coupling.links}
    if not agrees_with_numpy(lib, sorted(sizes)):
        return "the kernel's product differs from numpy's here"
    return ""


def _reads_fit(coupling) -> bool:
    """Whether every component reads into its own slot of the coupling's one read buffer, as planned: the kernel
    writes ``read_n`` values at ``read_buf + read_at`` with fmi2GetReal, so a component whose outputs grew after
    the plan (``FmuComponent.position`` of a new output) would write past its slot, into the next one's or
    beyond the buffer (memory Python hands to its objects)."""
    import ctypes

    ends = list(coupling._read_at[1:]) + [len(coupling._read_all)]
    base = ctypes.addressof(coupling._read_all)
    for comp, at, end in zip(coupling.comps, coupling._read_at, ends):
        read = comp._read
        if read is None or read[1] != end - at or ctypes.addressof(read[2]) != base + at * ctypes.sizeof(ctypes.c_double):
            return False
    return True


class KernelPlan:
    """The compiled kernel bound to one coupling; :meth:`make` returns None where it cannot run it."""

    def __init__(self, lib, coupling):
        self.lib, self.c = lib, coupling
        self._keep: list = []   # every array the C struct points into
        self._parts: dict = {}  # (part, members) -> (part, its group indices, the members) for cf_evaluate

    @classmethod
    def make(cls, lib, coupling) -> KernelPlan | None:
        """None where the Python exchange must run (:func:`python_reason` says why)."""
        if python_reason(lib, coupling):
            return None
        plan = cls(lib, coupling)
        plan._build()
        return plan

    def _array(self, values, dtype) -> int:
        a = np.ascontiguousarray(np.array(values, dtype=dtype))
        self._keep.append(a)
        return a.ctypes.data

    def _pointers(self, objs) -> int:
        arr = (ctypes.c_void_p * max(1, len(objs)))(*objs)
        self._keep.append(arr)
        return ctypes.addressof(arr)

    def _build(self) -> None:
        c = self.c
        comps = c.comps
        p = self.p = CPlan()
        i32, i64, f64 = np.int32, np.int64, np.float64
        p.n_comps = len(comps)
        p.inst = self._pointers([comp._c for comp in comps])
        p.do_step = self._pointers([_address(comp._do_step) for comp in comps])
        p.get_real = self._pointers([_address(comp._get_real) for comp in comps])
        p.set_real = self._pointers([_address(comp._set_real) for comp in comps])
        for comp in comps:
            comp.read()   # the read tuple exists (the buffer of the exchange plan)
        p.read_vrs = self._pointers([ctypes.addressof(comp._read[0]) for comp in comps])
        self._keep.extend(comp._read for comp in comps)   # the arrays those addresses are in, as long as the plan
        p.read_n = self._array([comp._read[1] for comp in comps], i32)
        p.read_at = self._array(c._read_at, i32)
        self.fresh = np.zeros(len(comps), dtype=i32)
        self.fmu_time = np.zeros(len(comps))
        self.fmu_calls = np.zeros(len(comps), dtype=i64)
        self._keep += [self.fresh, self.fmu_time, self.fmu_calls]
        p.fresh, p.fmu_time, p.fmu_calls = self.fresh.ctypes.data, self.fmu_time.ctypes.data, self.fmu_calls.ctypes.data
        p.read_buf = ctypes.addressof(c._read_all)
        p.n = c.n
        self.ring = np.zeros(4, dtype=i32)
        self.times = np.zeros(3)
        self._keep += [self.ring, self.times]
        p.past, p.ring, p.times = c._past.ctypes.data, self.ring.ctypes.data, self.times.ctypes.data
        p.fed, p.fed_rate, p.fed_curv = c.fed.ctypes.data, c.fed_rate.ctypes.data, c.fed_curvature.ctypes.data
        p.input_end, p.scale, p.held = c.input_end.ctypes.data, c.scale.ctypes.data, c.held.ctypes.data
        phases = c._phases
        p.n_phases = len(phases)
        p.ph_start = self._array([ph.sl.start for ph in phases], i32)
        p.ph_n = self._array([ph.n for ph in phases], i32)
        p.ph_plain = self._array([int(ph.plain) for ph in phases], i32)
        index = {id(comp): i for i, comp in enumerate(comps)}
        src, src_off = [], []
        for ph in phases:
            src_off.append(len(src))
            src += [index[id(comp)] for comp in ph.source_comps]
        p.ph_src_off, p.ph_src_n = self._array(src_off, i32), self._array([len(ph.source_comps) for ph in phases], i32)
        p.src = self._array(src, i32)
        n = max(1, c.n)
        gather, factor, offset, set_values = np.zeros(n, i64), np.zeros(n), np.zeros(n), np.zeros(n, i64)
        rate_sel, set_d1, set_d2, rate_off, writes, write_off = [], [], [], [], [], []
        for ph in phases:
            sl = ph.sl
            gather[sl], factor[sl], offset[sl], set_values[sl] = ph.gather, ph.factor, ph.offset, ph.set_values
            rate_off.append(len(rate_sel))
            rate_sel += ph.rate_sel.tolist()
            set_d1 += ph.set_d1.tolist()
            set_d2 += ph.set_d2.tolist()
            write_off.append(len(writes))
            writes += ph.writes
        p.gather, p.factor, p.offset = self._array(gather, i64), self._array(factor, f64), self._array(offset, f64)
        p.set_values = self._array(set_values, i64)
        p.ph_rate_off = self._array(rate_off, i32)
        p.ph_rate_n = self._array([len(ph.rate_sel) for ph in phases], i32)
        p.rate_sel, p.set_d1, p.set_d2 = self._array(rate_sel, i64), self._array(set_d1, i64), self._array(set_d2, i64)
        p.set_buf = ctypes.addressof(c._set_all)
        p.ph_write_off = self._array(write_off, i32)
        p.ph_write_n = self._array([len(ph.writes) for ph in phases], i32)
        p.w_comp = self._array([index[id(w.comp)] for w in writes], i32)
        p.w_count = self._array([w.count for w in writes], i32)
        p.w_start = self._array([w.start for w in writes], i32)
        p.w_stales = self._array([int(w.stales) for w in writes], i32)
        p.w_vrs = self._pointers([ctypes.addressof(w.vrs) for w in writes])
        p.scratch = self._array(np.zeros(8 * n), f64)
        p.n_real = c.n_real
        p.row_gather = self._array(c._row_gather, i64)
        reads = c._flag_reads
        p.n_flag_reads = len(reads)
        p.f_comp = self._array([index[id(comp)] for comp, *_ in reads], i32)
        p.f_n = self._array([m for _, _, m, _, _ in reads], i32)
        p.f_bool = self._array([int(b) for *_, b in reads], i32)
        p.f_get = self._pointers([_address(comp._get_boolean if b else comp._get_integer)
                                  for comp, _, _, _, b in reads])
        p.f_vrs = self._pointers([ctypes.addressof(vrs) for _, vrs, _, _, _ in reads])
        p.f_buf = self._array(np.zeros(max([1] + [m for _, _, m, _, _ in reads])), i32)
        p.n_flags = len(c.flag_names)
        links = c.links
        p.n_groups = len(links)
        p.g_start = self._array([g.sl.start for g in links], i32)
        p.g_n = self._array([g.sl.stop - g.sl.start for g in links], i32)
        p.g_src = self._array([g.src for g in links], i32)
        p.g_dst = self._array([g.dst for g in links], i32)
        p.g_set_at = self._array([g.set_at for g in links], i32)
        p.g_rates = self._array([int(g.dt_vrs is not None) for g in links], i32)
        p.g_keeps_fresh = self._array([int(g.keeps_fresh) for g in links], i32)
        p.g_keeps_outputs = self._array([int(g.keeps_outputs) for g in links], i32)
        g_gather = np.zeros(n, i64)
        for g in links:
            g_gather[g.sl] = [c._read_at[g.src] + int(j) for j in g.src_pos]
        p.g_gather = self._array(g_gather, i64)
        p.g_vrs = self._pointers([ctypes.addressof(g.set_vrs) for g in links])
        self._stages = None
        self._commands(index)
        transfers = c.discrete.transfers
        p.n_transfers = len(transfers)
        p.t_src = self._array([index[id(t.src)] for t in transfers], i32)
        p.t_dst = self._array([index[id(t.dst)] for t in transfers], i32)
        p.t_bool = self._array([int(t.boolean) for t in transfers], i32)
        p.t_n = self._array([t.n for t in transfers], i32)
        p.t_src_vrs = self._pointers([ctypes.addressof(t.src_vrs) for t in transfers])
        p.t_dst_vrs = self._pointers([ctypes.addressof(t.dst_vrs) for t in transfers])
        p.t_values = self._pointers([ctypes.addressof(t.values) for t in transfers])
        p.d_get = self._pointers([_address(_discrete_functions(t)[0]) for t in transfers])
        p.d_set = self._pointers([_address(_discrete_functions(t)[1]) for t in transfers])
        derivs = _derivative_functions(c)
        p.set_deriv = self._pointers([_address(f) if f is not None else None for f in derivs])
        p.g_deriv = self._array([int(g.fmi_derivatives) for g in links], i32)
        group_of = {id(g): gi for gi, g in enumerate(links)}
        w_groups, w_off = [], []
        for w in writes:
            w_off.append(len(w_groups))
            w_groups += [group_of[id(g)] for g, _, _ in w.derivatives]
        p.w_deriv_off, p.w_deriv_n = self._array(w_off, i32), self._array([len(w.derivatives) for w in writes], i32)
        p.w_groups = self._array(w_groups, i32)
        p.ones, p.twos = self._array(np.ones(n), i32), self._array(np.full(n, 2), i32)
        read_idx, end_idx = c.row_extra
        p.n_extra_read, p.n_extra_end = len(read_idx), len(end_idx)
        p.extra_read, p.extra_end = self._array(read_idx, i64), self._array(end_idx, i64)
        self.p = p
        self.ptr = ctypes.addressof(p)

    def _commands(self, index: dict) -> None:
        """The commanded inputs (:class:`~..commands.CommandFeed`): per component one fmi2SetReal of the
        values :meth:`~..commands.CommandFeed.fill` puts side by side; their row for one time."""
        p, feed = self.p, self.c.commands
        writes = feed.writes() if feed is not None else []
        p.n_cmd = len(writes)
        p.cmd_comp = self._array([index[id(comp)] for comp, _, _ in writes], np.int32)
        p.cmd_count = self._array([n for _, _, n in writes], np.int32)
        offsets = np.cumsum([0] + [n for _, _, n in writes])
        p.cmd_off = self._array(offsets[:-1], np.int32)
        p.cmd_width = self.cmd_width = int(offsets[-1])
        p.cmd_vrs = self._pointers([ctypes.addressof(vrs) for _, vrs, _ in writes])
        of = np.full(len(self.c.comps), -1, dtype=np.int32)
        for w, (comp, _, _) in enumerate(writes):
            of[index[id(comp)]] = w
        p.cmd_of = self._array(of, np.int32)
        self.cmd_row = np.zeros(max(1, self.cmd_width))
        self._keep.append(self.cmd_row)
        p.cmd_values = self.cmd_row.ctypes.data

    def _command_row(self, t: float) -> None:
        """The commanded values at t into the row the kernel writes at a step's end."""
        if self.p.n_cmd:
            self.c.commands.fill(t, self.cmd_row)

    def _set_stages(self, plan) -> None:
        """The Gauss-Seidel plan (algorithms.GaussSeidel.plan: per component in stepping order, the part fed
        from those stepped before it and the part held after its step, or None) as the kernel's arrays."""
        p, groups, fed_off, fed_n, held_off, held_n = self.p, [], [], [], [], []
        for _, stepped, held in plan:
            fed_off.append(len(groups))
            groups += [gi for gi, _ in stepped._groups]
            fed_n.append(len(stepped._groups))
            held_off.append(len(groups))
            groups += [gi for gi, _ in held._groups] if held is not None else []
            held_n.append(len(held._groups) if held is not None else 0)
        p.n_stages = len(plan)
        p.s_comp = self._array([d for d, _, _ in plan], np.int32)
        p.s_fed_off, p.s_fed_n = self._array(fed_off, np.int32), self._array(fed_n, np.int32)
        p.s_held_off, p.s_held_n = self._array(held_off, np.int32), self._array(held_n, np.int32)
        p.s_groups = self._array(groups, np.int32)
        self._stages = plan

    def gauss_seidel_step(self, plan, t: float, h: float, order: int) -> None:
        """One Gauss-Seidel macro step (algorithms.GaussSeidel.step) in compiled code."""
        if self._stages is not plan:
            self._set_stages(plan)
        self.p.ends_wanted = int(self.c.ends_wanted)
        self._call(self.lib.cf_gauss_seidel_step, t, h, t, h, order)
        self.c.stats.compiled_steps += 1

    # --- around a call ----------------------------------------------------------------------------
    def _call(self, function, t: float, h: float, *args) -> None:
        """``function(plan, *args)`` of the kernel for a step of h from t (h = 0: an exchange at t): the
        commanded values at t + h first, the coupling's state handed over and back around it; raises the
        Python path's error on a failure."""
        self._command_row(t + h)
        self._enter()
        status = function(self.ptr, *args)
        self._leave()
        if status:
            self._raise(t, h)

    def _enter(self) -> None:
        c = self.c
        c.stats.kernel_calls += 1
        count = len(c._rows)
        self.ring[0] = count
        self.ring[1:1 + count] = c._rows
        self.times[:count] = c._times
        self.fresh[:] = [comp.fresh for comp in c.comps]
        self.fmu_time[:] = 0.0
        self.fmu_calls[:] = 0

    def _leave(self) -> None:
        c = self.c
        count = int(self.ring[0])
        c._rows = self.ring[1:1 + count].tolist()
        c._times = self.times[:count].tolist()
        for comp, fresh in zip(c.comps, self.fresh.tolist()):
            comp.fresh = bool(fresh)
        stats = c.stats
        for comp, dt, calls in zip(c.comps, self.fmu_time.tolist(), self.fmu_calls.tolist()):
            stats.fmu_time[comp.name] += dt
            stats.fmu_calls[comp.name] += calls

    def jacobi_step(self, t: float, h: float, order: int) -> None:
        """One Jacobi macro step (coupled.Coupling.step, then commit) in compiled code."""
        self._call(self.lib.cf_jacobi_step, t, h, t, h, order)
        self.c.stats.compiled_steps += 1

    def evaluate(self, t: float, h: float, u: np.ndarray, degree: int, part, members, through_only: bool,
                 ends: bool) -> np.ndarray | None:
        """G(u) of a strongly coupled step in compiled code (see cf_evaluate in exchange.c): ``part`` fed
        along the polynomial through its last ``degree`` values and ``u``, the components ``members``
        stepped from t by h, what ``part``'s sources give then (passed on; ``through_only``: only where
        fed through, held).  None (nothing done) where the kernel does not take it: no past point, a
        degree above 2, or a batched product size whose bits it does not reproduce here."""
        from . import agrees_with_numpy

        c = self.c
        if not c._rows or degree > 2:
            return None
        key = (id(part), tuple(members))
        arrays = self._parts.get(key)
        if arrays is None:
            if part._batched and not agrees_with_numpy(self.lib, [part.n]):
                return None
            arrays = (part, np.array([gi for gi, _ in part._groups], dtype=np.int32),
                      np.array(list(members), dtype=np.int32))
            self._parts[key] = arrays
        _, groups, steps = arrays
        u = np.ascontiguousarray(u, dtype=float)
        gu = np.empty(part.n)
        self.p.ends_wanted = int(c.ends_wanted)
        self._call(self.lib.cf_evaluate, t, h, t, h, degree, int(part._batched), int(through_only), int(ends),
                   len(groups), groups.ctypes.data, len(steps), steps.ctypes.data, u.ctypes.data, gu.ctypes.data)
        return gu

    def plain_step(self, t: float, h: float) -> None:
        """One step of libcosim's fixed-step Jacobi (algorithms.PlainJacobi.step) in compiled code."""
        self._call(self.lib.cf_plain_step, t, h, t, h)
        self.c.stats.compiled_steps += 1

    def exchange(self, t: float, order: int) -> None:
        """Every value moves at t (coupled.Coupling.commit) in compiled code."""
        self._call(self.lib.cf_exchange, t, 0.0, t, order)

    def jacobi_steps(self, ts: np.ndarray, order: int, rows: np.ndarray) -> int:
        """Jacobi macro steps on the grid ``ts`` (len(ts) - 1 of them), each row (time, outputs, discrete
        outputs) into ``rows``; returns how many were done (all; a failure is raised after the rows
        before it are in ``rows``: the caller's ``done`` attribute says how many)."""
        steps = len(ts) - 1
        values = None
        if self.p.n_cmd:   # the commanded values at every step's end, one row each
            values = np.empty((steps, self.cmd_width))
            for i in range(steps):
                self.c.commands.fill(float(ts[i + 1]), values[i])
            self.p.cmd_values = values.ctypes.data
        self._enter()
        try:
            done = self.lib.cf_jacobi_steps(self.ptr, ts.ctypes.data, order, steps, rows.ctypes.data)
        finally:
            self.p.cmd_values = self.cmd_row.ctypes.data
        self._leave()
        if done < 0:
            self.done = -1 - done
            self.c.stats.compiled_steps += self.done
            self._raise(float(ts[self.done]), float(ts[self.done + 1] - ts[self.done]))
        self.done = done
        self.c.stats.compiled_steps += done
        return done

    def _raise(self, t: float, h: float) -> None:
        """The error the Python path raises for the failure the kernel reported."""
        p = self.p
        comp = self.c.comps[p.err_comp]
        what = {1: "fmi2DoStep", 2: "fmi2GetReal", 3: "fmi2SetReal", 4: "fmi2GetInteger", 6: "fmi2GetInteger",
                7: "fmi2SetInteger"}[p.err_what]
        try:
            comp._failed(what, p.err_status)
        except Exception:
            if p.err_what == 1:
                raise SimulationError(f"component {comp.name} failed in the step from t = {t:.9g} s (H = {h:.3g} s): "
                                      f"{comp.last_error()}. Try a smaller --step, --adaptive, or --algorithm "
                                      "iterative.") from None
            doing = {2: "reading its outputs", 3: "setting its inputs", 4: "reading its discrete outputs",
                     6: "reading its discrete outputs", 7: "setting its discrete inputs"}[p.err_what]
            raise self.c.refused(comp, doing) from None
