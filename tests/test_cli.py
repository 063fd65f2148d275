"""The command line: a run writes the CSV; user mistakes exit 2 with one clear line, no traceback."""
import csv
import subprocess
import sys


def cranefmu(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "cranefmu.cli", *args], capture_output=True, text=True, cwd=cwd)


def test_run_writes_csv_with_time_and_component_columns(built, tmp_path):
    out = tmp_path / "out.csv"
    p = cranefmu("run", "elastic_pendulum", "--stop-time", "0.5", "--step", "1e-3", "--output", str(out))
    assert p.returncode == 0, p.stderr
    rows = list(csv.reader(out.open()))
    assert rows[0][0] == "time" and "rope.tension" in rows[0] and "pendulum.theta" in rows[0]
    assert len(rows) == 1 + 501
    assert float(rows[-1][0]) == 0.5


def test_bad_inputs_exit_2_naming_the_item(built):
    for args, needle in [(["--step", "0"], "step_size = 0.0"),
                         (["--set", "rope.E=-1"], "rope.E = -1.0"),
                         (["--set", "rope.nothing=1"], "rope.nothing"),
                         (["--set", "pendulum.mass=abc"], "pendulum.mass = 'abc'")]:
        p = cranefmu("run", "elastic_pendulum", "--stop-time", "0.1", *args)
        assert p.returncode == 2, (args, p.stderr)
        assert needle in p.stderr and "Traceback" not in p.stderr
