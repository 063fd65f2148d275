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


def _main_calls(stats, p: int) -> int:
    """Kernel calls after the start-up's p iterative steps (each: its evaluations of G(u), one call each,
    and its closing exchange; every later step counts one iteration)."""
    start_up_evaluations = stats.iterations - (stats.steps - p)
    return stats.kernel_calls - start_up_evaluations - p


def _equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and len(a) == len(b) and all(np.array_equal(a[n], b[n]) for n in a.dtype.names)


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
    # 256 steps a call, after the two start-up steps (iterative: their evaluations and exchanges a call each)
    assert compiled.stats.compiled_steps == 598 and _main_calls(compiled.stats, 2) <= 3
    assert python.stats.kernel_calls == 0


def test_crane_scene_bit_for_bit(lib, monkeypatch):
    """truck_telescope: five FMUs, several exchange phases, rate inputs, discrete outputs."""
    python, compiled = _both(monkeypatch, "truck_telescope", algorithm="jacobi", extrapolation=2, implicit=[],
                             step_size=1e-3, stop_time=0.1)
    assert _equal(python.result, compiled.result)
    assert python.stats.steps == compiled.stats.steps == 100
    assert (python.stats.compiled_steps, compiled.stats.compiled_steps) == (0, 98)   # after a start-up of 2
    assert _main_calls(compiled.stats, 2) == 1   # after the start-up one stretch: the bonds' values ride in its rows


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


def _lowering():
    """rope.payout and its rate input commanded: lowering 0.3 m from t = 0.05 s (breakpoints between steps)."""
    from cranefmu.experiments.profiles import moves
    from cranefmu.master.commands import Command

    profile = moves(0.0, [{"start": 0.0503, "to": 0.3, "speed": 0.5, "accel_time": 0.1}])
    return profile, [Command("rope.payout", profile), Command("rope.payout_rate", profile.derivative())]


@pytest.mark.parametrize("algorithm", ["jacobi", "gauss-seidel"])
def test_commanded_inputs_bit_for_bit(lib, built, monkeypatch, algorithm):
    """elastic_pendulum lowered by a command (value, rate and curvature inputs): the kernel sets the
    commanded values Python evaluated for each step's end (after each FMU's step and at the exchange, as
    commands.CommandFeed does); the Jacobi steps run in stretches of one call, the rows are Python's."""
    profile, commands = _lowering()
    python, compiled = _both(monkeypatch, "elastic_pendulum", algorithm=algorithm, extrapolation=2, step_size=1e-3,
                             stop_time=0.4, commands=commands)
    assert _equal(python.result, compiled.result)
    assert python.stats.compiled_steps == 0 and compiled.stats.compiled_steps == 398   # after a start-up of 2
    if algorithm == "jacobi":
        assert _main_calls(compiled.stats, 2) <= 2   # after the start-up, stretches of up to loop.STRETCH steps
    # the command reached the FMU: the rope paid out 0.15 m by 0.4 s (the hanging length follows within 1 cm)
    length = compiled.result["rope.rope_length"]
    assert profile.at(0.4)[0] == pytest.approx(0.14985, abs=1e-9)
    assert length[-1] - length[0] == pytest.approx(profile.at(0.4)[0], abs=0.01)


def test_command_started_by_an_event_bit_for_bit(lib, built, monkeypatch):
    """A command that starts where a condition on a row first holds (an event watcher sees every row:
    no stretches, the kernel is called step by step with the values Python evaluates after the
    watcher saw the last row): the event is found at the same row, the rows are Python's."""
    from cranefmu.experiments.events import Trigger, Triggered
    from cranefmu.experiments.profiles import moves
    from cranefmu.master.commands import Command

    trigger = Trigger("pendulum.theta < 0")
    lower = Triggered(moves(0.0, [{"start": 0.0, "to": 0.5, "speed": 0.2, "accel_time": 0.5}]), trigger, "start")
    python, compiled = _both(monkeypatch, "elastic_pendulum", algorithm="jacobi", extrapolation=2, step_size=0.01,
                             stop_time=2.5, commands=[Command("rope.payout", lower)])
    assert _equal(python.result, compiled.result)
    assert compiled.stats.compiled_steps == 248 and _main_calls(compiled.stats, 2) == 248   # then one call a step
    theta, length, t = compiled.result["pendulum.theta"], compiled.result["rope.rope_length"], compiled.result["time"]
    k = int(np.flatnonzero(theta < 0)[0])   # the event's row: a quarter period of the 5 deg swing, about 1.6 s
    assert 1.0 < t[k] < 2.0
    assert np.ptp(length[:k + 1]) < 1e-3 and length[-1] - length[k] > 0.05   # lowering after it (0.13 m), not before


