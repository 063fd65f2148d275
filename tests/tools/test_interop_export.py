"""``cranefmu export``: one variant of a scene as a self-contained .ssp (docs/interop.md, docs/cli.md)."""
from __future__ import annotations

import zipfile

import numpy as np
import pytest

from cranefmu.errors import CraneFmuError, ParameterSetError, SceneError
from cranefmu.export import export_scene
from cranefmu.master.extracted import extracted_scene


def test_export_holds_one_bound_set_with_the_changes_and_its_settled_start(built, tmp_path):
    """truck_telescope, set luff45, pendulum.mass changed: one .ssv, bound by the System and by each
    component (bare names), holding the set's values, the change and every connected input's settled
    start; our master running the file equals our master running the scene with the same set and change
    (the start values of inputs are ignored by ours, the rest is the same variant), bit for bit."""
    from cranefmu.master.run import run

    path = export_scene("truck_telescope", tmp_path / "t.ssp", "luff45", {"pendulum.mass": "3000"})
    with zipfile.ZipFile(path) as zf:
        names = zf.namelist()
        ssd = zf.read("SystemStructure.ssd").decode()
    assert [n for n in names if n.endswith(".ssv")] == ["resources/default.ssv"]
    assert '<ssv:Parameter name="mass">' in ssd and "<ssd:ParameterBinding>" in ssd
    loaded = extracted_scene(path)[1]
    assert not loaded.sets and loaded.parameters["pendulum.mass"] == 3000.0
    assert loaded.parameters["boom.luff_angle"] == pytest.approx(np.radians(45.0), rel=1e-12)
    assert {f"{c.dst}.{c.dst_var}" for c in loaded.connections} <= set(loaded.parameters)
    assert loaded.parameters["rope.load"] == pytest.approx(3000.0 * 9.81, rel=1e-12)
    kw = dict(stop_time=0.05, step_size=1e-3, algorithm="jacobi-plain", extrapolation=0, progress=False)
    mine = run(str(path), **kw).result
    ours = run("truck_telescope", parameter_set="luff45", parameters={"pendulum.mass": 3000.0}, **kw).result
    for name in ours.dtype.names:
        np.testing.assert_array_equal(mine[name], ours[name], err_msg=name)


def test_export_of_a_set_takes_the_settings_it_stores(built, tmp_path):
    """overhead_lift's loose set stores every bond implicit over the scene's settings: its export has
    them as its own (and no settings of sets it does not hold); the default set's export has the scene's."""
    loose = extracted_scene(export_scene("overhead_lift", tmp_path / "loose.ssp", "loose"))[1]
    assert loose.settings["implicit"] == ["hook", "drum", "trolley"] and not loose.set_settings
    plain = extracted_scene(export_scene("overhead_lift", tmp_path / "default.ssp"))[1]
    assert "implicit" not in plain.settings and not plain.set_settings
    assert {k: v for k, v in loose.settings.items() if k != "implicit"} == plain.settings


@pytest.mark.parametrize("scene,parameter_set,changes,error,match", [
    ("nowhere", None, {}, SceneError, "scene 'nowhere' is not allowed: one of"),
    ("elastic_pendulum", "heavy", {}, ParameterSetError, "parameter set 'heavy' is not in scene"),
    ("elastic_pendulum", None, {"rope.load": "1"}, ParameterSetError, "rope.load is not allowed.*pendulum.rest_tension"),
    ("elastic_pendulum", None, {"rope.nothing": "1"}, ParameterSetError, "rope.nothing is not allowed.*no variable"),
    ("elastic_pendulum", None, {"pendulum.mass": "heavy"}, ParameterSetError, "pendulum.mass = 'heavy' is not a valid Real"),
    ("elastic_pendulum", None, {"pendulum.mass": "-1"}, CraneFmuError, r"pendulum.mass = -1.0 is out of range"),
])
def test_export_refuses_bad_input_by_name(built, tmp_path, scene, parameter_set, changes, error, match):
    with pytest.raises(error, match=match):
        export_scene(scene, tmp_path / "x.ssp", parameter_set, changes)
    assert not (tmp_path / "x.ssp").exists()


def test_export_refuses_an_output_that_is_not_an_ssp_file(built, tmp_path):
    with pytest.raises(CraneFmuError, match="--output .* ending in .ssp"):
        export_scene("elastic_pendulum", tmp_path / "x.zip")
    with pytest.raises(CraneFmuError, match="does not exist"):
        export_scene("elastic_pendulum", tmp_path / "no" / "x.ssp")


def test_export_command_line(built, tmp_path):
    from cranefmu.cli import main

    target = tmp_path / "lift.ssp"
    assert main(["export", "overhead_lift", "--parameter-set", "loose", "--set", "pendulum.mass=4000",
                 "--output", str(target)]) == 0
    loaded = extracted_scene(target)[1]
    assert loaded.parameters["rope.start_slack"] == 0.1 and loaded.parameters["pendulum.mass"] == 4000.0
    assert main(["export", "overhead_lift", "--set", "pendulum.mass", "--output", str(target)]) == 2
