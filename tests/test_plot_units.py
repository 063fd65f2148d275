"""Figures carry units: column units read from the FMUs' modelDescription label the y axes."""
import numpy as np

from cranefmu.master.plot import axis_label, write_plots
from cranefmu.master.scene import load_scene, output_units


def test_output_units_of_a_scene_come_from_the_fmus(built, tmp_path):
    from cranefmu.build import SSP_DIR

    units = output_units(load_scene(SSP_DIR / "elastic_pendulum.ssp", tmp_path))
    assert units["rope.tension"] == "N"
    assert units["pendulum.theta"] == "rad"
    assert units["pendulum.x"] == "m"


def test_axis_label_names_the_shared_unit_or_each_unit():
    units = {"a.F": "N", "b.F": "N", "c.x": "m"}
    assert axis_label(["a.F", "b.F"], units) == "[N]"
    assert axis_label(["a.F", "c.x"], units) == "[N] / [m]"
    assert axis_label(["bond.hook.E"], units) == "[J]"
    assert axis_label(["d.flag"], units) == "[1]"


def test_write_plots_with_units(tmp_path):
    t = np.linspace(0.0, 1.0, 11)
    result = np.zeros(11, dtype=[("time", float), ("a.F", float), ("c.x", float)])
    result["time"], result["a.F"], result["c.x"] = t, 2 * t, t ** 2
    paths = write_plots(result, "nosuchscene", tmp_path / "r", ["a.F", "c.x"], units={"a.F": "N", "c.x": "m"})
    assert len(paths) == 1 and paths[0].read_bytes()[:4] == b"\x89PNG"
