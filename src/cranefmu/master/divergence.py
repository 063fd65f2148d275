"""Default alarm for an unstable explicit coupling: geometric growth of the power-bond residuals.

Beyond its stability limit an explicit coupling multiplies its error by the spectral radius
rho > 1 of the step recurrence every macro step (:mod:`cranefmu.stability`), so the energy
residual of a bond grows like rho^(2n).  A slack-capable connection (a rope cannot push) may
bound the blow-up and leave finite nonsense, so waiting for a non-finite value is not enough.

The test (derived): the maxima of the residual over 4 consecutive blocks of W = 1, 2, 4, ... 256
steps; each block's maximum must be at least ``factor`` (and at least ``per_step``^W) times the
one before, and each of these ratios at least ``keep`` times the previous ratio.  Geometric growth
keeps its ratio; growth that follows a power of the time since an event, dE ~ (t - t_e)^p, has
ratios ((a + kW) / (a + (k-1)W))^p that fall from block to block, so it does not pass (measured:
the stable runs of every scene).  ``per_step`` = 1.01 leaves alone a slow energy gain such as an
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
        self.carried = np.zeros(n_bonds)       # largest carried energy per step so far
        # per level: completed block maxima of the residual, and the carried maximum at each block's end
        self.done: list[list[np.ndarray]] = [[] for _ in range(LEVELS)]
        self.scale: list[list[np.ndarray]] = [[] for _ in range(LEVELS)]

    def update(self, residual: np.ndarray, carried: np.ndarray) -> Growth | None:
        self.count += 1
        np.maximum(self.carried, carried, out=self.carried)
        hit = None
        for j in range(LEVELS):
            if self.count % (1 << j):
                break
            block = residual.copy() if j == 0 else np.maximum(*self.done[j - 1][-2:])
            done, scale = self.done[j], self.scale[j]
            done.append(block)
            scale.append(self.carried.copy())
            if len(done) > self.blocks + 1:
                del done[0], scale[0]
            if hit is None and len(done) == self.blocks + 1:
                hit = self._grown(done, scale[0], 1 << j)
        return hit

    def _grown(self, done: list[np.ndarray], carried: np.ndarray, width: int) -> Growth | None:
        first = done[0]
        ok = first > self.floor * carried
        least = max(self.factor, self.per_step ** width)
        ratio = None
        for a, b in zip(done, done[1:]):
            with np.errstate(divide="ignore", invalid="ignore"):
                r = b / a
            ok &= r >= least
            if ratio is not None:
                ok &= r >= self.keep * ratio
            ratio = r
        if not ok.any():
            return None
        k = int(np.argmax(np.where(ok, done[-1] / np.maximum(first, 1e-300), 0.0)))
        return Growth(k, self.blocks * width, float(done[-1][k] / first[k]))
