"""What a cold ``cranefmu run`` does once, not twice, and what it leaves out (benchmarks/cold_command.py
measures the CPU): an FMU's C sources are checked but not unzipped, a scene's SSD is parsed once for both
kinds' staleness checks, a current native scene is checked once, the summary reads only its own scene."""
from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from cranefmu.errors import SceneError
from cranefmu.master.untrusted import safe_extract


def _fmu_like(path: Path, extra: list[tuple[str, bytes]] = ()) -> Path:
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("modelDescription.xml", b"<fmiModelDescription/>")
        zf.writestr("binaries/linux64/M.so", b"\0")
        zf.writestr("sources/M.c", b"int x;")
        for name, data in extra:
            zf.writestr(name, data)
    return path


def test_skipped_members_are_not_written_but_still_checked(tmp_path):
    target = tmp_path / "t"
    target.mkdir()
    safe_extract(_fmu_like(tmp_path / "m.fmu"), target, skip=("sources/",))
    assert sorted(p.relative_to(target).as_posix() for p in target.rglob("*") if p.is_file()) == \
        ["binaries/linux64/M.so", "modelDescription.xml"]
    evil = _fmu_like(tmp_path / "evil.fmu", [("sources/../../escaped.c", b"pwned")])
    other = tmp_path / "u"
    other.mkdir()
    with pytest.raises(SceneError, match="outside"):
        safe_extract(evil, other, skip=("sources/",))
    assert not list(other.iterdir()) and not (tmp_path / "escaped.c").exists()


def test_an_extracted_native_fmu_has_no_sources_folder(built):
    from cranefmu.fmu_kinds import compiler_reason, scene_path
    from cranefmu.master.extracted import extracted_scene, fmu_dir

    if compiler_reason():
        pytest.skip(compiler_reason())
    ssp = scene_path("elastic_pendulum", "native")
    with zipfile.ZipFile(ssp) as zf, zipfile.ZipFile(zf.open("resources/Rope.fmu")) as fmu:
        assert any(n.startswith("sources/") for n in fmu.namelist())   # the FMU ships them
    workdir, scene = extracted_scene(ssp)
    for c in scene.components:
        d = fmu_dir(workdir, c.name)
        assert (d / "modelDescription.xml").is_file() and (d / "binaries").is_dir()
        assert not (d / "sources").exists()


def test_the_ssd_is_parsed_once_for_both_kinds(built, monkeypatch):
    from cranefmu import build as b
    from cranefmu.master import scene as scene_module

    calls = []
    real = scene_module.read_scene_folder
    monkeypatch.setattr(scene_module, "read_scene_folder", lambda *a: calls.append(a) or real(*a))
    monkeypatch.setattr(b, "_SCENE_FMUS", {})
    folder = next(d for d in b.scene_dirs() if d.name == "overhead_lift")
    python = b.scene_fmus(folder)
    native = b.scene_fmus(folder, b.FMU_DIR / "native")
    assert len(calls) == 1
    assert [p.name for p in python] == [p.name for p in native] == ["Drive.fmu", "Girder.fmu", "Pendulum.fmu",
                                                                      "Rope.fmu"]
    assert all(p.parent == b.FMU_DIR / "native" for p in native) and all(p.parent == b.FMU_DIR for p in python)


def test_a_current_native_scene_is_checked_once(built, monkeypatch):
    from cranefmu import fmu_kinds

    if fmu_kinds.compiler_reason():
        pytest.skip(fmu_kinds.compiler_reason())
    fmu_kinds.scene_path("overhead_lift", "native")   # built and current now
    checked = []
    real = fmu_kinds.native_fmu_is_stale
    walks = []
    shared = fmu_kinds._shared_sources
    monkeypatch.setattr(fmu_kinds, "native_fmu_is_stale", lambda name, *a: checked.append(name) or real(name, *a))
    monkeypatch.setattr(fmu_kinds, "_shared_sources", lambda: walks.append(1) or shared())
    assert fmu_kinds.scene_path("overhead_lift").parent.name == "native"
    assert sorted(checked) == ["Drive", "Girder", "Pendulum", "Rope"]   # each of its 4 FMUs once
    assert len(walks) == 1   # the sources they share walked once for the four, not once each


def test_the_summary_reads_only_its_own_scene(monkeypatch):
    from cranefmu import scenes

    read = []
    real = scenes.scene_info
    monkeypatch.setattr(scenes, "scene_info", lambda folder: read.append(Path(folder).name) or real(folder))
    folders = scenes.SceneFolders()
    assert folders.get("overhead_lift").name == "overhead_lift" and folders.get("no_such_scene") is None
    assert read == ["overhead_lift"]
    assert "hook_sway" in folders and len(folders) >= 5   # the whole mapping still there when asked for
    assert read.count("overhead_lift") == 1


def test_the_bundle_is_walked_once_per_build_check(built, monkeypatch):
    """``build.is_stale`` of a scene of four pythonfmu FMUs walks the bundled sources once for the four (it
    walked them once per FMU), and still finds an FMU older than the bundle stale."""
    from cranefmu import build as b

    if b.in_cache():
        pytest.skip("in the user cache a present FMU is current: the bundle is not walked")
    assert not b.is_stale(["overhead_lift"])
    walks = []
    real = b.bundle_sources
    monkeypatch.setattr(b, "bundle_sources", lambda: walks.append(1) or real())
    assert not b.is_stale(["overhead_lift"])
    assert len(walks) == 1
    script = b.FMU_SOURCES / "Rope.py"
    newest = b._newest(real())
    assert b.fmu_is_stale(script, newest) is False
    assert b.fmu_is_stale(script, (b.FMU_DIR / "Rope.fmu").stat().st_mtime + 1.0) is True   # a newer bundle file
