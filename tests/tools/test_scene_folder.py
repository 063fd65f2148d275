"""A scene is one folder: ssp/<scene>/analysis.toml holds its question, key outputs, plots, roles and listed
modes; cranefmu.scenes and cranefmu.analysis.modal read it and hold no per-scene literal data (issue 36)."""
from __future__ import annotations

import ast
import json
import shutil
from pathlib import Path

import pytest

from cranefmu import scenes

from cranefmu.analysis import modal
from cranefmu.errors import SceneError, SettingsError
from cranefmu.scenes.catalog import FIDELITY, fidelity
from cranefmu.analysis.reference import Monolith
from cranefmu.sources import PACKAGE_DIR, scene_dirs, scene_files

FOLDERS = scene_dirs()
NAMES = [d.name for d in FOLDERS]


def test_every_scene_folder_is_read():
    assert len(NAMES) >= 5 and list(scenes.SCENES) == NAMES == list(modal.MODES) == list(scenes.METRICS)


@pytest.mark.parametrize("folder", FOLDERS, ids=NAMES)
def test_the_folder_holds_question_key_outputs_and_modes(folder):
    """Its analysis.toml ships with the scene (scene_files: what a wheel carries) and states a question, key
    outputs and modes whose columns, probes and closed forms fit the scene's own components."""
    assert folder / scenes.ANALYSIS in scene_files(folder)
    info = scenes.SCENES[folder.name]
    assert len(info.question) > 20 and info.key_outputs and info.plots and info.measure in scenes.MEASURES
    assert [c for c, _, _ in info.components] == list(scenes._component_fmus(folder))   # a role for each instance
    mono = Monolith(folder.name)
    columns = set(mono.columns)
    assert set(info.key_outputs) <= columns
    assert {c for _, cols in info.plots for c in cols} <= columns
    assert set(scenes.MEASURES[info.measure].columns) <= columns
    specs = modal.specs(folder.name)
    assert specs and all(s.column in columns and s.scene == folder.name for s in specs)
    for spec in specs:
        Monolith(folder.name, parameters=spec.probe)   # every probe names parameters of the scene


def test_the_measured_settings_are_in_the_folder():
    """Each scene's measured choice and fidelity ladder is its folder's fidelity.json (shipped with the scene,
    read by info), not a table of all scenes beside the code (src/cranefmu/fidelity.json, before issue 36)."""
    assert not (PACKAGE_DIR / FIDELITY).exists()
    for folder in FOLDERS:
        assert folder / FIDELITY in scene_files(folder)
        stored = json.loads((folder / FIDELITY).read_text())
        assert fidelity(folder.name) == stored and stored["ladder"] and stored["span"] > 0
    assert fidelity("no_such_scene") is None


def test_the_host_steps_are_in_the_folder():
    """Each scene's plain-Jacobi steps (what the build writes into its .ssp for libcosim and ecos) are its folder's
    host_steps.json, a source of the scene: the .ssp is stale when it changes and the wheel ships it."""
    from cranefmu.host_steps import FILE, measured

    assert not (PACKAGE_DIR / FILE).exists()
    for folder in FOLDERS:
        assert folder / FILE in scene_files(folder)
        stored = json.loads((folder / FILE).read_text())
        assert "default" in stored and list(measured(folder.name))[0] == "default"
        assert all(measured(folder.name)[s]["step"] == stored[s]["step"] <= stored[s]["stored_step"]
                   for s in measured(folder.name))
    assert measured("no_such_scene") == {}


def test_a_closed_form_from_the_folder_gives_the_physics():
    """elastic_pendulum's axial mode: f = sqrt(c/M)/(2 pi), c = E A / L for one line (seed 001 eq. 8)."""
    import math

    spec = next(s for s in modal.specs("elastic_pendulum") if s.name == "rope axial")
    values = modal.scene_values("elastic_pendulum")
    rope, pend = modal._rope(values), modal._pendulum(values)
    c = rope.n_lines * rope.E * rope.A / rope.length
    f, _ = spec.closed_form({**values, **spec.probe})
    assert f == pytest.approx(math.sqrt(c / pend.mass) / (2 * math.pi), rel=1e-12)


def _strings(nodes) -> set[str]:
    return {n.value for node in nodes for n in ast.walk(node) if isinstance(n, ast.Constant) and isinstance(n.value, str)}


@pytest.mark.parametrize("module", ["scenes/__init__.py", "analysis/modal.py"])
def test_no_per_scene_literal_data_in_the_code(module):
    """No module-level table mentions a scene (the old SCENES and MODES literals), and no question, listed mode's
    name or formula is written anywhere in the code: they are the folders'.  (Code for one scene, e.g.
    truck_telescope_parameters deriving that scene's set, may name it.)"""
    tree = ast.parse((PACKAGE_DIR / module).read_text())
    tables = [node.value for node in tree.body if isinstance(node, (ast.Assign, ast.AnnAssign)) and node.value]
    assert not _strings(tables) & set(NAMES)
    stated = {*(scenes.SCENES[n].question for n in NAMES), *(s.name for n in NAMES for s in modal.specs(n)),
              *(s.formula for n in NAMES for s in modal.specs(n))}
    assert not _strings([tree]) & stated


def _copy(tmp_path: Path, text: str) -> Path:
    folder = tmp_path / "elastic_pendulum"
    if not folder.is_dir():
        shutil.copytree(next(d for d in FOLDERS if d.name == "elastic_pendulum"), folder)
    (folder / scenes.ANALYSIS).write_text(text)
    return folder


def test_bad_analysis_files_get_one_clear_line(tmp_path):
    with pytest.raises(SceneError, match=r"key 'questoin' is not allowed: one of question, "):
        scenes.scene_info(_copy(tmp_path, 'questoin = "x"\n'))
    with pytest.raises(SceneError, match=r"measure = 'dynamic' is not allowed: one of dynamic_factor, "):
        scenes.scene_info(_copy(tmp_path, 'measure = "dynamic"\n'))
    with pytest.raises(SceneError, match=r"role of 'hook', which is no component of the scene: one of rope, pendulum"):
        scenes.scene_info(_copy(tmp_path, '[roles]\nhook = "x"\n'))
    with pytest.raises(SettingsError, match=r"closed_form = 'axial' of mode 'm' is not allowed: one of rope_axial, "):
        modal.mode_spec("elastic_pendulum", {"name": "m", "column": "rope.tension", "formula": "", "closed_form": "axial",
                                             "span": 1.0})
    with pytest.raises(SettingsError, match=r"mode key 'spam' is not allowed"):
        modal.mode_spec("elastic_pendulum", {"name": "m", "spam": 1})
