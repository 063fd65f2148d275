"""Both kinds of FMU, one choice (issue 33): every scene and parameter set runs with the native FMUs and
with the pythonfmu FMUs and they agree to 1e-9 of each column's range; the ``fmus`` setting chooses the
kind, says which kind ran and refuses a bad value or a scene file of the other kind.

The short windows here keep a scene to seconds; benchmarks/native_conformance.py compares every scene's
natural length (and the slow test below runs it)."""
from __future__ import annotations

import pytest

from cranefmu.errors import SettingsError
from cranefmu.studies.kinds import TOLERANCE, agreement, relative_difference

SCENES = ("elastic_pendulum", "overhead_lift", "hook_sway", "truck_telescope", "truck_slewing")
WINDOW = 0.05   # [s]: 10 to 25 macro steps at the stored steps
# the smallest range of a column in the short window: 1e-3 in its SI unit, 1e-3 of its magnitude and of the largest
# magnitude in its unit (studies.kinds.relative_difference).  A scene starts at rest, where its outputs move by
# round-off only and the two kinds differ by round-off (measured in overhead_lift: 6.1e-13 m/s in pendulum.vy, whose
# 0.05 s range is about 1e-12, since the C Girder's exponential follows scipy's to 1e-14; 8.9e-9 N in a sling force that
# stays at +-4e-9 N noise beside a 2e4 N rope tension); over the natural length (the slow test,
# benchmarks/native_conformance.py) every column's own range counts
WINDOW_FLOOR, WINDOW_FLOOR_REL = 1e-3, 1e-3


@pytest.fixture(scope="module")
def native_built():
    from cranefmu.fmu_kinds import compiler_reason

    if compiler_reason():
        pytest.skip(compiler_reason())


@pytest.mark.parametrize("scene", SCENES)
def test_every_parameter_set_agrees(native_built, scene):
    from cranefmu.master.run import preview

    sets = preview(scene, "python").parameter_sets
    for name in sets:
        found = agreement(scene, None if name == "default" else name, stop_time=WINDOW, floor=WINDOW_FLOOR,
                          floor_rel=WINDOW_FLOOR_REL)
        assert found.rows[0] == found.rows[1] > 5, (scene, name, found.rows)
        assert found.worst <= TOLERANCE, (scene, name, found.column, found.worst)


@pytest.mark.slow
@pytest.mark.parametrize("scene", SCENES)
def test_natural_length_agrees(native_built, scene):
    from cranefmu.master.run import preview

    for name in preview(scene, "python").parameter_sets:
        found = agreement(scene, None if name == "default" else name)
        assert found.ok, (scene, name, found.rows, found.column, found.worst)


def test_relative_difference_finds_the_worst_column():
    import numpy as np

    a = np.zeros(3, dtype=[("time", float), ("x", float), ("flat", float)])
    a["time"], a["x"], a["flat"] = [0, 1, 2], [0.0, 2.0, 4.0], 5.0
    b = a.copy()
    b["x"][1] += 4e-9            # 1e-9 of the range 4
    assert relative_difference(a, b) == (pytest.approx(1e-9, rel=1e-6), "x")
    b["flat"][2] = 5.0 + 1e-14   # a constant column: against 1e-6 of its magnitude 5
    worst, column = relative_difference(a, b)
    assert column == "flat" and worst == pytest.approx(2e-9, rel=0.05)   # 5 + 1e-14 is 5 + 9.77e-15
    b["x"][0] = np.nan
    assert relative_difference(a, b) == (float("inf"), "x")


def test_header_says_which_kind_ran(native_built):
    from cranefmu.master.runspec import resolve

    native = resolve("elastic_pendulum", stop_time=WINDOW, fmus="native")
    python = resolve("elastic_pendulum", stop_time=WINDOW, fmus="python")
    assert native.settings.fmus == "native" and native.sources["fmus"] == "given"
    assert python.settings.fmus == "python" and python.ssp != native.ssp
    assert "fmus = 'python' (given)" in python.describe()[0]
    chosen = resolve("elastic_pendulum", stop_time=WINDOW)
    assert (chosen.settings.fmus, chosen.sources["fmus"]) == ("native", "default")
    assert "fmus = 'native' (default)" in chosen.describe()[0]
    held = resolve(python.ssp, stop_time=WINDOW)   # a scene file: the FMUs it holds
    assert (held.settings.fmus, held.sources["fmus"]) == ("python", "scene")


def test_a_bad_kind_is_refused_by_name():
    from cranefmu.master.runspec import resolve

    with pytest.raises(SettingsError, match=r"^fmus = 'c' is not allowed: native or python$"):
        resolve("elastic_pendulum", fmus="c")


def test_a_scene_file_of_the_other_kind_is_refused(native_built):
    from cranefmu.master.runspec import resolve

    python = resolve("elastic_pendulum", fmus="python").ssp
    with pytest.raises(SettingsError, match=r"fmus = 'native' is not allowed for the scene file .*its FMUs are python"):
        resolve(python, fmus="native")


