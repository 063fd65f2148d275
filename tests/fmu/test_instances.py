"""Several instances in one process are independent, an FMU can be instantiated again after a
free, and every host frees every instance.

The Pendulum FMU in 1-D (hoisting) under a constant rope force F falls with a = F/m - g, so after
time T: vy = a T and y = y0 + a T^2 / 2 (exact for RK4 up to round-off).  Instances with different
masses stepped in turn must each follow their own law; instances with the same parameters must
give bit-identical outputs.  Each case runs in a fresh child process whose exit status must be 0
(an instance left alive corrupts the heap at exit).  The second instance and the instantiation
after a free both crashed before fmi_adapter balanced pythonfmu 0.7.0's extra release of the
script module's namespace (CraneSlave.__init_subclass__).
"""
from __future__ import annotations

import multiprocessing

import pytest

G = 9.81
Y0 = -10.0
H = 1e-3
STEPS = 200


def in_child(fn, *args, timeout: float = 300.0):
    """``fn(*args)`` in a spawned process; its result, after checking the process exited with 0."""
    ctx = multiprocessing.get_context("spawn")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_call, args=(child, fn, args))
    proc.start()
    child.close()
    if not parent.poll(timeout):
        proc.kill()
        raise AssertionError(f"{fn.__name__} did not finish in {timeout} s")
    result = parent.recv()
    proc.join(timeout)
    assert proc.exitcode == 0, f"child exited with {proc.exitcode} after {fn.__name__} (heap corrupted at exit?)"
    if isinstance(result, BaseException):
        raise result
    return result


def _call(conn, fn, args):
    try:
        conn.send(fn(*args))
    except BaseException as err:  # handed to the parent, which raises it
        conn.send(err)


def fall(unzipdirs: list[str], masses: list[float], force: float, steps: int) -> list[tuple[float, float]]:
    """Child: one Pendulum instance per (unzip dir, mass), stepped in turn under the same force.
    Returns (y, vy) per instance; every instance is terminated and freed."""
    from fmpy import read_model_description
    from fmpy.fmi2 import FMU2Slave

    from cranefmu.master.process import callbacks

    md = read_model_description(unzipdirs[0])
    vr = {v.name: v.valueReference for v in md.modelVariables}
    insts = []
    for k, (d, m) in enumerate(zip(unzipdirs, masses)):
        f = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=f"pendulum{k}")
        f.instantiate(callbacks=callbacks())
        f.setupExperiment(startTime=0.0)
        f.setInteger([vr["dimension"]], [1])
        f.setReal([vr["mass"], vr["y0"], vr["g"]], [m, Y0, G])
        f.enterInitializationMode()
        f.setReal([vr["Fy_rope"]], [force])
        f.exitInitializationMode()
        insts.append(f)
    for n in range(steps):
        for f in insts:  # in turn: any shared state would leak from one into the next
            f.doStep(currentCommunicationPoint=n * H, communicationStepSize=H)
    out = []
    for f in insts:
        y, vy = f.getReal([vr["y"], vr["vy"]])
        f.terminate()
        f.freeInstance()
        out.append((y, vy))
    return out


@pytest.fixture(scope="module")
def unzipped(built, tmp_path_factory):
    """The Pendulum FMU unzipped twice into different directories."""
    from fmpy import extract

    base = tmp_path_factory.mktemp("pendulum")
    return [extract(str(built / "Pendulum.fmu"), unzipdir=str(base / name)) for name in ("a", "b")]


def expected(m: float, force: float, t: float) -> tuple[float, float]:
    a = force / m - G
    return Y0 + 0.5 * a * t * t, a * t


def check_law(results, masses, force):
    t = STEPS * H
    for (y, vy), m in zip(results, masses):
        ye, vye = expected(m, force, t)
        assert vy == pytest.approx(vye, rel=1e-9), (m, vy, vye)
        assert y == pytest.approx(ye, rel=1e-9, abs=1e-12), (m, y, ye)


