"""The measured settings (ssp/<scene>/fidelity.json, written by benchmarks/scene_defaults.py): the
stored setting of a measured scene is the one the measurement chose, its ladder runs from the fastest
to the most faithful, and `cranefmu info` shows both with their errors."""
import tempfile
from pathlib import Path

import pytest

from cranefmu.analysis import modal
from cranefmu.master.run import preview, resolve_scene
from cranefmu.master.scene import load_scene
from cranefmu.scenes.catalog import fidelity
from cranefmu.scenes.info import describe

MEASURED = [s for s in ("elastic_pendulum", "hook_sway", "overhead_lift", "truck_telescope", "truck_slewing")
            if fidelity(s)]


@pytest.mark.parametrize("scene", MEASURED)
def test_the_stored_setting_is_the_measured_choice(built, scene):
    chosen = fidelity(scene)["chosen"]
    if chosen is None:
        pytest.skip(f"{scene}: no measured setting meets every limit (docs/scenes.md says which is stored)")
    stored = preview(scene).settings
    assert (stored["algorithm"], stored["extrapolation"], stored["step_size"]) == \
        (chosen["algorithm"], chosen["extrapolation"], chosen["step_size"])
    assert list(stored.get("implicit") or []) == list(chosen.get("implicit") or [])
    assert chosen["ok"] and chosen["worst"] <= 0.01


@pytest.mark.parametrize("scene", MEASURED)
def test_the_ladder_runs_from_fastest_to_most_faithful(scene):
    ladder = fidelity(scene)["ladder"]
    assert 2 <= len(ladder) <= 4
    rtf = [r["rtf"] for r in ladder]
    assert rtf == sorted(rtf, reverse=True)
    # where no measured setting passes, the modes the stored one misses are listed as such (modal.NOT_KEPT)
    assert ladder[-1]["ok"] or (fidelity(scene)["chosen"] is None and modal.NOT_KEPT.get(scene))


@pytest.mark.parametrize("scene", MEASURED[:1])
def test_info_shows_the_chosen_setting_and_the_ladder(built, scene):
    with tempfile.TemporaryDirectory() as tmp:
        lines = describe(load_scene(resolve_scene(scene), Path(tmp)))
    data = fidelity(scene)
    text = "\n".join(lines)
    if data["chosen"]:
        assert f"    chosen: {data['chosen']['label']}: range" in text
    for r in data["ladder"]:
        # the ladder's walls were of a 10 s window with the pythonfmu FMUs: info shows no speed from them
        assert f"      {r['label']}: range {100 * r['worst']:.2g} %" in text
    assert "RTF" not in text
    assert "speed at the stored settings over the whole" in text    # cranefmu/speed.json (kinds_speed.py)
    assert "listed modes" in text
