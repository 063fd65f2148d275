"""Power bonds: force/velocity pairs between two components, and the ECCO energy residual.

Declared in the SSD (format in docs/power_bonds.md, "Declaring a bond"): an ``ssc:Annotation`` of type
``org.cranefmu.powerbonds`` in the System.  Per bond and step, dE = |P_a - P_b| * h [J]
(Sadjina et al. 2017, ECCO), P = sign * sum(force_i * velocity_i) of each side, every input taken
as the value it was fed at the end of the step and every output as read at the end of the step.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import SceneError

RESIDUAL_WARNING = 0.1   # a run warns when a bond's total residual exceeds this fraction of the energy it carried
NEGLIGIBLE = 1e-3        # ... unless it is below this fraction of the most energy any bond of the scene carried
#: ... or unless it is below the bond's impulse (sum over steps of the larger side's |force| h [N s or N m s])
#: times this speed [m/s or rad/s]: the two sides' velocities then differ by round-off on average.  A state at rest
#: reads as a speed of about eps x position / step (10 m at 1 ms: 2e-12 m/s).  Measured (residual / impulse):
#: overhead_lift at rest over 0.1 s at 10 ms steps 7e-13 m/s (hook), 1e-13 (trolley), 5e-15 rad/s (drum);
#: hook_sway over 10 s with its stored settings 4e-5 m/s, with the old default that pumps energy in (jacobi,
#: extrapolation 0, 1 ms) 1e-3 m/s.
ROUNDOFF_SPEED = 1e-9


@dataclass
class _Side:
    comp: int
    sign: float
    out_vrs: list[int]           # outputs, read in one call
    out_pos: list[int]           # their position in the side's value vector
    in_index: list[int]          # connected inputs: index into Coupling.input_end
    in_pos: list[int]
    free_vrs: list[int]          # unconnected inputs: read back from the FMU
    free_pos: list[int]
    n: int                       # number of force/velocity pairs
    read_pos: np.ndarray | None = None   # outputs and unconnected inputs: positions in the component's read vector
    value_pos: np.ndarray | None = None  # ... and in the side's value vector
    in_index_a: np.ndarray | None = None
    in_pos_a: np.ndarray | None = None

    def prepare(self, system) -> None:
        """Index arrays for :meth:`values`: the side's outputs and unconnected inputs join the
        component's one read per step (shared with the recorder and the exchange)."""
        self.read_pos = system.comps[self.comp].position(self.out_vrs + self.free_vrs)
        self.value_pos = np.array(self.out_pos + self.free_pos, dtype=np.intp)
        self.in_index_a = np.array(self.in_index, dtype=np.intp)
        self.in_pos_a = np.array(self.in_pos, dtype=np.intp)

    def values(self, system) -> np.ndarray:
        v = np.empty(2 * self.n)
        if len(self.read_pos):
            v[self.value_pos] = system.read_component(self.comp)[self.read_pos]
        if self.in_index:
            v[self.in_pos_a] = system.input_end[self.in_index_a]
        return v

    def power(self, system) -> float:
        v = self.values(system)
        with np.errstate(over="ignore", invalid="ignore"):  # a blow-up is reported by the run's check
            f, u = v[:self.n], v[self.n:]
            self.capacity = float(np.sqrt((f @ f) * (u @ u)))   # |force| |velocity| [W] (master/divergence.py)
            return self.sign * float(f @ u)


@dataclass
class Bond:
    name: str
    a: _Side
    b: _Side


