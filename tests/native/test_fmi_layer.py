"""The generic native FMI 2.0 layer (src/cranefmu/native/fmi2) against the pythonfmu adapter it mirrors.

The test model is OscMass (cranefmu_support.oscillator, a mass on a spring pushed by a coupling force),
whose C twin tests/native/models/OscMass.c exists only here: it proves the layer alone (solvers, input
rates, discrete output, switch, cross-field check, FMU state, refusals).  Every model listed in
conformance.MODEL_CASES is checked the same way with its own cases, and its modelDescription against
the pythonfmu one.
"""
from __future__ import annotations

import ctypes
import math
from pathlib import Path
from xml.etree import ElementTree

import pytest

from conformance import MODEL_CASES, MODEL_RTOL, RK45_RTOL, RTOL, Case, conform, drive_all, fmu_pair, in_child
from cranefmu.native.build import compiler_available
from cranefmu_support.oscillator import HERE as OSC_DIR

pytestmark = pytest.mark.skipif(not compiler_available(), reason="no C compiler and CMake")
HERE = Path(__file__).resolve().parent
OSC = dict(script=OSC_DIR / "OscMass.py", model_c=HERE / "models" / "OscMass.c")
WIGGLE = dict(inputs={"F": 0.5}, wiggle={"F": 2.0})


@pytest.fixture(scope="module")
def build_dir(tmp_path_factory) -> Path:
    shared = tmp_path_factory.getbasetemp() / "native_fmus"   # one build of each FMU per test session
    shared.mkdir(exist_ok=True)
    return shared


@pytest.fixture(scope="module")
def osc_pair(build_dir) -> tuple[Path, Path]:
    return fmu_pair("OscMass", build_dir, **OSC)


def test_explicit_solvers_give_the_pythonfmu_bits(osc_pair, build_dir):
    """euler, rk2, rk4 (several sub-steps, moving and held inputs, rollbacks): equal to the last bit."""
    cases = [Case({"x0": 0.1, "d": 0.5, "solver": s, "max_step": m}, rates=r, **WIGGLE)
             for s in ("euler", "rk2", "rk4") for m, r in ((1e-3, True), (3e-4, True), (3e-4, False))]
    cases.append(Case({"x0": 0.1, "x_flag": 0.05}, steps=60, h=5e-3, **WIGGLE, label="the discrete flag toggles"))
    cases.append(Case({"start": "equilibrium", "f": 3.0}, **WIGGLE, label="start at rest for the input"))
    worst = conform("OscMass", cases, build_dir, rtol=0.0, **OSC)
    assert worst == [0.0] * len(cases)


def test_trbdf2_agrees_to_round_off(osc_pair, build_dir):
    """trbdf2 inverts I - c h J with its own elimination (numpy: LAPACK): equal to 1e-12 relative."""
    cases = [Case({"x0": 0.1, "d": 20.0, "k": 4e4, "solver": "trbdf2", "max_step": 1e-3}, **WIGGLE)]
    assert max(conform("OscMass", cases, build_dir, rtol=RTOL, **OSC)) <= RTOL


def test_refusals_are_the_pythonfmu_lines(osc_pair, build_dir):
    """Every refused parameter: the native FMU logs the pythonfmu FMU's line and fails initialization."""
    cases = [Case(p, refused=True) for p in (
        {"m": -1.0}, {"m": 0.0}, {"k": float("nan")}, {"d": float("-inf")}, {"m": 1e-320 * -1},
        {"start": "equilibrium", "k": 0.0}, {"rtol": 0.0}, {"rtol": 1.5}, {"max_step": -2.5e-7},
        {"solver": 11}, {"solver": -1}, {"start": 5})]
    conform("OscMass", cases, build_dir, **OSC)
    got = in_child(drive_all, str(osc_pair[0]), [dict(params={"k": -3e16}, refused=True)])
    assert got[0]["error"] == "initialization"
    assert got[0]["messages"][-1] == ("inst0: initialization refused: ParameterError: mass.k = -3e+16 is out "
                                      "of range: allowed [0, inf) N/m")


def test_non_finite_state_is_the_pythonfmu_failure(osc_pair, build_dir):
    """A state that overflows fails the step with the line naming the state, in both FMUs."""
    cases = [Case({"m": 1e-300, "solver": "euler"}, inputs={"F": 1e300}, rollback=False)]
    conform("OscMass", cases, build_dir, **OSC)
    got = in_child(drive_all, str(osc_pair[0]), [dict(params=cases[0].params, inputs={"F": 1e300}, rollback=False)])
    assert "step at t = 0 s failed: FloatingPointError: non-finite state v at t = 0.001 s" in got[0]["messages"][-1]


