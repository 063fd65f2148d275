"""Power bonds: force/velocity pairs between two components, and the ECCO energy residual.

Declared in the SSD (format in README.md, "Power bonds"): an ``ssc:Annotation`` of type
``org.cranefmu.powerbonds`` in the System.  Per bond and step, dE = |P_a - P_b| * h [J]
(Sadjina et al. 2017, ECCO), P = sign * sum(force_i * velocity_i) of each side, every input taken
as the value it was fed at the end of the step and every output as read at the end of the step.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .divergence import Growth, GrowthAlarm
from .errors import SceneError
from .system import CoSystem

ANNOTATION = "org.cranefmu.powerbonds"


@dataclass
class _Side:
    comp: int
    sign: float
    out_vrs: list[int]           # outputs, read in one call
    out_pos: list[int]           # their position in the side's value vector
    in_index: list[int]          # connected inputs: index into CoSystem.input_end
    in_pos: list[int]
    free_vrs: list[int]          # unconnected inputs: read back from the FMU
    free_pos: list[int]
    n: int                       # number of force/velocity pairs

    def values(self, system: CoSystem) -> np.ndarray:
        v = np.empty(2 * self.n)
        comp = system.comps[self.comp]
        if self.out_vrs:
            v[self.out_pos] = comp.get_real(self.out_vrs)
        if self.in_index:
            v[self.in_pos] = system.input_end[self.in_index]
        if self.free_vrs:
            v[self.free_pos] = comp.get_real(self.free_vrs)
        return v

    def power(self, system: CoSystem) -> float:
        v = self.values(system)
        with np.errstate(over="ignore", invalid="ignore"):  # a blow-up is reported by the run's check
            return self.sign * float(v[:self.n] @ v[self.n:])


@dataclass
class Bond:
    name: str
    a: _Side
    b: _Side


def read_bonds(ssd: Path) -> list[tuple[str, list[dict]]]:
    """(bond name, [side attributes a, b]) from the SSD's power-bond annotation (none if absent)."""
    from lxml import etree

    root = etree.parse(str(ssd), etree.XMLParser(resolve_entities=False, no_network=True)).getroot()
    out = []
    for ann in root.iter("{*}Annotation"):
        if ann.get("type") != ANNOTATION:
            continue
        for bond in ann.iter("{*}Bond"):
            name = bond.get("name")
            sides = [dict(s.attrib) for s in bond if isinstance(s.tag, str) and etree.QName(s).localname == "Side"]
            if not name:
                raise SceneError(f"{ssd.name}: a power bond has no name")
            if len(sides) != 2:
                raise SceneError(f"{ssd.name}: power bond {name!r} has {len(sides)} Side elements; exactly 2 allowed")
            out.append((name, sides))
    return out


def resolve(system: CoSystem, bonds: list[tuple[str, list[dict]]]) -> list[Bond]:
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
            resolved.append(side)
        out.append(Bond(name, *resolved))
    return out


class BondMonitor:
    """Observer of the power bonds: per step dE and running total per bond; optional alarm."""

    def __init__(self, system: CoSystem, bonds: list[Bond]):
        self.system = system
        self.bonds = bonds
        self.names = [b.name for b in bonds]
        self.columns = [c for n in self.names for c in (f"bond.{n}.dE", f"bond.{n}.E")]
        self.total = np.zeros(len(bonds))
        self.residual = np.zeros(len(bonds))   # of the last step [J]
        self.carried = np.zeros(len(bonds))    # energy through each bond in the last step [J]
        self.row = np.zeros(2 * len(bonds))
        self.growth_alarm: GrowthAlarm | None = None   # set by the run: fixed step, alarm on
        self.grown: Growth | None = None

    def measure(self, h: float) -> None:
        """Residual of the step just taken (call after the step, before recording)."""
        for k, b in enumerate(self.bonds):
            pa, pb = b.a.power(self.system), b.b.power(self.system)
            self.residual[k] = abs(pa - pb) * h
            self.carried[k] = max(abs(pa), abs(pb)) * h
        self.total += self.residual
        self.row[0::2] = self.residual
        self.row[1::2] = self.total
        if self.growth_alarm is not None and self.grown is None:
            self.grown = self.growth_alarm.update(self.residual, self.carried)

    def between(self, k: int) -> str:
        """The components bond k joins, as 'a and b'."""
        b = self.bonds[k]
        return f"{self.system.comps[b.a.comp].name} and {self.system.comps[b.b.comp].name}"

    def totals(self) -> dict[str, float]:
        return {n: float(e) for n, e in zip(self.names, self.total)}
