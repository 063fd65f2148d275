"""docs/scenes_catalog.md is what `python -m cranefmu.scenes.docs` writes from the scenes (no drift), with a
section for every shipped scene that states the settings its scene file stores."""
from __future__ import annotations

import tomllib

import pytest

from cranefmu.scenes import docs as scene_docs
from cranefmu.sources import scene_dirs


@pytest.fixture(scope="module")
def page(built):
    return scene_docs.render()


def _section(page: str, name: str) -> str:
    start = page.index(f"\n## {name}\n")
    end = page.find("\n## ", start + 1)
    return page[start:end]


def test_committed_page_equals_the_generated_one(page):
    assert scene_docs.PAGE.read_text() == page, \
        "docs/scenes_catalog.md is out of date: run `python -m cranefmu.scenes.docs` and commit it"


@pytest.mark.parametrize("scene_dir", scene_dirs(), ids=lambda d: d.name)
def test_every_scene_has_a_section_with_its_stored_settings(page, scene_dir):
    """Read again from the scene source (scene.toml's [settings]), not from the built scene the page used (the
    hand-written page had no section for truck_slewing and typed each stored setting by hand)."""
    section = _section(page, scene_dir.name)
    stored = tomllib.loads((scene_dir / "scene.toml").read_text()).get("settings", {})
    own = {k: v for k, v in stored.items() if k != "sets"}
    assert f"- Stored run settings (used where a run gives none): {scene_docs.settings_text(own)}\n" in section
    for set_name, values in stored.get("sets", {}).items():
        assert f"parameter set `{set_name}` stores its own over them: {scene_docs.settings_text(values)}" in section
    row = next(line for line in page.splitlines() if line.startswith(f"| [`{scene_dir.name}`]"))
    assert row.endswith(f"| {scene_docs.settings_text(own)} |")


def test_settings_text():
    assert scene_docs.settings_text({"algorithm": "jacobi", "extrapolation": 2, "step_size": 0.005}) == "jacobi x2, 5 ms"
    assert scene_docs.settings_text({"algorithm": "jacobi", "implicit": ["hook", "drum"]}) == \
        "jacobi, implicit = hook,drum"
    assert scene_docs.settings_text({}) == "none"


def test_check_reports_a_changed_page(page, tmp_path):
    out = tmp_path / "catalog.md"
    out.write_text(page)
    assert scene_docs.main(["--check", "--output", str(out)]) == 0
    out.write_text(page.replace("jacobi x2, 5 ms", "jacobi x1, 10 ms"))
    assert scene_docs.main(["--check", "--output", str(out)]) == 1
