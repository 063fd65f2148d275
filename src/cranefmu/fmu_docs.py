"""One Markdown page per FMU, generated from the built ``.fmu`` alone, so the page cannot drift.

Everything on the page is read from the archive: the model description (variables, causality,
units, start values, descriptions, default experiment, capabilities, platforms) and the physics
sources bundled into ``resources/`` (the model module's docstring: what it models, from which
paper and equation; the Python packages the FMU imports).  Nothing volatile is written (no GUID,
date or bundle hash), so rebuilding an unchanged FMU gives the same page.

    cranefmu docs [--output docs/fmus] [--check] [NAME...]
"""
from __future__ import annotations

import ast
import re
import sys
import zipfile
from pathlib import Path

DOCS_DIR = Path(__file__).resolve().parent.parent.parent / "docs" / "fmus"
_PHYSICS_IMPORT = re.compile(r"^from\s+(_cranefmu_\w+)\.physics\.(\w+)\s+import\s+(\w+)", re.M)


def _md_escape(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _bundle(zf: zipfile.ZipFile) -> tuple[str, str, str]:
    """(bundle package, physics module, model class) named by the FMU's script."""
    script = zf.read("resources/slavemodule.txt").decode().strip()
    text = zf.read(f"resources/{script}.py").decode()
    m = _PHYSICS_IMPORT.search(text)
    if m is None:
        raise ValueError(f"resources/{script}.py imports no cranefmu physics model")
    return m.group(1), m.group(2), m.group(3)


def _third_party_imports(zf: zipfile.ZipFile, package: str) -> list[str]:
    """Top-level packages the bundled sources import that are neither the standard library nor bundled."""
    names: set[str] = set()
    for entry in zf.namelist():
        if entry.startswith(f"resources/{package}/") and entry.endswith(".py"):
            tree = ast.parse(zf.read(entry))
            for node in ast.walk(tree):
                if isinstance(node, ast.Import):
                    names.update(a.name.split(".")[0] for a in node.names)
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    names.add(node.module.split(".")[0])
    bundled = {package, "pythonfmu"}
    return sorted(n for n in names if n not in sys.stdlib_module_names and n not in bundled)


def _python_host(zf: zipfile.ZipFile) -> dict[str, str]:
    """The attributes of the model description's PythonHost annotation (what a host needs), {} if none."""
    from xml.etree import ElementTree

    from .adapter.fmi_adapter import PYTHON_HOST_TOOL

    root = ElementTree.fromstring(zf.read("modelDescription.xml"))
    found = root.find(f"VendorAnnotations/Tool[@name='{PYTHON_HOST_TOOL}']/PythonHost")
    return dict(found.attrib) if found is not None else {}


def _needs(packages: list[str], host: dict[str, str]) -> str:
    """The packages a host's Python needs: the annotation's (required, scipy's condition, optional), else
    every third-party package the bundled sources import."""
    if not host:
        return "the packages " + (", ".join(f"`{p}`" for p in packages) or "(none)")
    required = ", ".join(f"`{p}`" for p in host.get("packages", "").split())
    scipy = host.get("scipy", "")
    scipy = "`scipy` at no setting" if scipy == "never" else f"`scipy` {scipy}" if scipy else ""
    optional = f"optionally {host['optional']}" if host.get("optional") else ""
    return f"the package {required}" + "".join(f"; {x}" for x in (scipy, optional) if x)


def _start(v) -> str:
    if v.start is None:
        return ""
    if v.type == "String":
        return f"`{v.start}`"
    return str(v.start)


def _allowed(description: str) -> str:
    m = re.search(r"\(allowed (.*)\)\s*$", description or "")
    return m.group(1) if m else ""


def _plain(description: str) -> str:
    return re.sub(r"\s*\(allowed .*\)\s*$", "", description or "") or (description or "")


def render(fmu: Path) -> str:
    """The Markdown page of one built FMU."""
    from fmpy import read_model_description

    from .master.fmu import ENUMERATIONS_TOOL, fmu_switch_names

    fmu = Path(fmu)
    md = read_model_description(str(fmu), validate=False)
    names = fmu_switch_names(fmu)
    with zipfile.ZipFile(fmu) as zf:
        package, module, model_class = _bundle(zf)
        source = zf.read(f"resources/{package}/physics/{module}.py").decode()
        packages = _third_party_imports(zf, package)
        host = _python_host(zf)
        platforms = sorted({Path(n).parent.name for n in zf.namelist()
                            if n.startswith("binaries/") and not n.endswith("/")})
    physics_doc = ast.get_docstring(ast.parse(source)) or ""
    name = md.modelName
    variables = md.modelVariables
    params = [v for v in variables if v.causality == "parameter"]
    switches = [v for v in params if v.type in ("String", "Integer")]
    inputs = [v for v in variables if v.causality == "input"]
    outputs = [v for v in variables if v.causality == "output"]
    # the adapter's extrapolation inputs of the coupling inputs (a model's own rate inputs, e.g. a commanded
    # motion's extension_command_dt, are inputs of their own)
    extrapolation = [v for v in inputs if v.name.endswith(("_dt", "_dt2"))
                     and "for input extrapolation" in (v.description or "")]
    coupling = [v for v in inputs if v not in extrapolation]
    feedthrough = {u.variable.name: [d.name for d in (u.dependencies or [])] for u in md.outputs}
    cs = md.coSimulation
    de = md.defaultExperiment

    out = [f"# {name} FMU", "",
           "<!-- generated by `cranefmu docs` from fmus/" + fmu.name + "; do not edit by hand -->", "",
           f"{md.description}", "",
           f"FMI {md.fmiVersion} co-simulation, model identifier `{cs.modelIdentifier}`, generated by "
           f"{md.generationTool}. Physics: `cranefmu.physics.{module}.{model_class}`.", "",
           "## What it models", "", "```text", physics_doc, "```", "",
           "## Fidelity switches and solvers", "",
           "Every FMU integrates its own states between communication points with the solver named by "
           "`solver`; `rtol` applies to the adaptive ones, `max_step` bounds the internal step (the sub-step "
           "of the fixed-step ones).", "",
           "Switches are Integer parameters: the value is the position of a name in the list below (tools "
           "without String parameters, such as libcosim and fmpy's `simulate_ssp`, set them as integers; "
           "libcosim ignores FMI Enumeration variables). The names are listed in the model description too "
           f"(`VendorAnnotations`, tool `{ENUMERATIONS_TOOL}`), so cranefmu's master, `--set` and `cranefmu info` "
           "take and show them: `--set rope.model=bouc_wen` and `--set rope.model=1` are the same.", "",
           "| parameter | default | allowed | what it selects |", "|---|---|---|---|"]
    for v in switches + [v for v in params if v.name in ("rtol", "max_step")]:
        default = _start(v)
        if v.name in names:
            default += " (" + ", ".join(f"`{n}`" for n, c in names[v.name].items() if str(c) == str(v.start)) + ")"
        out.append(f"| `{v.name}` | {default} | {_md_escape(_allowed(v.description))} | "
                   f"{_md_escape(_plain(v.description))} |")
    out += ["", "## Variables", ""]
    for title, group in (("Parameters", params), ("Inputs", coupling), ("Outputs", outputs)):
        out += [f"### {title}", "", "| name | causality | variability | type | unit | start | description |",
                "|---|---|---|---|---|---|---|"]
        for v in group:
            desc = v.description or ""
            if v.causality == "output" and feedthrough.get(v.name):
                desc += f" (direct feedthrough from {', '.join(feedthrough[v.name])})"
            out.append(f"| `{v.name}` | {v.causality} | {v.variability} | {v.type} | {v.unit or ''} | {_start(v)} | "
                       f"{_md_escape(desc)} |")
        out.append("")
    if extrapolation:
        out += ["### Extrapolation inputs", "",
                "For each coupling input `u` the FMU also has inputs `u_dt` and `u_dt2` (start 0): the first and "
                "second time derivative of `u` over the coming step; inside a step the FMU uses "
                "u(t) = u + s u_dt + s^2/2 u_dt2. A tool that leaves them at 0 gets a zero-order hold. "
                f"Here: {', '.join(f'`{v.name}`' for v in extrapolation)}.", ""]
    out += ["## Default experiment and capabilities", ""]
    if de is not None:
        out.append(f"- default experiment: start {de.startTime} s, stop {de.stopTime} s, step {de.stepSize} s")
    out += [f"- canGetAndSetFMUstate: {str(bool(cs.canGetAndSetFMUstate)).lower()}, canSerializeFMUstate: "
            f"{str(bool(cs.canSerializeFMUstate)).lower()} (the state covers the internal states, time and every "
            "non-output variable)",
            f"- canHandleVariableCommunicationStepSize: {str(bool(cs.canHandleVariableCommunicationStepSize)).lower()}, "
            f"needsExecutionTool: {str(bool(cs.needsExecutionTool)).lower()} (a Python interpreter)",
            f"- binaries: {', '.join(platforms)}", ""]
    out += ["## Using it from another tool", "",
            f"The binary is pythonfmu's wrapper: it runs the model in the CPython of the host process, which needs "
            f"{_needs(packages, host)} (the physics is bundled in the "
            "FMU under a build-unique package name, so it never clashes with an installed cranefmu or another "
            "FMU). Tested with CPython 3.11 in fmpy, fmpy's container FMU, fmu-manipulation-toolbox's "
            "fmucontainer and a C host (tests/fmu/test_native_hosts.py).", "",
            "- **Python host** (fmpy, this project's master): nothing to set up beyond the packages, e.g. "
            f"`fmpy.simulate_fmu('{fmu.name}', stop_time=1.0, step_size=1e-3)`.",
            "- **C/C++ host** (dlopen + FMI 2.0 C API): the binary leaves libpython unresolved. Preload it and "
            "point the interpreter at an environment with the packages:", "",
            "  ```sh",
            "  export LD_PRELOAD=$(python3 -c 'import sysconfig as s; "
            "print(s.get_config_var(\"LIBDIR\") + \"/\" + s.get_config_var(\"LDLIBRARY\"))')",
            "  export PATH=/path/to/venv/bin:$PATH          # CPython finds its prefix (the venv) from python3 on PATH",
            "  export PYTHONPATH=$(python3 -c 'import site; print(site.getsitepackages()[0])')",
            "  ```", "",
            "  Without LD_PRELOAD the library does not load (`undefined symbol: _Py_NoneStruct`); without the "
            "packages fmi2Instantiate returns NULL. The FMU keeps one Python thread state per host thread alive "
            "across calls (a thread without one would create and destroy it in every call, 28-44 us a call measured; "
            "`CRANEFMU_KEEP_THREAD_STATE=0` turns this off). See support/cranefmu_support/c_host/host.c for a complete host.",
            "- **Instances**: several instances (and copies unzipped twice) run side by side in one process and are "
            "independent, and an instance can be freed and the FMU instantiated again (tests/fmu/test_instances.py). "
            "Terminate and free every instance before the process exits. pythonfmu 0.7.0's binary released its "
            "interpreter guard twice at exit (its C++ static destructor, then its ELF destructor on the freed block) "
            "and a C host aborted with `free(): corrupted unsorted chunks` (exit 134); the FMU now empties the guard "
            "first from an exit handler of its own (cranefmu.adapter.pythonfmu_exit; tests/fmu/test_c_host_exit.py).",
            "- **Parameters** are checked at initialization: a refused value fails fmi2ExitInitializationMode with "
            "a logged message naming the parameter, its value and the allowed range.",
            f"- **FMI 3.0**: `cranefmu build-fmi3 {name}` builds `fmus/{name}3.fmu` with pythonfmu3, the same "
            "variables plus the independent variable `time` (value references shifted by one), the same physics "
            "and adapter (tests/fmu/test_fmi3.py).", ""]
    return "\n".join(out)


def fmu_files(names: list[str] | None = None) -> list[Path]:
    from .build import FMU_DIR, fmu_scripts

    return [FMU_DIR / f"{s.stem}.fmu" for s in fmu_scripts() if not names or s.stem in names]


def write_docs(output: Path = DOCS_DIR, names: list[str] | None = None) -> list[Path]:
    """Write ``<output>/<Name>.md`` for the built FMUs (all, or ``names``); returns the pages."""
    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    pages = []
    for fmu in fmu_files(names):
        page = output / f"{fmu.stem}.md"
        page.write_text(render(fmu))
        pages.append(page)
    return pages


def stale_pages(output: Path = DOCS_DIR, names: list[str] | None = None) -> list[str]:
    """Names of FMUs whose page in ``output`` differs from what the built FMU gives (or is missing)."""
    bad = []
    for fmu in fmu_files(names):
        page = Path(output) / f"{fmu.stem}.md"
        if not page.exists() or page.read_text() != render(fmu):
            bad.append(fmu.stem)
    return bad
