"""What a scene can connect on one FMU: its variables (causality, type, unit), its mechanical ports
and its switches, read from the FMU's modelDescription.xml.

Ports are the ``org.cranefmu.ports`` VendorAnnotation our FMUs carry (declared in physics as
:class:`cranefmu.physics.component.Port`, written by :mod:`cranefmu.adapter.fmi_adapter`); a foreign FMU has
none and is connected by its variables.  Switches are the ``org.cranefmu.enumerations`` annotation
(a text switch is an Integer code in the FMU).
"""
from __future__ import annotations

import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import SceneError

PORTS_TOOL = "org.cranefmu.ports"               # as cranefmu.adapter.fmi_adapter writes them (it is bundled into
ENUMERATIONS_TOOL = "org.cranefmu.enumerations"  # each FMU; the composer does not import it)
PARTS = ("position", "velocity", "force")


@dataclass(frozen=True)
class Variable:
    name: str
    causality: str   # input, output, parameter, ...
    type: str        # Real, Integer, Boolean, String
    unit: str = ""


@dataclass(frozen=True)
class PortSpec:
    """A port as the FMU declares it: ``parts`` maps position/velocity/force to variable names."""

    name: str
    kind: str
    takes: str        # "motion" (gives force, or nothing) or "force" (gives motion)
    description: str
    parts: dict[str, tuple[str, ...]]
    sign: int = 1


@dataclass(frozen=True)
class Interface:
    fmu: Path
    model_name: str
    variables: dict[str, Variable]
    ports: dict[str, PortSpec] = field(default_factory=dict)
    switches: dict[str, tuple[str, ...]] = field(default_factory=dict)


def read_interface(fmu: Path) -> Interface:
    """The :class:`Interface` of the FMU file ``fmu`` (cached per file version)."""
    fmu = Path(fmu)
    try:
        key = (str(fmu.resolve()), fmu.stat().st_mtime_ns)
    except OSError:
        raise SceneError(f"FMU {fmu} does not exist") from None
    if key not in _CACHE:
        _CACHE[key] = _read(fmu)
    return _CACHE[key]


_CACHE: dict[tuple[str, int], Interface] = {}


def _read(fmu: Path) -> Interface:
    from ..master.untrusted import check_xml

    try:
        with zipfile.ZipFile(fmu) as zf:
            data = zf.read("modelDescription.xml")
    except (OSError, KeyError, zipfile.BadZipFile) as err:
        raise SceneError(f"{fmu.name}: cannot read modelDescription.xml: {err}") from None
    root = check_xml(data, f"{fmu.name}/modelDescription.xml")
    types = {t.get("name"): t for t in root.iter("SimpleType")}
    variables = {}
    for sv in root.iter("ScalarVariable"):
        typed = next((c for c in sv if c.tag in ("Real", "Integer", "Boolean", "String", "Enumeration")), None)
        if typed is None:
            continue
        unit = typed.get("unit") or ""
        declared = types.get(typed.get("declaredType", ""))
        if not unit and declared is not None and len(declared):
            unit = declared[0].get("unit") or ""
        variables[sv.get("name")] = Variable(sv.get("name"), sv.get("causality", "local"), typed.tag, unit)
    ports, switches = {}, {}
    for tool in root.iter("Tool"):
        if tool.get("name") == PORTS_TOOL:
            for p in tool.iter("Port"):
                parts = {part: tuple(p.get(part, "").split()) for part in PARTS}
                ports[p.get("name")] = PortSpec(p.get("name"), p.get("kind", "linear"), p.get("takes", "motion"),
                                                p.get("description", ""), parts, int(p.get("sign", "1")))
        elif tool.get("name") == ENUMERATIONS_TOOL:
            for v in tool.iter("Variable"):
                switches[v.get("name")] = tuple(i.get("name") for i in v.iter("Item"))
    return Interface(fmu, root.get("modelName", fmu.stem), variables, ports, switches)
