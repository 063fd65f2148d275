"""The one scene reader: an SSD and its .ssv parameter sets, parsed once into a :class:`Scene`.

Everything that uses a scene reads it here: the master (from an extracted .ssp), the monolithic
reference, the build and ``cranefmu info`` (from the source folder ``ssp/<scene>/``).  Every XML
file goes through the guarded parser of :mod:`.untrusted`.  What is read (SSP 1.0):

- elements (FMU components only; nested systems are refused), their connectors;
- connections, with their ``ssc:LinearTransformation`` (factor, offset);
- parameters, typed as in the .ssv (Real, Integer, Boolean, String, Enumeration); a Real's
  ``unit=`` is converted to SI (:mod:`cranefmu.adapter.units`) or refused; an Integer must be a whole
  number.  The System's bindings and every Component's own bindings (bare variable names, as
  libcosim reads them) form the default set; a parameter bound twice with two values is refused.
  Other .ssv files in ``resources/`` are named parameter sets;
- the DefaultExperiment, the power bonds (:mod:`.power_bonds`) and the stop conditions
  (:mod:`.stop_conditions`) from their annotations;
- the scene's stored run settings (``org.cranefmu.settings``: the attributes of one
  ``cf:Settings`` element, named as the fields of :class:`.settings.Settings`), typed and
  validated by :func:`.settings.stored_settings`; a ``cf:ParameterSet name="SET"`` element inside it
  holds the settings stored for that named parameter set, over the scene's when the set is chosen;

fmpy's ``read_ssd`` is not used: it extracts the archive a second time, parses without the guard
and reports problems as bare exceptions.  The SSP schema is checked on the built files by the
tests instead (tests/master/test_scene_reader.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Union

from .bond_declarations import ANNOTATION as BONDS_ANNOTATION, read_bonds
from ..errors import ParameterSetError, SceneError, SettingsError
from .settings import parse_bool, stored_settings
from ..adapter.units import parse as parse_unit
from .stop_conditions import read_stop_conditions
from .fmi_integer import fmi_integer
from .untrusted import check_xml_files, parse_xml, safe_extract

SSD_NS = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSV_NS = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
SSC_NS = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SETTINGS_ANNOTATION = "org.cranefmu.settings"
TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration")

Value = Union[float, int, bool, str]


@dataclass(frozen=True)
class Connector:
    name: str
    kind: str        # input, output, parameter, ...
    type: str = ""   # Real, Integer, ... (empty: not given)
    unit: str = ""


@dataclass(frozen=True)
class ComponentSpec:
    name: str
    fmu: Path        # the FMU file (in an extracted .ssp: resolved from ``source``)
    source: str = ""  # as written in the SSD, e.g. "resources/Rope.fmu"
    connectors: list[Connector] = field(default_factory=list)


@dataclass(frozen=True)
class ConnectionSpec:
    src: str
    src_var: str
    dst: str
    dst_var: str
    factor: float = 1.0
    offset: float = 0.0
    transformed: bool = False   # the SSD gives a LinearTransformation (also an identity one): no unit conversion

    def __str__(self) -> str:
        return f"{self.src}.{self.src_var} -> {self.dst}.{self.dst_var}"


@dataclass(frozen=True)
class Parameter:
    """One parameter value: ``name`` "component.variable", ``value`` in SI (a Real's .ssv unit applied)."""

    name: str
    type: str
    value: Value
    unit: str = ""   # as written in the .ssv ("" if none)


@dataclass(frozen=True)
class Scene:
    """A scene as read (frozen: a run, a reference solve and ``info`` see the same one; change a copy
    with :func:`dataclasses.replace`)."""

    name: str
    path: Path
    components: list[ComponentSpec]
    connections: list[ConnectionSpec]
    bound: dict[str, Parameter] = field(default_factory=dict)              # the default set
    sets: dict[str, dict[str, Parameter]] = field(default_factory=dict)   # named sets (over the default)
    start_time: float | None = None
    stop_time: float | None = None
    bonds: list[tuple[str, list[dict]]] = field(default_factory=list)
    stop_conditions: dict[str, str] = field(default_factory=dict)
    settings: dict[str, object] = field(default_factory=dict)   # stored run settings (name -> typed value)
    bonds_declared: bool = False   # the SSD has a power-bond annotation (an empty one: no bonds, none inferred)
    set_settings: dict[str, dict[str, object]] = field(default_factory=dict)   # a named set's own stored settings
    # whether ``bonds`` were inferred from the FMUs' units: decided once the FMUs were read
    # (:func:`.extracted.extracted_scene`); None before (a scene read from its SSD alone)
    bonds_inferred: bool | None = None
    # the largest stable plain-Jacobi step per set the file carries (:mod:`.host_steps`; {}: none)
    host_steps: dict[str, dict] = field(default_factory=dict)

    @property
    def parameters(self) -> dict[str, Value]:
        """"component.variable" -> value of the default set."""
        return {k: p.value for k, p in self.bound.items()}

    @property
    def parameter_sets(self) -> dict[str, dict[str, Value]]:
        return {name: {k: p.value for k, p in ps.items()} for name, ps in self.sets.items()}

    @property
    def input_sources(self) -> dict[str, str]:
        """"component.variable" of every connected input -> "component.variable" of its source."""
        return {f"{c.dst}.{c.dst_var}": f"{c.src}.{c.src_var}" for c in self.connections}

    @property
    def driven_inputs(self) -> set[str]:
        """"component.variable" of every connected input: a set's value for one is the settled start
        the build writes for hosts that do not settle a scene (cranefmu.settled_start), not a parameter."""
        return set(self.input_sources)

    def model_values(self, parameter_set: str | None = None) -> dict[str, Value]:
        """:meth:`values` without the settled start of connected inputs: the parameters a model takes
        (our initialization derives the start, so a run never depends on those values)."""
        driven = self.driven_inputs
        return {k: v for k, v in self.values(parameter_set).items() if k not in driven}

    def values(self, parameter_set: str | None = None) -> dict[str, Value]:
        """The default set with the named set over it."""
        out = self.parameters
        if parameter_set not in (None, "default"):
            if parameter_set not in self.sets:
                raise ParameterSetError(f"parameter set {parameter_set!r} is not in scene {self.name}: one of "
                                        f"{', '.join(['default', *self.sets])}")
            out.update(self.parameter_sets[parameter_set])
        return out


def typed_value(text: str, kind: str, where: str, unit: str = "") -> Value:
    """``text`` as a value of SSP type ``kind`` (a Real times its unit's factor to SI); raises
    :class:`ParameterSetError` naming ``where``, the value and what is allowed."""
    if kind not in TYPES:
        raise ParameterSetError(f"{where}: type {kind!r} is not allowed: one of {', '.join(TYPES)}")
    factor = 1.0
    if unit:
        try:
            factor = parse_unit(unit)[0]
        except ValueError as err:
            raise ParameterSetError(f"{where} = {text!r} {unit}: {err}") from None
    try:
        if kind == "Real":
            value = float(text) * factor
            if not math.isfinite(value):
                raise ValueError
            return value
        if kind == "Integer":
            return fmi_integer(text, where)   # 32 bits, quoted as given (the variable's range: at the FMU)
        if kind == "Boolean":
            return parse_bool(text)
        return str(text)
    except (ValueError, KeyError, TypeError):
        allowed = {"Real": "a finite number", "Integer": "a whole number", "Boolean": "true or false"}[kind]
        raise ParameterSetError(f"{where} = {text!r} is not a valid {kind} value: allowed {allowed}") from None


def _local(el) -> str:
    tag = el.tag
    return tag.rpartition("}")[2] if isinstance(tag, str) else ""


def _children(el, name: str) -> list:
    return [c for c in el if _local(c) == name]


def _first(el, name: str):
    found = _children(el, name)
    return found[0] if found else None


def read_parameter_set(root, label: str, prefix: str = "") -> dict[str, Parameter]:
    """The parameters of an ``ssv:ParameterSet`` element (``prefix`` + name, e.g. "rope." for a
    component's own binding with bare names)."""
    out: dict[str, Parameter] = {}
    params = _first(root, "Parameters")
    for p in _children(params, "Parameter") if params is not None else []:
        name = p.get("name")
        if not name:
            raise ParameterSetError(f"{label}: a Parameter has no name")
        typed = [c for c in p if _local(c) in TYPES]
        if len(typed) != 1:
            raise ParameterSetError(f"{label}: parameter {name!r} needs exactly one of {', '.join(TYPES)}")
        kind, text, unit = _local(typed[0]), typed[0].get("value"), typed[0].get("unit", "")
        if text is None:
            raise ParameterSetError(f"{label}: parameter {name!r} has no value")
        full = prefix + name
        out[full] = Parameter(full, kind, typed_value(text, kind, f"{label}: parameter {full}", unit), unit)
    return out


def _bindings(element, label: str, resources: Path, prefix: str, copies: dict | None = None) -> dict[str, Parameter]:
    """The parameters bound on a System or Component: ``source=`` .ssv files and inline sets.  An inline
    set named after one of the scene's named sets (a key of ``copies``) is not bound: it is that set's
    copy for hosts that choose a set among a component's bindings (ecos; the build writes them),
    collected into ``copies[name]`` and checked against the set by :func:`read_ssd`."""
    out: dict[str, Parameter] = {}
    holder = _first(element, "ParameterBindings")
    for binding in _children(holder, "ParameterBinding") if holder is not None else []:
        if binding.get("prefix"):
            raise SceneError(f"{label}: ParameterBinding prefix={binding.get('prefix')!r} is not supported "
                             "(libcosim ignores it): use full names")
        source = binding.get("source")
        if source:
            path = resources / Path(source).name
            if not path.is_file():
                raise SceneError(f"{label}: ParameterBinding source {source!r} is not in the scene")
            sets = [parse_xml(path)]
            where = f"{label}: {source}"
        else:
            values = _first(binding, "ParameterValues")
            sets = _children(values, "ParameterSet") if values is not None else []
            where = f"{label}: inline parameters"
        for ps in sets:
            if copies is not None and not source and ps.get("name") in copies:
                copies[ps.get("name")].update(read_parameter_set(ps, where, prefix))
                continue
            _merge(out, read_parameter_set(ps, where, prefix), where)
    return out


def _check_copies(copies: dict[str, dict[str, Parameter]], bound: dict[str, Parameter],
                  sets: dict[str, dict[str, Parameter]], label: str) -> None:
    """Each component's copy of a named set must give the set's values (the default set with the set over it)."""
    for name, copy in copies.items():
        whole = {**bound, **sets[name]}
        for key, p in copy.items():
            if key not in whole or whole[key].value != p.value:
                given = whole[key].value if key in whole else "nothing"
                raise ParameterSetError(f"{label}: the component binding of parameter set {name!r} gives {key} = "
                                        f"{p.value!r}, but the set gives {given}: bind each set's values once "
                                        "(or the same)")


def _merge(into: dict[str, Parameter], new: dict[str, Parameter], where: str) -> None:
    for key, p in new.items():
        old = into.get(key)
        if old is not None and old.value != p.value:
            raise ParameterSetError(f"{where}: parameter {key} = {p.value!r} contradicts {old.value!r} bound "
                                    "elsewhere in the scene: bind each parameter once (or with the same value)")
        into[key] = p


def _connectors(el) -> list[Connector]:
    holder = _first(el, "Connectors")
    out = []
    for c in _children(holder, "Connector") if holder is not None else []:
        typed = [t for t in c if _local(t) in TYPES]
        kind = _local(typed[0]) if typed else ""
        out.append(Connector(c.get("name", ""), c.get("kind", ""), kind, typed[0].get("unit", "") if typed else ""))
    return out


def _number(text: str | None, what: str, label: str) -> float | None:
    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        raise SceneError(f"{label}: {what}={text!r} is not a number") from None


def read_ssd(ssd: Path, resources: Path, fmu_dir: Path | None = None, label: str | None = None) -> Scene:
    """The scene of ``ssd``; its ``resources/…`` files are looked up in ``resources`` (the extracted
    archive's resources/ folder, or the scene's source folder).  A component's FMU is
    ``fmu_dir / <file name>`` (default: next to the resources)."""
    ssd = Path(ssd)
    label = label or ssd.name
    root = parse_xml(ssd)
    if _local(root) != "SystemStructureDescription":
        raise SceneError(f"{label}: the root element is {_local(root)!r}, not SystemStructureDescription")
    system = _first(root, "System")
    if system is None:
        raise SceneError(f"{label}: SystemStructure.ssd has no System")
    fmu_dir = fmu_dir or resources
    components: list[ComponentSpec] = []
    bound = _bindings(system, label, resources, "")
    bound_files = {Path(b.get("source")).name for b in system.iter("{*}ParameterBinding") if b.get("source")}
    set_files = [ssv for ssv in sorted(resources.glob("*.ssv")) if ssv.name not in bound_files]
    copies: dict[str, dict[str, Parameter]] = {ssv.stem: {} for ssv in set_files}
    elements = _first(system, "Elements")
    for el in [e for e in elements if _local(e)] if elements is not None else []:
        name = el.get("name", "")
        if _local(el) != "Component":
            raise SceneError(f"{label}: element {name!r} is not an FMU component (nested systems are not supported)")
        source = el.get("source")
        if not source:
            raise SceneError(f"{label}: component {name!r} has no source FMU")
        components.append(ComponentSpec(name, fmu_dir / Path(source).name, source, _connectors(el)))
        _merge(bound, _bindings(el, f"{label}: component {name!r}", resources, f"{name}.", copies),
               f"{label}: component {name!r}")
    names = {c.name for c in components}
    connections = []
    holder = _first(system, "Connections")
    for c in _children(holder, "Connection") if holder is not None else []:
        attributes = ("startElement", "startConnector", "endElement", "endConnector")
        ends = tuple(c.get(a) for a in attributes)
        text = f"{ends[0]}.{ends[1]} -> {ends[2]}.{ends[3]}"
        missing = [a for a, value in zip(attributes, ends) if not value]
        if missing:
            raise SceneError(f"{label}: connection {text.replace('None', '?')} has no {' and no '.join(missing)} "
                             f"attribute: cranefmu needs all of {', '.join(attributes)} (no connection to the "
                             "system's own connectors)")
        for role, comp in (("start", ends[0]), ("end", ends[2])):
            if comp not in names:
                raise SceneError(f"{label}: connection {text}: {role} element {comp!r} is not a component "
                                 f"(components: {', '.join(sorted(names))})")
        factor, offset, transformed = 1.0, 0.0, False
        for lt in c.iter("{*}LinearTransformation"):
            factor = _number(lt.get("factor", "1"), f"connection {text}: LinearTransformation factor", label)
            offset = _number(lt.get("offset", "0"), f"connection {text}: LinearTransformation offset", label)
            transformed = True
        connections.append(ConnectionSpec(*ends, factor, offset, transformed))

    start = stop = None
    for de in _children(root, "DefaultExperiment"):
        start = _number(de.get("startTime"), "DefaultExperiment startTime", label)
        stop = _number(de.get("stopTime"), "DefaultExperiment stopTime", label)
    sets = {ssv.stem: read_parameter_set(parse_xml(ssv), f"{label}: parameter set {ssv.name}") for ssv in set_files}
    _check_copies(copies, bound, sets, label)
    name = root.get("name") or system.get("name") or ssd.parent.name
    declared = any(ann.get("type") == BONDS_ANNOTATION for ann in system.iter("{*}Annotation"))
    settings, set_settings = read_settings(system, label, stop, set(sets))
    from .host_steps import read as read_host_steps

    return Scene(name, ssd, components, connections, bound, sets, start, stop, read_bonds(system, label),
                 read_stop_conditions(system, label), settings, declared, set_settings,
                 host_steps=read_host_steps(system))


def read_settings(system, label: str, stop_time: float | None,
                  sets: set[str] = frozenset()) -> tuple[dict[str, object], dict[str, dict[str, object]]]:
    """The run settings a scene stores (``org.cranefmu.settings`` annotation of the System; empty if
    absent): what ``cranefmu run SCENE`` uses for every setting not given; and per named parameter set
    (of ``sets``) those it stores over them.  A bad one is a :class:`SceneError` naming the scene, the
    setting, its value and what is allowed."""
    found = [el for ann in system.iter("{*}Annotation") if ann.get("type") == SETTINGS_ANNOTATION
             for el in ann if _local(el) == "Settings"]
    if len(found) > 1:
        raise SceneError(f"{label}: {len(found)} stored settings ({SETTINGS_ANNOTATION}): give one cf:Settings")
    if not found:
        return {}, {}

    def attributes(el) -> dict[str, str]:
        return {str(k).rpartition("}")[2]: v for k, v in el.attrib.items()}

    try:
        settings = stored_settings(attributes(found[0]), stop_time)
    except SettingsError as err:
        raise SceneError(f"{label}: stored run settings ({SETTINGS_ANNOTATION}): {err}") from None
    per_set = {}
    for el in found[0]:
        if _local(el) != "ParameterSet":
            continue
        own = attributes(el)
        name = own.pop("name", "")
        if name not in sets:
            raise SceneError(f"{label}: stored run settings ({SETTINGS_ANNOTATION}): parameter set {name!r} is not "
                             f"a parameter set of the scene: one of {', '.join(sorted(sets)) or '(none)'}")
        try:
            merged = stored_settings({**attributes(found[0]), **own}, stop_time)
        except SettingsError as err:
            raise SceneError(f"{label}: stored run settings of parameter set {name} ({SETTINGS_ANNOTATION}): "
                             f"{err}") from None
        per_set[name] = {k: merged[k] for k in own}
    return settings, per_set


def load_scene(ssp: Path, workdir: Path) -> Scene:
    """Extract ``ssp`` safely into ``workdir`` and read it; every FMU it names must be in the archive."""
    ssp = Path(ssp)
    if not ssp.is_file():
        raise SceneError(f"scene file {ssp} does not exist")
    safe_extract(ssp, workdir)
    check_xml_files(workdir, ssp.name)
    ssd = workdir / "SystemStructure.ssd"
    if not ssd.is_file():
        raise SceneError(f"{ssp.name}: cannot read SystemStructure.ssd: not in the archive")
    scene = read_ssd(ssd, workdir / "resources", label=ssp.name)
    components = [replace(c, fmu=(workdir / c.source).resolve()) for c in scene.components]
    for c in components:
        if not c.fmu.is_file():
            raise SceneError(f"{ssp.name}: component {c.name!r} refers to {c.source}, which is not in the archive")
    return replace(scene, components=components, path=ssp,
                   name=ssp.stem if scene.name == "SystemStructure" else scene.name)


def read_scene_folder(folder: Path, fmu_dir: Path) -> Scene:
    """A scene's sources: ``folder``/SystemStructure.ssd with its .ssv files next to it (the
    SSD's ``resources/x.ssv`` is ``folder/x.ssv``), FMUs in ``fmu_dir``."""
    folder = Path(folder)
    ssd = folder / "SystemStructure.ssd"
    if not ssd.is_file():
        raise SceneError(f"scene folder {folder} has no SystemStructure.ssd")
    check_xml_files(folder, folder.name)
    return read_ssd(ssd, folder, fmu_dir, label=f"{folder.name}/SystemStructure.ssd")


def model_description(fmu: Path):
    """fmpy's model description of the FMU file ``fmu``, its XML passed through the guard of
    :mod:`.untrusted` first (no DTD, no entities reach lxml); a :class:`SceneError` naming the file."""
    import zipfile

    from fmpy import read_model_description

    from .untrusted import check_xml

    fmu = Path(fmu)
    try:
        with zipfile.ZipFile(fmu) as zf:
            data = zf.read("modelDescription.xml")
    except (OSError, KeyError, zipfile.BadZipFile) as err:
        raise SceneError(f"{fmu.name}: cannot read modelDescription.xml: {err}") from None
    check_xml(data, f"{fmu.name}/modelDescription.xml")
    return read_model_description(str(fmu), validate=False)


def output_units(scene: Scene) -> dict[str, str]:
    """Unit of each result column ``component.variable`` that has one, from the FMUs' modelDescription
    (the variable's own unit, else its declared type's)."""
    units = {}
    for c in scene.components:
        for v in model_description(c.fmu).modelVariables:
            unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
            if unit:
                units[f"{c.name}.{v.name}"] = unit
    return units