def test_without_a_compiler_a_run_takes_python_after_one_line(monkeypatch, capsys):
    """The fallback: no compiler (and no native scene built in this folder) -> python, one line why."""
    import cranefmu.fmu_kinds as kinds

    monkeypatch.setattr(kinds, "native_ssp_is_stale", lambda scene_dir: True)
    monkeypatch.setattr(kinds, "compiler_reason", lambda: "no C compiler and CMake found on PATH (test)")
    monkeypatch.setattr(kinds, "_TOLD", set())
    from cranefmu.master.runspec import resolve

    spec = resolve("elastic_pendulum", stop_time=WINDOW)
    assert spec.settings.fmus == "python"
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["cranefmu: scene elastic_pendulum runs with the pythonfmu FMUs: no C compiler and CMake found "
                   "on PATH (test)"]
    with pytest.raises(SettingsError, match="fmus = 'native' is not allowed for scene elastic_pendulum: no C compiler"):
        resolve("elastic_pendulum", fmus="native")


def test_sweep_rows_say_which_kind_ran(native_built, tmp_path):
    import cranefmu
    from cranefmu.sweep.engine import connect
    from cranefmu.sweep.table import header

    assert header(["fmus"], []).count("fmus") == 1   # given as an input: its one column
    client, cluster = connect(workers=1)
    try:
        rows = {kind: cranefmu.sweep("elastic_pendulum", ["rope.E=5e10,1e11"], ["max:rope.tension"],
                                     tmp_path / f"{kind}.csv", client=client, stop_time=WINDOW, fmus=kind).rows
                for kind in ("native", "python")}
    finally:
        client.close()
        cluster.close()
    assert [r["fmus"] for r in rows["native"]] == ["native", "native"]
    assert [r["fmus"] for r in rows["python"]] == ["python", "python"]
    for a, b in zip(rows["native"], rows["python"]):   # the same runs with either kind
        assert a["max:rope.tension"] == pytest.approx(b["max:rope.tension"], rel=1e-12)


def test_the_report_says_which_kind_ran(native_built, tmp_path):
    from cranefmu.master.run import run
    from cranefmu.report import write_report

    res = run("elastic_pendulum", stop_time=WINDOW, fmus="native", progress=False)
    text = write_report(tmp_path / "r.html", res).read_text()
    assert "cranefmu run of elastic_pendulum with the native FMUs" in text
    assert "<td>fmus</td><td>&#x27;native&#x27;</td><td>given</td>" in text.replace("\n", "")


def test_a_native_fmu_is_stale_when_its_sources_or_tables_change(tmp_path, monkeypatch):
    """Touched sources that assemble to the same files: current (and its time renewed); changed
    generated tables: stale; missing: stale.  The FMU is the assembled source FMU (no binary needed)."""
    import os

    import cranefmu.native.build as nb
    from cranefmu import build as b
    from cranefmu import fmu_kinds

    before = (b.FMU_DIR, b.SSP_DIR)
    b.set_build_dirs(tmp_path / "fmus", tmp_path / "ssp")
    try:
        assert fmu_kinds.native_fmu_is_stale("Girder")                      # missing
        fmu = nb.zip_fmu(nb.assemble_source_fmu("Girder", tmp_path / "src" / "Girder"),
                         fmu_kinds.native_fmu_dir() / "Girder.fmu")
        os.utime(fmu, (1e9, 1e9))                                          # older than every source: checked
        assert not fmu_kinds.native_fmu_is_stale("Girder")
        assert fmu.stat().st_mtime > 1e9                                   # renewed: not assembled again
        os.utime(fmu, (1e9, 1e9))
        import cranefmu.native.tables as nt   # imported by assemble_source_fmu when it runs

        real = nt.model_header
        monkeypatch.setattr(nt, "model_header", lambda *a, **k: real(*a, **k) + "\n/* changed table */\n")
        assert fmu_kinds.native_fmu_is_stale("Girder")
    finally:
        b.set_build_dirs(*before)


def test_a_native_build_that_fails_falls_back_to_python_in_one_line(monkeypatch, capsys):
    import cranefmu.fmu_kinds as kinds
    from cranefmu.errors import CraneFmuError
    from cranefmu.native.build import NativeBuildError

    def broken(**kw):
        raise NativeBuildError("Rope: cmake --build failed:\nRope.c:1: error: expected ';'")

    monkeypatch.setattr(kinds, "native_reason", lambda scene: None)
    monkeypatch.setattr(kinds, "native_ssp_is_stale", lambda scene_dir: True)
    monkeypatch.setattr(kinds, "build_native", broken)
    assert kinds.scene_path("elastic_pendulum").parent.name != "native"
    assert capsys.readouterr().err.strip().splitlines()[-1] == (
        "cranefmu: scene elastic_pendulum runs with the pythonfmu FMUs: its native FMUs could not be built "
        "(Rope: cmake --build failed:)")
    with pytest.raises(CraneFmuError, match="^scene elastic_pendulum: the native FMUs could not be built: Rope: cmake"):
        kinds.scene_path("elastic_pendulum", "native")
