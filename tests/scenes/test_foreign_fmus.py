"""Our master on scenes it did not write: a scene of one FMU, a hand-written SSP of our Rope and
Pendulum without annotations (power bonds inferred by unit, so the instability alarm watches it),
and the inferred bonds of every shipped scene (docs/foreign_fmus.md)."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu.errors import SimulationError
from cranefmu.master.run import run
from cranefmu_support.foreign_ssp import ROPE_PENDULUM, ROPE_PENDULUM_PARAMETERS, write_ssp

LENGTH, E, AREA, DELTA = 10.0, 1e11, 5.655e-5, 0.01


def test_a_scene_of_one_fmu_runs(built, tmp_path):
    """The Rope alone, its hook held 1 cm below the unstretched length: T = E A / L delta at every row
    (before: 'need at least one array to concatenate' in initialization)."""
    ssp = write_ssp(tmp_path / "rope_alone.ssp", {"rope": built / "Rope.fmu"}, [],
                    {"rope.length": LENGTH, "rope.E": E, "rope.A": AREA, "rope.zeta": 0.0})
    res = run(ssp, stop_time=0.1, step_size=0.01, parameters={"rope.y_hook": -(LENGTH + DELTA)}, progress=False)
    assert res.rows == 11 and res.stats.init_iterations == 0
    assert np.allclose(res.result["rope.tension"], E * AREA / LENGTH * DELTA, rtol=1e-12, atol=0.0)


def test_a_stiff_hand_written_scene_trips_the_alarm_through_inferred_bonds(built, tmp_path):
    """elastic_pendulum's wiring written by hand, rope 10x stiffer, 10 ms steps: the explicit coupling
    is unstable.  Measured before the bonds were inferred: it ran to the end, the rope slack in 138
    of 301 rows and 232 kN peaks (static 9.81 kN), printing nothing.  Now the bond rope-pendulum,
    inferred from Fx_hook [N] -> Fx_rope with vx [m/s] -> vx_hook, stops it."""
    ssp = write_ssp(tmp_path / "stiff.ssp", {"rope": built / "Rope.fmu", "pendulum": built / "Pendulum.fmu"},
                    ROPE_PENDULUM, {**ROPE_PENDULUM_PARAMETERS, "rope.E": 1e12})
    with pytest.raises(SimulationError) as err:
        run(ssp, stop_time=3.0, step_size=0.01, progress=False)
    msg = str(err.value)
    assert "power bond rope-pendulum (between rope and pendulum)" in msg and "unstable" in msg, msg
    rows = err.value.result
    assert rows["time"][-1] < 3.0 and "bond.rope-pendulum.dE" in rows.dtype.names
    # without the alarm the same run goes on to the nonsense measured before
    res = run(ssp, stop_time=3.0, step_size=0.01, progress=False, instability_alarm=False)
    assert res.rows == 301 and res.result["rope.tension"].max() > 10 * 9.81 * 1000.0


@pytest.mark.parametrize("scene", ["elastic_pendulum", "hook_sway", "overhead_lift", "truck_telescope"])
def test_inferred_bonds_pair_what_each_scene_declares(built, scene):
    """Every declared bond's force/velocity pairs are inferred from the connections' units alone
    (the signs aside: truck_telescope's foot_tilt counts the moment against the rotation)."""
    from fmpy import read_model_description

    from cranefmu import build as b
    from cranefmu.master.bond_inference import infer_bonds
    from cranefmu.master.scene import read_scene_folder
    from cranefmu.sources import scene_dirs

    folder = next(d for d in scene_dirs() if d.name == scene)
    s = read_scene_folder(folder, b.FMU_DIR)
    mds = {c.name: read_model_description(str(c.fmu), validate=False) for c in s.components}

    def pairs(bonds):
        return {frozenset((side["component"], f, v) for side in sides
                          for f, v in zip(side["force"].split(), side["velocity"].split())) for _, sides in bonds}

    assert s.bonds and pairs(infer_bonds(s, mds)) == pairs(s.bonds)


def test_info_shows_inferred_bonds(built, tmp_path):
    from cranefmu.master.scene import load_scene
    from cranefmu.scenes.info import describe

    ssp = write_ssp(tmp_path / "hand.ssp", {"rope": built / "Rope.fmu", "pendulum": built / "Pendulum.fmu"},
                    ROPE_PENDULUM, ROPE_PENDULUM_PARAMETERS)
    lines = describe(load_scene(ssp, tmp_path / "x"))
    assert "  power bonds, inferred from the connections' units (the scene declares none):" in lines
    assert ("    rope-pendulum: rope force Fx_hook Fy_hook Fz_hook / velocity vx_hook vy_hook vz_hook <-> "
            "pendulum force Fx_rope Fy_rope Fz_rope / velocity vx vy vz") in lines


def test_an_inferred_bond_can_be_coupled_implicitly(built, tmp_path):
    """implicit = the inferred bond's name: the stiff hand-written scene of the alarm test runs its 3 s
    at 10 ms with the rope taut, the tension within 1.5 % of static (load 1000 kg at 5 deg)."""
    ssp = write_ssp(tmp_path / "stiff.ssp", {"rope": built / "Rope.fmu", "pendulum": built / "Pendulum.fmu"},
                    ROPE_PENDULUM, {**ROPE_PENDULUM_PARAMETERS, "rope.E": 1e12})
    res = run(ssp, stop_time=3.0, step_size=0.01, algorithm="jacobi", implicit=["rope-pendulum"], progress=False)
    r = res.result
    assert res.rows == 301 and not r["rope.slack"].any()
    assert np.max(np.abs(r["rope.tension"] / (1000.0 * 9.81) - 1.0)) < 0.015


def test_bonds_are_settled_when_the_scene_is_read(built, tmp_path):
    """The scene a run reads (extracted once per process) carries its power bonds decided: declared
    ones as declared, a scene without any inferred from its FMUs' units there, not later by each reader."""
    from cranefmu.master.extracted import extracted_scene
    from cranefmu.master.scene_names import resolve_scene

    ssp = write_ssp(tmp_path / "plain.ssp", {"rope": built / "Rope.fmu", "pendulum": built / "Pendulum.fmu"},
                    ROPE_PENDULUM, ROPE_PENDULUM_PARAMETERS)
    _, scene = extracted_scene(ssp)
    assert scene.bonds_inferred is True and [name for name, _ in scene.bonds] == ["rope-pendulum"]
    _, declared = extracted_scene(resolve_scene("hook_sway"))
    assert declared.bonds_inferred is False and [name for name, _ in declared.bonds] == ["hook"]