@pytest.fixture(scope="module")
def integrators_ssp(tmp_path_factory):
    """Two Integrator FMUs (tests/c_fmu/integrator.c: x' = u, canInterpolateInputs, no rate inputs) in a
    loop, a.u = b.y and b.u = -a.y (a LinearTransformation): x_a = cos t, x_b = sin t from a.x0 = 1."""
    from c_fmu.integrator import build, compiler
    from cranefmu_support.foreign_ssp import write_ssp

    if compiler() is None:
        pytest.skip("no C compiler")
    folder = tmp_path_factory.mktemp("integrators")
    fmu = build(folder / "Integrator.fmu")
    minus = '<ssc:LinearTransformation factor="-1" offset="0"/>'
    return write_ssp(folder / "integrators.ssp", {"a": fmu, "b": fmu}, [("b", "y", "a", "u"), ("a", "y", "b", "u")],
                     parameters={"a.x0": 1.0}, transform={("b", "u"): minus})


@pytest.mark.parametrize("algorithm", ["jacobi", "gauss-seidel"])
def test_fmi_input_derivatives_bit_for_bit(lib, monkeypatch, integrators_ssp, algorithm):
    """An FMU that interpolates its inputs gets the extrapolation's slopes through
    fmi2SetRealInputDerivatives, from the kernel as from Python: the same bits; and they are used: the
    circle x_a^2 + x_b^2 = 1 holds to 1e-5 over a period at H = 10 ms (measured 4.7e-6 Jacobi, 2.1e-6
    Gauss-Seidel; with extrapolation 0, inputs held, 6.5e-2 and 5.0e-3)."""
    python, compiled = _both(monkeypatch, integrators_ssp, algorithm=algorithm, extrapolation=2, step_size=0.01,
                             stop_time=6.3)
    assert _equal(python.result, compiled.result)
    assert python.stats.compiled_steps == 0 and compiled.stats.compiled_steps == 628   # after a start-up of 2
    r = compiled.result
    assert r["a.y"][0] == 1.0 and np.max(np.abs(r["a.y"] - np.cos(r["time"]))) < 1e-5
    radius = r["a.y"] ** 2 + r["b.y"] ** 2
    assert np.max(np.abs(radius - 1.0)) < 1e-5


@pytest.mark.parametrize("extrapolation", [0, 1, 2])
def test_iterative_steps_in_compiled_code_bit_for_bit(lib, monkeypatch, oscillator_ssp, extrapolation):
    """The iterative algorithm decides in Python (acceleration, convergence); each evaluation of G(u) (feed
    along the polynomial through the past and u, every FMU steps, image: Coupling.evaluate) and the exchange
    that ends each step (Coupling.commit) run in the kernel, a call each, with the same bits."""
    python, compiled = _both(monkeypatch, oscillator_ssp, algorithm="iterative", extrapolation=extrapolation,
                             step_size=1e-3, stop_time=0.2, parameters={"mass.x0": 0.1})
    assert _equal(python.result, compiled.result)
    evaluations = compiled.stats.iterations
    assert python.stats.iterations == evaluations > 200   # more than one evaluation a step
    assert (python.stats.kernel_calls, compiled.stats.kernel_calls) == (0, 200 + evaluations)
    assert max(np.ptp(compiled.result[n]) for n in compiled.result.dtype.names[1:]) > 1e-3


@pytest.mark.parametrize("extrapolation", [0, 1, 2])
def test_implicit_group_in_compiled_code_bit_for_bit(lib, monkeypatch, extrapolation):
    """overhead_lift's loose set (hook, drum and trolley solved as an implicit group, Newton in Python): each
    evaluation of the group (its values fed in one product, its FMUs stepped, their image passed on where
    fed through) and the exchange after each step run in the kernel; the rows are Python's."""
    python, compiled = _both(monkeypatch, "overhead_lift", parameter_set="loose", stop_time=0.1,
                             extrapolation=extrapolation)
    assert _equal(python.result, compiled.result)
    steps = compiled.stats.steps
    assert steps == python.stats.steps >= 50 and compiled.stats.iterations == python.stats.iterations
    assert python.stats.kernel_calls == 0 and compiled.stats.kernel_calls > 2 * steps


