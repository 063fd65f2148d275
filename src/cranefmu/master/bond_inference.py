"""Power bonds inferred from a scene's connections by unit, for a scene whose SSD declares none.

Two components a and b form a bond where a sends b forces and b sends a velocities: a force [N]
with a velocity [m/s], a torque [N.m] with an angular velocity [rad/s or 1/s] (units from the
FMUs' model descriptions, else the SSD's connectors).  Side a is a's force outputs with its
velocity inputs, side b is b's force inputs with its velocity outputs, so that on each side
P = sum(F_i v_i) is the power through the seam (the format of :func:`.power_bonds.read_bonds`;
docs/power_bonds.md).  Forces are paired with velocities by the axis letter of their names
(``Fx_hook`` with ``vx``; an axis on one side only is left out) where each names a distinct
axis, else in the order of the connections if they are as many; a pair of components whose
forces and velocities cannot be paired so, or whose transformations flip some signs and not
others, gets no bond.  Both sides take P = F.v (sign 1): a declared bond may give both sides -1
(a moment counted against the rotation), which flips the sign of the imbalance, not its size.  Positions and other quantities
never form a bond, so a force/displacement coupling is watched through its velocity connections.
"""
from __future__ import annotations

import re
from typing import Mapping

from ..adapter.units import parse as parse_unit
from .scene import ConnectionSpec, Scene

FORCE, VELOCITY, TORQUE, ANGULAR = "force", "velocity", "torque", "angular velocity"
_KINDS = {
    (("kg", 1), ("m", 1), ("s", -2)): FORCE,
    (("m", 1), ("s", -1)): VELOCITY,
    (("kg", 1), ("m", 2), ("s", -2)): TORQUE,
    (("rad", 1), ("s", -1)): ANGULAR,
    (("s", -1),): ANGULAR,
}
_EFFORT_FLOW = ((FORCE, VELOCITY), (TORQUE, ANGULAR))
_AXIS = re.compile(r"^[A-Za-z]?([xyz])$")
_BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def _exponents(unit: str, md) -> tuple | None:
    """Base-unit exponents of ``unit``: parsed, else from the FMU's UnitDefinitions (None if unknown)."""
    try:
        return tuple(sorted(parse_unit(unit)[1].items()))
    except ValueError:
        pass
    for u in getattr(md, "unitDefinitions", None) or []:
        if u.name == unit and u.baseUnit is not None:
            return tuple((k, int(getattr(u.baseUnit, k))) for k in _BASE if int(getattr(u.baseUnit, k)))
    return None


def _unit(scene: Scene, md, comp: str, var: str) -> str:
    """The variable's unit in the FMU (its own or its declared type's), else the SSD connector's."""
    for v in md.modelVariables if md is not None else []:
        if v.name == var:
            unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
            if unit:
                return unit
            break
    for c in scene.components:
        if c.name == comp:
            for conn in c.connectors:
                if conn.name == var and conn.unit:
                    return conn.unit
    return ""


def _kind(scene: Scene, descriptions: Mapping[str, object], comp: str, var: str) -> str | None:
    md = descriptions.get(comp)
    unit = _unit(scene, md, comp, var)
    return _KINDS.get(_exponents(unit, md)) if unit else None


def _axis(c: ConnectionSpec) -> str | None:
    """The axis letter of a connection's ends (``Fx_hook`` -> x), if one of them names one."""
    for name in (c.src_var, c.dst_var):
        for token in name.split("_"):
            m = _AXIS.match(token)
            if m:
                return m.group(1)
    return None


def _pairs(efforts: list[ConnectionSpec], flows: list[ConnectionSpec]) -> list[tuple] | None:
    """Efforts paired with flows one to one: by axis letter where every one names a distinct axis
    (an axis on one side only is left out), else in order if they are as many."""
    ea, fa = [_axis(c) for c in efforts], [_axis(c) for c in flows]
    if None not in ea and None not in fa and len(set(ea)) == len(ea) and len(set(fa)) == len(fa):
        by_axis = dict(zip(fa, flows))
        return [(e, by_axis[a]) for e, a in zip(efforts, ea) if a in by_axis] or None
    return list(zip(efforts, flows)) if len(efforts) == len(flows) else None


def infer_bonds(scene: Scene, descriptions: Mapping[str, object]) -> list[tuple[str, list[dict]]]:
    """(bond name, [side a, side b] attributes) for every component pair that exchanges forces one
    way and velocities the other, one for forces and one (``a-b-rotation``) for torques
    (``descriptions``: component name -> fmpy ModelDescription)."""
    kinds = {}
    for c in scene.connections:
        kinds[c] = _kind(scene, descriptions, c.src, c.src_var) or _kind(scene, descriptions, c.dst, c.dst_var)
    names = [c.name for c in scene.components]
    out = []
    for a in names:
        for b in names:
            for effort_kind, flow_kind in _EFFORT_FLOW if a != b else ():
                efforts = [c for c in scene.connections if (c.src, c.dst) == (a, b) and kinds[c] == effort_kind]
                flows = [c for c in scene.connections if (c.src, c.dst) == (b, a) and kinds[c] == flow_kind]
                pairs = _pairs(efforts, flows) if efforts and flows else None
                signs = {(e.factor > 0) == (f.factor > 0) for e, f in pairs or ()}
                if not pairs or len(signs) != 1:
                    continue
                name = f"{a}-{b}" + ("" if effort_kind == FORCE else "-rotation")
                out.append((name, [
                    {"component": a, "force": " ".join(e.src_var for e, _ in pairs),
                     "velocity": " ".join(f.dst_var for _, f in pairs)},
                    {"component": b, "force": " ".join(e.dst_var for e, _ in pairs),
                     "velocity": " ".join(f.src_var for _, f in pairs), "sign": "1" if signs.pop() else "-1"}]))
    return out


def scene_bonds(scene: Scene, descriptions: Mapping[str, object]) -> tuple[list[tuple[str, list[dict]]], bool]:
    """The scene's declared power bonds, or if it declares none the inferred ones; and whether inferred.
    An empty power-bond annotation declares that the scene has none: nothing is inferred.  A scene
    whose bonds were settled when it was read (``bonds_inferred`` not None) answers from them."""
    if scene.bonds_inferred is not None:
        return scene.bonds, scene.bonds_inferred
    if scene.bonds or scene.bonds_declared:
        return scene.bonds, False
    return infer_bonds(scene, descriptions), True


def describe_bonds(scene: Scene, descriptions: Mapping[str, object]) -> list[str]:
    """Lines for ``cranefmu info``: each power bond the instability alarm and ECCO watch."""
    bonds, inferred = scene_bonds(scene, descriptions)
    how = "inferred from the connections' units (the scene declares none)" if inferred else "declared in the scene"
    lines = [f"  power bonds, {how}:" if bonds else f"  power bonds: none ({how})"]
    for name, (a, b) in bonds:
        lines.append(f"    {name}: {a['component']} force {a['force']} / velocity {a['velocity']} <-> "
                     f"{b['component']} force {b['force']} / velocity {b['velocity']}"
                     + (" (sign -1)" if b.get("sign") == "-1" else ""))
    return lines