def test_rk45_agrees_with_scipy_to_round_off(osc_pair, build_dir):
    """rk45 is scipy's RK45 step control in C (plain sums where scipy calls BLAS): the same steps, equal to
    round-off (RK45_RTOL), over tolerances from loose to tight and with max_step limiting the steps."""
    cases = [Case({"x0": 0.1, "d": 0.5, "solver": "rk45", "rtol": r, "max_step": m}, steps=40, h=h, **WIGGLE)
             for r, m, h in ((1e-3, 1.0, 2e-2), (1e-6, 1.0, 2e-2), (1e-10, 1.0, 2e-2), (1e-6, 2e-3, 1e-2))]
    assert max(conform("OscMass", cases, build_dir, rtol=RK45_RTOL, **OSC)) <= RK45_RTOL


def test_implicit_adaptive_solvers_are_refused_in_one_line(osc_pair):
    """radau and bdf (scipy) are the pythonfmu FMU's: the native FMU refuses them naming what it offers."""
    got = in_child(drive_all, str(osc_pair[0]), [dict(params={"solver": s}) for s in ("radau", "bdf")])
    for code, (name, r) in enumerate(zip(("radau", "bdf"), got), start=5):
        assert r["error"] == "initialization"
        assert r["messages"][-1] == (
            f"inst{code - 5}: initialization refused: ParameterError: mass.solver = {code} ({name}) is not offered "
            "by the native FMU: allowed 0 = euler, 1 = rk2, 2 = rk4, 3 = trbdf2, 4 = rk45 (radau and bdf: the "
            "pythonfmu FMU)")


def _native_calls(fmu: Path):
    """The native FMU's library and a fresh instance, called through ctypes (no Python in the FMU)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    unzipdir = extract(str(fmu))
    md = read_model_description(unzipdir)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="layer")
    vr = {v.name: v.valueReference for v in md.modelVariables}
    return slave, vr


def test_fixed_parameter_refused_after_initialization_tunable_rebuilds(build_dir):
    """After initialization a fixed parameter is refused naming its old value; a tunable one changes the
    model (Girder's b1), and the refused value stays refused."""
    if "Girder" not in MODEL_CASES or not (Path(__file__).parents[2] / "src/cranefmu/native/models/Girder.c").exists():
        pytest.skip("no native Girder")
    from fmpy.fmi1 import FMICallException

    native, _ = fmu_pair("Girder", build_dir)
    slave, vr = _native_calls(native)
    messages = []
    from fmpy import calloc, free
    from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                           fmi2CallbackLoggerTYPE)

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, cat, msg: messages.append(msg.decode()))
    cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    slave.instantiate(callbacks=cb)
    try:
        slave.setupExperiment(startTime=0.0)
        slave.setInteger([vr["solver"]], [2])
        slave.enterInitializationMode()
        slave.setReal([vr["Fy_rope"]], [2e4])
        slave.exitInitializationMode()
        slave.setReal([vr["Fy_rope"]], [4e4])    # a load step: the girder swings
        slave.doStep(0.0, 1e-2)
        before = slave.getReal([vr["vy_top"]])[0]
        with pytest.raises(FMICallException):
            slave.setReal([vr["c1"]], [1e6])
        assert messages[-1] == ("layer: parameter refused: ParameterError: girder.c1 = 1000000.0 is refused: a fixed "
                                "parameter cannot change after initialization (it is 4600000.0)")
        slave.setReal([vr["c1"]], [4.6e6])   # back to its value: accepted again
        state = slave.getFMUstate()
        slave.doStep(1e-2, 1e-2)
        same_b1 = slave.getReal([vr["y_top"], vr["vy_top"]])
        slave.setFMUstate(state)
        slave.setReal([vr["b1"]], [0.0])      # tunable: the model is rebuilt, the state kept
        slave.doStep(1e-2, 1e-2)
        no_damping = slave.getReal([vr["y_top"], vr["vy_top"]])
        slave.freeFMUstate(state)
        assert before != 0.0 and same_b1 != no_damping
        with pytest.raises(FMICallException):
            slave.setReal([vr["b1"]], [-1.0])
        assert messages[-1].endswith("girder.b1 = -1.0 is out of range: allowed [0, inf) N.s/m")
    finally:
        slave.terminate()
        slave.freeInstance()


