"""fmpy's ``simulate_ssp`` as a host of every scene.  It applies no binding of the SSD itself: it gets
the file's own set as its ``parameter_set`` (read from the file: the settled start included), so the
FMUs start settled.  What the file cannot change: fmpy sets every connector to 0.0 and feeds those
zeros to the inputs at the first step (no initialization exchange), so the first step runs with zero
inputs and the run then differs from ours by the kick of that step (docs/interop.md; measured in
benchmarks/results/interop_difference.md)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.master.extracted import extracted_scene
from cranefmu.scenes import SCENES
from cranefmu.studies.hosts import scene_file

SCENE_NAMES = [d.name for d in b.scene_dirs()]
H = 1e-3


def _fmpy(ssp: str, stop: float) -> tuple[dict, dict]:
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import fmpy_run

    loaded = extracted_scene(Path(ssp))[1]
    parameters = loaded.parameters          # the file's default set, with its settled start
    return in_child(fmpy_run, ssp, H, stop, parameters), loaded


@pytest.mark.parametrize("scene", SCENE_NAMES)
def test_every_scene_runs_in_fmpy_simulate_ssp_with_the_files_parameters(built, scene):
    out, loaded = _fmpy(scene_file(scene), 10 * H)
    inputs = {f"{c.dst}.{c.dst_var}" for c in loaded.connections}
    assert {k for k in loaded.parameters} & inputs == inputs    # the file carries every connected input's start
    parameters = {k: v for k, v in loaded.parameters.items() if k not in inputs}   # inputs change as it runs
    assert {k: out["parameters"][k] for k in parameters} == parameters
    result = out["result"]
    assert len(result["time"]) == 10
    for k in [k for k in SCENES[scene].key_outputs if k in result]:
        assert np.all(np.isfinite(result[k])), k


def test_fmpy_first_step_runs_with_zero_inputs(built):
    """elastic_pendulum: the pendulum starts settled (the file's start values reach the FMUs), but
    fmpy feeds its connectors' 0.0 at the first step, so the load falls freely in that step: its
    vertical velocity after one step is -g h, and ours differs by exactly h F_y(0) / m.  fmpy labels
    each row with the time at the start of the step that produced it: its row k is our row k + 1."""
    from cranefmu.master.run import run

    out, loaded = _fmpy(scene_file("elastic_pendulum"), 3 * H)
    theirs = out["result"]
    ours = run("elastic_pendulum", stop_time=3 * H, step_size=H, algorithm="jacobi-plain", extrapolation=0).result
    assert theirs["time"][0] == 0.0 and theirs["pendulum.vy"][0] == pytest.approx(-9.81 * H, rel=1e-12)
    force, mass = ours["rope.Fy_hook"][0], loaded.parameters["pendulum.mass"]
    assert force > 9e3
    assert ours["pendulum.vy"][1] - theirs["pendulum.vy"][0] == pytest.approx(H * force / mass, rel=1e-9)
    # the swing angle (a state: no input reaches it in one step) is ours to round-off
    assert theirs["pendulum.theta"][0] == pytest.approx(ours["pendulum.theta"][1], rel=1e-9)


def test_fmpy_starts_the_truck_hook_under_the_tip(built):
    """truck_telescope from the file's own set: the hook starts under the boom tip as our initialization
    placed it (without the settled start in the file fmpy started it 5.25 m away); the zero-input
    first step only lets it fall freely for that step."""
    from cranefmu.master.run import run

    out, _ = _fmpy(scene_file("truck_telescope"), 2 * H)
    theirs = out["result"]
    ours = run("truck_telescope", stop_time=2 * H, step_size=H, algorithm="jacobi-plain", extrapolation=0).result
    reach = abs(ours["boom.x_tip"][0])
    assert abs(theirs["pendulum.x"][0] - ours["boom.x_tip"][0]) <= 1e-6 * reach
    # the zero-input step: the hook falls freely for one step, g h^2 / 2 below ours
    assert theirs["pendulum.y"][0] - ours["pendulum.y"][1] == pytest.approx(-9.81 * H * H / 2, rel=1e-2)
