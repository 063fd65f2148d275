"""No FMI call reaches an instance after it returned fmi2Fatal (FMI 2.0 section 2.1.3; cranefmu.master.fatal_status).

The memory fault that crashed long test processes in garbage collection (tests/README.md, "Memory faults"): the
pythonfmu Rope raises while it computes its outputs (the rope paid out past its length), pythonfmu 0.7.0 then
releases the instance's Python object and returns fmi2Fatal, and the iterative coupling's rescue restored the
snapshot with fmi2SetFMUstate on that instance: a method called on a freed object, which corrupts the memory Python
hands to its next objects.  Before the fix the subprocess below died with SIGSEGV in ``gc.collect()`` every time
(PYTHONMALLOC=debug fills freed memory, so the first use of it crashes)."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from cranefmu.errors import CraneFmuError

# the scene of tests/tools/test_fault_matrix.py's iteration test: rope.payout to -30 m at 100 m/s leaves no
# rope at t = 0.1 s, and the Rope refuses to compute its outputs there (status fatal in pythonfmu)
RUN = """
from cranefmu.experiments.profiles import moves
from cranefmu.master.commands import Command
from cranefmu.master.run import run

PAY_OUT = moves(0.0, [{"start": 0.0, "to": -30.0, "speed": 100.0, "accel_time": 0.0}])


def failing_run(**settings):
    return run("elastic_pendulum", stop_time=0.2, step_size=1e-3, commands=[Command("rope.payout", PAY_OUT)],
               fmus="python", progress=False, **settings)
"""
SETTINGS = {"iterative": dict(algorithm="iterative"), "jacobi-implicit": dict(algorithm="jacobi", implicit=["hook"]),
            "gauss-seidel": dict(algorithm="gauss-seidel"), "jacobi": dict(algorithm="jacobi", instability_alarm=False)}


def _failing_run():
    space: dict = {}
    exec(RUN, space)
    return space["failing_run"]


@pytest.mark.parametrize("name", list(SETTINGS))
def test_no_fmi_call_reaches_an_instance_after_it_returned_fatal(built, name):
    """Every FMI call of the run seen through wrap_fmi_calls: once an instance returned status 4 (fatal), no
    later call reaches it (before the fix: fmi2SetFMUstate and fmi2FreeFMUstate did, in the iterative rescue
    and in the implicit group's release), and the run still fails with the Rope's own reason."""
    from cranefmu.master.fmu import wrap_fmi_calls

    calls: list[tuple[str, str, object]] = []

    def recording(instance, fname, f):
        def call(*args):
            status = f(*args)
            calls.append((instance, fname, status))
            return status

        for attr in ("argtypes", "restype", "argnames"):
            setattr(call, attr, getattr(f, attr, None))
        return call

    with wrap_fmi_calls(recording), pytest.raises(CraneFmuError) as err:
        _failing_run()(**SETTINGS[name])
    assert "component rope failed" in str(err.value) and "leaves no rope" in str(err.value), err.value
    fatal = [i for i, (instance, _, status) in enumerate(calls) if instance == "rope" and status == 4]
    assert fatal, "the Rope never returned fmi2Fatal: the test no longer exercises the fault"
    after = [fname for instance, fname, _ in calls[fatal[0] + 1:] if instance == "rope"]
    assert after == [], f"called on the rope after its fmi2Fatal: {after}"


def test_failing_pythonfmu_runs_leave_the_process_memory_sound(built, tmp_path):
    """The failing run with each algorithm, then a full garbage collection, in a fresh process whose freed memory
    Python fills (PYTHONMALLOC=debug): it ends normally (before the fix: SIGSEGV in the collection)."""
    script = tmp_path / "fail_then_collect.py"
    script.write_text(RUN + textwrap.dedent(f"""
        import gc
        from cranefmu.errors import CraneFmuError

        for settings in {list(SETTINGS.values())!r}:
            try:
                failing_run(**settings)
            except CraneFmuError:
                pass
            gc.collect()
            kept = [dict(a=[j]) for j in range(50000)]   # reuse the memory the collection freed
            gc.collect()
        print("sound")
    """))
    env = {**os.environ, "PYTHONMALLOC": "debug", "PYTHONFAULTHANDLER": "1"}
    p = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=600)
    assert p.returncode == 0 and p.stdout.strip() == "sound", (p.returncode, p.stderr[-3000:])
