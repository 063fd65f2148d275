"""Native FMUs as drop-in FMUs for other tools: fmpy validate, fmpy.simulate_fmu, and plain C hosts with no
libpython in the process (the project's support/cranefmu_support/c_host/host.c, and tests/native/cycle_host.c
over instantiate/free cycles, FMU-state round trips and the failure paths, also under valgrind).

The FMUs: the layer's test model OscMass (tests/native/models/OscMass.c) and every model listed in
conformance.MODEL_CASES whose C file exists.
"""
from __future__ import annotations

import csv
import math
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from conformance import MODEL_CASES, native_fmu
from cranefmu.native.build import MODELS_DIR, compiler_available
from cranefmu_support.c_host.native import compile_host, fmi2_headers, write_config
from cranefmu_support.oscillator import HERE as OSC_DIR

pytestmark = pytest.mark.skipif(not compiler_available(), reason="no C compiler and CMake")
HERE = Path(__file__).resolve().parent
OSC = dict(script=OSC_DIR / "OscMass.py", model_c=HERE / "models" / "OscMass.c")
MODELS = ["OscMass", *[n for n in MODEL_CASES if (MODELS_DIR / f"{n}.c").exists()]]
# a Real parameter each model refuses at this value (cycle_host's failure path)
BAD = {"OscMass": ("m", -1.0), "Girder": ("c1", -1.0), "Boom": ("telescope_speed", -1.0),
       "SlewingBoom": ("slew_speed", -1.0), "Rope": ("E", -1.0), "Drive": ("J_w", -1.0),
       "Chassis": ("soil_coefficient", -1.0), "Chassis4": ("J_roll", -1.0)}


@pytest.fixture(scope="module")
def build_dir(tmp_path_factory) -> Path:
    shared = tmp_path_factory.getbasetemp() / "native_fmus"   # one build of each FMU per test session
    shared.mkdir(exist_ok=True)
    return shared


def _fmu(name: str, build_dir: Path) -> Path:
    return native_fmu(name, build_dir, **(OSC if name == "OscMass" else {}))


def _unzipped(fmu: Path, build_dir: Path) -> Path:
    from fmpy import extract

    target = build_dir / "unzipped" / fmu.stem
    if not target.exists():
        extract(str(fmu), str(target))
    return target


def _clean_env() -> dict[str, str]:
    """An environment without any route to a Python: no LD_PRELOAD, no PYTHONPATH, no venv on PATH."""
    env = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env["PATH"] = "/usr/bin:/bin"
    return env


@pytest.mark.parametrize("name", MODELS)
def test_fmpy_validate(name, build_dir):
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(_fmu(name, build_dir))) == []


@pytest.mark.parametrize("name", MODELS)
def test_binary_needs_no_python(name, build_dir):
    """The linux64 binary links libm and libc only."""
    if shutil.which("ldd") is None:
        pytest.skip("no ldd")
    so = _unzipped(_fmu(name, build_dir), build_dir) / "binaries" / "linux64" / f"{name}.so"
    linked = subprocess.run(["ldd", str(so)], capture_output=True, text=True, check=True).stdout
    assert "libpython" not in linked and "libm.so" in linked


def test_simulate_fmu_oscillates_at_the_natural_frequency(build_dir):
    """fmpy.simulate_fmu runs the native FMU alone: x = x0 cos(sqrt(k/m) t) to rk4's accuracy."""
    from fmpy import simulate_fmu

    result = simulate_fmu(str(_fmu("OscMass", build_dir)), stop_time=1.0, step_size=1e-3, output_interval=1e-3,
                          start_values={"x0": 0.1, "k": 40.0, "m": 1.0}, output=["x", "flag"])
    t, x = result["time"], result["x"]
    assert t[-1] == pytest.approx(1.0)
    np.testing.assert_allclose(x, 0.1 * np.cos(math.sqrt(40.0) * t), rtol=0, atol=1e-11)


