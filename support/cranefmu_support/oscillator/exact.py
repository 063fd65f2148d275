"""Exact solution of the two-mass oscillator (monolithic, matrix exponential) and the
amplification matrix of Jacobi with zero-order hold.  Parameters as in OscMass/OscSpring.

State z = [x1, v1, x2, v2] (with spring.m = 0 the far end is anchored and z = [x1, v1]).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm


@dataclass(frozen=True)
class Oscillator:
    m1: float = 1.0
    k1: float = 40.0
    d1: float = 0.0
    f1: float = 0.0
    m2: float = 1.0
    kc: float = 100.0
    dc: float = 0.0
    k2: float = 60.0
    d2: float = 0.0
    f2: float = 0.0

    def parameters(self) -> dict:
        """The master's ``parameters=`` overrides for this oscillator."""
        return {"mass.m": self.m1, "mass.k": self.k1, "mass.d": self.d1, "mass.f": self.f1,
                "spring.m": self.m2, "spring.kc": self.kc, "spring.dc": self.dc, "spring.k": self.k2,
                "spring.d": self.d2, "spring.f": self.f2}

    @property
    def anchored(self) -> bool:
        return self.m2 == 0

    def system(self) -> tuple[np.ndarray, np.ndarray]:
        """z' = A z + b (monolithic, derived)."""
        m1, k1, d1, kc, dc = self.m1, self.k1, self.d1, self.kc, self.dc
        if self.anchored:
            return np.array([[0, 1], [-(k1 + kc) / m1, -(d1 + dc) / m1]]), np.array([0, self.f1 / m1])
        m2, k2, d2 = self.m2, self.k2, self.d2
        a = np.array([[0, 1, 0, 0],
                      [-(k1 + kc) / m1, -(d1 + dc) / m1, kc / m1, dc / m1],
                      [0, 0, 0, 1],
                      [kc / m2, dc / m2, -(kc + k2) / m2, -(dc + d2) / m2]])
        return a, np.array([0, self.f1 / m1, 0, self.f2 / m2])

    def solution(self, t: np.ndarray, z0: np.ndarray) -> np.ndarray:
        """z(t) for every t (rows), exact up to rounding."""
        a, b = self.system()
        n = len(z0)
        aug = np.zeros((n + 1, n + 1))
        aug[:n, :n], aug[:n, n] = a, b
        out = np.empty((len(t), n))
        for i, ti in enumerate(t):
            out[i] = (expm(aug * ti) @ np.append(z0, 1.0))[:n]
        return out

    def energy(self, z: np.ndarray) -> np.ndarray:
        """Mechanical energy [J] of rows z (no loads)."""
        x1, v1 = z[:, 0], z[:, 1]
        if self.anchored:
            return 0.5 * self.m1 * v1 ** 2 + 0.5 * (self.k1 + self.kc) * x1 ** 2
        x2, v2 = z[:, 2], z[:, 3]
        return (0.5 * self.m1 * v1 ** 2 + 0.5 * self.m2 * v2 ** 2 + 0.5 * self.k1 * x1 ** 2
                + 0.5 * self.kc * (x2 - x1) ** 2 + 0.5 * self.k2 * x2 ** 2)

    def frequencies(self) -> np.ndarray:
        """Undamped natural frequencies [rad/s]."""
        a, _ = self.system()
        return np.sort(np.abs(np.linalg.eigvals(a).imag))[::2]

    def jacobi_zoh_matrix(self, h: float) -> np.ndarray:
        """z_{n+1} = M z_n for Jacobi with zero-order hold (no loads): each FMU integrates its own
        part exactly with the other's output held at its value at t_n (derived)."""
        m1, k1, d1, kc, dc = self.m1, self.k1, self.d1, self.kc, self.dc
        # subsystem 1: [x1, v1]' = A1 [x1, v1] + B1 F_n ;  F_n = C z_n
        a1 = np.array([[0, 1], [-k1 / m1, -d1 / m1]])
        b1 = np.array([[0], [1 / m1]])
        if self.anchored:
            c = np.array([[-kc, -dc]])
            return _held(a1, b1, h) @ np.vstack([np.eye(2), c])
        m2, k2, d2 = self.m2, self.k2, self.d2
        c = np.array([[-kc, -dc, kc, dc]])
        a2 = np.array([[0, 1], [-(kc + k2) / m2, -(dc + d2) / m2]])
        b2 = np.array([[0, 0], [kc / m2, dc / m2]])   # inputs x1_n, v1_n held
        m = np.zeros((4, 4))
        m[:2] = _held(a1, b1, h) @ np.vstack([np.eye(4)[:2], c])
        m[2:] = _held(a2, b2, h) @ np.vstack([np.eye(4)[2:], np.eye(4)[:2]])
        return m


def _held(a: np.ndarray, b: np.ndarray, h: float) -> np.ndarray:
    """[Phi, Gamma] of x' = a x + b u with u held over h: x(h) = Phi x0 + Gamma u."""
    n, k = b.shape
    aug = np.zeros((n + k, n + k))
    aug[:n, :n], aug[:n, n:] = a, b
    e = expm(aug * h)
    return e[:n, :]
