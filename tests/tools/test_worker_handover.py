"""The worker of ``cranefmu run`` runs from the command's extraction of the scene, moved into the job folder,
and extracts nothing itself (issue 23: a CLI run unzipped every scene and FMU twice, once per process)."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

# In a child (a process of its own, as the worker is): extract, hand over, adopt, then run with every
# unzip refused: the run must need none.
_CHILD = textwrap.dedent("""
    import sys
    from pathlib import Path
    from cranefmu.master import extracted, process, untrusted
    from cranefmu.master.run import _run_here
    from cranefmu.master.runspec import resolve

    spec = resolve("elastic_pendulum", stop_time=0.05, progress=False)
    root = process.scenes_root()
    folder, scene = extracted.hand_over(spec.ssp, Path(sys.argv[1]))
    print("root left", root.exists(), "components inside", all(folder in c.fmu.parents for c in scene.components))
    extracted.adopt(spec.ssp, folder, scene)

    def refuse(*args, **kwargs):
        raise AssertionError("extracted again")

    safe_extract, untrusted.safe_extract = untrusted.safe_extract, refuse
    result = _run_here(spec, None)
    print("rows", result.rows)
""")


def test_a_worker_runs_from_the_handed_over_extraction_without_unzipping(built, tmp_path):
    jobdir = tmp_path / "job"
    jobdir.mkdir()
    out = subprocess.run([sys.executable, "-c", _CHILD, str(jobdir)], cwd=tmp_path, capture_output=True, text=True,
                         env={**os.environ, "TMPDIR": str(tmp_path)}, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[:2] == ["root left False components inside True", "rows 11"]   # 5 ms stored step
    assert [p.name.startswith("scene_") for p in jobdir.iterdir()] == [True]


@pytest.mark.parametrize("where", ["--isolate", "--in-process"])
def test_a_cli_run_leaves_no_extraction_behind(built, tmp_path, where):
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    out = subprocess.run([sys.executable, "-m", "cranefmu.cli", "run", "elastic_pendulum", "--stop-time", "0.05",
                          "--output", str(tmp_path / "out.csv"), where], capture_output=True, text=True, cwd=tmp_path,
                         env={**os.environ, "TMPDIR": str(tmpdir)}, timeout=300)
    assert out.returncode == 0, out.stderr
    assert list(tmpdir.iterdir()) == []


def test_an_api_caller_keeps_its_extraction_for_its_other_runs(built, tmp_path):
    """Only the command hands its extraction over: an API caller may run in other threads from that folder."""
    code = ("import cranefmu\nfrom cranefmu.master import process\n"
            "cranefmu.simulate('elastic_pendulum', stop_time=0.05, isolate=True, progress=False)\n"
            "print([folder.is_dir() for folder, _ in process.SCENES.values()])\n")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True,
                         env={**os.environ, "TMPDIR": str(tmp_path)}, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["[True]"]
