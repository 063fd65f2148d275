"""The native Rope and Drive FMUs with the solvers whose arithmetic is not Python's to the bit: trbdf2
(the C layer inverts I - c h J by its own elimination, numpy by LAPACK) and rk45 (scipy's RK45 in C, plain
sums where scipy calls BLAS), against their pythonfmu FMUs through the same FMI call sequences
(conformance.py).  Measured worst difference, relative to each output's range (2026-11-28, this machine):
Rope (Bouc-Wen, overhead_lift's fitted reeving) rk45 2.3e-16, trbdf2 0; Drive trbdf2 1.4e-15, rk45
3.2e-15.  Asserted at the layer's stated tolerances (TRBDF2_RTOL here, RK45_RTOL of conformance.py); the
explicit solvers are bitwise and covered by conformance.MODEL_CASES."""
from __future__ import annotations

from pathlib import Path

import pytest

from conformance import _LIFT_ROPE, _ROPE_WIGGLE, RK45_RTOL, Case, _hanging, conform
from cranefmu.native.build import compiler_available

pytestmark = pytest.mark.skipif(not compiler_available(), reason="no C compiler and CMake")
TRBDF2_RTOL = 1e-12   # as tests/native/test_fmi_layer.py asserts for the layer's trbdf2

_BW = dict(inputs=_hanging(10.0, 2e-3), wiggle=dict(_ROPE_WIGGLE, y_hook=4e-3), steps=60)
_LIFT = dict(inputs=_hanging(12.0, 0.0, 1000.0, 4), wiggle=dict(_ROPE_WIGGLE, y_hook=1e-3))
_DRUM = dict(inputs={"drum_force": 5e3}, wiggle={"drum_force": 1e3})


@pytest.fixture(scope="module")
def build_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("native_rope_drive")


def test_trbdf2_agrees_to_round_off(build_dir):
    rope = [Case({"model": "bouc_wen", "solver": "trbdf2", "max_step": 2e-4}, label="Rope Bouc-Wen trbdf2", **_BW),
            Case(dict(_LIFT_ROPE, solver="trbdf2"), label="Rope overhead_lift trbdf2", **_LIFT)]
    drive = [Case({"solver": "trbdf2", "max_step": 1e-3, "start_time": 0.005}, steps=60, label="Drive trbdf2",
                  **_DRUM)]
    assert max(conform("Rope", rope, build_dir, rtol=TRBDF2_RTOL)) <= TRBDF2_RTOL
    assert max(conform("Drive", drive, build_dir, rtol=TRBDF2_RTOL)) <= TRBDF2_RTOL


def test_rk45_agrees_to_round_off(build_dir):
    rope = [Case({"model": "bouc_wen", "solver": "rk45", "rtol": r}, label=f"Rope Bouc-Wen rk45 {r:g}", **_BW)
            for r in (1e-4, 1e-9)]
    drive = [Case({"solver": "rk45", "rtol": 1e-6, "start_time": 0.005}, steps=40, label="Drive rk45 start",
                  **_DRUM),
             Case({"solver": "rk45", "rtol": 1e-9, "start_time": 0.2, "ramp_time": 0.5}, inputs={"drum_force": 2453.0},
                  wiggle={"drum_force": 500.0}, t0=0.18, steps=40, label="Drive rk45 overhead_lift")]
    assert max(conform("Rope", rope, build_dir, rtol=RK45_RTOL)) <= RK45_RTOL
    assert max(conform("Drive", drive, build_dir, rtol=RK45_RTOL)) <= RK45_RTOL
