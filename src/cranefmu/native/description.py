"""The native FMU's modelDescription.xml and its variable tables for the C layer, from the pythonfmu FMU's.

One source for both FMU kinds: the description starts as the pythonfmu adapter's own
:meth:`~cranefmu.adapter.fmi_adapter.CraneSlave.to_xml` of the same slave class (``fmus/<Name>.py``), so names,
value references, causality, variability, units, start values, descriptions, the enumerations and ports
annotations and the ModelStructure are the same by construction.  Only what differs is changed: the
generation tool, no execution tool needed, FMU state and its serialization, the C sources
(``<SourceFiles>``), a GUID of the content, and a description and vendor annotation saying native.

:func:`variables_header` writes ``cf_fmu_variables.h``, the tables the generic layer
(``fmi2/cf_fmi2.c``) reads: each parameter's kind, start, range or choices and the texts of
:func:`cranefmu.physics.params.check_value`'s messages; the inputs, rates and outputs.
"""
from __future__ import annotations

import hashlib
import importlib.util
import math
import re
import sys
import uuid
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, indent, tostring

from ..version import __version__
from ..adapter.fmi_adapter import EXTRAPOLATION_SUFFIXES, CraneSlave, solvers
from ..physics.params import allowed_text, enumeration_text

NATIVE_TOOL = "org.cranefmu.native"   # VendorAnnotations tool describing the native build
#: solvers of the pythonfmu FMU that the native layer does not offer (scipy's implicit adaptive methods)
NOT_NATIVE = ("radau", "bdf")
GENERATION_TOOL = f"cranefmu {__version__} native FMI 2.0 layer (C99, libm)"
NATIVE_NOTE = ("Native FMU: C99 and libm only, no Python in the host's process; its C sources are in "
               "sources/ (listed in SourceFiles)")


def slave_class(name: str, script: Path | None = None) -> type[CraneSlave]:
    """The pythonfmu slave class ``name`` of ``fmus/<name>.py`` (or of ``script``)."""
    if script is None:
        from ..sources import FMU_SOURCES

        script = FMU_SOURCES / f"{name}.py"
    if not script.is_file():
        raise FileNotFoundError(f"FMU script {script} not found: a native FMU is built from fmus/<Name>.py")
    module_name = f"_cranefmu_native_script_{name}"
    module = sys.modules.get(module_name)
    if module is None or getattr(module, "__file__", None) != str(script):
        spec = importlib.util.spec_from_file_location(module_name, script)
        module = importlib.util.module_from_spec(spec)
        sys.modules[module_name] = module
        spec.loader.exec_module(module)
    cls = getattr(module, name, None)
    if not (isinstance(cls, type) and issubclass(cls, CraneSlave)):
        raise TypeError(f"{script} defines no CraneSlave subclass named {name}")
    return cls


def slave_instance(cls: type[CraneSlave]) -> CraneSlave:
    """An instance of the slave as pythonfmu's builder makes one to write the description."""
    return cls(instance_name="description")


def pythonfmu_description(cls: type[CraneSlave]) -> Element:
    """The pythonfmu FMU's modelDescription (as ``cranefmu build`` writes it, with the FMU state options)."""
    return slave_instance(cls).to_xml(dict(canGetAndSetFMUstate=True, canSerializeFMUstate=True))


