"""Scene defaults: each scene stores the run settings ``cranefmu run SCENE`` uses where none are given
(annotation ``org.cranefmu.settings``, chosen by benchmarks/scene_defaults.py), and they meet 1 % of
range on the scene's key outputs against the monolithic reference (a short run of each scene) and keep
every listed mode's frequency and damping (its probe run)."""
from __future__ import annotations

import re
import tempfile
from pathlib import Path

import numpy as np
import pytest

from cranefmu import cli

from cranefmu.analysis import modal
from cranefmu.analysis.converge import key_outputs, monolithic_reference
from cranefmu.errors import SceneError
from cranefmu.master.power_bonds import RESIDUAL_WARNING
from cranefmu.master.run import preview, resolve_scene, run
from cranefmu.master.scene import load_scene
from cranefmu.analysis.modal import MODES
from cranefmu.scenes.info import describe
from cranefmu.scenes import hook_sway_metrics
from reference_cache import References
from scene_edit import edit_ssp

# simulated span of the short run per scene [s]: long enough for the key outputs to move (the
# overhead crane's motor starts at 0.2 s and lifts the load; the truck's boom starts telescoping)
SPAN = {"elastic_pendulum": 3.0, "hook_sway": 3.0, "overhead_lift": 1.5, "truck_telescope": 4.8, "truck_slewing": 6.0}
TARGET = 1e-2   # of each key output's range in the reference
# looser than converge's 1e-10: the errors below agree to 3 digits with rtol 1e-10 (elastic_pendulum,
# hook_sway, truck_telescope) and 1e-7 (overhead_lift, whose 1e-10 solve takes minutes)
REF_RTOL = 1e-8


@pytest.mark.parametrize("scene", sorted(SPAN))
def test_run_without_settings_uses_the_scene_settings_and_meets_one_percent(built, scene):
    stored = preview(scene).settings
    assert {"algorithm", "extrapolation", "step_size"} <= set(stored)
    res = run(scene, stop_time=SPAN[scene], progress=False)
    assert {k for k, v in res.spec.sources.items() if v == "scene"} == set(stored)
    for name, value in stored.items():
        assert getattr(res.settings, name) == value
    assert res.stats.steps == round(SPAN[scene] / stored["step_size"])
    t = res.result["time"]
    assert np.allclose(np.diff(t), stored["step_size"], rtol=0, atol=1e-9)
    ref = monolithic_reference(scene, SPAN[scene], t, rtol=REF_RTOL)
    for key in key_outputs(scene):
        span = np.ptp(ref[key])
        assert span > 0, key
        err = np.max(np.abs(res.result[key] - ref[key])) / span
        assert err <= TARGET, f"{scene} {key}: {err:.3g} of range with {stored}"
    assert not res.warnings


@pytest.mark.parametrize("scene", sorted(MODES))
def test_the_stored_settings_keep_every_listed_mode(built, scene):
    """Issue 24: each listed mode (cranefmu.analysis.modal.MODES) within 0.5 % in frequency and 5 % in damping
    ratio of the monolith's over its probe run, and every bond's residual within 10 % of the energy it
    carried (the old elastic_pendulum setting, jacobi x2 at 20 ms, raised the axial damping by 38 %)."""
    check = modal.check_setting(scene, {}, references=References(scene, None, None))   # test_modes' solves
    assert check.failure is None
    assert len(check.errors) == len(MODES[scene])
    for e in check.errors:
        if e.name in modal.NOT_KEPT.get(scene, ()):
            # a documented miss (docs/scenes_catalog.md): still measured as one, or the catalog is out of date
            assert not e.meets, f"{scene} {e.name} is kept now: take it off modal.NOT_KEPT and the catalog's list"
            continue
        assert e.freq_err <= modal.FREQ_LIMIT, f"{scene} {e.name}: f {e.frequency:.6g} against {e.ref_frequency:.6g}"
        assert e.damp_err <= modal.DAMP_LIMIT, f"{scene} {e.name}: zeta {e.damping:.4g} against {e.ref_damping:.4g}"
    assert check.bond_ratio is not None and check.bond_ratio <= RESIDUAL_WARNING


def test_a_parameter_set_takes_its_own_stored_settings(built):
    """overhead_lift's loose set stores every bond implicit ([settings.sets.loose]): its slack rope snaps
    taut at t = 0.93 s, where the scene's explicit setting (jacobi x1, 2 ms) misses 1 % of range on the
    tension (measured 3.4 %) and the implicit bonds at the same step meet it (0.68 %).  A setting given
    wins over the set's; the default set keeps the scene's."""
    span = SPAN["overhead_lift"]
    res = run("overhead_lift", parameter_set="loose", stop_time=span, progress=False)
    assert res.settings.implicit == ["hook", "drum", "trolley"] and res.spec.sources["implicit"] == "parameter set"
    assert (res.settings.step_size, res.settings.extrapolation) == (preview("overhead_lift").settings["step_size"], 1)
    explicit = run("overhead_lift", parameter_set="loose", stop_time=span, implicit=[], progress=False)
    assert explicit.settings.implicit == [] and explicit.spec.sources["implicit"] == "given"
    assert run("overhead_lift", stop_time=0.01, progress=False).spec.sources["implicit"] == "default"
    t = res.result["time"]
    ref = monolithic_reference("overhead_lift", span, t, parameter_set="loose", rtol=REF_RTOL)
    scale = np.ptp(ref["rope.tension"])
    err = np.max(np.abs(res.result["rope.tension"] - ref["rope.tension"])) / scale
    assert err <= TARGET, f"loose with its stored setting: {err:.3g} of range"
    assert np.max(np.abs(explicit.result["rope.tension"] - ref["rope.tension"])) / scale > 2 * TARGET
    for key in key_outputs("overhead_lift"):
        assert np.max(np.abs(res.result[key] - ref[key])) / np.ptp(ref[key]) <= TARGET, key
    assert not res.warnings
    with tempfile.TemporaryDirectory() as tmp:
        lines = describe(load_scene(resolve_scene("overhead_lift"), Path(tmp)))
    assert "  run settings stored for parameter set loose (over the scene's when it is chosen): implicit = " \
           "['hook', 'drum', 'trolley']" in lines


