"""fmpy's ``simulate_ssp`` as a host of every scene: it runs them all (no String parameters left:
the switches are Integers) with the scene's parameters, passed as its ``parameter_set`` because it
applies no binding of the SSD.  Its difference from our master is a known one: every connector
starts at 0.0 and there is no initialization exchange, so the first step runs with zero inputs."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.master.scene import read_scene_folder
from cranefmu.scenes import SCENES

SCENE_NAMES = [d.name for d in b.scene_dirs()]
H = 1e-3


def _fmpy(scene: str, stop: float) -> dict:
    from fmu_child import in_child
    from interop_hosts import fmpy_run

    parameters = read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR).parameters
    return in_child(fmpy_run, str(b.SSP_DIR / f"{scene}.ssp"), H, stop, parameters), parameters


@pytest.mark.parametrize("scene", SCENE_NAMES)
def test_every_scene_runs_in_fmpy_simulate_ssp_with_its_parameters(built, scene):
    out, parameters = _fmpy(scene, 10 * H)
    assert out["parameters"] == parameters
    result = out["result"]
    assert len(result["time"]) == 10
    connected = [k for k in SCENES[scene].key_outputs if k in result]
    for k in connected:
        assert np.all(np.isfinite(result[k])), k


def test_fmpy_first_step_runs_with_zero_inputs(built):
    """elastic_pendulum: fmpy's pendulum falls freely in the first step (rope force input 0.0, not the
    initialized 9.7 kN), so its vertical velocity after one step is -g h and ours differs by exactly
    h F_y(0) / m (a constant force on a point mass).  fmpy labels each row with the time at the start
    of the step that produced it: its row k is our row k + 1."""
    from cranefmu.master.run import run

    out, parameters = _fmpy("elastic_pendulum", 3 * H)
    theirs = out["result"]
    ours = run("elastic_pendulum", stop_time=3 * H, step_size=H, algorithm="jacobi", extrapolation=0).result
    assert theirs["time"][0] == 0.0 and theirs["pendulum.vy"][0] == pytest.approx(-9.81 * H, rel=1e-12)
    force, mass = ours["rope.Fy_hook"][0], parameters["pendulum.mass"]
    assert force > 9e3
    assert ours["pendulum.vy"][1] - theirs["pendulum.vy"][0] == pytest.approx(H * force / mass, rel=1e-9)
