"""How far apart two vectors of coupling values are, relative to each value's size.

One definition for the master's uses, each with its own floor under the size (so that a value near
zero is not divided by zero): the fixed-point residual of the iterative coupling (:mod:`.algorithms`,
size = the largest magnitude so far or now, floored at 1e-12 of the largest) and of the
initialization (:mod:`.initialization`, size = the larger magnitude now, floored at 1e-12 of the
largest), and the error estimate of the adaptive step (:func:`.step_control.coupling_error`, floor
1e-9 of the largest size so far).
"""
from __future__ import annotations

import numpy as np


def relative_residual(a: np.ndarray, b: np.ndarray, scale: np.ndarray, floor: float,
                      tolerance: float = 1.0) -> tuple[float, int]:
    """(max_i |b_i - a_i| / (tolerance * max(scale_i, floor)), the index i of that maximum); an entry
    with b_i == a_i counts 0 (also an infinity that did not change).  (0.0, 0) for empty vectors.
    A NaN difference is returned as the maximum (the caller's check for non-finite values sees it)."""
    if len(a) == 0:
        return 0.0, 0
    r = np.abs(b - a) / (tolerance * np.maximum(scale, floor))
    r[b == a] = 0.0
    worst = int(np.argmax(r))
    return float(r[worst]), worst


class CouplingCriterion:
    """When the iterative coupling has converged: every coupling value u_i satisfies

        |G(u)_i - u_i| <= tolerance * size_i + floor_i,

    size_i the largest magnitude of the value so far or now (relative part), floor_i = NOISE *
    ref_i an absolute floor per connection, ref_i the larger of the nominal its source output
    declares (FMI ``nominal`` times the connection's factor; 0 where none is declared: FMI's default
    1 in SI units is far too coarse for a position next to a stiff rope) and the signal's range so far
    (max - min of its values at the communication points).  A fixed-point map evaluated through FMUs is exact
    only to their internal solvers' accuracy and round-off (measured: 2e-13 of the forces, 4e-9 of
    a hook velocity of 2e-6 m/s on truck_telescope's start-up, 6.5e-15 m/s on a hook velocity of
    3e-10 m/s at rest on the ground in overhead_lift):
    without the floor, a tolerance at or below that level asks for more than the map can give.
    With it, the tolerance is never below NOISE of what the signal does, whatever is asked.

    A value at rest has no range: its noise (6.5e-15 m/s, 2e-5 of its size) is met by
    :meth:`stalled`: an iteration whose error has not halved in STALL iterations is at the map's
    noise; it is accepted only if every value then changes by at most STALL_NOISE of its size.
    """

    NOISE = 1e-10
    STALL = 5
    STALL_NOISE = 1e-4

    def __init__(self, tolerance: float, nominal: np.ndarray):
        self.tolerance = tolerance
        self.nominal = np.where(np.isnan(nominal), 0.0, np.abs(nominal))
        self.lo = self.hi = None
        self.floor = np.zeros(len(self.nominal))

    def start(self, values: np.ndarray) -> None:
        """Take in the coupling values at the start of a step (they widen the range)."""
        if self.lo is None:
            self.lo, self.hi = values.copy(), values.copy()
        else:
            np.minimum(self.lo, values, out=self.lo)
            np.maximum(self.hi, values, out=self.hi)
        self.floor = self.NOISE * np.maximum(self.nominal, self.hi - self.lo)

    def error(self, u: np.ndarray, gu: np.ndarray, size: np.ndarray) -> tuple[float, int]:
        """(max_i |gu_i - u_i| / (tolerance size_i + floor_i), its index): converged if <= 1."""
        if len(u) == 0:
            return 0.0, 0
        bound = self.tolerance * size + self.floor
        r = np.abs(gu - u)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(r == 0.0, 0.0, r / bound)
        r[gu == u] = 0.0
        worst = int(np.argmax(r))
        return float(r[worst]), worst

    def stalled(self, errors: list[float], u: np.ndarray, gu: np.ndarray, size: np.ndarray) -> bool:
        """True if the error (``errors``: this step's, oldest first) has not halved in STALL iterations
        and every value changes by at most STALL_NOISE of its size: the map's noise, accepted."""
        if len(errors) <= self.STALL or errors[-1] <= 0.5 * min(errors[:-self.STALL]):
            return False
        return bool(np.all(np.abs(gu - u) <= self.STALL_NOISE * size))