def test_a_set_the_scene_has_not_in_the_stored_settings_is_a_scene_error(built, tmp_path):
    """elastic_pendulum has no named set: settings stored for one are refused, naming it."""
    ssp = edit_ssp(tmp_path / "bad.ssp", ssd=lambda text: re.sub(
        r'(<cf:Settings xmlns:cf="[^"]*"[^>]*)/>', r'\1><cf:ParameterSet name="loose" step_size="0.001"/></cf:Settings>',
        text, count=1))
    with pytest.raises(SceneError, match=r"bad.ssp: stored run settings \(org.cranefmu.settings\): parameter set "
                                         r"'loose' is not a parameter set of the scene: one of \(none\)"):
        run(ssp, stop_time=0.1, progress=False)


def test_explicit_settings_override_the_stored_ones(built):
    stored = preview("elastic_pendulum").settings
    res = run("elastic_pendulum", stop_time=0.1, step_size=1e-3, extrapolation=0, progress=False)
    assert (res.settings.step_size, res.settings.extrapolation) == (1e-3, 0)
    assert res.settings.algorithm == stored["algorithm"]
    assert {k for k, v in res.spec.sources.items() if v == "scene"} == set(stored) - {"step_size", "extrapolation"}
    assert res.stats.steps == 100


def test_a_stored_step_longer_than_the_run_is_refused_naming_it(built):
    h = preview("elastic_pendulum").settings["step_size"]
    with pytest.raises(Exception, match=r"step_size = .* stored setting"):
        run("elastic_pendulum", stop_time=h / 2, progress=False)


@pytest.mark.parametrize("attrs, named", [
    ('extrapolation="3"', "extrapolation = 3 is not allowed: 0, 1 or 2"),
    ('step_size="fast"', "step_size = 'fast' is not allowed: a number"),
    ('algorithm="newton"', "algorithm = 'newton' is not allowed: one of jacobi"),
    ('stepsize="0.01"', "stepsize = '0.01' is not allowed as a stored setting: one of accelerator"),
    ('stop_time="5"', "stop_time = '5' is not allowed as a stored setting (the scene's DefaultExperiment"),
    ('adaptive="maybe"', "adaptive = 'maybe' is not allowed: true or false"),
])
def test_a_bad_stored_setting_is_a_scene_error_naming_it(built, tmp_path, attrs, named):
    ssp = edit_ssp(tmp_path / "bad.ssp", ssd=lambda text: re.sub(r'(<cf:Settings xmlns:cf="[^"]*")[^>]*/>',
                                                               rf'\1 {attrs}/>', text, count=1))
    with pytest.raises(SceneError) as err:
        run(ssp, stop_time=0.1, progress=False)
    assert "bad.ssp" in str(err.value) and "org.cranefmu.settings" in str(err.value)
    assert named in str(err.value)


def test_hook_sway_defaults_add_no_energy_and_the_old_default_is_flagged(built):
    """Released from an offset, nothing excites the swing: its amplitude must not grow.  The scene's
    settings keep the payload sway's decay (last 2 s against the first 2 s of 10 s) the monolith's to 0.002
    (measured 0.9961 against 0.9962; the study's own criterion, scene_defaults.SWAY_GROWTH) and the hook
    bond's residual within issue 24's limit, 10 % of the energy it carried (measured 1.2 %, 0.084 J: it goes
    into the rope's damped axial mode, not the swing); jacobi x0 at 1 ms (the old global default) pumps
    energy in, and the run says so."""
    res = run("hook_sway", stop_time=10.0, progress=False)
    ref = monolithic_reference("hook_sway", 10.0, res.result["time"], rtol=REF_RTOL)
    ratio = hook_sway_metrics(res.result)["sway_ratio"]
    assert ratio < 1.0
    assert ratio == pytest.approx(hook_sway_metrics(ref)["sway_ratio"], abs=2e-3)
    assert abs(res.stats.bond_energy["hook"]) <= RESIDUAL_WARNING * res.stats.bond_carried["hook"]
    assert not res.warnings
    old = run("hook_sway", stop_time=10.0, step_size=1e-3, algorithm="jacobi", extrapolation=0, progress=False)
    assert hook_sway_metrics(old.result)["sway_ratio"] > 1.0
    assert old.stats.bond_energy["hook"] > RESIDUAL_WARNING * old.stats.bond_carried["hook"]
    assert len(old.warnings) == 1 and "power bond hook" in old.warnings[0]


def test_info_and_the_command_show_the_stored_settings_and_the_warning(built, capsys):
    with tempfile.TemporaryDirectory() as tmp:
        lines = describe(load_scene(resolve_scene("hook_sway"), Path(tmp)))
    stored = preview("hook_sway").settings
    assert any(line.startswith("  run settings stored in the scene") and f"step_size = {stored['step_size']!r}"
               in line for line in lines)
    assert cli.main(["run", "hook_sway", "--stop-time", "10", "--step", "1e-3", "--extrapolation", "0",
                     "--in-process", "--no-progress"]) == 0
    out, err = capsys.readouterr()
    header = out.split("  settings: ")[1].splitlines()[0]
    assert f"algorithm = {stored['algorithm']!r} (scene)" in header and "step_size = 0.001 (given)" in header
    assert err.count("warning: power bond hook") == 1