@pytest.mark.parametrize("name", [n for n in MODELS if n != "OscMass"])
def test_simulate_fmu_runs_each_model(name, build_dir):
    """Each model alone in fmpy.simulate_fmu at its default parameters and start inputs: finite outputs."""
    from fmpy import simulate_fmu

    result = simulate_fmu(str(_fmu(name, build_dir)), stop_time=0.1, step_size=1e-3, output_interval=1e-3)
    assert len(result) == 101
    for column in result.dtype.names:
        assert np.all(np.isfinite(result[column])), column


@pytest.fixture(scope="module")
def c_host(build_dir) -> Path:
    return compile_host(build_dir)


def test_plain_c_host_without_python(c_host, build_dir):
    """The project's C host runs the native OscMass with no libpython anywhere, exits 0 and frees it; the
    values are the oscillator's."""
    unzipdir = _unzipped(_fmu("OscMass", build_dir), build_dir)
    config, out = build_dir / "osc.cfg", build_dir / "osc.csv"
    write_config(config, [("mass", unzipdir)], {"mass.x0": 0.1}, [], [("mass", "x")], 0.0, 1.0, 1e-3)
    done = subprocess.run([str(c_host), str(config), str(out)], capture_output=True, text=True, env=_clean_env(),
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert "freed 1 instances" in done.stdout
    with open(out) as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["time"]) for r in rows])
    x = np.array([float(r["mass.x"]) for r in rows])
    assert len(rows) == 1001
    np.testing.assert_allclose(x, 0.1 * np.cos(math.sqrt(40.0) * t), rtol=0, atol=1e-11)


@pytest.fixture(scope="module")
def cycle_host(build_dir) -> Path:
    exe = build_dir / "cycle_host"
    cc = shutil.which(os.environ.get("CC", "gcc")) or shutil.which("cc")
    subprocess.run([cc, "-O1", "-g", "-std=c99", "-Wall", "-I", str(fmi2_headers()), str(HERE / "cycle_host.c"),
                    "-o", str(exe), "-ldl"], check=True, capture_output=True, text=True)
    return exe


def _cycle_args(name: str, build_dir: Path, cycles: int) -> list[str]:
    from fmpy import read_model_description

    unzipdir = _unzipped(_fmu(name, build_dir), build_dir)
    md = read_model_description(str(unzipdir))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    output = next(v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real")
    bad_name, bad_value = BAD[name]
    return [str(unzipdir), md.coSimulation.modelIdentifier, md.guid, str(cycles), str(output), str(vr[bad_name]),
            repr(bad_value)]


@pytest.mark.parametrize("name", [n for n in MODELS if n in BAD])
def test_instantiate_free_cycles_in_a_c_host(name, cycle_host, build_dir):
    """Instantiate/free cycles with state round trips and the failure paths: exit 0, one line per failure."""
    done = subprocess.run([str(cycle_host), *_cycle_args(name, build_dir, 20)], capture_output=True, text=True,
                          env=_clean_env(), timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "cycles 20 ok"
    assert "is out of range" in done.stderr and "GUID" in done.stderr


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="no valgrind")
@pytest.mark.parametrize("name", [n for n in MODELS if n in BAD])
def test_valgrind_finds_no_invalid_access_and_no_leak(name, cycle_host, build_dir):
    """Under valgrind (memcheck): no invalid read or write, no use of undefined values, no definitely or
    indirectly lost bytes over 3 instantiate/free cycles and the failure paths."""
    done = subprocess.run(["valgrind", "--error-exitcode=99", "--leak-check=full",
                           "--errors-for-leak-kinds=definite,indirect", "--track-origins=yes",
                           str(cycle_host), *_cycle_args(name, build_dir, 3)],
                          capture_output=True, text=True, env=_clean_env(), timeout=300)
    assert done.returncode == 0, done.stderr[-4000:]
    assert "ERROR SUMMARY: 0 errors" in done.stderr
    assert "definitely lost: 0 bytes" in done.stderr or "All heap blocks were freed" in done.stderr
