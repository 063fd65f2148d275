"""`cranefmu converge`: observed order of the reported errors, the recommendation, bad arguments."""
import csv
import math

import pytest

from cranefmu.cli import main


def run_table(text: str) -> dict[str, dict]:
    """The first table of the report: run label -> worst rel, order, wall, meets."""
    rows = {}
    for line in text.splitlines():
        parts = line.split()
        if parts and parts[0].startswith(("H=", "tol=")) and len(parts) >= 9 and parts[-1] in ("yes", "no"):
            rows[parts[0]] = {"worst": float(parts[1]), "wall": float(parts[6]), "meets": parts[-1] == "yes"}
    return rows


def error_table(text: str) -> dict[tuple[str, str], dict]:
    rows = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) == 5 and parts[0].startswith("H=") and "." in parts[1]:
            rows[(parts[0], parts[1])] = {"abs": float(parts[2]), "rel": float(parts[3]),
                                          "order": None if parts[4] == "-" else float(parts[4])}
    return rows


@pytest.fixture(scope="module")
def report(built, tmp_path_factory):
    out = tmp_path_factory.mktemp("converge")
    import io
    from contextlib import redirect_stdout

    buf = io.StringIO()
    with redirect_stdout(buf):
        rc = main(["converge", "elastic_pendulum", "--stop-time", "1", "--steps", "1e-3,4e-3,2e-3",
                   "--extrapolation", "0", "--target", "2e-3", "--no-modes", "--output", str(out)])
    # (--no-modes: this module studies the range errors; the modal check is test_converge_modes.py's)
    assert rc == 0
    return buf.getvalue(), out


def test_jacobi_zero_order_hold_converges_with_order_one(report):
    text, _ = report
    errors = error_table(text)
    orders = [e["order"] for e in errors.values() if e["order"] is not None]
    assert len(orders) == 4  # two keys, two neighbour pairs
    for p in orders:
        assert p == pytest.approx(1.0, abs=0.2)
    # the relative error is the absolute error over the reference's range, so both fall together
    for key in ("pendulum.theta", "rope.tension"):
        assert errors[("H=0.001", key)]["abs"] < errors[("H=0.004", key)]["abs"] / 3


def test_recommendation_is_the_cheapest_run_meeting_the_target(report):
    text, _ = report
    table = run_table(text)
    assert set(table) == {"H=0.004", "H=0.002", "H=0.001"}
    for r in table.values():
        assert r["meets"] == (r["worst"] <= 2e-3)
    meeting = {k: r for k, r in table.items() if r["meets"]}
    assert meeting and len(meeting) < len(table)  # the target separates the runs
    cheapest = min(meeting, key=lambda k: meeting[k]["wall"])
    assert f"recommended: {cheapest} " in text


def test_writes_the_table_and_the_plot(report):
    text, out = report
    with open(out / "converge.csv") as f:
        rows = list(csv.DictReader(f))
    table = run_table(text)
    assert [r["run"] for r in rows] == list(table)
    for r in rows:
        assert float(r["worst_rel"]) == pytest.approx(table[r["run"]]["worst"], rel=5e-3)
        assert int(r["steps"]) == round(1.0 / float(r["step_size"]))
        assert math.isfinite(float(r["real_time_factor"]))
    assert (out / "error_vs_wall.png").stat().st_size > 1000


@pytest.mark.parametrize("args, named", [
    (["--steps", "1e-3,abc"], "--steps 'abc'"),
    (["--steps", "1e-3,-2e-3"], "--steps '-2e-3'"),
    (["--reference", "exact"], "reference = 'exact'"),
    (["--extrapolation", "3"], "extrapolation = 3"),
    (["--algorithm", "newton"], "algorithm = 'newton'"),
    (["--target", "0"], "target = 0"),
])
def test_bad_arguments_give_a_clear_error(args, named, capsys):
    assert main(["converge", "elastic_pendulum", *args]) == 2
    err = capsys.readouterr().err
    assert named in err and "not allowed" in err


def test_unknown_scene_is_named(capsys):
    assert main(["converge", "no_such_scene", "--steps", "1e-3"]) == 2
    assert "no_such_scene" in capsys.readouterr().err


def test_adaptive_runs_are_measured_against_their_tolerance(built, tmp_path, capsys):
    """--tolerances: one adaptive run per tolerance; the reported error falls with the tolerance and the
    order column is taken against the tolerance (error proportional to it: about 1)."""
    assert main(["converge", "elastic_pendulum", "--stop-time", "1", "--steps", "2e-3", "--extrapolation", "1",
                 "--tolerances", "1e-3,1e-4", "--no-modes", "--output", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    table = run_table(text)
    assert set(table) == {"H=0.002", "tol=0.001", "tol=0.0001"}
    assert table["tol=0.0001"]["worst"] < table["tol=0.001"]["worst"] / 3
    rows = {r["run"]: r for r in csv.DictReader(open(tmp_path / "converge.csv"))}
    assert float(rows["tol=0.0001"]["tolerance"]) == 1e-4
    assert int(rows["tol=0.0001"]["steps"]) > int(rows["tol=0.001"]["steps"])
    order = float(rows["tol=0.0001"]["pendulum.theta.order"])
    assert order == pytest.approx(1.0, abs=0.3)
