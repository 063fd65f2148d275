"""cranefmu: crane dynamics as FMI co-simulation components, and a master to run them.

Public API: :func:`simulate` (run a scene or an .ssp), :func:`build` (build FMUs and scenes),
:func:`sweep` (a study of many runs on Dask).
"""
from __future__ import annotations

__version__ = "0.1.0"

__all__ = ["simulate", "build", "sweep", "__version__"]


def __getattr__(name: str):
    # imported lazily so that the physics can be used without fmpy or pythonfmu loaded
    if name == "simulate":
        from .master.run import simulate
        return simulate
    if name == "build":
        from .build import build
        return build
    if name == "sweep":   # the package cranefmu.sweep, callable as the function (see its __init__)
        import importlib

        return importlib.import_module(".sweep", __name__)
    raise AttributeError(f"module 'cranefmu' has no attribute {name!r}")
