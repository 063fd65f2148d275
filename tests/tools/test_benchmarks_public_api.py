"""Benchmarks use the public API only (issue 21): no script puts tests/ on sys.path, reaches into the
master's stepping loop (``master.run._loop``) or patches fmpy's private function loader."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
PRIVATE = {
    "tests/ on sys.path": re.compile(r"sys\.path\.(insert|append)\([^\n]*\b(tests|TESTS)\b"),
    "master.run._loop": re.compile(r"\b_loop\b"),
    "fmpy's _loadFunctions": re.compile(r"_loadFunctions"),
}


def offences(text: str) -> list[str]:
    """The private reaches in one script's text, named."""
    return [what for what, pattern in PRIVATE.items() if pattern.search(text)]


def test_the_check_catches_each_reach():
    assert offences('sys.path.insert(0, str(ROOT / "tests"))') == ["tests/ on sys.path"]
    assert offences("sys.path.insert(0, str(TESTS))") == ["tests/ on sys.path"]
    assert offences("from cranefmu.master.run import _loop") == ["master.run._loop"]
    assert offences("fmi1._FMU._loadFunctions = timed") == ["fmpy's _loadFunctions"]
    assert offences("x, f = hoist_loop()\nsys.path.insert(0, str(Path(__file__).parent))") == []


@pytest.mark.parametrize("script", sorted(p.name for p in BENCH.glob("*.py")))
def test_benchmark_uses_public_api_only(script):
    found = offences((BENCH / script).read_text())
    assert not found, f"benchmarks/{script}: {', '.join(found)}"
