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
def small_disk(tmp_path):
    """A 1 MiB tmpfs under the test's directory (root only): a disk that fills (room for a CSV header and about
    1000 rows of elastic_pendulum, 0.7 MB)."""
    mount = tmp_path / "small"
    mount.mkdir()
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(mount)],
                                           capture_output=True).returncode != 0:
        pytest.skip("cannot mount a small tmpfs here (root only)")
    yield mount
    subprocess.run(["umount", "-l", str(mount)], check=False)
