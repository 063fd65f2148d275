"""Timed runs in a fresh Python process, for the speed and start-up studies.

``python -m cranefmu.studies.timing METHOD SCENE STOP STEP OUT [KIND [RTOL]]`` imports what METHOD
needs, runs it twice in the process and prints one JSON line: ``import``, ``first`` (the first run: cold
in the process), ``second`` (warm: the same run again), wall [s] (``time.perf_counter``), and the same
three as CPU [s] of the process (``time.process_time``: user + system, ``*_cpu``), and saves the second
run's key outputs at its output times to OUT (``.npz``); ``setup`` and ``setup_cpu``: what the method needed
that is not its own (libcosim: our run that finds the settled start it is handed; 0 for the others).  Methods: ``ours`` (our master, in-process,
with the FMUs of KIND: native or python), ``monolith`` (the scene's equations in one ODE, Radau, rtol
RTOL, default 1e-6, output every STEP), ``libcosim`` (libcosimpy, fixed step from the .ssp with FMUs of
KIND, started from our settled inputs) and ``ecos`` (ecospy, fixed step, the .ssp's bound set), both
through :mod:`cranefmu.studies.hosts`.  The machine may be shared: a wall includes waiting for a core.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time as clock
from pathlib import Path

MONO_RTOL = 1e-6


def keys(scene: str) -> tuple[str, ...]:
    from ..analysis.converge import key_outputs

    return key_outputs(scene)


def libcosim_available() -> bool:
    import importlib.util

    return importlib.util.find_spec("libcosimpy") is not None


def _ours(scene: str, stop: float, step: float, kind: str | None = None, rtol: float = MONO_RTOL):
    from ..master.run import run

    return run(scene, stop_time=stop, step_size=step, isolate=False, progress=False, fmus=kind).result


def _monolith(scene: str, stop: float, step: float, kind: str | None = None, rtol: float = MONO_RTOL):
    import numpy as np

    from ..analysis.reference import solve

    # the macro step's grid k * step up to stop (a step that does not divide stop, hook_sway's 3 ms in 10 s, gave
    # linspace's 3.0003 ms before: no time on the grid the accuracy is read at)
    n = int(np.floor(stop / step + 1e-9)) + 1
    return solve(scene, stop, np.arange(n) * step, rtol=rtol)


def _ecos(scene: str, stop: float, step: float, kind: str | None = None, rtol: float = MONO_RTOL):
    from ..master.run import resolve_scene
    from .hosts import ecos_run

    return ecos_run(str(resolve_scene(scene, kind)), step, stop, list(keys(scene)))


def _libcosim(scene: str, stop: float, step: float, kind: str | None = None, rtol: float = MONO_RTOL):
    from ..master.run import resolve_scene
    from .hosts import libcosim_timed

    out = libcosim_timed(list(keys(scene)), stop, str(resolve_scene(scene, kind)), step,
                         initial_values=_START.get(scene))
    if "error" in out:
        raise RuntimeError(out["error"])
    return out


_START: dict[str, dict] = {}


def settled_start(scene: str, kind: str | None = None) -> dict:
    """Our initialization's settled value of every connected input (FMUs of ``kind``), handed to libcosim as
    initial values (it exchanges nothing in initialization mode: tests/tools/test_interop_libcosim.py)."""
    from .. import build as b
    from ..master.run import run
    from ..master.scene import read_scene_folder
    from ..settled_start import settled_inputs

    first = run(scene, stop_time=1e-3, step_size=1e-3, isolate=False, progress=False, fmus=kind).result[0]
    return settled_inputs(read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR).connections, first)


METHODS = {"ours": _ours, "monolith": _monolith, "libcosim": _libcosim, "ecos": _ecos}


def child(method: str, scene: str, stop: float, step: float, out: str, kind: str | None = None,
          rtol: float = MONO_RTOL) -> dict:
    """Import (timed), then two timed runs (wall and CPU); the second's key outputs to ``out``."""
    import numpy as np

    c0 = clock.process_time()
    t0 = clock.perf_counter()
    fn = METHODS[method]
    if method == "ours":
        import cranefmu.master.run  # noqa: F401 - timed as the import
    elif method == "monolith":
        import cranefmu.analysis.reference  # noqa: F401
    elif method == "ecos":
        import ecospy  # noqa: F401
    else:
        import libcosimpy.CosimExecution  # noqa: F401
    t1, c1 = clock.perf_counter(), clock.process_time()
    setup = setup_cpu = 0.0
    if method == "libcosim":   # timed apart (``setup``): our own run, to hand libcosim the same settled start
        _START[scene] = settled_start(scene, kind)
        setup, setup_cpu = clock.perf_counter() - t1, clock.process_time() - c1
        t1, c1 = clock.perf_counter(), clock.process_time()
    fn(scene, stop, step, kind, rtol)
    t2, c2 = clock.perf_counter(), clock.process_time()
    res = fn(scene, stop, step, kind, rtol)
    t3, c3 = clock.perf_counter(), clock.process_time()
    np.savez(out, time=np.asarray(res["time"]), **{k: np.asarray(res[k]) for k in keys(scene)})
    return {"import": t1 - t0 - setup, "first": t2 - t1, "second": t3 - t2, "setup": setup,
            "import_cpu": c1 - c0 - setup_cpu, "first_cpu": c2 - c1, "second_cpu": c3 - c2, "setup_cpu": setup_cpu}


