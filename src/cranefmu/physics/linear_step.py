"""Exact step of a linear model with inputs polynomial in time over the step (derived).

For x' = A x + b + B u(s) with u(s) = u0 + s r1 + s^2/2 r2 (s: time into the step, the inputs a
co-simulation master feeds an FMU), the vector z = (x, 1, u0, r1, r2) obeys z' = Z z with

    Z = [[A, b, B, 0, 0],      x' = A x + b + B u
         [0, 0, 0, 0, 0],      1' = 0
         [0, 0, 0, I, 0],      u' = r1 + s r2
         [0, 0, 0, 0, I],      (r1 + s r2)' = r2
         [0, 0, 0, 0, 0]]

so x(s) = [expm(Z s) z(0)] restricted to x, exact to round-off (the augmented-matrix construction of
Van Loan 1978 for integrals of matrix exponentials).  One expm per step size, then a matrix-vector
product per step.  The exponential, the powers of the sub-step map and the product per step are
cranefmu.physics.expm's (scipy's algorithm in the fixed order of operations of the C twin
native/models/cf_linear_step.c: the Python and the native FMUs step to the same bits, issue 33).
"""
from __future__ import annotations

import numpy as np

from .expm import expm, matmul, matvec


def step_key(h: float) -> float:
    """The step size [s] to 12 significant digits: a fixed-step master computes h as t_next - t,
    which differs from step to step in the last bits (measured: a cache keyed on the raw h missed
    on every step of truck_telescope and recomputed expm each time).  The map for the rounded h
    differs from the exact one by ~1e-12 relative of h, far below the step's own error."""
    return float(f"{h:.12g}")


class LinearPropagator:
    """Maps of z = (x, 1, u0, r1, r2) to the state at sub-points of a step, cached per step size."""

    def __init__(self, a: np.ndarray, b: np.ndarray, big_b: np.ndarray):
        n, m = big_b.shape
        if a.shape != (n, n) or b.shape != (n,):
            raise ValueError(f"linear system shapes do not match: A {a.shape}, b {b.shape}, B {big_b.shape}")
        self.n, self.m = n, m
        size = n + 1 + 3 * m
        z = np.zeros((size, size))
        z[:n, :n], z[:n, n], z[:n, n + 1:n + 1 + m] = a, b, big_b
        z[n + 1:n + 1 + m, n + 1 + m:n + 1 + 2 * m] = np.eye(m)
        z[n + 1 + m:n + 1 + 2 * m, n + 1 + 2 * m:] = np.eye(m)
        self.generator = z
        self.spectral_radius = float(np.max(np.abs(np.linalg.eigvals(a)), initial=0.0))
        self._cache: dict[tuple[float, int], list[np.ndarray]] = {}
        self._last: tuple | None = None   # (h as given, k, maps) of the last call

    @staticmethod
    def apply(m: np.ndarray, z: np.ndarray) -> np.ndarray:
        """The state m z of a map from :meth:`maps` and z from :meth:`augment`, each row summed from 0.0 left to
        right (C's cf_linear_apply; numpy's BLAS product orders its sums its own way)."""
        return np.array(matvec(m, z))

    def augment(self, x: np.ndarray, u0: np.ndarray, r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
        return np.concatenate((x, (1.0,), u0, r1, r2))

    def maps(self, h: float, k: int = 1) -> list[np.ndarray]:
        """[M_0, ..., M_k]: x(j h / k) = M_j z for j = 0..k (M_0 picks x out of z)."""
        last = self._last
        if last is not None and last[0] == h and last[1] == k:   # a fixed-step master: the same h again
            return last[2]
        h_given = h
        h = step_key(h)
        key = (h, k)
        maps = self._cache.get(key)
        if maps is None:
            sub = expm(self.generator * (h / k))
            phi = np.eye(self.generator.shape[0])
            maps = [phi[:self.n].copy()]
            for _ in range(k):
                phi = matmul(sub, phi)
                maps.append(phi[:self.n].copy())
            if len(self._cache) >= 16:   # an adaptive master varies h: keep the cache small
                self._cache.clear()
            self._cache[key] = maps
        self._last = (h_given, k, maps)
        return maps
