"""Every scene at its stored settings with each kind of FMU (native C, pythonfmu): cold and warm, CPU and wall.

cold: the whole ``cranefmu run SCENE --fmus KIND`` command in a fresh process (interpreter, imports, build
check, the run, in the command's own process for native FMUs and in a worker for pythonfmu ones, the report);
CPU = user + system of the command and its worker (``resource.getrusage(RUSAGE_CHILDREN)`` around it).  The
commands run with Python's bytecode cache, as an installed package has it (PYTHONDONTWRITEBYTECODE removed
from their environment; one untimed short run per scene and kind first).  warm: in one fresh process, a first
short run, then the timed run (``cranefmu.simulate``, in-process): wall (``perf_counter``) and CPU
(``process_time``).  Real-time factor = simulated time / time.  Rounds alternate the kinds; the table gives the
minimum over the rounds.  A second table holds, for the native FMUs, the cold command with ``--isolate`` (the
worker process, the default before native FMUs ran in the command), the floor of any cold command
(``python -c "import numpy, fmpy"``: the interpreter and the two libraries every run needs) and what that
floor and the warm run leave reachable cold.

Usage: .venv/bin/python benchmarks/kinds_speed.py [--scenes a,b] [--stop T] [--rounds N] [--smoke]
``--stop``: simulated time of every run (default: each scene's natural length, its DefaultExperiment);
``--smoke`` (the numbers mean little): elastic_pendulum, 0.5 s, one round, into kinds_speed_smoke.md.
Writes benchmarks/results/kinds_speed.md (commit, date, load, the table) and, read from it,
src/cranefmu/speed.json, which ``cranefmu info`` quotes, and the tables of docs/benchmarks.md and docs/scenes.md (``--from-table``: no runs, only that step).
"""
from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from result_table import save, stamp

REPO = Path(__file__).resolve().parents[1]
SCENES = ("elastic_pendulum", "overhead_lift", "hook_sway", "truck_telescope", "truck_slewing")
KINDS = ("native", "python")
_WARM = ("import sys, time, cranefmu\n"
         "scene, kind, stop = sys.argv[1], sys.argv[2], float(sys.argv[3])\n"
         "cranefmu.simulate(scene, stop_time=min(stop, 0.05), fmus=kind, progress=False)\n"
         "w0, c0 = time.perf_counter(), time.process_time()\n"
         "cranefmu.simulate(scene, stop_time=stop, fmus=kind, progress=False)\n"
         "print(time.perf_counter() - w0, time.process_time() - c0)\n")


def _cranefmu() -> list[str]:
    exe = Path(sys.executable).with_name("cranefmu")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "cranefmu.cli"]


ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}   # bytecode cached, as installed


def _timed(command: list[str], cwd: str | None = None) -> tuple[float, float, subprocess.CompletedProcess]:
    """(wall, CPU) [s] of ``command`` and its children, and its outcome."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    w0 = time.perf_counter()
    done = subprocess.run(command, cwd=cwd, capture_output=True, text=True, env=ENV)
    wall = time.perf_counter() - w0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), done


def floor() -> tuple[float, float]:
    """(wall, CPU) [s] of ``python -c "import numpy, fmpy"``: what any cold run costs before cranefmu's code."""
    wall, cpu, done = _timed([sys.executable, "-c", "import numpy, fmpy"])
    if done.returncode != 0:
        raise RuntimeError(f"import numpy, fmpy failed: {done.stderr.strip()[-500:]}")
    return wall, cpu


def cold(scene: str, kind: str, stop: float, *extra: str) -> tuple[float, float]:
    """(wall, CPU) [s] of the whole ``cranefmu run`` command (``extra``: more of its options)."""
    with tempfile.TemporaryDirectory() as tmp:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        w0 = time.perf_counter()
        done = subprocess.run([*_cranefmu(), "run", scene, "--fmus", kind, "--stop-time", repr(stop),
                               "--no-progress", *extra], cwd=tmp, capture_output=True, text=True, env=ENV)
        wall = time.perf_counter() - w0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"cranefmu run {scene} --fmus {kind} failed: {done.stderr.strip()[-500:]}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def warm(scene: str, kind: str, stop: float) -> tuple[float, float]:
    """(wall, CPU) [s] of the second run in one process."""
    done = subprocess.run([sys.executable, "-c", _WARM, scene, kind, repr(stop)], capture_output=True, text=True,
                          env=ENV)
    if done.returncode != 0:
        raise RuntimeError(f"warm run {scene} {kind} failed: {done.stderr.strip()[-500:]}")
    wall, cpu = (float(x) for x in done.stdout.split()[-2:])
    return wall, cpu


