"""A composed scene written as SSP 1.0 SystemStructure.ssd, with our annotations (power bonds, stop
conditions, stored run settings) in the forms :mod:`cranefmu.master.scene` reads."""
from __future__ import annotations

from .expand import Expanded
from .interface import Interface
from .source import FILE, SceneSource

SSD_NS = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC_NS = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV_NS = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
HEADER = (f" generated from {FILE} by cranefmu.compose (docs/composition.md): edit {FILE}, not this file; "
          "`cranefmu build` writes it again ")


def ssd_bytes(src: SceneSource, interfaces: dict[str, Interface], expanded: Expanded) -> bytes:
    """The SSD of the scene ``src`` with its connections ``expanded``."""
    from lxml import etree

    root = etree.Element(_q("SystemStructureDescription"), nsmap={"ssd": SSD_NS, "ssc": SSC_NS}, version="1.0",
                         name=src.name)
    system = etree.SubElement(root, _q("System"), name=src.name)
    if src.description:
        system.set("description", src.description)
    _bindings(system, src, interfaces)
    _elements(system, src, interfaces, expanded)
    connections = etree.SubElement(system, _q("Connections"))
    for k in expanded.links:
        etree.SubElement(connections, _q("Connection"), startElement=k.src, startConnector=k.src_var,
                         endElement=k.dst, endConnector=k.dst_var)
    _annotations(system, src, expanded)
    experiment = etree.SubElement(root, _q("DefaultExperiment"), startTime=_number(src.start_time))
    if src.stop_time is not None:
        experiment.set("stopTime", _number(src.stop_time))
    etree.indent(root, space="  ")
    for connector in root.iter(_q("Connector")):   # one line each, as a person writes them
        connector.text = connector[0].tail = None
    body = etree.tostring(root, encoding="unicode")
    return f'<?xml version="1.0" encoding="UTF-8"?>\n<!--{HEADER}-->\n{body}\n'.encode()


def _q(tag: str, ns: str = SSD_NS) -> str:
    return f"{{{ns}}}{tag}"


def _number(value: float) -> str:
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def add_parameters(holder, parameters, bare: bool = False) -> None:
    """Append an ``ssv:Parameter`` per :class:`~cranefmu.master.scene.Parameter` to the ``ssv:Parameters``
    element ``holder`` (``bare``: the variable name without "component.", for a component binding)."""
    from lxml import etree

    from ..adapter.units import parse as parse_unit

    for p in parameters:
        entry = etree.SubElement(holder, f"{{{SSV_NS}}}Parameter", name=p.name.partition(".")[2] if bare else p.name)
        text = {bool: lambda v: str(v).lower(), float: repr}.get(type(p.value), str)(p.value)
        typed = etree.SubElement(entry, f"{{{SSV_NS}}}{p.type}", value=text)
        if p.unit and parse_unit(p.unit)[0] == 1.0:   # the value is in SI: keep only an SI unit
            typed.set("unit", p.unit)


def _bindings(system, src: SceneSource, interfaces: dict[str, Interface]) -> None:
    from lxml import etree

    inline = [p for c in src.components for p in _inline_parameters(src, c, interfaces[c.name])]
    if src.parameters is None and not inline:
        return
    holder = etree.SubElement(system, _q("ParameterBindings"))
    if src.parameters is not None:
        etree.SubElement(holder, _q("ParameterBinding"), source=f"resources/{src.parameters}")
    if inline:
        values = etree.SubElement(etree.SubElement(holder, _q("ParameterBinding")), _q("ParameterValues"))
        pset = etree.SubElement(values, _q("ParameterSet", SSV_NS), nsmap={"ssv": SSV_NS}, version="1.0",
                                name=f"{src.name} components")
        add_parameters(etree.SubElement(pset, _q("Parameters", SSV_NS)), inline)


