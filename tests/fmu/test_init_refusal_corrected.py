"""A parameter refused at fmi2EnterInitializationMode and corrected before fmi2ExitInitializationMode: the
pythonfmu FMU initializes and computes its outputs from the corrected value (it kept the enter-time error
and never refreshed its outputs again; the native FMU's twin test is in tests/native/test_fmi_layer.py)."""
from __future__ import annotations

import subprocess
import sys

SCRIPT = r"""
import sys
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
fmu = sys.argv[1]
md = read_model_description(fmu)
vr = {v.name: v.valueReference for v in md.modelVariables}
slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu), modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="rope")
slave.instantiate()
slave.setupExperiment(startTime=0.0)
slave.setReal([vr["E"]], [-1.0])
slave.enterInitializationMode()
slave.setReal([vr["E"], vr["y_hook"], vr["zeta"]], [1.0e11, -10.01, 0.0])
slave.exitInitializationMode()
print(slave.getReal([vr["tension"]])[0])
slave.terminate()
slave.freeInstance()
"""


def test_a_value_corrected_before_the_end_of_initialization_is_taken(built):
    out = subprocess.run([sys.executable, "-c", SCRIPT, str(built / "Rope.fmu")], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    # E A / L x 0.01 m: 1e11 * 5.655e-5 / 10 * 0.01 = 5655 N (was 0.0: the outputs were never computed)
    assert abs(float(out.stdout.split()[-1]) - 5655.0) < 1e-6
