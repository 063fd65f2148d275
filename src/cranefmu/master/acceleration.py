"""Accelerators of a fixed-point iteration u = G(u) on the coupling values (scaled to order 1).

Each proposes the next iterate from the current one and its image.  ``start_step`` is called at
the start of every macro step (or initialization block).
"""
from __future__ import annotations

import numpy as np


class Plain:
    """No acceleration: u_{k+1} = G(u_k) (relaxed by ``omega``)."""

    def __init__(self, omega: float = 1.0):
        self.omega = omega

    def start_step(self) -> None:
        pass

    def next(self, u: np.ndarray, gu: np.ndarray) -> np.ndarray:
        return u + self.omega * (gu - u)


class Aitken:
    """Dynamic Aitken relaxation: omega_k = -omega_{k-1} r_{k-1}.(r_k - r_{k-1}) / |r_k - r_{k-1}|^2,
    u_{k+1} = u_k + omega_k r_k with r = G(u) - u (Irons and Tuck 1969; Kuettler and Wall 2008, eq. 44)."""

    def __init__(self, omega0: float = 0.5, omega_max: float = 2.0):
        self.omega0, self.omega_max = omega0, omega_max
        self.start_step()

    def start_step(self) -> None:
        self.omega = self.omega0
        self.prev_r: np.ndarray | None = None

    def next(self, u: np.ndarray, gu: np.ndarray) -> np.ndarray:
        r = gu - u
        if self.prev_r is not None:
            dr = r - self.prev_r
            den = float(dr @ dr)
            if den > 0.0:
                omega = -self.omega * float(self.prev_r @ dr) / den
                if np.isfinite(omega) and omega != 0.0:
                    self.omega = float(np.clip(omega, -self.omega_max, self.omega_max))
        self.prev_r = r
        return u + self.omega * r


class IQNILS:
    """Interface quasi-Newton with an inverse Jacobian from a least-squares model (IQN-ILS,
    Degroote, Bathe and Vierendeels 2009, eq. 10-14).

    Columns V = [Delta r], W = [Delta G(u)] from this step's iterations and from the last
    ``reuse`` macro steps; c = argmin |V c + r_k|, u_{k+1} = G(u_k) + W c.  Without columns it
    takes a relaxed step u + omega0 r.  Nearly dependent columns are dropped (QR filter).
    """

    def __init__(self, omega0: float = 0.5, reuse: int = 3, filter_eps: float = 1e-10):
        self.omega0, self.reuse, self.eps = omega0, reuse, filter_eps
        self.old: list[tuple[np.ndarray, np.ndarray]] = []   # (V, W) of past steps, newest last
        self.v: list[np.ndarray] = []
        self.w: list[np.ndarray] = []
        self.prev: tuple[np.ndarray, np.ndarray] | None = None

    def start_step(self) -> None:
        if self.v and self.reuse:
            self.old.append((np.array(self.v).T, np.array(self.w).T))
            del self.old[:-self.reuse]
        self.v, self.w, self.prev = [], [], None

    def next(self, u: np.ndarray, gu: np.ndarray) -> np.ndarray:
        r = gu - u
        if self.prev is not None:
            r0, g0 = self.prev
            self.v.append(r - r0)
            self.w.append(gu - g0)
        self.prev = (r, gu)
        cols_v = [np.array(self.v).T] if self.v else []
        cols_w = [np.array(self.w).T] if self.w else []
        for v, w in reversed(self.old):
            cols_v.append(v)
            cols_w.append(w)
        if not cols_v:
            return u + self.omega0 * r
        v = np.hstack(cols_v)
        w = np.hstack(cols_w)
        keep = _independent(v, self.eps)
        if not keep:
            return u + self.omega0 * r
        v, w = v[:, keep], w[:, keep]
        c, *_ = np.linalg.lstsq(v, -r, rcond=None)
        return gu + w @ c


def _independent(v: np.ndarray, eps: float) -> list[int]:
    """Indices of columns kept, newest first, dropping each one nearly in the span of those before."""
    keep: list[int] = []
    basis: list[np.ndarray] = []
    for j in range(v.shape[1]):
        col = v[:, j].copy()
        norm0 = float(np.linalg.norm(col))
        if norm0 == 0.0:
            continue
        for q in basis:
            col -= (q @ col) * q
        if np.linalg.norm(col) > eps * norm0 and len(basis) < v.shape[0]:
            basis.append(col / np.linalg.norm(col))
            keep.append(j)
    return keep


ACCELERATORS = {"iqn-ils": IQNILS, "aitken": Aitken, "none": Plain}
