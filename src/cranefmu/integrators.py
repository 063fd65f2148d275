"""Solvers an FMU can pick for its internal stepping between communication points.

One contract for every method: ``integrate(f, t0, x0, h, method, ...)`` advances ``x' = f(t, x)``
from ``t0`` to ``t0 + h`` and returns the new state.  Fixed-step methods take
``ceil(h / max_step)`` equal sub-steps; the adaptive ones delegate to scipy's ``solve_ivp``
with ``rtol``/``atol`` and ``max_step``.  Bundled into every FMU: numpy and scipy only.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

RHS = Callable[[float, np.ndarray], np.ndarray]

FIXED_STEP = ("euler", "rk2", "rk4")
ADAPTIVE = ("rk45", "radau", "bdf")
METHODS = FIXED_STEP + ADAPTIVE


def _euler(f: RHS, t: float, x: np.ndarray, h: float) -> np.ndarray:
    return x + h * f(t, x)


def _rk2(f: RHS, t: float, x: np.ndarray, h: float) -> np.ndarray:
    # Heun's method, 2nd order
    k1 = f(t, x)
    k2 = f(t + h, x + h * k1)
    return x + 0.5 * h * (k1 + k2)


def _rk4(f: RHS, t: float, x: np.ndarray, h: float) -> np.ndarray:
    k1 = f(t, x)
    k2 = f(t + 0.5 * h, x + 0.5 * h * k1)
    k3 = f(t + 0.5 * h, x + 0.5 * h * k2)
    k4 = f(t + h, x + h * k3)
    return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


_STEPPERS = {"euler": _euler, "rk2": _rk2, "rk4": _rk4}


def substeps(h: float, max_step: float) -> int:
    """Number of equal sub-steps a fixed-step method takes over ``h`` [s]."""
    return max(1, math.ceil(h / max_step - 1e-9))


def integrate(f: RHS, t0: float, x0: np.ndarray, h: float, method: str = "rk4",
              rtol: float = 1e-6, atol: float = 1e-9, max_step: float = 1e-3) -> np.ndarray:
    """Advance ``x' = f(t, x)`` from ``t0`` over ``h`` seconds with the named method."""
    if x0.size == 0 or h == 0.0:
        return x0.copy()
    if method in _STEPPERS:
        step = _STEPPERS[method]
        n = substeps(h, max_step)
        dt = h / n
        x = x0
        for i in range(n):
            x = step(f, t0 + i * dt, x, dt)
        return x
    if method in ADAPTIVE:
        from scipy.integrate import solve_ivp  # only the adaptive methods need scipy

        sol = solve_ivp(f, (t0, t0 + h), x0, method={"rk45": "RK45", "radau": "Radau", "bdf": "BDF"}[method],
                        rtol=rtol, atol=atol, max_step=max_step)
        if not sol.success:
            raise FloatingPointError(f"solver {method} failed at t = {t0:.6g} s: {sol.message}")
        return sol.y[:, -1]
    raise ValueError(f"solver = {method!r} is not allowed: one of {', '.join(METHODS)}")
