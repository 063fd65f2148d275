"""Fixtures every layer shares: the FMUs and scenes are built once per test session (only what is stale).

The helper modules beside this file (scene_edit, cli_process, pendulum_cases, the faulty package, ...) are
imported by plain name from every layer folder: this directory is put on sys.path here, whatever pytest's
import mode (README.md); so is support/ (the cranefmu_support package: model_cases, fmu_child, oscillator,
c_fmu, ..., scaffolding the wheel does not ship)."""
from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

HELPERS = str(Path(__file__).resolve().parent)
SUPPORT = str(Path(__file__).resolve().parents[1] / "support")
for _folder in (SUPPORT, HELPERS):
    if _folder not in sys.path:
        sys.path.insert(0, _folder)


@pytest.fixture(scope="session")
def built():
    """Build every stale FMU and SSP; returns the checkout's fmus/ directory.  Under pytest-xdist each
    worker asks: an exclusive lock on a file beside fmus/ makes the first build and the others find
    nothing stale."""
    import fcntl

    from cranefmu import build as b

    b.FMU_DIR.mkdir(parents=True, exist_ok=True)
    with open(b.FMU_DIR.parent / ".pytest_build.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            b.build(verbose=False)
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
    return b.FMU_DIR


@pytest.fixture(scope="session")
def lib():
    """The compiled exchange's library (cranefmu.master.kernel); the test is skipped where none can be built."""
    from cranefmu.master import kernel

    built = kernel.library()
    if built is None:
        pytest.skip(f"no compiled exchange here: {kernel.why_not}")
    return built


@pytest.fixture(scope="session")
def oscillator_ssp(tmp_path_factory):
    """The master's test problem (support/cranefmu_support/oscillator): two FMUs built from test models, one .ssp."""
    from cranefmu_support.oscillator import build_oscillator

    return build_oscillator(tmp_path_factory.mktemp("oscillator"))


_EXIT_STATUS: list[int] = []


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session, exitstatus):
    _EXIT_STATUS[:] = [int(exitstatus)]


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    """End the test process the way the master's worker processes end (``cranefmu.master.worker``): once
    pytest has written its report, run Python's exit handlers and leave with ``os._exit``, skipping the
    interpreter's teardown and the C/C++ static destructors of the hundreds of FMU binaries one test session
    loads (pythonfmu's, each native FMU's, libcosim's, ecos's).  A CI run ended with exit 139 after
    "1659 passed": one of those destructors crashed after every test had passed, and no traceback names it
    (faulthandler is off by then).  A crash in a test still fails: the tests that check a process exits
    cleanly (tests/fmu/test_process_exit.py, the CLI and host tests) do so in child processes."""
    if not _EXIT_STATUS or config.option.collectonly:
        return
    import atexit
    import os

    master_fmu = sys.modules.get("cranefmu.master.fmu")
    if master_fmu is not None:   # its only job is to keep the C teardown we skip from crashing
        atexit.unregister(master_fmu.release_pythonfmu_libraries)
    atexit._run_exitfuncs()      # temporary folders (cranefmu.master.process.clear, hosts' exports, pytest's)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(_EXIT_STATUS[0])


if os.environ.get("CRANEFMU_GC_EACH_TEST", "") not in ("", "0"):
    @pytest.hookimpl(trylast=True)
    def pytest_runtest_teardown(item, nextitem):
        """CRANEFMU_GC_EACH_TEST=1 (off by default; tests/README.md, "Memory faults"): a full garbage collection
        after every test, so that memory a test's native code damaged is found in that test's teardown, not by
        a collection hundreds of tests later; with PYTHONMALLOC=debug freed memory is filled, so a use of it
        crashes at once."""
        import gc

        gc.collect()
