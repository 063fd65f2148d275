"""The compiled exchange's check against numpy (master/kernel: its product must give numpy's bits) is kept
beside the library for this numpy and BLAS: a later process reads the sizes checked instead of checking them
again (a cold ``cranefmu run`` spent 0.02-0.2 s of CPU on it), and another numpy or BLAS checks anew."""
from __future__ import annotations

import numpy as np
import pytest

from cranefmu.master import kernel


@pytest.fixture
def lib(monkeypatch, tmp_path):
    built = kernel.library()
    if built is None:
        pytest.skip(f"no compiled exchange here: {kernel.why_not}")
    monkeypatch.setattr(kernel, "_FOLDER", [tmp_path])
    monkeypatch.setattr(kernel, "_CHECKED", set())
    return built


def _no_check(*args, **kwargs):
    raise AssertionError("checked again")


def test_the_sizes_checked_are_kept_and_read_by_a_later_process(lib, monkeypatch):
    assert kernel.agrees_with_numpy(lib, [3, 5], trials=2)
    (kept,) = list(kernel._FOLDER[0].glob("agrees_*.txt"))
    assert kept.read_text().split() == ["3", "5"]
    monkeypatch.setattr(kernel, "_CHECKED", set())            # a new process: nothing checked in it
    monkeypatch.setattr(np.random, "default_rng", _no_check)  # the check draws its values from here
    assert kernel.agrees_with_numpy(lib, [5, 3])
    assert kernel._CHECKED == {3, 5}


def test_another_numpy_checks_anew(lib, monkeypatch):
    assert kernel.agrees_with_numpy(lib, [4], trials=2)
    monkeypatch.setattr(kernel, "_CHECKED", set())
    monkeypatch.setattr(np, "__version__", np.__version__ + ".other")
    monkeypatch.setattr(np.random, "default_rng", _no_check)
    with pytest.raises(AssertionError, match="checked again"):
        kernel.agrees_with_numpy(lib, [4])