def test_bad_calls_are_error_statuses_not_crashes(osc_pair):
    """Wrong value references, types, a step before initialization, a foreign state: status error and a line."""
    from fmpy.fmi1 import FMICallException

    slave, vr = _native_calls(osc_pair[0])
    slave.instantiate()
    try:
        slave.setupExperiment(startTime=0.0)
        for call in (lambda: slave.getReal([9999]), lambda: slave.getReal([vr["flag"]]),
                     lambda: slave.setInteger([vr["m"]], [1]), lambda: slave.setReal([vr["x"]], [1.0]),
                     lambda: slave.doStep(0.0, 1e-3), lambda: slave.getBoolean([0]),
                     lambda: slave.deSerializeFMUstate(b"\0" * 64)):
            with pytest.raises(FMICallException):
                call()
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        state = slave.getFMUstate()
        blob = slave.serializeFMUstate(state)
        with pytest.raises(FMICallException):
            slave.deSerializeFMUstate(blob[:-1])
        slave.freeFMUstate(state)
        slave.doStep(0.0, 1e-3)
    finally:
        slave.terminate()
        slave.freeInstance()


def test_python_repr_of_floats_in_messages(osc_pair):
    """The layer's repr of a float (its messages) is Python's repr, over magnitudes and the edges."""
    from fmpy import extract

    lib = ctypes.CDLL(str(Path(extract(str(osc_pair[0]))) / "binaries" / "linux64" / "OscMass.so"))
    assert not hasattr(lib, "cf_pyrepr"), "the layer's own functions must be hidden (only fmi2* exported)"
    got = in_child(drive_all, str(osc_pair[0]), [dict(params={"m": -v}, refused=True) for v in _REPR_VALUES])
    for value, r in zip(_REPR_VALUES, got):
        assert r["messages"][-1].split("mass.m = ")[1].split(" is ")[0] == repr(-value)


_REPR_VALUES = [1.0, 0.1, 1e-4, 1.5e-5, 123456789.0, 1e15, 1e16, 1.2345678901234567e16, 2.0 ** -1074,
                1.7976931348623157e308, math.pi, 1 / 3, 5e-324, 0.3, 2.5, 100.0, 1e22, 9007199254740993.0]


@pytest.mark.parametrize("name", ["OscMass", *MODEL_CASES])
def test_model_description_equals_the_pythonfmu_one(name, build_dir):
    """Every variable's name, value reference, causality, variability, unit, start and description, the
    ModelStructure, the enumerations and ports annotations: the same in both FMUs."""
    import zipfile

    kwargs = OSC if name == "OscMass" else {}
    if name != "OscMass" and not (Path(__file__).parents[2] / f"src/cranefmu/native/models/{name}.c").exists():
        pytest.skip(f"no native {name}")
    native, python = fmu_pair(name, build_dir, **kwargs)
    roots = [ElementTree.fromstring(zipfile.ZipFile(f).read("modelDescription.xml")) for f in (native, python)]

    def variables(root):
        out = []
        for sv in root.find("ModelVariables"):
            t = sv[0]
            out.append((sv.get("name"), sv.get("valueReference"), sv.get("causality"), sv.get("variability"),
                        sv.get("initial"), sv.get("description"), t.tag, t.get("unit"), t.get("start")))
        return out

    def tree(element):   # tag, attributes and children, whatever the indentation
        if element is None:
            return None
        return element.tag, sorted(element.attrib.items()), [tree(child) for child in element]

    assert variables(roots[0]) == variables(roots[1])
    assert len(variables(roots[0])) > 5
    assert tree(roots[0].find("ModelStructure")) == tree(roots[1].find("ModelStructure"))
    assert tree(roots[0].find("UnitDefinitions")) == tree(roots[1].find("UnitDefinitions"))
    for tool in ("org.cranefmu.enumerations", "org.cranefmu.ports"):
        found = [tree(r.find(f"VendorAnnotations/Tool[@name='{tool}']")) for r in roots]
        assert found[0] == found[1]
    cs = roots[0].find("CoSimulation")
    assert cs.get("canGetAndSetFMUstate") == cs.get("canSerializeFMUstate") == "true"
    assert cs.get("needsExecutionTool") == "false"
    files = [f.get("name") for f in cs.find("SourceFiles")]
    assert "cf_fmi2.c" in files and f"{kwargs.get('model_c', Path(name + '.c')).name}" in files
    with zipfile.ZipFile(native) as zf:
        assert {f"sources/{f}" for f in files} <= set(zf.namelist())
        assert f"binaries/linux64/{name}.so" in zf.namelist()


@pytest.mark.parametrize("name", list(MODEL_CASES))
def test_model_conforms(name, build_dir):
    """The model's native and pythonfmu FMUs through the same FMI call sequences (conformance.MODEL_CASES)."""
    if not (Path(__file__).parents[2] / f"src/cranefmu/native/models/{name}.c").exists():
        pytest.skip(f"no native {name}")
    rtol = MODEL_RTOL.get(name, RTOL)
    assert max(conform(name, MODEL_CASES[name], build_dir, rtol=rtol)) <= rtol


