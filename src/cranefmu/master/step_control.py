"""Macro step size control: error estimates and the PI controller.

Error of a step (``coupling_error``): how far each coupling value at t + h lies from the value the
extrapolation polynomial of order p predicted for it from the past, relative to ``tolerance``
times the variable's size (its largest magnitude so far).  It is the local error of the inputs the
FMUs were fed: O(h^(p+1)).  A step is accepted when the error is <= 1.

``ecco_error``: the power bonds' energy residuals, relative to the energy the bond carried in the
step (ECCO, Sadjina et al. 2017); used without rejection.

``ESTIMATES`` maps the ``step_control`` setting to its error estimate; each checks what it needs
(:meth:`from_settings`).  :func:`make_step_control` gives the controller a run's settings ask for.
"""
from __future__ import annotations

import math

import numpy as np

from .coupled import Coupling
from ..errors import SettingsError
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
    judges = False   # every step is taken as proposed

    def __init__(self, start: float, stop: float, step: float):
        self.start, self.stop, self.step = start, stop, step
        self.count = max(1, round((stop - start) / step))
        self.n = 0
        self.t_next = start

    def begin(self, flags: list[int]) -> None:
        pass

    def propose(self, t: float) -> float | None:
        """The next step from t [s], or None at the end."""
        if self.n >= self.count:
            return None
        self.t_next = self.stop if self.n == self.count - 1 else self.start + (self.n + 1) * self.step
        return self.t_next - t

    def upcoming(self, t: float, most: int) -> np.ndarray:
        """t and the next grid times after it (at most ``most`` steps), as :meth:`propose` gives them."""
        steps = min(most, self.count - self.n)
        ts = np.empty(steps + 1)
        ts[0] = t
        ts[1:] = self.start + np.arange(self.n + 1, self.n + steps + 1) * self.step   # each as propose()
        if self.n + steps == self.count:
            ts[-1] = self.stop
        return ts

    def prepare(self, t: float, h: float, algorithm) -> None:
        pass

    def judge(self, t: float, h: float, algorithm, flags: list[int]) -> bool:
        return True

    def advance(self, t: float, h: float) -> float:
        self.n += 1
        return self.t_next

    def advance_grid(self, ts: np.ndarray, steps: int) -> float:
        """:meth:`propose` and :meth:`advance` for each of the first ``steps`` steps of ``ts`` (from
        :meth:`upcoming`); returns the time reached [s]."""
        self.n += steps
        self.t_next = float(ts[steps])
        return self.t_next

    def accepted(self, h: float, bonds) -> None:
        pass


class AdaptiveSteps:
    """Adaptive macro step: PI control of an error estimate, rollback of a rejected step, and
    event location (a step in which a discrete output switches is halved down to h_min, then the
    step restarts from h_min).

    ``estimate``: :class:`ExtrapolationError` (rejecting) or :class:`EccoError` (never rejecting)."""

    rolls_back = True
    judges = True

    def __init__(self, estimate, start: float, stop: float, step: float, h_min: float, h_max: float, order: int):
        self.estimate, self.stop = estimate, stop
        self.h, self.h_min = step, h_min
        self.controller = PIController(order, h_min, h_max)
        self.flags: list[int] = []
        self.locating = self.event = False
        self.err = 0.0

    def begin(self, flags: list[int]) -> None:
        self.flags = flags

    def propose(self, t: float) -> float | None:
        remaining = self.stop - t
        if remaining <= 1e-12 * max(1.0, abs(self.stop)):
            return None
        if self.h >= remaining or remaining - self.h < 0.1 * self.h:
            self.h = remaining
        return self.h

    def prepare(self, t: float, h: float, algorithm) -> None:
        self.estimate.prepare(t, h)

    def judge(self, t: float, h: float, algorithm, flags: list[int]) -> bool:
        """Accept the step just taken (``flags``: the discrete outputs after it), or set the step to
        retry with (the caller rolls back)."""
        self.err = 0.0
        self.event = flags != self.flags
        if self.event and h > self.h_min * (1 + 1e-9):
            self.h, self.locating = max(0.5 * h, self.h_min), True
            return False
        if algorithm.estimable:
            self.err = self.estimate.rejecting(h)
            if self.err > 1.0 and h > self.h_min * (1 + 1e-9) and not self.locating:
                self.h = self.controller.rejected(h, self.err)
                return False
        self.flags = flags
        return True

    def advance(self, t: float, h: float) -> float:
        return t + h

    def accepted(self, h: float, bonds) -> None:
        """``bonds``: the power bonds as the loop measured them over the accepted step."""
        if self.locating and self.event:      # the switch is located to min_step: restart small
            self.locating = False
            self.h = self.h_min
        elif not self.locating:
            self.h = self.controller.accepted(h, self.estimate.after(self.err, bonds))


class ExtrapolationError:
    """The coupling values' error against their extrapolation (:func:`coupling_error`); rejects."""

    def __init__(self, coupling, tolerance: float):
        self.coupling, self.tolerance = coupling, tolerance
        self.predicted = None

    @classmethod
    def from_settings(cls, coupling, s, bonds) -> ExtrapolationError:
        return cls(coupling, s.tolerance)

    @staticmethod
    def refuse(bonds) -> None:
        """Raise a :class:`SettingsError` if the scene cannot give this estimate (it always can)."""

    @staticmethod
    def order(s) -> int:
        """The order in h of the error: that of the extrapolation's local error."""
        return s.extrapolation + 1

    def prepare(self, t: float, h: float) -> None:
        self.predicted = self.coupling.predict(t, h)

    def rejecting(self, h: float) -> float:
        c = self.coupling
        return coupling_error(self.predicted, c.values(), c.sizes(), self.tolerance)[0]

    def after(self, err: float, bonds) -> float:
        return err


class EccoError:
    """The power bonds' energy residuals of the accepted step (:func:`ecco_error`); never rejects."""

    def __init__(self, tolerance: float):
        self.tolerance = tolerance

    @classmethod
    def from_settings(cls, coupling, s, bonds) -> EccoError:
        cls.refuse(bonds)
        return cls(s.tolerance)

    @staticmethod
    def refuse(bonds) -> None:
        """Raise a :class:`SettingsError` if the scene has no power bond to measure."""
        if not bonds.bonds:
            raise SettingsError("step_control = 'ecco' is not allowed for this scene: it declares no power bonds "
                                "(see docs/power_bonds.md, 'Declaring a bond')")

    @staticmethod
    def order(s) -> int:
        return 2

    def prepare(self, t: float, h: float) -> None:
        pass

    def rejecting(self, h: float) -> float:
        return 0.0

    def after(self, err: float, bonds) -> float:
        return ecco_error(bonds.residual, bonds.carried, self.tolerance, 1e-3 * self.tolerance)


ESTIMATES = {"extrapolation": ExtrapolationError, "ecco": EccoError}


def make_step_control(coupling: Coupling, s, bonds):
    """The step controller the settings ``s`` ask for (``coupling``: the run's
    :class:`~.coupled.Coupling`; ``bonds``: its power-bond monitor)."""
    if not s.adaptive:
        return FixedSteps(s.start_time, s.stop_time, s.step_size)
    kind = ESTIMATES[s.step_control]
    return AdaptiveSteps(kind.from_settings(coupling, s, bonds), s.start_time, s.stop_time, s.step_size,
                         s.h_min, s.h_max, kind.order(s))
