"""A non-Python FMU in every run of the suite: SpringSupport (support/cranefmu_support/c_fmu/spring_support.c, FMI 2.0
written in C, compiled with cc while the tests run) as the sprung suspension point of our Rope and
Pendulum in a hand-written SSP (docs/foreign_fmus.md)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from cranefmu_support.c_fmu import C_ROPE, G, K, LOAD, M_SUPPORT, support_scene
from cranefmu_support.c_fmu.build import build, compiler
from cranefmu.master.run import run


@pytest.fixture(scope="module")
def c_fmu(tmp_path_factory):
    if compiler() is None:
        pytest.skip("no C compiler (cc or gcc) on PATH: the C test FMU cannot be built")
    return build(tmp_path_factory.mktemp("c_fmu") / "SpringSupport.fmu")


def _free_vibration(fmu: str) -> dict:
    from fmpy import simulate_fmu

    r = simulate_fmu(fmu, stop_time=0.1, step_size=1e-3, start_values={"start": 0, "y0": 0.01}, output=["y"])
    return {"time": r["time"].tolist(), "y": r["y"].tolist()}


def test_the_c_fmu_validates_and_vibrates_at_its_frequency(c_fmu):
    """fmpy validate finds nothing; alone, from y0 = 1 cm with F = 0: y = y0 cos(sqrt(k/m) t)."""
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(c_fmu)) == []
    r = _free_vibration(str(c_fmu))
    w = np.sqrt(1e6 / 10.0)   # the FMU's start values of k and m
    assert np.max(np.abs(np.array(r["y"]) - 0.01 * np.cos(w * np.array(r["time"])))) < 1e-8


def test_the_c_fmu_holds_the_rope_at_rest(built, tmp_path, c_fmu):
    """Settled in initialization mode across the C and Python FMUs: the support sags m g / k under the
    hanging load, the tension is the weight, and nothing moves (jacobi and iterative)."""
    ssp = support_scene(tmp_path / "c_support.ssp", built, c_fmu)
    for algorithm in ("jacobi", "iterative"):
        res = run(ssp, stop_time=0.2, step_size=1e-3, algorithm=algorithm, progress=False)
        r = res.result
        assert np.max(np.abs(r["support.y"] + LOAD * G / K)) < 1e-9 * LOAD * G / K
        assert np.max(np.abs(r["rope.tension"] - LOAD * G)) < 1e-8 * LOAD * G
        assert np.max(np.abs(r["support.v"])) < 1e-9 and "bond.rope-support.dE" in r.dtype.names


def test_the_c_fmu_and_the_load_vibrate_as_two_masses_on_springs(built, tmp_path, c_fmu):
    """Released from y = 0 (start = 0), Mg/k above its rest, with the load hanging at rest below it:
    the vertical motion is that of two masses (support, load) on the support spring k and the rope
    c = E A / L (exact by the matrix exponential).  Measured: 2.6 % of the amplitude at H = 0.1 ms over
    0.2 s, the same with the iterative algorithm (so it is the rope model's, not the coupling's)."""
    ssp = support_scene(tmp_path / "c_support.ssp", built, c_fmu, **{"support.start": 0, "rope.zeta": 0.0})
    r = run(ssp, stop_time=0.1, step_size=1e-4, algorithm="jacobi", extrapolation=1, progress=False).result
    a = np.array([[0, 1, 0, 0], [-(K + C_ROPE) / M_SUPPORT, 0, C_ROPE / M_SUPPORT, 0],
                  [0, 0, 0, 1], [C_ROPE / LOAD, 0, -C_ROPE / LOAD, 0]])
    lift = LOAD * G / K
    exact = np.array([(expm(a * t) @ [lift, 0.0, lift, 0.0])[0] for t in r["time"]]) - lift
    assert np.max(np.abs(r["support.y"] - exact)) < 0.05 * lift
    assert np.ptp(r["support.y"]) > 1.5 * lift   # it does vibrate
