"""Scenes composed from ports (cranefmu.compose, docs/composition.md): the FMUs declare their mechanical
ports, a scene.toml connects them, the build writes the SSD.  The four shipped scenes are written so;
their generated SSDs hold what the hand-written ones of commit 0cc7c7f held (connections in the same
order: the exchange order, so results are bitwise equal), bad lines get one-line errors naming the
file, the line and the port, a foreign FMU joins by its variables, and a new scene of under 30 lines
hangs at rest and travels."""
from __future__ import annotations

import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

from cranefmu import build as b
from cranefmu.cli import main as cli
from cranefmu.compose import compose, has_source
from cranefmu.compose.interface import read_interface
from cranefmu.errors import CompositionError
from cranefmu.master.run import run
# the hand-written SSD is zipped with the pythonfmu FMUs (build_ssp's default): the composed scene is run with them too
from cranefmu.master.scene_names import resolve_scene
from cranefmu.master.scene import read_ssd
from cranefmu.physics import boom, chassis, drive, girder, pendulum, rope
from cranefmu.physics.component import Port, check_ports

CHECKOUT = Path(__file__).resolve().parents[2]
HAND_WRITTEN = "0cc7c7f"   # the last commit whose SSDs were written by hand
SCENES = [d.name for d in b.scene_dirs() if has_source(d)]
MODELS = {"Rope": rope.RopeModel, "Pendulum": pendulum.PendulumModel, "Boom": boom.BoomModel,
          "Chassis": chassis.ChassisModel, "Drive": drive.DriveModel, "Girder": girder.GirderModel}
EXAMPLE = CHECKOUT / "ssp" / "examples" / "trolley_travel.toml"


def test_the_four_scenes_are_composed():
    assert set(SCENES) >= {"elastic_pendulum", "hook_sway", "overhead_lift", "truck_telescope"}


def test_every_model_declares_its_ports_consistently():
    for name, model in MODELS.items():
        assert model.ports, name
        check_ports(model)
    bad = type("Bad", (rope.RopeModel,), {"ports": (Port("hook", "", force=("x_hook", "y_hook", "z_hook")),)})
    with pytest.raises(ValueError, match="port hook: force x_hook has unit m, a linear port's force needs N"):
        check_ports(bad)


def test_each_fmu_carries_its_ports_and_an_osp_model_description(built):
    from lxml import etree

    for name, model in MODELS.items():
        iface = read_interface(built / f"{name}.fmu")
        assert {p: s.parts for p, s in iface.ports.items()} == \
            {p.name: dict(position=p.position, velocity=p.velocity, force=p.force) for p in model.ports}
        osp = etree.parse(str(built / f"{name}_OspModelDescription.xml")).getroot()
        groups = {el.get("name"): etree.QName(el).localname for el in osp.iter() if el.get("name")}
        for p in model.ports:
            if p.force and p.velocity:
                assert groups[p.name] == ("LinearMechanicalPort" if p.kind == "linear" else "AngularMechanicalPort")
                refs = [v.get("ref") for g in osp.iter() if g.get("name") == f"{p.name}.force" for v in g]
                assert refs == list(p.force)
    hook = read_interface(built / "Rope.fmu").ports["hook"]
    assert (hook.takes, hook.kind) == ("motion", "linear")
    assert read_interface(built / "Pendulum.fmu").ports["hook"].takes == "force"


@pytest.mark.parametrize("scene", SCENES)
def test_the_committed_ssd_is_the_one_its_scene_toml_generates(built, scene):
    folder = b.SSP_SOURCES / scene
    assert compose(folder, built).ssd == (folder / "SystemStructure.ssd").read_bytes(), \
        f"ssp/{scene}/SystemStructure.ssd differs from what scene.toml generates: edit scene.toml, run cranefmu build"


