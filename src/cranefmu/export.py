"""One variant of a scene (a parameter set, ``--set`` changes) as a self-contained .ssp.

Hosts that cannot choose a parameter set (libcosim reads only the SSD's bindings; ecos applies the bound
set; fmpy's ``simulate_ssp`` applies what it is handed) get the variant as the scene's only set: its
values over the default set, bound by the System (``resources/default.ssv``) and by each Component
(inline, bare names, ``ssd:``/``ssv:`` prefixes: what libcosim reads), with the settled start of the
parameters in force (:mod:`cranefmu.settled_start`), so the host starts at rest as loaded.
"""
from __future__ import annotations

import tempfile
from pathlib import Path

from .errors import CraneFmuError, ParameterSetError, SceneError
from .master.scene import Parameter, Scene, typed_value


def export_scene(scene: str, output: str | Path, parameter_set: str | None = None,
                 parameters: dict[str, object] | None = None, fmus: str | None = None) -> Path:
    """Write ``output`` (.ssp), see :func:`export_scene_kind`; returns the path written."""
    return export_scene_kind(scene, output, parameter_set, parameters, fmus)[0]


def export_scene_kind(scene: str, output: str | Path, parameter_set: str | None = None,
                      parameters: dict[str, object] | None = None,
                      fmus: str | None = None) -> tuple[Path, str | None]:
    """Write ``output`` (.ssp): ``scene`` with ``parameter_set`` and ``parameters`` ({"comp.var": value or
    text}) over its default set as its one bound set, with the settled start of those values, holding
    FMUs of kind ``fmus`` (native or python; None: native where built or buildable, see
    :mod:`cranefmu.fmu_kinds`; :func:`exported_kind` reads it back).
    Returns the path written and the kind its FMUs are (:func:`exported_kind`, read from the archive
    before it is copied: the target may be standard output, unreadable after).  Raises a :class:`CraneFmuError` naming a bad scene, set, value or target."""
    from . import build as b
    from .fmu_kinds import check_kind, native_fmu_dir, native_ssp_dir, scene_path
    from .experiments.scene_check import interface
    from .master.scene import read_scene_folder
    from .parameter_units import in_declared_units

    from . import whole_file

    whole_file.check(output, "--output", (".ssp",))   # before any work: a directory, a missing folder
    names = [d.name for d in b.scene_dirs()]
    if scene not in names:
        raise SceneError(f"scene {scene!r} is not allowed: one of {', '.join(names)}")
    check_kind(fmus)
    b.build(verbose=False, only=[scene])
    native = scene_path(scene, fmus).parent == native_ssp_dir()   # builds the native scene if it is chosen
    folder = b.SSP_DIR / scene
    loaded = read_scene_folder(folder, b.FMU_DIR)
    parameters = in_declared_units(parameters or {}, lambda: interface(scene, fmus).units or {})   # "45 deg" -> rad
    values = variant_values(loaded, parameter_set, parameters)
    bound = b._bound_files(folder)
    if len(bound) != 1:
        raise SceneError(f"scene {scene}: the System binds {len(bound)} .ssv files; export needs exactly one")
    label = parameter_set or "default"
    with tempfile.TemporaryDirectory(prefix="cranefmu_export_") as tmp:
        variant = Path(tmp) / scene
        variant.mkdir()
        (variant / "SystemStructure.ssd").write_bytes(variant_ssd(folder / "SystemStructure.ssd", parameter_set))
        (variant / bound.pop()).write_bytes(b.ssv_of(values, label))
        written = b.build_ssp(variant, dest=Path(tmp) / f"{scene}.ssp", fmu_dir=native_fmu_dir() if native else None,
                              host_steps=variant_host_steps(scene, parameter_set, parameters or {}))
        kind = exported_kind(written)
        return whole_file.copy(written, output, "--output"), kind   # beside the target, renamed: whole or nothing


def variant_host_steps(scene: str, parameter_set: str | None, parameters: dict) -> dict[str, dict]:
    """The measured plain-Jacobi step of the exported set, as the variant's own ("default"); none when
    ``parameters`` change it (a changed mass or stiffness moves the limit: not measured)."""
    from .host_steps import measured

    found = measured(scene).get(parameter_set or "default")
    return {"default": found} if found and not parameters else {}


