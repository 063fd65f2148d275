"""Issue 37: a parameter that depends on another follows it, or the change is refused in one line
(cranefmu.derived, applied by resolve: runs, the CLI, experiments, sweeps).

Before, changing truck_telescope's boom length left the hoist paying out the 20.6 m of the 10.5 -> 22.4 m
manoeuvre (the load ended metres below where it hung), and a boom held at another length kept its
segments retracted unless the caller computed their offsets (the load chart did it through the API)."""
from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from cranefmu.derived import RULES, _defaults, derive, rules_of
from cranefmu.errors import ParameterSetError
from cranefmu.master.runspec import resolve
from cranefmu.physics.boom import BoomParams, telescope_law
from cranefmu.physics.drive import DriveParams, trapezoid


def _overrides(**parameters) -> dict[str, object]:
    spec = resolve("truck_telescope", parameters={k.replace("__", "."): v for k, v in parameters.items()})
    return {f"{c}.{v}": x for (c, v), x in spec.overrides.items()}


def _hook_drop(values: dict, t: np.ndarray) -> np.ndarray:
    """How far [m] the hook has gone down at each t: the rope paid out per fall minus the tip's rise
    (boom law and payout law of the models, rigid chassis and rope)."""
    boom = BoomParams(**{k: float(values[f"boom.{k}"]) for k in ("boom_length_start", "boom_length_end",
                                                                  "telescope_speed", "t_acc", "luff_angle")})
    drive = DriveParams(**{k: float(values[f"drive.{k}"]) for k in ("payout_speed", "duration", "t_acc")},
                        start_time=float(values.get("drive.start_time", 0.0)))
    rise = np.array([sum(telescope_law(x, boom)[0]) for x in t]) * math.sin(boom.luff_angle)
    paid = np.array([trapezoid(x, drive)[0] for x in t]) / float(values["rope.n_lines"])
    return paid - rise


@pytest.mark.parametrize("change", [{"boom__boom_length_end": 14.0}, {"boom__boom_length_end": "18.3"},
                                    {"boom__boom_length_start": 14.0},
                                    {"boom__luff_angle": math.radians(45.0), "boom__boom_length_end": 16.0},
                                    {"boom__telescope_speed": 0.5, "rope__n_lines": 4}])
def test_the_hook_keeps_its_height_when_the_boom_changes(built, change):
    """The payout follows the telescoping: at every instant the hook's drop (rope paid out per fall minus the
    tip's rise) is zero, as in the shipped sets.  Old code: boom_length_end = 14 paid out 20.6 m over 20 s
    against the tip's 3.03 m rise, the hook ending 7.3 m lower."""
    values = _overrides(**change)
    spec = resolve("truck_telescope", parameters={k.replace("__", "."): v for k, v in change.items()})
    assert spec.describe()[-1].startswith("following the parameters changed: ")
    assert f"drive.payout_speed = {values['drive.payout_speed']:.6g}" in spec.describe()[-1]
    t = np.linspace(0.0, 40.0, 801)
    assert np.max(np.abs(_hook_drop(values, t))) < 1e-12
    shipped = _overrides()
    assert np.max(np.abs(_hook_drop(shipped, t))) < 1e-12   # the default set holds it too


def test_a_boom_held_at_a_length_has_its_segments_out_and_no_payout(built):
    """boom_length_start = boom_length_end = L: segments 4 and 3 at (L - 10.5) / 2 and L - 10.5 (the load
    chart's static case, cranefmu.sweep.load_chart.static_parameters), the hoist still."""
    from cranefmu.sweep.load_chart import segment_extensions, static_parameters

    values = _overrides(boom__boom_length_start=17.3, boom__boom_length_end=17.3)
    s1, s2 = segment_extensions(17.3)
    assert (values["boom.seg4_offset"], values["boom.seg3_offset"]) == (s1, s1 + s2)
    assert values["drive.payout_speed"] == 0.0
    api = resolve("truck_telescope", parameters=static_parameters(60.0, 17.3, 2000.0)).overrides
    assert resolve("truck_telescope", parameters={"boom.boom_length_start": 17.3, "boom.boom_length_end": 17.3,
                                                  "pendulum.mass": 2000.0, "pendulum.start": "below_top"}
                   ).overrides == api


def test_a_telescope_command_holds_the_hoist(built):
    """telescope_source = input: the law does not telescope (an operator's command does), so no payout; a
    payout given with it stands (the law cannot know the command's profile)."""
    assert _overrides(boom__telescope_source="input")["drive.payout_speed"] == 0.0
    assert _overrides(boom__telescope_source="input", drive__payout_speed=0.3)["drive.payout_speed"] == 0.3