# the environment of a timed child: Python's bytecode cache written and used, as an installed package has it
# (PYTHONDONTWRITEBYTECODE would recompile every module in every cold command)
def _env() -> dict:
    return {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}, "PYTHONWARNINGS": "ignore"}


def _timed(args: list[str], timeout: float) -> tuple[float, float, subprocess.CompletedProcess]:
    """(wall, CPU) [s] of a command and its children (``RUSAGE_CHILDREN`` around it: user + system)."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = clock.perf_counter()
    p = subprocess.run(args, capture_output=True, text=True, timeout=timeout, env=_env())
    wall = clock.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), p


def in_child(method: str, scene: str, stop: float, step: float, out: Path, timeout: float = 1800.0,
             kind: str | None = None, rtol: float = MONO_RTOL) -> dict:
    """Run :func:`child` in a fresh interpreter; its measurement, plus ``process`` and ``process_cpu`` [s]:
    the whole child (interpreter start to exit), wall and CPU; ``error`` when it failed."""
    args = [sys.executable, "-m", "cranefmu.studies.timing", method, scene, repr(stop), repr(step), str(out),
            kind or "default", repr(rtol)]
    wall, cpu, p = _timed(args, timeout)
    lines = [x for x in p.stdout.splitlines() if x.startswith("{")]
    if p.returncode != 0 or not lines:
        tail = (p.stderr.strip().splitlines() or ["no output"])[-1]
        return {"error": f"{method} exited {p.returncode}: {tail}", "process": wall, "process_cpu": cpu}
    return {**json.loads(lines[-1]), "process": wall, "process_cpu": cpu}


def cranefmu_command() -> list[str]:
    """The ``cranefmu`` console script beside this interpreter (as a user runs it), else the same via -c."""
    script = Path(sys.executable).parent / "cranefmu"
    if script.is_file():
        return [str(script)]
    return [sys.executable, "-c", "import sys; from cranefmu.cli import main; sys.exit(main())"]


def command_time(args: list[str], timeout: float = 1800.0) -> tuple[float, float, str, str]:
    """(wall, CPU) [s] of a whole command (cold: a fresh process, its children included), its error line
    ('' when it exited 0) and what it printed on stdout."""
    wall, cpu, p = _timed(args, timeout)
    return wall, cpu, "" if p.returncode == 0 else ((p.stderr.strip().splitlines() or ["?"])[-1]), p.stdout


def command_wall(args: list[str], timeout: float = 1800.0) -> tuple[float, str]:
    """Seconds of a whole command (cold: a fresh process) and its error line ('' when it exited 0)."""
    wall, _, error, _ = command_time(args, timeout)
    return wall, error


if __name__ == "__main__":
    m, sc, T, H, o = sys.argv[1:6]
    kind = sys.argv[6] if len(sys.argv) > 6 and sys.argv[6] != "default" else None
    rtol = float(sys.argv[7]) if len(sys.argv) > 7 else MONO_RTOL
    print(json.dumps(child(m, sc, float(T), float(H), o, kind, rtol)), flush=True)
