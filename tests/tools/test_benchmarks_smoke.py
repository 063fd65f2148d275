"""Every script in benchmarks/ at its smallest size, as a subprocess (as a reader would run it), so an
interface change that breaks a benchmark fails CI instead of the next measurement.

Each runs in a scratch copy of the checkout's writable parts (benchmarks/ with its results, docs/, ssp/
and src/ copied; everything else linked; git still answers for the checkout), so no script writes into
the checkout's benchmarks/results/, docs/, ssp/ (each scene's fidelity.json).  A script passes when
it exits 0 and writes its result files (newer than the start).  Numbers at smoke size mean nothing:
they are not checked here, and the tables are thrown away.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "benchmarks"
COPIED = ("benchmarks", "docs", "ssp", "src")   # the folders a script may write into
H = "0.02"

# script -> (its smallest arguments, the files it writes, relative to the copy's root)
SMOKE: dict[str, tuple[list[str], list[str]]] = {
    "blas_threads.py": (["--stop", "0.1", "--rounds", "1", "--before", "HEAD", "--out", "{tmp}"],
                        ["{tmp}/blas_threads.md"]),
    "exchange_paths.py": (["--steps", "3", "--out", "{tmp}"], ["{tmp}/exchange_paths.md"]),
    "compiled_pieces.py": (["--rounds", "1", "--scale", "0.2", "--out", "{tmp}"], ["{tmp}/compiled_pieces.md"]),
    "small_linalg_cost.py": (["--repeat", "1"], ["benchmarks/results/small_linalg_cost.md"]),
    "sweep_reuse.py": (["--runs", "2"], ["benchmarks/results/sweep_reuse.md"]),
    "sweep_overhead.py": (["--runs", "3", "--long", "1", "--rounds", "1", "--modes", "in-process,local", "--out",
                           "{tmp}/sweep_overhead.md"], ["{tmp}/sweep_overhead.md"]),
    "kernel_call_cost.py": (["--calls", "2000", "--out", "{tmp}"], ["{tmp}/kernel_call_cost.md"]),
    "kinds_speed.py": (["--smoke"], ["benchmarks/results/kinds_speed_smoke.md"]),
    "stretch_observers.py": (["--smoke"], ["benchmarks/results/stretch_observers_smoke.md"]),
    "cold_run_ab.py": (["--before", "HEAD", "--rounds", "1", "--scenes", "elastic_pendulum"],
                       ["benchmarks/results/cold_run_ab.md"]),
    "master_per_step.py": (["--steps", "200", "--rounds", "1", "--ks", "1", "--out", "{tmp}"],
                           ["{tmp}/master_per_step.md", "{tmp}/master_per_step.json"]),
    "memory_flat.py": (["--short", "0.2", "--long", "0.5", "--out", "{tmp}"], ["{tmp}/memory_flat.md"]),
    "native_conformance.py": (["--smoke"], ["benchmarks/results/native_conformance_smoke.md"]),
    "native_exact_step.py": (["--cases", "2"], ["benchmarks/results/native_exact_step.md"]),
    "alarm_margins.py": (["--smoke"], ["benchmarks/results/alarm_margins_smoke.md"]),
    "bouc_wen_step.py": (["--smoke"], ["benchmarks/results/bouc_wen_step_smoke.md"]),
    "boucwen_hoist_fit.py": (["--smoke"], ["benchmarks/results/boucwen_hoist_fit_smoke.md",
                                           "benchmarks/results/boucwen_hoist_loop_smoke.csv"]),
    "cli_startup.py": (["--before", "HEAD", "--rounds", "1"], ["benchmarks/results/cli_startup.md"]),
    "chassis_carried_step.py": (["--steps", "5", "--repeats", "1"], ["benchmarks/results/chassis_carried_step.md"]),
    "check_engines.py": (["--smoke"], ["benchmarks/results/check_engines_smoke.md"]),
    "cold_command.py": (["--smoke"], ["benchmarks/results/cold_command_smoke.md"]),
    "warm_breakdown.py": (["--smoke"], ["benchmarks/results/warm_breakdown_overhead_lift_smoke.md"]),
    "command_cost.py": (["--smoke"], ["benchmarks/results/command_cost_smoke.md"]),
    "compose_roundtrip.py": (["0.002"], ["benchmarks/results/compose_roundtrip.md"]),
    "energy_drift.py": ([H], ["benchmarks/results/energy_drift.txt"]),
    "exit_valgrind.py": (["--smoke"], ["benchmarks/results/exit_valgrind_smoke.md"]),
    "fmu_floor.py": (["--label", "smoke", "--scenes", "elastic_pendulum", "--rounds", "1", "--batch", "5"],
                     ["benchmarks/results/fmu_floor_smoke.csv"]),
    "fmu_step_cost.py": (["--label", "smoke", "--scenes", "hook_sway", "--stop", "0.05"],
                         ["benchmarks/results/fmu_step_cost_smoke.csv"]),
    "foreign_fmus.py": ([], ["benchmarks/results/foreign_fmus.md"]),
    "honesty_cost.py": (["--smoke"], ["benchmarks/results/honesty_cost_smoke.md"]),
    "hook_bond_jacobian.py": (["--smoke"], ["benchmarks/results/hook_bond_jacobian_smoke.md"]),
    "hook_length_trend.py": (["--smoke"], ["benchmarks/results/hook_length_trend_smoke.md"]),
    "hook_pin_damping.py": ([], ["benchmarks/results/hook_pin_damping.md"]),
    "hook_sway_levers.py": (["--smoke"], ["benchmarks/results/hook_sway_levers_smoke.md"]),
    "implicit_bond.py": (["--stop", "0.5", "--steps", H, "--repeats", "1", "--reference", "{tmp}/ref.npz"],
                         ["benchmarks/results/implicit_bond.md"]),
    "integrators.py": (["--cases", "girder-elastic"], ["benchmarks/results/integrators.md"]),
    "interop_difference.py": (["--smoke"], ["benchmarks/results/interop_difference_smoke.md"]),
    "jacobi_stable_step.py": (["--smoke"], ["benchmarks/results/jacobi_stable_step_smoke.md",
                                            "benchmarks/results/host_steps_smoke.json"]),
    "long_run_memory.py": (["--stop", "0.5", "--every", "0.1", "--results", "{tmp}/memory"], ["{tmp}/memory"]),
    # one case (the one whose setting had to change); all four took 118 s at load 7-9
    "master_calls.py": (["--before", "HEAD", "--rounds", "1", "--scenes", "overhead_lift", "--out", "{tmp}/calls.md"],
                        ["{tmp}/calls.md"]),
    "master_overhead.py": (["--before", "HEAD", "--rounds", "1", "--out", "{tmp}/overhead.md"],
                           ["{tmp}/overhead.md"]),
    "native_host_cost.py": (["--stop-time", "0.05", "--repeat", "1"], ["benchmarks/results/native_host_cost.md"]),
    "overhead_modes.py": (["--smoke", "--output", "{tmp}/modes.md"], ["{tmp}/modes.md", "{tmp}/modes.csv"]),
    "overhead_sensitivity.py": (["--smoke"], ["benchmarks/results/overhead_sensitivity_smoke.md"]),
    "realtime_targets.py": (["--repeats", "1", "--scenes", "elastic_pendulum", "--output", "{tmp}/rt"],
                            ["{tmp}/rt/realtime_targets.md"]),
    "reference_speed.py": (["--quick", "--methods", "Radau"], ["benchmarks/results/reference_speed.md"]),
    "report_size.py": (["--smoke"], ["benchmarks/results/report_size_smoke.md"]),
    "result_table.py": ([], []),   # a library of the physics benchmarks: importing it is its smoke run
    "scene_defaults.py": (["--scenes", "elastic_pendulum", "--stop", "0.2", "--natural", "0.4", "--steps", H,
                           "--output", "{tmp}/defaults.md"], ["{tmp}/defaults.md"]),
    "speed_accuracy.py": (["--quick", "--scenes", "elastic_pendulum", "--stop-time", "0.2", "--steps", H,
                           "--algorithms", "jacobi", "--extrapolations", "0", "--no-target", "--no-libcosim",
                           "--repeats", "1", "--output", "{tmp}/speed"], ["{tmp}/speed/speed_accuracy.md"]),
    # a forwarder to `cranefmu study stability-map`, whose smoke size tests/tools/test_studies.py runs
    "stability_map.py": (["--help"], []),
    "startup.py": (["--repeat", "1", "--runs", "2"], ["benchmarks/results/startup.md"]),
    "studies.py": (["startup", "--smoke", "--output", "{tmp}/studies"], ["{tmp}/studies/startup.md"]),
    "sweep_scaling.py": (["--smoke"], ["benchmarks/results/sweep_scaling_smoke.md"]),
    "truck_full_run.py": (["--smoke"], ["benchmarks/results/truck_full_run_smoke.md"]),
    "truck_load_inertia.py": (["--smoke"], ["benchmarks/results/truck_load_inertia_smoke.md"]),
    "truck_slewing.py": (["--smoke"], ["benchmarks/results/truck_slewing_smoke.md"]),
    "truck_slewing_rocking.py": (["--smoke"], ["benchmarks/results/truck_slewing_rocking_smoke.md"]),
    "truck_slewing_tipping.py": ([], ["benchmarks/results/truck_slewing_tipping.md"]),
    "truck_slewing_bonds.py": (["--smoke"], ["benchmarks/results/truck_slewing_bonds_smoke.md"]),
    "truck_modes.py": (["--smoke", "--output", "{tmp}/truck_modes.md"], ["{tmp}/truck_modes.md"]),
    "implicit_group_steps.py": (["--steps", "0.04", "--stop", "0.4", "--output", "{tmp}/igs.md"], ["{tmp}/igs.md"]),
    "truck_slewing_coupling.py": (["--steps", "0.02,0.01", "--output", "{tmp}/tsc.md"], ["{tmp}/tsc.md"]),
    "truck_telescope_ssv.py": ([], ["ssp/truck_telescope/default.ssv"]),
    "validation_report.py": (["--quick"], ["docs/validation.md"]),
    "warm_run.py": (["--smoke"], ["benchmarks/results/warm_run_smoke.md"]),
}
# every script's smoke run is out of the default run (pytest -m 'not slow': the tests of the product) and in
# .ci/run's own step `pytest -m slow tests/tools/test_benchmarks_smoke.py ...`: together they took about 15 min of
# CPU of the default run (`--durations`, 2026-11-28, /work/logs in the session note; warm_run.py 161 s,
# truck_slewing_bonds.py 144 s, compose_roundtrip.py 103 s, overhead_modes.py 96 s at load 10-20)
SLOW = set(SMOKE)
# broken at this commit (measured): left visible as xfail for the script's owner, not hidden
BROKEN: dict[str, str] = {}
# a program the script runs that .ci/run does not install: skipped, with the reason, where it is missing
NEEDS = {"exit_valgrind.py": "valgrind"}
# bitwise_check.py is the master's bit-for-bit check (save/compare of ~36 runs in fresh children, minutes):
# it is the merge check itself, run by hand against a saved tree, not a measurement to smoke
NOT_RUN = {"bitwise_check.py"}


def test_every_benchmark_script_has_a_smoke_run():
    scripts = {p.name for p in BENCH.glob("*.py")}
    assert scripts - NOT_RUN == set(SMOKE), "give the new script an entry (its smallest size) in SMOKE"


@pytest.fixture(scope="module")
def tree(built, tmp_path_factory):
    """A scratch root: the writable folders copied, the rest of the checkout linked."""
    root = tmp_path_factory.mktemp("bench_root")
    for entry in ROOT.iterdir():
        if entry.name in COPIED:
            shutil.copytree(entry, root / entry.name, symlinks=True,
                            ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        elif entry.name not in (".git", ".venv"):
            (root / entry.name).symlink_to(entry)
    return root


def _env() -> dict[str, str]:
    # bytecode cached as on a user's machine (the scratch tree's own __pycache__)
    env = {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}, "MPLBACKEND": "Agg"}
    git = subprocess.run(["git", "rev-parse", "--absolute-git-dir"], cwd=ROOT, capture_output=True, text=True)
    if git.returncode == 0:   # a script's `git rev-parse`/`git archive` reads the checkout's history
        env.update(GIT_DIR=git.stdout.strip(), GIT_WORK_TREE=str(ROOT))
    return env


def _params():
    for script in sorted(SMOKE):
        marks = ([pytest.mark.slow] if script in SLOW else []) + \
            ([pytest.mark.xfail(reason=BROKEN[script], run=False)] if script in BROKEN else [])   # minutes of CI
        yield pytest.param(script, marks=marks, id=script)


@pytest.mark.parametrize("script", list(_params()))
def test_benchmark_runs_at_its_smallest_size(script, tree, tmp_path):
    if script in NEEDS and shutil.which(NEEDS[script]) is None:
        pytest.skip(f"{script} needs {NEEDS[script]}, which is not installed")
    args, writes = SMOKE[script]
    fill = {"tmp": str(tmp_path)}
    start = time.time()
    p = subprocess.run([sys.executable, str(tree / "benchmarks" / script), *(a.format(**fill) for a in args)],
                       cwd=tmp_path, env=_env(), capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, f"{script} exited {p.returncode}:\n{p.stdout[-1500:]}\n{p.stderr[-3000:]}"
    for rel in writes:
        path = Path(rel.format(**fill))
        path = path if path.is_absolute() else tree / path
        assert path.exists() and path.stat().st_mtime >= start - 1, f"{script} did not write {path}"