def _hand_written(scene: str) -> str:
    try:
        return subprocess.run(["git", "-C", str(CHECKOUT), "show", f"{HAND_WRITTEN}:ssp/{scene}/SystemStructure.ssd"],
                              capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip(f"no git history with commit {HAND_WRITTEN} (the hand-written SSDs)")


@pytest.mark.parametrize("scene", ["elastic_pendulum", "hook_sway", "overhead_lift", "truck_telescope"])
def test_the_generated_ssd_holds_what_the_hand_written_one_held(built, scene, tmp_path):
    """Same components and connectors, connections in the same order, parameter sets, power bonds and
    stop conditions, as the scene reader sees them."""
    (tmp_path / "SystemStructure.ssd").write_text(_hand_written(scene))
    folder = b.SSP_SOURCES / scene
    old, new = read_ssd(tmp_path / "SystemStructure.ssd", folder, built), read_ssd(folder / "SystemStructure.ssd",
                                                                                  folder, built)
    # not the stored settings: they are re-measured on purpose (issue 24 changed hook_sway's and overhead_lift's
    # after the port); tests/scenes/test_stored_settings.py holds them to their limits
    for field in ("name", "connections", "bound", "sets", "start_time", "stop_time", "bonds", "stop_conditions",
                  "bonds_declared"):
        assert getattr(new, field) == getattr(old, field), field
    assert [(c.name, c.source, set(c.connectors)) for c in new.components] == \
        [(c.name, c.source, set(c.connectors)) for c in old.components]


@pytest.mark.parametrize("scene", ["overhead_lift", "truck_telescope"])
def test_the_generated_scene_runs_bitwise_as_the_hand_written_one(built, scene, tmp_path):
    """The scenes whose port parts are connected apart (the old exchange order), under the iterative
    coupling, which an other order of the connections changes in the last bits."""
    old = tmp_path / scene
    old.mkdir()
    (old / "SystemStructure.ssd").write_text(_hand_written(scene))
    for ssv in (b.SSP_SOURCES / scene).glob("*.ssv"):
        (old / ssv.name).write_bytes(ssv.read_bytes())
    old_ssp = b.build_ssp(old, tmp_path / f"{scene}_hand_written.ssp")
    kw = dict(stop_time=0.03, step_size=1e-3, algorithm="iterative", extrapolation=1)
    a, c = run(old_ssp, **kw).result, run(resolve_scene(scene, "python"), **kw).result
    assert a.dtype.names == c.dtype.names and len(a) == len(c) == 31
    assert [n for n in a.dtype.names if not np.array_equal(a[n], c[n], equal_nan=True)] == []


BASE = '''components = {rope = "Rope", pendulum = "Pendulum"}
connect = [
  "rope.hook = pendulum.hook",
  "pendulum.suspended_mass -> rope.m_load",
  "pendulum.rest_tension -> rope.load",
  "rope.hang_length -> pendulum.drop",
  "LINE",
]
'''


def _compose(tmp_path: Path, built: Path, line: str):
    folder = tmp_path / "bad"
    folder.mkdir(exist_ok=True)
    (folder / "scene.toml").write_text(BASE.replace("LINE", line))
    return compose(folder, built)


@pytest.mark.parametrize("line, fragments", [
    ("rope.hook = rope.top", ["ports rope.hook and rope.top both take motion (both give force)"]),
    ("pendulum.hook = girder.trolley", ["unknown component 'girder' (components: rope, pendulum)"]),
    ("rope.hok = pendulum.top", ["rope (Rope.fmu) has no port or variable 'hok' (ports: hook, top, drum"]),
    ("rope.top = pendulum.hook", ["a power bond named 'hook' exists already: name this one with 'as NAME'"]),
    ("pendulum.theta -> rope.x_top", ["pendulum.theta -> rope.x_top joins unit rad to m"]),
    ("pendulum.vx -> rope.x_top", ["pendulum.vx -> rope.x_top joins unit m/s to m"]),
    ("rope.Fx_top -> pendulum.x", ["rope.Fx_top -> pendulum.x runs from output to output"]),
    ("rope.drum = pendulum.top", ["both take motion"]),
    ("pendulum.hook.motion -> rope.drum.motion", ["6 variables (x y z vx vy vz) to 2 (payout payout_rate)"]),
    ("pendulum.x -> rope.x_hook", ["input rope.x_hook is driven already by pendulum.x"]),
    ("rope.hook -> pendulum.hook", ["rope.hook is a port: connect two ports with '=', or name a part"]),
    ("rope.hook pendulum.hook", ["is not a connection"]),
])
def test_a_bad_connect_line_is_one_error_naming_the_file_line_and_port(built, tmp_path, line, fragments):
    with pytest.raises(CompositionError) as err:
        _compose(tmp_path, built, line)
    text = str(err.value)
    assert "\n" not in text and f"bad/scene.toml:7: connect {line!r}" in text
    for fragment in fragments:
        assert fragment in text


def test_the_port_checks_refuse_a_unit_mismatch_between_ports(built, tmp_path):
    """Ports of one kind pair axis by axis: a linear port to an angular one is refused by kind."""
    folder = tmp_path / "kinds"
    folder.mkdir()
    (folder / "scene.toml").write_text('components = {boom = "Boom", chassis = "Chassis"}\n'
                                       'connect = ["boom.foot_tilt = chassis.foot_heave"]\n')
    with pytest.raises(CompositionError, match=r"scene.toml:2: connect .*port boom.foot_tilt is angular, "
                                               r"chassis.foot_heave is linear"):
        compose(folder, built)


def test_bad_toml_and_bad_values_name_the_line(built, tmp_path):
    folder = tmp_path / "toml"
    folder.mkdir()
    (folder / "scene.toml").write_text('components = {rope = "Rope"}\nconnect = ["rope.hook = \n')
    with pytest.raises(CompositionError, match=r"toml/scene.toml: malformed TOML: .*line 2"):
        compose(folder, built)
    (folder / "scene.toml").write_text('connect = []\n[components.pendulum]\nfmu = "Pendulum"\npayload = "rigd"\n')
    with pytest.raises(CompositionError, match=r"scene.toml:4: pendulum.payload = 'rigd' is not allowed: one of "
                                               r"none, rigid, elastic"):
        compose(folder, built)
    (folder / "scene.toml").write_text('components = {rope = "Rope"}\nconect = []\n')
    with pytest.raises(CompositionError, match=r"scene.toml:2: key 'conect' is not allowed"):
        compose(folder, built)


def test_bad_settings_and_component_names_name_the_line(built, tmp_path):
    folder = tmp_path / "settings"
    folder.mkdir()
    (folder / "scene.toml").write_text('# the settings below\ncomponents = {rope = "Rope"}\nconnect = []\n'
                                       '[settings]\nalgorithm = "jacobi"\nstep_size = -1.0\n')
    with pytest.raises(CompositionError, match=r"scene.toml:4: stored run settings: .*step_size"):
        compose(folder, built)
    (folder / "scene.toml").write_text('connect = []\n[components]\n"my.rope" = "Rope"\n')
    with pytest.raises(CompositionError, match=r"scene.toml:3: component name 'my.rope' is not allowed"):
        compose(folder, built)


def test_a_parameter_sets_stored_settings_are_written_and_checked(built, tmp_path):
    """[settings.sets.NAME] goes into the settings annotation as a cf:ParameterSet the reader gives back
    per set; a set the folder has no .ssv for, or a bad value, is refused naming the line."""
    folder = tmp_path / "sets"
    folder.mkdir()
    (folder / "loose.ssv").write_text((b.SSP_SOURCES / "overhead_lift" / "loose.ssv").read_text())
    head = 'components = {rope = "Rope"}\nconnect = []\n[settings]\nstep_size = 0.002\n'
    (folder / "scene.toml").write_text(head + '[settings.sets.loose]\nstep_size = 0.001\nextrapolation = 1\n')
    (folder / "SystemStructure.ssd").write_bytes(compose(folder, built).ssd)
    scene = read_ssd(folder / "SystemStructure.ssd", folder, built)
    assert scene.settings == {"step_size": 0.002}
    assert scene.set_settings == {"loose": {"step_size": 0.001, "extrapolation": 1}}
    (folder / "scene.toml").write_text(head + '[settings.sets.tight]\nstep_size = 0.001\n')
    with pytest.raises(CompositionError, match=r"scene.toml:5: settings.sets.tight: 'tight' is not a parameter "
                                               r"set of the scene: one of loose"):
        compose(folder, built)
    (folder / "scene.toml").write_text(head + '[settings.sets.loose]\nextrapolation = 3\n')
    with pytest.raises(CompositionError, match=r"scene.toml:5: stored run settings of parameter set loose: "
                                               r"extrapolation = 3 is not allowed: 0, 1 or 2"):
        compose(folder, built)


def test_the_build_keeps_an_ssd_edited_after_its_scene_toml(built, tmp_path):
    """An SSD changed by hand (or merged in) after scene.toml is not overwritten: the build says so and
    leaves it for a person to carry into scene.toml; an edit of scene.toml writes the SSD again."""
    import os

    from cranefmu.compose import write_ssd

    folder = tmp_path / "scene"
    folder.mkdir()
    (folder / "scene.toml").write_text(BASE.replace('  "LINE",\n', ""))
    assert write_ssd(folder, built) == "written" and write_ssd(folder, built) == "same"
    ssd = folder / "SystemStructure.ssd"
    edited = ssd.read_text().replace('name="scene"', 'name="edited"')
    ssd.write_text(edited)
    toml = folder / "scene.toml"
    os.utime(toml, (ssd.stat().st_mtime - 10,) * 2)
    assert write_ssd(folder, built) == "kept" and ssd.read_text() == edited
    os.utime(toml, (ssd.stat().st_mtime + 10,) * 2)
    assert write_ssd(folder, built) == "written" and 'name="scene"' in ssd.read_text()


def test_the_cli_reports_a_bad_scene_in_one_line(built, tmp_path, capsys):
    folder = tmp_path / "cli"
    folder.mkdir()
    (folder / "scene.toml").write_text(BASE.replace("LINE", "rope.hook = rope.top"))
    assert cli(["compose", str(folder), "--output", str(tmp_path / "x.ssp")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "cli/scene.toml:7" in err and "both take motion" in err


def test_a_foreign_fmu_joins_by_its_variables(built, tmp_path):
    """SpringSupport (C, support/cranefmu_support/c_fmu) as the rope's sprung top, connected variable by variable beside the
    rope's and hook's ports: settled at rest, the support sags m g / k and the tension is the weight."""
    from cranefmu_support.c_fmu import G, K, LOAD, M_SUPPORT
    from cranefmu_support.c_fmu.build import build, compiler

    if compiler() is None:
        pytest.skip("no C compiler (cc or gcc) on PATH: the C test FMU cannot be built")
    folder = tmp_path / "sprung"
    folder.mkdir()
    build(folder / "SpringSupport.fmu")
    (folder / "scene.toml").write_text(f'''stop_time = 0.2
connect = [
  "rope.hook = pendulum.hook",
  "pendulum.suspended_mass -> rope.m_load",
  "pendulum.rest_tension -> rope.load",
  "rope.hang_length -> pendulum.drop",
  "rope.Fy_top -> support.F",
  "support.y -> rope.y_top",
  "support.v -> rope.vy_top",
  "support.y -> pendulum.y_top",
]
[components]
rope = {{fmu = "Rope", length = 10.0, E = 1e11, A = 5.655e-5}}
pendulum = {{fmu = "Pendulum", mass = {LOAD}, start = "below_top"}}
support = {{fmu = "SpringSupport.fmu", k = {K}, m = {M_SUPPORT}}}
''')
    from cranefmu.compose.command import pack

    ssp = pack(folder, tmp_path / "sprung.ssp")
    with zipfile.ZipFile(ssp) as zf:
        assert "resources/SpringSupport.fmu" in zf.namelist()
    r = run(ssp, stop_time=0.2, step_size=1e-3, algorithm="jacobi").result
    assert np.max(np.abs(r["support.y"] + LOAD * G / K)) < 1e-9 * LOAD * G / K
    assert np.max(np.abs(r["rope.tension"] - LOAD * G)) < 1e-8 * LOAD * G


def test_the_trolley_example_is_short_hangs_at_rest_and_travels(built, tmp_path, capsys):
    """ssp/examples/trolley_travel.toml: under 30 lines that are not comments; composed and built by
    ``cranefmu compose``, run by ``cranefmu run``; at t = 0 the rope holds hook and payload at rest
    (tension = weight to 1e-9), and the trolley (Boom's kinematic tip) travels 2 m and stops."""
    lines = [x for x in EXAMPLE.read_text().splitlines() if x.strip() and not x.lstrip().startswith("#")]
    assert len(lines) < 30
    ssp = tmp_path / "trolley_travel.ssp"
    assert cli(["compose", str(EXAMPLE), "--output", str(ssp)]) == 0
    assert cli(["run", str(ssp), "--stop-time", "0.01"]) == 0
    r = run(ssp, stop_time=6.5).result   # its stored settings: jacobi x2 at 2 ms
    weight = (50.0 + 1000.0) * 9.81
    assert abs(r["rope.tension"][0] - weight) < 1e-9 * weight
    x_tip = r["trolley.x_tip"]
    assert x_tip[-1] - x_tip[0] == pytest.approx(2.0, abs=1e-12)   # the travel law's distance, stopped at 6 s
    assert np.max(np.abs(r["pendulum.theta_payload"])) > 0.01      # the start and stop swing the payload


def test_libcosim_joins_whole_ports_from_the_osp_system_structure(built, tmp_path):
    """``cranefmu compose --osp``: libcosim loads OspSystemStructure.xml, finds Rope's and Pendulum's
    OspModelDescription beside the FMUs and connects port hook to port hook as variable groups (force
    and velocity, then position): under its plain Jacobi every input is its source's output one step
    earlier, in both directions."""
    pytest.importorskip("libcosimpy")
    from cranefmu_support.fmu_child import in_child
    from cranefmu.studies.hosts import libcosim_run

    folder = tmp_path / "osp"
    assert cli(["compose", str(b.SSP_SOURCES / "elastic_pendulum"), "--output", str(tmp_path / "ep.ssp"),
                "--osp", str(folder)]) == 0
    text = (folder / "OspSystemStructure.xml").read_text()
    assert text.count("<VariableGroupConnection>") == 2 and text.count("<VariableConnection>") == 3
    pairs = [("pendulum.x", "rope.x_hook"), ("pendulum.vz", "rope.vz_hook"), ("rope.Fy_hook", "pendulum.Fy_rope")]
    out = in_child(libcosim_run, str(folder / "OspSystemStructure.xml"), 0.005, 10, [c for p in pairs for c in p])
    assert out["ok"] and out["time"][-1] == pytest.approx(0.05, rel=1e-9)
    for source, target in pairs:
        assert out[target][1:] == out[source][:-1], (source, target)
    assert max(abs(v) for v in out["pendulum.x"]) > 0.8   # released at 5 deg on a 10 m rope: x = L sin(theta)
