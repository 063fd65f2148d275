"""Compile integrator.c into Integrator.fmu (FMI 2.0 co-simulation, headers from fmpy): x' = u with an
input it interpolates (canInterpolateInputs: the master sets its slopes with fmi2SetRealInputDerivatives),
outputs y = x and ny = -x; two of them in a loop are a harmonic oscillator."""
from __future__ import annotations

from pathlib import Path

from cranefmu_support.c_fmu.build import compile_fmu, compiler  # noqa: F401 (compiler: the tests' skip)

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
    return compile_fmu(dest, HERE / "integrator.c", IDENTIFIER, model_description())