@pytest.mark.parametrize("scene, settings", [
    ("hook_sway", dict(algorithm="jacobi", extrapolation=1, implicit=["hook"], step_size=2e-3)),
    ("hook_sway", dict(algorithm="iterative", extrapolation=2, step_size=2e-3))])
def test_commands_with_strongly_coupled_steps_bit_for_bit(lib, built, monkeypatch, scene, settings):
    """hook_sway's boom tip commanded as a trolley travel (boom.x_travel and its rate, breakpoints between
    steps) with the hook bond implicit, or every value iterated: each evaluation of G(u) in the kernel sets the
    commanded values at t + h after each stepped FMU as the Python path does; the rows are Python's."""
    from cranefmu.experiments.profiles import moves
    from cranefmu.master.commands import Command

    travel = moves(0.0, [{"start": 0.0301, "to": 0.2, "speed": 0.5, "accel_time": 0.1}])
    commands = [Command("boom.x_travel", travel), Command("boom.vx_travel", travel.derivative())]
    python, compiled = _both(monkeypatch, scene, stop_time=0.3, commands=commands, **settings)
    assert _equal(python.result, compiled.result)
    assert python.stats.kernel_calls == 0 and compiled.stats.kernel_calls > 2 * compiled.stats.steps
    x = compiled.result["boom.x_tip"]
    assert x[-1] - x[0] == pytest.approx(travel.at(0.3)[0], abs=1e-12) and travel.at(0.3)[0] > 0.05


@pytest.mark.parametrize("scene, stop", [("oscillator", 0.5), ("truck_telescope", 0.1)])
def test_plain_jacobi_bit_for_bit(lib, monkeypatch, oscillator_ssp, scene, stop):
    """libcosim's fixed-step Jacobi (every output read once right after the step, held over the next one)
    in compiled code, one call a step: the rows are Python's."""
    python, compiled = _both(monkeypatch, oscillator_ssp if scene == "oscillator" else scene, algorithm="jacobi-plain",
                             extrapolation=0, step_size=1e-3, stop_time=stop,
                             **({"parameters": {"mass.x0": 0.1}} if scene == "oscillator" else {}))
    steps = round(stop / 1e-3)
    assert _equal(python.result, compiled.result) and compiled.stats.steps == steps
    assert (python.stats.compiled_steps, compiled.stats.compiled_steps, compiled.stats.kernel_calls) == (0, steps, steps)
    assert max(np.ptp(compiled.result[n]) for n in compiled.result.dtype.names[1:]) > 1e-3


def test_a_component_whose_outputs_grew_after_planning_is_not_given_to_the_kernel():
    """The kernel reads each component's outputs into its slot of one buffer, sized when the exchange was
    planned; a component that reads more since (an output positioned later) must not reach it: fmi2GetReal
    would write past the slot (two-worker test runs crashed in garbage collection after such writes)."""
    import ctypes
    from types import SimpleNamespace

    from cranefmu.master.kernel.plan import python_reason

    buffer = (ctypes.c_double * 5)()
    slot = lambda at, n: (ctypes.c_double * n).from_buffer(buffer, 8 * at)   # noqa: E731
    fits = [SimpleNamespace(_read=(None, 2, slot(0, 2), None)), SimpleNamespace(_read=(None, 3, slot(2, 3), None))]
    grown = [fits[0], SimpleNamespace(_read=(None, 4, (ctypes.c_double * 4)(), None))]   # its own, larger buffer
    for comps, planned in ((grown, False), ([fits[0], SimpleNamespace(_read=None)], False)):
        coupling = SimpleNamespace(_phases=[object()], comps=comps, _read_at=[0, 2], _read_all=buffer)
        assert python_reason(object(), coupling) == "a component's outputs were added after the exchange was planned"
    from cranefmu.master.kernel.plan import _reads_fit

    assert _reads_fit(SimpleNamespace(comps=fits, _read_at=[0, 2], _read_all=buffer))
