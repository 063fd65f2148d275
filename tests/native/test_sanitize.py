"""cranefmu.sanitize: CRANEFMU_SANITIZE adds AddressSanitizer's flags to the C this package compiles, nothing when
unset, and names a value it does not know (tests/README.md, "Memory faults")."""
from __future__ import annotations

import pytest

from cranefmu.sanitize import VARIABLE, sanitize_flags


def test_unset_adds_nothing_and_address_adds_the_sanitizer(monkeypatch):
    monkeypatch.delenv(VARIABLE, raising=False)
    assert sanitize_flags() == []
    monkeypatch.setenv(VARIABLE, "")
    assert sanitize_flags() == []
    monkeypatch.setenv(VARIABLE, "address")
    assert sanitize_flags() == ["-fsanitize=address", "-fno-omit-frame-pointer", "-g"]


def test_an_unknown_sanitizer_is_one_line_naming_it(monkeypatch):
    monkeypatch.setenv(VARIABLE, "thread")
    with pytest.raises(ValueError) as err:
        sanitize_flags()
    assert str(err.value) == "CRANEFMU_SANITIZE='thread' is not a sanitizer here: allowed address or unset"


def test_the_kernel_flags_follow_the_variable(monkeypatch):
    from cranefmu.master.kernel import _flags

    monkeypatch.delenv(VARIABLE, raising=False)
    assert _flags("unix") == ["-O2", "-ffp-contract=off", "-std=c99"]   # the plain build, as before
    monkeypatch.setenv(VARIABLE, "address")
    assert _flags("unix")[-3:] == ["-fsanitize=address", "-fno-omit-frame-pointer", "-g"]
