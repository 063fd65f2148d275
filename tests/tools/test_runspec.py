"""One run request (:func:`cranefmu.master.runspec.resolve`): where each setting comes from, the
stored-settings rule, text values through the settings' own types, and every path taking the spec."""
from __future__ import annotations

import pytest

from cranefmu import cli
from cranefmu.errors import SettingsError
from cranefmu.master.run import preview
from cranefmu.master.runspec import choose, resolve
from cranefmu.master.settings import DEFAULT_STOP_TIME, NUMERICAL, Settings, convert, parse_bool

STORED = {"algorithm": "jacobi", "extrapolation": 1, "implicit": ["hook", "drum"], "step_size": 0.08,
          "coupling_tolerance": 1e-3}


def test_each_setting_says_where_it_came_from():
    values, sources, aside, stored_for = choose({"step_size": 0.01}, STORED, 7.0)
    assert (values["step_size"], sources["step_size"]) == (0.01, "given")
    assert (values["extrapolation"], sources["extrapolation"]) == (1, "scene")
    assert (values["implicit"], sources["implicit"]) == (["hook", "drum"], "scene")
    assert (values["stop_time"], sources["stop_time"]) == (7.0, "scene")
    assert (values["max_iterations"], sources["max_iterations"]) == (Settings().max_iterations, "default")
    assert (aside, stored_for) == ({}, "jacobi")
    values, sources, _, _ = choose({}, {}, None)
    assert (values["stop_time"], sources["stop_time"]) == (DEFAULT_STOP_TIME, "default")


def test_another_algorithm_takes_its_own_defaults_for_every_numerical_setting():
    """The scene's settings were measured for its algorithm: none of the numerical ones carries over,
    extrapolation included; they are kept aside to be shown."""
    values, sources, aside, _ = choose({"algorithm": "iterative", "step_size": 0.01}, STORED, None)
    assert values["extrapolation"] == Settings().extrapolation and sources["extrapolation"] == "default"
    assert values["implicit"] is None and values["coupling_tolerance"] == Settings().coupling_tolerance
    assert aside == {k: v for k, v in STORED.items() if k not in ("algorithm", "step_size")}
    assert set(aside) <= set(NUMERICAL)
    values, sources, _, _ = choose({"algorithm": "jacobi-plain"}, STORED, None)
    assert (values["extrapolation"], sources["extrapolation"]) == (0, "algorithm default")
    # the stored algorithm named again: the stored settings hold
    values, _, aside, _ = choose({"algorithm": "jacobi"}, STORED, None)
    assert (values["extrapolation"], values["step_size"], aside) == (1, 0.08, {})


def test_text_values_go_through_the_fields_types_and_one_boolean_parser():
    assert convert("step_size", " 2e-3 ") == 2e-3 and convert("max_iterations", "20") == 20
    assert convert("adaptive", "TRUE") is True and convert("instability_alarm", "0") is False
    assert convert("implicit", "tip, hook") == ["tip", "hook"] and convert("stop_when", "none") == []
    assert convert("step_size", 0.5) == 0.5   # typed values pass
    for name, text, allowed in (("adaptive", "maybe", "true or false"), ("max_iterations", "2.5", "an integer"),
                                ("step_size", "fast", "a number")):
        with pytest.raises(SettingsError, match=f"{name} = '{text}' is not allowed: {allowed}"):
            convert(name, text)
    assert [parse_bool(t) for t in ("true", "False", "1", "0")] == [True, False, True, False]


def test_resolve_on_a_scene_records_sources_and_refuses_a_stored_value_by_name(built):
    stored = preview("elastic_pendulum").settings
    spec = resolve("elastic_pendulum", stop_time=1.0, algorithm="iterative", step_size="1e-2")
    assert spec.settings.step_size == 1e-2 and spec.sources["step_size"] == "given"
    assert spec.settings.extrapolation == 0 and spec.set_aside["extrapolation"] == stored["extrapolation"]
    assert spec.describe()[1].startswith("not taken from the scene (measured for jacobi, this run is iterative)")
    with pytest.raises(SettingsError, match=r"step_size = .* stored setting"):
        resolve("elastic_pendulum", stop_time=stored["step_size"] / 2)