def test_two_instances_of_one_fmu_are_independent(unzipped):
    force = 5000.0
    masses = [1000.0, 250.0, 1000.0]
    res = in_child(fall, [unzipped[0]] * 3, masses, force, STEPS)
    check_law(res, masses, force)
    assert res[0] == res[2]          # same parameters, same inputs: bit-identical
    assert res[0][1] != res[1][1]   # different mass: different motion


def test_same_fmu_unzipped_twice_is_independent(unzipped):
    force = 5000.0
    masses = [1000.0, 400.0, 1000.0, 400.0]
    res = in_child(fall, [unzipped[0], unzipped[1], unzipped[1], unzipped[0]], masses, force, STEPS)
    check_law(res, masses, force)
    assert res[0] == res[2] and res[1] == res[3]


def test_two_different_fmus_in_one_process_each_keep_their_own_code(built):
    """Rope and Pendulum (the same pythonfmu wrapper binary, one shared interpreter) in one process:
    each runs its own model, the rope's static tension c*delta and the pendulum's free fall."""
    res = in_child(rope_and_pendulum, str(built / "Rope.fmu"), str(built / "Pendulum.fmu"))
    tension, expected_tension, vy = res
    assert tension == pytest.approx(expected_tension, rel=1e-12)
    assert vy == pytest.approx(-G * STEPS * H, rel=1e-9)


def rope_and_pendulum(rope_fmu: str, pendulum_fmu: str) -> tuple[float, float, float]:
    """Child: a Rope with its hook held 1 cm below the unstretched length (tension n E A delta / L)
    next to a Pendulum in free fall (F = 0)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from cranefmu.master.process import callbacks

    slaves, vrs = [], []
    for path, name in ((rope_fmu, "rope"), (pendulum_fmu, "pendulum")):
        md = read_model_description(path)
        f = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=name)
        f.instantiate(callbacks=callbacks())
        f.setupExperiment(startTime=0.0)
        slaves.append(f)
        vrs.append({v.name: v.valueReference for v in md.modelVariables})
    rope, pend = slaves
    rv, pv = vrs
    length, E, A, delta = 10.0, 1e11, 5.655e-5, 0.01
    rope.setReal([rv["length"], rv["E"], rv["A"], rv["zeta"]], [length, E, A, 0.0])
    pend.setInteger([pv["dimension"]], [1])
    for f in slaves:
        f.enterInitializationMode()
    rope.setReal([rv["x_hook"], rv["y_hook"], rv["z_hook"]], [0.0, -(length + delta), 0.0])
    pend.setReal([pv["Fy_rope"]], [0.0])
    for f in slaves:
        f.exitInitializationMode()
    for n in range(STEPS):
        for f in slaves:
            f.doStep(currentCommunicationPoint=n * H, communicationStepSize=H)
    tension = rope.getReal([rv["tension"]])[0]
    vy = pend.getReal([pv["vy"]])[0]
    for f in slaves:
        f.terminate()
        f.freeInstance()
    return tension, E * A / length * delta, vy


def fall_again(unzipdir: str, masses: list[float], force: float, steps: int) -> list[tuple[float, float]]:
    """Child: instantiate, run, free; then again in the same process (once crashed in pythonfmu 0.7.0)."""
    return [fall([unzipdir], [m], force, steps)[0] for m in masses]


def test_instantiate_again_after_free_in_one_process(unzipped):
    force = 5000.0
    masses = [1000.0, 250.0, 1000.0]
    res = in_child(fall_again, unzipped[0], masses, force, STEPS)
    check_law(res, masses, force)
    assert res[0] == res[2]


def test_a_failing_child_is_reported(tmp_path):
    """The harness itself: an exception in the child reaches the test (the checks above can fail)."""
    with pytest.raises(FileNotFoundError):
        in_child(fall, [str(tmp_path / "missing")], [1.0], 0.0, 1)