def _inline_parameters(src: SceneSource, comp, iface: Interface) -> list:
    """The values a component's table gives (``mass = 1000.0``, a switch by name: ``dimension = 3``,
    ``payload = "rigid"``) as :class:`~cranefmu.master.scene.Parameter`, typed as the FMU's variables."""
    from ..master.scene import Parameter

    out = []
    for key, value in comp.values.items():
        var = iface.variables.get(key)
        if var is None or var.causality != "parameter":
            raise src.fail(key, f"component {comp.name} ({comp.fmu_file}): {key!r} is not a parameter of the FMU")
        names = iface.switches.get(key)
        if names is not None and isinstance(value, str):
            if value not in names:
                raise src.fail(key, f"{comp.name}.{key} = {value!r} is not allowed: one of {', '.join(names)}")
            value = names.index(value)
        kinds = {"Real": (int, float), "Integer": (int,), "Boolean": (bool,), "String": (str,)}[var.type]
        if not isinstance(value, kinds) or (isinstance(value, bool) and var.type != "Boolean"):
            raise src.fail(key, f"{comp.name}.{key} = {value!r} is not allowed: a {var.type} value")
        value = float(value) if var.type == "Real" else value
        out.append(Parameter(f"{comp.name}.{key}", var.type, value, var.unit if var.type == "Real" else ""))
    return out


def _elements(system, src: SceneSource, interfaces: dict[str, Interface], expanded: Expanded) -> None:
    from lxml import etree

    used: dict[str, set[str]] = {c.name: set() for c in src.components}
    for k in expanded.links:
        used[k.src].add(k.src_var)
        used[k.dst].add(k.dst_var)
    for text in src.expose:
        comp, _, var = text.partition(".")
        if comp not in interfaces or var not in interfaces[comp].variables:
            raise src.fail(text, f"expose {text!r}: no such component variable")
        used[comp].add(var)
    elements = etree.SubElement(system, _q("Elements"))
    for c in src.components:
        el = etree.SubElement(elements, _q("Component"), name=c.name, source=f"resources/{c.fmu_file}",
                              type="application/x-fmu-sharedlibrary")
        holder = etree.SubElement(el, _q("Connectors"))
        for var in interfaces[c.name].variables.values():   # in the FMU's order
            if var.name in used[c.name]:
                typed = etree.SubElement(etree.SubElement(holder, _q("Connector"), name=var.name, kind=var.causality),
                                         _q(var.type, SSC_NS))
                if var.unit and var.type == "Real":
                    typed.set("unit", var.unit)


def _annotations(system, src: SceneSource, expanded: Expanded) -> None:
    from lxml import etree

    if not (expanded.bonds or src.stop_when or src.settings or src.set_settings):
        return
    holder = etree.SubElement(system, _q("Annotations"))

    def annotation(kind: str, tag: str):
        ns = f"urn:{kind}"
        ann = etree.SubElement(holder, _q("Annotation", SSC_NS), type=kind)
        return etree.SubElement(ann, f"{{{ns}}}{tag}", nsmap={"cf": ns}), ns

    if expanded.bonds:
        bonds, ns = annotation("org.cranefmu.powerbonds", "PowerBonds")
        for b in expanded.bonds:
            el = etree.SubElement(bonds, f"{{{ns}}}Bond", name=b.name, description=b.description)
            for comp, port in b.sides:
                side = etree.SubElement(el, f"{{{ns}}}Side", component=comp, force=" ".join(port.parts["force"]),
                                        velocity=" ".join(port.parts["velocity"]))
                if port.sign != 1:
                    side.set("sign", str(port.sign))
    if src.stop_when:
        stop, ns = annotation("org.cranefmu.stopwhen", "StopWhen")
        for variable, reason in src.stop_when.items():
            etree.SubElement(stop, f"{{{ns}}}Output", variable=variable, reason=reason)
    if src.settings or src.set_settings:
        settings, ns = annotation("org.cranefmu.settings", "Settings")
        for key, value in src.settings.items():
            settings.set(key, setting_text(value))
        for name, table in src.set_settings.items():   # a parameter set's own, over the scene's when it is chosen
            one = etree.SubElement(settings, f"{{{ns}}}ParameterSet", name=name)
            for key, value in table.items():
                one.set(key, setting_text(value))


def setting_text(value) -> str:
    """A stored setting's TOML value as the SSD attribute's text (a list joined with commas)."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, list):
        return ",".join(str(v) for v in value)
    return str(value)
