"""Parameter values typed with a unit where a person sets them: ``cranefmu run --set``, ``run(parameters=)``
(through ``resolve``) and an experiment's ``set``; converted to the declared unit, a wrong unit refused in one line."""
from __future__ import annotations

from pathlib import Path

import pytest

from cli_process import cranefmu
from cranefmu.errors import CraneFmuError
from cranefmu.experiments.runner import prepare
from cranefmu.master.runspec import resolve

DEG = 0.017453292519943295   # rad per deg, as units.py holds it: 10 deg is 10 * DEG bit for bit


def test_cli_set_in_degrees_runs_bit_for_bit_like_radians(tmp_path):
    deg, rad = tmp_path / "deg.csv", tmp_path / "rad.csv"
    a = cranefmu("run", "hook_sway", "--set", "pendulum.theta0=10 deg", "--stop-time", "0.2", "--output", str(deg))
    b = cranefmu("run", "hook_sway", "--set", f"pendulum.theta0={10 * DEG!r}", "--stop-time", "0.2", "--output", str(rad))
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    assert deg.read_bytes() == rad.read_bytes()
    rows = deg.read_text().splitlines()
    theta = rows[0].split(",").index("pendulum.theta")
    assert float(rows[1].split(",")[theta]) == pytest.approx(10 * DEG, rel=1e-12)   # started at 10 deg


def test_cli_set_with_a_wrong_unit_is_one_line(tmp_path):
    r = cranefmu("run", "hook_sway", "--set", "pendulum.theta0=10 kN", "--stop-time", "0.2")
    assert r.returncode != 0
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert lines == ["cranefmu: error: pendulum.theta0 = '10 kN' is not allowed: pendulum.theta0 is in rad, "
                     "'kN' does not measure that"]


def test_api_parameters_take_units_and_plain_numbers_stay_si():
    spec = resolve("hook_sway", parameters={"pendulum.theta0": "10 deg", "pendulum.mass": "2.5 t",
                                            "boom.luff_angle": 0.9})
    assert spec.overrides[("pendulum", "theta0")] == 10 * DEG
    assert spec.overrides[("pendulum", "mass")] == 2500.0
    assert spec.overrides[("boom", "luff_angle")] == 0.9
    with pytest.raises(CraneFmuError, match=r"^pendulum.mass = '2.5 m' is not allowed: pendulum.mass is in kg"):
        resolve("hook_sway", parameters={"pendulum.mass": "2.5 m"})


EXPERIMENT = """name = "units"
scene = "elastic_pendulum"
stop_time = 0.2
set = {{"pendulum.theta0" = "{theta0}", "pendulum.mass" = "{mass}"}}

[[assert]]
name = "sway_bounded"
column = "pendulum.theta"
max = "pendulum.theta0 * 1.0001"
"""


def test_experiment_set_takes_units_into_the_run_and_its_expressions(tmp_path):
    path = tmp_path / "units.toml"
    path.write_text(EXPERIMENT.format(theta0="10 deg", mass="0.5 t"))
    (planned,) = prepare([path])
    assert planned.spec.overrides[("pendulum", "theta0")] == 10 * DEG
    assert planned.spec.overrides[("pendulum", "mass")] == 500.0
    assert planned.values["pendulum.theta0"] == 10 * DEG     # what the assertion's limit reads


@pytest.mark.parametrize("theta0, mass, says", [
    ("10 kN", "0.5 t", "set: pendulum.theta0 = '10 kN' is not allowed: pendulum.theta0 is in rad, 'kN' does not "
                       "measure that"),
    ("10 deg", "0.5 m", "set: pendulum.mass = '0.5 m' is not allowed: pendulum.mass is in kg"),
    ("10 degree", "0.5 t", "set: pendulum.theta0 = '10 degree' is not allowed: a number (SI) or a number with a unit"),
])
def test_experiment_set_with_a_wrong_unit_names_file_and_line(tmp_path, theta0, mass, says):
    path = tmp_path / "units.toml"
    path.write_text(EXPERIMENT.format(theta0=theta0, mass=mass))
    with pytest.raises(CraneFmuError) as err:
        prepare([path])
    assert str(err.value).startswith(f"{path}:4: {says}"), str(err.value)


def test_export_set_takes_units(tmp_path):
    import zipfile

    out = tmp_path / "v.ssp"
    r = cranefmu("export", "hook_sway", "--set", "pendulum.theta0=10 deg", "--output", str(out))
    assert r.returncode == 0, r.stderr
    ssv = zipfile.ZipFile(out).read("resources/default.ssv").decode()
    block = ssv[ssv.index('name="pendulum.theta0"'):]
    assert float(block.split('value="', 1)[1].split('"', 1)[0]) == 10 * DEG
