"""Read a scene: an .ssp archive (SSD + SSV parameter sets + FMUs), safely extracted."""
from __future__ import annotations

import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ParameterSetError, SceneError
from .xml_guard import check_xml_files, parse_xml


@dataclass
class ComponentSpec:
    name: str
    fmu: Path  # extracted .fmu file


@dataclass(frozen=True)
class ConnectionSpec:
    src: str
    src_var: str
    dst: str
    dst_var: str
    factor: float = 1.0
    offset: float = 0.0

    def __str__(self) -> str:
        return f"{self.src}.{self.src_var} -> {self.dst}.{self.dst_var}"


@dataclass
class Scene:
    name: str
    path: Path
    components: list[ComponentSpec]
    connections: list[ConnectionSpec]
    parameters: dict[str, str]  # the parameter set bound in the SSD: "comp.var" -> value text
    parameter_sets: dict[str, dict[str, str]] = field(default_factory=dict)  # other .ssv in resources/
    stop_time: float | None = None


def safe_extract(archive: Path, target: Path) -> None:
    """Extract a zip, refusing members that would land outside ``target`` (absolute, ``..``, links)."""
    target = target.resolve()
    with zipfile.ZipFile(archive) as zf:
        for info in zf.infolist():
            dest = (target / info.filename).resolve()
            if dest != target and target not in dest.parents:
                raise SceneError(f"{archive.name}: entry {info.filename!r} would be extracted outside "
                                 f"{target}; refusing the archive")
            if (info.external_attr >> 16) & 0o170000 == 0o120000:
                raise SceneError(f"{archive.name}: entry {info.filename!r} is a symbolic link; refusing the archive")
        zf.extractall(target)


def _parameter_dict(parameter_set) -> dict[str, str]:
    return {p.name: p.value for p in parameter_set.parameters}


def linear_transformations(ssd: Path) -> dict[tuple[str, str, str, str], tuple[float, float]]:
    """(start element, start connector, end element, end connector) -> (factor, offset) of each
    connection's ``LinearTransformation``.  Read here because fmpy 0.3 looks for it in the ssd
    namespace, while the SSP schema (which fmpy validates against) puts it in ssc."""
    root = parse_xml(ssd)
    out = {}
    for conn in root.iter("{*}Connection"):
        for lt in conn.iter("{*}LinearTransformation"):
            key = (conn.get("startElement"), conn.get("startConnector"), conn.get("endElement"), conn.get("endConnector"))
            try:
                out[key] = (float(lt.get("factor", 1.0)), float(lt.get("offset", 0.0)))
            except ValueError:
                raise SceneError(f"{ssd.name}: connection {key[0]}.{key[1]} -> {key[2]}.{key[3]}: LinearTransformation "
                                 f"factor={lt.get('factor')!r} offset={lt.get('offset')!r} are not numbers") from None
    return out


def load_scene(ssp: Path, workdir: Path) -> Scene:
    """Extract ``ssp`` into ``workdir`` and read its structure with fmpy's SSD reader."""
    from fmpy.ssp.ssd import Component, read_ssd, read_ssv

    ssp = Path(ssp)
    if not ssp.is_file():
        raise SceneError(f"scene file {ssp} does not exist")
    try:
        safe_extract(ssp, workdir)
        check_xml_files(workdir, ssp.name)  # no DTD/entities before fmpy's parser sees them
        ssd = read_ssd(str(ssp))
    except SceneError:
        raise
    except Exception as err:  # fmpy raises bare Exceptions for schema problems
        raise SceneError(f"{ssp.name}: cannot read SystemStructure.ssd: {err}") from None
    system = ssd.system
    components = []
    for el in system.elements:
        if not isinstance(el, Component):
            raise SceneError(f"{ssp.name}: element {el.name!r} is not an FMU component (nested systems are "
                             "not supported)")
        if not el.source:
            raise SceneError(f"{ssp.name}: component {el.name!r} has no source FMU")
        fmu = (workdir / el.source).resolve()
        if not fmu.is_file():
            raise SceneError(f"{ssp.name}: component {el.name!r} refers to {el.source}, which is not in the archive")
        components.append(ComponentSpec(el.name, fmu))
    names = {c.name for c in components}
    connections = []
    transforms = linear_transformations(workdir / "SystemStructure.ssd")
    for c in system.connections:
        for role, comp in (("start", c.startElement), ("end", c.endElement)):
            if comp not in names:
                raise SceneError(f"{ssp.name}: connection {c.startElement}.{c.startConnector} -> "
                                 f"{c.endElement}.{c.endConnector}: {role} element {comp!r} is not a component "
                                 f"(components: {', '.join(sorted(names))})")
        factor, offset = transforms.get((c.startElement, c.startConnector, c.endElement, c.endConnector), (1.0, 0.0))
        connections.append(ConnectionSpec(c.startElement, c.startConnector, c.endElement, c.endConnector,
                                          factor, offset))
    bound: dict[str, str] = {}
    for binding in system.parameterBindings:
        for pset in binding.parameterValues:
            bound.update(_parameter_dict(pset))
    bound_sources = {b.source for b in system.parameterBindings if b.source}
    sets = {}
    for ssv in sorted((workdir / "resources").glob("*.ssv")):
        if f"resources/{ssv.name}" in bound_sources:
            continue
        try:
            sets[ssv.stem] = _parameter_dict(read_ssv(str(ssv)))
        except Exception as err:
            raise ParameterSetError(f"{ssp.name}: parameter set {ssv.name} cannot be read: {err}") from None
    stop = default_stop_time(workdir / "SystemStructure.ssd")
    return Scene(ssd.name or ssp.stem, ssp, components, connections, bound, sets, stop)


def default_stop_time(ssd: Path) -> float | None:
    """stopTime [s] of the SSD's DefaultExperiment (read here: fmpy 0.3's SSD reader leaves
    ``defaultExperiment`` empty), or None."""
    root = parse_xml(ssd)
    for de in root.iter("{*}DefaultExperiment"):
        text = de.get("stopTime")
        if text is None:
            return None
        try:
            stop = float(text)
        except ValueError:
            raise SceneError(f"{ssd.name}: DefaultExperiment stopTime={text!r} is not a number") from None
        return stop
    return None


def output_units(scene: Scene) -> dict[str, str]:
    """Unit of each result column ``component.variable`` that has one, from the FMUs' modelDescription
    (the variable's own unit, else its declared type's)."""
    from fmpy import read_model_description

    units = {}
    for c in scene.components:
        for v in read_model_description(str(c.fmu), validate=False).modelVariables:
            unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
            if unit:
                units[f"{c.name}.{v.name}"] = unit
    return units
