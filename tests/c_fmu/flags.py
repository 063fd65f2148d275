"""Compile flags.c into Flags.fmu (FMI 2.0 co-simulation, headers from fmpy): a feedthrough of one
Real, Boolean, Enumeration and Integer each, declared in the Reference FMU Feedthrough's order
(a Boolean before an Enumeration and an Integer), to check columns and connections by type."""
from __future__ import annotations

from pathlib import Path

from cranefmu_support.c_fmu.build import compile_fmu, compiler  # noqa: F401 (compiler: the tests' skip)

HERE = Path(__file__).resolve().parent
IDENTIFIER = "Flags"

# name, type, value reference, causality, start (the order of ModelVariables)
VARIABLES = [
    ("Real_input", "Real", 0, "input", "0.0"),
    ("Real_output", "Real", 1, "output", None),
    ("Boolean_input", "Boolean", 0, "input", "false"),
    ("Boolean_output", "Boolean", 1, "output", None),
    ("Enumeration_input", "Enumeration", 2, "input", "1"),
    ("Enumeration_output", "Enumeration", 3, "output", None),
    ("Integer_input", "Integer", 0, "input", "0"),
    ("Integer_output", "Integer", 1, "output", None),
]


def model_description(variable_step: bool = True) -> str:
    rows = []
    for name, kind, vr, causality, start in VARIABLES:
        variability = "discrete" if kind != "Real" else "continuous"
        initial = ' initial="calculated"' if causality == "output" else ""
        attrs = (' declaredType="Option"' if kind == "Enumeration" else "") + (f' start="{start}"' if start else "")
        rows.append(f'<ScalarVariable name="{name}" valueReference="{vr}" causality="{causality}" '
                    f'variability="{variability}"{initial}><{kind}{attrs}/></ScalarVariable>')
    index = {v[0]: i + 1 for i, v in enumerate(VARIABLES)}
    outputs = "".join(f'<Unknown index="{index[n]}" dependencies="{index[n.replace("output", "input")]}"/>'
                      for n, _, _, c, _ in VARIABLES if c == "output")
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="2.0" modelName="{IDENTIFIER}" guid="{{flags-cranefmu-tests}}" '
            'generationTool="tests/c_fmu" variableNamingConvention="flat" numberOfEventIndicators="0">'
            f'<CoSimulation modelIdentifier="{IDENTIFIER}" canHandleVariableCommunicationStepSize='
            f'"{str(variable_step).lower()}"/>'
            '<TypeDefinitions><SimpleType name="Option"><Enumeration><Item name="one" value="1"/>'
            '<Item name="two" value="2"/><Item name="three" value="3"/></Enumeration></SimpleType>'
            '</TypeDefinitions><DefaultExperiment startTime="0" stopTime="1" stepSize="0.1"/>'
            f'<ModelVariables>{"".join(rows)}</ModelVariables>'
            f'<ModelStructure><Outputs>{outputs}</Outputs><InitialUnknowns>{outputs}</InitialUnknowns></ModelStructure>'
            '</fmiModelDescription>')


def build(dest: Path, variable_step: bool = True) -> Path:
    """Compile and zip ``dest`` (an .fmu path); raises RuntimeError with the compiler's message."""
    return compile_fmu(dest, HERE / "flags.c", IDENTIFIER, model_description(variable_step))
