"""Files lose nothing: a failed start leaves an existing CSV byte for byte; two runs on one file never
interleave; a full disk keeps the whole rows written before; targets are checked before the run
(one line, exit 2); errors at the boundary name the component and the cause."""
from __future__ import annotations

import signal
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from cranefmu.errors import ParameterSetError, SceneError, SimulationError
from cranefmu.master.results import read_csv
from cranefmu.master.run import run

from faulty import faulty_fmu, faulty_scene
from scene_edit import scene_ssp
from cli_process import cranefmu, start, wait_for_rows

OLD = b"time,x\n0.0,1.0\n"   # what a previous run left


def one_line_error(p: subprocess.CompletedProcess, needle: str) -> None:
    assert p.returncode == 2, p.stderr
    assert p.stderr.count("\n") == 1 and needle in p.stderr and "Traceback" not in p.stderr, p.stderr


def test_a_failed_start_leaves_an_existing_csv_byte_for_byte(built, tmp_path):
    out = tmp_path / "out.csv"
    out.write_bytes(OLD)
    p = cranefmu("run", "elastic_pendulum", "--stop-time", "0.1", "--set", "pendulum.mass=-1", "--output", str(out))
    one_line_error(p, "pendulum.mass = -1.0")
    assert out.read_bytes() == OLD and sorted(x.name for x in tmp_path.iterdir()) == ["out.csv"]
    with pytest.raises(ParameterSetError):
        run("elastic_pendulum", stop_time=0.1, parameters={"pendulum.mass": -1.0}, output=out)
    assert out.read_bytes() == OLD and sorted(x.name for x in tmp_path.iterdir()) == ["out.csv"]


def test_a_second_run_on_the_same_file_refuses_and_the_first_keeps_a_whole_file(built, tmp_path):
    first, out, _ = start(tmp_path)
    wait_for_rows(first, out)
    second = cranefmu("run", "elastic_pendulum", "--stop-time", "0.1", "--step", "1e-3", "--output", str(out))
    one_line_error(second, "another run is writing it")
    first.send_signal(signal.SIGINT)
    _, err = first.communicate(timeout=60)
    assert first.returncode == 130, err
    rows = read_csv(out)
    assert len(rows) > 1000 and np.allclose(rows["time"], 1e-3 * np.arange(len(rows)), rtol=0, atol=1e-9)
    again = cranefmu("run", "elastic_pendulum", "--stop-time", "0.1", "--step", "1e-3", "--output", str(out))   # the lock is gone
    assert again.returncode == 0, again.stderr
    assert len(read_csv(out)) == 101


def test_disk_full_on_dev_full_says_no_rows_were_written(built):
    p = cranefmu("run", "elastic_pendulum", "--stop-time", "0.1", "--output", "/dev/full")
    one_line_error(p, "No space left on device")
    assert "no rows were written" in p.stderr



def test_a_full_disk_keeps_the_whole_rows_written_before(built, small_disk):
    out = small_disk / "out.csv"
    p = cranefmu("run", "elastic_pendulum", "--stop-time", "5", "--step", "1e-3", "--output", str(out))
    one_line_error(p, "No space left on device")
    rows = read_csv(out)
    assert 1 < len(rows) < 5001
    assert f"the {len(rows)} rows written before are in {out}" in p.stderr
    assert np.allclose(rows["time"], 1e-3 * np.arange(len(rows)), rtol=0, atol=1e-9)
    assert [x.name for x in small_disk.iterdir()] == ["out.csv"]


def test_targets_are_checked_before_the_run(built, tmp_path):
    (tmp_path / "adir").mkdir()
    for args, needle in [(["--output", str(tmp_path / "adir")], "is a directory"),
                         (["--output", str(tmp_path / "nowhere" / "o.csv")], "does not exist"),
                         (["--output", str(tmp_path / "scene.ssp")], "names a scene or FMU file"),
                         (["--plot", "rope.tension,rope.nothing"], "--plot rope.nothing is not allowed: no such column"),
                         (["--stop-time", "1e6"], "more than --max-rows 1e+07"),
                         (["--set", "rope.x_hook=1"], "rope.x_hook is not allowed as a parameter: it is an input "
                                                      "connected to pendulum.x")]:
        p = cranefmu("run", "elastic_pendulum", "--stop-time", "0.1", *args, cwd=tmp_path)
        one_line_error(p, needle)
        assert "scene elastic_pendulum:" not in p.stdout   # refused before the run
    assert sorted(x.name for x in tmp_path.iterdir()) == ["adir"]


