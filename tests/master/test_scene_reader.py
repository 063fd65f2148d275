"""The one scene reader (cranefmu.master.scene): typed parameters, units to SI, component-level
bindings, and the same refusal of a bad value in the master, the monolithic reference and the build."""
from __future__ import annotations

import math

import pytest

from cranefmu import build as b
from cranefmu.errors import ParameterSetError, SceneError
from cranefmu.master.scene import load_scene, read_scene_folder, read_ssd
from cranefmu.analysis.reference import Monolith

SSD = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="t">
  <ssd:System name="t">
    <ssd:ParameterBindings><ssd:ParameterBinding source="resources/default.ssv"/></ssd:ParameterBindings>
    <ssd:Elements>
      <ssd:Component name="rope" source="resources/Rope.fmu">{component}</ssd:Component>
    </ssd:Elements>
  </ssd:System>
</ssd:SystemStructureDescription>"""
SSV = """<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0"
    name="default"><ssv:Parameters>{}</ssv:Parameters></ssv:ParameterSet>"""


def _param(name: str, kind: str, value: str, unit: str = "") -> str:
    u = f' unit="{unit}"' if unit else ""
    return f'<ssv:Parameter name="{name}"><ssv:{kind} value="{value}"{u}/></ssv:Parameter>'


def _scene(tmp_path, params: str, component: str = ""):
    (tmp_path / "SystemStructure.ssd").write_text(SSD.format(component=component))
    (tmp_path / "default.ssv").write_text(SSV.format(params))
    return read_ssd(tmp_path / "SystemStructure.ssd", tmp_path)


def test_values_are_typed_and_units_converted_to_si(tmp_path):
    s = _scene(tmp_path, _param("rope.length", "Real", "0.25", "m") + _param("rope.t_ramp", "Real", "2", "min") + _param("rope.n_lines", "Integer", "4")
               + _param("rope.zeta", "Real", "0.07") + _param("rope.flag", "Boolean", "true")
               + _param("rope.angle", "Real", "90", "deg") + _param("rope.F", "Real", "2", "kN"))
    v = s.parameters
    assert v["rope.n_lines"] == 4 and isinstance(v["rope.n_lines"], int)
    assert v["rope.angle"] == pytest.approx(math.pi / 2, rel=1e-15) and v["rope.F"] == 2000.0
    assert v["rope.flag"] is True and v["rope.zeta"] == 0.07 and v["rope.t_ramp"] == 120.0 and v["rope.length"] == 0.25


@pytest.mark.parametrize("param, needle", [
    (_param("rope.n_lines", "Integer", "1.5"), "parameter rope.n_lines = '1.5' is not a valid Integer value"),
    (_param("rope.length", "Real", "12", "furlong"), "unknown symbol 'furlong'"),
    (_param("rope.length", "Real", "long"), "rope.length = 'long' is not a valid Real value: allowed a finite"),
    (_param("rope.on", "Boolean", "maybe"), "rope.on = 'maybe' is not a valid Boolean value: allowed true or false"),
])
def test_a_bad_value_is_refused_naming_file_parameter_and_value(tmp_path, param, needle):
    with pytest.raises(ParameterSetError, match="resources/default.ssv") as err:
        _scene(tmp_path, param)
    assert needle in str(err.value)


def test_component_bindings_with_bare_names_join_the_default_set(tmp_path):
    inline = ('<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" '
              'name="p"><ssv:Parameters>{}</ssv:Parameters></ssv:ParameterSet></ssd:ParameterValues>'
              '</ssd:ParameterBinding></ssd:ParameterBindings>')
    s = _scene(tmp_path, _param("rope.length", "Real", "2"), inline.format(_param("zeta", "Real", "0.1")
                                                                            + _param("length", "Real", "2")))
    assert s.parameters == {"rope.length": 2.0, "rope.zeta": 0.1}
    with pytest.raises(ParameterSetError, match="rope.length = 3.0 contradicts 2.0"):
        _scene(tmp_path, _param("rope.length", "Real", "2"), inline.format(_param("length", "Real", "3")))


def test_an_integer_of_1_5_is_refused_by_the_reference_and_the_master_as_by_the_reader(built):
    from cranefmu.master.run import run

    with pytest.raises(ParameterSetError, match="parameter rope.n_lines = '1.5' is not a valid Integer value"):
        Monolith("elastic_pendulum", parameters={"rope.n_lines": "1.5"})
    assert Monolith("elastic_pendulum", parameters={"rope.n_lines": "2"}).models[0].p.n_lines == 2
    with pytest.raises(ParameterSetError, match="rope.n_lines = '1.5' is not a valid Integer value"):
        run("elastic_pendulum", stop_time=0.01, step_size=1e-3, parameters={"rope.n_lines": "1.5"})


@pytest.mark.parametrize("scene", [d.name for d in b.scene_dirs()])
def test_every_scene_reads_the_same_from_sources_and_from_its_ssp(built, tmp_path, scene):
    """The build, the reference (sources) and the master (.ssp) see one scene; fmpy's schema
    validation accepts every built SSD."""
    from fmpy.ssp.ssd import read_ssd as fmpy_read_ssd

    source = read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR)
    packed = load_scene(b.SSP_DIR / f"{scene}.ssp", tmp_path)
    # the .ssp adds each set's settled start: every connected input's value (cranefmu.settled_start)
    driven = {f"{c.dst}.{c.dst_var}" for c in source.connections}

    def strip(values: dict) -> dict:
        return {k: v for k, v in values.items() if k not in driven}

    assert strip(packed.parameters) == source.parameters
    # a named set's file in the .ssp is complete (the default set with the set over it: docs/interop.md)
    assert {n: strip(v) for n, v in packed.parameter_sets.items()} == {n: source.values(n) for n in source.sets}
    assert set(packed.parameters) - set(source.parameters) == driven
    assert all(set(v) - set(source.values(n)) == driven for n, v in packed.parameter_sets.items())
    assert packed.connections == source.connections and packed.bonds == source.bonds
    assert [c.name for c in packed.components] == [c.name for c in source.components]
    assert packed.stop_time == source.stop_time and packed.stop_conditions == source.stop_conditions
    assert all(c.fmu.is_file() for c in packed.components)
    assert fmpy_read_ssd(str(b.SSP_DIR / f"{scene}.ssp")).name == scene
    assert b.scene_fmus(b.SSP_DIR / scene) == sorted({b.FMU_DIR / c.fmu.name for c in packed.components})


def test_a_nested_system_is_refused(tmp_path):
    (tmp_path / "SystemStructure.ssd").write_text(SSD.format(component="").replace(
        '<ssd:Component name="rope" source="resources/Rope.fmu"></ssd:Component>', '<ssd:System name="inner"/>'))
    (tmp_path / "default.ssv").write_text(SSV.format(""))
    with pytest.raises(SceneError, match="element 'inner' is not an FMU component"):
        read_ssd(tmp_path / "SystemStructure.ssd", tmp_path)


def test_an_unknown_name_in_a_component_binding_is_refused_naming_component_and_name(built, tmp_path):
    """libcosim skips such a name with a log line; our tools refuse the scene."""
    from cranefmu.master.run import run
    from scene_edit import edit_ssp

    first = '<ssv:Parameter name="length">'
    ssp = edit_ssp(tmp_path / "unknown.ssp", ssd=lambda text: text.replace(
        first, '<ssv:Parameter name="stiffnes"><ssv:Real value="1"/></ssv:Parameter>' + first, 1))
    with pytest.raises(ParameterSetError, match=r"rope\.stiffnes does not exist in Rope"):
        run(ssp, stop_time=0.01, step_size=1e-3)


def test_switches_take_their_names_or_codes_in_the_master(built):
    """rope.model as the FMU's Integer code or as its name (listed in the model description)."""
    from cranefmu.master.run import run

    by_name = run("elastic_pendulum", stop_time=0.02, step_size=1e-2, parameters={"rope.model": "bouc_wen"}).result
    by_code = run("elastic_pendulum", stop_time=0.02, step_size=1e-2, parameters={"rope.model": 1}).result
    kelvin = run("elastic_pendulum", stop_time=0.02, step_size=1e-2).result
    assert by_name.tobytes() == by_code.tobytes() and kelvin.tobytes() != by_name.tobytes()
    with pytest.raises(ParameterSetError, match="rope.model = 'maxwell' is not a valid Integer value: allowed "
                                                r"kelvin_voigt \(= 0\), bouc_wen \(= 1\)"):
        run("elastic_pendulum", stop_time=0.02, step_size=1e-2, parameters={"rope.model": "maxwell"})


