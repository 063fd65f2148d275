"""A run's fixed Jacobi steps go to the compiled kernel in stretches of up to ``loop.STRETCH`` steps: each
stretch costs the observers a fixed set of numpy calls (benchmarks/warm_breakdown.py), so a scene's natural
length runs in as few calls as that bound allows."""
from __future__ import annotations

import pytest

from cranefmu.master import loop
from cranefmu.master.kernel import plan
from cranefmu.master.run import run


@pytest.fixture
def kernel_calls(lib, built, monkeypatch) -> list[int]:
    """The Jacobi steps of each compiled kernel call of the runs in the test (skips without a C compiler)."""
    from cranefmu.fmu_kinds import compiler_reason

    if compiler_reason():
        pytest.skip(compiler_reason())
    calls: list[int] = []
    real = plan.KernelPlan.jacobi_steps
    monkeypatch.setattr(plan.KernelPlan, "jacobi_steps",
                        lambda self, ts, order, rows: calls.append(len(ts) - 1) or real(self, ts, order, rows))
    return calls


def test_a_natural_length_run_is_one_stretch(kernel_calls):
    """overhead_lift, native FMUs, stored settings (jacobi x1, 2 ms, 6 s): after the one start-up step the
    2999 Jacobi steps are one kernel call (they were 12 with stretches of 256)."""
    res = run("overhead_lift", fmus="native", progress=False)
    assert res.stats.steps == 3000 and res.stats.compiled_steps == 2999
    assert kernel_calls == [2999] and loop.STRETCH >= 2999


def test_a_run_longer_than_a_stretch_is_cut_into_stretches(kernel_calls, monkeypatch):
    """The bound still holds: with stretches of 400 steps a 2 s run is 3 calls (400, 400, 199) and
    gives the same rows bit for bit."""
    whole = run("overhead_lift", fmus="native", progress=False, stop_time=2.0).result
    kernel_calls.clear()   # only the cut run's calls
    monkeypatch.setattr(loop, "STRETCH", 400)
    cut = run("overhead_lift", fmus="native", progress=False, stop_time=2.0).result
    assert kernel_calls == [400, 400, 199]
    assert all((whole[n] == cut[n]).all() for n in whole.dtype.names) and len(whole) == len(cut) == 1001


def test_a_run_writing_a_file_keeps_short_stretches(kernel_calls, tmp_path):
    """With an output file the recorder asks for stretches of at most 256 steps (a crash inside an FMU loses
    at most those and the rows not yet flushed: tests/tools/test_nothing_lost.py); the rows are the same."""
    res = run("overhead_lift", fmus="native", progress=False, stop_time=1.0, output=str(tmp_path / "o.csv"))
    assert kernel_calls == [256, 243] and res.stats.compiled_steps == 499
    assert (tmp_path / "o.csv").is_file()
