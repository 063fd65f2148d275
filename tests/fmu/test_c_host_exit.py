"""Every pythonfmu FMU runs in a plain C host (support/cranefmu_support/c_host/host.c: dlopen, instantiate,
initialize, doSteps, terminate, free, return 0) and the process exits 0 (issue 33).

Before cranefmu.adapter.pythonfmu_exit, pythonfmu 0.7.0's binary released its static interpreter guard
twice at exit (C++'s exit handler, then its ELF destructor on the freed block) and 6 of the 8 FMUs aborted
with ``free(): corrupted unsorted chunks`` (exit 134) on every try; the FMU now empties the guard from an
exit handler of its own that runs first.  Each host is a child process."""
from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from cranefmu_support.c_host import native

FMUS = ("Boom", "Chassis", "Chassis4", "Drive", "Girder", "Pendulum", "Rope", "SlewingBoom")
H = 2e-3


def host_config(built: Path, names: tuple[str, ...], workdir: Path) -> Path:
    """A config running ``names`` side by side, uncoupled, at their defaults for 5 steps, recording two
    Real outputs of each."""
    from fmpy import extract, read_model_description

    fmus, outputs = [], []
    for name in names:
        unzipped = Path(extract(str(built / f"{name}.fmu"), unzipdir=str(workdir / name)))
        fmus.append((name, unzipped))
        md = read_model_description(str(unzipped))
        outputs += [(name, v.name) for v in md.modelVariables if v.causality == "output" and v.type == "Real"][:2]
    config = workdir / "host.cfg"
    native.write_config(config, fmus, {}, [], outputs, 0.0, 5 * H, H)
    return config


def run(c_host: Path, config: Path, workdir: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(c_host), str(config), str(workdir / "out.csv")], capture_output=True, text=True,
                          env=native.host_environment(), timeout=120)


@pytest.mark.parametrize("name", FMUS)
def test_c_host_exits_0_after_a_pythonfmu_fmu(built, c_host, tmp_path, name):
    done = run(c_host, host_config(built, (name,), tmp_path), tmp_path)
    assert done.returncode == 0, f"exit {done.returncode}: {done.stderr[-600:]}"
    assert "steps 5 " in done.stdout and "freed 1 instances" in done.stdout
    rows = (tmp_path / "out.csv").read_text().splitlines()
    assert len(rows) == 1 + 6 and "nan" not in rows[-1]


def test_c_host_exits_0_after_two_pythonfmu_libraries(built, c_host, tmp_path):
    """Two binaries, two guards: the one whose guard started the interpreter finalizes it at exit."""
    done = run(c_host, host_config(built, ("Rope", "Pendulum"), tmp_path), tmp_path)
    assert done.returncode == 0, f"exit {done.returncode}: {done.stderr[-600:]}"
    assert "freed 2 instances" in done.stdout