def test_info_shows_units_and_each_set_as_its_changes_from_default(built, tmp_path):
    from cranefmu.scenes.info import describe

    lines = describe(load_scene(b.SSP_DIR / "truck_telescope.ssp", tmp_path))
    text = "\n".join(lines)
    assert "    rope.E = 140000000000.0 Pa" in lines and "    rope.run_length = 9.0 m" in lines and "    pendulum.start = 1 (below_top)" in lines
    assert "    rope.n_lines = 2" in lines and "    boom.t_acc = 3.0 s" in lines
    # luff30.ssv repeats 11 default values; only the two it changes are shown
    i = lines.index("  parameter set luff30: 2 change(s) from default:")
    assert lines[i + 1:i + 3] == ["    boom.luff_angle: 1.0471975511965976 rad -> 0.5235987755982988 rad",
                                  "    drive.payout_speed: 1.212435565298214 m/s -> 0.6999999999999998 m/s"]
    # the load is stated once (the pendulum's mass): the rope and the hook's drop follow from it
    i = lines.index("  parameter set load3500: 1 change(s) from default:")
    assert lines[i + 1] == "    pendulum.mass: 2500.0 kg -> 3500.0 kg"



@pytest.mark.parametrize("scene", [d.name for d in b.scene_dirs()])
def test_every_ssv_unit_has_the_dimension_of_the_fmu_variable(built, scene):
    """A value's .ssv unit is converted to SI by the reader; it must measure what the FMU's
    variable measures (m for m, rad for rad ...), else the converted number means something else."""
    from fmpy import read_model_description

    from cranefmu.adapter.units import parse

    source = read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR)
    units = {f"{c.name}.{v.name}": v.unit or "" for c in source.components
             for v in read_model_description(str(c.fmu), validate=False).modelVariables}
    every = [p for ps in [source.bound, *source.sets.values()] for p in ps.values()]
    checked = [p for p in every if p.unit]
    assert checked
    for p in checked:
        assert parse(p.unit)[1] == parse(units[p.name])[1], (p.name, p.unit, units[p.name])


def test_generated_component_bindings_change_nothing_in_our_master(built, tmp_path):
    """The same run with and without the build's component-level bindings: bitwise equal rows."""
    import re

    from cranefmu.master.run import run
    from scene_edit import edit_ssp, scene_ssp

    def strip(text: str) -> str:
        out, n = re.subn(r"\s*<ssd:ParameterBindings>\s*<ssd:ParameterBinding>\s*<ssd:ParameterValues>.*?"
                         r"</ssd:ParameterBindings>", "", text, flags=re.S)
        assert n == 2   # rope and pendulum
        return out

    bare = edit_ssp(tmp_path / "system_binding_only.ssp", ssd=strip)
    with_bindings = run(scene_ssp(), stop_time=0.05, step_size=1e-3).result
    assert run(bare, stop_time=0.05, step_size=1e-3).result.tobytes() == with_bindings.tobytes()
