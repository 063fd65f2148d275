"""libcosim's ECCO algorithm on our scenes (the side-by-side runs of benchmarks/speed_accuracy.py):
the hand-built libcosim execution it needs equals libcosim's own SSP load, our vector power bonds
become libcosim's scalar ones per axis, and libcosim's step follows its tolerance."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.master.scene import read_scene_folder
from cranefmu.scenes import SCENES

pytest.importorskip("libcosimpy")

SCENE_NAMES = [d.name for d in b.scene_dirs()]
H = 1e-3


def test_vector_bonds_become_one_scalar_bond_per_axis():
    from cranefmu.studies.hosts import scalar_bonds

    scene = read_scene_folder(b.SSP_DIR / "truck_telescope", b.FMU_DIR)
    split = scalar_bonds(scene.bonds)
    # hook 3 axes + drum 1 + tip 3 + foot_heave 1 + the slewing moment 1 (sign -1 on both sides)
    assert len(split) == sum(len(a["force"].split()) for _, (a, _b) in scene.bonds) == 9
    assert ("hook[1]", ("rope", "Fy_hook", "vy_hook"), ("pendulum", "Fy_rope", "vy")) in split
    with pytest.raises(ValueError, match="power bond 'x'.*different signs"):
        scalar_bonds([("x", [{"component": "a", "force": "F", "velocity": "v", "sign": "1"},
                             {"component": "b", "force": "F", "velocity": "v", "sign": "-1"}])])


@pytest.mark.parametrize("scene", SCENE_NAMES)
def test_hand_built_libcosim_execution_equals_libcosims_ssp_load(built, scene):
    """Same slaves, connections and parameters as libcosim's SSP loader: 50 fixed steps agree to the bit."""
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import libcosim_run

    keys = list(SCENES[scene].key_outputs)
    ssp = str(b.SSP_DIR / f"{scene}.ssp")
    loaded = in_child(libcosim_run, ssp, H, 50, keys)
    built_here = in_child(libcosim_run, ssp, H, 50, keys, str(b.SSP_DIR / scene), str(b.FMU_DIR))
    assert loaded["ok"] and built_here["ok"]
    assert built_here["parameters"] == loaded["parameters"]
    for k in keys:
        np.testing.assert_array_equal(built_here[k], loaded[k], err_msg=k)


def test_libcosim_ecco_step_follows_its_tolerance(built):
    """elastic_pendulum, 1 s: a 100x tighter abs_tolerance takes more and smaller steps, every step
    inside [min_step, max_step], and lands closer to a fine fixed-step run (H / 10) in the swing angle.
    Both runs start from the settled start the built .ssp carries (the hand-built execution applies
    the file's values, as libcosim's SSP loader does)."""
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import libcosim_timed

    keys = ["pendulum.theta", "rope.tension"]
    stop, h = 1.0, 2e-3
    fine = in_child(libcosim_timed, keys, stop, str(b.SSP_DIR / "elastic_pendulum.ssp"), h / 10)
    runs = {}
    for tol in (1e-1, 1e-3):
        ecco = {"step": h, "min_step": h / 10, "max_step": 10 * h, "abs_tolerance": tol}
        runs[tol] = in_child(libcosim_timed, keys, stop, None, None, str(b.SSP_DIR / "elastic_pendulum"),
                             str(b.FMU_DIR), ecco)
    errors = {}
    for tol, r in runs.items():
        assert r["ok"] and r["end"] >= stop
        dt = np.diff(np.concatenate([[0.0], r["time"]]))
        assert dt.min() >= h / 10 * (1 - 1e-6) and dt.max() <= 10 * h * (1 + 1e-6)
        ref = np.interp(r["time"], fine["time"], fine["pendulum.theta"])
        errors[tol] = np.max(np.abs(r["pendulum.theta"] - ref)) / np.ptp(fine["pendulum.theta"])
    assert runs[1e-3]["steps"] > 2 * runs[1e-1]["steps"]
    assert errors[1e-3] < 0.5 * errors[1e-1]
