"""Fixtures of the FMU-layer tests."""
from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def c_host(tmp_path_factory):
    """The project's plain FMI 2.0 C host (cranefmu_support.c_host), built against this machine's libpython so it
    can load the pythonfmu FMUs; the test is skipped without a C compiler or a shared libpython."""
    from cranefmu_support.c_host import native

    if native.compiler() is None:
        pytest.skip("no C compiler (gcc/cc) on PATH: the C host cannot be built")
    try:
        native.libpython()
    except RuntimeError as err:
        pytest.skip(str(err))
    return native.compile_host(tmp_path_factory.mktemp("c_host"))
