"""Compile spring_support.c with the machine's C compiler and zip it with its
modelDescription.xml into SpringSupport.fmu (FMI 2.0 co-simulation; headers from fmpy)."""
from __future__ import annotations

import os
import shutil
import subprocess
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
IDENTIFIER = "SpringSupport"
GUID = "{6a3a1d7e-0c1f-4c8e-9a51-cranefmu-c-fmu}"   # as in spring_support.c

# name, value reference, causality, variability, unit, start, description (the order of ModelVariables)
REALS = [
    ("m", 0, "parameter", "fixed", "kg", 10.0, "mass of the support"),
    ("k", 1, "parameter", "fixed", "N/m", 1.0e6, "spring of the support"),
    ("d", 2, "parameter", "fixed", "N.s/m", 0.0, "damper of the support"),
    ("y0", 3, "parameter", "fixed", "m", 0.0, "start position (start = 0)"),
    ("v0", 4, "parameter", "fixed", "m/s", 0.0, "start velocity (start = 0)"),
    ("max_step", 5, "parameter", "fixed", "s", 1.0e-4, "largest RK4 substep"),
    ("F", 6, "input", "continuous", "N", 0.0, "force on the support (up positive)"),
    ("y", 7, "output", "continuous", "m", None, "position of the support from the unloaded spring (up)"),
    ("v", 8, "output", "continuous", "m/s", None, "velocity of the support"),
    ("a", 9, "output", "continuous", "m/s2", None, "acceleration of the support"),
]
UNITS = {"kg": dict(kg=1), "N/m": dict(kg=1, s=-2), "N.s/m": dict(kg=1, s=-1), "m": dict(m=1),
         "m/s": dict(m=1, s=-1), "s": dict(s=1), "N": dict(kg=1, m=1, s=-2), "m/s2": dict(m=1, s=-2)}


def compiler() -> str | None:
    return shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")


def model_description() -> str:
    units = "".join(f'<Unit name="{u}"><BaseUnit ' + " ".join(f'{k}="{v}"' for k, v in e.items()) + "/></Unit>"
                    for u, e in UNITS.items())
    rows = []
    for name, vr, causality, variability, unit, start, text in REALS:
        initial = ' initial="calculated"' if causality == "output" else ""
        start_attr = f' start="{start!r}"' if start is not None else ""
        rows.append(f'<ScalarVariable name="{name}" valueReference="{vr}" causality="{causality}" '
                    f'variability="{variability}"{initial} description="{text}"><Real unit="{unit}"{start_attr}/>'
                    "</ScalarVariable>")
    rows.append('<ScalarVariable name="start" valueReference="0" causality="parameter" variability="fixed" '
                'description="1: at rest for the input F at initialization (y = F/k); 0: from y0, v0">'
                '<Integer start="1"/></ScalarVariable>')
    index = {r[0]: i + 1 for i, r in enumerate(REALS)}
    outputs = "".join(f'<Unknown index="{index[n]}" dependencies=""/>' for n in ("y", "v"))
    outputs += f'<Unknown index="{index["a"]}" dependencies="{index["F"]}"/>'
    deps = " ".join(str(index[n]) for n in ("F",))
    initial = "".join(f'<Unknown index="{index[n]}" dependencies="{deps}"/>' for n in ("y", "v", "a"))
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="2.0" modelName="{IDENTIFIER}" guid="{GUID}" '
            'description="sprung suspension point written in C (cranefmu test FMU)" generationTool="tests/c_fmu" '
            'variableNamingConvention="flat" numberOfEventIndicators="0">'
            f'<CoSimulation modelIdentifier="{IDENTIFIER}" canHandleVariableCommunicationStepSize="true" '
            'canGetAndSetFMUstate="true" canNotUseMemoryManagementFunctions="true"/>'
            f'<UnitDefinitions>{units}</UnitDefinitions>'
            f'<DefaultExperiment startTime="0" stopTime="1" stepSize="1e-3"/>'
            f'<ModelVariables>{"".join(rows)}</ModelVariables>'
            f'<ModelStructure><Outputs>{outputs}</Outputs><InitialUnknowns>{initial}</InitialUnknowns>'
            '</ModelStructure></fmiModelDescription>')


def build(dest: Path) -> Path:
    """Compile and zip ``dest`` (an .fmu path); raises RuntimeError with the compiler's message."""
    return compile_fmu(dest, HERE / "spring_support.c", IDENTIFIER, model_description(),
                       flags=("-O2", "-Wextra"), libs=("-lm",), with_source=True)


def compile_fmu(dest: Path, source: Path, identifier: str, description: str, *, flags: tuple[str, ...] = ("-O1",),
                libs: tuple[str, ...] = (), with_source: bool = False) -> Path:
    """Compile one C file against fmpy's FMI 2.0 headers into a shared library and zip it with
    ``description`` (modelDescription.xml) into the FMU ``dest`` (and the source under sources/ if
    ``with_source``); raises RuntimeError naming the file and the compiler's message."""
    import fmpy

    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler (cc or gcc) on PATH")
    dest = Path(dest)
    lib = dest.with_suffix(".so")
    headers = Path(fmpy.__file__).parent / "c-code"
    cmd = [cc, "-shared", "-fPIC", *flags, "-std=c11", "-Wall", "-Werror", "-I", str(headers), str(source),
           "-o", str(lib), *libs]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"compiling {Path(source).name} failed: {done.stderr.strip()}")
    with zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("modelDescription.xml", description)
        zf.write(lib, f"binaries/{fmpy.platform}/{identifier}{fmpy.sharedLibraryExtension}")
        if with_source:
            zf.write(source, f"sources/{Path(source).name}")
    lib.unlink()
    return dest
