"""Parameter studies of many runs on Dask: a design (:mod:`.spec`), metrics per run (:mod:`.metrics`),
the distributed engine (:mod:`.engine`, runs in :mod:`.worker`), the CSV table (:mod:`.table`) and
the ``cranefmu sweep`` command (:mod:`.command`).

``cranefmu.sweep(scene, vary, ...)`` calls :func:`.engine.sweep`: this package is callable, so the
name works both as the package and as the function.
"""
from __future__ import annotations

import sys
import types

from .engine import SweepResult, sweep

__all__ = ["sweep", "SweepResult"]


class _CallableModule(types.ModuleType):
    # `import cranefmu.sweep` binds the package to the name cranefmu.sweep; calling it runs a sweep
    def __call__(self, *args, **kwargs) -> SweepResult:
        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