def test_plot_into_a_read_only_directory_is_refused_before_the_run(built, tmp_path, tmpfs):
    ro = tmpfs("ro", "ro,size=64k")
    p = cranefmu("run", "elastic_pendulum", "--stop-time", "0.1", "--plot", "--output", str(tmp_path / "o.csv"), cwd=ro)
    assert p.returncode == 0   # the CSV's directory is writable: figures go next to it
    p = cranefmu("run", "elastic_pendulum", "--stop-time", "0.1", "--plot", cwd=ro)
    one_line_error(p, "is not writable")
    assert "scene elastic_pendulum:" not in p.stdout


def test_a_run_with_an_output_file_streams_its_rows_and_reads_back_what_it_shows(built, tmp_path, monkeypatch,
                                                                                  capsys):
    """With --output FILE the CLI keeps no row in memory (issue 34: memory flat in run length): the CSV has
    them all; the summary and the figures read their columns back from it."""
    from cranefmu import cli
    from cranefmu.master import run as master_run

    kept = []
    real_run = master_run.run
    monkeypatch.setattr(master_run, "run", lambda spec, **kw: kept.append(spec.keep) or real_run(spec, **kw))
    out = tmp_path / "long.csv"
    assert cli.main(["run", "elastic_pendulum", "--stop-time", "0.5", "--step", "1e-3", "--in-process",
                     "--output", str(out),
                     "--plot", "rope.tension,pendulum.theta"]) == 0
    text = capsys.readouterr().out
    assert kept == [False]
    rows = read_csv(out)
    assert len(rows) == 501 and f"results: {out} (501 rows" in text
    # the summary, from the CSV: the tension's range and final value as the file has them
    tension = rows["rope.tension"]
    assert f"rope.tension             min {tension.min():.6g}  max {tension.max():.6g}  final {tension[-1]:.6g}" in text
    assert (tmp_path / "long_rope_tension_pendulum_theta.png").read_bytes()[:4] == b"\x89PNG"


def _variant(fmu: Path, dst: Path, edit) -> Path:
    dst.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(fmu) as zin, zipfile.ZipFile(dst, "w") as zout:
        for info in zin.infolist():
            zout.writestr(*edit(info.filename, zin.read(info.filename)))
    return dst


def test_boundary_errors_name_the_component_and_the_cause(built, tmp_path):
    fmu = faulty_fmu(tmp_path / "ok")

    def bad_import(name, data):
        script = name.startswith("resources/Faulty_") and name.endswith(".py")
        return name, (b"import no_such_module_xyz\n" + data) if script else data

    def no_binary(name, data):
        return name.replace("binaries/linux64/", "binaries/win64/"), data

    for edit, needle in [(bad_import, "component 'faulty' (Faulty) could not be instantiated: ModuleNotFoundError"),
                         (no_binary, "component 'faulty': Faulty.fmu has no binary for this platform (linux64): "
                                     "it has win64")]:
        broken = _variant(fmu, tmp_path / edit.__name__ / "Faulty.fmu", edit)
        ssp = faulty_scene(scene_ssp(), broken, tmp_path / f"{edit.__name__}.ssp")
        with pytest.raises(SceneError) as info:
            run(ssp, stop_time=0.01, step_size=1e-3)
        assert needle in str(info.value) and "\n" not in str(info.value)
        if edit is bad_import:
            assert "no_such_module_xyz" in str(info.value)


def test_a_segfault_inside_an_fmu_names_the_signal_and_the_component(faulty_ssp, tmp_path):
    ssp = faulty_ssp
    out = tmp_path / "crash.csv"
    with pytest.raises(SimulationError) as info:
        run(ssp, stop_time=1.0, parameters={"faulty.t_segfault": 0.5}, output=out, isolate=True)
    msg = str(info.value)
    assert "killed by SIGSEGV, inside component faulty" in msg and "Segmentation fault" in msg
    rows = read_csv(out)
    assert f"{len(rows)} rows written before are in {out}" in msg and rows["time"][-1] < 0.5


def test_build_fmi3_without_pythonfmu3_says_what_to_install():
    code = ("import sys; sys.modules['pythonfmu3'] = None; from cranefmu.cli import main; "
            "sys.exit(main(['build-fmi3', 'Rope']))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    one_line_error(p, "pip install 'cranefmu[fmi3]'")
