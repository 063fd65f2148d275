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
