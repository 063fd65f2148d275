"""Timed runs in a fresh Python process, for the speed and start-up studies.

``python -m cranefmu.studies.timing METHOD SCENE STOP STEP OUT`` imports what METHOD needs, runs it
twice in the process and prints one JSON line: ``import`` [s], ``first`` [s] (the first run: cold in
the process), ``second`` [s] (warm: the same run again), and saves the second run's key outputs at
its output times to OUT (``.npz``).  Methods: ``ours`` (our master, in-process), ``monolith`` (the
scene's equations in one ODE, Radau, rtol 1e-6, output at ``time`` of the matching ``ours`` run, or
every STEP), ``libcosim`` (libcosimpy, fixed step from the .ssp, started from our settled inputs) and
``ecos`` (ecospy, fixed step, the .ssp's bound set), both through :mod:`cranefmu.studies.hosts`.  Timings are wall clock (``time.perf_counter``); the machine may be shared.
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


def _ours(scene: str, stop: float, step: float):
    from ..master.run import run

    return run(scene, stop_time=stop, step_size=step, isolate=False, progress=False).result


def _monolith(scene: str, stop: float, step: float):
    import numpy as np

    from ..analysis.reference import solve

    # the macro step's grid k * step up to stop (a step that does not divide stop, hook_sway's 3 ms in 10 s, gave
    # linspace's 3.0003 ms before: no time on the grid the accuracy is read at)
    n = int(np.floor(stop / step + 1e-9)) + 1
    return solve(scene, stop, np.arange(n) * step, rtol=MONO_RTOL)


def _ecos(scene: str, stop: float, step: float):
    from ..master.run import resolve_scene
    from .hosts import ecos_run

    return ecos_run(str(resolve_scene(scene)), step, stop, list(keys(scene)))


def _libcosim(scene: str, stop: float, step: float):
    from ..master.run import resolve_scene
    from .hosts import libcosim_timed

    out = libcosim_timed(list(keys(scene)), stop, str(resolve_scene(scene)), step, initial_values=_START.get(scene))
    if "error" in out:
        raise RuntimeError(out["error"])
    return out


_START: dict[str, dict] = {}


def settled_start(scene: str) -> dict:
    """Our initialization's settled value of every connected input, handed to libcosim as initial values
    (it exchanges nothing in initialization mode: tests/tools/test_interop_libcosim.py)."""
    from .. import build as b
    from ..master.run import run
    from ..master.scene import read_scene_folder
    from ..settled_start import settled_inputs

    first = run(scene, stop_time=1e-3, step_size=1e-3, isolate=False, progress=False).result[0]
    return settled_inputs(read_scene_folder(b.SSP_DIR / scene, b.FMU_DIR).connections, first)


METHODS = {"ours": _ours, "monolith": _monolith, "libcosim": _libcosim, "ecos": _ecos}


def child(method: str, scene: str, stop: float, step: float, out: str) -> dict:
    """Import (timed), then two timed runs; the second's key outputs to ``out``."""
    import numpy as np

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
    t1 = clock.perf_counter()
    if method == "libcosim":   # not timed: our own run, to hand libcosim the same settled start
        _START[scene] = settled_start(scene)
        t1 = clock.perf_counter()
    fn(scene, stop, step)
    t2 = clock.perf_counter()
    res = fn(scene, stop, step)
    t3 = clock.perf_counter()
    np.savez(out, time=np.asarray(res["time"]), **{k: np.asarray(res[k]) for k in keys(scene)})
    return {"import": t1 - t0, "first": t2 - t1, "second": t3 - t2}


def in_child(method: str, scene: str, stop: float, step: float, out: Path, timeout: float = 1800.0) -> dict:
    """Run :func:`child` in a fresh interpreter; its measurement, plus ``process`` [s]: the whole child
    (interpreter start to exit); ``error`` when it failed."""
    t0 = clock.perf_counter()
    p = subprocess.run([sys.executable, "-m", "cranefmu.studies.timing", method, scene, repr(stop), repr(step),
                        str(out)], capture_output=True, text=True, timeout=timeout,
                       env={**os.environ, "PYTHONWARNINGS": "ignore"})
    wall = clock.perf_counter() - t0
    lines = [x for x in p.stdout.splitlines() if x.startswith("{")]
    if p.returncode != 0 or not lines:
        tail = (p.stderr.strip().splitlines() or ["no output"])[-1]
        return {"error": f"{method} exited {p.returncode}: {tail}", "process": wall}
    return {**json.loads(lines[-1]), "process": wall}


def cranefmu_command() -> list[str]:
    """The ``cranefmu`` console script beside this interpreter (as a user runs it), else the same via -c."""
    script = Path(sys.executable).parent / "cranefmu"
    if script.is_file():
        return [str(script)]
    return [sys.executable, "-c", "import sys; from cranefmu.cli import main; sys.exit(main())"]


def command_wall(args: list[str], timeout: float = 1800.0) -> tuple[float, str]:
    """Seconds of a whole command (cold: a fresh process) and its error line ('' when it exited 0)."""
    t0 = clock.perf_counter()
    p = subprocess.run(args, capture_output=True, text=True, timeout=timeout)
    wall = clock.perf_counter() - t0
    return wall, "" if p.returncode == 0 else ((p.stderr.strip().splitlines() or ["?"])[-1])


if __name__ == "__main__":
    m, sc, T, H, o = sys.argv[1:6]
    print(json.dumps(child(m, sc, float(T), float(H), o)), flush=True)
