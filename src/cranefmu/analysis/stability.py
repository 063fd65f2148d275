"""Stability of explicit co-simulation of a mass on a spring-damper split into two parts (derived).

The split: a stateless spring-damper (force F = -c x - b v, direct feedthrough from the mass's
position and velocity) and a mass m integrated exactly under the force it is given.  At each
communication point t_n the master reads x_n, v_n, evaluates F_n and hands the mass the
polynomial through the last ``order + 1`` force values (order 0: zero-order hold):

    F(t_n + tau) = F_n + d1 tau + d2 tau^2 / 2,   0 <= tau <= H
    order 1: d1 = (F_n - F_{n-1}) / H
    order 2: d1 = (3 F_n - 4 F_{n-1} + F_{n-2}) / (2 H),  d2 = (F_n - 2 F_{n-1} + F_{n-2}) / H^2

and the mass moves exactly:  v_{n+1} = v_n + (1/m) int_0^H F,  x_{n+1} = x_n + H v_n + (1/m) int_0^H (H - tau) F.
In units m = 1, omega = sqrt(c / m) = 1 (s = omega H, z = b / (2 sqrt(c m))) this is a linear
recurrence on (x_n, v_n, x_{n-1}, v_{n-1}, x_{n-2}, v_{n-2}); it is stable while the spectral
radius of its matrix is below 1.

Zero-order hold in closed form (Jury's conditions on the 2 x 2 matrix, trace 2 - s^2/2 - 2 z s,
determinant 1 - 2 z s + s^2 / 2):  stable iff  s < min(4 z, 1 / z).  Undamped (z = 0) it is never
stable: |lambda|^2 = 1 + s^2 / 2 per step.  With a stateless spring-damper, Gauss-Seidel in
feedthrough order (mass first) gives the same recurrence as Jacobi.
"""
from __future__ import annotations

import math

import numpy as np


def step_matrix(s: float, zeta: float, order: int) -> np.ndarray:
    """Matrix of the recurrence over one macro step (units m = 1, omega = 1, H = s), 6 x 6."""
    h = s
    # force at the points n, n-1, n-2 as rows over the state (x_n, v_n, x_n-1, v_n-1, x_n-2, v_n-2)
    f = np.zeros((3, 6))
    for k in range(3):
        f[k, 2 * k], f[k, 2 * k + 1] = -1.0, -2.0 * zeta
    if order == 0:
        d1, d2 = np.zeros(6), np.zeros(6)
    elif order == 1:
        d1, d2 = (f[0] - f[1]) / h, np.zeros(6)
    elif order == 2:
        d1 = (3 * f[0] - 4 * f[1] + f[2]) / (2 * h)
        d2 = (f[0] - 2 * f[1] + f[2]) / h ** 2
    else:
        raise ValueError(f"order = {order!r} is not allowed: 0, 1 or 2")
    impulse = f[0] * h + d1 * h ** 2 / 2 + d2 * h ** 3 / 6          # int_0^H F
    moment = f[0] * h ** 2 / 2 + d1 * h ** 3 / 6 + d2 * h ** 4 / 24  # int_0^H (H - tau) F
    a = np.zeros((6, 6))
    a[0] = moment
    a[0, 0] += 1.0
    a[0, 1] += h
    a[1] = impulse
    a[1, 1] += 1.0
    a[2, 0] = a[3, 1] = a[4, 2] = a[5, 3] = 1.0  # shift the history
    return a


def spectral_radius(s: float, zeta: float, order: int) -> float:
    """Largest |eigenvalue| of :func:`step_matrix` (the history modes of lower orders are 0)."""
    return float(np.max(np.abs(np.linalg.eigvals(step_matrix(s, zeta, order)))))


def zoh_limit(zeta: float) -> float:
    """Largest stable omega H of zero-order hold: min(4 zeta, 1 / zeta) (0 when undamped)."""
    return 0.0 if zeta <= 0.0 else min(4.0 * zeta, 1.0 / zeta)


def _stable(s: float, zeta: float, order: int) -> bool:
    # 1e-12: round-off of the eigenvalues; a real growth at omega H >= 1e-2 is far above it
    return spectral_radius(s, zeta, order) < 1.0 + 1e-12


def stability_limit(zeta: float, order: int, s_max: float = 10.0, n: int = 4000) -> float:
    """Largest omega H in [1e-2, s_max] below which every omega H is stable (0 if 1e-2 is not;
    scan on a log grid, then bisection)."""
    grid = np.geomspace(1e-2, s_max, n)
    stable = np.array([_stable(s, zeta, order) for s in grid])
    if not stable[0]:
        return 0.0
    if stable.all():
        return math.inf
    i = int(np.argmin(stable))  # first unstable grid point
    lo, hi = grid[i - 1], grid[i]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _stable(mid, zeta, order) else (lo, mid)
    return float(lo)
