"""Waveform iteration: strong coupling on a sub-grid of the macro step.

Inside one macro step [t, t + H] every FMU steps over ``m`` sub-intervals of H/m.  The unknowns
are the coupling values at the m sub-points t_j = t + j H/m (stacked, m times the coupling
vector); the value at t is known.  An iteration rolls every FMU back to t (get/set FMU state),
feeds each input on [t_j, t_j+1] a quadratic taken from the current waveform, steps all FMUs
sub-interval by sub-interval, and reads what they give at every sub-point (in feedthrough order,
as :meth:`Iterative._image`).  The stacked residual is driven to the coupling tolerance by the
run's accelerator (IQN-ILS or Aitken).

The fed quadratic (FMUs take value, ``_dt`` and ``_dt2`` only) is the L2 projection onto
quadratics on the sub-interval of the degree-q polynomial through the q + 1 nearest sub-points
(this step's and the previous step's).  The projection error is orthogonal to every quadratic, so
in the variation-of-constants integral over a sub-interval of length d it leaves O(d^3 * d^3 * d)
(derived); with the interpolation error O(d^(q+1)) the global error is O(d^min(q+1, 6)).  Default
q = 5: sixth order in H/m (measured 7.0 to 5.7 in tests/master/test_waveform.py).
"""
from __future__ import annotations

import numpy as np

from .algorithms import Iterative, floored
from .coupled import Coupling


def _projection(degree: int) -> np.ndarray:
    """P (3 x degree+1): coefficients on 1, x, x^2 of the L2 projection on [0, 1] of x^k
    (normal equations with the Hilbert matrix: int_0^1 x^i x^k dx = 1 / (i + k + 1))."""
    gram = 1.0 / (np.arange(3)[:, None] + np.arange(3)[None, :] + 1.0)
    moments = 1.0 / (np.arange(3)[:, None] + np.arange(degree + 1)[None, :] + 1.0)
    return np.linalg.solve(gram, moments)


def fed_quadratic(ts: np.ndarray, values: np.ndarray, t0: float, dt: float) -> np.ndarray:
    """[u0, d1, d2] (rows) of the quadratic u0 + s d1 + s^2/2 d2 (s = t - t0 in [0, dt]) that is
    the L2 projection of the polynomial through (ts[i], values[i]) (values: points x variables)."""
    x = (ts - t0) / dt
    q = len(ts) - 1
    coef = np.linalg.solve(np.vander(x, q + 1, increasing=True), values)   # in x = s / dt
    c = _projection(q) @ coef
    return np.array([c[0], c[1] / dt, 2.0 * c[2] / dt ** 2])


def stencil(n_points: int, j: int, size: int) -> slice:
    """The ``size`` consecutive points out of ``n_points`` that contain points j and j + 1, as
    centred on the interval between them as the ends allow."""
    size = min(size, n_points)
    start = j + 1 - size // 2 if size % 2 == 0 else j - size // 2
    return slice(max(0, min(start, n_points - size)), max(0, min(start, n_points - size)) + size)


class WaveformIterative(Iterative):
    """Iterative coupling with ``substeps`` sub-intervals per macro step (see the module doc); the
    iteration, its accelerator and convergence test are :class:`~.algorithms.Iterative`'s."""

    name = "waveform"
    needs_snapshot = True

    def __init__(self, coupling: Coupling, substeps: int, tolerance: float, max_iterations: int,
                 accelerator: str, degree: int = 5):
        super().__init__(coupling, degree=degree, tolerance=tolerance, max_iterations=max_iterations,
                         accelerator=accelerator)
        self.m = substeps
        self.past: list[tuple[float, np.ndarray]] = []   # the last accepted sub-points, oldest first

    @classmethod
    def from_settings(cls, coupling: Coupling, s) -> Iterative:
        return cls(coupling, s.substeps, tolerance=s.coupling_tolerance, max_iterations=s.max_iterations,
                   accelerator=s.accelerator)

    def _points(self, t: float, h: float, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
        """(times, values, index of t): past sub-points, the value at t, the waveform w (m x n)."""
        past = [p for p in self.past if p[0] < t - 1e-12 * max(1.0, abs(t))][-self.degree:]
        ts = np.array([p[0] for p in past] + [t + h * j / self.m for j in range(self.m + 1)])
        values = np.vstack([*(p[1] for p in past), self.coupling.values(), w])
        return ts, values, len(past)

    def _feed_sub(self, ts: np.ndarray, values: np.ndarray, j: int) -> None:
        sel = stencil(len(ts), j, self.degree + 1)
        quad = fed_quadratic(ts[sel], values[sel], ts[j], ts[j + 1] - ts[j])
        self.coupling.feed_polynomial(quad[0], quad[1], quad[2])

    def step(self, t: float, h: float, snapshot=None) -> tuple[float, int]:
        c, m = self.coupling, self.m
        n = c.n
        w = np.vstack([c.predict(t, h * j / m, order=2) for j in range(1, m + 1)])
        scale = np.tile(floored(c.sizes()), m)
        self.check.criterion.start(c.values())
        self.acc.start_step()
        span, errors = (t, h), []
        for k in range(1, self.max_iterations + 1):
            if k > 1:
                c.restore(snapshot)
                w = (scale * self.acc.next(w.ravel() / scale, gw.ravel() / scale)).reshape(m, n)
            ts, values, i0 = self._points(t, h, w)
            gw = np.empty((m, n))
            for j in range(m):
                self._feed_sub(ts, values, i0 + j)
                c.step(ts[i0 + j], ts[i0 + j + 1] - ts[i0 + j], ends=j == m - 1)
                gw[j] = c.image()
            done, worst = self.check.converged(w.ravel(), gw.ravel(), scale, errors, span, m)
            if done:
                c.commit(t + h)
                self.past = [p for p in self.past if p[0] < t] + [(ts[i0 + j], gw[j - 1]) for j in range(1, m + 1)]
                del self.past[:-self.degree]
                return h, k
        raise self.check.failure(k, w.ravel(), gw.ravel(), scale, worst, span)
