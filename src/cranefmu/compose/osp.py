"""Our ports in the Open Simulation Platform's form: ``<Model>_OspModelDescription.xml`` (OSP-IS),
and a composed scene as an ``OspSystemStructure.xml`` that joins whole ports as variable groups.

libcosim looks for ``<modelName>_OspModelDescription.xml`` beside the FMU file, then beside the
OspSystemStructure.xml (osp_config_parser.cpp), and connects two variable groups named in a
``VariableGroupConnection`` variable by variable, in the groups' order.  Each port becomes a
``LinearMechanicalPort`` (Force + LinearVelocity) or ``AngularMechanicalPort`` (Torque +
AngularVelocity) where it has force and velocity, its position a ``LinearDisplacement`` /
``AngularDisplacement`` group of its own (``<port>.position``); a port without that pair lists its
parts as single groups.  Group names are unique in the file: libcosim looks nested groups up by name.
"""
from __future__ import annotations

from .interface import PARTS, Interface

OSS_NS = "http://opensimulationplatform.com/MSMI/OSPSystemStructure"

OSP_NS = "https://open-simulation-platform.com/OspModelDescription/1.0.0"
# OSP-IS names of a port and its parts, by kind
_GROUPS = {"linear": ("LinearMechanicalPort", {"force": "Force", "velocity": "LinearVelocity",
                                               "position": "LinearDisplacement"}),
           "angular": ("AngularMechanicalPort", {"force": "Torque", "velocity": "AngularVelocity",
                                                 "position": "AngularDisplacement"})}


def osp_model_description(iface: Interface) -> bytes:
    """The OspModelDescription.xml of the FMU whose interface is ``iface`` (its ports as variable groups)."""
    from lxml import etree

    from ..adapter.units import parse as parse_unit

    root = etree.Element(f"{{{OSP_NS}}}OspModelDescription", nsmap={None: OSP_NS}, version="1.0")
    units = etree.SubElement(root, f"{{{OSP_NS}}}UnitDefinitions")
    groups = etree.SubElement(root, f"{{{OSP_NS}}}VariableGroups")
    used: set[str] = set()

    def group(parent, tag: str, name: str, variables: tuple[str, ...]):
        el = etree.SubElement(parent, f"{{{OSP_NS}}}{tag}", name=name)
        for v in variables:
            unit = iface.variables[v].unit
            etree.SubElement(el, f"{{{OSP_NS}}}Variable", ref=v, **({"unit": unit} if unit else {}))
            used.add(unit)
        return el

    for port in iface.ports.values():
        port_tag, part_tags = _GROUPS[port.kind]
        paired = bool(port.parts["force"] and port.parts["velocity"])
        if paired:
            holder = etree.SubElement(groups, f"{{{OSP_NS}}}{port_tag}", name=port.name)
            for part in ("force", "velocity"):
                group(holder, part_tags[part], f"{port.name}.{part}", port.parts[part])
        for part in ("position",) if paired else ("position", "velocity", "force"):
            if port.parts[part]:
                group(groups, part_tags[part], f"{port.name}.{part}", port.parts[part])
    for unit in sorted(u for u in used if u):
        factor, exponents = parse_unit(unit)
        base = {k: str(exponents.get(k, 0)) for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad")}
        etree.SubElement(etree.SubElement(units, f"{{{OSP_NS}}}Unit", name=unit), f"{{{OSP_NS}}}BaseUnit",
                         **base, factor=repr(factor), offset="0.0")
    etree.indent(root, space="  ")
    return etree.tostring(root.getroottree(), xml_declaration=True, encoding="utf-8")


def osp_file_name(iface: Interface) -> str:
    """Where libcosim looks beside the FMU: ``<modelName>_OspModelDescription.xml``."""
    return f"{iface.model_name}_OspModelDescription.xml"


def osp_system_structure(composed, parameters: dict, step_size: float) -> bytes:
    """The OspSystemStructure.xml of a :class:`~cranefmu.compose.Composed` scene: its FMUs (sources by
    file name, beside this file with their OSP model descriptions), ``parameters`` ("comp.var" ->
    :class:`~cranefmu.master.scene.Parameter`) as initial values, a fixed step ``step_size`` [s].
    A port line all of whose links were added becomes VariableGroupConnections (the mechanical port,
    then the position; a port without force and velocity part by part); every other link a
    VariableConnection, in the scene's order.  Give the settled start among ``parameters`` (every
    connected input's value at t = 0): libcosim's one initial exchange does not settle a scene
    (docs/interop.md), so without it a scene released from rest starts with a jolt."""
    from lxml import etree

    def el(parent, tag: str, **attrs):
        return etree.SubElement(parent, f"{{{OSS_NS}}}{tag}", **attrs)

    root = etree.Element(f"{{{OSS_NS}}}OspSystemStructure", nsmap={None: OSS_NS}, version="0.1")
    el(root, "StartTime").text = repr(float(composed.source.start_time))
    el(root, "BaseStepSize").text = repr(float(step_size))
    el(root, "Algorithm").text = "fixedStep"
    simulators = el(root, "Simulators")
    for c in composed.source.components:
        sim = el(simulators, "Simulator", name=c.name, source=composed.interfaces[c.name].fmu.name)
        values = el(sim, "InitialValues")
        for key, p in parameters.items():
            comp, _, var = key.partition(".")
            if comp == c.name:
                text = str(p.value).lower() if isinstance(p.value, bool) else repr(p.value) \
                    if isinstance(p.value, float) else str(p.value)
                el(el(values, "InitialValue", variable=var), p.type, value=text)
    connections = el(root, "Connections")
    starts = {pair.first: pair for pair in composed.expanded.pairs}
    covered: set[int] = set()
    for i, link in enumerate(composed.expanded.links):
        pair = starts.get(i)
        if pair is not None:
            covered |= set(range(i, i + pair.count))
            (ca, pa), (cb, pb) = pair.a, pair.b
            mechanical = all(p.parts[x] for p in (pa, pb) for x in ("force", "velocity"))
            groups = ([(pa.name, pb.name)] if mechanical else []) + \
                [(f"{pa.name}.{x}", f"{pb.name}.{x}") for x in PARTS
                 if pa.parts[x] and pb.parts[x] and not (mechanical and x != "position")]
            for ga, gb in groups:
                conn = el(connections, "VariableGroupConnection")
                el(conn, "VariableGroup", simulator=ca, name=ga)
                el(conn, "VariableGroup", simulator=cb, name=gb)
        if i not in covered:
            conn = el(connections, "VariableConnection")
            el(conn, "Variable", simulator=link.src, name=link.src_var)
            el(conn, "Variable", simulator=link.dst, name=link.dst_var)
    etree.indent(root, space="  ")
    return etree.tostring(root.getroottree(), xml_declaration=True, encoding="utf-8")
