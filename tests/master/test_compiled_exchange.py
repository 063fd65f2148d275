"""The compiled exchange (master/kernel) gives the Python exchange's bits: the same run with each, in
worker processes (pythonfmu FMUs instantiate once per process), compared column by column; and its
extrapolation product gives numpy's for every size it is checked on."""
import numpy as np
import pytest

from cranefmu.master import kernel
from cranefmu.master.run import run


def _both(monkeypatch, scene, **settings):
    out = {}
    for mode in ("python", "compiled"):
        monkeypatch.setenv(kernel.DISABLE, "1" if mode == "python" else "0")
        out[mode] = run(scene, isolate=True, progress=False, **settings)
    return out["python"], out["compiled"]


def _equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and len(a) == len(b) and all(np.array_equal(a[n], b[n]) for n in a.dtype.names)


@pytest.fixture(scope="module")
def lib():
    built = kernel.library()
    if built is None:
        pytest.skip(f"no compiled exchange here: {kernel.why_not}")
    return built


@pytest.mark.parametrize("extrapolation", [0, 1, 2])
def test_oscillator_bit_for_bit(lib, monkeypatch, oscillator_ssp, extrapolation):
    python, compiled = _both(monkeypatch, oscillator_ssp, algorithm="jacobi", extrapolation=extrapolation,
                             step_size=1e-3, stop_time=0.5, parameters={"mass.x0": 0.1})
    assert python.stats.steps == compiled.stats.steps == 500
    # the first `extrapolation` steps are the iterative start-up (Python); every later one is compiled
    assert (python.stats.compiled_steps, compiled.stats.compiled_steps) == (0, 500 - extrapolation)
    assert _equal(python.result, compiled.result)
    # the run moved (a comparison of two frozen runs proves nothing): the masses swing by millimetres or more
    assert max(np.ptp(compiled.result[n]) for n in compiled.result.dtype.names[1:]) > 1e-3


@pytest.mark.parametrize("extrapolation", [0, 1, 2])
def test_gauss_seidel_oscillator_bit_for_bit(lib, monkeypatch, oscillator_ssp, extrapolation):
    python, compiled = _both(monkeypatch, oscillator_ssp, algorithm="gauss-seidel", extrapolation=extrapolation,
                             step_size=1e-3, stop_time=0.3, parameters={"mass.x0": 0.1})
    assert (python.stats.compiled_steps, compiled.stats.compiled_steps) == (0, 300 - extrapolation)
    assert _equal(python.result, compiled.result)
    assert max(np.ptp(compiled.result[n]) for n in compiled.result.dtype.names[1:]) > 1e-3


def test_stretch_of_steps_in_one_call_bit_for_bit(lib, monkeypatch, oscillator_ssp):
    """No observer needs the steps one by one (the recorder, the value check, the bond's watch take rows
    after the fact): the compiled Jacobi takes stretches of them in one call, its rows carrying what the
    power bond measures; rows and bond residuals are the Python path's."""
    python, compiled = _both(monkeypatch, oscillator_ssp, algorithm="jacobi", extrapolation=2, step_size=1e-3,
                             stop_time=0.6, parameters={"mass.x0": 0.1})
    assert python.stats.bond_energy == compiled.stats.bond_energy and python.stats.bond_energy["coupling"] > 0
    assert _equal(python.result, compiled.result) and len(compiled.result) == 601
    assert compiled.stats.compiled_steps == 598 and compiled.stats.kernel_calls <= 3   # 256 steps a call
    assert python.stats.kernel_calls == 0


def test_crane_scene_bit_for_bit(lib, monkeypatch):
    """truck_telescope: five FMUs, several exchange phases, rate inputs, discrete outputs."""
    python, compiled = _both(monkeypatch, "truck_telescope", algorithm="jacobi", extrapolation=2, implicit=[],
                             step_size=1e-3, stop_time=0.1)
    assert _equal(python.result, compiled.result)
    assert python.stats.steps == compiled.stats.steps == 100
    assert (python.stats.compiled_steps, compiled.stats.compiled_steps) == (0, 98)   # after a start-up of 2
    assert compiled.stats.kernel_calls == 1   # one stretch: the bonds' values ride in its rows


def test_gauss_seidel_crane_scene_bit_for_bit(lib, monkeypatch):
    """truck_telescope with Gauss-Seidel: each component fed along the polynomial through its sources' new
    values, outputs that feed through held at their end values."""
    python, compiled = _both(monkeypatch, "truck_telescope", algorithm="gauss-seidel", extrapolation=1,
                             step_size=1e-3, stop_time=0.1)
    assert _equal(python.result, compiled.result)
    assert (python.stats.compiled_steps, compiled.stats.compiled_steps) == (0, 99)


def test_product_matches_numpy_on_every_size(lib):
    assert kernel.agrees_with_numpy(lib, list(range(1, 41)), trials=10)


def test_without_a_compiler_one_line_says_so_and_python_runs(monkeypatch, tmp_path, capsys):
    """A build that fails (no compiler, no setuptools) leaves the Python exchange, with one line on stderr."""
    monkeypatch.setenv("CRANEFMU_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv(kernel.DISABLE, raising=False)
    monkeypatch.setattr(kernel, "_TRIED", False)
    monkeypatch.setattr(kernel, "_LIB", None)
    monkeypatch.setattr(kernel, "why_not", "")

    def no_compiler(target):
        raise OSError("no C compiler here")

    monkeypatch.setattr(kernel, "_build", no_compiler)
    assert kernel.library() is None
    assert "OSError: no C compiler here" in kernel.why_not
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].endswith("the exchange runs in Python (same results, slower)")
