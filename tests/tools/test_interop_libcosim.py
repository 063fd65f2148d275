"""libcosim (the Open Simulation Platform's master, through libcosimpy) as a tested host of every scene
and every parameter set, as loaded: nothing handed over.  The built .ssp carries each set's settled
start (cranefmu.settled_start), libcosim reads the default set from the component bindings, and a
named set reaches it through ``cranefmu export``; with those, libcosim's plain Jacobi equals our
``jacobi-plain`` over 2 s (docs/interop.md)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.master.scene import read_scene_folder
from cranefmu.scenes import SCENES
from cranefmu.studies.hosts import (AGREEMENT_SPAN, agreement_step, scene_file, scene_variants, worst_relative)

pytest.importorskip("libcosimpy")

SCENE_NAMES = [d.name for d in b.scene_dirs()]
H = 1e-3


def _libcosim(ssp: str, steps: int, columns: list[str]) -> dict:
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import libcosim_run

    return in_child(libcosim_run, ssp, H, steps, columns)


@pytest.mark.parametrize("scene", SCENE_NAMES)
def test_every_scene_runs_in_libcosim_with_its_parameters_applied(built, scene):
    keys = list(SCENES[scene].key_outputs)
    out = _libcosim(str(b.SSP_DIR / f"{scene}.ssp"), 20, keys)
    assert out["ok"] and out["time"][-1] == pytest.approx(20 * H, rel=1e-12)
    ours = read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR).parameters
    read_back = {k: out["parameters"][k] for k in ours}
    assert read_back == ours    # the very values, switches as their Integer codes
    for k in keys:
        assert np.all(np.isfinite(out[k])), k


@pytest.mark.parametrize("scene,parameter_set", scene_variants())
def test_libcosim_as_loaded_equals_our_plain_jacobi(built, scene, parameter_set):
    """The file as it is (the built .ssp, or the export of a named set): libcosim's fixed-step Jacobi
    (outputs read once right after each step) and our ``jacobi-plain`` agree on every key output
    to 1e-9 of its range over 2 s (measured: to the last bit or within 5e-16).  Fails without the
    settled start in the file: libcosim's initialization (one exchange sweep per simulator) leaves
    elastic_pendulum's rope unloaded (2.3e-2) and truck_telescope's hook 0.2 m beside the tip."""
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import libcosim_timed

    from cranefmu.master.run import run

    h = agreement_step(scene)
    keys = list(SCENES[scene].key_outputs)
    ours = run(scene, parameter_set=parameter_set, stop_time=AGREEMENT_SPAN, step_size=h, algorithm="jacobi-plain",
               extrapolation=0, progress=False).result
    theirs = in_child(libcosim_timed, keys, AGREEMENT_SPAN, scene_file(scene, parameter_set), h)
    assert theirs["ok"] and len(theirs["time"]) == len(ours) - 1
    np.testing.assert_allclose(ours["time"][1:], theirs["time"], rtol=1e-12)
    worst = worst_relative(ours, theirs, keys)
    assert max(worst.values()) <= 1e-9, worst


def _first_step(ssp: str, columns: list[str]) -> dict:
    out = _libcosim(ssp, 1, columns)
    assert out["ok"]
    return {**{k: out[k][0] for k in columns}, **out["parameters"]}


def test_exported_mass_starts_elastic_pendulum_at_rest_in_libcosim(built):
    """``cranefmu export elastic_pendulum --set pendulum.mass=1500`` loaded in libcosim: the rope
    carries T(0) = m g cos(theta0) (radial equilibrium of the released load) to 1e-6 after the first
    step; the default file gives the default mass's tension (a check that the mass reached it)."""
    cols = ["rope.tension", "pendulum.theta", "pendulum.vx", "pendulum.vy"]
    for mass in (1500.0, None):
        y = _first_step(scene_file("elastic_pendulum", None, {"pendulum.mass": mass} if mass else None), cols)
        m = mass or 1000.0
        assert y["pendulum.mass"] == m
        expected = m * y["pendulum.g"] * math.cos(y["pendulum.theta0"])
        assert y["rope.tension"] == pytest.approx(expected, rel=1e-6)
        # released at rest in radial equilibrium: after one step the load moves along the swing's
        # tangent only (g sin(theta0) h); unsettled, it would fall radially by g cos(theta0) h = 1e-2 m/s
        theta = y["pendulum.theta"]
        radial = y["pendulum.vx"] * math.sin(theta) - y["pendulum.vy"] * math.cos(theta)
        assert abs(radial) <= 1e-6 * y["pendulum.g"] * H
        tangential = y["pendulum.vx"] * math.cos(theta) + y["pendulum.vy"] * math.sin(theta)
        assert -tangential == pytest.approx(y["pendulum.g"] * math.sin(y["pendulum.theta0"]) * H, rel=1e-3)


def test_exported_mass_starts_truck_telescope_at_rest_in_libcosim(built):
    """``cranefmu export truck_telescope --set pendulum.mass=3000`` loaded in libcosim: the hook hangs
    under the boom tip (horizontal offset below 1e-6 of the reach), the rope carries the load's weight
    and the outriggers carry the total weight (chassis + boom + load), each to 1e-6."""
    cols = ["pendulum.x", "boom.x_tip", "rope.tension", "chassis.N_front", "chassis.N_rear"]
    y = _first_step(scene_file("truck_telescope", None, {"pendulum.mass": 3000.0}), cols)
    assert y["pendulum.mass"] == 3000.0
    assert abs(y["pendulum.x"] - y["boom.x_tip"]) <= 1e-6 * abs(y["boom.x_tip"])
    g = y["pendulum.g"]
    assert y["rope.tension"] == pytest.approx(3000.0 * g, rel=1e-6)   # the force on the hook, all falls
    boom = sum(y[f"boom.{m}"] for m in ("m_head", "m_seg3", "m_seg4", "m_seg5"))
    total = (y["chassis.m_body"] + y["chassis.m_platform"] + boom + 3000.0) * g
    assert y["chassis.N_front"] + y["chassis.N_rear"] == pytest.approx(total, rel=1e-6)
