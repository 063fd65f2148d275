"""An FMU's messages belong to its instance (master/fmu.py, master/process.py): two runs at once, each
with a component called ``rope``, keep separate logs, so the error naming an FMU's last message names its
own.  Before, the log was a process-global list per instance name: both ropes wrote into one."""
from __future__ import annotations

import threading

import pytest

from cranefmu.master.fmu import FmuComponent


@pytest.fixture(scope="module")
def native_rope():
    import cranefmu
    from cranefmu.errors import CraneFmuError

    try:
        return cranefmu.fmu_path("Rope", "native")
    except CraneFmuError as err:
        pytest.skip(f"no native Rope FMU: {err}")


def _refused_start(comp: FmuComponent, length: float, together: threading.Barrier) -> None:
    """Instantiate ``comp``, wait for the other thread, then start it with a refused rope length."""
    comp.instantiate()
    together.wait(timeout=60)
    comp.fmu.setupExperiment(startTime=0.0)
    comp.set_start("length", length)
    comp.fmu.enterInitializationMode()
    try:
        comp.fmu.exitInitializationMode()
    except Exception:   # refused: the status is an error, the reason is in the log
        pass
    together.wait(timeout=60)


def test_two_concurrent_instances_of_one_name_keep_their_own_messages(native_rope, tmp_path):
    lengths = {"first": 0.0, "second": -2.0}
    comps = {k: FmuComponent("rope", native_rope, tmp_path / k) for k in lengths}
    together = threading.Barrier(len(comps))
    errors: list[BaseException] = []

    def go(key: str) -> None:
        try:
            _refused_start(comps[key], lengths[key], together)
        except BaseException as err:   # noqa: BLE001 (reported below)
            errors.append(err)
            together.abort()

    threads = [threading.Thread(target=go, args=(k,)) for k in lengths]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    try:
        assert not errors, errors
        for key, length in lengths.items():
            own = comps[key].messages
            other = lengths["second" if key == "first" else "first"]
            assert any(f"rope.length = {length}" in m for m in own), (key, own)
            assert not any(f"rope.length = {other}" in m for m in own), (key, own)
            assert f"rope.length = {length}" in comps[key].last_error()
    finally:
        for comp in comps.values():
            comp.free()


def test_messages_are_kept_per_instance_and_capped(native_rope, tmp_path):
    from cranefmu.master.process import Messages

    comp = FmuComponent("rope", native_rope, tmp_path / "one")
    assert comp.messages == [] and comp.last_error() == "no message from the FMU"
    log = Messages()
    for i in range(Messages.KEPT + 7):
        log.add(f"m{i}")
    assert len(log) == Messages.KEPT and log[0] == "m7" and log[-1] == f"m{Messages.KEPT + 6}"