def exported_kind(ssp: Path) -> str | None:
    """The kind of FMU an .ssp holds (native, python, None: neither or mixed), from its FMUs' generationTool."""
    import re
    import zipfile

    from .master.fmu_kind import kind_of_tool

    kinds = set()
    with zipfile.ZipFile(ssp) as zf:
        for name in (n for n in zf.namelist() if n.endswith(".fmu")):
            with zf.open(name) as inner, zipfile.ZipFile(inner) as fmu:
                found = re.search(rb'generationTool\s*=\s*"([^"]*)"', fmu.read("modelDescription.xml")[:8192])
                kinds.add(kind_of_tool(found.group(1).decode()) if found else None)
    return kinds.pop() if len(kinds) == 1 else None


def variant_ssd(ssd: Path, parameter_set: str | None) -> bytes:
    """The SSD of the variant: the run settings ``parameter_set`` stores (a ``cf:ParameterSet`` in the
    settings annotation) become the variant's own, and every set's are dropped (it has no named sets)."""
    from lxml import etree

    from .master.scene import SETTINGS_ANNOTATION
    from .master.untrusted import parse_xml

    root = parse_xml(ssd)
    per_set = [(settings, el) for ann in root.iter("{*}Annotation") if ann.get("type") == SETTINGS_ANNOTATION
               for settings in ann for el in settings if etree.QName(el).localname == "ParameterSet"]
    if not per_set:
        return ssd.read_bytes()
    for settings, el in per_set:
        if el.get("name") == parameter_set:
            for key, value in el.attrib.items():
                if key != "name":
                    settings.set(key, value)
        settings.remove(el)
    return etree.tostring(root.getroottree(), xml_declaration=True, encoding="UTF-8")


def variant_values(scene: Scene, parameter_set: str | None, parameters: dict[str, object]) -> dict[str, Parameter]:
    """The default set with ``parameter_set`` and then ``parameters`` over it, typed as the FMU
    declares each variable (a switch may be given by name).  A connected input, an unknown
    component or variable, or a value of the wrong type is refused by name."""
    from .master.fmu import fmu_switch_names

    scene.values(parameter_set)                       # an unknown set: refused with the scene's sets
    out = dict(scene.bound)
    out.update(scene.sets.get(parameter_set, {}) if parameter_set not in (None, "default") else {})
    driven = scene.input_sources
    components = {c.name: c for c in scene.components}
    from .derived import derive

    # with the parameters that follow a changed one, as a run resolves them (cranefmu.derived)
    parameters = derive(scene.name, scene.model_values(parameter_set), parameters)
    for key, value in parameters.items():
        comp, _, var = str(key).partition(".")
        if comp not in components or not var:
            raise ParameterSetError(f"parameter {key!r} must be 'component.variable' with a component of "
                                    f"{scene.name}: {', '.join(sorted(components))}")
        if key in driven:
            raise ParameterSetError(f"{key} is not allowed as a parameter: it is an input connected to "
                                    f"{driven[key]}; set a parameter of {driven[key].partition('.')[0]} instead")
        kind = _variable_type(components[comp].fmu, comp, var)
        switches = fmu_switch_names(components[comp].fmu).get(var, {})
        text = str(value).strip()
        if kind == "Integer" and text in switches:
            text = str(switches[text])
        try:
            typed = typed_value(text, kind, f"--set {key}")
        except CraneFmuError as err:
            allowed = f" (switch names: {', '.join(switches)})" if switches else ""
            raise ParameterSetError(f"{err}{allowed}") from None
        out[key] = Parameter(key, kind, typed)
    return out


def _variable_type(fmu: Path, comp: str, var: str) -> str:
    """The FMI type of ``var`` in ``fmu`` (Enumeration as Integer); refuses an unknown or fixed variable."""
    from fmpy import read_model_description

    found = {v.name: v for v in read_model_description(str(fmu)).modelVariables}
    v = found.get(var)
    if v is None:
        raise ParameterSetError(f"{comp}.{var} is not allowed: {fmu.name} has no variable {var!r}")
    if v.causality not in ("parameter", "input"):
        raise ParameterSetError(f"{comp}.{var} is a {v.causality} and cannot be set (only parameters and inputs)")
    return "Integer" if v.type == "Enumeration" else v.type
