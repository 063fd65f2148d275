"""One monolithic reference solve per argument set, shared by every test of the session.

:func:`cranefmu.analysis.reference.solve` is deterministic: the same scene, parameter set, parameters, stop time,
output times, rtol and method give the same arrays.  Tests that need the same reference (the listed modes
sharing one probe run, a mode fit and a setting check) call :func:`solve` here instead, and the second
call returns copies of the first call's arrays without solving again.  :data:`SOLVES` counts the solves.
"""
from __future__ import annotations

import numpy as np

from cranefmu.analysis import modal
from cranefmu.analysis import reference

_CACHE: dict[tuple, dict] = {}
SOLVES: list[tuple] = []   # the keys actually solved, in order (for the cache's own test)


def _key(scene: str, stop_time: float, times: np.ndarray | None, parameter_set: str, parameters: dict | None,
         rtol: float, method: str) -> tuple:
    if times is not None:
        t = np.ascontiguousarray(times, dtype=float)
        times = (t.shape, t.tobytes())
    frozen = tuple(sorted((k, repr(v)) for k, v in (parameters or {}).items()))
    return scene, float(stop_time), times, parameter_set, frozen, float(rtol), method


def solve(scene: str, stop_time: float, times: np.ndarray | None = None, parameter_set: str = "default",
          parameters: dict | None = None, rtol: float = 1e-10, method: str = "Radau") -> dict[str, np.ndarray]:
    """:func:`cranefmu.analysis.reference.solve` with the same arguments, solved once per session; the caller gets
    its own copies of the arrays (it may change them)."""
    key = _key(scene, stop_time, times, parameter_set, parameters, rtol, method)
    if key not in _CACHE:
        SOLVES.append(key)
        _CACHE[key] = reference.solve(scene, stop_time, times, parameter_set=parameter_set, parameters=parameters,
                                      rtol=rtol, method=method)
    return {name: (value.copy() if isinstance(value, np.ndarray) else value) for name, value in _CACHE[key].items()}


class References(modal.References):
    """:class:`cranefmu.analysis.modal.References` whose solves go through the session cache (same arguments)."""

    def at(self, probe: dict, span: float) -> dict:
        times = np.linspace(0.0, span, int(round(span / modal.REF_GRID)) + 1)
        return solve(self.scene, span, times, parameter_set=self.parameter_set or "default",
                     parameters={**(self.parameters or {}), **probe}, rtol=self.rtol)