def test_issue_stiff_iterative_run_completes_without_extrapolation_given(built, capsys):
    """``run elastic_pendulum --step 1e-2 --algorithm iterative --set rope.E=1.4e14`` failed at t = 0.17 s
    (the scene's extrapolation 2, measured for its Jacobi, carried into the iterative run); through the
    worker process, past the failing time; the header names where the settings came from."""
    assert cli.main(["run", "elastic_pendulum", "--stop-time", "0.5", "--step", "1e-2", "--algorithm", "iterative",
                     "--set", "rope.E=1.4e14", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "50 steps of 0.01 s to t = 0.5 s (iterative, extrapolation 0)" in out
    assert "algorithm = 'iterative' (given)" in out and "step_size = 0.01 (given)" in out
    assert "not taken from the scene (measured for jacobi, this run is iterative): " in out
    assert "extrapolation = 2" in out


def test_step_help_names_the_scenes_stored_step():
    parser = cli.build_parser()
    run_help = parser._subparsers._group_actions[0].choices["run"].format_help()
    sweep_help = parser._subparsers._group_actions[0].choices["sweep"].format_help()
    for text in (run_help, sweep_help):
        flat = " ".join(text.split())
        assert "--step STEP_SIZE" in flat and "default: the scene's stored step_size, else 0.001" in flat


def test_info_on_an_fmu_declaring_an_external_entity_is_one_line_exit_2(built, tmp_path):
    """``info`` read an FMU's model description with fmpy before the XML guard: a raw lxml traceback."""
    import zipfile

    from cli_process import cranefmu
    from scene_edit import edit_fmu_in_ssp, scene_ssp

    with zipfile.ZipFile(scene_ssp()) as zf, zipfile.ZipFile(zf.open("resources/Rope.fmu")) as fmu:
        md = fmu.read("modelDescription.xml").decode()
    head, _, rest = md.partition("?>")
    rest = rest.replace('description="', 'description="&e; ', 1)   # used, from a file that is not there
    md = head + '?>\n<!DOCTYPE fmiModelDescription [<!ENTITY e SYSTEM "file:///nonexistent/secret">]>' + rest
    ssp = edit_fmu_in_ssp(tmp_path / "xxe_md.ssp", "resources/Rope.fmu", replace={"modelDescription.xml": md.encode()})
    done = cranefmu("info", str(ssp))
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cranefmu: error: ") and "DOCTYPE" in lines[0]
    assert "Rope.fmu/modelDescription.xml" in lines[0] and done.stdout == ""


def test_converge_runs_and_its_finest_reference_are_one_form(built, monkeypatch):
    """truck_telescope: the study's runs (through the sweep) took the scene's stored implicit group while
    its ``--reference finest`` run was explicit; both now resolve to the same settings but the step."""
    from dataclasses import replace

    import cranefmu.master.run as master_run
    from cranefmu.analysis import converge
    from cranefmu.errors import CraneFmuError, SimulationError

    seen = {}

    def sweep_runs(scene, settings, stop_time, algorithm, extrapolation, parameter_set=None, parameters=None,
                   progress=None, client=None, **run_options):   # client: the cluster, not a run setting
        seen["runs"] = dict(run_options, algorithm=algorithm, extrapolation=extrapolation, stop_time=stop_time)
        return [converge.ConvergenceRun(h, tol) for h, tol in settings], [None] * len(settings), 0.2

    def reference_run(scene, parameter_set=None, parameters=None, **options):
        seen["reference"] = options
        raise SimulationError("the reference run, stopped by the test")

    monkeypatch.setattr(converge, "run_settings", sweep_runs)
    monkeypatch.setattr(master_run, "run", reference_run)
    with pytest.raises(CraneFmuError, match="stopped by the test"):
        converge.study("truck_telescope", [0.02], algorithm="jacobi", extrapolation=1, reference="finest",
                       stop_time=0.2)
    runs = resolve("truck_telescope", step_size=0.02, **seen["runs"]).settings
    reference = resolve("truck_telescope", **seen["reference"]).settings
    assert seen["reference"]["step_size"] == 0.02 / converge.FINEST_FACTOR
    assert runs.implicit == reference.implicit == []
    assert replace(runs, step_size=0.0) == replace(reference, step_size=0.0)


def test_a_sweep_fixes_and_varies_implicit(built, tmp_path):
    """``implicit`` was no sweep input; now varied (values separated by ';') and fixed, and each run
    gives the result of the same settings run directly."""
    import numpy as np

    from cranefmu.master.run import run
    from cranefmu.master.scene_names import resolve_scene
    from cranefmu.sweep.spec import design
    from cranefmu.sweep.worker import SspFile, execute

    fixed = {"step_size": "0.02", "stop_time": "0.1", "algorithm": "jacobi", "extrapolation": "1"}
    varied = design(["implicit=none;tip;foot_heave,tip"], fixed).runs("truck_telescope")
    assert [r.inputs["implicit"] for r in varied] == [[], ["tip"], ["foot_heave", "tip"]]
    held = design(["step_size=0.02,0.01"], {"implicit": "tip,hook", "stop_time": 0.1}).runs("truck_telescope")
    assert [r.inputs["implicit"] for r in held] == [["tip", "hook"]] * 2
    ssp = SspFile.of(resolve_scene("truck_telescope"), "truck_telescope", with_data=False)
    for r in varied[:2]:
        row = execute(ssp, r, [], str(tmp_path))
        assert row["status"] == "ok", row["error"]
    explicit, group = (np.load(tmp_path / f"{r.key}.npy") for r in varied[:2])
    direct = run("truck_telescope", step_size=0.02, stop_time=0.1, algorithm="jacobi", extrapolation=1,
                 implicit=["tip"], progress=False).result
    assert np.array_equal(group, direct) and not np.array_equal(explicit, group)


def test_info_shows_the_stored_settings_their_algorithm_and_where_a_runs_settings_come_from(built):
    from cranefmu.master.extracted import extracted_scene
    from cranefmu.master.scene_names import resolve_scene
    from cranefmu.scenes.info import describe

    _, scene = extracted_scene(resolve_scene("hook_sway"))
    lines = describe(scene)
    stored = next(line for line in lines if line.startswith("  run settings stored in the scene"))
    assert "measured for jacobi" in stored and "step_size = 0.003" in stored
    default_run = next(line for line in lines if line.startswith("  a run given no settings: "))
    assert "step_size = 0.003 (scene)" in default_run and "extrapolation = 2 (scene)" in default_run
    assert f"stop_time = {scene.stop_time!r} (scene)" in default_run


def test_hook_sway_iterative_takes_iterative_defaults(built):
    """The issue's second case, ``hook_sway --step 5e-3 --algorithm iterative --set rope.E=1e12``, took the
    scene's extrapolation (2 then, 1 since issue 24 re-measured it, 2 again since issue 34's ladder; measured for
    its Jacobi); now iterative's
    default.  That the run then completes
    (Newton's method where the fixed point cannot contract): tests/master/test_stiff_coupling.py."""
    spec = resolve("hook_sway", step_size=5e-3, algorithm="iterative", parameters={"rope.E": 1e12})
    assert (spec.settings.extrapolation, spec.sources["extrapolation"]) == (Settings().extrapolation, "default")
    assert spec.set_aside == {"extrapolation": 2} and spec.overrides[("rope", "E")] == 1e12


def test_the_reference_solves_the_scene_a_run_read(built):
    """``reference.solve`` takes the :class:`Scene` a run read from its .ssp (wiring, parameters and start
    from the same object) and gives the solve of the scene's sources bit for bit."""
    import numpy as np

    from cranefmu.master.extracted import extracted_scene
    from cranefmu.master.scene_names import resolve_scene
    from cranefmu.analysis.reference import solve

    _, scene = extracted_scene(resolve_scene("elastic_pendulum"))
    times = np.linspace(0.0, 0.5, 11)
    from_run = solve(scene, 0.5, times, rtol=1e-8)
    from_sources = solve("elastic_pendulum", 0.5, times, rtol=1e-8)
    assert set(from_run) == set(from_sources)
    for key, column in from_sources.items():
        assert np.array_equal(from_run[key], column), key
