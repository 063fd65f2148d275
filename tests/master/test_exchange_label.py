"""Which exchange a run took, as the run's statistics, ``cranefmu run`` and ``cranefmu info`` say it
(master/exchange_label.py): the compiled kernel, or Python and why, counted from the steps the run took."""
from __future__ import annotations

from types import SimpleNamespace

import pytest

from cli_process import cranefmu
from cranefmu.master import kernel
from cranefmu.master.exchange_label import exchange_label
from cranefmu.master.run import run
from cranefmu.master.system import RunStats


def _stats(steps: int, compiled: int, calls: int = 1, why: str = "", rejections: int = 0) -> RunStats:
    return RunStats(steps=steps, compiled_steps=compiled, kernel_calls=calls, python_exchange=why,
                    rejections=rejections)


JACOBI = SimpleNamespace(name="jacobi")
STARTED = SimpleNamespace(name="jacobi", main=JACOBI, p=2)   # as algorithms.StartUp wraps it


def test_every_step_compiled():
    assert exchange_label(_stats(500, 500, 500), JACOBI) == "compiled kernel: all 500 macro steps, in 500 kernel calls"


def test_the_start_up_steps_are_named_as_python():
    assert exchange_label(_stats(100, 98), STARTED) == ("compiled kernel: 98 of 100 macro steps, in 1 kernel calls; "
                                                        "Python: the other 2, the iterative start-up of extrapolation "
                                                        "order 2")
    # rejected steps are steps taken too (the kernel counts each attempt)
    assert exchange_label(_stats(20, 19, 19, rejections=1), STARTED).startswith(
        "compiled kernel: 19 of 21 macro steps (1 rejected), in 19 kernel calls; Python: the other 2, the iterative")


def test_python_says_why():
    refused = "commanded inputs (the kernel does not feed commands)"
    assert exchange_label(_stats(10, 0, 0, refused), JACOBI) == f"Python: {refused}"
    assert exchange_label(_stats(10, 0, 0), SimpleNamespace(name="iterative")) == (
        "Python: the iterative algorithm has no compiled exchange; the kernel covers jacobi, gauss-seidel and "
        "jacobi-plain steps")
    # the iterative algorithm's steps in Python, its evaluations of G(u) and exchanges in the kernel
    assert exchange_label(_stats(10, 0, 25), SimpleNamespace(name="iterative")) == (
        "Python steps of the iterative algorithm (10 macro steps); their 25 evaluations and exchanges in the "
        "compiled kernel")
    assert exchange_label(_stats(0, 0, 0), JACOBI) == "none (no macro step was taken)"


def test_a_native_jacobi_run_says_compiled_and_an_iterative_one_python(built, lib):
    jacobi = run("elastic_pendulum", stop_time=0.1, progress=False)   # stored: jacobi, extrapolation 2, 5 ms
    assert jacobi.stats.exchange == ("compiled kernel: 18 of 20 macro steps, in 11 kernel calls; Python: the other "
                                     "2, the iterative start-up of extrapolation order 2")
    iterative = run("elastic_pendulum", stop_time=0.05, algorithm="iterative", progress=False)
    assert iterative.stats.compiled_steps == 0 and iterative.stats.kernel_calls > 0
    assert iterative.stats.exchange.startswith("Python steps of the iterative algorithm (50 macro steps); their ")


def test_the_python_exchange_asked_for_is_said(built, monkeypatch):
    monkeypatch.setenv(kernel.DISABLE, "1")   # read once per process: the run goes to a worker
    res = run("elastic_pendulum", stop_time=0.05, isolate=True, progress=False)
    assert res.stats.compiled_steps == 0 and res.stats.exchange == f"Python: {kernel.DISABLE} is set"


def test_run_and_info_print_it(built, lib):
    done = cranefmu("run", "elastic_pendulum", "--stop-time", "0.05", "--no-progress")
    assert done.returncode == 0, done.stderr
    assert ("  exchange: compiled kernel: 8 of 10 macro steps, in 11 kernel calls; Python: the other 2, the "
            "iterative start-up of extrapolation order 2") in done.stdout.splitlines()
    done = cranefmu("info", "elastic_pendulum")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    at = lines.index("  exchange at the stored settings (a probe run of the first steps; cranefmu run says it for "
                     "every run):")
    assert lines[at + 1] == ("    default (5 steps): compiled kernel: 3 of 5 macro steps, in 11 kernel calls; Python: "
                             "the other 2, the iterative start-up of extrapolation order 2")


def test_the_html_report_lists_it():
    from cranefmu.report import _stats_rows

    label = "compiled kernel: all 500 macro steps, in 500 kernel calls"
    rows = _stats_rows(RunStats(steps=500, compiled_steps=500, kernel_calls=500, exchange=label), None)
    assert ("exchange", label) in rows
