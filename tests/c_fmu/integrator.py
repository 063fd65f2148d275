"""Compile integrator.c into Integrator.fmu (FMI 2.0 co-simulation, headers from fmpy): x' = u with an
input it interpolates (canInterpolateInputs: the master sets its slopes with fmi2SetRealInputDerivatives),
outputs y = x and ny = -x; two of them in a loop are a harmonic oscillator."""
from __future__ import annotations

import subprocess
import zipfile
from pathlib import Path

from cranefmu_support.c_fmu.build import compiler

HERE = Path(__file__).resolve().parent
IDENTIFIER = "Integrator"


def model_description() -> str:
    rows = ('<ScalarVariable name="x0" valueReference="0" causality="parameter" variability="fixed">'
            '<Real start="0.0"/></ScalarVariable>'
            '<ScalarVariable name="u" valueReference="1" causality="input" variability="continuous">'
            '<Real start="0.0"/></ScalarVariable>'
            '<ScalarVariable name="y" valueReference="2" causality="output" variability="continuous" '
            'initial="calculated"><Real/></ScalarVariable>'
            '<ScalarVariable name="ny" valueReference="3" causality="output" variability="continuous" '
            'initial="calculated"><Real/></ScalarVariable>')
    outputs = '<Unknown index="3" dependencies=""/><Unknown index="4" dependencies=""/>'
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="2.0" modelName="{IDENTIFIER}" guid="{{integrator-cranefmu-tests}}" '
            'generationTool="tests/c_fmu" variableNamingConvention="flat" numberOfEventIndicators="0">'
            f'<CoSimulation modelIdentifier="{IDENTIFIER}" canHandleVariableCommunicationStepSize="true" '
            'canInterpolateInputs="true" maxOutputDerivativeOrder="0" canGetAndSetFMUstate="true"/>'
            '<DefaultExperiment startTime="0" stopTime="1" stepSize="0.01"/>'
            f'<ModelVariables>{rows}</ModelVariables>'
            f'<ModelStructure><Outputs>{outputs}</Outputs><InitialUnknowns>{outputs}</InitialUnknowns></ModelStructure>'
            '</fmiModelDescription>')


def build(dest: Path) -> Path:
    """Compile and zip ``dest`` (an .fmu path); raises RuntimeError with the compiler's message."""
    import fmpy

    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler (cc or gcc) on PATH")
    dest = Path(dest)
    lib = dest.with_suffix(".so")
    cmd = [cc, "-shared", "-fPIC", "-O1", "-std=c11", "-Wall", "-Werror", "-I", str(Path(fmpy.__file__).parent / "c-code"),
           str(HERE / "integrator.c"), "-o", str(lib)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"compiling integrator.c failed: {done.stderr.strip()}")
    with zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("modelDescription.xml", model_description())
        zf.write(lib, f"binaries/{fmpy.platform}/{IDENTIFIER}{fmpy.sharedLibraryExtension}")
    lib.unlink()
    return dest
