"""The command line: a run writes the CSV; user mistakes exit 2 with one clear line, no traceback."""
import csv

from cli_process import cranefmu


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


def test_run_iterative_adaptive_with_plots(oscillator_ssp, tmp_path):
    out = tmp_path / "osc.csv"
    p = cranefmu("run", str(oscillator_ssp), "--stop-time", "0.5", "--step", "1e-2", "--algorithm", "iterative",
                 "--extrapolation", "2", "--adaptive", "--tolerance", "1e-4", "--set", "mass.x0=0.1",
                 "--output", str(out), "--plot", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "coupling iterations" in p.stdout and "power bond coupling" in p.stdout and "rejected" in p.stdout
    header = out.read_text().splitlines()[0].split(",")
    assert header[:2] == ["time", "mass.x"] and "bond.coupling.E" in header and "mass.flag" in header
    pngs = sorted(x.name for x in tmp_path.glob("osc_*.png"))
    assert pngs and all((tmp_path / n).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for n in pngs)
    p = cranefmu("run", str(oscillator_ssp), "--stop-time", "0.1", "--step", "1e-2", "--plot", "mass.x,spring.F",
                 cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "oscillator_mass_x_spring_f.png").is_file()


def test_bad_run_settings_exit_2_naming_the_item(oscillator_ssp, tmp_path):
    for args, needle in [(["--algorithm", "newton"], "algorithm = 'newton' is not allowed: one of jacobi, "
                          "gauss-seidel, iterative"),
                         (["--extrapolation", "3"], "extrapolation = 3 is not allowed"),
                         (["--accelerator", "broyden"], "accelerator = 'broyden' is not allowed"),
                         (["--plot", "mass.nothing"], "--plot mass.nothing is not allowed: no such column"),
                         (["--adaptive", "--step-control", "pid"], "step_control = 'pid' is not allowed")]:
        p = cranefmu("run", str(oscillator_ssp), "--stop-time", "0.05", "--step", "1e-2", *args, cwd=tmp_path)
        assert p.returncode == 2, (args, p.stderr)
        assert needle in p.stderr and "Traceback" not in p.stderr, (args, p.stderr)


def test_run_options_and_signature_come_from_the_one_settings_definition():
    """Every Settings field is a `cranefmu run` option (typed, absent unless given, its default in --help)
    and a keyword of run() with the same default."""
    import inspect
    from dataclasses import fields

    from cranefmu.cli import build_parser
    from cranefmu.master.run import run
    from cranefmu.master.settings import Settings, flag_of

    parser = build_parser()
    assert not hasattr(parser.parse_args(["run", "x"]), "step_size")   # the default lives in Settings only
    given = {"value": "2", "list": "a,b", "switch": None, "negate": None, "off": None}
    expect = {"value": None, "list": ["a", "b"], "switch": True, "negate": False, "off": False}
    signature = inspect.signature(run).parameters
    for f in fields(Settings):
        form = f.metadata["form"]
        extra = [given[form]] if given[form] is not None else []
        args = parser.parse_args(["run", "x", flag_of(f), *extra])
        want = f.metadata["type"]("2") if form == "value" else expect[form]
        assert getattr(args, f.name) == want and type(getattr(args, f.name)) is type(want), f.name
        assert signature[f.name].default == f.default, f.name
    assert parser.parse_args(["run", "x", "--stop-when", "none"]).stop_when == []