def resolve(system, bonds: list[tuple[str, list[dict]]]) -> list[Bond]:
    """Check every side's component and variables and resolve them to value references."""
    names = [c.name for c in system.comps]
    fed = {}  # (component index, input value reference) -> index in the coupling vector
    for g, sl in zip(system.links, system.slices):
        for j, vr in enumerate(g.dst_vrs):
            fed[(g.dst, vr)] = sl.start + j
    seen = set()
    out = []
    for name, sides in bonds:
        if name in seen:
            raise SceneError(f"power bond {name!r} is declared twice")
        seen.add(name)
        resolved = []
        for label, attrs in zip("ab", sides):
            where = f"power bond {name!r}, side {label}"
            comp_name = attrs.get("component", "")
            if comp_name not in names:
                raise SceneError(f"{where}: component {comp_name!r} is not in the scene (one of {', '.join(names)})")
            ci = names.index(comp_name)
            comp = system.comps[ci]
            force = attrs.get("force", "").split()
            velocity = attrs.get("velocity", "").split()
            if not force or len(force) != len(velocity):
                raise SceneError(f"{where}: force {force} and velocity {velocity} must name the same number (>= 1) "
                                 "of variables")
            try:
                sign = float(attrs.get("sign", "1"))
            except ValueError:
                sign = 0.0
            if sign not in (1.0, -1.0):
                raise SceneError(f"{where}: sign = {attrs.get('sign')!r} is not allowed: 1 or -1")
            side = _Side(ci, sign, [], [], [], [], [], [], len(force))
            for pos, var in enumerate(force + velocity):
                v = comp.variables.get(var)
                if v is None:
                    raise SceneError(f"{where}: {comp_name} has no variable {var!r}")
                if v.type != "Real" or v.causality not in ("input", "output"):
                    raise SceneError(f"{where}: {comp_name}.{var} is a {v.causality} {v.type}; a Real input or "
                                     "output is needed")
                if v.causality == "output":
                    side.out_vrs.append(v.valueReference)
                    side.out_pos.append(pos)
                elif (ci, v.valueReference) in fed:
                    side.in_index.append(fed[(ci, v.valueReference)])
                    side.in_pos.append(pos)
                else:
                    side.free_vrs.append(v.valueReference)
                    side.free_pos.append(pos)
            side.prepare(system)
            resolved.append(side)
        out.append(Bond(name, *resolved))
    return out


class BondBlock:
    """What :meth:`BondMonitor.measure_block` measured over a stretch, one row per step, one column per
    bond [J]: residual, carried, imbalance, capacity, roundoff as the monitor keeps them for one step,
    and the running totals after each step (total, carried_total, impulse)."""

    steps: int
    residual: np.ndarray
    carried: np.ndarray
    imbalance: np.ndarray
    capacity: np.ndarray
    roundoff: np.ndarray
    total: np.ndarray
    carried_total: np.ndarray
    impulse: np.ndarray


