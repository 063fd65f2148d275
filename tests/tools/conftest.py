"""Fixtures of the tools layer (CLI, output files, robustness of a run)."""
from __future__ import annotations

import pytest

from faulty import faulty_fmu, faulty_scene
from scene_edit import scene_ssp


@pytest.fixture(scope="session")
def faulty_ssp(built, tmp_path_factory):
    """elastic_pendulum plus the unconnected ``Faulty`` component (tests/faulty), built once per session;
    tests set ``faulty.t_fail`` / ``faulty.t_segfault`` to make it fail."""
    d = tmp_path_factory.mktemp("faulty")
    return faulty_scene(scene_ssp(), faulty_fmu(d), d / "faulty.ssp")