def test_prepare_exact_step_hook_is_found_in_a_model_source():
    """The optional cf_prepare_exact_step (include/cf_model.h) is called only where a model defines it."""
    from cranefmu.native.description import defines_prepare_exact_step

    assert defines_prepare_exact_step("static int x;\nint cf_prepare_exact_step(CfModel *m) {\n    return 0;\n}\n")
    assert defines_prepare_exact_step("int cf_prepare_exact_step(CfModel *m)\n{\n")
    assert not defines_prepare_exact_step("int cf_prepare_exact_step(CfModel *m);\n")   # a declaration only
    assert not defines_prepare_exact_step((HERE / "models" / "OscMass.c").read_text())


def test_parameter_fixed_during_initialization_mode_is_accepted(osc_pair):
    """A value refused at fmi2EnterInitializationMode but corrected before fmi2ExitInitializationMode
    initializes, and the outputs are computed from it (the pythonfmu adapter kept its enter-time error
    and never refreshed the outputs again)."""
    slave, vr = _native_calls(osc_pair[0])
    slave.instantiate()
    try:
        slave.setupExperiment(startTime=0.0)
        slave.setReal([vr["m"]], [-1.0])
        slave.enterInitializationMode()
        slave.setReal([vr["m"], vr["x0"], vr["F"]], [2.0, 0.25, 3.0])
        slave.exitInitializationMode()
        x, a = slave.getReal([vr["x"], vr["a"]])
        assert (x, a) == (0.25, (3.0 + 0.0 - 40.0 * 0.25 - 0.0 * 0.0) / 2.0)
    finally:
        slave.terminate()
        slave.freeInstance()


def test_setuptools_build_equals_the_cmake_build(osc_pair, build_dir):
    """Without CMake the same sources are compiled by setuptools' compiler: an FMU that validates, links no
    Python, and gives the CMake-built FMU's bits."""
    from dataclasses import asdict

    from fmpy.validation import validate_fmu

    from cranefmu.native.build import build_native_fmu

    other = build_native_fmu("OscMass", build_dir / "setuptools", tool="setuptools", **OSC)
    assert validate_fmu(str(other)) == []
    cases = [asdict(Case({"x0": 0.1, "d": 0.5, "solver": s}, **WIGGLE)) for s in ("rk4", "rk45", "trbdf2")]
    a, b = (in_child(drive_all, str(f), cases) for f in (osc_pair[0], other))
    assert [r["rows"] for r in a] == [r["rows"] for r in b]
    assert all(r["error"] is None and len(r["rows"]) > 30 for r in b)


def test_a_state_of_another_fmu_is_refused(osc_pair, build_dir):
    """fmi2SetFMUstate with a state of another native FMU (Girder's, set into OscMass): status error and a
    line, the instance unchanged."""
    from fmpy.fmi1 import FMICallException

    if not (Path(__file__).parents[2] / "src/cranefmu/native/models/Girder.c").exists():
        pytest.skip("no native Girder")
    osc, vr = _native_calls(osc_pair[0])
    girder, _ = _native_calls(fmu_pair("Girder", build_dir)[0])
    for s in (osc, girder):
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
    try:
        foreign = girder.getFMUstate()
        with pytest.raises(FMICallException):
            osc.setFMUstate(foreign)
        girder.freeFMUstate(foreign)
        osc.doStep(0.0, 1e-3)
        assert osc.getReal([vr["x"]]) == [0.0]
    finally:
        for s in (osc, girder):
            s.terminate()
            s.freeInstance()


def _cpu_has_fma() -> bool:
    try:
        return " fma " in " " + Path("/proc/cpuinfo").read_text().replace("\n", " ") + " "
    except OSError:
        return False


@pytest.mark.skipif(not _cpu_has_fma(), reason="the CPU has no fused multiply-add")
def test_sources_keep_pythons_arithmetic_when_a_tool_contracts(osc_pair, build_dir):
    """A tool compiling sources/ with its own flags, fused multiply-adds allowed (-mfma -ffp-contract=fast),
    gets the same bits: every source file starts with the pragma that turns contraction off."""
    import zipfile
    from dataclasses import asdict

    from cranefmu.native.build import compile_binary, zip_fmu

    unzipdir = build_dir / "contracting" / "OscMass"
    with zipfile.ZipFile(osc_pair[0]) as zf:
        zf.extractall(unzipdir)
    (unzipdir / "binaries" / "linux64" / "OscMass.so").unlink()
    compile_binary(unzipdir, "cmake", c_flags="-O3 -mfma -ffp-contract=fast")
    other = zip_fmu(unzipdir, build_dir / "contracting" / "OscMass.fmu")
    cases = [asdict(Case({"x0": 0.1, "d": 0.5, "solver": s}, **WIGGLE)) for s in ("rk4", "rk45")]
    a, b = (in_child(drive_all, str(f), cases) for f in (osc_pair[0], other))
    assert [r["rows"] for r in a] == [r["rows"] for r in b]