def native_description(cls: type[CraneSlave], source_files: list[str], digest: str) -> tuple[bytes, str]:
    """The native FMU's modelDescription.xml (bytes) and GUID, for C sources ``source_files`` (the .c
    files in ``sources/``) whose content hashes to ``digest``."""
    from ..adapter.fmi_adapter import PYTHON_HOST_TOOL, python_host_note

    root = pythonfmu_description(cls)
    root.set("generationTool", GENERATION_TOOL)
    note = python_host_note(cls.physics)
    description = root.get("description", "").replace(f" [{note}]", "").replace(f"[{note}]", "")
    for holder in root.iter("VendorAnnotations"):   # what a pythonfmu FMU's host needs: not this one's
        for tool in [t for t in holder if t.get("name") == PYTHON_HOST_TOOL]:
            holder.remove(tool)
    root.set("description", f"{description} [{NATIVE_NOTE}]" if description else NATIVE_NOTE)
    root.attrib.pop("generationDateAndTime", None)   # the build is reproducible: same sources, same FMU
    cs = root.find("CoSimulation")
    cs.set("needsExecutionTool", "false")
    cs.set("canGetAndSetFMUstate", "true")
    cs.set("canSerializeFMUstate", "true")
    cs.set("canBeInstantiatedOnlyOncePerProcess", "false")
    cs.set("canNotUseMemoryManagementFunctions", "true")
    files = SubElement(cs, "SourceFiles")
    for f in source_files:
        SubElement(files, "File", name=f)
    annotations = root.find("VendorAnnotations")
    if annotations is None:
        annotations = Element("VendorAnnotations")
        root.insert(list(root).index(root.find("ModelVariables")), annotations)
    tool = SubElement(annotations, "Tool", name=NATIVE_TOOL)
    methods = solvers(cls.physics)
    SubElement(tool, "Native", language="C99", libraries="libm", sources="sources/",
               solvers=" ".join(m for m in methods if m not in NOT_NATIVE),
               description="built by cranefmu.native.build from the same tables as the pythonfmu FMU")
    root.set("guid", "")
    guid = "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, "cranefmu-native:" + hashlib.sha256(
        tostring(root) + digest.encode()).hexdigest())) + "}"
    root.set("guid", guid)
    indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="utf-8") + b"\n", guid


# --- the C tables --------------------------------------------------------------------------------

