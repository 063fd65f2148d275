"""libcosim (the Open Simulation Platform's master, through libcosimpy) as a tested host of every scene:
the .ssp loads, runs, and every parameter of the scene is applied (libcosim reads only the
component-level bindings the build generates).  With our plain-Jacobi mode the trajectories agree."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.master.scene import read_scene_folder
from cranefmu.scenes import SCENES

pytest.importorskip("libcosimpy")

SCENE_NAMES = [d.name for d in b.scene_dirs()]
H = 1e-3


def _libcosim(scene: str, steps: int, columns: list[str]) -> dict:
    from fmu_child import in_child
    from interop_hosts import libcosim_run

    return in_child(libcosim_run, str(b.SSP_DIR / f"{scene}.ssp"), H, steps, columns)


@pytest.mark.parametrize("scene", SCENE_NAMES)
def test_every_scene_runs_in_libcosim_with_its_parameters_applied(built, scene):
    keys = list(SCENES[scene].key_outputs)
    out = _libcosim(scene, 20, keys)
    assert out["ok"] and out["time"][-1] == pytest.approx(20 * H, rel=1e-12)
    ours = read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR).parameters
    read_back = {k: out["parameters"][k] for k in ours}
    assert read_back == ours    # the very values, switches as their Integer codes
    for k in keys:
        assert np.all(np.isfinite(out[k])), k


def _plain_jacobi_available() -> bool:
    try:
        from cranefmu.master.algorithms import ALGORITHMS
    except ImportError:
        from cranefmu.master.run import ALGORITHMS
    return "jacobi-plain" in ALGORITHMS


# libcosim's initialization does not settle a loop through feedthrough outputs (measured at 0.11.2):
# overhead_lift starts with a rope force of 145.9 N on the hook instead of the 294.3 N equilibrium
# (rope top 11.00006 m, not 11.0000269 m), truck_telescope's sway angle is off by 1.1e-6 relative
# after the first step (benchmarks/results/interop_difference.md).  Strict: a pass is news.
_UNSETTLED_START = pytest.mark.xfail(strict=True, reason="libcosim starts from unsettled connection values")
# Since the start state is derived at initialization (the pendulum hands the load to the rope,
# docs/equilibrium.md), elastic_pendulum's rope also starts unloaded in libcosim: its hook sinks
# 4.9e-6 m more in the first step and the swing drifts 5e-7 relative in 200 steps.
AGREEING = [s if s not in ("overhead_lift", "truck_telescope", "elastic_pendulum")
            else pytest.param(s, marks=_UNSETTLED_START)
            for s in SCENE_NAMES]


@pytest.mark.skipif(not _plain_jacobi_available(), reason="algorithm 'jacobi-plain' not merged yet")
@pytest.mark.parametrize("scene", AGREEING)
def test_libcosim_trajectories_equal_our_plain_jacobi(built, scene):
    """libcosim's fixed-step algorithm reads each output once, right after the step (no re-read
    of direct-feedthrough outputs after the inputs are set): our "jacobi-plain" does the same, so
    the key outputs agree to 1e-9 relative over 200 steps (libcosim reports no row at t = 0)."""
    from cranefmu.master.run import run

    steps = 200
    keys = list(SCENES[scene].key_outputs)
    theirs = _libcosim(scene, steps, keys)
    ours = run(scene, stop_time=steps * H, step_size=H, algorithm="jacobi-plain").result
    np.testing.assert_allclose(ours["time"][1:], theirs["time"], rtol=1e-12)
    for k in keys:
        scale = max(float(np.max(np.abs(ours[k]))), 1e-300)
        assert np.max(np.abs(ours[k][1:] - np.asarray(theirs[k]))) <= 1e-9 * scale, k
