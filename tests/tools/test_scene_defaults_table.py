"""benchmarks/scene_defaults.py re-derives the choice and the ladder from a results file it wrote
(``--from-table``): every candidate row is read back, the implicit group's among them."""
import importlib.util
import json
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "scene_defaults.py"


def load():
    spec = importlib.util.spec_from_file_location("scene_defaults_script", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_implicit_group_rows_are_read_back(tmp_path):
    """The label 'jacobi x2 implicit all bonds H 10 ms' has a space in its bond list: the parser skipped it (and
    with it every implicit candidate of the truck, so --from-table chose among the explicit ones only)."""
    sd = load()
    cells = "| 0.00059 | chassis.N_rear | 0.00051 | 0.00791 | 1000 | 35.50 | 0.3 | 0.177 | 2.54e+05 | 0.000233 | nan | no |"
    path = tmp_path / "defaults.md"
    path.write_text("\n".join([
        "## truck_telescope (10 s; key outputs pendulum.theta, chassis.N_rear)", "",
        "| candidate | worst rel err | worst key | worst f err | worst zeta err | steps | wall [s] | RTF | bond residual [J] "
        "| carried [J] | residual/carried (worst bond) | sway ratio | adds energy | passes |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        f"| jacobi x2 H 5 ms {cells} yes |",
        f"| jacobi x2 implicit all bonds H 10 ms **chosen** {cells} yes |",
        f"| jacobi x1 implicit all bonds H 20 ms {cells} no |", ""]))
    rows, facts = sd.rows_from_table(path)["truck_telescope"]
    assert [(r["label"], r["extrapolation"], r["step_size"], r["ok"]) for r in rows] == [
        ("jacobi x2 H 5 ms", 2, 0.005, True), ("jacobi x2 implicit all bonds H 10 ms", 2, 0.01, True),
        ("jacobi x1 implicit all bonds H 20 ms", 1, 0.02, False)]
    assert rows[0]["implicit"] is None and rows[1]["implicit"] == sd.IMPLICIT["truck_telescope"]["implicit"]
    assert facts["keys"] == ("pendulum.theta", "chassis.N_rear")


def test_a_bond_at_rest_adds_no_energy():
    """truck_slewing's drum bond (the rope held: no speed on either side) carries 0 J with 0 J of residual: it
    counted as an infinite residual ratio, so every candidate 'added energy' and none passed."""
    sd = load()
    assert sd.worst_bond_ratio({"hook": 8e-5, "drum": 0.0}, {"hook": 234.0, "drum": 0.0}) == 8e-5 / 234.0
    assert sd.worst_bond_ratio({"hook": 8e-5, "drum": 1e-9}, {"hook": 234.0, "drum": 0.0}) == float("inf")
    assert sd.worst_bond_ratio({}, {}) == 0.0


def test_the_measurement_is_stored_in_the_scene_folder(tmp_path):
    """write_fidelity writes ssp/<scene>/fidelity.json (one file per scene, the entry alone: no other scene's
    table touched), and the docs' ladders are read back from the folders."""
    sd = load()
    sd.SSP = tmp_path
    (tmp_path / "elastic_pendulum").mkdir()
    (tmp_path / "hook_sway").mkdir()
    (tmp_path / "hook_sway" / "fidelity.json").write_text('{"untouched": 1}\n')
    row = {"scene": "elastic_pendulum", "label": "jacobi x1 H 2 ms", "algorithm": "jacobi", "extrapolation": 1, "step_size": 0.002, "rtf": 40.0,
           "worst": 0.001, "freq_err": 0.0001, "damp_err": 0.01, "cpu": 0.25, "ok": True, "fmus": "native", "exchange": "compiled"}
    sd.write_fidelity("elastic_pendulum", [row], {"stop": 10.0, "natural": 30.0}, "abc1234", "scene_defaults.py",
                      when="2026-11-28 17:00")
    stored = json.loads((tmp_path / "elastic_pendulum" / "fidelity.json").read_text())
    assert stored["chosen"]["label"] == "jacobi x1 H 2 ms" and stored["span"] == 10.0 and stored["natural"] == 30.0
    assert [r["label"] for r in stored["ladder"]] == ["jacobi x1 H 2 ms"]
    assert json.loads((tmp_path / "hook_sway" / "fidelity.json").read_text()) == {"untouched": 1}
    assert set(stored) == {"measured", "span", "chosen", "ladder", "natural", "cost"}   # the entry, not a table
    (tmp_path / "hook_sway" / "fidelity.json").unlink()
    assert "`elastic_pendulum` (10 s; chosen: jacobi x1 H 2 ms;" in "\n".join(sd.ladder_section())


# a written table's candidate rows: the cells after the label, the header and the rule
CELLS = "| 0.00059 | rope.tension | 0.00051 | 0.00791 | 1000 | 0.5 | 40.0 | 0.177 | 2.54e+05 | 0.000233 | nan | no |"
HEADER = ("| candidate | worst rel err | worst key | worst f err | worst zeta err | steps | CPU [s] | RTF | bond residual [J] "
          "| carried [J] | residual/carried (worst bond) | sway ratio | adds energy | passes |")
RULE = "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"


def test_retiming_into_the_same_file_keeps_the_other_scenes_and_each_sections_facts(tmp_path, monkeypatch):
    """``--from-table F --rounds N --output F`` re-times the candidates and merges the sections into F: it wrote
    F anew with the first scene's table alone (and then failed on the next scene, F's header gone); the lines
    above each table (the natural length, the monolith's answer) are the measured ones."""
    sd = load()
    path = tmp_path / "defaults.md"
    path.write_text("\n".join([
        "# Scene defaults", "", "- date: 2026-11-28 14:02 UTC, commit 7697f7f", "", "## Summary", "",
        "| scene | simulated [s] | chosen | worst rel err | RTF | old default jacobi x0 1 ms |",
        "| --- | --- | --- | --- | --- | --- |",
        "| elastic_pendulum | 10 | jacobi x2 H 5 ms | 0.00059 | 40.0 | error 0.00264, RTF 50.2 |",
        "| hook_sway | 10 | jacobi x2 H 3 ms | 0.00059 | 40.0 | error 0.318, RTF 42.9 |", "",
        "## elastic_pendulum (10 s; key outputs pendulum.theta, rope.tension)", "",
        "Every candidate ran over the natural length 20 s (measured facts).", "", HEADER, RULE,
        f"| jacobi x2 H 5 ms **chosen** {CELLS} yes |", "",
        "## hook_sway (10 s; key outputs pendulum.theta_payload)", "", HEADER, RULE,
        f"| jacobi x2 H 3 ms **chosen** {CELLS} yes |", ""]) + "\n")

    def faster(scene, rows, stop, rounds):
        for r in rows:
            r["cpu"], r["rtf"] = 0.1, 200.0

    monkeypatch.setattr(sd, "retime", faster)
    monkeypatch.setattr(sd, "write_fidelity", lambda *a, **k: None)
    monkeypatch.setattr(sd, "write_docs_ladders", lambda: None)
    assert sd.main(["--from-table", str(path), "--rounds", "1", "--output", str(path), "--scenes",
                    "elastic_pendulum"]) == 0
    text = path.read_text()
    assert "## hook_sway (10 s" in text and "| hook_sway | 10 | jacobi x2 H 3 ms | 0.00059 | 40.0 |" in text
    assert "| elastic_pendulum | 10 | jacobi x2 H 5 ms | 0.00059 | 200.0 | error 0.00264, RTF 50.2 |" in text
    assert "Every candidate ran over the natural length 20 s (measured facts)." in text
    assert "- elastic_pendulum: re-measured" in text and "- date: 2026-11-28 14:02 UTC, commit 7697f7f" in text


def test_a_retimed_entry_says_when_and_at_which_commit_its_costs_were_measured(tmp_path, monkeypatch):
    """The stored entry of a re-time carried only the table's date and commit (when the errors were measured), so
    a cost re-timed hours later read as measured then."""
    sd = load()
    path = tmp_path / "defaults.md"
    path.write_text("\n".join([
        "# Scene defaults", "", "- date: 2026-11-28 14:02 UTC, commit 7697f7f", "",
        "## elastic_pendulum (10 s; key outputs pendulum.theta, rope.tension)", "", HEADER, RULE,
        f"| jacobi x2 H 5 ms **chosen** {CELLS} yes |", ""]) + "\n")
    stored = []
    monkeypatch.setattr(sd, "retime", lambda scene, rows, stop, rounds: None)
    monkeypatch.setattr(sd, "head_commit", lambda: "feed123")
    monkeypatch.setattr(sd, "write_fidelity", lambda *a, **k: stored.append((a, k)))
    monkeypatch.setattr(sd, "write_docs_ladders", lambda: None)
    assert sd.main(["--from-table", str(path), "--rounds", "2", "--output", str(tmp_path / "out.md"), "--scenes",
                    "elastic_pendulum"]) == 0
    (scene, _, _, commit, command), kw = stored[0]
    assert scene == "elastic_pendulum" and commit == "7697f7f" and kw["when"] == "2026-11-28 14:02"
    assert "re-timed 20" in command and "UTC at commit feed123: --from-table --rounds 2" in command
