"""The Python API works wherever Python is written: a plain script without a main guard, ``python -``,
``python -c``, a thread; in the caller's process or isolated; SIGINT stops an in-process run between
steps and the process can run again."""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from cranefmu.master.results import read_csv

SCRIPT = """
import json, threading
import cranefmu
rows = {}
rows["here"] = cranefmu.simulate("elastic_pendulum", stop_time=0.2, step_size=1e-3)
rows["isolated"] = cranefmu.simulate("elastic_pendulum", stop_time=0.2, step_size=1e-3, isolate=True)
box = {}
worker = threading.Thread(target=lambda: box.update(r=cranefmu.simulate("elastic_pendulum", stop_time=0.2,
                                                                                   step_size=1e-3)))
worker.start(); worker.join()
rows["thread"] = box["r"]
print(json.dumps({k: [len(v), float(v["rope.tension"][-1]), float(v["pendulum.theta"][-1])] for k, v in rows.items()}))
"""


@pytest.fixture(scope="module")
def reference(built):
    from cranefmu.master.run import run

    r = run("elastic_pendulum", stop_time=0.2, step_size=1e-3).result
    return [len(r), float(r["rope.tension"][-1]), float(r["pendulum.theta"][-1])]


@pytest.mark.parametrize("how", ["script", "stdin", "-c"])
def test_a_guardless_script_runs_in_process_isolated_and_in_a_thread(reference, tmp_path, how):
    script = tmp_path / "plain.py"
    script.write_text(SCRIPT)
    argv = {"script": [str(script)], "stdin": ["-"], "-c": ["-c", SCRIPT]}[how]
    p = subprocess.run([sys.executable, *argv], input=SCRIPT if how == "stdin" else None, capture_output=True,
                       text=True, cwd=tmp_path, timeout=300)
    assert p.returncode == 0, p.stderr
    got = json.loads(p.stdout.splitlines()[-1])
    for where in ("here", "isolated", "thread"):
        assert got[where] == reference, where   # the same rows and values, bit for bit
    assert sorted(x.name for x in tmp_path.iterdir()) == ["plain.py"]


INTERRUPTED = """
import sys
from cranefmu.master.run import RunInterrupted, run
try:
    run("elastic_pendulum", stop_time=200, step_size=1e-3, output=sys.argv[1])
except RunInterrupted as err:
    print("interrupted", len(err.result), err.output, err.signum, flush=True)
again = run("elastic_pendulum", stop_time=0.05, step_size=1e-3)
print("again", len(again.result), flush=True)
"""


def test_sigint_stops_an_in_process_run_between_steps_and_the_process_runs_again(built, tmp_path):
    out = tmp_path / "out.csv"
    part = out.with_name("out.csv.part")
    proc = subprocess.Popen([sys.executable, "-c", INTERRUPTED, str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    end = time.monotonic() + 120
    while not (part.exists() and part.read_bytes().count(b"\n") > 1000):
        assert proc.poll() is None and time.monotonic() < end, proc.communicate()
        time.sleep(0.02)
    proc.send_signal(signal.SIGINT)   # what a notebook's "interrupt" sends
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, stderr
    first, second = stdout.splitlines()[-2:]
    _, n, where, signum = first.split()
    rows = read_csv(out)
    assert int(n) == len(rows) > 1000 and where == str(out) and int(signum) == signal.SIGINT
    assert np.allclose(rows["time"], 1e-3 * np.arange(len(rows)), rtol=0, atol=1e-9)
    assert second == "again 51"   # no dangling FMU instance: the next run in the process works
    assert "Fatal" not in stderr and "Traceback" not in stderr


def test_run_refuses_an_unknown_setting_by_name(built):
    from cranefmu.errors import SettingsError
    from cranefmu.master.run import run

    with pytest.raises(SettingsError, match="step is not a run setting: one of .*step_size"):
        run("elastic_pendulum", step=1e-3)
