"""Where ``cranefmu run`` runs the FMUs (master/run_process.py): cranefmu's native FMUs in the command's own
process, pythonfmu FMUs and other tools' in a worker process; ``--isolate`` and ``--in-process`` choose; the
header says which.  And what a cold native run imports (its CPU is the product's cold speed,
benchmarks/results/kinds_speed.md): none of scipy, matplotlib, pythonfmu, nor the sweep, study, compose or
export code."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from cranefmu.master.run_process import choose

# the run path of a native scene never needs these (a module here costs every cold command its import)
NOT_ON_THE_RUN_PATH = ("scipy", "matplotlib", "pythonfmu", "dask", "distributed", "cranefmu.sweep",
                       "cranefmu.studies", "cranefmu.compose", "cranefmu.export", "cranefmu.analysis.fit_boucwen",
                       "cranefmu.adapter.fmi_adapter", "cranefmu.report.page", "cranefmu.report.drawing")

WORKER_CPU = 0.05   # [s] a worker process (an interpreter importing numpy and fmpy) costs more than this

_CHILD = """
import json, resource, sys
from cranefmu.cli import main
code = main(sys.argv[1:])
children = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"code": code, "modules": sorted(sys.modules), "children": children.ru_utime + children.ru_stime}))
"""


def _cli_in_child(*args: str) -> tuple[int, list[str], str, float]:
    """``cranefmu *args`` in a fresh interpreter: (exit code, its modules after the command, its stdout, the
    CPU time [s] of the processes it started)."""
    p = subprocess.run([sys.executable, "-c", _CHILD, *args], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    *out, last = p.stdout.strip().splitlines()
    got = json.loads(last)
    return got["code"], got["modules"], "\n".join(out), got["children"]


def _loaded(modules: list[str], name: str) -> bool:
    return any(m == name or m.startswith(name + ".") for m in modules)


@pytest.mark.parametrize("kind, isolate, in_process, worker", [
    ("native", False, False, False), ("python", False, False, True), (None, False, False, True),
    ("native", True, False, True), ("python", False, True, False), (None, False, True, False)])
def test_native_fmus_run_here_the_others_in_a_worker_unless_asked(kind, isolate, in_process, worker):
    got, line = choose(kind, isolate, in_process)
    assert got is worker
    assert line.startswith("process: a worker process" if worker else "process: this one")


def test_isolate_and_in_process_exclude_each_other():
    with pytest.raises(ValueError):
        choose("native", True, True)


def test_a_native_run_is_in_the_command_process_and_imports_only_the_run_path(built):
    code, modules, out, children = _cli_in_child("run", "elastic_pendulum", "--stop-time", "0.05", "--no-progress")
    assert code == 0
    assert "  process: this one (native FMUs; --isolate runs them in a worker process)" in out.splitlines()
    # no worker was started: a Python process importing numpy costs over 0.1 s of CPU; fmpy's import runs
    # ``ldconfig -p`` (ctypes.util.find_library), under 0.01 s
    assert children < WORKER_CPU and not _loaded(modules, "cranefmu.master.isolated")
    assert [m for m in NOT_ON_THE_RUN_PATH if _loaded(modules, m)] == []


def test_isolate_runs_native_fmus_in_a_worker(built):
    code, modules, out, children = _cli_in_child("run", "elastic_pendulum", "--stop-time", "0.05", "--no-progress",
                                                 "--isolate")
    assert code == 0 and "  process: a worker process (--isolate)" in out.splitlines()
    assert children > WORKER_CPU and _loaded(modules, "cranefmu.master.isolated")


def test_pythonfmu_fmus_run_in_a_worker_and_the_command_loads_none_of_their_code(built):
    code, modules, out, children = _cli_in_child("run", "elastic_pendulum", "--stop-time", "0.05", "--no-progress",
                                                 "--fmus", "python")
    assert code == 0 and children > WORKER_CPU
    assert any(line.startswith("  process: a worker process (pythonfmu FMUs") for line in out.splitlines())
    assert _loaded(modules, "cranefmu.master.isolated")
    assert not _loaded(modules, "pythonfmu") and not _loaded(modules, "scipy")


def test_the_command_list_names_every_subcommand():
    """``cranefmu run`` builds only its own subparser from :data:`cli.COMMANDS`: a subcommand missing there
    would be unreachable by name (the full parser, built for anything else, lists every one)."""
    import argparse

    from cranefmu import cli

    (sub,) = [a for a in cli.build_parser()._actions if isinstance(a, argparse._SubParsersAction)]
    assert tuple(sub.choices) == cli.COMMANDS
    (only,) = [a for a in cli.build_parser("run")._actions if isinstance(a, argparse._SubParsersAction)]
    assert tuple(only.choices) == ("run",)