def _c_string(text: str | None) -> str:
    if text is None:
        return "NULL"
    out = []
    for byte in text.encode("utf-8"):
        ch = chr(byte)
        if ch in '"\\':
            out.append("\\" + ch)
        elif 32 <= byte < 127 and ch != "?":   # no '?' so that no trigraph forms
            out.append(ch)
        else:
            out.append(f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


def _c_double(value: float) -> str:
    value = float(value)
    if math.isnan(value):
        return "NAN"
    if math.isinf(value):
        return "HUGE_VAL" if value > 0 else "(-HUGE_VAL)"
    return repr(value)


def _param_spec(inst: CraneSlave, name: str, xml_type: str, component: str) -> str:
    meta = inst._param_meta[name]
    kind, codes, choices = "CF_REAL", None, ()
    if name in inst._switches:
        kind, codes = "CF_SWITCH", enumeration_text(inst._switches[name])
    elif xml_type == "Integer" and meta.get("choices"):
        kind, choices = "CF_INT_CHOICE", tuple(meta["choices"])
    elif xml_type == "Integer":
        kind = "CF_INTEGER"
    elif xml_type != "Real":
        raise TypeError(f"{type(inst).__name__}.{name}: a {xml_type} parameter has no native form")
    n_choices = len(inst._switches[name]) if kind == "CF_SWITCH" else len(choices)
    # rtol and max_step name the instance in their messages, the model's fields its component
    owner = None if name in ("rtol", "max_step") else component
    lo, hi = meta.get("min"), meta.get("max")
    choice_array = f"cf_choices_{name}" if choices else "NULL"
    return (f"    {{{_c_string(name)}, {_c_string(owner)}, {kind}, {_c_double(getattr(inst, name))}, "
            f"{int(bool(meta.get('tunable')))}, {int(lo is not None)}, {int(bool(meta.get('min_open')))}, "
            f"{int(hi is not None)}, {int(bool(meta.get('max_open')))}, {_c_double(0 if lo is None else lo)}, "
            f"{_c_double(0 if hi is None else hi)}, {_c_string(allowed_text(meta))}, {_c_string(codes)}, "
            f"{n_choices}, {choice_array}}}")


_PREPARE_EXACT_STEP = re.compile(r"^\s*int\s+cf_prepare_exact_step\s*\(", re.M)


def defines_prepare_exact_step(model_source: str) -> bool:
    """True when a C model's source defines the optional ``cf_prepare_exact_step`` (include/cf_model.h)."""
    return any(_PREPARE_EXACT_STEP.match(line) and not line.rstrip().endswith(";")
               for line in model_source.splitlines())


def variables_header(cls: type[CraneSlave], name: str, guid: str, description: Element | None = None,
                     model_source: str = "") -> str:
    """``cf_fmu_variables.h`` for slave ``cls`` (FMU ``name``, C model text ``model_source``): the layer's
    tables, checked against the value references of the pythonfmu description (``description``, made if
    not given)."""
    inst = slave_instance(cls)
    root = description if description is not None else pythonfmu_description(cls)
    physics = cls.physics
    component = physics.Params.component
    inputs = [s.name for s in physics.inputs]
    coupling = [i for i, s in enumerate(physics.inputs) if s.coupling]
    rates = [inputs[i] + x for i in coupling for x in EXTRAPOLATION_SUFFIXES]
    outputs = [s.name for s in physics.outputs]
    expected = list(inst._param_names) + inputs + rates + outputs
    found, types = [], {}
    for sv in root.find("ModelVariables"):
        found.append((sv.get("name"), int(sv.get("valueReference"))))
        types[sv.get("name")] = sv[0].tag
    if found != [(n, vr) for vr, n in enumerate(expected)]:
        raise ValueError(f"{name}: the pythonfmu variables are not in the layer's order (parameters, inputs, "
                         f"rates, outputs with value references 0, 1, ...): {found}")
    methods = solvers(physics)
    native = ", ".join(f"{code} = {m}" for code, m in enumerate(methods) if m not in NOT_NATIVE)
    lines = [f"/* generated by cranefmu.native.description from {cls.__module__}.{cls.__name__} "
             f"({physics.__module__}.{physics.__name__}): do not edit */",
             "#ifndef CF_FMU_VARIABLES_H", "#define CF_FMU_VARIABLES_H", "", "#include <math.h>", "",
             '#include "cf_fmi2.h"', f'#include "{name}_tables.h"', "",
             f"#define CF_MODEL_IDENTIFIER {_c_string(name)}", f"#define CF_GUID {_c_string(guid)}",
             f"#define CF_COMPONENT {_c_string(component)}", f"#define CF_N_PARAM_VARS {len(inst._param_names)}",
             f"#define CF_N_COUPLING {len(coupling)}", f"#define CF_NATIVE_SOLVERS {_c_string(native)}",
             f"#define CF_HAS_PREPARE_EXACT_STEP {int(defines_prepare_exact_step(model_source))}", "",
             f"#if N_PARAMS + 3 != CF_N_PARAM_VARS || N_INPUTS != {len(inputs)} || N_OUTPUTS != {len(outputs)}",
             f'#error "{name}_tables.h does not match the FMU\'s variables: regenerate both"', "#endif", "",
             "static const char *const cf_solver_names[] = {" + ", ".join(_c_string(m) for m in methods) + "};"]
    for pname in inst._param_names:
        meta = inst._param_meta[pname]
        if types[pname] == "Integer" and meta.get("choices") and pname not in inst._switches:
            lines.append(f"static const double cf_choices_{pname}[] = {{"
                         + ", ".join(_c_double(c) for c in meta["choices"]) + "};")
    lines.append("static const CfParamSpec cf_param_specs[CF_N_PARAM_VARS] = {")
    lines.append(",\n".join(_param_spec(inst, p, types[p], component) for p in inst._param_names))
    lines.append("};")
    lines.append("static const char *const cf_input_names[] = {" + ", ".join(map(_c_string, inputs + [""])) + "};")
    lines.append("static const double cf_input_start[] = {"
                 + ", ".join(_c_double(s.start) for s in physics.inputs) + (", " if inputs else "") + "0.0};")
    lines.append("static const int cf_coupling[] = {" + ", ".join(map(str, coupling + [-1])) + "};")
    lines.append("static const char *const cf_rate_names[] = {" + ", ".join(map(_c_string, rates + [""])) + "};")
    lines.append("static const char *const cf_output_names[] = {" + ", ".join(map(_c_string, outputs + [""])) + "};")
    lines.append("static const int cf_output_discrete[] = {"
                 + ", ".join(str(int(s.discrete)) for s in physics.outputs) + (", " if outputs else "") + "0};")
    lines += ["", "#endif", ""]
    return "\n".join(lines)