def _larger(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Python's max(a, b) elementwise (a unless b > a: a NaN in b is not taken, one in a is kept)."""
    return np.where(b > a, b, a)


def _running(start: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """start + steps[0], then + steps[1], ... per column (one addition after another, as a running float
    total adds them), shape of ``steps``."""
    return np.cumsum(np.concatenate([start[None, :], steps]), axis=0)[1:]


class BondMonitor:
    """Observer of the power bonds: per step dE and running total per bond; optional alarm."""

    def __init__(self, system, bonds: list[Bond]):
        self.system = system
        self.bonds = bonds
        self.names = [b.name for b in bonds]
        self.columns = [c for n in self.names for c in (f"bond.{n}.dE", f"bond.{n}.E")]
        self.total = np.zeros(len(bonds))
        self.residual = np.zeros(len(bonds))   # of the last step [J]
        self.carried = np.zeros(len(bonds))    # energy through each bond in the last step [J]
        self.carried_total = np.zeros(len(bonds))   # ... summed over the run [J]
        self.impulse = [0.0] * len(bonds)   # sum over steps of the larger side's |force| h [N s] (warnings' floor)
        self.row = np.zeros(2 * len(bonds))
        self.imbalance = [0.0] * len(bonds)   # signed P_a - P_b times h of the last step [J]
        self.residual_list = [0.0] * len(bonds)   # residual and carried of the last step as lists
        self.carried_list = [0.0] * len(bonds)
        self.roundoff_list = [0.0] * len(bonds)   # ROUNDOFF_SPEED x the larger side's |force| h of the last step [J]
        self.capacity = [0.0] * len(bonds)    # largest |force| |velocity| of the two sides times h [J]
        self._plan()

    def _plan(self) -> None:
        """Index arrays for :meth:`measure`: every side's force and velocity values in one vector
        (sides a, b of bond 0, then of bond 1, ...), filled with one gather per component and one
        from the inputs' end values."""
        sides = [s for b in self.bonds for s in (b.a, b.b)]
        offsets = np.cumsum([0] + [2 * s.n for s in sides])
        reads: dict[int, tuple[list, list]] = {}
        in_v, in_index = [], []
        for s, off in zip(sides, offsets):
            vpos, rpos = reads.setdefault(s.comp, ([], []))
            vpos += [off + int(i) for i in s.value_pos]
            rpos += [int(i) for i in s.read_pos]
            in_v += [off + i for i in s.in_pos]
            in_index += s.in_index
        self._v = np.zeros(int(offsets[-1]))
        self._reads = [(c, np.array(v, dtype=np.intp), np.array(r, dtype=np.intp)) for c, (v, r) in reads.items()]
        self._in_v, self._in_index = np.array(in_v, dtype=np.intp), np.array(in_index, dtype=np.intp)
        self._has_inputs = bool(in_v)
        if self._has_inputs:
            self.system.ends_wanted = True   # the coupling notes its inputs' end values each step
        self._sides = [(int(off), s.n, s.sign) for s, off in zip(sides, offsets)]

    def measure(self, h: float) -> None:
        """Residual of the step just taken (call after the step, before recording).  The sums of
        :meth:`_Side.power` for every side, on Python floats (a bond has 1-3 force/velocity pairs:
        cheaper than array calls; an overflow gives inf, reported by the run's check)."""
        if not self.bonds:
            return
        v, system = self._v, self.system
        for comp, vpos, rpos in self._reads:
            v[vpos] = system.read_component(comp)[rpos]
        if self._has_inputs:
            v[self._in_v] = system.input_end[self._in_index]
        self._compute(h)

    def stretch_layout(self, read_at: list[int]) -> tuple[list[int], list[int]]:
        """What a compiled stretch's rows carry for :meth:`measure_values`: positions in the coupling's
        read buffer (each component's part starts at ``read_at``) and in its inputs' end values."""
        return [read_at[c] + int(r) for c, _, rpos in self._reads for r in rpos], self._in_index.tolist()

    def measure_values(self, values: np.ndarray, h: float) -> None:
        """:meth:`measure` from the values a stretch's row carries (:meth:`stretch_layout`)."""
        v, at = self._v, 0
        for _, vpos, _ in self._reads:
            v[vpos] = values[at:at + len(vpos)]
            at += len(vpos)
        if self._has_inputs:
            v[self._in_v] = values[at:]
        self._compute(h)

    def measure_block(self, values: np.ndarray, hs: np.ndarray) -> "BondBlock":
        """:meth:`measure_values` for every row of a stretch at once (``values``: the rows' bond values,
        shape (steps, ...); ``hs``: each step [s]), without changing the monitor: :meth:`commit` does.
        The same operations in the same order as :meth:`_compute` on each row (elementwise products and
        sums, running totals accumulated one row after another), so the same bits."""
        steps, nb = len(hs), len(self.bonds)
        b = BondBlock()
        b.steps = steps
        if nb == 0:
            b.residual = b.carried = b.imbalance = b.capacity = b.roundoff = np.zeros((steps, 0))
            b.total = b.carried_total = b.impulse = np.zeros((steps, 0))
            return b
        v = np.empty((steps, len(self._v)))
        order = [vpos for _, vpos, _ in self._reads] + ([self._in_v] if self._has_inputs else [])
        v[:, np.concatenate(order)] = values
        power, capacity, force = [], [], []
        with np.errstate(over="ignore", invalid="ignore"):
            for off, n, sign in self._sides:
                p, ff, uu = np.zeros(steps), np.zeros(steps), np.zeros(steps)
                for i in range(off, off + n):
                    f, u = v[:, i], v[:, i + n]
                    p += f * u
                    ff += f * f
                    uu += u * u
                power.append(sign * p)
                capacity.append(np.sqrt(ff * uu))
                force.append(ff)
            h = hs[:, None]
            pa, pb = np.stack(power[0::2], axis=1), np.stack(power[1::2], axis=1)
            b.residual = np.abs(pa - pb) * h
            b.carried = _larger(np.abs(pa), np.abs(pb)) * h
            b.imbalance = (pa - pb) * h
            b.capacity = _larger(np.stack(capacity[0::2], axis=1), np.stack(capacity[1::2], axis=1)) * h
            impulse = np.sqrt(_larger(np.stack(force[0::2], axis=1), np.stack(force[1::2], axis=1))) * h
            b.roundoff = ROUNDOFF_SPEED * impulse
            b.total = _running(self.total, b.residual)
            b.carried_total = _running(self.carried_total, b.carried)
            b.impulse = _running(np.array(self.impulse, dtype=float), impulse)
        return b

    def commit(self, block: "BondBlock", rows: int) -> None:
        """The monitor as :meth:`measure_values` leaves it after the first ``rows`` rows of ``block``."""
        if rows == 0 or not self.bonds:
            return
        i = rows - 1
        residual, carried = block.residual[i], block.carried[i]
        self.residual[:] = residual
        self.carried[:] = carried
        self.residual_list, self.carried_list = residual.tolist(), carried.tolist()
        self.roundoff_list = block.roundoff[i].tolist()
        self.imbalance = block.imbalance[i].tolist()
        self.capacity = block.capacity[i].tolist()
        self.impulse = block.impulse[i].tolist()
        self.total[:] = block.total[i]
        self.carried_total[:] = block.carried_total[i]
        self.row[0::2] = self.residual
        self.row[1::2] = self.total

    def _compute(self, h: float) -> None:
        x = self._v.tolist()
        power, capacity, force = [], [], []
        for off, n, sign in self._sides:
            p = ff = uu = 0.0
            for i in range(off, off + n):
                f, u = x[i], x[i + n]
                p += f * u
                ff += f * f
                uu += u * u
            power.append(sign * p)
            capacity.append(math.sqrt(ff * uu) if ff * uu >= 0.0 else math.nan)
            force.append(ff)
        residual, carried, roundoff = [], [], []
        for k in range(len(self.bonds)):
            pa, pb = power[2 * k], power[2 * k + 1]
            residual.append(abs(pa - pb) * h)
            carried.append(max(abs(pa), abs(pb)) * h)
            self.imbalance[k] = (pa - pb) * h
            self.capacity[k] = max(capacity[2 * k], capacity[2 * k + 1]) * h
            impulse = math.sqrt(max(force[2 * k], force[2 * k + 1])) * h
            self.impulse[k] += impulse
            roundoff.append(ROUNDOFF_SPEED * impulse)
        self.residual[:] = residual
        self.carried[:] = carried
        self.residual_list, self.carried_list = residual, carried   # the same, as floats (for the alarm)
        self.roundoff_list = roundoff
        self.total += self.residual
        self.carried_total += self.carried
        self.row[0::2] = self.residual
        self.row[1::2] = self.total

    def between(self, k: int) -> str:
        """The components bond k joins, as 'a and b'."""
        b = self.bonds[k]
        return f"{self.system.comps[b.a.comp].name} and {self.system.comps[b.b.comp].name}"

    def totals(self) -> dict[str, float]:
        return {n: float(e) for n, e in zip(self.names, self.total)}

    def carried_totals(self) -> dict[str, float]:
        """Energy through each bond over the run [J]: the sum over steps of max(|P_a|, |P_b|) h."""
        return {n: float(e) for n, e in zip(self.names, self.carried_total)}

    def warnings(self, fraction: float = RESIDUAL_WARNING) -> list[str]:
        """One line per bond whose total residual exceeds ``fraction`` of the energy it carried: the
        coupling created or destroyed that much energy at the seam (it never steers the run).  Not
        reported: a bond near rest whose residual is below NEGLIGIBLE of the most any bond carried, and
        a residual below ROUNDOFF_SPEED times the bond's impulse (round-off of a scene at rest)."""
        out = []
        scale = float(self.carried_total.max()) if len(self.names) else 0.0
        for k, name in enumerate(self.names):
            total, carried = float(self.total[k]), float(self.carried_total[k])
            if (total > fraction * carried and total > NEGLIGIBLE * scale
                    and total > ROUNDOFF_SPEED * self.impulse[k]):
                out.append(f"power bond {name} (between {self.between(k)}): energy residual {total:.3g} J is "
                           f"{total / carried if carried > 0 else math.inf:.3g} of the {carried:.3g} J it carried "
                           f"(more than {fraction:g}): the coupling adds or removes energy at this seam; "
                           "a smaller step or a higher extrapolation order keeps it in check (docs/power_bonds.md)")
        return out
