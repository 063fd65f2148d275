"""Fixtures every layer shares: the FMUs and scenes are built once per test session (only what is stale).

The helper modules beside this file (scene_edit, cli_process, pendulum_cases, the faulty package and the
re-exports of cranefmu.studies' model_cases, fmu_child, interop_hosts, oscillator, ...) are imported by plain name from every layer
folder: this directory is put on sys.path here, whatever pytest's import mode (README.md)."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

HELPERS = str(Path(__file__).resolve().parent)
if HELPERS not in sys.path:
    sys.path.insert(0, HELPERS)


@pytest.fixture(scope="session")
def built():
    """Build every stale FMU and SSP; returns the checkout's fmus/ directory."""
    from cranefmu import build as b

    b.build(verbose=False)
    return b.FMU_DIR


@pytest.fixture(scope="session")
def oscillator_ssp(tmp_path_factory):
    """The master's test problem (src/cranefmu/studies/oscillator): two FMUs built from test models, one .ssp."""
    from oscillator import build_oscillator

    return build_oscillator(tmp_path_factory.mktemp("oscillator"))
