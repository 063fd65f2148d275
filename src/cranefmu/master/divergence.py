"""Default alarm for an unstable explicit coupling: geometric growth of the power-bond residuals.

Beyond its stability limit an explicit coupling multiplies its error by the spectral radius
rho > 1 of the step recurrence every macro step (:mod:`cranefmu.stability`), so the energy
residual of a bond grows like rho^(2n).  A slack-capable connection (a rope cannot push) may
bound the blow-up and leave finite nonsense, so waiting for a non-finite value is not enough.

The test (derived): the maxima of the residual over 4 consecutive blocks of W = 1, 2, 4, ... 256
steps; each block's maximum must be at least ``factor`` (and at least ``per_step``^W) times the
one before, and each of these ratios at least ``keep`` times the previous ratio.  Geometric growth
keeps its ratio; growth that follows a power of the time since an event, dE ~ (t - t_e)^p, has
ratios ((a + kW) / (a + (k-1)W))^p that fall from block to block, so it does not pass unless p is
so large (about 10) that it is growth in all but name (measured: no alarm in the stable runs of
every scene).  ``per_step`` = 1.01 leaves alone a slow energy gain such as an
undamped Jacobi oscillator at omega H < 0.14 (energy factor 1 + (omega H)^2 / 2 per step, see
README).  A residual at the level of round-off (below ``floor`` times the largest energy the bond
carried in a step so far) is not growth.  Fixed-step runs only: with an adaptive step dE follows
h as well.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LEVELS = 9   # block lengths 1 ... 256 steps


@dataclass
class Growth:
    bond: int          # index of the bond
    steps: int         # steps over which it grew
    factor: float      # residual at the end / residual at the start of those steps

    def per_step(self) -> float:
        return self.factor ** (1.0 / self.steps)


class GrowthAlarm:
    """Feed it each step's residuals and carried energies [J] per bond; :meth:`update` returns the
    :class:`Growth` that trips it, or None."""

    def __init__(self, n_bonds: int, factor: float = 3.0, per_step: float = 1.01, keep: float = 0.7,
                 blocks: int = 3, floor: float = 1e-9):
        self.factor, self.per_step, self.keep, self.blocks, self.floor = factor, per_step, keep, blocks, floor
        self.count = 0
        self.carried = [0.0] * n_bonds        # largest carried energy per step so far
        # per level: completed block maxima of the residual per bond, and the carried maxima at each
        # block's end (plain floats: a few bonds, and numpy's per-call cost would dominate)
        self.done: list[list[list[float]]] = [[] for _ in range(LEVELS)]
        self.scale: list[list[list[float]]] = [[] for _ in range(LEVELS)]
        self.least = [max(factor, per_step ** (1 << j)) for j in range(LEVELS)]   # least ratio per level

    def update(self, residual: np.ndarray, carried: np.ndarray) -> Growth | None:
        self.count += 1
        self.carried = [max(a, b) for a, b in zip(self.carried, carried.tolist())]
        hit = None
        for j in range(LEVELS):
            if self.count % (1 << j):
                break
            block = residual.tolist() if j == 0 else [max(a, b) for a, b in zip(*self.done[j - 1][-2:])]
            done, scale = self.done[j], self.scale[j]
            done.append(block)
            scale.append(self.carried)
            if len(done) > self.blocks + 1:
                del done[0], scale[0]
            if hit is None and len(done) == self.blocks + 1:
                least = self.least[j]
                # cheap test first (the newest ratio): it fails on almost every step of a sound run
                for k, (a, b) in enumerate(zip(done[-2], block)):
                    if b >= least * a and self._grown(done, scale[0], k, least):
                        hit = Growth(k, self.blocks << j, block[k] / done[0][k])
                        break
        return hit

    def _grown(self, done: list[list[float]], carried: list[float], k: int, least: float) -> bool:
        first = done[0][k]
        if not first > self.floor * carried[k]:
            return False
        ratio = None
        for a, b in zip(done, done[1:]):
            r = b[k] / a[k]
            if r < least or (ratio is not None and r < self.keep * ratio):
                return False
            ratio = r
        return True
