"""cranefmu: crane dynamics as FMI co-simulation components, and a master to run them.

Public API: :func:`simulate` (run a scene or an .ssp, returns the rows), :func:`run` (the same, with
statistics, a :class:`RunResult`), :class:`Execution` (a run the caller steps; :class:`Observer`,
:class:`Command` and :class:`Source` plug into it, :class:`RunInterrupted` ends it on a signal), :func:`resolve` (the :class:`RunSpec` a run would take: every setting and where it came
from; ``run(spec)`` runs it), :func:`build` (build FMUs and scenes), :func:`sweep` (a study of many runs on Dask).
Scene names resolve through :mod:`cranefmu.scene_catalog`, registered with the master here so the
master imports nothing of it.
"""
from __future__ import annotations

from pathlib import Path

from .master.scene_names import register_scene_resolver as _register_scene_resolver

__version__ = "0.1.0"

__all__ = ["simulate", "run", "resolve", "RunSpec", "Execution", "RunResult", "RunInterrupted", "Observer", "Command",
           "Source", "build", "sweep", "fmu_path", "__version__"]


def _resolve_scene_name(name: str) -> Path:
    # imported on first use: `import cranefmu` stays light (the physics runs without fmpy or pythonfmu)
    from .scene_catalog import resolve

    return resolve(name)


_register_scene_resolver(_resolve_scene_name)


def fmu_path(name: str) -> Path:
    """The built ``<name>.fmu`` (``"Rope"``), built first if missing or stale: in ``fmus/`` of a checkout,
    in the user cache when installed (``cranefmu build --where`` prints the folder)."""
    from . import build as b
    from .errors import CraneFmuError
    from .sources import fmu_scripts

    known = sorted(s.stem for s in fmu_scripts())
    if name not in known:
        raise CraneFmuError(f"FMU {name!r} is unknown: one of {', '.join(known)}")
    b.build(verbose=False, only=[name])
    return b.FMU_DIR / f"{name}.fmu"


def __getattr__(name: str):
    # imported lazily so that the physics can be used without fmpy or pythonfmu loaded
    if name in ("simulate", "run", "Execution", "RunResult", "RunInterrupted", "Observer", "Command", "Source"):
        from .master import run as master_run
        return getattr(master_run, name)
    if name in ("resolve", "RunSpec"):
        from .master import runspec
        return getattr(runspec, name)
    if name == "build":
        from .build import build
        return build
    if name == "sweep":   # the package cranefmu.sweep, callable as the function (see its __init__)
        import importlib

        return importlib.import_module(".sweep", __name__)
    raise AttributeError(f"module 'cranefmu' has no attribute {name!r}")
