"""FMI 3.0 variants built with pythonfmu3 over the same FMI 2.0 adapter and physics
(cranefmu.adapter.fmi3_adapter): they pass `fmpy validate` and compute what the FMI 2.0 FMUs compute."""
from __future__ import annotations

import pytest

from cranefmu_support.fmu_child import in_pool as in_child

pytest.importorskip("pythonfmu3")

G = 9.81


@pytest.fixture(scope="module")
def fmi3(built, tmp_path_factory):
    from cranefmu.build import build_fmi3

    out = tmp_path_factory.mktemp("fmi3")
    return {name: build_fmi3(name, out / f"{name}3.fmu") for name in ("Pendulum", "Rope")}


def simulate(fmu: str, start_values: dict, outputs: list[str], stop: float):
    from fmpy import simulate_fmu

    r = simulate_fmu(fmu, stop_time=stop, step_size=1e-3, output_interval=1e-3, start_values=start_values,
                     output=outputs)
    return {k: r[k].tolist() for k in ["time", *outputs]}


@pytest.mark.parametrize("name", ["Pendulum", "Rope"])
def test_fmi3_variant_validates_and_declares_what_the_fmi2_one_does(built, fmi3, name):
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(fmi3[name])) == []
    md3 = read_model_description(str(fmi3[name]))
    md2 = read_model_description(str(built / f"{name}.fmu"))
    assert md3.fmiVersion == "3.0" and md3.coSimulation.canGetAndSetFMUstate
    v3 = {v.name: v for v in md3.modelVariables}
    assert v3["time"].causality == "independent"
    for v in md2.modelVariables:
        assert v3[v.name].causality == v.causality and (v3[v.name].unit or "") == (v.unit or ""), v.name
    outs3 = {u.variable.name: sorted(d.name for d in u.dependencies or []) for u in md3.outputs}
    outs2 = {u.variable.name: sorted(d.name for d in u.dependencies or []) for u in md2.outputs}
    assert outs3 == outs2


def test_fmi3_pendulum_falls_by_the_law_and_as_the_fmi2_one(built, fmi3):
    sv = {"dimension": 1, "mass": 250.0, "Fy_rope": 5000.0}
    r3 = in_child(simulate, str(fmi3["Pendulum"]), sv, ["y", "vy"], 0.2)
    r2 = in_child(simulate, str(built / "Pendulum.fmu"), sv, ["y", "vy"], 0.2)
    a = 5000.0 / 250.0 - G
    assert r3["vy"][-1] == pytest.approx(a * 0.2, rel=1e-9)
    assert r3["y"] == r2["y"] and r3["vy"] == r2["vy"]  # the same code: bit-identical


def test_fmi3_rope_static_tension(fmi3):
    length, E, A, delta = 10.0, 1e11, 5.655e-5, 0.01
    sv = {"length": length, "E": E, "A": A, "zeta": 0.0, "y_hook": -(length + delta)}
    r = in_child(simulate, str(fmi3["Rope"]), sv, ["tension"], 0.01)
    assert r["tension"][0] == pytest.approx(E * A / length * delta, rel=1e-12)
    assert r["tension"][-1] == pytest.approx(E * A / length * delta, rel=1e-12)


def state_round_trip(fmu: str) -> tuple[float, float, float]:
    """Child: step, save (and serialize) the state, step on, restore, step again; free."""
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Slave

    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    f = FMU3Slave(guid=md.guid, unzipDirectory=extract(fmu), modelIdentifier=md.coSimulation.modelIdentifier)
    f.instantiate()
    f.setInt32([vr["dimension"]], [1])
    f.enterInitializationMode(startTime=0.0)
    f.setFloat64([vr["Fy_rope"]], [5000.0])
    f.exitInitializationMode()
    t = 0.0
    for _ in range(50):
        f.doStep(currentCommunicationPoint=t, communicationStepSize=1e-3)
        t += 1e-3
    state = f.getFMUState()
    blob = f.serializeFMUState(state)
    for _ in range(50):
        f.doStep(currentCommunicationPoint=t + _ * 1e-3, communicationStepSize=1e-3)
    first = f.getFloat64([vr["vy"]])[0]
    f.setFMUState(f.deserializeFMUState(blob))
    for _ in range(50):
        f.doStep(currentCommunicationPoint=t + _ * 1e-3, communicationStepSize=1e-3)
    second = f.getFloat64([vr["vy"]])[0]
    f.freeFMUState(state)
    f.terminate()
    f.freeInstance()
    return first, second, (5000.0 / 1000.0 - G) * 0.1


def test_fmi3_state_save_serialize_restore(fmi3):
    first, second, expected = in_child(state_round_trip, str(fmi3["Pendulum"]))
    assert first == second
    assert first == pytest.approx(expected, rel=1e-9)
