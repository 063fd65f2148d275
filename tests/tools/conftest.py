"""Fixtures of the tools layer (CLI, output files, robustness of a run)."""
from __future__ import annotations

import os
import subprocess

import pytest

from faulty import faulty_fmu, faulty_scene
from scene_edit import scene_ssp


@pytest.fixture(scope="session")
def faulty_ssp(built, tmp_path_factory):
    """elastic_pendulum plus the unconnected ``Faulty`` component (tests/faulty), built once per session;
    tests set ``faulty.t_fail`` / ``faulty.t_segfault`` to make it fail."""
    d = tmp_path_factory.mktemp("faulty")
    return faulty_scene(scene_ssp(), faulty_fmu(d), d / "faulty.ssp")


@pytest.fixture
def tmpfs(tmp_path):
    """``tmpfs(name, options)``: a tmpfs mounted at ``tmp_path / name`` with the mount ``options`` (``size=1m``,
    ``ro,size=64k``), unmounted after the test; the test is skipped where it cannot be mounted (root only)."""
    mounted = []

    def mount(name: str, options: str):
        path = tmp_path / name
        path.mkdir()
        if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)],
                                               capture_output=True).returncode != 0:
            pytest.skip(f"cannot mount a tmpfs ({options}) here (root only)")
        mounted.append(path)
        return path

    yield mount
    for path in mounted:
        subprocess.run(["umount", "-l", str(path)], check=False)


@pytest.fixture
def small_disk(tmpfs):
    """A 1 MiB tmpfs under the test's directory (root only): a disk that fills (room for a CSV header and about
    1000 rows of elastic_pendulum, 0.7 MB)."""
    return tmpfs("small", "size=1m")
