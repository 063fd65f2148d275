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


class FixedSteps:
    """Fixed macro step H on the grid t0 + n H (the last step ends exactly at the stop time)."""

    rolls_back = False

    def __init__(self, start: float, stop: float, step: float):
        self.start, self.stop, self.step = start, stop, step
        self.count = max(1, round((stop - start) / step))
        self.n = 0
        self.t_next = start

    def propose(self, t: float) -> float | None:
        """The next step from t [s], or None at the end."""
        if self.n >= self.count:
            return None
        self.t_next = self.stop if self.n == self.count - 1 else self.start + (self.n + 1) * self.step
        return self.t_next - t

    def prepare(self, t: float, h: float, algorithm) -> None:
        pass

    def judge(self, t: float, h: float, algorithm) -> bool:
        return True

    def advance(self, t: float, h: float) -> float:
        self.n += 1
        return self.t_next

    def accepted(self, h: float) -> None:
        pass


class AdaptiveSteps:
    """Adaptive macro step: PI control of an error estimate, rollback of a rejected step, and
    event location (a step in which a discrete output switches is halved down to h_min, then the
    step restarts from h_min).

    ``estimate``: :class:`ExtrapolationError` (rejecting) or :class:`EccoError` (never rejecting)."""

    rolls_back = True

    def __init__(self, system, estimate, start: float, stop: float, step: float, h_min: float, h_max: float,
                 order: int):
        self.system, self.estimate, self.stop = system, estimate, stop
        self.h, self.h_min = step, h_min
        self.controller = PIController(order, h_min, h_max)
        self.flags = system.flags()
        self.locating = self.event = False
        self.err = 0.0

    def propose(self, t: float) -> float | None:
        remaining = self.stop - t
        if remaining <= 1e-12 * max(1.0, abs(self.stop)):
            return None
        if self.h >= remaining or remaining - self.h < 0.1 * self.h:
            self.h = remaining
        return self.h

    def prepare(self, t: float, h: float, algorithm) -> None:
        self.estimate.prepare(t, h)

    def judge(self, t: float, h: float, algorithm) -> bool:
        """Accept the step just taken, or set the step to retry with (the caller rolls back)."""
        self.err = 0.0
        new_flags = self.system.flags()
        self.event = new_flags != self.flags
        if self.event and h > self.h_min * (1 + 1e-9):
            self.h, self.locating = max(0.5 * h, self.h_min), True
            return False
        if algorithm.estimable:
            self.err = self.estimate.rejecting(h)
            if self.err > 1.0 and h > self.h_min * (1 + 1e-9) and not self.locating:
                self.h = self.controller.rejected(h, self.err)
                return False
        self.flags = new_flags
        return True

    def advance(self, t: float, h: float) -> float:
        return t + h

    def accepted(self, h: float) -> None:
        if self.locating and self.event:      # the switch is located to min_step: restart small
            self.locating = False
            self.h = self.h_min
        elif not self.locating:
            self.h = self.controller.accepted(h, self.estimate.after(self.err))


class ExtrapolationError:
    """The coupling values' error against their extrapolation (:func:`coupling_error`); rejects."""

    def __init__(self, system, tolerance: float):
        self.system, self.tolerance = system, tolerance
        self.predicted = None

    def prepare(self, t: float, h: float) -> None:
        self.predicted = self.system.predicted(t, h)

    def rejecting(self, h: float) -> float:
        s = self.system
        return coupling_error(self.predicted, s.coupling_values(), s.scale, self.tolerance)[0]

    def after(self, err: float) -> float:
        return err


class EccoError:
    """The power bonds' energy residuals of the accepted step (:func:`ecco_error`); never rejects."""

    def __init__(self, bonds, tolerance: float):
        self.bonds, self.tolerance = bonds, tolerance

    def prepare(self, t: float, h: float) -> None:
        pass

    def rejecting(self, h: float) -> float:
        return 0.0

    def after(self, err: float) -> float:
        b = self.bonds
        return ecco_error(b.residual, b.carried, self.tolerance, 1e-3 * self.tolerance)


def make_step_control(system, s, bonds):
    """The step controller the settings ``s`` ask for (``bonds``: the run's power-bond monitor)."""
    if not s.adaptive:
        return FixedSteps(s.start_time, s.stop_time, s.step_size)
    ecco = s.step_control == "ecco"
    estimate = EccoError(bonds, s.tolerance) if ecco else ExtrapolationError(system, s.tolerance)
    return AdaptiveSteps(system, estimate, s.start_time, s.stop_time, s.step_size, s.h_min, s.h_max,
                         2 if ecco else s.extrapolation + 1)
