"""Figures carry units: labels `quantity [unit]`, angles in degrees, one axis per unit (issue 17)."""
import math

import numpy as np
import pytest

from cranefmu.master.plot import axis_label, by_unit, make_figure, write_plots
from cranefmu.master.scene import load_scene, output_units

UNITS = {"a.F": "N", "b.F": "N", "c.x": "m", "p.theta": "rad", "p.omega": "rad/s"}


def _result(n: int = 11) -> np.ndarray:
    t = np.linspace(0.0, 1.0, n)
    result = np.zeros(n, dtype=[("time", float), *[(c, float) for c in UNITS]])
    result["time"] = t
    for k, c in enumerate(UNITS):
        result[c] = (k + 1) * t
    return result


def test_output_units_of_a_scene_come_from_the_fmus(built, tmp_path):
    from cranefmu.build import SSP_DIR

    units = output_units(load_scene(SSP_DIR / "elastic_pendulum.ssp", tmp_path))
    assert units["rope.tension"] == "N"
    assert units["pendulum.theta"] == "rad"
    assert units["pendulum.x"] == "m"


def test_axis_label_is_quantity_and_unit_with_angles_in_degrees():
    assert axis_label(["a.F", "b.F"], UNITS) == "F [N]"
    assert axis_label(["c.x"], UNITS) == "x [m]"
    assert axis_label(["p.theta"], UNITS) == "theta [deg]"
    assert axis_label(["p.omega"], UNITS) == "omega [deg/s]"
    assert axis_label(["bond.hook.E"], UNITS) == "hook.E [J]"
    assert axis_label(["d.flag"], UNITS) == "flag [1]"
    assert by_unit(["a.F", "c.x", "b.F", "p.theta"], UNITS) == [["a.F", "b.F"], ["c.x"], ["p.theta"]]


def test_mixed_units_get_one_axis_each_and_angles_are_plotted_in_degrees():
    result = _result()
    fig = make_figure(result, "mixed", ["a.F", "p.theta", "b.F", "c.x"], UNITS)
    axes = fig.axes
    assert [ax.get_ylabel() for ax in axes] == ["F [N]", "theta [deg]", "x [m]"]
    assert axes[-1].get_xlabel() == "time [s]"
    lines = {line.get_label(): line for ax in axes for line in ax.get_lines()}
    assert set(lines) == {"a.F", "p.theta", "b.F", "c.x"}
    theta = lines["p.theta"].get_ydata()
    assert theta[-1] == pytest.approx(math.degrees(result["p.theta"][-1]), rel=1e-12)  # 4 rad -> 229.18 deg
    assert lines["a.F"].get_ydata()[-1] == result["a.F"][-1]                            # not converted
    assert len(fig.axes[0].get_lines()) == 2   # both forces share the N axis


def test_write_plots_writes_one_png_per_group(tmp_path):
    paths = write_plots(_result(), "nosuchscene", tmp_path / "r", [("Forces", ["a.F", "b.F"]), ("Sway", ["p.theta"])],
                        units=UNITS)
    assert [p.name for p in paths] == ["r_forces.png", "r_sway.png"]
    assert all(p.read_bytes()[:4] == b"\x89PNG" for p in paths)


def test_plot_module_does_not_import_the_crane_scenes():
    import subprocess
    import sys

    code = ("import sys, numpy as np, cranefmu.master.plot as p; "
            "r = np.zeros(3, dtype=[('time', float), ('a.F', float)]); p.make_figure(r, 't', ['a.F'], {}); "
            "print(sorted(m for m in sys.modules if m.startswith('cranefmu') and not m.startswith('cranefmu.master')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "['cranefmu', 'cranefmu.errors', 'cranefmu.version']"   # version: a leaf
