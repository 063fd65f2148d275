"""The native Pendulum FMU against the pythonfmu one through the same FMI call sequences (tests/native/
conformance.py with tests/native/native_pendulum_cases.py: the scenes' sets, the optional physics, ground events,
tunable changes, rollbacks, refusals): equal to the last bit (measured; the cases that pass through numpy's
BLAS are held to PENDULUM_RTOL, see test_pendulum_model.py)."""
from __future__ import annotations

from pathlib import Path

import pytest

from conformance import Case, conform
from cranefmu.native.build import compiler_available
from native_pendulum_cases import HOOK_SWAY, PENDULUM_CASES

pytestmark = pytest.mark.skipif(not compiler_available(), reason="no C compiler and CMake")

#: where numpy's BLAS/LAPACK is in the path (pin damper, inertias): another OpenBLAS kernel may round differently
PENDULUM_RTOL = 1e-12


@pytest.fixture(scope="module")
def build_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("native_pendulum")


def test_pendulum_conforms(build_dir):
    worst = conform("Pendulum", PENDULUM_CASES, build_dir, rtol=PENDULUM_RTOL)
    print(f"worst relative difference over {len(worst)} cases: {max(worst):.3g}")
    assert max(worst) <= PENDULUM_RTOL


def test_exact_with_payload_is_refused_at_initialization(build_dir):
    """cf_prepare_exact_step: both FMUs refuse solver = 'exact' with a payload at fmi2ExitInitializationMode."""
    conform("Pendulum", [Case(dict(HOOK_SWAY, solver="exact"), refused=True, label="exact with payload")],
            build_dir)


def test_pendulum_model_description_equals_the_pythonfmu_one(build_dir):
    """Names, value references, units, starts, descriptions, ModelStructure, the dimension/payload/start/ground
    enumerations and the ports: the same in both FMUs (test_fmi_layer's check, on Pendulum)."""
    from test_fmi_layer import test_model_description_equals_the_pythonfmu_one as same_description

    same_description("Pendulum", build_dir)
