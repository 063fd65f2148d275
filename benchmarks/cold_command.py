"""Where a cold ``cranefmu run`` goes beyond its floor and its run: the command at a base commit against this
checkout, per scene, at the stored settings with native FMUs (in the command's own process).

Per scene and tree (``before``: the base commit's ``src/`` in a temporary git worktree holding this checkout's
built FMUs and scenes, their times renewed so that nothing is rebuilt; ``after``: this checkout), the CPU
(user + system, ``resource.getrusage(RUSAGE_CHILDREN)``) of

- ``cold``: the whole ``cranefmu run SCENE --no-progress`` command in a fresh process;
- ``cold, --output``: the same writing ``--output x.csv`` (rows streamed to the file, the summary read back);
- ``warm``: in one fresh process a first 0.05 s run, then the timed run (``process_time``, in-process);

and the floor ``python -c "import numpy, fmpy"`` (what any cold run pays before cranefmu's own code).  Every
command runs with Python's bytecode cache (as an installed package has it) and is run once untimed first;
rounds alternate the trees; the table gives the least CPU over the rounds.  "beyond" is cold - floor - warm:
the CPU of the command that is neither the interpreter with numpy and fmpy nor the run itself.

Usage: .venv/bin/python benchmarks/cold_command.py [--before 0d3c6c3] [--rounds 3] [--scenes a,b] [--smoke]
``--smoke``: elastic_pendulum, one round, into cold_command_smoke.md (the numbers mean little).
Writes benchmarks/results/cold_command.md (commit, date, load, the tables).
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from result_table import save, stamp

REPO = Path(__file__).resolve().parents[1]
SCENES = ("elastic_pendulum", "overhead_lift", "hook_sway", "truck_telescope", "truck_slewing")
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}   # bytecode cached, as installed
_CLI = "import sys; sys.path.insert(0, {src!r}); sys.argv = ['cranefmu', *sys.argv[1:]]\nfrom cranefmu.cli import main\nmain()"
_WARM = ("import sys, time; sys.path.insert(0, {src!r}); import cranefmu\n"
         "scene, stop = sys.argv[1], float(sys.argv[2])\n"
         "cranefmu.simulate(scene, stop_time=min(stop, 0.05), fmus='native', progress=False)\n"
         "c0 = time.process_time()\n"
         "cranefmu.simulate(scene, stop_time=stop, fmus='native', progress=False)\n"
         "print(time.process_time() - c0)\n")


def _cpu(command: list[str], cwd: str) -> tuple[float, str]:
    """(CPU [s] of ``command`` and its children, its stdout); raises if it fails."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(command, cwd=cwd, capture_output=True, text=True, env=ENV)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)[-200:]} failed: {done.stderr.strip()[-500:]}")
    if "building" in done.stderr:   # a rebuild in a timed command would time the build
        raise RuntimeError(f"{' '.join(command)[-200:]} built something: {done.stderr.strip()[-300:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), done.stdout


def cold(src: Path, scene: str, *extra: str) -> float:
    """CPU [s] of ``cranefmu run SCENE --no-progress`` (``extra``: more options) with the package in ``src``."""
    with tempfile.TemporaryDirectory() as tmp:
        return _cpu([sys.executable, "-c", _CLI.format(src=str(src)), "run", scene, "--no-progress", *extra], tmp)[0]


def warm(src: Path, scene: str, stop: float) -> float:
    """CPU [s] of the second run of ``scene`` in one process."""
    return float(_cpu([sys.executable, "-c", _WARM.format(src=str(src)), scene, repr(stop)],
                      tempfile.gettempdir())[1].split()[-1])


def floor() -> float:
    """CPU [s] of ``python -c "import numpy, fmpy"``."""
    return _cpu([sys.executable, "-c", "import numpy, fmpy"], tempfile.gettempdir())[0]


def _before_tree(commit: str, where: Path) -> Path:
    """A git worktree of ``commit`` at ``where`` holding this checkout's built FMUs and scenes (times renewed:
    current, nothing rebuilt); returns its ``src``."""
    subprocess.run(["git", "worktree", "add", "--detach", str(where), commit], cwd=REPO, check=True,
                   capture_output=True)
    for folder in ("fmus", "ssp"):
        shutil.copytree(REPO / folder, where / folder, dirs_exist_ok=True)
    now = time.time()
    for pattern, at in (("fmus/**/*.fmu", now), ("fmus/**/*.xml", now), ("ssp/**/*.ssp", now + 1)):
        for path in where.glob(pattern):
            os.utime(path, (at, at))   # scenes newer than their FMUs, both newer than the sources
    return where / "src"


def natural_stop(scene: str) -> float:
    from cranefmu.master.runspec import resolve

    return resolve(scene, fmus="native").settings.stop_time


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="0d3c6c3", help="the base commit (default 0d3c6c3, before s11's cold work)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--smoke", action="store_true")
    args = ap.parse_args(argv)
    if args.smoke:
        args.scenes, args.rounds = "elastic_pendulum", 1
    t0 = time.time()
    head = stamp("cold_command.py")
    rows = []
    with tempfile.TemporaryDirectory(prefix="cranefmu_cold_before_") as tmp:
        trees = {"before": _before_tree(args.before, Path(tmp) / "tree"), "after": REPO / "src"}
        try:
            for scene in args.scenes.split(","):
                stop = natural_stop(scene)
                best: dict[tuple[str, str], float] = {}
                for src in trees.values():   # untimed: bytecode written, files in the page cache
                    cold(src, scene, "--stop-time", "0.05")
                for _ in range(args.rounds):
                    best["", "floor"] = min(best.get(("", "floor"), float("inf")), floor())
                    for tree, src in trees.items():
                        for mode, fn in (("cold", lambda: cold(src, scene)),
                                         ("output", lambda: cold(src, scene, "--output", "x.csv")),
                                         ("warm", lambda: warm(src, scene, stop))):
                            cpu = fn()
                            best[tree, mode] = min(best.get((tree, mode), float("inf")), cpu)
                            print(f"{scene} {tree} {mode}: CPU {cpu:.3f} s", flush=True)
                fl = best["", "floor"]
                for tree in trees:
                    c, o, w = (best[tree, m] for m in ("cold", "output", "warm"))
                    rows.append(f"| {scene} | {stop:g} | {tree} | {c:.3f} ({stop / c:.1f}x) | {o:.3f} ({stop / o:.1f}x) "
                                f"| {fl:.3f} | {w:.3f} | {c - fl - w:+.3f} | {o - fl - w:+.3f} | {stop / (fl + w):.1f}x |")
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(Path(tmp) / "tree")], cwd=REPO,
                           capture_output=True)
    lines = ["# The cold `cranefmu run` command: its floor, its run and the rest", "", head,
             f"{os.cpu_count()} cores shared; least CPU of {args.rounds} round(s); load at the end "
             f"{os.getloadavg()[0]:.1f}; before = {args.before}; native FMUs in the command's process; commands "
             "with Python's bytecode cache.", "",
             "CPU [s] (real-time factor) of the cold command without and with `--output x.csv`; the floor "
             "`python -c \"import numpy, fmpy\"`; the warm run; beyond = cold - floor - warm (the command's own "
             "CPU that is neither); the real-time factor a cold command costing only floor + warm would reach.", "",
             "| scene | T [s] | tree | cold | cold, --output | floor | warm | beyond | beyond, --output | "
             "floor + warm reach |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |", *rows]
    save("cold_command_smoke" if args.smoke else "cold_command", lines, t0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
