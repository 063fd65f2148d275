"""Shared fixtures: the FMUs and scenes are built once per test session (only what is stale)."""
from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def built():
    """Build every stale FMU and SSP; returns the checkout's fmus/ directory."""
    from cranefmu import build as b

    b.build(verbose=False)
    return b.FMU_DIR


@pytest.fixture(scope="session")
def oscillator_ssp(tmp_path_factory):
    """The master's test problem (tests/oscillator): two FMUs built from test models, one .ssp."""
    from oscillator import build_oscillator

    return build_oscillator(tmp_path_factory.mktemp("oscillator"))
