"""``cranefmu info``'s speed lines come from benchmarks/kinds_speed.py's table (cranefmu/speed.json), the
run over each scene's whole natural length: parsed as written, quoted with the file and its stamp."""
from __future__ import annotations

import json

import pytest

from cranefmu import speed_table

TABLE = """# Every scene at its stored settings with each kind of FMU

Commit abc1234, 2026-11-28 12:04 UTC, load 2.1 (benchmarks/kinds_speed.py)
2 cores shared; minimum over 2 round(s); load at the end 3.3.

| scene | T [s] | FMUs | RTF cold, CPU | RTF cold, wall | RTF warm, CPU | RTF warm, wall | cold CPU / wall [s] | warm CPU / wall [s] |
| --- | --- | --- | --- | --- | --- | --- | --- | --- |
| truck_telescope | 40 | native | 37.48 | 35.47 | 148.84 | 137.35 | 1.07 / 1.13 | 0.27 / 0.29 |
| truck_telescope | 40 | python | 13.63 | 11.36 | 21.64 | 10.24 | 2.94 / 3.52 | 1.85 / 3.91 |
"""


def test_the_table_is_read_as_written(tmp_path):
    (tmp_path / "t.md").write_text(TABLE)
    data = speed_table.write_from_table(tmp_path / "t.md", tmp_path / "speed.json")
    assert json.loads((tmp_path / "speed.json").read_text()) == data
    row = data["scenes"]["truck_telescope"]
    assert row["stop"] == 40.0
    assert row["native"] == {"rtf_cold_cpu": 37.48, "rtf_cold_wall": 35.47, "rtf_warm_cpu": 148.84,
                             "rtf_warm_wall": 137.35, "cold_cpu": 1.07, "cold_wall": 1.13, "warm_cpu": 0.27,
                             "warm_wall": 0.29}
    assert data["measured"].startswith("Commit abc1234")
    lines = speed_table.info_lines("truck_telescope", tmp_path / "speed.json")
    assert "benchmarks/results/kinds_speed.md: Commit abc1234" in lines[0] and "whole 40 s" in lines[0]
    assert "cold (the whole cranefmu run command) 37.48x on CPU" in lines[1]
    assert "warm (a second run in one process) 21.64x on CPU" in lines[2]
    assert speed_table.info_lines("hook_sway", tmp_path / "speed.json") == [
        "  speed: not measured for this scene (benchmarks/kinds_speed.py)"]


def test_a_table_without_rows_is_refused(tmp_path):
    (tmp_path / "t.md").write_text("# nothing\n")
    with pytest.raises(ValueError, match="no row"):
        speed_table.write_from_table(tmp_path / "t.md", tmp_path / "speed.json")


def test_the_shipped_record_covers_every_scene_over_its_natural_length():
    from cranefmu.master.runspec import resolve
    from cranefmu.scenes.catalog import scene_names

    data = json.loads(speed_table.STORE.read_text())
    for scene in scene_names():
        assert data["scenes"][scene]["stop"] == resolve(scene, fmus="python").settings.stop_time, scene


def test_the_docs_tables_are_the_record():
    """docs/benchmarks.md and docs/scenes.md carry the table kinds_speed.py generates from the same record."""
    from pathlib import Path

    docs = Path(__file__).resolve().parents[2] / "docs"
    block = "\n".join(speed_table.docs_block(json.loads(speed_table.STORE.read_text())))
    for page in ("benchmarks.md", "scenes.md"):
        assert block in (docs / page).read_text(), page
