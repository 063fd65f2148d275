"""Solvers an FMU can pick for its internal stepping between communication points.

One contract for every method: ``integrate(f, t0, x0, h, method, ...)`` advances ``x' = f(t, x)``
from ``t0`` to ``t0 + h`` and returns the new state.  Fixed-step methods take
``ceil(h / max_step)`` equal sub-steps; the adaptive ones delegate to scipy's ``solve_ivp``
with ``rtol``/``atol`` and ``max_step``.  Bundled into every FMU: numpy, and scipy for the adaptive methods only (imported at their first step).

Explicit fixed-step: ``euler`` (order 1), ``rk2`` (Heun, 2), ``rk4`` (4): cheap, but stable only
for ``max_step`` below about 2.8/|lambda_max| (rk4) on a stiff internal.
Implicit fixed-step: ``trbdf2`` (Bank et al. 1985, gamma = 2 - sqrt(2)): a trapezoidal stage to
t + gamma h, then BDF2 through (t, t + gamma h, t + h); order 2, L-stable, one step (no history to
carry across communication points).  Both stages solve ``y = a + c h f(y)`` with the same
c = gamma/2 = (1 - gamma)/(2 - gamma), so one finite-difference Jacobian and one inverse of
I - c h J per sub-step serve both (simplified Newton; the inverse is kept over the sub-steps of a
call while Newton converges).  The states are few (at most 10): a matrix-vector product with the
inverse costs less than scipy's LU solve per Newton iteration.
Adaptive: ``rk45`` (explicit), ``radau`` and ``bdf`` (implicit), from scipy.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

RHS = Callable[[float, np.ndarray], np.ndarray]

FIXED_STEP = ("euler", "rk2", "rk4", "trbdf2")
#: the model's own closed-form step (``Model.exact_step``), offered by the FMUs whose model has one
EXACT = "exact"
AUTO = "auto"   # a model's own closed-form step where it applies, rk4 elsewhere (fmi_adapter.solvers)
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


_GAMMA = 2.0 - math.sqrt(2.0)
_C = 0.5 * _GAMMA                                    # = (1 - gamma) / (2 - gamma)
_W_G = 1.0 / (_GAMMA * (2.0 - _GAMMA))               # BDF2 weights of x(t + gamma h) and x(t)
_W_0 = (1.0 - _GAMMA) ** 2 / (_GAMMA * (2.0 - _GAMMA))
_NEWTON_ITERATIONS = 12


def _jacobian(f: RHS, t: float, x: np.ndarray, fx: np.ndarray) -> np.ndarray:
    """Forward-difference Jacobian df/dx (n extra evaluations of f)."""
    n = x.size
    jac = np.empty((n, n))
    for j in range(n):
        dx = 1.49e-8 * max(1.0, abs(x[j]))
        xp = x.copy()
        xp[j] += dx
        jac[:, j] = (f(t, xp) - fx) / dx
    return jac


def _solve_stage(f: RHS, t: float, a: np.ndarray, y: np.ndarray, ch: float, inverse: np.ndarray,
                 tol: float) -> np.ndarray:
    """Simplified Newton for y = a + ch f(t, y) with the inverse of I - ch J."""
    for _ in range(_NEWTON_ITERATIONS):
        r = y - a - ch * f(t, y)
        dy = inverse @ r
        y = y - dy
        if np.all(np.abs(dy) <= tol * (1.0 + np.abs(y))):
            return y
    raise FloatingPointError(f"solver trbdf2: Newton iteration did not converge at t = {t:.6g} s "
                             f"(sub-step {ch / _C:.3g} s)")


def _trbdf2_step(f: RHS, t: float, x: np.ndarray, dt: float, inverse: np.ndarray, tol: float) -> np.ndarray:
    """One TR-BDF2 step with ``inverse`` = (I - c dt J)^-1; FloatingPointError if Newton fails."""
    ch = _C * dt
    fx = f(t, x)
    tg = t + _GAMMA * dt
    xg = _solve_stage(f, tg, x + ch * fx, x + _GAMMA * dt * fx, ch, inverse, tol)
    return _solve_stage(f, t + dt, _W_G * xg - _W_0 * x, xg + (1.0 - _GAMMA) * dt * f(tg, xg), ch, inverse, tol)


def _trbdf2(f: RHS, t0: float, x0: np.ndarray, dt: float, n: int, tol: float = 1e-10, depth: int = 0) -> np.ndarray:
    """``n`` TR-BDF2 sub-steps of ``dt``.  The inverse is kept while the simplified Newton iteration
    converges and renewed when it does not; if Newton fails even with a fresh Jacobian (a kink of
    f inside the step: contact, slack), the sub-step is halved, at most 8 times."""

    def fresh_inverse(t: float, x: np.ndarray) -> np.ndarray:
        try:
            return np.linalg.inv(np.eye(x.size) - _C * dt * _jacobian(f, t, x, f(t, x)))
        except np.linalg.LinAlgError:
            raise FloatingPointError(f"solver trbdf2: singular Newton matrix at t = {t:.6g} s") from None

    x, inverse = x0, None
    for i in range(n):
        t = t0 + i * dt
        try:
            inverse = inverse if inverse is not None else fresh_inverse(t, x)
            try:
                x = _trbdf2_step(f, t, x, dt, inverse, tol)
            except FloatingPointError:
                inverse = fresh_inverse(t, x)
                x = _trbdf2_step(f, t, x, dt, inverse, tol)
        except FloatingPointError:
            if depth >= 8:
                raise
            x, inverse = _trbdf2(f, t, x, 0.5 * dt, 2, tol, depth + 1), None
    return x


_STEPPERS = {"euler": _euler, "rk2": _rk2, "rk4": _rk4}


def rk4_list(f: Callable[[float, list], list], t0: float, x0: list[float], h: float,
             max_step: float = 1e-3) -> list[float]:
    """:func:`integrate` with ``rk4`` for a right-hand side on lists of floats: the same sub-steps and
    the same operations per component in the same order as the array form (so the same result to the
    last bit), without a numpy call per stage (on a few states those cost more than the arithmetic)."""
    if not x0 or h == 0.0:
        return list(x0)
    n = substeps(h, max_step)
    dt = h / n
    half, sixth = 0.5 * dt, dt / 6.0
    x = x0
    for i in range(n):
        t = t0 + i * dt
        k1 = f(t, x)
        k2 = f(t + 0.5 * dt, [a + half * b for a, b in zip(x, k1)])
        k3 = f(t + 0.5 * dt, [a + half * b for a, b in zip(x, k2)])
        k4 = f(t + dt, [a + dt * b for a, b in zip(x, k3)])
        x = [a + sixth * (b1 + 2.0 * b2 + 2.0 * b3 + b4) for a, b1, b2, b3, b4 in zip(x, k1, k2, k3, k4)]
    return x


def substeps(h: float, max_step: float) -> int:
    """Number of equal sub-steps a fixed-step method takes over ``h`` [s]."""
    return max(1, math.ceil(h / max_step - 1e-9))


def integrate(f: RHS, t0: float, x0: np.ndarray, h: float, method: str = "rk4",
              rtol: float = 1e-6, atol: float = 1e-9, max_step: float = 1e-3) -> np.ndarray:
    """Advance ``x' = f(t, x)`` from ``t0`` over ``h`` seconds with the named method."""
    if x0.size == 0 or h == 0.0:
        return x0.copy()
    if method in FIXED_STEP:
        n = substeps(h, max_step)
        dt = h / n
        if method == "trbdf2":
            return _trbdf2(f, t0, x0, dt, n)
        step = _STEPPERS[method]
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
