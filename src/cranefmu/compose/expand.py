"""The connect lines of a scene source expanded into variable connections and power bonds, checked.

Two forms (docs/composition.md):

- ``"a.port = b.port"`` (``as NAME`` or ``no bond`` optional): two ports, one that takes motion and
  gives force (the rope at the hook) and one that takes force and gives motion (the hook).  Expands,
  axis by axis, to position and velocity from the motion side and force back, in that order; a part
  one port lacks is left out.  Where both have force and velocity the pair is a power bond, named
  ``NAME`` or after the motion side's port, its force side first; ``no bond`` leaves it undeclared
  (the scene's comment says why).  An input that an earlier line already drives keeps that source (a scene may route a part elsewhere, e.g. a position passed on through another FMU).
- ``"a.x -> b.y"``: output to input, one variable or a part of a port on each end
  (``a.port.position``, ``velocity``, ``force`` or ``motion`` = position and velocity).

Every pair is checked: the source an output, the destination an input nobody else drives, the
same unit (a foreign FMU joins by its variables with the same checks).
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from ..adapter.units import parse as parse_unit
from .interface import PARTS, Interface, PortSpec
from .source import SceneSource

_PORT_PAIR = re.compile(r"^\s*(\S+)\s*=\s*(\S+?)(?:\s+as\s+(\w+))?(\s+no\s+bond)?\s*$")
_FLOW = re.compile(r"^\s*(\S+)\s*->\s*(\S+)\s*$")


@dataclass(frozen=True)
class Link:
    src: str
    src_var: str
    dst: str
    dst_var: str


@dataclass(frozen=True)
class Bond:
    name: str
    description: str
    sides: tuple[tuple[str, PortSpec], tuple[str, PortSpec]]   # (component, port): force side first


@dataclass(frozen=True)
class PortPair:
    """A port line whose every link was added (none routed elsewhere): other tools may join it as one
    (an OSP VariableGroupConnection); its links are ``count`` from index ``first``."""

    a: tuple[str, PortSpec]
    b: tuple[str, PortSpec]
    first: int
    count: int


@dataclass(frozen=True)
class Expanded:
    links: list[Link]
    bonds: list[Bond]
    pairs: list[PortPair]


def expand(src: SceneSource, interfaces: dict[str, Interface]) -> Expanded:
    """Every connect line of ``src`` as links and bonds; a :class:`CompositionError` naming the file,
    the line and the port or variable at the first misfit."""
    links: list[Link] = []
    bonds: list[Bond] = []
    pairs: list[PortPair] = []
    driven: dict[tuple[str, str], Link] = {}
    for line in src.connect:
        pair, flow = _PORT_PAIR.match(line), _FLOW.match(line)
        if pair:
            new, bond, ends = _port_pair(src, interfaces, line, *pair.groups()[:3], declare=not pair.group(4))
            kept = [k for k in new if (k.dst, k.dst_var) not in driven]
            if kept == new and new:
                pairs.append(PortPair(*ends, len(links), len(new)))
            new = kept
            if bond is not None:
                if any(b.name == bond.name for b in bonds):
                    raise src.fail(line, f"connect {line!r}: a power bond named {bond.name!r} exists already: "
                                         "name this one with 'as NAME'")
                bonds.append(bond)
        elif flow:
            new = _flow(src, interfaces, line, *flow.groups())
            for k in new:
                if (k.dst, k.dst_var) in driven:
                    old = driven[(k.dst, k.dst_var)]
                    raise src.fail(line, f"connect {line!r}: input {k.dst}.{k.dst_var} is driven already by "
                                         f"{old.src}.{old.src_var}: an input takes one source")
        else:
            raise src.fail(line, f"connect {line!r} is not a connection: write \"a.port = b.port\" (two ports) "
                                 "or \"a.x -> b.y\" (an output to an input)")
        for k in new:
            driven[(k.dst, k.dst_var)] = k
        links += new
    return Expanded(links, bonds, pairs)


def _end(src: SceneSource, interfaces: dict[str, Interface], line: str, text: str, port_first: bool = False):
    """(component, variable) or (component, PortSpec, part or None) of one end ``text`` (a name that is
    both a port and a variable, as the Boom's switch ``tip``: the port if ``port_first``)."""
    comp, _, rest = text.partition(".")
    if comp not in interfaces:
        raise src.fail(line, f"connect {line!r}: unknown component {comp!r} (components: "
                             f"{', '.join(interfaces)})")
    iface = interfaces[comp]
    if rest in iface.variables and not (port_first and rest in iface.ports):
        return comp, rest
    if rest in iface.ports:
        return comp, iface.ports[rest], None
    port, _, part = rest.rpartition(".")
    if port in iface.ports and part in (*PARTS, "motion"):
        return comp, iface.ports[port], part
    ports = ", ".join(iface.ports) or "none"
    raise src.fail(line, f"connect {line!r}: {comp} ({iface.fmu.name}) has no port or variable {rest!r} "
                         f"(ports: {ports}; a part: PORT.position, .velocity, .force or .motion)")


def _variables(src: SceneSource, line: str, end) -> list[str]:
    if len(end) == 2:
        return [end[1]]
    comp, port, part = end
    if part is None:
        raise src.fail(line, f"connect {line!r}: {comp}.{port.name} is a port: connect two ports with '=', or "
                             f"name a part ({comp}.{port.name}.force)")
    names = port.parts["position"] + port.parts["velocity"] if part == "motion" else port.parts[part]
    if not names:
        raise src.fail(line, f"connect {line!r}: port {comp}.{port.name} has no {part}")
    return list(names)


def _flow(src: SceneSource, interfaces: dict[str, Interface], line: str, a: str, b: str) -> list[Link]:
    ea, eb = _end(src, interfaces, line, a), _end(src, interfaces, line, b)
    va, vb = _variables(src, line, ea), _variables(src, line, eb)
    if len(va) != len(vb):
        raise src.fail(line, f"connect {line!r}: {len(va)} variables ({' '.join(va)}) to {len(vb)} ({' '.join(vb)})")
    return [_checked(src, interfaces, line, Link(ea[0], x, eb[0], y)) for x, y in zip(va, vb)]


def _port_pair(src: SceneSource, interfaces: dict[str, Interface], line: str, a: str, b: str,
               name: str | None, declare: bool = True) -> tuple[list[Link], Bond | None, tuple]:
    ends = [_end(src, interfaces, line, text, port_first=True) for text in (a, b)]
    for end, text in zip(ends, (a, b)):
        if len(end) == 2 or end[2] is not None:
            raise src.fail(line, f"connect {line!r}: {text} is not a port ('=' joins two ports; '->' one "
                                 "variable or part to another)")
    (ca, pa, _), (cb, pb, _) = ends
    if pa.kind != pb.kind:
        raise src.fail(line, f"connect {line!r}: port {ca}.{pa.name} is {pa.kind}, {cb}.{pb.name} is {pb.kind}")
    if pa.takes == pb.takes:
        both = "take motion (both give force)" if pa.takes == "motion" else "take force (both give motion)"
        raise src.fail(line, f"connect {line!r}: ports {ca}.{pa.name} and {cb}.{pb.name} both {both}: join a "
                             "port that gives force to one that gives motion")
    (cf, pf), (cm, pm) = ((ca, pa), (cb, pb)) if pa.takes == "motion" else ((cb, pb), (ca, pa))
    links = []
    for part in PARTS:
        vf, vm = pf.parts[part], pm.parts[part]
        if not vf or not vm:
            continue
        if len(vf) != len(vm):
            raise src.fail(line, f"connect {line!r}: {part} of {cf}.{pf.name} has {len(vf)} axes, of {cm}.{pm.name} "
                                 f"{len(vm)}")
        pairs = zip(vf, vm)
        links += [_checked(src, interfaces, line, Link(cf, f, cm, m) if part == "force" else Link(cm, m, cf, f))
                  for f, m in pairs]
    powered = bool(pf.parts["force"] and pf.parts["velocity"] and pm.parts["force"] and pm.parts["velocity"])
    if name and not (powered and declare):
        raise src.fail(line, f"connect {line!r}: 'as {name}' names a power bond, and " + (
            "'no bond' declares none" if powered else "these ports do not form one (each needs force and velocity)"))
    if powered and not declare:   # joined, but the bond left out of the SSD on purpose (the scene says why)
        return links, None, ((ca, pa), (cb, pb))
    if not powered and not declare:
        raise src.fail(line, f"connect {line!r}: 'no bond' is not needed: {ca}.{pa.name} and {cb}.{pb.name} form "
                             "no power bond (each would need force and velocity)")
    bond = Bond(name or pm.name, pf.description, ((cf, pf), (cm, pm))) if powered else None
    return links, bond, ((ca, pa), (cb, pb))


def _checked(src: SceneSource, interfaces: dict[str, Interface], line: str, link: Link) -> Link:
    """``link`` if it runs from an output to an input of the same unit."""
    a = interfaces[link.src].variables[link.src_var]
    b = interfaces[link.dst].variables[link.dst_var]
    text = f"{link.src}.{link.src_var} -> {link.dst}.{link.dst_var}"
    if a.causality != "output" or b.causality != "input":
        raise src.fail(line, f"connect {line!r}: {text} runs from {a.causality} to {b.causality}: a connection "
                             "runs from an output to an input")
    if a.type != b.type:
        raise src.fail(line, f"connect {line!r}: {text} joins {a.type} to {b.type}")
    if not same_unit(a.unit, b.unit):
        raise src.fail(line, f"connect {line!r}: {text} joins unit {a.unit or '1'} to {b.unit or '1'}")
    return link


def same_unit(a: str, b: str) -> bool:
    """True if the units ``a`` and ``b`` are one (equal text, or the same factor and SI exponents); a
    variable that declares no unit (a foreign FMU's) is not checked."""
    if a == b or not a or not b:
        return True
    try:
        return parse_unit(a or "1") == parse_unit(b or "1")
    except ValueError:
        return False
