"""Macro step size control: error estimates and the PI controller.

Error of a step (``coupling_error``): how far each coupling value at t + h lies from the value the
extrapolation polynomial of order p predicted for it from the past, relative to ``tolerance``
times the variable's size (its largest magnitude so far).  It is the local error of the inputs the
FMUs were fed: O(h^(p+1)).  A step is accepted when the error is <= 1.

``ecco_error``: the power bonds' energy residuals, relative to the energy the bond carried in the
step (ECCO, Sadjina et al. 2017); used without rejection.
"""
from __future__ import annotations

import math

import numpy as np

from .residual import relative_residual


def coupling_error(predicted: np.ndarray, actual: np.ndarray, scale: np.ndarray, tolerance: float) -> tuple[float, int]:
    """(max relative error / tolerance, index of the worst variable)."""
    if len(actual) == 0:
        return 0.0, 0
    return relative_residual(predicted, actual, scale, 1e-9 * max(1.0, float(np.max(scale))), tolerance)


def ecco_error(residuals: np.ndarray, carried: np.ndarray, rtol: float, atol: float) -> float:
    """sqrt(mean_k (dE_k / (atol + rtol * E_k))^2), E_k the energy through bond k in the step [J]."""
    if len(residuals) == 0:
        return 0.0
    return float(np.sqrt(np.mean((residuals / (atol + rtol * carried)) ** 2)))


class PIController:
    """h_next = h * clamp(safety * err^-alpha * err_prev^beta, rmin, rmax) with alpha = 0.7/k,
    beta = 0.4/k for an error of order k in h (Gustafsson's PI control, Hairer and Wanner II, IV.2);
    a rejected step retries with h * clamp(safety * err^(-1/k), rmin, 1)."""

    def __init__(self, k: int, h_min: float, h_max: float, safety: float = 0.9, rmin: float = 0.2,
                 rmax: float = 4.0):
        self.k, self.h_min, self.h_max = k, h_min, h_max
        self.safety, self.rmin, self.rmax = safety, rmin, rmax
        self.alpha, self.beta = 0.7 / k, 0.4 / k
        self.err_prev = 1.0

    def accepted(self, h: float, err: float) -> float:
        err = max(err, 1e-10)
        ratio = self.safety * err ** -self.alpha * self.err_prev ** self.beta
        self.err_prev = err
        return self._clip(h * min(self.rmax, max(self.rmin, ratio)))

    def rejected(self, h: float, err: float) -> float:
        ratio = self.safety * max(err, 1e-10) ** (-1.0 / self.k) if math.isfinite(err) else self.rmin
        return self._clip(h * min(1.0, max(self.rmin, ratio)))

    def _clip(self, h: float) -> float:
        return min(self.h_max, max(self.h_min, h))