@pytest.mark.parametrize("change, named", [
    ({"boom.boom_length_end": 14.0, "drive.payout_speed": 0.5}, ("drive.payout_speed = 0.5", "boom.boom_length_end = 14.0",
                                                                  "allowed 1.21243556529821")),
    ({"boom.boom_length_start": 14.0, "boom.boom_length_end": 14.0, "boom.seg3_offset": 0.0},
     ("boom.seg3_offset = 0.0", "boom.boom_length_start = 14.0", "allowed 3.5")),
    ({"boom.boom_length_start": 9.0}, ("boom.boom_length_start = 9.0", "allowed >= 10.5"))])
def test_a_disagreeing_value_is_refused_in_one_line(built, change, named):
    with pytest.raises(ParameterSetError) as err:
        resolve("truck_telescope", parameters=change)
    text = str(err.value)
    assert "\n" not in text and all(n in text for n in named), text


def test_a_value_that_agrees_is_taken_as_given():
    """truck_tipping_statics gives the offsets itself (2.585 for (15.67 - 10.5) / 2 = 2.5850000000000009):
    within 1e-9 of the derived value they stay as written (the runs unchanged)."""
    given = {"boom.boom_length_start": 15.67, "boom.boom_length_end": 15.67, "boom.seg4_offset": 2.585,
             "boom.seg3_offset": 5.17}
    out = derive("truck_telescope", {}, given)
    assert out["boom.seg4_offset"] == 2.585 and out["boom.seg3_offset"] == 5.17 and out["drive.payout_speed"] == 0.0


def test_every_shipped_parameter_set_satisfies_the_rules(built):
    """Each set of truck_telescope and truck_slewing, read as if a user gave all its values, is accepted and
    its targets equal what the rules derive bit for bit (the sets are written by the same arithmetic)."""
    from cranefmu.master.extracted import extracted_scene
    from cranefmu.master.scene_names import resolve_scene

    for scene in ("truck_telescope", "truck_slewing"):
        _, loaded = extracted_scene(resolve_scene(scene, None))
        for name in (None, *loaded.sets):
            values = loaded.model_values(name)
            derive(scene, {}, values)   # accepted
            for rule in rules_of(scene):
                derived = rule.derive({**_defaults(), **values})
                for k, v in derived.items():
                    if k in values:
                        assert float(values[k]) == v, (scene, name, k, values[k], v)
    assert {r.name for r in RULES} == {"segments", "payout"}


def test_cli_refuses_a_payout_that_does_not_follow(built):
    p = subprocess.run([sys.executable, "-m", "cranefmu.cli", "run", "truck_telescope", "--set",
                        "boom.boom_length_end=14", "--set", "drive.payout_speed=0.5", "--stop-time", "0.01"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode != 0
    lines = [x for x in p.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and "drive.payout_speed = '0.5'" in lines[0] and "boom.boom_length_end = '14'" in lines[0]
    assert "allowed 1.2124355652982142" in lines[0]


def test_an_experiment_follows_and_refuses_at_its_set_line(built, tmp_path):
    from cranefmu.experiments.reader import ExperimentError, load
    from cranefmu.experiments.runner import prepare_case

    f = tmp_path / "e.toml"
    f.write_text('scene = "truck_telescope"\nstop_time = 0.1\n'
                 'set = {"boom.boom_length_end" = 14.0}\n'
                 '[[assert]]\nname = "n"\ncolumn = "chassis.N_front"\nat = 0.0\nmin = 0.0\n')
    (case,) = load(f)
    planned = prepare_case(case, set(), {})
    assert planned.spec.overrides[("drive", "duration")] == 8.0          # T2 = 3.5 / 0.7 s + T1
    assert planned.values["drive.duration"] == 8.0                        # what expressions see
    f.write_text('scene = "truck_telescope"\nstop_time = 0.1\n'
                 'set = {"boom.boom_length_end" = 14.0, "drive.duration" = 20.0}\n'
                 '[[assert]]\nname = "n"\ncolumn = "chassis.N_front"\nat = 0.0\nmin = 0.0\n')
    (case,) = load(f)
    with pytest.raises(ExperimentError) as err:
        prepare_case(case, set(), {})
    assert str(err.value).startswith(f"{f}:3: set: drive.duration = 20.0 is not allowed with boom.boom_length_end")