def natural_stop(scene: str) -> float:
    from cranefmu.master.runspec import resolve

    return resolve(scene, fmus="python").settings.stop_time


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--stop", type=float, default=None, help="simulated time [s] (default: each scene's own)")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--smoke", action="store_true")
    ap.add_argument("--from-table", action="store_true", help="no runs: write src/cranefmu/speed.json from "
                    "benchmarks/results/kinds_speed.md")
    args = ap.parse_args(argv)
    if args.from_table:
        return _store()
    if args.smoke:
        args.scenes, args.stop, args.rounds = "elastic_pendulum", 0.5, 1
    t0 = time.time()
    head = stamp("kinds_speed.py")
    rows, native_rows = [], []
    for scene in args.scenes.split(","):
        stop = args.stop or natural_stop(scene)
        for kind in KINDS:   # untimed: built, compiled to bytecode, in the page cache
            cold(scene, kind, min(stop, 0.05))
        best: dict[tuple[str, str], tuple[float, float]] = {}
        modes = (("cold", cold), ("warm", warm), ("isolated", lambda s, k, t: cold(s, k, t, "--isolate")),
                 ("floor", lambda s, k, t: floor()))
        for _ in range(args.rounds):
            for kind in KINDS:
                for mode, fn in modes:
                    if mode in ("isolated", "floor") and kind != "native":
                        continue
                    wall, cpu = fn(scene, kind, stop)
                    old = best.get((kind, mode), (float("inf"), float("inf")))
                    best[(kind, mode)] = (min(old[0], wall), min(old[1], cpu))
                    print(f"{scene} {kind} {mode}: wall {wall:.2f} s, CPU {cpu:.2f} s", flush=True)
        for kind in KINDS:
            (cw, cc), (ww, wc) = best[(kind, "cold")], best[(kind, "warm")]
            rows.append(f"| {scene} | {stop:g} | {kind} | {stop / cc:.2f} | {stop / cw:.2f} | {stop / wc:.2f} | "
                        f"{stop / ww:.2f} | {cc:.2f} / {cw:.2f} | {wc:.2f} / {ww:.2f} |")
        cc, ic, fc, wc = (best[("native", m)][1] for m in ("cold", "isolated", "floor", "warm"))
        native_rows.append(f"| {scene} | {stop:g} | {cc:.3f} ({stop / cc:.1f}x) | {ic:.3f} ({stop / ic:.1f}x) | "
                           f"{fc:.3f} | {wc:.3f} | {stop / (fc + wc):.1f}x | {stop / 100:.3f} | "
                           f"{'yes' if stop / cc >= 100 else 'no'} |")
    lines = ["# Every scene at its stored settings with each kind of FMU", "", head,
             f"{os.cpu_count()} cores shared; minimum over {args.rounds} round(s); load at the end "
             f"{os.getloadavg()[0]:.1f}; commands with Python's bytecode cache.", "",
             "| scene | T [s] | FMUs | RTF cold, CPU | RTF cold, wall | RTF warm, CPU | RTF warm, wall | "
             "cold CPU / wall [s] | warm CPU / wall [s] |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
             *rows, "",
             "## Native FMUs, cold: in the command's process, in a worker, and the floor", "",
             "CPU [s] (real-time factor) of the cold command as it runs by default (native FMUs in the command's "
             "process) and with `--isolate` (a worker process); the floor `python -c \"import numpy, fmpy\"` that "
             "any cold run pays; the warm run; the real-time factor a cold command could reach if it cost only the "
             "floor and the warm run; the CPU that 100x real time allows; and whether the cold command reaches it.",
             "", "| scene | T [s] | cold | cold, --isolate | floor | warm | floor + warm reach | 100x allows | "
             "100x cold |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- |", *native_rows]
    save("kinds_speed_smoke" if args.smoke else "kinds_speed", lines, t0)
    return 0 if args.smoke or args.stop else _store()


def _store() -> int:
    """src/cranefmu/speed.json from benchmarks/results/kinds_speed.md (only a run over each scene's natural
    length writes it: ``cranefmu info`` says so)."""
    from cranefmu.speed_table import STORE, write_docs, write_from_table

    data = write_from_table(REPO / "benchmarks" / "results" / "kinds_speed.md")
    print(f"written {STORE} ({len(data['scenes'])} scene(s))")
    for page in (REPO / "docs" / "benchmarks.md", REPO / "docs" / "scenes.md"):
        if write_docs(data, page):
            print(f"written the speed table into {page}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
